// Per-performer bone lengths from a capture: for every bone, the median over
// frames of the triangulated distance between its two keypoints, after
// rejecting gross samples (outside [0.3, 3] x the prior length) and outliers
// (beyond mad_gate robust standard deviations from the median), optionally less
// the upward bias of a distance between two noisy points (below). Bones with too
// few samples take the prior length times the hand's overall scale; every
// length is finally clamped to [min_ratio, max_ratio] x the prior length.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "arco/hand/hand_model.h"
#include "arco/hand/kinematics.h"
#include "arco/util/status.h"

namespace arco::hand {

struct BoneLengthOptions {
  int min_samples = 10;     // frames with both keypoints finite, after gross rejection
  double mad_gate = 3.0;    // outlier gate in robust standard deviations (1.4826 MAD)
  double min_mad_mm = 1.0;  // floor of the robust deviation
  double min_ratio = 0.6;   // anatomical bounds relative to the prior bone
  double max_ratio = 1.6;
  // Noise lengthens a measured distance on average: with independent errors of
  // spread tau along each axis of the difference, d = |L + n| ~ L + n_par +
  // |n_perp|^2 / (2 L), whose mean is L + tau^2 / L (the two perpendicular
  // components add in quadrature and never cancel). tau is the inliers' robust
  // spread along the bone (n_par), so the length is taken as m - tau^2 / m
  // (m: the inliers' median). On SPD's real cellist re-captured by arco synth the
  // phalanges came out 1.5-2.9 mm too long on average without it, -0.5 to +0.4 mm
  // with it (docs/hand.md), and every joint group of the fitted hand got closer.
  // Off by default: with the hand not moved (refine.h, move_hand) the truer,
  // shorter fingers leave more contacts out of the playing finger's reach, and
  // arco's contact deviation on its synthetic captures rose by 0.16-0.79 mm
  // (docs/accuracy.md), past the bar run_capture_test checks.
  bool correct_noise_bias = false;
  // [0.5, 1): each length is this quantile of its inliers (numpy's linear interpolation);
  // 0.5 is the median. One camera's lifted points (track/monocular_lift.h) lie at one
  // depth per frame, so their distances are the bones' projections on a plane parallel
  // to the image, whole only when a bone lies parallel to it: the hand stage takes a
  // higher quantile there (HandStageOptions::one_view_bone_quantile).
  double quantile = 0.5;
  // [0.5, 1): the quantile for the palm's bones (wrist to the four finger bases) and for the
  // thumb's four. One camera sees a cellist's left palm turned to the neck and the thumb
  // behind it, rarely parallel to the image, while the fingers' phalanges often are: on
  // SPD's cellist seen by one camera the 0.75 quantile left the palm's bones 4 % short and
  // put the thumb's 6 % long; 0.8 and 0.7 there raised fingers 0.844 -> 0.855 and the hand
  // within 15 mm 0.244 -> 0.254 (docs/hand.md, "One camera"). 0.5 with several cameras.
  double palm_quantile = 0.5;
  double thumb_quantile = 0.5;
  // The palm as one rigid piece: its four bones (wrist to the finger bases) become the
  // prior's times one scale, the mean of the middle two of their measured ratios to the
  // prior (each measured at palm_quantile). The palm does not bend, and hands differ in its
  // size far more than in its proportions (the prior's 88 / 87 / 84 / 80 mm; SPD's
  // cellist 95 / 100 / 93 / 87), while one view foreshortens each of its bones by its own
  // tilt: there the 0.8 quantile gave SPD's cellist 101 / 103 / 91 / 78 mm, one scale
  // 98 / 97 / 94 / 89 (docs/hand.md, "One camera"). The hand stage sets it with one
  // camera (HandStageOptions::one_view_palm_as_one); false: each bone by itself.
  bool palm_as_one = false;
  Status Validate() const;
};

struct BoneLengthEstimate {
  BoneLengthsMm lengths_mm{};                    // by child keypoint (entry 0 unused)
  std::array<int, kNumHandKeypoints> samples{};  // after gross rejection
  std::array<int, kNumHandKeypoints> inliers{};
  std::array<uint8_t, kNumHandKeypoints> from_data{};  // 0: prior length x scale
  std::array<uint8_t, kNumHandKeypoints> clamped{};    // hit the anatomical bounds
  double hand_scale = 1.0;  // median over measured bones of length / prior length
};

// `frames`: triangulated keypoints per frame (mm, NaN = missing). Errors when no
// bone has enough samples or the hand's scale is outside [min_ratio, max_ratio]
// (e.g. world units that are not millimetres).
StatusOr<BoneLengthEstimate> EstimateBoneLengths(const std::vector<HandPointsMm>& frames,
                                                 const HandModel& prior,
                                                 const BoneLengthOptions& options);

}  // namespace arco::hand
