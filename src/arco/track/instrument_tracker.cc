#include "arco/track/instrument_tracker.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <stdexcept>

#include "arco/mocap/triangulate_point.h"
#include "arco/track/one_view_pnp.h"
#include "arco/util/number_range.h"
#include "arco/util/parallel.h"

namespace arco::track {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// A Gray8 image as a cv::Mat header (no copy).
cv::Mat AsMat(const media::Image& image) {
  if (image.format != media::PixelFormat::kGray8) {
    throw std::invalid_argument("InstrumentTracker: frames must be gray8");
  }
  return cv::Mat(image.height, image.width, CV_8UC1, const_cast<uint8_t*>(image.pixels.data()));
}

bool Inside(const cv::Mat& image, const Eigen::Vector2d& p, double margin) {
  return p.x() >= margin && p.y() >= margin && p.x() <= image.cols - 1 - margin &&
         p.y() <= image.rows - 1 - margin;
}

struct Feature {
  Eigen::Vector3d in_template;
  Eigen::Vector2d pixel;
  int anchor = -1;  // the anchor it came from, -1 for a Lucas-Kanade corner
};

struct Anchor {
  Eigen::Vector3d in_template;
  Eigen::Vector2d label_pixel;
};

struct View {
  Camera camera;
  cv::Mat label_image;  // the labelled frame (owned copy), for the anchors' patches
  cv::Mat previous;     // owned copy of the previous frame
  std::vector<Feature> features;
  std::vector<Anchor> anchors;
  bool lost = false;
  ViewTrackReport report;
};

}  // namespace

struct InstrumentTracker::State {
  InstrumentTrackerOptions options;
  RigidTemplate body;
  std::vector<View> views;
  std::vector<Eigen::Vector3d> known_points;  // the template's finite points
  Rigid3d pose, previous_pose;
  int frames = 0;

  // Ray of `pixel` in view v meets the body's plane at `pose`: the template point.
  std::optional<Eigen::Vector3d> BackProject(int v,
                                             const Eigen::Vector2d& pixel,
                                             const Rigid3d& at) const {
    const Camera& cam = views[v].camera;
    const Eigen::Vector3d centre = cam.CenterInWorld();
    const Eigen::Vector3d ray = cam.RayInWorld(pixel);
    const Eigen::Vector3d normal = at.rotation * body.plane_normal;
    const Eigen::Vector3d point = at * body.plane_point;
    const double denom = normal.dot(ray);
    if (std::abs(denom) < 0.1) return std::nullopt;  // grazing
    const double s = normal.dot(point - centre) / denom;
    if (!(s > 0)) return std::nullopt;
    return at.Inverse() * (centre + s * ray);
  }

  // The projected outline of the body at `at` in view v, grown by the margin; empty when
  // fewer than three points project.
  std::vector<cv::Point> Outline(int v, const Rigid3d& at) const {
    std::vector<cv::Point2f> points;
    const double m = options.outline_margin_px;
    for (const auto& x : known_points) {
      const auto p = views[v].camera.Project(at * x);
      if (!p) continue;
      for (int k = 0; k < 8; ++k) {
        const double a = k * M_PI / 4;
        points.emplace_back(static_cast<float>(p->x() + m * std::cos(a)),
                            static_cast<float>(p->y() + m * std::sin(a)));
      }
    }
    std::vector<cv::Point> hull;
    if (points.size() < 2 * 8) return hull;
    std::vector<cv::Point2f> h;
    cv::convexHull(points, h);
    for (const auto& q : h) hull.emplace_back(cvRound(q.x), cvRound(q.y));
    return hull;
  }

  // Corners inside the outline at `at`, away from the view's features; appended with
  // their template points. Returns the number added.
  int AddCorners(int v, const cv::Mat& image, const Rigid3d& at, int wanted, bool anchors) {
    View& view = views[v];
    const std::vector<cv::Point> hull = Outline(v, at);
    if (hull.empty() || wanted <= 0) return 0;
    cv::Rect box = cv::boundingRect(hull) & cv::Rect(0, 0, image.cols, image.rows);
    if (box.width < 8 || box.height < 8) return 0;
    cv::Mat mask = cv::Mat::zeros(box.size(), CV_8UC1);
    std::vector<cv::Point> shifted;
    for (const auto& p : hull) shifted.emplace_back(p.x - box.x, p.y - box.y);
    cv::fillConvexPoly(mask, shifted, cv::Scalar(255));
    const int r = static_cast<int>(std::ceil(options.min_feature_distance_px));
    for (const Feature& f : view.features) {
      cv::circle(mask,
                 cv::Point(cvRound(f.pixel.x()) - box.x, cvRound(f.pixel.y()) - box.y),
                 r,
                 cv::Scalar(0),
                 -1);
    }
    std::vector<cv::Point2f> corners;
    cv::goodFeaturesToTrack(image(box),
                            corners,
                            wanted,
                            options.corner_quality,
                            options.min_feature_distance_px,
                            mask,
                            5);
    int added = 0;
    for (const auto& c : corners) {
      const Eigen::Vector2d px(c.x + box.x, c.y + box.y);
      const auto x = BackProject(v, px, at);
      if (!x) continue;
      view.features.push_back({*x, px, -1});
      if (anchors && static_cast<int>(view.anchors.size()) < options.anchors_per_view) {
        view.anchors.push_back({*x, px});
      }
      ++added;
    }
    return added;
  }

  // Lucas-Kanade from the previous frame with the forward-backward check.
  // `prediction`: the body's predicted pose; each feature starts where the prediction
  // moves it (its offset from its projection kept), so a fast body (the bow) needs only
  // a small correction from Lucas-Kanade.
  void Flow(int v, const cv::Mat& image, const Rigid3d& prediction) {
    View& view = views[v];
    // No picture (a dropped frame, a camera not started yet): the features wait for the
    // next one.
    if (view.features.empty() || image.empty()) return;
    std::vector<cv::Point2f> from, to, back;
    for (const Feature& f : view.features) {
      from.emplace_back(static_cast<float>(f.pixel.x()), static_cast<float>(f.pixel.y()));
      Eigen::Vector2d start = f.pixel;
      const auto was = view.camera.Project(pose * f.in_template);
      const auto will = view.camera.Project(prediction * f.in_template);
      if (was && will) start += *will - *was;
      to.emplace_back(static_cast<float>(start.x()), static_cast<float>(start.y()));
    }
    back = from;
    std::vector<uchar> ok_forward, ok_backward;
    std::vector<float> err;
    const cv::Size window(options.lk_window_px, options.lk_window_px);
    const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
    cv::calcOpticalFlowPyrLK(view.previous,
                             image,
                             from,
                             to,
                             ok_forward,
                             err,
                             window,
                             options.lk_levels,
                             stop,
                             cv::OPTFLOW_USE_INITIAL_FLOW);
    // Backwards from scratch: the check must not start where it should end.
    cv::calcOpticalFlowPyrLK(
        image, view.previous, to, back, ok_backward, err, window, options.lk_levels, stop);
    std::vector<Feature> kept;
    for (size_t i = 0; i < from.size(); ++i) {
      if (!ok_forward[i] || !ok_backward[i]) continue;
      const double fb = std::hypot(back[i].x - from[i].x, back[i].y - from[i].y);
      const Eigen::Vector2d p(to[i].x, to[i].y);
      if (!(fb <= options.max_forward_backward_px) || !Inside(image, p, 1)) continue;
      Feature f = view.features[i];
      f.pixel = p;
      kept.push_back(f);
    }
    view.features = std::move(kept);
  }

  // Anchors re-matched by NCC around their prediction at `at`: appended to `matches`.
  void Rematch(int v, const cv::Mat& image, const Rigid3d& at, std::vector<Feature>* matches) {
    View& view = views[v];
    const int s = options.ncc_patch_px, r = options.ncc_search_px;
    const double c = (s - 1) / 2.0;
    const double h = 4;
    for (size_t a = 0; a < view.anchors.size(); ++a) {
      const Anchor& anchor = view.anchors[a];
      const auto q = view.camera.Project(at * anchor.in_template);
      if (!q || !Inside(image, *q, c + r + 2)) continue;
      // The local affine map labelled image -> current image, through the body's plane.
      const auto x1 = BackProject(v, anchor.label_pixel + Eigen::Vector2d(h, 0), Rigid3d());
      const auto x2 = BackProject(v, anchor.label_pixel + Eigen::Vector2d(0, h), Rigid3d());
      if (!x1 || !x2) continue;
      const auto q1 = view.camera.Project(at * *x1);
      const auto q2 = view.camera.Project(at * *x2);
      if (!q1 || !q2) continue;
      Eigen::Matrix2d A;
      A.col(0) = (*q1 - *q) / h;
      A.col(1) = (*q2 - *q) / h;
      if (std::abs(A.determinant()) < 0.05) continue;
      const Eigen::Matrix2d Ai = A.inverse();
      // dst -> src: src = label + Ai (dst - c).
      const Eigen::Vector2d t = anchor.label_pixel - Ai * Eigen::Vector2d(c, c);
      const cv::Matx23d M(Ai(0, 0), Ai(0, 1), t.x(), Ai(1, 0), Ai(1, 1), t.y());
      cv::Mat patch;
      cv::warpAffine(view.label_image,
                     patch,
                     M,
                     cv::Size(s, s),
                     cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                     cv::BORDER_REPLICATE);
      cv::Scalar mean, stddev;
      cv::meanStdDev(patch, mean, stddev);
      if (stddev[0] < 4) continue;  // too flat to match
      const int x0 = static_cast<int>(std::lround(q->x() - c)) - r;
      const int y0 = static_cast<int>(std::lround(q->y() - c)) - r;
      const cv::Rect roi(x0, y0, s + 2 * r, s + 2 * r);
      if ((roi & cv::Rect(0, 0, image.cols, image.rows)) != roi) continue;
      cv::Mat score;
      cv::matchTemplate(image(roi), patch, score, cv::TM_CCOEFF_NORMED);
      double best;
      cv::Point at_best;
      cv::minMaxLoc(score, nullptr, &best, nullptr, &at_best);
      if (best < options.min_ncc) continue;
      if (at_best.x == 0 || at_best.y == 0 || at_best.x == score.cols - 1 ||
          at_best.y == score.rows - 1) {
        continue;  // on the border of the search: no peak
      }
      const auto vertex = [](float m, float z, float p) {
        const float d = m - 2 * z + p;
        return d < 0 ? 0.5 * (m - p) / d : 0.0;
      };
      const float* row = score.ptr<float>(at_best.y);
      const double dx = vertex(row[at_best.x - 1], row[at_best.x], row[at_best.x + 1]);
      const double dy = vertex(score.at<float>(at_best.y - 1, at_best.x),
                               row[at_best.x],
                               score.at<float>(at_best.y + 1, at_best.x));
      const Eigen::Vector2d found(x0 + at_best.x + c + dx, y0 + at_best.y + c + dy);
      matches->push_back({anchor.in_template, found, static_cast<int>(a)});
    }
  }

  std::vector<PoseCorrespondence> Correspondences(const std::vector<std::vector<Feature>>& extra,
                                                  const std::vector<cv::Mat>& images) {
    std::vector<PoseCorrespondence> c;
    for (size_t v = 0; v < views.size(); ++v) {
      if (images[v].empty()) continue;  // no frame: its features are from an older one
      for (const Feature& f : views[v].features) {
        c.push_back({static_cast<int>(v), f.in_template, f.pixel, 1.0});
      }
      for (const Feature& f : extra[v]) {
        c.push_back({static_cast<int>(v), f.in_template, f.pixel, options.anchor_weight});
      }
    }
    return c;
  }

  TrackFrame Result(bool pose_ok, int inliers, double residual) {
    TrackFrame out;
    out.pose_ok = pose_ok;
    out.world_from_template = pose;
    out.inliers = inliers;
    out.residual_px = residual;
    const double pose_score = pose_ok ? 1.0 / (1.0 + std::pow(residual / 2.0, 2)) : 0.1;
    for (View& view : views) {
      out.views.push_back(view.report);
      std::vector<TrackedPoint> points(body.points.size());
      for (size_t p = 0; p < body.points.size(); ++p) {
        if (!std::isfinite(body.points[p].x())) continue;
        const auto q = view.camera.Project(pose * body.points[p]);
        if (!q) continue;
        points[p].pixel = *q;
        double s = pose_score * (view.report.lost ? 0.6 : 1.0);
        if (!InImage(view.camera, *q)) s *= 0.2;
        points[p].score = std::max(0.01, std::min(1.0, s));
      }
      out.points.push_back(std::move(points));
    }
    return out;
  }

  static bool InImage(const Camera& c, const Eigen::Vector2d& p) {
    return p.x() >= -0.5 && p.y() >= -0.5 && p.x() < c.width - 0.5 && p.y() < c.height - 0.5;
  }
};

Status InstrumentTrackerOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(
      CheckInRange("max_features_per_view", max_features_per_view, Closed(8, 5000)));
  ARCO_RETURN_IF_ERROR(
      CheckInRange("min_feature_distance_px", min_feature_distance_px, Closed(1, 200)));
  ARCO_RETURN_IF_ERROR(CheckInRange("corner_quality", corner_quality, AboveZero(1)));
  ARCO_RETURN_IF_ERROR(CheckInRange("lk_window_px", lk_window_px, Closed(5, 101)));
  if (lk_window_px % 2 == 0) return Status::Error("lk_window_px must be odd");
  ARCO_RETURN_IF_ERROR(CheckInRange("lk_levels", lk_levels, Closed(0, 8)));
  ARCO_RETURN_IF_ERROR(
      CheckInRange("max_forward_backward_px", max_forward_backward_px, AboveZero(100)));
  ARCO_RETURN_IF_ERROR(CheckInRange("outline_margin_px", outline_margin_px, Closed(0, 1000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("replenish_below", replenish_below, Closed(0, 1)));
  ARCO_RETURN_IF_ERROR(CheckInRange("keyframe_interval", keyframe_interval, Closed(0, 100000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("anchors_per_view", anchors_per_view, Closed(0, 5000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("ncc_patch_px", ncc_patch_px, Closed(5, 101)));
  if (ncc_patch_px % 2 == 0) return Status::Error("ncc_patch_px must be odd");
  ARCO_RETURN_IF_ERROR(CheckInRange("ncc_search_px", ncc_search_px, Closed(1, 200)));
  ARCO_RETURN_IF_ERROR(CheckInRange("min_ncc", min_ncc, Closed(-1, 1)));
  ARCO_RETURN_IF_ERROR(CheckInRange("anchor_weight", anchor_weight, AboveZero(1000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("min_view_inliers", min_view_inliers, Closed(1, 1000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("num_threads", num_threads, Closed(0, 1024)));
  ARCO_RETURN_IF_ERROR(pose.Validate().WithContext("pose"));
  return Status::Ok();
}

Json ToJson(const InstrumentTrackerOptions& o) {
  return Json{{"max_features_per_view", o.max_features_per_view},
              {"min_feature_distance_px", o.min_feature_distance_px},
              {"corner_quality", o.corner_quality},
              {"lk_window_px", o.lk_window_px},
              {"lk_levels", o.lk_levels},
              {"max_forward_backward_px", o.max_forward_backward_px},
              {"outline_margin_px", o.outline_margin_px},
              {"replenish_below", o.replenish_below},
              {"keyframe_interval", o.keyframe_interval},
              {"anchors_per_view", o.anchors_per_view},
              {"ncc_patch_px", o.ncc_patch_px},
              {"ncc_search_px", o.ncc_search_px},
              {"min_ncc", o.min_ncc},
              {"anchor_weight", o.anchor_weight},
              {"min_view_inliers", o.min_view_inliers},
              {"pose",
               {{"inlier_px", o.pose.inlier_px},
                {"ransac_trials", o.pose.ransac_trials},
                {"sample_size", o.pose.sample_size},
                {"loss_scale_px", o.pose.loss_scale_px},
                {"max_iterations", o.pose.max_iterations},
                {"prior_weight", o.pose.prior_weight},
                {"seed", o.pose.seed}}}};
}

namespace {

// The plane that fits a template's points best (least squares): features get their
// template coordinates where their ray cuts it.
Status FitTemplatePlane(const std::vector<Eigen::Vector3d>& known, RigidTemplate* body) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& x : known) mean += x;
  mean /= static_cast<double>(known.size());
  Eigen::MatrixXd centred(known.size(), 3);
  for (size_t i = 0; i < known.size(); ++i) centred.row(i) = (known[i] - mean).transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeFullV);
  if (svd.singularValues()(1) < 1e-6 * std::max(1.0, svd.singularValues()(0))) {
    return Status::Error("the labelled points lie on a line: no plane for the features");
  }
  body->plane_point = mean;
  body->plane_normal = svd.matrixV().col(2).normalized();
  return Status::Ok();
}

}  // namespace

StatusOr<RigidTemplate> TriangulateTemplate(const std::vector<Camera>& cameras,
                                            const FrameLabels& labels,
                                            double max_label_error_px,
                                            bool thin) {
  const int views = static_cast<int>(cameras.size());
  if (static_cast<int>(labels.pixels.size()) != views) {
    throw std::invalid_argument("TriangulateTemplate: labels for " +
                                std::to_string(labels.pixels.size()) + " views, " +
                                std::to_string(views) + " cameras");
  }
  int labelled_views = 0;
  for (const auto& v : labels.pixels) {
    bool any = false;
    for (const auto& p : v) any = any || std::isfinite(p.x());
    labelled_views += any;
  }
  if (labelled_views < 2) {
    return Status::Error("labels in " + std::to_string(labelled_views) +
                         " view(s): at least two views are needed");
  }
  Rig rig;
  rig.cameras = cameras;
  TriangulationOptions t;
  t.max_reprojection_px = max_label_error_px;
  t.min_score = 0;
  const Triangulator triangulator(rig, t);
  RigidTemplate body;
  body.point_names = labels.point_names;
  body.points.assign(labels.point_names.size(), Eigen::Vector3d::Constant(kNaN));
  body.label_views.assign(labels.point_names.size(), 0);
  std::vector<Eigen::Vector3d> known;
  double sum2 = 0;
  int count = 0;
  for (size_t p = 0; p < labels.point_names.size(); ++p) {
    std::vector<PointObservation> obs;
    for (int v = 0; v < views; ++v) {
      if (p < labels.pixels[v].size() && std::isfinite(labels.pixels[v][p].x())) {
        obs.push_back({v, labels.pixels[v][p], 1.0});
      }
    }
    body.label_views[p] = static_cast<int>(obs.size());
    if (obs.size() < 2) continue;
    const auto x = triangulator.Triangulate(obs);
    if (!x || x->inlier_cameras.size() < obs.size()) {
      return Status::Error("label " + labels.point_names[p] +
                           ": the views do not agree (rays miss by more than " +
                           std::to_string(max_label_error_px) + " px)");
    }
    body.points[p] = x->point_in_world;
    known.push_back(x->point_in_world);
    sum2 += x->rms_reprojection_px * x->rms_reprojection_px;
    ++count;
  }
  const size_t needed = thin ? 2 : 3;
  if (known.size() < needed) {
    return Status::Error(std::to_string(known.size()) +
                         " point(s) labelled in two views: at least " + std::to_string(needed) +
                         " are needed");
  }
  body.rms_reprojection_px = std::sqrt(sum2 / count);
  if (thin) {
    // The plane through the axis that faces the labelling cameras best.
    const Eigen::Vector3d a = known.front(), b = known.back();
    const Eigen::Vector3d axis = (b - a).normalized();
    Eigen::Vector3d towards = Eigen::Vector3d::Zero();
    for (int v = 0; v < views; ++v) {
      bool any = false;
      for (const auto& p : labels.pixels[v]) any = any || std::isfinite(p.x());
      if (any) towards += (cameras[v].CenterInWorld() - 0.5 * (a + b)).normalized();
    }
    const Eigen::Vector3d normal = towards - towards.dot(axis) * axis;
    if (!((b - a).norm() > 0) || normal.norm() < 1e-6) {
      return Status::Error("the thin body's points coincide or its axis points at the cameras");
    }
    body.plane_point = 0.5 * (a + b);
    body.plane_normal = normal.normalized();
    return body;
  }
  ARCO_RETURN_IF_ERROR(FitTemplatePlane(known, &body));
  return body;
}

StatusOr<RigidTemplate> PoseTemplateInOneView(const Camera& camera,
                                              const FrameLabels& labels,
                                              const std::vector<Eigen::Vector3d>& model_points,
                                              double max_label_error_px) {
  if (labels.pixels.size() != 1 || model_points.size() != labels.point_names.size()) {
    throw std::invalid_argument("PoseTemplateInOneView: one view and one model point per name");
  }
  const std::vector<Eigen::Vector2d>& pixels = labels.pixels[0];
  std::vector<PoseCorrespondence> c;
  std::vector<Eigen::Vector3d> object;
  std::vector<Eigen::Vector2d> undistorted;
  std::vector<size_t> label_of;  // per correspondence, its label
  for (size_t p = 0; p < labels.point_names.size() && p < pixels.size(); ++p) {
    if (!std::isfinite(pixels[p].x()) || !model_points[p].allFinite()) continue;
    label_of.push_back(p);
    c.push_back({0, model_points[p], pixels[p], 1.0});
    object.push_back(model_points[p]);
    undistorted.push_back(camera.UndistortPixel(pixels[p]));
  }
  // EPnP needs four points; a fifth makes its RANSAC choose.
  constexpr int kMinPoints = 4;
  if (static_cast<int>(c.size()) < kMinPoints) {
    return Status::Error(std::to_string(c.size()) +
                         " of the instrument's points labelled in the one view: a pose from "
                         "one view needs at least " +
                         std::to_string(kMinPoints));
  }
  Eigen::Matrix3d K;
  K << camera.fx, camera.skew, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1;
  const std::optional<OneViewPnp> pnp =
      EpnpInRansac(object, undistorted, K, max_label_error_px, kMinPoints);
  if (!pnp || !(pnp->translation.z() > 0)) {
    return Status::Error(
        "the labels do not fit the instrument's shape in one view (no pose "
        "within " +
        NumberText(max_label_error_px) + " px)");
  }
  const Eigen::Matrix3d& Rc = camera.cam_from_world.rotation;
  const Eigen::Vector3d& tc = camera.cam_from_world.translation;
  const Rigid3d start(Eigen::Matrix3d(Rc.transpose() * pnp->cam_from_object.rotation),
                      Rc.transpose() * (pnp->translation - tc));
  PoseSolverOptions refine;
  refine.inlier_px = max_label_error_px;
  refine.ransac_trials = 0;  // EPnP's RANSAC chose the start; only the refinement here
  refine.sample_size = kMinPoints;
  const std::optional<PoseSolution> solved =
      SolveRigidPose({camera}, c, start, refine, static_cast<int>(c.size()));
  if (!solved) {
    // Every label must agree, as with several views: name the one farthest from the pose
    // the others agree on.
    size_t worst = 0;
    double worst_px = -1;
    for (size_t i = 0; i < c.size(); ++i) {
      const auto seen = camera.Project(start * c[i].point_in_template);
      const double px = seen ? (*seen - c[i].pixel).norm() : kInfinity;
      if (px > worst_px) worst_px = px, worst = i;
    }
    return Status::Error("label " + labels.point_names[label_of[worst]] +
                         ": the labels do not fit the instrument's shape in one view (it is " +
                         NumberText(std::round(worst_px)) + " px from where the others put it; " +
                         NumberText(max_label_error_px) + " px at most)");
  }
  RigidTemplate body;
  body.point_names = labels.point_names;
  body.points.assign(labels.point_names.size(), Eigen::Vector3d::Constant(kNaN));
  body.label_views.assign(labels.point_names.size(), 0);
  std::vector<Eigen::Vector3d> known;
  for (size_t p = 0; p < labels.point_names.size(); ++p) {
    if (p >= pixels.size() || !std::isfinite(pixels[p].x()) || !model_points[p].allFinite())
      continue;
    body.points[p] = solved->world_from_template * model_points[p];
    body.label_views[p] = 1;
    known.push_back(body.points[p]);
  }
  body.rms_reprojection_px = solved->rms_px;
  ARCO_RETURN_IF_ERROR(FitTemplatePlane(known, &body));
  return body;
}

InstrumentTracker::InstrumentTracker(std::vector<Camera> cameras,
                                     RigidTemplate body,
                                     const InstrumentTrackerOptions& options)
    : state_(std::make_unique<State>()) {
  const Status valid = options.Validate();
  if (!valid.ok()) throw std::invalid_argument("InstrumentTrackerOptions: " + valid.message());
  state_->options = options;
  state_->body = std::move(body);
  for (const auto& x : state_->body.points)
    if (std::isfinite(x.x())) state_->known_points.push_back(x);
  if (state_->known_points.empty()) throw std::invalid_argument("InstrumentTracker: no points");
  for (auto& c : cameras) {
    View v;
    v.camera = std::move(c);
    state_->views.push_back(std::move(v));
  }
}

InstrumentTracker::~InstrumentTracker() = default;
InstrumentTracker::InstrumentTracker(InstrumentTracker&&) noexcept = default;
const RigidTemplate& InstrumentTracker::body() const { return state_->body; }

TrackFrame InstrumentTracker::Start(const std::vector<const media::Image*>& frames) {
  State& s = *state_;
  if (frames.size() != s.views.size()) throw std::invalid_argument("Start: one frame per view");
  s.pose = s.previous_pose = Rigid3d();
  s.frames = 1;
  ParallelFor(
      static_cast<int64_t>(s.views.size()),
      s.options.num_threads,
      [&](int64_t v, int) {
        View& view = s.views[v];
        const cv::Mat image = AsMat(*frames[v]);
        view.label_image = image.clone();
        view.previous = view.label_image;
        view.features.clear();
        view.anchors.clear();
        view.report = ViewTrackReport();
        view.report.added =
            s.AddCorners(static_cast<int>(v), image, s.pose, s.options.max_features_per_view, true);
        view.report.tracked = static_cast<int>(view.features.size());
        view.report.inliers = view.report.tracked;
        view.lost = view.report.lost = view.report.inliers < s.options.min_view_inliers;
      },
      1);
  int inliers = 0;
  for (const View& v : s.views) inliers += v.report.inliers;
  return s.Result(true, inliers, 0);
}

TrackFrame InstrumentTracker::Next(const std::vector<const media::Image*>& frames,
                                   const std::vector<std::vector<Eigen::Vector2d>>* labels) {
  State& s = *state_;
  if (frames.size() != s.views.size()) throw std::invalid_argument("Next: one frame per view");
  const int n = static_cast<int>(s.views.size());
  std::vector<cv::Mat> images(n);
  for (int v = 0; v < n; ++v)
    if (frames[v] != nullptr) images[v] = AsMat(*frames[v]);
  // This frame's labels, as correspondences on the template's own points.
  std::vector<PoseCorrespondence> labelled;
  if (labels != nullptr) {
    for (int v = 0; v < n && v < static_cast<int>(labels->size()); ++v) {
      for (size_t p = 0; p < (*labels)[v].size() && p < s.body.points.size(); ++p) {
        if (!std::isfinite((*labels)[v][p].x()) || !std::isfinite(s.body.points[p].x())) continue;
        labelled.push_back({v, s.body.points[p], (*labels)[v][p], 10 * s.options.anchor_weight});
      }
    }
  }
  // Constant-velocity prediction.
  const Rigid3d velocity = s.pose * s.previous_pose.Inverse();
  const Rigid3d prediction = s.frames >= 2 ? velocity * s.pose : s.pose;

  ParallelFor(
      n,
      s.options.num_threads,
      [&](int64_t v, int) {
        View& view = s.views[v];
        view.report = ViewTrackReport();
        s.Flow(static_cast<int>(v), images[v], prediction);
        view.report.tracked = static_cast<int>(view.features.size());
      },
      1);
  std::vector<std::vector<Feature>> no_extra(n);
  std::vector<PoseCorrespondence> c = s.Correspondences(no_extra, images);
  c.insert(c.end(), labelled.begin(), labelled.end());
  std::optional<PoseSolution> solved = SolveRigidPose(
      [&] {
        std::vector<Camera> cams;
        for (const View& v : s.views) cams.push_back(v.camera);
        return cams;
      }(),
      c,
      prediction,
      s.options.pose,
      6);
  Rigid3d pose = solved ? solved->world_from_template : prediction;

  // Keyframes (and after a loss): anchors re-matched, the pose solved again with them.
  bool any_lost = !solved;
  for (const View& v : s.views) any_lost = any_lost || v.lost;
  const bool keyframe =
      s.options.keyframe_interval > 0 && (s.frames % s.options.keyframe_interval == 0 || any_lost);
  std::vector<std::vector<Feature>> matches(n);
  std::vector<Camera> cams;
  for (const View& v : s.views) cams.push_back(v.camera);
  if (keyframe) {
    ParallelFor(
        n,
        s.options.num_threads,
        [&](int64_t v, int) { s.Rematch(static_cast<int>(v), images[v], pose, &matches[v]); },
        1);
    size_t total = 0;
    for (const auto& m : matches) total += m.size();
    if (total > 0) {
      c = s.Correspondences(matches, images);
      c.insert(c.end(), labelled.begin(), labelled.end());
      auto again = SolveRigidPose(cams, c, pose, s.options.pose, 6);
      if (again) {
        solved = again;
        pose = again->world_from_template;
      }
    }
  }

  // Inliers kept (per view), outliers dropped; re-matched anchors replace the features
  // near them.
  s.previous_pose = s.pose;
  s.pose = pose;
  ++s.frames;
  int total_inliers = 0;
  double total_sum2 = 0;
  ParallelFor(
      n,
      s.options.num_threads,
      [&](int64_t v, int) {
        View& view = s.views[v];
        if (images[v].empty()) {
          // No picture: the features and the last picture are kept as they were for the
          // view's next picture (Lucas-Kanade from it, the anchors when it is lost).
          view.report.tracked = 0;
          return;
        }
        const Camera& cam = view.camera;
        const double gate = s.options.pose.inlier_px;
        const auto error = [&](const Feature& f) {
          const auto p = cam.Project(pose * f.in_template);
          return p ? (*p - f.pixel).norm() : std::numeric_limits<double>::infinity();
        };
        std::vector<Feature> kept;
        double sum2 = 0;
        for (const Feature& f : matches[v]) {
          const double e = error(f);
          if (!solved || !(e < gate)) continue;
          kept.push_back(f);
          sum2 += e * e;
        }
        view.report.rematched = static_cast<int>(kept.size());
        const double d2 = s.options.min_feature_distance_px * s.options.min_feature_distance_px / 4;
        for (const Feature& f : view.features) {
          const double e = error(f);
          if (solved && !(e < gate)) continue;
          bool near_anchor = false;
          for (size_t k = 0; k < static_cast<size_t>(view.report.rematched); ++k) {
            near_anchor = near_anchor || (kept[k].pixel - f.pixel).squaredNorm() < d2 ||
                          (kept[k].anchor == f.anchor && f.anchor >= 0);
          }
          if (near_anchor) continue;
          kept.push_back(f);
          if (solved) sum2 += e * e;
        }
        view.features = std::move(kept);
        view.report.inliers = solved ? static_cast<int>(view.features.size()) : 0;
        view.report.residual_px =
            view.report.inliers > 0 ? std::sqrt(sum2 / view.report.inliers) : 0;
        const bool lost = view.report.inliers < s.options.min_view_inliers;
        view.report.reacquired = view.lost && !lost;
        view.report.lost = lost;
        view.lost = lost;
        // New corners when the tracks thin out.
        const int want = s.options.max_features_per_view - static_cast<int>(view.features.size());
        if (solved &&
            view.features.size() < s.options.replenish_below * s.options.max_features_per_view) {
          view.report.added = s.AddCorners(static_cast<int>(v), images[v], pose, want, false);
        }
        view.previous = images[v].clone();
      },
      1);
  for (const View& v : s.views) {
    total_inliers += v.report.inliers;
    total_sum2 += v.report.residual_px * v.report.residual_px * v.report.inliers;
  }
  const double residual = total_inliers > 0 ? std::sqrt(total_sum2 / total_inliers) : 0;
  return s.Result(solved.has_value(), total_inliers, residual);
}

PointTracker2d::PointTracker2d(const InstrumentTrackerOptions& options,
                               std::vector<Eigen::Vector2d> start)
    : options_(options), points_(std::move(start)) {}
PointTracker2d::~PointTracker2d() = default;

std::vector<Eigen::Vector2d> PointTracker2d::Next(const media::Image& previous,
                                                  const media::Image& current) {
  const cv::Mat a = AsMat(previous), b = AsMat(current);
  std::vector<int> index;
  std::vector<cv::Point2f> from, to, back;
  for (size_t i = 0; i < points_.size(); ++i) {
    if (!std::isfinite(points_[i].x())) continue;
    index.push_back(static_cast<int>(i));
    from.emplace_back(static_cast<float>(points_[i].x()), static_cast<float>(points_[i].y()));
  }
  if (from.empty()) return points_;
  std::vector<uchar> ok_forward, ok_backward;
  std::vector<float> err;
  const cv::Size window(options_.lk_window_px, options_.lk_window_px);
  const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  cv::calcOpticalFlowPyrLK(a, b, from, to, ok_forward, err, window, options_.lk_levels, stop);
  cv::calcOpticalFlowPyrLK(b, a, to, back, ok_backward, err, window, options_.lk_levels, stop);
  for (size_t k = 0; k < index.size(); ++k) {
    const double fb = std::hypot(back[k].x - from[k].x, back[k].y - from[k].y);
    // The baseline keeps a point while its forward-backward error stays within 2 px
    // (looser than the instrument tracker's features: the point itself must be kept).
    if (ok_forward[k] && ok_backward[k] && fb <= 4 * options_.max_forward_backward_px) {
      points_[index[k]] = Eigen::Vector2d(to[k].x, to[k].y);
    } else {
      points_[index[k]] = Eigen::Vector2d::Constant(kNaN);
    }
  }
  return points_;
}

}  // namespace arco::track
