// The bow and the right hand, in the instrument frame (synth_instrument.h).
//
// The bow is a straight hair line of `bow_length_mm` from the frog to the tip,
// perpendicular to the strings, touching the sounding string at about
// `contact_fraction` of the string length from the bridge (between bridge and
// fingerboard): louder notes nearer the bridge (the fraction scaled from 1.25x at
// velocity 1 to 0.75x at 127), so the sounding point changes from note to note. It is
// inclined about the string axis as a bow resting on that string of an arched bridge
// (InstrumentModel::BowInclinationRad; string crossings glide over `crossing_s`); a double
// stop's bow rests on both of its strings (the chord of the arch through them). Each note is one
// stroke, alternating down-bow (the contact moves from the frog towards the tip) and up-bow; a
// stroke uses more bow for longer notes. In silence the bow rests `lift_mm` above the string. The
// right hand holds the frog in a fixed bow-hold posture within the joint limits.
#pragma once

#include <Eigen/Core>

#include "arco/hand/hand_model.h"
#include "arco/instrument/instrument_model.h"
#include "arco/synth/performance.h"
#include "arco/synth/synth_instrument.h"
#include "arco/util/status.h"

namespace arco::synth {

struct BowOptions {
  double bow_length_mm = 0;        // frog to tip; 0 = the instrument's typical bow
  double contact_fraction = 0.08;  // bow-string contact, fraction of the string from the bridge
  double crossing_s = 0.06;        // duration of a string crossing
  double lift_mm = 15;             // bow above the string in silence
  Status Validate() const;
};

struct BowFrame {
  Eigen::Vector3d frog_mm, tip_mm;  // instrument frame
  int string = 0;                   // 1 = highest; 0 in silence
  int second_string = 0;            // a double stop's upper string, bowed with `string`; else 0
  // Truth of the bow arm (refine/bowing.h's conventions): +1 down-bow (the contact moves
  // from the frog toward the tip), -1 up-bow, 0 in silence; the contact's distance from
  // the bridge along the string and its place on the bow (0 frog, 1 tip).
  int direction = 0;
  double sounding_point_mm = 0;
  double bow_position = 0;
  hand::HandPose right_hand;  // instrument_from_wrist
};

class BowAnimator {
 public:
  // `right_side` is the performer's right expressed in the instrument frame (the
  // frog is on that side). Throws std::invalid_argument on invalid options.
  BowAnimator(const hand::HandModel& right_hand,
              const InstrumentModel& instrument,
              const InstrumentTemplate& tmpl,
              const Performance& performance,
              const Eigen::Vector3d& right_side,
              const BowOptions& options);
  BowFrame At(double time_s) const;

 private:
  double TiltRad(int string) const;
  // Where the bow rests during a note: its string(s) and the bow's tilt about the strings.
  struct Rest {
    int string = 0, second_string = 0;  // 1 = highest; second 0 on a single note
    double tilt_rad = 0;
  };
  Rest RestOn(size_t note) const;
  Eigen::Vector3d ContactOn(const Rest& rest, double fraction) const;
  double ContactFraction(size_t note) const;
  double BowFractionAt(double time_s) const;  // fraction of the bow at the contact

  const hand::HandModel& right_hand_;
  const InstrumentModel& instrument_;
  const InstrumentTemplate& tmpl_;
  const Performance& perf_;
  BowOptions options_;
  double bow_length_mm_;
  double side_sign_;  // +1 when the performer's right is +y in the instrument frame
  std::vector<double> stroke_start_, stroke_end_;  // bow fraction per note
  hand::HandPose hold_;                            // bow-hold joint angles
};

}  // namespace arco::synth
