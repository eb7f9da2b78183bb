// 3D keypoints from ONE calibrated view (issue 26 part 4, docs/phones.md "One camera").
//
// One view fixes a keypoint's ray, not its depth. What can be known is used, and every
// lifted point says where its depth came from (LiftDepth):
//  - the instrument is rigid and of known size: its pose per frame is a PnP of its
//    nominal keypoints (instrument/nominal_keypoints.h) against their pixels (EPnP in
//    RANSAC, then Levenberg-Marquardt on arco's camera model with its distortion), its
//    depth a median over the frames around, so its points, strings and scale are placed
//    in 3D (a real instrument larger than the nominal one is placed nearer: on SPD's
//    cello and first camera, about 60 mm at 2 m);
//  - the left hand plays on the strings: its keypoints are placed at one depth, the
//    median over its four fingertips of the depth where each one's ray passes closest to
//    a string: a depth that the hand fit keeps (hand/one_view_depth.h). Fingertips,
//    because they touch the strings while the wrist and thumb lie off them; the strings'
//    lines, not their plane, because cameras often look along the neck and cut the plane
//    at a grazing angle (on SPD's first camera a plane put the wrist 440 mm away);
//  - the body and the right hand have no depth cue here: they are placed on the plane
//    parallel to the image through a point `body_behind_mm` behind the middle of the
//    strings (the performer sits behind the instrument), flagged kAssumedPlane;
//  - the bow's frog and tip are NOT lifted: one view gives the bow's line in the image,
//    and its depth would be a guess that the bowing measures (bow speed, tilt, sounding
//    point) would report as measured.
// Frames without an instrument pose lift nothing (NaN).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "arco/camera/camera.h"
#include "arco/geometry/transform.h"
#include "arco/util/npy.h"
#include "arco/util/status.h"

namespace arco::track {

// Where a lifted point's depth came from (triangulation/depth_source.npy).
enum class LiftDepth : uint8_t {
  kNone = 0,            // not lifted (missing, low score, or no instrument pose)
  kInstrumentPose = 1,  // an instrument point: the PnP pose of the rigid instrument
  kStringLine = 2,      // at the depth where its fingertips pass closest to the strings
  kAssumedPlane = 3,    // the plane parallel to the image behind the instrument (a guess)
};

struct MonocularLiftOptions {
  double min_score = 0.3;         // [0, 1]: keypoints below are not lifted
  int min_instrument_points = 4;  // [4, 64]: instrument points a frame's PnP needs
  double pnp_gate_px = 8.0;       // (0, 200]: RANSAC gate and the pose's largest RMS
  double body_behind_mm = 150.0;  // [0, 2000]: the assumed plane behind the instrument
  // [0, 300]: the instrument's depth is the median over this many frames on each side
  // (0: each frame's own PnP). A held instrument barely comes nearer or goes (SPD's cello:
  // 8 mm over 11 s), while a detector's error on its points lasts seconds: on the real
  // take seen by one camera the frames' depths over +-15 frames wandered by 260 mm, over
  // +-90 (3 s at 30 fps) the instrument's error fell from 100 to 86 mm and the left hand
  // within 15 mm of SPD's in the instrument's frame rose from 0.29 to 0.36 of frames
  // (docs/accuracy.md, "One camera: the instrument's depth over seconds").
  int depth_window_frames = 90;
  // [0, 3000]: the same window for an instrument that stands on its end pin
  // (MonocularScene::stands_on_end_pin: a cello, a double bass). Its end pin stays where
  // it is on the floor for the take (SPD's cello: within 4 mm over 11 s, its bridge within
  // 10 mm) while a detector's error on its points wanders over the whole take: on 30
  // captures of the real take seen by one camera the frames' own depths went from 76 mm
  // nearer to 155 mm farther than SPD's (`shared` 0). Over +-250 frames (8.3 s at 30 fps)
  // instead of +-90 the instrument in the world came from 86 to 47 mm of SPD's, arco's
  // left hand in the world from 91 to 56 mm, the hand within 15 mm of SPD's in the
  // instrument's frame from 0.259 to 0.280 of frames, strings 0.992 -> 0.991, fingers
  // 0.872 -> 0.869 (docs/accuracy.md, "One camera: a cello stands on its end pin"). A
  // cello moved during the take is followed over seconds, later than a held violin.
  int end_pin_depth_window_frames = 250;
  // [0, 300]: its orientation is the average over this many frames on each side (0: each
  // frame's own).
  int rotation_window_frames = 15;
  double min_ray_plane_cos = 0.2;  // (0, 1]: a flatter ray misses the assumed plane
  Status Validate() const;
};

// The instrument as one view needs it, in its own frame (mm).
struct MonocularScene {
  std::vector<int> instrument_columns;                // layout columns of its rigid points
  std::vector<Eigen::Vector3d> instrument_points_mm;  // their nominal places
  // The strings (nut end, bridge end) and the top plate's normal (unit, to the front).
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> strings_mm;
  Eigen::Vector3d front = Eigen::Vector3d::UnitZ();
  std::vector<int> string_line_columns;        // the left hand: lifted at one depth, ...
  std::vector<int> string_line_depth_columns;  // ... its fingertips' nearest the line
  std::vector<int> unlifted_columns;           // the bow's frog and tip: left NaN
  // The instrument stands on its end pin (cello, double bass): its depth is held over
  // MonocularLiftOptions::end_pin_depth_window_frames instead of depth_window_frames.
  bool stands_on_end_pin = false;
};

struct MonocularLiftSummary {
  int64_t frames = 0;
  int64_t frames_with_pose = 0;      // instrument PnP accepted
  double median_pnp_rms_px = 0;      // over the accepted frames (NaN when none)
  int64_t lifted[4] = {0, 0, 0, 0};  // points per LiftDepth
};

struct MonocularLift {
  NpyArray<double> points3d_mm;    // (F, P, 3) world mm, NaN when not lifted
  NpyArray<uint8_t> depth_source;  // (F, P) LiftDepth
  NpyArray<float> pnp_rms_px;      // (F) the instrument's PnP RMS (NaN: no pose)
  // (F) how far the instrument's depth may be off, mm: the spread (1.4826 MAD) of the
  // frames' own PnP depths over the depth window, NaN without a pose. Not divided by the
  // frames' number: their errors hold for seconds (the template's misfit, the detector's
  // slow drift), so the window's median is as uncertain as one frame.
  NpyArray<float> depth_sigma_mm;
  std::vector<std::optional<Rigid3d>> world_from_instrument;  // per frame
  MonocularLiftSummary summary;
};

// `camera_mm`: the view's camera with the world in mm. `keypoints2d`: (F, 1, P, 3).
// Errors: invalid options or scene, a keypoints array of another shape, columns outside
// it. Deterministic (no randomness; frames are independent).
StatusOr<MonocularLift> LiftOneView(const Camera& camera_mm,
                                    const NpyArray<double>& keypoints2d,
                                    const MonocularScene& scene,
                                    const MonocularLiftOptions& options);

}  // namespace arco::track
