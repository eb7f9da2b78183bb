// The instrument in every camera from labels in one frame (`arco track`, docs/track.md):
// the labelled points triangulated into a rigid template; per view, pyramidal
// Lucas-Kanade on corners inside the instrument's projected outline with a
// forward-backward check; per frame, the body's 6-DoF pose from all views' tracks at once
// (track/pose_solver.h: RANSAC + Levenberg-Marquardt, a constant-velocity prediction and
// a weak prior towards it); every template point re-projected into every view, occluded
// ones included, with a score. Drift control: at keyframes, patches of the labelled
// frame (anchors, whose template points are exact) are warped into the current view's
// geometry and re-matched by normalised cross-correlation.
//
// Features get their template coordinates by intersecting their ray with the plane that
// fits the labelled points best (the instrument's front: scroll, nut, bridge, tail and
// end pin lie close to one plane); docs/track.md says what that costs on a real cello.
// OpenCV is private: no OpenCV type appears here.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "arco/camera/camera.h"
#include "arco/geometry/transform.h"
#include "arco/media/image.h"
#include "arco/track/pose_solver.h"
#include "arco/util/json_io.h"
#include "arco/util/status.h"

namespace arco::track {

// The labelled points of one frame: per view, per template point, a pixel (NaN: not
// labelled in that view).
struct FrameLabels {
  std::vector<std::string> point_names;
  std::vector<std::vector<Eigen::Vector2d>> pixels;  // [view][point]
};

// A rigid body's points in the world at the labelled frame (its template frame), and the
// plane that fits them.
struct RigidTemplate {
  std::vector<std::string> point_names;
  std::vector<Eigen::Vector3d> points;  // NaN for a point labelled in fewer than two views
  std::vector<int> label_views;         // views that labelled each point
  Eigen::Vector3d plane_point = Eigen::Vector3d::Zero();
  Eigen::Vector3d plane_normal = Eigen::Vector3d::UnitZ();
  double rms_reprojection_px = 0;  // of the labels, over the triangulated points
};

// Errors: fewer than two views with labels, fewer than three points labelled in two
// views (two with `thin`), labels that do not triangulate (rays that miss each other by
// more than max_label_error_px). `thin`: a stick such as the bow, two points on its axis;
// its plane contains the axis and faces the cameras that labelled it.
StatusOr<RigidTemplate> TriangulateTemplate(const std::vector<Camera>& cameras,
                                            const FrameLabels& labels,
                                            double max_label_error_px = 10,
                                            bool thin = false);

// The template from labels in ONE view (a one-camera capture): the instrument's model
// points (`model_points`, one per label name, its own frame in the world's units; NaN for
// a name the model lacks) posed by a PnP of the labelled ones (EPnP in RANSAC, then
// Levenberg-Marquardt on the camera's model with its distortion). One view fixes no
// depth: the model's real size places the template, as `arco run` places a one-camera
// instrument (monocular_lift.h). Points are the posed model's (label_views 1), so every
// labelled point of the model gets a place; rms_reprojection_px is the labels' against
// the posed model. Errors: fewer than four labelled model points, no pose within
// max_label_error_px.
StatusOr<RigidTemplate> PoseTemplateInOneView(const Camera& camera,
                                              const FrameLabels& labels,
                                              const std::vector<Eigen::Vector3d>& model_points,
                                              double max_label_error_px = 10);

struct InstrumentTrackerOptions {
  int max_features_per_view = 200;
  double min_feature_distance_px = 8;
  double corner_quality = 0.01;  // goodFeaturesToTrack's, relative to the best corner
  int lk_window_px = 21;         // Lucas-Kanade window (odd)
  int lk_levels = 3;             // pyramid levels above the image
  double max_forward_backward_px = 0.5;
  double outline_margin_px = 12;  // the projected outline grown by this much
  double replenish_below = 0.7;   // new corners when fewer than this x max remain
  int keyframe_interval = 5;      // NCC re-matching every N frames (and when lost)
  int anchors_per_view = 80;      // labelled-frame patches kept for re-matching
  int ncc_patch_px = 15;          // odd
  int ncc_search_px = 6;          // +- around the prediction
  double min_ncc = 0.85;
  double anchor_weight = 2;  // of a re-matched anchor in the pose solve
  int min_view_inliers = 4;  // fewer: the view has lost the instrument
  PoseSolverOptions pose;
  int num_threads = 1;  // views in parallel; results do not depend on it
  Status Validate() const;
};

Json ToJson(const InstrumentTrackerOptions& options);

struct ViewTrackReport {
  int tracked = 0;          // features that survived Lucas-Kanade and the forward-backward check
  int inliers = 0;          // of those and the re-matched anchors, inliers of the pose
  double residual_px = 0;   // RMS over the inliers (0 when none)
  int rematched = 0;        // anchors re-matched by NCC this frame
  int added = 0;            // new corners
  bool lost = false;        // fewer than min_view_inliers
  bool reacquired = false;  // lost in the previous frame, not any more
};

struct TrackedPoint {
  Eigen::Vector2d pixel = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  double score = 0;
};

struct TrackFrame {
  bool pose_ok = false;  // false: the pose is the prediction (scores are low)
  Rigid3d world_from_template;
  int inliers = 0;
  double residual_px = 0;
  double match_ncc = 0;  // the bow's profile match (bow_tracker.h); 0 for the instrument
  std::vector<ViewTrackReport> views;
  std::vector<std::vector<TrackedPoint>> points;  // [view][template point]
};

class InstrumentTracker {
 public:
  // Throws std::invalid_argument on invalid options or a template without a point.
  InstrumentTracker(std::vector<Camera> cameras,
                    RigidTemplate body,
                    const InstrumentTrackerOptions& options);
  ~InstrumentTracker();
  InstrumentTracker(InstrumentTracker&&) noexcept;

  // The labelled frame, one Gray8 image per view (the cameras' sizes): corners and
  // anchors are found; the pose is the identity.
  TrackFrame Start(const std::vector<const media::Image*>& frames);
  // The next frame in tracking order (forwards or backwards in time). A null frame is a
  // view that did not record this frame (its features wait for its next frame).
  // `labels` ([view][template point], NaN = none), when given, are labels of this frame:
  // they enter the pose solve with 10 x anchor_weight.
  TrackFrame Next(const std::vector<const media::Image*>& frames,
                  const std::vector<std::vector<Eigen::Vector2d>>* labels = nullptr);

  const RigidTemplate& body() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// The baseline of docs/track.md: each view on its own, the labelled points themselves
// tracked by the same Lucas-Kanade (with its forward-backward check) and no rigid model.
// Returns [frame][point] pixels (NaN once lost) for frames[0] = the labelled frame.
class PointTracker2d {
 public:
  PointTracker2d(const InstrumentTrackerOptions& options, std::vector<Eigen::Vector2d> start);
  ~PointTracker2d();
  std::vector<Eigen::Vector2d> Next(const media::Image& previous, const media::Image& current);

 private:
  InstrumentTrackerOptions options_;
  std::vector<Eigen::Vector2d> points_;
};

}  // namespace arco::track
