// The two writers of a plot scene (plot.h): SVG text and an OpenCV raster (PNG).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "arco/export/plot.h"

namespace arco::exporter {
namespace {

std::string Num(double v, const char* fmt = "%.6g") {
  char buf[64];
  std::snprintf(buf, sizeof(buf), fmt, v);
  return buf;
}

std::string XmlEscape(const std::string& s) {
  std::string out;
  for (const char c : s) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string Rgb(const PlotRgb& c) {
  char buf[16];
  std::snprintf(buf, sizeof(buf), "#%02x%02x%02x", c[0], c[1], c[2]);
  return buf;
}

}  // namespace

std::string PlotSvg(const PlotScene& scene) {
  std::string s = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  s += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(scene.width) +
       "\" height=\"" + std::to_string(scene.height) + "\" viewBox=\"0 0 " +
       std::to_string(scene.width) + " " + std::to_string(scene.height) +
       "\" font-family=\"sans-serif\">\n";
  s += "<rect x=\"0\" y=\"0\" width=\"" + std::to_string(scene.width) + "\" height=\"" +
       std::to_string(scene.height) + "\" fill=\"#ffffff\"/>\n";
  for (const PlotShape& p : scene.shapes) {
    std::string attrs;
    if (!p.css_class.empty()) attrs += " class=\"" + XmlEscape(p.css_class) + "\"";
    for (const auto& [k, v] : p.data) attrs += " data-" + k + "=\"" + XmlEscape(v) + "\"";
    const std::string fill = p.filled ? Rgb(p.fill) : "none";
    switch (p.kind) {
      case PlotShape::Kind::kPolyline: {
        s += "<polyline" + attrs + " fill=\"none\" stroke=\"" + Rgb(p.stroke) +
             "\" stroke-width=\"" + Num(p.size) + "\" points=\"";
        for (size_t i = 0; i < p.points.size(); ++i) {
          s += (i ? " " : "") + Num(p.points[i].x(), "%.3f") + "," + Num(p.points[i].y(), "%.3f");
        }
        s += "\"/>\n";
        break;
      }
      case PlotShape::Kind::kRect: {
        const Eigen::Vector2d lo = p.points[0].cwiseMin(p.points[1]);
        const Eigen::Vector2d hi = p.points[0].cwiseMax(p.points[1]);
        s += "<rect" + attrs + " x=\"" + Num(lo.x(), "%.3f") + "\" y=\"" + Num(lo.y(), "%.3f") +
             "\" width=\"" + Num(hi.x() - lo.x(), "%.3f") + "\" height=\"" +
             Num(hi.y() - lo.y(), "%.3f") + "\" fill=\"" + fill + "\"" +
             (p.outlined ? " stroke=\"" + Rgb(p.stroke) + "\" stroke-width=\"1\"" : "") + "/>\n";
        break;
      }
      case PlotShape::Kind::kCircle:
        s += "<circle" + attrs + " cx=\"" + Num(p.points[0].x(), "%.3f") + "\" cy=\"" +
             Num(p.points[0].y(), "%.3f") + "\" r=\"" + Num(p.size) + "\" fill=\"" + fill +
             "\" stroke=\"" + Rgb(p.stroke) + "\" stroke-width=\"2\"/>\n";
        break;
      case PlotShape::Kind::kText: {
        const char* anchor = p.align < 0 ? "start" : p.align == 0 ? "middle" : "end";
        s += "<text" + attrs + " x=\"" + Num(p.points[0].x(), "%.3f") + "\" y=\"" +
             Num(p.points[0].y(), "%.3f") + "\" font-size=\"" + Num(p.size) + "\" text-anchor=\"" +
             anchor + "\" fill=\"" + Rgb(p.stroke) + "\">" + XmlEscape(p.text) + "</text>\n";
        break;
      }
    }
  }
  s += "</svg>\n";
  return s;
}

media::Image RasterisePlot(const PlotScene& scene) {
  media::Image image = media::MakeImage(scene.width, scene.height, media::PixelFormat::kRgb8);
  cv::Mat m(scene.height, scene.width, CV_8UC3, image.pixels.data());
  m.setTo(cv::Scalar(255, 255, 255));
  constexpr int kShift = 4;
  auto fixed = [](const Eigen::Vector2d& p) {
    return cv::Point(static_cast<int>(std::lround(p.x() * (1 << kShift))),
                     static_cast<int>(std::lround(p.y() * (1 << kShift))));
  };
  auto color = [](const PlotRgb& c) { return cv::Scalar(c[0], c[1], c[2]); };  // RGB canvas
  auto width = [](double w) { return std::max(1, static_cast<int>(std::lround(w))); };
  for (const PlotShape& p : scene.shapes) {
    switch (p.kind) {
      case PlotShape::Kind::kPolyline: {
        std::vector<cv::Point> pts;
        for (const auto& v : p.points) pts.push_back(fixed(v));
        cv::polylines(m, pts, false, color(p.stroke), width(p.size), cv::LINE_AA, kShift);
        break;
      }
      case PlotShape::Kind::kRect:
        if (p.filled) {
          cv::rectangle(m,
                        fixed(p.points[0]),
                        fixed(p.points[1]),
                        color(p.fill),
                        cv::FILLED,
                        cv::LINE_AA,
                        kShift);
        }
        if (p.outlined) {
          cv::rectangle(
              m, fixed(p.points[0]), fixed(p.points[1]), color(p.stroke), 1, cv::LINE_AA, kShift);
        }
        break;
      case PlotShape::Kind::kCircle: {
        const int r = static_cast<int>(std::lround(p.size * (1 << kShift)));
        if (p.filled) {
          cv::circle(m, fixed(p.points[0]), r, color(p.fill), cv::FILLED, cv::LINE_AA, kShift);
        }
        cv::circle(m, fixed(p.points[0]), r, color(p.stroke), 2, cv::LINE_AA, kShift);
        break;
      }
      case PlotShape::Kind::kText: {
        // Hershey simplex capitals are about 22 px tall at scale 1; SVG font-size is the
        // em height, capitals about 0.7 of it.
        const double font_scale = 0.7 * p.size / 22.0;
        int baseline = 0;
        const cv::Size size =
            cv::getTextSize(p.text, cv::FONT_HERSHEY_SIMPLEX, font_scale, 1, &baseline);
        double x = p.points[0].x();
        if (p.align == 0) x -= size.width / 2.0;
        if (p.align > 0) x -= size.width;
        cv::putText(m,
                    p.text,
                    cv::Point(static_cast<int>(std::lround(x)),
                              static_cast<int>(std::lround(p.points[0].y()))),
                    cv::FONT_HERSHEY_SIMPLEX,
                    font_scale,
                    color(p.stroke),
                    1,
                    cv::LINE_AA);
        break;
      }
    }
  }
  return image;
}

}  // namespace arco::exporter
