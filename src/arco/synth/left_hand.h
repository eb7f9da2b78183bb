// The left hand of the synthetic performer, in the instrument frame
// (synth_instrument.h), driven by the performance (pitch, fingering).
//
// Per frame:
//  1. The hand position (fingering.h) gives an anchor for the MCP row: along the
//     strings at the middle of the positions' four finger places, beside the
//     string being played (towards the high-string side, where the fingers come
//     from on every bowed instrument), a little above the string plane. Shifts
//     glide smoothly (smoothstep) over `shift_s` before the next note; string
//     changes glide over `string_change_s`.
//  2. Vibrato: the anchor moves along the string by the displacement of the
//     contact point between the note's centre pitch and the pitch at this
//     instant, so the hand rocks in phase with the audio's pitch modulation.
//  3. Fingers by the hand layer's IK (SolveFingertipIk, all four dofs of each
//     finger, bounded by the joint limits): the idle fingers hover `hover_mm`
//     above their own places, the thumb reaches for the back of the neck, and the
//     playing finger's tip goes to the contact point. Whatever the IK cannot reach
//     is taken up by translating the whole hand, so the playing fingertip lies on
//     the string at the contact point exactly and every joint stays in its limits.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "arco/hand/hand_model.h"
#include "arco/instrument/instrument_model.h"
#include "arco/synth/performance.h"
#include "arco/synth/synth_instrument.h"
#include "arco/util/status.h"

namespace arco::synth {

struct LeftHandOptions {
  double hover_mm = 12;          // idle fingertips above their places on the string
  double mcp_beside_string_mm = 38;  // MCP row beside the played string (towards high strings)
  double mcp_above_strings_mm = 24;  // MCP row above the string plane
  double shift_s = 0.15;         // duration of a shift, ending at the next onset
  double string_change_s = 0.08; // lateral glide of the hand for a string change
  bool rock_with_vibrato = true;
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
  // Anchor (MCP row centre) along x for a hand position, and y beside a string.
  double AnchorX(double position_semitones) const;
  double StringY(int string, double x) const;
  double PositionAt(double time_s) const;
  int StringForHandAt(double time_s) const;

  const hand::HandModel& model_;
  const InstrumentModel& instrument_;
  const InstrumentTemplate& tmpl_;
  const Performance& perf_;
  LeftHandOptions options_;
  Eigen::Matrix3d wrist_rotation_;  // instrument_from_wrist rotation
  Eigen::Vector3d middle_mcp_in_wrist_;
  std::optional<hand::HandPose> previous_;
  double smoothed_string_y_ = NAN;
  double last_time_s_ = -1e300;
};

}  // namespace arco::synth
