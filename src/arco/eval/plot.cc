#include "arco/eval/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace arco::eval {
namespace {

constexpr double kWidth = 900, kPanelHeight = 180, kLeft = 70, kRight = 20, kTop = 30, kGap = 50;
const char* kColors[] = {"#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"};

struct Panel {
  std::ostringstream* out;
  double y0;  // top of the panel
  double t_max, v_min, v_max;
  double X(double t) const { return kLeft + (kWidth - kLeft - kRight) * t / t_max; }
  double Y(double v) const { return y0 + kPanelHeight * (1 - (v - v_min) / (v_max - v_min)); }
};

// Polyline of a series, broken at NaN.
void Series(
    const Panel& p, const std::vector<double>& v, double fps, const char* color, double width) {
  std::ostringstream& o = *p.out;
  bool open = false;
  char buf[64];
  for (size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) {
      if (open) o << "\"/>\n";
      open = false;
      continue;
    }
    if (!open)
      o << "<polyline fill=\"none\" stroke=\"" << color << "\" stroke-width=\"" << width
        << "\" points=\"";
    open = true;
    std::snprintf(
        buf, sizeof(buf), "%.1f,%.1f ", p.X(i / fps), p.Y(std::clamp(v[i], p.v_min, p.v_max)));
    o << buf;
  }
  if (open) o << "\"/>\n";
}

void Axes(const Panel& p, const std::string& title, const std::string& unit) {
  std::ostringstream& o = *p.out;
  o << "<rect x=\"" << kLeft << "\" y=\"" << p.y0 << "\" width=\"" << kWidth - kLeft - kRight
    << "\" height=\"" << kPanelHeight << "\" fill=\"none\" stroke=\"#888\"/>\n";
  o << "<text x=\"" << kLeft << "\" y=\"" << p.y0 - 8 << "\" font-size=\"13\">" << title
    << "</text>\n";
  char buf[64];
  for (int k = 0; k <= 4; ++k) {
    const double v = p.v_min + (p.v_max - p.v_min) * k / 4;
    std::snprintf(buf, sizeof(buf), "%.0f", v);
    o << "<text x=\"" << kLeft - 6 << "\" y=\"" << p.Y(v) + 4
      << "\" font-size=\"10\" text-anchor=\"end\">" << buf << "</text>\n";
  }
  o << "<text x=\"12\" y=\"" << p.y0 + kPanelHeight / 2 << "\" font-size=\"10\">" << unit
    << "</text>\n";
  for (int k = 0; k <= 5; ++k) {
    const double t = p.t_max * k / 5;
    std::snprintf(buf, sizeof(buf), "%.1f s", t);
    o << "<text x=\"" << p.X(t) << "\" y=\"" << p.y0 + kPanelHeight + 14
      << "\" font-size=\"10\" text-anchor=\"middle\">" << buf << "</text>\n";
  }
}

double MaxFinite(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) {
    if (std::isfinite(x)) m = std::max(m, x);
  }
  return m;
}

std::vector<double> Midi(const std::vector<double>& hz) {
  std::vector<double> out;
  for (double f : hz) out.push_back(f > 0 ? 69 + 12 * std::log2(f / 440.0) : NAN);
  return out;
}

}  // namespace

std::string EvalPlotSvg(const EvalReport& report, double fps) {
  const bool has_pitch = !report.truth_f0_hz.empty() && !report.estimate_f0_hz.empty();
  const int panels = 2 + (has_pitch ? 1 : 0);
  const double height = kTop + panels * (kPanelHeight + kGap);
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kWidth << "\" height=\"" << height
    << "\" font-family=\"sans-serif\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  size_t frames = 0;
  for (const auto& m : report.methods) frames = std::max(frames, m.frame_hand_mm.size());
  const double t_max = std::max(1.0, frames / fps);
  double y = kTop;
  if (has_pitch) {
    const std::vector<double> truth = Midi(report.truth_f0_hz), est = Midi(report.estimate_f0_hz);
    double lo = 1e9, hi = -1e9;
    for (double v : truth) {
      if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
    }
    if (lo > hi) lo = 40, hi = 80;
    Panel p{&o, y, t_max, std::floor(lo - 2), std::ceil(hi + 2)};
    Axes(p, "pitch: truth (black) and estimate (orange)", "MIDI");
    Series(p, truth, fps, "#000", 2.5);
    Series(p, est, fps, "#ff7f0e", 1.2);
    y += kPanelHeight + kGap;
  }
  double hand_max = 5, contact_max = 5;
  for (const auto& m : report.methods) {
    hand_max = std::max(hand_max, MaxFinite(m.frame_hand_mm));
    contact_max = std::max(contact_max, MaxFinite(m.frame_contact_mm));
  }
  std::string legend;
  for (size_t i = 0; i < report.methods.size(); ++i) {
    legend += std::string(i ? ", " : "") + report.methods[i].method + " (" + kColors[i % 6] + ")";
  }
  Panel hand{&o, y, t_max, 0, std::ceil(std::min(hand_max, 60.0))};
  Axes(hand, "left-hand error, wrist-aligned mean per frame: " + legend, "mm");
  for (size_t i = 0; i < report.methods.size(); ++i)
    Series(hand, report.methods[i].frame_hand_mm, fps, kColors[i % 6], 1.2);
  y += kPanelHeight + kGap;
  Panel contact{&o, y, t_max, 0, std::ceil(std::min(contact_max, 60.0))};
  Axes(contact, "contact deviation per pressed frame", "mm");
  for (size_t i = 0; i < report.methods.size(); ++i) {
    Series(contact, report.methods[i].frame_contact_mm, fps, kColors[i % 6], 1.2);
  }
  o << "</svg>\n";
  return o.str();
}

}  // namespace arco::eval
