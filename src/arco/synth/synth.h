// `arco synth`: a synthetic string performance with exact truth.
//
// Generate() builds everything in memory (deterministic for a seed):
// score -> fingering -> expression -> per-frame motion (instrument sway, left
// hand by IK, bow and right hand, body) -> truth -> emulated 2D detections.
// WriteCapture() writes the capture folder (capture.json, calibration.json,
// keypoints2d.npy, audio.wav) and truth/ beside the capture's files
// (docs/synth.md lists every file).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "arco/camera/rig.h"
#include "arco/hand/hand_model.h"
#include "arco/instrument/instrument_model.h"
#include "arco/refine/bowing.h"
#include "arco/synth/body.h"
#include "arco/synth/bow.h"
#include "arco/synth/detections.h"
#include "arco/synth/fingering.h"
#include "arco/synth/left_hand.h"
#include "arco/synth/performance.h"
#include "arco/synth/score.h"
#include "arco/synth/stage.h"
#include "arco/util/json_io.h"
#include "arco/util/npy.h"
#include "arco/util/status.h"

namespace arco::synth {

struct SynthOptions {
  std::string instrument = "cello";
  std::string piece = "scale-2oct";  // built-in piece; ignored when midi_path is set
  std::string midi_path;             // a Standard MIDI File instead of a piece
  double tempo_scale = 1.0;          // > 1 plays slower
  double max_duration_s = 0;         // 0 = the whole piece
  double fps = 30.0;
  double a4_hz = 440.0;
  uint64_t seed = 0;
  int num_threads = 0;  // 0 = all cores (results do not depend on it)

  StageOptions stage;
  FingeringOptions fingering;
  ExpressionOptions expression;
  LeftHandOptions left_hand;
  BowOptions bow;
  SwayOptions sway;
  DetectionOptions detection;

  Status Validate() const;
};

// Per-frame contact truth. string: 1 = highest .. 0 = none (rest, open string);
// finger: 1 = index .. 4 = little, 0 = none.
struct ContactTruth {
  int string = 0;
  int finger = 0;
  int note_index = -1;
  double f0_hz = 0;
  Eigen::Vector3d point_mm = Eigen::Vector3d::Constant(NAN);
  bool open_string = false;
  // The upper note of a sounding double stop (truth/contact_2.csv): its string (1 =
  // highest), finger (0 = open), f0 and contact point (NaN unless pressed).
  bool double_stop = false;
  int second_string = 0;
  int second_finger = 0;
  double second_f0_hz = 0;
  Eigen::Vector3d second_point_mm = Eigen::Vector3d::Constant(NAN);
};

struct SyntheticCapture {
  SynthOptions options;
  Rig rig_mm;  // the calibration scaled to mm (world frame of everything below)
  Stage stage;
  InstrumentKind instrument_kind = InstrumentKind::kCello;
  std::string layout;        // capture layout: spd_cello / spd_violin
  std::string truth_layout;  // layout + contact_13: spd_cello_contact / spd_violin_contact
  std::vector<std::string> keypoint_names;  // capture layout names
  int num_instrument_points = 0;
  Score score;
  FingeringPlan fingering;
  Performance performance;
  int num_frames = 0;
  // Truth, world mm: (frames, truth points, 3) in truth_layout order.
  NpyArray<double> points3d;
  std::vector<hand::HandPose> left_hand, right_hand;  // world_from_wrist, mm
  std::vector<ContactTruth> contact;
  std::vector<refine::BowingFrame> bowing;  // the bow arm (bow.h); empty for a recording
  std::vector<Eigen::Matrix4d> world_from_instrument;  // rotation | bridge centre, mm
  NpyArray<float> keypoints2d;                         // (frames, views, capture points, 3)
  double max_residual_shift_mm = 0;  // largest whole-hand correction the IK needed
  // Double stops: their count, and the farthest one of their fingertips stayed from its
  // contact (left_hand.h).
  int double_stops = 0;
  double max_second_residual_mm = 0;
  int pressed_frames = 0;
  // A re-captured recording (motion.h): the motion and the audio it came from (the audio is
  // copied, not rendered; the performance, score and hand poses are empty) and the
  // detector error model applied (error_model.h). Empty for a generated performance.
  std::string motion_source, audio_source;
  Json error_model;
};

// Errors: invalid options, unknown instrument/piece, MIDI problems, a rig with
// fewer than two cameras.
StatusOr<SyntheticCapture> Generate(const Rig& rig, const SynthOptions& options);

}  // namespace arco::synth
