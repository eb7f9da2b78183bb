// Emulated 2D keypoint detections: the truth projected into every camera (with
// its distortion) and spoiled the way real detectors spoil it.
//
// Per keypoint and view, in this order (each draw from the view's own seeded
// stream, so views can run in parallel and results do not depend on threads):
//  0. View-consistent error (before projection, in 3D): every keypoint carries an
//     offset that all views agree on, as a real detector's errors largely are
//     (a wrong finger pose is wrong in every view), so triangulation cannot
//     average it away: Gaussian, `jitter_mm` per axis for hand points (x1.5 for
//     body and face, x0.3 for instrument points, x1 for the bow), smooth in time
//     (first-order autoregressive with time constant `jitter_time_s`).
//  1. Finger bias (before projection, in 3D): on frames with a pressed note the
//     playing finger's tip moves `finger_bias_mm` off the string along the
//     instrument's front normal and its DIP half as far: the detector sees an
//     unloaded, lifted finger (the failure the paper corrects). Triangulation
//     cannot remove it because every view agrees on it.
//  2. Projection; points behind the camera or outside the image are missing
//     (x = y = NaN, score 0).
//  3. Geometric occlusion: the line of sight passes through the instrument's body
//     (an ellipse in its top plate) or the performer's torso (a capsule) before
//     the point; or a random drop-out (`occlusion_rate`). The detector still
//     answers, badly: error ~ 4 noise_px + up to 25 px, score 0.05-0.45.
//  4. Gross outliers (`outlier_rate` per point): 40-250 px off, score 0.4-0.9
//     (confidently wrong).
//  5. Ordinary points: Gaussian noise of noise_px per axis (x noise_scale for
//     instrument and bow points); score 0.98 minus 0.06 per noise_px of error,
//     jittered, within [0.5, 1]: the score correlates with the error.
//  6. Hand swaps: with probability `outlier_rate` per view and frame the left and
//     right hand detections trade places.
// Three further errors of real hand detectors, off by default (the named error models of
// synth/error_model.h switch them on). Each draws from its own seeded streams, so switching
// one on leaves every other draw, and today's captures, unchanged:
//  7. Per-finger offset (before projection, in 3D, shared by all views): each left-hand
//     finger carries one smooth offset (first-order autoregressive, `finger_offset_time_s`),
//     `finger_offset_mm` per axis at the tip, 3/4 at the DIP, 1/2 at the PIP, 1/4 at the
//     MCP: the detector's systematic error on fingers pressing strings (a finger drawn too
//     straight or too bent in every view), which triangulation cannot remove.
//  8. The hand seen from behind: in a view that looks at the back of the left hand (the
//     angle between the line of sight and the hand's back normal, DetectionFrame::
//     left_hand_back, below `hand_back_max_deg`) the fingers' PIP, DIP and tips are
//     hidden behind the hand; the detector guesses them as for an occluded point
//     (4 noise_px + up to 25 px, score 0.05-0.45).
//  9. Finger confusions: with probability `finger_confusion_rate` per view and frame two
//     neighbouring fingers of the left hand (index-middle, middle-ring, ring-little) trade
//     their PIP, DIP and tip detections.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "arco/camera/rig.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/util/npy.h"
#include "arco/util/status.h"

namespace arco::synth {

struct DetectionOptions {
  double noise_px = 2.0;
  double outlier_rate = 0.01;
  double occlusion_rate = 0.05;
  double finger_bias_mm = 12.0;
  double jitter_mm = 4.0;               // view-consistent 3D error per axis (hand points)
  double jitter_time_s = 0.15;          // its correlation time
  double instrument_noise_scale = 0.5;  // instrument points (tracked, TAPIR-like)
  double bow_noise_scale = 1.5;         // frog and tip (a dedicated detector)
  bool geometric_occlusion = true;
  double finger_offset_mm = 0;        // 7. per-finger shared 3D offset at the tip (0 = off)
  double finger_offset_time_s = 0.6;  // its correlation time
  double hand_back_max_deg = 0;       // 8. back-of-hand view cone half-angle (0 = off)
  double finger_confusion_rate = 0;   // 9. neighbouring-finger swaps per view and frame
  Status Validate() const;
};

// Everything about one frame that the detector emulation needs (world, mm).
struct DetectionFrame {
  std::vector<Eigen::Vector3d> points;  // truth keypoints of the capture layout
  int bias_tip = -1, bias_dip = -1;     // keypoint indices biased this frame (-1: none)
  Eigen::Vector3d bias_direction = Eigen::Vector3d::Zero();  // unit, world
  // Unit normal of the back of the left hand (away from the palm); zero: unknown (no
  // back-of-hand occlusion this frame).
  Eigen::Vector3d left_hand_back = Eigen::Vector3d::Zero();
  // Instrument body ellipse: centre, unit axes, semi-axes (mm).
  Eigen::Vector3d body_centre, body_axis_x, body_axis_y;
  double body_half_x = 0, body_half_y = 0;
  // Torso capsule from the hip centre to the neck base.
  Eigen::Vector3d torso_a, torso_b;
  double torso_radius = 140;
};

struct DetectionLayout {
  int num_points = 0;
  int left_hand_first = wholebody::kLeftHandFirst;
  int right_hand_first = wholebody::kRightHandFirst;
  int instrument_first = wholebody::kNumPoints;
  std::vector<int> bow_points;    // e.g. frog, tip
  std::vector<int> torso_points;  // points on the torso surface (never torso-occluded)
};

// (frames, views, points, 3) float array of [x_px, y_px, score].
NpyArray<float> EmulateDetections(const Rig& rig_mm,
                                  const std::vector<DetectionFrame>& frames,
                                  const DetectionLayout& layout,
                                  const DetectionOptions& options,
                                  double fps,
                                  uint64_t seed,
                                  int num_threads = 0);

}  // namespace arco::synth
