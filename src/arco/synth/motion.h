// Re-capture of a recorded performance (`arco synth --motion RESULTS.npy --audio TAKE.wav`):
// released 3D results of a real take (SPD's `spd_cello_contact` / `spd_violin_contact`
// arrays: COCO-WholeBody, instrument, bow, strings, contact point and playing finger, mm in
// the authors' own world frame) are placed in a calibrated rig by the instrument, projected
// into every camera with its distortion and spoiled by a named detector error model
// (synth/error_model.h). The result is an ordinary synthetic capture (capture_writer.h)
// whose truth folder holds the recorded motion instead of a generated one:
//
//   - placement: one rigid transform for the whole take, from the recorded instrument's
//     median keypoints onto arco's instrument template at its rest pose on the rig's stage
//     (stage.h), so the performer sits where a synthetic one would and every camera that
//     would see a synthetic performer sees this one;
//   - truth points3d: the recorded array moved into the rig (the same layout);
//   - contacts: the recorded contact point (150) and playing finger (151-154): the string
//     is the string segment (142-149) nearest the contact point, the finger the left-hand
//     fingertip the annotation's playing tip coincides with (within 1 mm; SPD copies it).
//     A frame without a contact is "rest": the annotation does not tell an open string
//     from silence;
//   - instrument pose: the template fitted rigidly to the moved instrument keypoints;
//   - no hand pose truth (arco's hand model does not describe a real hand: the angles
//     would be a fit, not truth) and no pitch truth (the audio is the recording's):
//     `arco eval` reports what needs them as absent.
//
// The recording is used as given, never resampled: frame i is at i / fps of the audio.
#pragma once

#include <string>

#include "arco/camera/rig.h"
#include "arco/synth/synth.h"
#include "arco/util/status.h"

namespace arco::synth {

struct MotionOptions {
  std::string motion_path;  // (frames, points, 3) float64 mm in the instrument's spd_*_contact
  std::string audio_path;   // the take's audio; frame 0 at its time 0; copied into the capture
  std::string instrument = "cello";
  double fps = 30.0;
  double max_duration_s = 0;  // 0 = the whole take
  double a4_hz = 440.0;
  uint64_t seed = 0;
  int num_threads = 0;
  StageOptions stage;
  // Which of the rig's cameras film the take: "" = all; a count N = N cameras spread
  // around the performer (farthest-point selection over their viewing directions, from
  // the camera facing the performer most directly, among those that see the instrument);
  // or camera names separated by commas. The performer is placed with the whole rig, so
  // a subset films the same scene.
  std::string cameras;
  std::string error_model = "synth";  // error_model.h: a named preset ...
  DetectionOptions detection;         // ... applied to these (the caller's overrides)
  Status Validate() const;
};

// Errors name the file: an array that is not (frames, P, 3) float64 with P the layout's
// size, a non-finite coordinate in a frame's body, hand, instrument or string points (only
// the contact extras may be NaN, all five together), an audio shorter than the motion, a
// rig in which fewer than two cameras see the instrument, an unknown camera name or a count
// above the cameras that see the instrument.
StatusOr<SyntheticCapture> GenerateFromMotion(const Rig& rig, const MotionOptions& options);

}  // namespace arco::synth
