// The left hand of the synthetic performer, in the instrument frame
// (synth_instrument.h), driven by the performance (pitch, fingering).
//
// Per note, an anchor for the middle MCP: for a pressed note, where a pressing
// posture (press_*_deg, clamped into the joint limits) puts the playing
// fingertip on the contact point of the note's centre pitch; for an open string,
// at the middle of the hand position's four finger places on that string. The
// fingers come from the high-string side of the neck on every bowed instrument.
// Between notes the anchor glides (smoothstep) over `shift_s` when the hand
// position changes and over `change_s` otherwise, arriving at the next onset;
// a pressing finger holds the hand until its note ends, so after a stopped note
// the glide fits in the articulation gap (a fast shift), after an open string
// it starts earlier.
// Per frame:
//  1. Vibrato: the anchor moves with the contact point between the note's centre
//     pitch and the pitch at this instant, so the hand rocks along the string in
//     phase with the audio's pitch modulation.
//  2. Idle fingers and the thumb relax towards a hovering curl (time constant
//     relax_s); the playing finger's tip goes to the contact point by the hand
//     layer's IK (SolveFingertipIk, all four dofs of the finger, bounded by the
//     joint limits, regularised towards the pressing posture and the previous
//     frame). What the IK cannot reach
//     is taken up by translating the whole hand, so the playing fingertip lies on
//     the string at the contact point exactly and every joint stays in its limits.
// Double stops: the anchor lies midway between the two fingers' anchors; the first
// finger is placed as above (the hand translated by its residual), then the second by the
// same IK; while either misses by more than 0.5 mm (at most 6 rounds) the hand moves by the
// mean of the two misses and both are placed again, so a span the joints cannot reach is
// shared by the two fingertips (second_residual_mm). A fifth stopped by one finger puts its tip
// midway between the two strings' contact points (the pad covers both); each string's contact is
// still its own point on that string.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "arco/hand/hand_model.h"
#include "arco/instrument/instrument_model.h"
#include "arco/synth/performance.h"
#include "arco/synth/synth_instrument.h"
#include "arco/util/status.h"

namespace arco::synth {

struct LeftHandOptions {
  double relax_s = 0.05;   // idle fingers relax towards the hovering curl
  double shift_s = 0.15;   // glide of the hand for a change of position
  double change_s = 0.06;  // glide for a finger or string change in one position
  // Pressing posture of the playing finger (degrees): MCP, PIP, DIP flexion.
  double press_mcp_deg = 45, press_pip_deg = 70, press_dip_deg = 30;
  bool rock_with_vibrato = true;
  // Also place every idle fingertip by IK `hover_mm` above its own place on the
  // string (about 5x slower; the benchmark's baseline). Off: idle fingers relax.
  bool ik_idle_fingers = false;
  double hover_mm = 12;
  Status Validate() const;
};

// One frame of the left hand (instrument frame, mm).
struct LeftHandFrame {
  hand::HandPose pose;  // world_from_wrist here means instrument_from_wrist
  int string = 0;       // 1 = highest; 0 = no pressed note
  int finger = 0;       // 1 = index .. 4 = little; 0 = none
  int note_index = -1;  // sounding note, -1 in silence
  double f0_hz = 0;     // sounding pitch, 0 in silence
  Eigen::Vector3d contact_mm = Eigen::Vector3d::Constant(NAN);  // NaN when not pressed
  double residual_shift_mm = 0;  // how far the hand was translated to reach exactly
  // The upper note of a sounding double stop (string 0 when none or when it is open;
  // second_open: it sounds on an open string).
  bool double_stop = false;
  bool second_open = false;
  int second_string = 0, second_finger = 0;
  double second_f0_hz = 0;
  Eigen::Vector3d second_contact_mm = Eigen::Vector3d::Constant(NAN);
  double second_residual_mm = 0;  // farthest a double stop's fingertip stays from its target
};

class LeftHandAnimator {
 public:
  // Throws std::invalid_argument on invalid options or a right-hand model.
  LeftHandAnimator(const hand::HandModel& model,
                   const InstrumentModel& instrument,
                   const InstrumentTemplate& tmpl,
                   const Performance& performance,
                   const LeftHandOptions& options);

  // Frames must be requested in increasing time order (the IK starts from the
  // previous frame's pose, like a real hand moving continuously).
  LeftHandFrame Next(double time_s);

 private:
  double PlaceX(double semitones) const;  // distance from the bridge of a stop
  double StringY(int string, double x) const;
  Eigen::Vector3d AnchorAt(double time_s) const;

  const hand::HandModel& model_;
  const InstrumentModel& instrument_;
  const InstrumentTemplate& tmpl_;
  const Performance& perf_;
  LeftHandOptions options_;
  Eigen::Matrix3d wrist_rotation_;  // instrument_from_wrist rotation
  Eigen::Vector3d middle_mcp_in_wrist_;
  hand::HandPose press_pose_, curl_pose_;
  std::vector<Eigen::Vector3d> tip_from_mcp_;  // per finger 0..4, pressing posture
  std::vector<Eigen::Vector3d> anchors_;       // per note
  std::vector<double> glide_s_;                // glide into note i
  std::optional<hand::HandPose> previous_;
  double last_time_s_ = -1e300;
  double previous_time_s_ = 0;
};

}  // namespace arco::synth
