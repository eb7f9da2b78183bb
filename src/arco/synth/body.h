// The performer's body: a seated COCO-WholeBody skeleton (133 points; the face
// is a coarse 68-point template) in the performer frame (stage.h: x left, y up,
// z forward, mm, origin on the seat between the hips), and the instrument's rest
// pose in that frame.
//
// The torso sways (small rotations about the hips at ~0.2-0.4 Hz); the arms are
// two-bone chains from the shoulders to the wrists that the hands dictate
// (elbow placed by the law of cosines towards a pole direction).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>

#include "arco/geometry/transform.h"
#include "arco/instrument/instrument_model.h"
#include "arco/registry/keypoint_layout.h"

namespace arco::synth {

// Point indices: wholebody:: in registry/keypoint_layout.h.

struct SwayOptions {
  double torso_deg = 2.0;       // amplitude of each torso rotation component
  double instrument_deg = 1.5;  // extra rotation of the instrument (about its floor point)
  double min_hz = 0.15;         // sway frequencies drawn in [min_hz, max_hz]
  double max_hz = 0.45;
};

// Slow sway drawn once per capture from the seed.
class Sway {
 public:
  Sway(const SwayOptions& options, uint64_t seed);
  // Torso rotation about the hip centre (performer frame) at time t.
  Eigen::Matrix3d TorsoRotation(double time_s) const;
  // Additional instrument rotation at time t.
  Eigen::Matrix3d InstrumentRotation(double time_s) const;

 private:
  std::array<double, 6> amp_rad_{}, freq_hz_{}, phase_rad_{};
};

// Instrument rest pose: performer_from_instrument (instrument frame in
// synth_instrument.h). Cello and double bass stand on the end pin between the
// knees with the neck beside the left side of the head; violin and viola rest on
// the left shoulder pointing forward-left, the top tilted towards the right.
RigidMatrix3d InstrumentRestPose(InstrumentKind kind, double scale);

// Pivot of the instrument's sway in the performer frame (the end pin on the
// floor, or the chin rest).
Eigen::Vector3d InstrumentPivot(InstrumentKind kind, double scale);

// Body keypoints (0-90: body, feet, face) at time t given the torso rotation and
// both wrists (performer frame); hand keypoints 91-132 are left to the caller.
// `violin_hold` turns the head towards the instrument on the left shoulder.
void BodyKeypoints(const Eigen::Matrix3d& torso_rotation,
                   const Eigen::Vector3d& left_wrist,
                   const Eigen::Vector3d& right_wrist,
                   bool violin_hold,
                   std::array<Eigen::Vector3d, wholebody::kNumPoints>* points);

// Elbow of a two-bone arm (law of cosines); the wrist is unreachable beyond
// upper + fore: the elbow then lies on the shoulder-wrist line.
Eigen::Vector3d ElbowPosition(const Eigen::Vector3d& shoulder,
                              const Eigen::Vector3d& wrist,
                              double upper_mm,
                              double fore_mm,
                              const Eigen::Vector3d& pole);

// Shoulder positions at time t (needed by the hands' reach checks).
Eigen::Vector3d LeftShoulder(const Eigen::Matrix3d& torso_rotation);
Eigen::Vector3d RightShoulder(const Eigen::Matrix3d& torso_rotation);

}  // namespace arco::synth
