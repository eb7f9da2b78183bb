#include "arco/track/bow_tracker.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "arco/track/bow_line.h"
#include "arco/track/bow_pose_solver.h"
#include "arco/util/parallel.h"

namespace arco::track {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

cv::Mat AsMat(const media::Image& image) {
  if (image.format != media::PixelFormat::kGray8) {
    throw std::invalid_argument("BowTracker: frames must be gray8");
  }
  return cv::Mat(image.height, image.width, CV_8UC1, const_cast<uint8_t*>(image.pixels.data()));
}

// Bilinear intensity at a pixel centre coordinate (integers are pixel centres); NaN
// outside.
double Sample(const cv::Mat& image, const Eigen::Vector2d& p) {
  const double x = p.x(), y = p.y();
  if (!(x >= 0 && y >= 0 && x < image.cols - 1 && y < image.rows - 1)) return kNaN;
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const double ax = x - x0, ay = y - y0;
  const uint8_t* r0 = image.ptr<uint8_t>(y0) + x0;
  const uint8_t* r1 = image.ptr<uint8_t>(y0 + 1) + x0;
  return (1 - ay) * ((1 - ax) * r0[0] + ax * r0[1]) + ay * ((1 - ax) * r1[0] + ax * r1[1]);
}

// A point's ideal (undistorted) pixel; nullopt behind the camera.
std::optional<Eigen::Vector2d> IdealPixel(const Camera& cam, const Eigen::Vector3d& world) {
  const Eigen::Vector3d c = cam.PointInCamera(world);
  if (!(c.z() > 1e-6)) return std::nullopt;
  const Eigen::Vector3d h = cam.K() * (c / c.z());
  return h.head<2>();
}

struct View {
  Camera camera;
  cv::Mat label_image;
  std::vector<double> profile;  // the labelled frame's, NaN where unseen
  std::vector<StickSegment> segments;
  std::vector<double> current;  // this frame's, slide_search_mm longer at both ends
  // Step 4: the labelled frame's intensities at State::u per blur level, and this frame's
  // blurred box (float) per level.
  std::vector<std::vector<double>> label_values;
  std::vector<cv::Mat> blurred;
  cv::Rect box;
  ViewTrackReport report;
  bool lost = false;
};

// Normalised cross-correlation of a with b shifted by `shift` samples, over the samples
// finite in both; n: how many.
double Ncc(const std::vector<double>& a, const std::vector<double>& b, int shift, int* n) {
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  int count = 0;
  for (size_t k = 0; k < a.size(); ++k) {
    const double x = a[k], y = b[k + shift];
    if (!std::isfinite(x) || !std::isfinite(y)) continue;
    sa += x;
    sb += y;
    saa += x * x;
    sbb += y * y;
    sab += x * y;
    ++count;
  }
  *n = count;
  if (count < 2) return 0;
  const double va = saa - sa * sa / count, vb = sbb - sb * sb / count;
  if (!(va > 1e-9 && vb > 1e-9)) return 0;
  return (sab - sa * sb / count) / std::sqrt(va * vb);
}

// Least squares on the views' rays through their right-hand pixels (NaN: none); nullopt
// with fewer than two views or rays that all but coincide.
std::optional<Eigen::Vector3d> TriangulateRays(const std::vector<View>& views,
                                               const std::vector<Eigen::Vector2d>& pixels) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  int used = 0;
  for (size_t v = 0; v < views.size() && v < pixels.size(); ++v) {
    if (!pixels[v].allFinite()) continue;
    const Camera& cam = views[v].camera;
    const Eigen::Vector3d r = cam.RayInWorld(pixels[v]);
    const Eigen::Matrix3d m = Eigen::Matrix3d::Identity() - r * r.transpose();
    a += m;
    b += m * cam.CenterInWorld();
    ++used;
  }
  if (used < 2) return std::nullopt;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(a);
  if (!(eig.eigenvalues()(0) > 1e-3 * eig.eigenvalues()(2))) return std::nullopt;
  const Eigen::Vector3d x = a.ldlt().solve(b);
  if (!x.allFinite()) return std::nullopt;
  return x;
}

}  // namespace

Status BowTrackerOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(CheckInRange("roi_margin_px", roi_margin_px, Closed(0, 1000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("search_px", search_px, AboveZero(1000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("max_angle_deg", max_angle_deg, AboveZero(45)));
  ARCO_RETURN_IF_ERROR(CheckInRange("min_segment_px", min_segment_px, Closed(2, 1000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("huber_px", huber_px, AboveZero(100)));
  ARCO_RETURN_IF_ERROR(CheckInRange("slide_search_mm", slide_search_mm, Closed(1, 1000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("profile_margin", profile_margin, Closed(0, 0.5)));
  ARCO_RETURN_IF_ERROR(CheckInRange("min_ncc", min_ncc, Closed(-1, 1)));
  ARCO_RETURN_IF_ERROR(CheckInRange("coarse_blur_px", coarse_blur_px, AboveZero(20)));
  ARCO_RETURN_IF_ERROR(CheckInRange("fine_blur_px", fine_blur_px, AboveZero(20)));
  ARCO_RETURN_IF_ERROR(CheckInRange("sample_step_mm", sample_step_mm, Closed(0.25, 100)));
  ARCO_RETURN_IF_ERROR(CheckInRange("intensity_sigma", intensity_sigma, AboveZero(255)));
  ARCO_RETURN_IF_ERROR(CheckInRange("line_sigma_px", line_sigma_px, AboveZero(100)));
  ARCO_RETURN_IF_ERROR(CheckInRange("motion_sigma_mm", motion_sigma_mm, AboveZero(1e4)));
  ARCO_RETURN_IF_ERROR(CheckInRange("hand_sigma_mm", hand_sigma_mm, AboveZero(1e4)));
  ARCO_RETURN_IF_ERROR(CheckInRange("hand_reacquire_mm", hand_reacquire_mm, AboveZero(1e4)));
  ARCO_RETURN_IF_ERROR(CheckInRange("num_threads", num_threads, Closed(0, 1024)));
  return Status::Ok();
}

Json ToJson(const BowTrackerOptions& o) {
  return Json{{"roi_margin_px", o.roi_margin_px},
              {"search_px", o.search_px},
              {"max_angle_deg", o.max_angle_deg},
              {"min_segment_px", o.min_segment_px},
              {"huber_px", o.huber_px},
              {"slide_search_mm", o.slide_search_mm},
              {"profile_margin", o.profile_margin},
              {"min_ncc", o.min_ncc},
              {"refine", o.refine},
              {"coarse_blur_px", o.coarse_blur_px},
              {"fine_blur_px", o.fine_blur_px},
              {"sample_step_mm", o.sample_step_mm},
              {"intensity_sigma", o.intensity_sigma},
              {"line_sigma_px", o.line_sigma_px},
              {"motion_sigma_mm", o.motion_sigma_mm},
              {"hand_sigma_mm", o.hand_sigma_mm},
              {"hand_reacquire_mm", o.hand_reacquire_mm}};
}

struct BowTracker::State {
  BowTrackerOptions options;
  std::vector<View> views;
  Eigen::Vector3d frog0, direction0;  // the labelled frame's
  double length = 0;
  Eigen::Vector3d frog, tip, frog_velocity = Eigen::Vector3d::Zero(),
                             tip_velocity = Eigen::Vector3d::Zero();
  int margin = 0, slide = 0, samples = 0;  // mm; samples per profile (1 mm apart)
  std::vector<double> u;                   // step 4's samples along the stick (mm)
  // The right hand at the labelled frame: frog + hand_along d + hand_across (world; the
  // across part is not turned with the bow: the bow turns little, and the prior is weak).
  double hand_along = 0;
  Eigen::Vector3d hand_across = Eigen::Vector3d::Zero();
  bool last_ok = true;

  std::vector<double> BlurSigmas() const { return {options.coarse_blur_px, options.fine_blur_px}; }

  // A box of the image, as floats, blurred (Gaussian, sigma px; the box's edges repeat).
  static cv::Mat Blurred(const cv::Mat& image, const cv::Rect& box, double sigma) {
    cv::Mat f, out;
    image(box).convertTo(f, CV_32F);
    cv::GaussianBlur(f, out, cv::Size(0, 0), sigma, sigma, cv::BORDER_REPLICATE);
    return out;
  }

  // The box step 4 reads in a view: the projections of the stick at the prediction and
  // at the first estimate, grown by the slide search and a margin; empty when the stick
  // is not in the image.
  cv::Rect RefineBox(const View& view,
                     const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& sticks,
                     const cv::Mat& image) const {
    double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;
    for (const auto& [f, t] : sticks)
      for (int i = -2; i <= 18; ++i) {
        // Points i < 0 and i > 16: the slide search beyond frog and tip.
        const double beyond = i < 0 ? -1.0 : (i > 16 ? 1.0 : 0.0);
        const Eigen::Vector3d d = (t - f).normalized();
        const auto p = view.camera.Project(f + (t - f) * (std::clamp(i, 0, 16) / 16.0) +
                                           beyond * options.slide_search_mm * d);
        if (!p) continue;
        x0 = std::min(x0, p->x());
        y0 = std::min(y0, p->y());
        x1 = std::max(x1, p->x());
        y1 = std::max(y1, p->y());
      }
    if (!(x1 >= x0)) return cv::Rect();
    const double m = options.roi_margin_px + 3 * options.coarse_blur_px;
    const cv::Rect box =
        cv::Rect(
            cv::Point(static_cast<int>(std::floor(x0 - m)), static_cast<int>(std::floor(y0 - m))),
            cv::Point(static_cast<int>(std::ceil(x1 + m)), static_cast<int>(std::ceil(y1 + m)))) &
        cv::Rect(0, 0, image.cols, image.rows);
    return box.width >= 8 && box.height >= 8 ? box : cv::Rect();
  }

  // The intensity along the line `origin + u d` for u = start, start + 1, ... (count
  // samples, mm), each the mean of three pixels across the line's image (1 px apart).
  void Profile(const View& view,
               const cv::Mat& image,
               const Eigen::Vector3d& origin,
               const Eigen::Vector3d& d,
               double start,
               int count,
               std::vector<double>* out) const {
    out->assign(count, kNaN);
    for (int k = 0; k < count; ++k) {
      const Eigen::Vector3d x = origin + (start + k) * d;
      const auto p = view.camera.Project(x);
      const auto q = view.camera.Project(x + d);
      if (!p || !q || (*q - *p).norm() < 1e-6) continue;
      const Eigen::Vector2d t = (*q - *p).normalized();
      const Eigen::Vector2d n(-t.y(), t.x());
      double sum = 0;
      bool ok = true;
      for (int j = -1; j <= 1 && ok; ++j) {
        const double s = Sample(image, *p + j * n);
        ok = std::isfinite(s);
        sum += s;
      }
      if (ok) (*out)[k] = sum / 3;
    }
  }

  // Segments near the predicted stick (frog_p, tip_p) in view v.
  void FindSegments(View& view,
                    const cv::Mat& image,
                    const Eigen::Vector3d& frog_p,
                    const Eigen::Vector3d& tip_p) const {
    view.segments.clear();
    const Camera& cam = view.camera;
    const auto a = IdealPixel(cam, frog_p), b = IdealPixel(cam, tip_p);
    if (!a || !b || (*b - *a).norm() < 4) return;
    const double extent = (*b - *a).norm();
    const Eigen::Vector2d t = (*b - *a) / extent, n(-t.y(), t.x());
    // The box: the distorted projection of the stick, sampled along it.
    double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;
    for (int i = 0; i <= 16; ++i) {
      const auto p = cam.Project(frog_p + (tip_p - frog_p) * (i / 16.0));
      if (!p) continue;
      x0 = std::min(x0, p->x());
      y0 = std::min(y0, p->y());
      x1 = std::max(x1, p->x());
      y1 = std::max(y1, p->y());
    }
    const double m = options.roi_margin_px;
    const cv::Rect box =
        cv::Rect(
            cv::Point(static_cast<int>(std::floor(x0 - m)), static_cast<int>(std::floor(y0 - m))),
            cv::Point(static_cast<int>(std::ceil(x1 + m)), static_cast<int>(std::ceil(y1 + m)))) &
        cv::Rect(0, 0, image.cols, image.rows);
    if (box.width < 8 || box.height < 8) return;
    const cv::Ptr<cv::LineSegmentDetector> lsd = cv::createLineSegmentDetector(cv::LSD_REFINE_STD);
    std::vector<cv::Vec4f> lines;
    lsd->detect(image(box).clone(), lines);
    const double sin_gate = std::sin(options.max_angle_deg * M_PI / 180);
    for (const cv::Vec4f& l : lines) {
      // LSD's coordinates put pixel centres at .5.
      const Eigen::Vector2d p(l[0] + box.x - 0.5, l[1] + box.y - 0.5);
      const Eigen::Vector2d q(l[2] + box.x - 0.5, l[3] + box.y - 0.5);
      if ((q - p).norm() < options.min_segment_px) continue;
      StickSegment s;
      s.a = cam.UndistortPixel(p);
      s.b = cam.UndistortPixel(q);
      s.length = (s.b - s.a).norm();
      if (s.length < options.min_segment_px) continue;
      const Eigen::Vector2d u = (s.b - s.a) / s.length;
      if (std::abs(u.x() * t.y() - u.y() * t.x()) > sin_gate) continue;
      if (std::abs(n.dot(s.a - *a)) > options.search_px ||
          std::abs(n.dot(s.b - *a)) > options.search_px)
        continue;
      const double mid = t.dot(0.5 * (s.a + s.b) - *a);
      if (mid < -0.1 * extent || mid > 1.1 * extent) continue;
      view.segments.push_back(s);
    }
  }

  // The distorted pixel of an ideal one.
  static Eigen::Vector2d Distorted(const Camera& cam, const Eigen::Vector2d& ideal) {
    const double y = (ideal.y() - cam.cy) / cam.fy;
    const double x = (ideal.x() - cam.cx - cam.skew * y) / cam.fx;
    double xd = 0, yd = 0;
    cam.Distort(x, y, &xd, &yd);
    return Eigen::Vector2d(cam.fx * xd + cam.skew * yd + cam.cx, cam.fy * yd + cam.cy);
  }

  // The pixel of world point x moved across onto the view's fitted line (ideal
  // point/direction); nullopt behind the camera.
  static std::optional<Eigen::Vector2d> OnLine(const Camera& cam,
                                               const Eigen::Vector3d& x,
                                               const Eigen::Vector2d& point,
                                               const Eigen::Vector2d& direction) {
    const auto ideal = IdealPixel(cam, x);
    if (!ideal) return std::nullopt;
    return Distorted(cam, point + direction * direction.dot(*ideal - point));
  }

  // Intensities along the view's fitted line at the image positions of origin + u d
  // (u = start, start + 1, ... mm) moved onto the line; the mean of three pixels across.
  void LineProfile(const View& view,
                   const cv::Mat& image,
                   const Eigen::Vector2d& point,
                   const Eigen::Vector2d& direction,
                   const Eigen::Vector3d& origin,
                   const Eigen::Vector3d& d,
                   double start,
                   int count,
                   std::vector<double>* out) const {
    out->assign(count, kNaN);
    for (int k = 0; k < count; ++k) {
      const auto p = OnLine(view.camera, origin + (start + k) * d, point, direction);
      const auto q = OnLine(view.camera, origin + (start + k + 1) * d, point, direction);
      if (!p || !q || (*q - *p).norm() < 1e-6) continue;
      const Eigen::Vector2d t = (*q - *p).normalized();
      const Eigen::Vector2d n(-t.y(), t.x());
      double sum = 0;
      bool ok = true;
      for (int j = -1; j <= 1 && ok; ++j) {
        const double s = Sample(image, *p + j * n);
        ok = std::isfinite(s);
        sum += s;
      }
      if (ok) (*out)[k] = sum / 3;
    }
  }

  struct Refined {
    bool ok = false;
    Eigen::Vector3d frog, tip;
    double ncc = 0;
  };

  // Step 4 (bow_pose_solver.h): the pose from all views at once, from the prediction and
  // from step 3's estimate (`first`), coarse to fine; the lower final cost wins. The terms
  // depend on the prediction only, so both starts solve the same problem. ok: the
  // texture at the result matches the labelled frame's (NCC >= min_ncc) in two views.
  Refined Refine(const std::vector<cv::Mat>& images,
                 const std::vector<Eigen::Vector2d>& line_point,
                 const std::vector<Eigen::Vector2d>& line_direction,
                 const std::vector<double>& line_weight,
                 const Eigen::Vector3d& frog_p,
                 const Eigen::Vector3d& tip_p,
                 const std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& first,
                 const std::optional<Eigen::Vector3d>& hand,
                 bool motion_prior) {
    const int n = static_cast<int>(views.size());
    std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> sticks{{frog_p, tip_p}};
    if (first) sticks.push_back(*first);
    const std::vector<double> sigmas = BlurSigmas();
    ParallelFor(
        n,
        options.num_threads,
        [&](int64_t v, int) {
          View& view = views[v];
          view.blurred.clear();
          view.box = cv::Rect();
          if (images[v].empty()) return;
          view.box = RefineBox(view, sticks, images[v]);
          if (view.box.empty()) return;
          for (const double sigma : sigmas)
            view.blurred.push_back(Blurred(images[v], view.box, sigma));
        },
        1);
    const Eigen::Vector3d d_p = (tip_p - frog_p).normalized();
    std::vector<std::vector<BowViewTerms>> terms(sigmas.size());
    for (size_t l = 0; l < sigmas.size(); ++l)
      for (int v = 0; v < n; ++v) {
        const View& view = views[v];
        BowViewTerms t;
        t.camera = &view.camera;
        t.line_point = line_point[v];
        t.line_direction = line_direction[v];
        t.line_weight = line_weight[v];
        if (!view.blurred.empty()) {
          const cv::Mat& b = view.blurred[l];
          t.image = b.ptr<float>(0);
          t.rows = b.rows;
          t.cols = b.cols;
          t.x0 = view.box.x;
          t.y0 = view.box.y;
          // Samples seen in the labelled frame and, at the prediction, inside the box.
          const std::vector<double> at_prediction =
              SampleStick(view.camera, t.image, t.rows, t.cols, t.x0, t.y0, frog_p, d_p, u);
          for (size_t k = 0; k < u.size(); ++k) {
            if (!std::isfinite(view.label_values[l][k]) || !std::isfinite(at_prediction[k]))
              continue;
            t.u.push_back(u[k]);
            t.value.push_back(view.label_values[l][k]);
          }
          if (t.u.size() < u.size() / 4) {
            t.image = nullptr;
            t.u.clear();
            t.value.clear();
          }
        }
        terms[l].push_back(std::move(t));
      }
    std::vector<BowPointPrior> priors;
    if (motion_prior) {
      priors.push_back({0, frog_p, options.motion_sigma_mm});
      priors.push_back({length, tip_p, options.motion_sigma_mm});
    }
    if (hand) priors.push_back({0, *hand, options.hand_sigma_mm});
    BowSolveOptions so;
    so.line_sigma_px = options.line_sigma_px;
    so.intensity_sigma = options.intensity_sigma;
    std::optional<BowPose> best;
    for (const auto& [f, t] : sticks) {
      BowPose pose;
      pose.frog = f;
      pose.direction = (t - f).normalized();
      for (size_t l = 0; l < sigmas.size(); ++l) {
        pose = SolveBowPose(terms[l], priors, length, pose, so);
        if (!pose.usable) break;
      }
      if (pose.usable && (!best || pose.cost < best->cost)) best = pose;
    }
    Refined out;
    if (!best) return out;
    out.frog = best->frog;
    out.tip = best->frog + length * best->direction;
    // The check: the fine level's texture at the result against the labelled frame's.
    double sum = 0;
    int matched = 0;
    for (int v = 0; v < n; ++v) {
      const BowViewTerms& t = terms.back()[v];
      if (t.image == nullptr) continue;
      const std::vector<double> now = SampleStick(
          views[v].camera, t.image, t.rows, t.cols, t.x0, t.y0, out.frog, best->direction, u);
      std::vector<double> a, b;
      for (size_t k = 0; k < u.size(); ++k) {
        if (!std::isfinite(now[k]) || !std::isfinite(views[v].label_values.back()[k])) continue;
        a.push_back(views[v].label_values.back()[k]);
        b.push_back(now[k]);
      }
      int count = 0;
      const double c = Ncc(a, b, 0, &count);
      if (count >= static_cast<int>(u.size() / 4) && c >= options.min_ncc) {
        sum += c;
        ++matched;
      }
    }
    out.ok = matched >= 2;
    out.ncc = matched > 0 ? sum / matched : 0;
    return out;
  }

  TrackFrame Output(bool ok, double ncc) {
    TrackFrame r;
    r.pose_ok = ok;
    r.match_ncc = ncc;
    const Eigen::Vector3d d = (tip - frog).normalized();
    r.world_from_template.rotation = Eigen::Quaterniond::FromTwoVectors(direction0, d);
    r.world_from_template.translation = frog - r.world_from_template.rotation * frog0;
    double residual2 = 0;
    for (View& v : views) {
      ViewTrackReport& report = v.report;
      report.tracked = static_cast<int>(v.segments.size());
      report.inliers = 0;
      double sum2 = 0;
      for (const StickSegment& s : v.segments) {
        if (s.residual_px > 3 * options.huber_px) continue;
        ++report.inliers;
        sum2 += s.residual_px * s.residual_px;
      }
      report.residual_px = report.inliers > 0 ? std::sqrt(sum2 / report.inliers) : 0;
      r.inliers += report.inliers;
      residual2 += sum2;
      r.views.push_back(report);
      std::vector<TrackedPoint> points(2);
      for (int i = 0; i < 2; ++i) {
        const auto px = v.camera.Project(i == 0 ? frog : tip);
        if (!px) continue;
        points[i].pixel = *px;
        double score = ok ? std::clamp(ncc, 0.0, 1.0) : 0.1;
        if (report.lost) score *= 0.6;
        if (px->x() < -0.5 || px->y() < -0.5 || px->x() > v.camera.width - 0.5 ||
            px->y() > v.camera.height - 0.5)
          score *= 0.2;
        points[i].score = score;
      }
      r.points.push_back(points);
    }
    r.residual_px = r.inliers > 0 ? std::sqrt(residual2 / r.inliers) : 0;
    return r;
  }
};

BowTracker::BowTracker(std::vector<Camera> cameras,
                       const Eigen::Vector3d& frog,
                       const Eigen::Vector3d& tip,
                       const BowTrackerOptions& options)
    : state_(std::make_unique<State>()) {
  const Status s = options.Validate();
  if (!s.ok()) throw std::invalid_argument("BowTracker: " + s.message());
  if (!frog.allFinite() || !tip.allFinite() || (tip - frog).norm() < kMinBowLengthMm) {
    throw std::invalid_argument(
        "BowTracker: frog and tip must be finite and >= kMinBowLengthMm (50 mm) apart");
  }
  State& st = *state_;
  st.options = options;
  st.frog = st.frog0 = frog;
  st.tip = tip;
  st.length = (tip - frog).norm();
  st.direction0 = (tip - frog) / st.length;
  st.margin = static_cast<int>(std::ceil(st.options.profile_margin * st.length));
  st.slide = static_cast<int>(std::ceil(options.slide_search_mm));
  st.samples = static_cast<int>(std::floor(st.length)) + 1 + 2 * st.margin;
  for (double u = 0; u <= st.length + 1e-9; u += options.sample_step_mm) st.u.push_back(u);
  for (Camera& c : cameras) {
    View v;
    v.camera = std::move(c);
    st.views.push_back(std::move(v));
  }
}

BowTracker::~BowTracker() = default;
BowTracker::BowTracker(BowTracker&&) noexcept = default;

TrackFrame BowTracker::Start(const std::vector<const media::Image*>& frames,
                             const std::vector<Eigen::Vector2d>* right_hand) {
  State& st = *state_;
  st.hand_along = 0;
  st.hand_across = Eigen::Vector3d::Zero();
  if (right_hand != nullptr) {
    if (const auto hand = TriangulateRays(st.views, *right_hand)) {
      st.hand_along = (*hand - st.frog0).dot(st.direction0);
      st.hand_across = *hand - st.frog0 - st.hand_along * st.direction0;
    }
  }
  const int n = static_cast<int>(st.views.size());
  ParallelFor(
      n,
      st.options.num_threads,
      [&](int64_t v, int) {
        View& view = st.views[v];
        view.label_image = AsMat(*frames[v]).clone();
        st.Profile(
            view, view.label_image, st.frog0, st.direction0, -st.margin, st.samples, &view.profile);
        view.label_values.clear();
        const cv::Rect all(0, 0, view.label_image.cols, view.label_image.rows);
        for (const double sigma : st.BlurSigmas()) {
          const cv::Mat b = State::Blurred(view.label_image, all, sigma);
          view.label_values.push_back(SampleStick(
              view.camera, b.ptr<float>(0), b.rows, b.cols, 0, 0, st.frog0, st.direction0, st.u));
        }
      },
      1);
  return st.Output(true, 1);
}

TrackFrame BowTracker::Next(const std::vector<const media::Image*>& frames,
                            const std::vector<std::vector<Eigen::Vector2d>>* labels,
                            const std::vector<Eigen::Vector2d>* right_hand) {
  State& st = *state_;
  const int n = static_cast<int>(st.views.size());
  Eigen::Vector3d frog_p = st.frog + st.frog_velocity;
  Eigen::Vector3d tip_p = st.tip + st.tip_velocity;
  // The right hand holds the frog: seen in two views, it re-places a prediction that
  // went astray (or follows a lost frame) and is a prior on the frog below.
  std::optional<Eigen::Vector3d> hand;
  bool moved_to_hand = false;  // then the motion prior is no prior: left out
  if (right_hand != nullptr) hand = TriangulateRays(st.views, *right_hand);
  if (hand) {
    // The frog the hand implies, at its labelled-frame offset along the predicted axis.
    const Eigen::Vector3d d = (tip_p - frog_p).normalized();
    *hand -= st.hand_along * d + st.hand_across;
    if (!st.last_ok || (frog_p - *hand).norm() > st.options.hand_reacquire_mm) {
      tip_p += *hand - frog_p;
      frog_p = *hand;
      moved_to_hand = true;
    }
  }
  std::vector<cv::Mat> images(n);
  for (int v = 0; v < n; ++v)
    if (frames[v] != nullptr) images[v] = AsMat(*frames[v]);
  ParallelFor(
      n,
      st.options.num_threads,
      [&](int64_t v, int) {
        View& view = st.views[v];
        view.segments.clear();
        if (!images[v].empty()) st.FindSegments(view, images[v], frog_p, tip_p);
      },
      1);
  for (View& v : st.views) {
    const bool lost = v.segments.empty();
    v.report = ViewTrackReport{};
    v.report.lost = lost;
    v.report.reacquired = v.lost && !lost;
    v.lost = lost;
  }
  bool ok = false;
  double ncc = 0;
  Eigen::Vector3d frog = frog_p, tip = tip_p;
  // Per view: the stick's line, then where along it the labelled frame's profile
  // matches best (a slide in mm along the predicted axis); frog and tip are then
  // triangulated from the views' matches. Lines alone would not do: with cameras around
  // the player, a bow lying across the rig's baselines gives planes that all but
  // coincide (its depth is then unknown).
  std::vector<Eigen::Vector2d> line_point(n), line_direction(n);
  std::vector<char> has_line(n, 0);
  std::vector<double> line_weight(n, 0);
  for (int v = 0; v < n; ++v)
    has_line[v] =
        FitStickLine(&st.views[v].segments, &line_point[v], &line_direction[v], &line_weight[v]);
  // Per view: the profile's best shift (+-slide_search_mm around the prediction).
  const int range = st.slide;
  std::vector<double> view_ncc(n, 0), view_shift(n, 0);
  const Eigen::Vector3d d_p = (tip_p - frog_p).normalized();
  ParallelFor(
      n,
      st.options.num_threads,
      [&](int64_t v, int) {
        View& view = st.views[v];
        view.current.clear();
        if (images[v].empty() || !has_line[v]) return;
        st.LineProfile(view,
                       images[v],
                       line_point[v],
                       line_direction[v],
                       frog_p,
                       d_p,
                       -st.margin - range,
                       st.samples + 2 * range,
                       &view.current);
        std::vector<double> score(2 * range + 1, -2);
        for (int s = -range; s <= range; ++s) {
          int count = 0;
          const double c = Ncc(view.profile, view.current, s + range, &count);
          if (count >= st.samples / 4) score[s + range] = c;
        }
        const int best =
            static_cast<int>(std::max_element(score.begin(), score.end()) - score.begin());
        double shift = best - range;
        if (best > 0 && best + 1 < static_cast<int>(score.size())) {
          // Sub-millimetre: the parabola through the peak and its neighbours.
          const double l = score[best - 1], c = score[best], r = score[best + 1];
          const double denom = l - 2 * c + r;
          if (denom < 0) shift += std::clamp(0.5 * (l - r) / denom, -0.5, 0.5);
        }
        view_ncc[v] = score[best];
        view_shift[v] = shift;
      },
      1);
  // Frog and tip triangulated from the views that matched (least squares on the rays,
  // weighted by the match), then put the bow's length apart about their middle.
  std::vector<char> use(n, 0);
  double ncc_sum = 0;
  int matched = 0;
  for (int v = 0; v < n; ++v) {
    use[v] = has_line[v] && view_ncc[v] >= st.options.min_ncc;
    if (use[v]) {
      ncc_sum += view_ncc[v];
      ++matched;
    }
  }
  const auto triangulate = [&](const Eigen::Vector3d& predicted, Eigen::Vector3d* out) {
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    int used = 0;
    for (int v = 0; v < n; ++v) {
      if (!use[v]) continue;
      const View& view = st.views[v];
      const auto px = State::OnLine(
          view.camera, predicted + view_shift[v] * d_p, line_point[v], line_direction[v]);
      if (!px) continue;
      const Eigen::Vector3d r = view.camera.RayInWorld(*px);
      const Eigen::Matrix3d m = view_ncc[v] * (Eigen::Matrix3d::Identity() - r * r.transpose());
      a += m;
      b += m * view.camera.CenterInWorld();
      ++used;
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(a);
    if (used < 2 || !(eig.eigenvalues()(0) > 1e-4 * eig.eigenvalues()(2))) return false;
    *out = a.ldlt().solve(b);
    return out->allFinite();
  };
  Eigen::Vector3d f3, t3;
  if (matched >= 2 && triangulate(frog_p, &f3) && triangulate(tip_p, &t3)) {
    const Eigen::Vector3d centre = 0.5 * (f3 + t3), d = (t3 - f3).normalized();
    frog = centre - 0.5 * st.length * d;
    tip = centre + 0.5 * st.length * d;
    ok = true;
    ncc = ncc_sum / matched;
  }
  if (st.options.refine) {
    const auto refined = st.Refine(
        images,
        line_point,
        line_direction,
        line_weight,
        frog_p,
        tip_p,
        ok ? std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>>(std::make_pair(frog, tip))
           : std::nullopt,
        hand,
        !moved_to_hand);
    if (refined.ok) {
      frog = refined.frog;
      tip = refined.tip;
      ok = true;
      ncc = refined.ncc;
    } else {
      ok = false;
      frog = frog_p;
      tip = tip_p;
    }
  }
  // Labels of this frame (two views) override the estimate.
  if (labels != nullptr) {
    FrameLabels l{{"frog", "tip"}, *labels};
    std::vector<Camera> cams;
    for (const View& v : st.views) cams.push_back(v.camera);
    auto labelled = TriangulateTemplate(cams, l, 10, /*thin=*/true);
    if (labelled.ok() && labelled->points[0].allFinite() && labelled->points[1].allFinite()) {
      frog = labelled->points[0];
      tip = frog + st.length * (labelled->points[1] - frog).normalized();
      ok = true;
      ncc = 1;
    }
  }
  if (ok) {
    st.frog_velocity = frog - st.frog;
    st.tip_velocity = tip - st.tip;
  } else {
    // Not found: coast on half the velocity.
    st.frog_velocity *= 0.5;
    st.tip_velocity *= 0.5;
  }
  st.frog = frog;
  st.tip = tip;
  st.last_ok = ok;
  return st.Output(ok, ncc);
}

}  // namespace arco::track
