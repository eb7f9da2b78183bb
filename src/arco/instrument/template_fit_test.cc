#include "arco/instrument/template_fit.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "arco/instrument/contact.h"
#include "arco/instrument/pose_smoothing.h"

namespace arco {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const InstrumentModel& Cello() {
  static const InstrumentModel model = *InstrumentModel::Create("cello");
  return model;
}

// A cello in its instrument frame (mm), distances as on the real frame-128 labels
// (DOMAIN.md section 5); frog/tip (the bow) move independently.
std::vector<Eigen::Vector3d> TruthCello() {
  return {{695 + 186, 0, -25},    // scroll_top
          {695, 11.95, 0},        // nut_l (low side, +y)
          {695, -11.95, 0},       // nut_r
          {0, 24.1, 0},           // bridge_l
          {0, -24.1, 0},          // bridge_r
          {-370, 0, -70},         // tail_gut
          {-370 - 300, 0, -160},  // end_pin
          {kNaN, kNaN, kNaN},
          {kNaN, kNaN, kNaN}};
}

SimMatrix3d TruthPose(int f) {
  SimMatrix3d p;
  const double t = 0.05 * f;
  p.rotation = (Eigen::AngleAxisd(1.2 + 0.08 * std::sin(t), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(0.3 + 0.05 * std::cos(0.7 * t), Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitY()))
                   .toRotationMatrix();
  p.scale = 1.0 / 2020.0;  // world units per mm: Metashape-like units
  p.translation = Eigen::Vector3d(0.1 + 0.01 * std::sin(0.3 * t), -0.2, 1.9 + 0.005 * t);
  return p;
}

struct Clip {
  std::vector<Eigen::Matrix3Xd> keypoints;
  std::vector<FrontHint> hints;
  std::vector<std::vector<bool>> displaced;  // [frame][keypoint]
  std::vector<bool> garbage;                 // whole frame corrupted
  std::vector<bool> sparse;                  // fewer than 3 points left
};

Clip MakeClip(int num_frames, double noise_mm, uint32_t seed, bool mirror = false) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_mm);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const std::vector<Eigen::Vector3d> truth = TruthCello();
  const Eigen::Matrix3d m =
      mirror ? Eigen::Vector3d(-1, 1, 1).asDiagonal().toDenseMatrix() : Eigen::Matrix3d::Identity();
  Clip clip;
  for (int f = 0; f < num_frames; ++f) {
    const SimMatrix3d pose = TruthPose(f);
    Eigen::Matrix3Xd kp = Eigen::Matrix3Xd::Constant(3, 9, kNaN);
    std::vector<bool> displaced(9, false);
    const bool garbage = f % 37 == 5;
    const bool sparse = f % 53 == 7;
    for (int k = 0; k < 7; ++k) {
      Eigen::Vector3d p = truth[k] + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
      if (garbage) p = truth[k] + 150.0 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
      if (!garbage && uniform(rng) < 0.06) {  // a gross outlier point
        p += Eigen::Vector3d(noise(rng), noise(rng), noise(rng)).normalized() *
             (80 + 120 * uniform(rng));
        displaced[k] = true;
      }
      kp.col(k) = m * (pose * p);
      if (uniform(rng) < 0.1 || (sparse && k >= 2)) kp.col(k).setConstant(kNaN);
    }
    kp.col(7) =
        m * (pose * Eigen::Vector3d(300 + 50 * std::sin(0.1 * f), 100, 60));  // bow: not rigid
    kp.col(8) = m * (pose * Eigen::Vector3d(-100.0, -400.0 + (30 * f) % 200, 90.0));
    clip.keypoints.push_back(kp);
    clip.hints.push_back(
        {FrontHint::Kind::kPerformerPoint, m * (pose * Eigen::Vector3d(450, 50, -300))});
    clip.displaced.push_back(displaced);
    clip.garbage.push_back(garbage);
    clip.sparse.push_back(sparse);
  }
  return clip;
}

// The string end points in the instrument frame (mm).
std::vector<Eigen::Vector3d> TruthStrings() {
  std::vector<Eigen::Vector3d> out;
  for (int s = 1; s <= 4; ++s) {
    out.emplace_back(695, Cello().LateralOffsetAtNutMm(s), 0);
    out.emplace_back(0, Cello().LateralOffsetAtBridgeMm(s), 0);
  }
  return out;
}

TEST(FitInstrument, RecoversTemplateScaleAndPosesDespiteOutliers) {
  const Clip clip = MakeClip(400, 2.0, 7);
  auto fit = FitInstrument(Cello(), clip.keypoints, clip.hints);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  const InstrumentFit& r = *fit;
  EXPECT_TRUE(r.summary.converged);
  EXPECT_FALSE(r.instrument.order.ambiguous) << r.instrument.order.warning;
  EXPECT_TRUE(r.instrument.order.labels_agree);
  EXPECT_DOUBLE_EQ(r.summary.front_agreement, 1.0);
  EXPECT_NEAR(r.instrument.world_units_per_mm * 2020.0, 1.0, 2e-3);
  const std::vector<Eigen::Vector3d> truth = TruthCello();
  for (int k = 0; k < 7; ++k) {
    // 2 mm noise per coordinate over ~370 frames: the nut and bridge points (which define
    // the frame) to a fraction of a mm; far points also carry the frame's small tilt.
    const double tolerance_mm = (k >= 1 && k <= 4) ? 0.6 : 2.0;
    EXPECT_LT((r.instrument.keypoints_in_instrument[k] - truth[k]).norm(), tolerance_mm) << k;
  }
  EXPECT_FALSE(r.instrument.keypoints_in_instrument[7].allFinite());  // the bow is not rigid
  // String 4 (C) on the +y side, 23 mm outer spacing at the nut.
  EXPECT_NEAR(r.instrument.strings_in_instrument[3].nut.y(), 11.5, 0.5);
  EXPECT_NEAR(r.instrument.strings_in_instrument[0].nut.y(), -11.5, 0.5);

  std::vector<double> placement_mm;
  int good = 0, flagged_outliers = 0, outliers = 0, false_rejects = 0, inlier_total = 0;
  for (size_t f = 0; f < clip.keypoints.size(); ++f) {
    const InstrumentFramePose& p = r.frames[f];
    if (clip.sparse[f]) {
      EXPECT_FALSE(p.has_pose()) << f;
      continue;
    }
    if (clip.garbage[f]) {
      EXPECT_NE(p.status, FrameFitStatus::kOk) << f;
      continue;
    }
    ASSERT_TRUE(p.has_pose()) << f;
    if (p.status != FrameFitStatus::kOk) continue;
    ++good;
    const SimMatrix3d truth_pose = TruthPose(static_cast<int>(f));
    // Where the pose puts the instrument (its keypoints and the string ends), in mm.
    double worst_mm = 0;
    for (const Eigen::Vector3d& q : TruthStrings()) {
      worst_mm = std::max(worst_mm, (p.world_from_instrument * q - truth_pose * q).norm() * 2020.0);
    }
    placement_mm.push_back(worst_mm);
    EXPECT_LT(p.rms_residual_mm, 8.0);
    for (int k = 0; k < 7; ++k) {
      if (!clip.keypoints[f].col(k).allFinite()) continue;
      const bool inlier = p.inlier_mask & (1u << k);
      if (clip.displaced[f][k]) {
        ++outliers;
        flagged_outliers += inlier ? 0 : 1;
      } else {
        ++inlier_total;
        false_rejects += inlier ? 0 : 1;
      }
    }
  }
  EXPECT_GT(good, 300);
  // String placement error per frame (worst of the 8 string ends): with 3-7 noisy points
  // per frame, a few frames with only 3 inliers tilt by several degrees.
  std::sort(placement_mm.begin(), placement_mm.end());
  EXPECT_LT(placement_mm[placement_mm.size() / 2], 3.0);
  EXPECT_LT(placement_mm[placement_mm.size() * 95 / 100], 5.0);
  EXPECT_LT(placement_mm.back(), 10.0);
  EXPECT_GT(outliers, 50);
  EXPECT_EQ(flagged_outliers, outliers);
  EXPECT_LT(false_rejects, 0.01 * inlier_total);
  EXPECT_LT(r.summary.median_rms_residual_mm, 4.0);
}

TEST(FitInstrument, StringsFromPoseMatchTruthAndOctaveIsHalfWay) {
  const Clip clip = MakeClip(200, 1.5, 11);
  auto fit = FitInstrument(Cello(), clip.keypoints, clip.hints);
  ASSERT_TRUE(fit.ok());
  const Contact octave = ContactPoint(Cello(), 3, 2 * Cello().open_hz(3));
  for (int f : {0, 10, 99, 150}) {
    ASSERT_EQ(fit->frames[f].status, FrameFitStatus::kOk) << f;
    const SimMatrix3d& pose = fit->frames[f].world_from_instrument;
    const std::vector<StringSegment> strings = StringsAt(fit->instrument, pose);
    const SimMatrix3d truth = TruthPose(f);
    const double nut_y = Cello().LateralOffsetAtNutMm(3);
    const Eigen::Vector3d truth_nut = truth * Eigen::Vector3d(695, nut_y, 0);
    EXPECT_LT((strings[2].nut - truth_nut).norm() * 2020.0, 3.0);
    const Eigen::Vector3d p = strings[2].PointAtFraction(octave.fraction_from_bridge);
    EXPECT_NEAR((p - strings[2].bridge).norm(), (p - strings[2].nut).norm(), 1e-9);
  }
}

TEST(FitInstrument, MirroredClipPutsLowStringOnTheLabelsRightSide) {
  const Clip clip = MakeClip(120, 1.0, 3, /*mirror=*/true);
  auto fit = FitInstrument(Cello(), clip.keypoints, clip.hints);
  ASSERT_TRUE(fit.ok());
  EXPECT_FALSE(fit->instrument.order.labels_agree);
  EXPECT_FALSE(fit->instrument.order.ambiguous);
  // String 4 sits next to the keypoint labelled nut_r.
  const Eigen::Vector3d nut_r = fit->instrument.keypoints_in_instrument[2];
  EXPECT_GT(nut_r.y(), 0);
  EXPECT_NEAR(fit->instrument.strings_in_instrument[3].nut.y(), 11.5, 0.5);
}

TEST(FitInstrument, SplitFrontHintsAreAmbiguous) {
  Clip clip = MakeClip(100, 1.0, 5);
  for (size_t f = 0; f < clip.hints.size(); f += 2) {
    clip.hints[f].kind = FrontHint::Kind::kFrontPoint;  // half the frames claim the opposite
  }
  auto fit = FitInstrument(Cello(), clip.keypoints, clip.hints);
  ASSERT_TRUE(fit.ok());
  EXPECT_TRUE(fit->instrument.order.ambiguous);
  EXPECT_NE(fit->instrument.order.warning.find("ambiguous"), std::string::npos);
  EXPECT_FALSE(fit->summary.warnings.empty());
  std::vector<FrontHint> none(1,
                              {FrontHint::Kind::kPerformerPoint, Eigen::Vector3d::Constant(kNaN)});
  auto no_hint = FitInstrument(Cello(), clip.keypoints, none);
  ASSERT_TRUE(no_hint.ok());
  EXPECT_TRUE(no_hint->instrument.order.ambiguous);
}

TEST(FitInstrument, ResultsDoNotDependOnThreadCount) {
  const Clip clip = MakeClip(150, 2.0, 9);
  InstrumentFitOptions one, four;
  one.num_threads = 1;
  four.num_threads = 4;
  auto a = FitInstrument(Cello(), clip.keypoints, clip.hints, one);
  auto b = FitInstrument(Cello(), clip.keypoints, clip.hints, four);
  ASSERT_TRUE(a.ok() && b.ok());
  for (size_t f = 0; f < a->frames.size(); ++f) {
    EXPECT_EQ(a->frames[f].status, b->frames[f].status);
    EXPECT_EQ(a->frames[f].world_from_instrument.rotation,
              b->frames[f].world_from_instrument.rotation);
    EXPECT_EQ(a->frames[f].world_from_instrument.translation,
              b->frames[f].world_from_instrument.translation);
    EXPECT_EQ(a->frames[f].inlier_mask, b->frames[f].inlier_mask);
  }
  EXPECT_EQ(a->instrument.world_units_per_mm, b->instrument.world_units_per_mm);
}

TEST(FitInstrument, BadInputIsAnErrorNotACrash) {
  const Clip clip = MakeClip(20, 1.0, 1);
  EXPECT_FALSE(FitInstrument(Cello(), {}, {clip.hints[0]}).ok());
  std::vector<Eigen::Matrix3Xd> wrong(3, Eigen::Matrix3Xd::Zero(3, 7));
  EXPECT_THROW(static_cast<void>(FitInstrument(Cello(), wrong, {clip.hints[0]})),
               std::invalid_argument);
  std::vector<FrontHint> two(2, clip.hints[0]);
  EXPECT_THROW(static_cast<void>(FitInstrument(Cello(), clip.keypoints, two)),
               std::invalid_argument);
  std::vector<Eigen::Matrix3Xd> nan(5, Eigen::Matrix3Xd::Constant(3, 9, kNaN));
  auto all_nan = FitInstrument(Cello(), nan, {clip.hints[0]});
  ASSERT_FALSE(all_nan.ok());
  EXPECT_NE(all_nan.status().message().find("nut_l"), std::string::npos);
  std::vector<Eigen::Matrix3Xd> coincident = clip.keypoints;
  for (Eigen::Matrix3Xd& m : coincident) {
    m.col(1) = m.col(3);
    m.col(2) = m.col(4);
  }
  auto c = FitInstrument(Cello(), coincident, {clip.hints[0]});
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("coincide"), std::string::npos);
  InstrumentFitOptions bad;
  bad.scale = InstrumentFitOptions::Scale::kGiven;  // without a value
  EXPECT_FALSE(FitInstrument(Cello(), clip.keypoints, clip.hints, bad).ok());
  bad = {};
  bad.min_point_gate_mm = 100;  // above max_point_gate_mm
  EXPECT_FALSE(bad.Validate().ok());
  EXPECT_THROW(FitFramePose({}, clip.keypoints[0], 10.0), std::invalid_argument);
}

TEST(SmoothFramePoses, ReducesJitterFillsGapsAndKeepsScale) {
  const Clip clip = MakeClip(300, 4.0, 21);
  auto fit = FitInstrument(Cello(), clip.keypoints, clip.hints);
  ASSERT_TRUE(fit.ok());
  PoseSmoothingOptions options;
  options.sigma_frames = 3.0;
  options.max_fill_gap_frames = 3;
  const std::vector<InstrumentFramePose> smooth = SmoothFramePoses(fit->frames, options);
  ASSERT_EQ(smooth.size(), fit->frames.size());
  double raw_error = 0, smooth_error = 0;
  int n = 0;
  for (size_t f = 10; f + 10 < smooth.size(); ++f) {
    if (clip.sparse[f]) {
      EXPECT_TRUE(smooth[f].has_pose());
      EXPECT_TRUE(smooth[f].filled);
    }
    if (fit->frames[f].status != FrameFitStatus::kOk) continue;
    const SimMatrix3d truth = TruthPose(static_cast<int>(f));
    // Compare where the pose puts the nut centre (mm).
    const Eigen::Vector3d nut_truth = truth * Eigen::Vector3d(695, 0, 0);
    raw_error +=
        (fit->frames[f].world_from_instrument * Eigen::Vector3d(695, 0, 0) - nut_truth).norm() *
        2020.0;
    smooth_error +=
        (smooth[f].world_from_instrument * Eigen::Vector3d(695, 0, 0) - nut_truth).norm() * 2020.0;
    EXPECT_EQ(smooth[f].world_from_instrument.scale, fit->frames[f].world_from_instrument.scale);
    EXPECT_NEAR(smooth[f].world_from_instrument.rotation.determinant(), 1.0, 1e-9);
    ++n;
  }
  ASSERT_GT(n, 200);
  EXPECT_LT(smooth_error, 0.7 * raw_error);
  // Strings from the smoothed pose; residual recomputed against the keypoints.
  const double r = PoseResidualMm(fit->instrument,
                                  smooth[50].world_from_instrument,
                                  clip.keypoints[50],
                                  fit->frames[50].inlier_mask);
  EXPECT_TRUE(std::isfinite(r));
  EXPECT_LT(r, 15.0);
  PoseSmoothingOptions bad;
  bad.sigma_frames = 0;
  EXPECT_THROW(SmoothFramePoses(fit->frames, bad), std::invalid_argument);
  EXPECT_TRUE(SmoothFramePoses({}, options).empty());
}

// A clip whose first 8 and last 3 frames or so have too few points for a pose (a take
// that starts with the bridge hidden): the smoothing holds the posed frames' pose over the
// ends within max_end_hold_frames of them, near the truth there, and leaves the rest
// without a pose; 0 holds nothing.
TEST(SmoothFramePoses, HoldsTheClipsEndsWithinTheirLimit) {
  const Clip clip = MakeClip(120, 4.0, 23);
  auto fit = FitInstrument(Cello(), clip.keypoints, clip.hints);
  ASSERT_TRUE(fit.ok());
  std::vector<InstrumentFramePose> frames = fit->frames;
  const int n = static_cast<int>(frames.size());
  auto ok = [&](int f) { return frames[static_cast<size_t>(f)].status == FrameFitStatus::kOk; };
  int first = 8, last = n - 4;
  while (!ok(first)) ++first;
  while (!ok(last)) --last;
  for (int f = 0; f < n; ++f) {
    if (f < first || f > last) frames[static_cast<size_t>(f)].status = FrameFitStatus::kTooFewPoints;
  }
  PoseSmoothingOptions options;
  options.sigma_frames = 3.0;
  options.max_fill_gap_frames = 3;
  options.max_end_hold_frames = 5;
  const std::vector<InstrumentFramePose> held = SmoothFramePoses(frames, options);
  int checked = 0;
  for (int f = 0; f < n; ++f) {
    if (f >= first && f <= last) continue;
    const InstrumentFramePose& p = held[static_cast<size_t>(f)];
    if (first - f > 5 || f - last > 5) {
      EXPECT_FALSE(p.has_pose()) << f;
      continue;
    }
    ASSERT_TRUE(p.has_pose()) << f;
    EXPECT_TRUE(p.filled) << f;
    // Held, not extrapolated: off the truth by what the instrument moved since the
    // nearest posed frame, and a few mm more (the one-sided kernel's average lies a frame
    // or two inside; this clip's instrument turns by 2.5 mm a frame at the nut).
    const Eigen::Vector3d nut(695, 0, 0);
    const int nearest = f < first ? first : last;
    const double off_mm = (p.world_from_instrument * nut - TruthPose(f) * nut).norm() * 2020.0;
    const double moved_mm = (TruthPose(nearest) * nut - TruthPose(f) * nut).norm() * 2020.0;
    EXPECT_LT(off_mm, moved_mm + 8.0) << f;
    ++checked;
  }
  EXPECT_GE(checked, 8);  // 5 at the start, 3 at the end
  EXPECT_FALSE(held[0].has_pose());
  options.max_end_hold_frames = 0;
  const std::vector<InstrumentFramePose> none = SmoothFramePoses(frames, options);
  EXPECT_FALSE(none[static_cast<size_t>(first - 1)].has_pose());
  EXPECT_FALSE(none[static_cast<size_t>(n - 1)].has_pose());
  options.max_end_hold_frames = -1;
  EXPECT_THROW(SmoothFramePoses(frames, options), std::invalid_argument);
}

// A pose track with known truth: the instrument translated by `amplitude_mm` * sin(2 pi f /
// period_frames) along x and turned about z by amplitude / 700 rad, the measured poses off by
// white noise of `noise_mm` per axis.
std::vector<InstrumentFramePose> MovingTrack(int frames,
                                             double amplitude_mm,
                                             double period_frames,
                                             double noise_mm,
                                             unsigned seed,
                                             std::vector<SimMatrix3d>* truth) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_mm);
  std::vector<InstrumentFramePose> out(static_cast<size_t>(frames));
  truth->clear();
  for (int f = 0; f < frames; ++f) {
    const double s = std::sin(2 * M_PI * f / period_frames);
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(amplitude_mm / 700.0 * s, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Vector3d t(amplitude_mm * s, 0, 2000);
    truth->push_back(SimMatrix3d(1.0, r, t));
    const Eigen::Matrix3d rn =
        Eigen::AngleAxisd(noise(rng) / 350.0, Eigen::Vector3d::UnitY()).toRotationMatrix() * r;
    out[static_cast<size_t>(f)].status = FrameFitStatus::kOk;
    out[static_cast<size_t>(f)].world_from_instrument =
        SimMatrix3d(1.0, rn, t + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
  }
  return out;
}

TEST(LeaveOneOutSigmaFrames, WideForAHeldInstrumentNarrowForAMovingOne) {
  const std::vector<Eigen::Vector3d> probes = {
      {695, 12, 0}, {695, -12, 0}, {0, 24, 0}, {0, -24, 0}};
  const std::vector<double> candidates = {2, 3, 5, 7, 10, 15, 20};
  std::vector<SimMatrix3d> truth;
  // Held still, 2 mm of noise: the widest kernel, and it lands nearer the truth than sigma 2.
  const std::vector<InstrumentFramePose> held = MovingTrack(330, 3.0, 330, 2.0, 11, &truth);
  const double wide = LeaveOneOutSigmaFrames(held, probes, candidates);
  std::printf("[ loo ] held instrument: sigma %.0f frames\n", wide);
  EXPECT_GE(wide, 15);
  const auto error = [&](double sigma) {
    PoseSmoothingOptions o;
    o.sigma_frames = sigma;
    const std::vector<InstrumentFramePose> smooth = SmoothFramePoses(held, o);
    double sum = 0;
    for (size_t f = 0; f < smooth.size(); ++f)
      sum += (smooth[f].world_from_instrument * probes[0] - truth[f] * probes[0]).norm();
    return sum / static_cast<double>(smooth.size());
  };
  EXPECT_LT(error(wide), 0.6 * error(2));
  // Moving 40 mm every second with 0.3 mm of noise: the narrowest.
  const std::vector<InstrumentFramePose> moving = MovingTrack(330, 40.0, 30, 0.3, 12, &truth);
  EXPECT_EQ(LeaveOneOutSigmaFrames(moving, probes, candidates), 2);
  // Too few posed frames: the first candidate; frames without a pose are left out.
  std::vector<InstrumentFramePose> few = held;
  for (size_t f = 20; f < few.size(); ++f) few[f].status = FrameFitStatus::kTooFewPoints;
  EXPECT_EQ(LeaveOneOutSigmaFrames(few, probes, candidates), 2);
  EXPECT_THROW(LeaveOneOutSigmaFrames(held, probes, {}), std::invalid_argument);
  EXPECT_THROW(LeaveOneOutSigmaFrames(held, probes, {2, 0}), std::invalid_argument);
}

}  // namespace
}  // namespace arco
