// The second note of double stops (issue 27): after the refinement has decoded and placed
// the first voice (refine.h), the upper note of each double-stop frame gets its string, its
// finger and its contact, and the hand its second finger.
//
// Input per frame: the two notes a polyphonic tracker heard (audio/double_stops.h,
// TrackDoubleStops: lower f0 first, 0 = none). The caller hands the refinement the lower
// note as the frame's pitch (so the first voice is the lower note, as a synthetic truth's
// contact.csv has it) and the upper note here. Per frame with a first voice (pressed or on
// an open string) and an upper note:
//   1. String: the next higher string (string - 1; 1 = highest): double stops are played
//      on adjacent strings. None (the first voice is on the highest string, or the note
//      lies below that string's open pitch by more than open_tolerance_cents): no second
//      note.
//   2. Open: within open_tolerance_cents of that string's open pitch the string sounds
//      open (finger 0).
//   3. Otherwise the contact (instrument/contact.h, ContactPoint) on that string of the
//      frame's strings; a playable hand: the two stops at most max_span_semitones apart
//      along the fingerboard, else uncertain.
//   4. The fingers, per first-voice note and upper semitone: a fifth (the two stops within
//   fifth_semitones)
//      is stopped by the first voice's finger on both strings. Otherwise the pair of
//      fingers that one frame of the hand can hold at the two stops (registry/
//      instruments.h, FingerReaches: the positions the two reaches give within half a
//      semitone) whose fingertips, as the cameras saw the hand, lie nearest the two
//      contacts summed over the note's frames. The first voice was decoded alone and may
//      hold a finger that leaves none of the hand for the second stop (a cello sixth as
//      fingers 1 and 4 two semitones apart, where they stand three apart): the pair then
//      changes the first voice's finger too (its old finger back to the cameras' pose,
//      the new one to the first contact by IK), in a note whose frames mostly have a second
//      voice and never for an octave (its upper note is as often the lower note's own 2nd
//      partial: a single-note take under --double-stops hears many). Both fingers within
//      max_tip_distance_mm of their contacts on average over the frames, or the pair is not taken.
//      No such pair: the first voice's finger and the nearest other fingertip. A second finger
//      farther than max_tip_distance_mm from its contact: uncertain.
//  00. The bow (bow_gate): a double stop is bowed on both its strings at once, so a frame whose
//      bow is seen on the strings and rests on one string (BowRestOf: its inclination
//      nearer one string's than any two adjacent strings'; refine/bowing.h) has no second
//      voice, whatever the tracker heard, unless its first-voice note is bowed on two
//      strings on most of its frames and the frame comes before the note's last such frame
//      (a noisy inclination at a double stop's start; its release rings on while the bow
//      leaves) (whichever string the first voice was decoded on:
//      a chord's lower pair may be on other strings until step 0b): on a real cello the 2nd partial
//      and the previous note still ringing are heard as a second note on half the frames
//      (docs/accuracy.md, "Double stops"). An unseen or lifted bow leaves the frame to the
//      sound alone.
//   0. A first-voice note (FrameContact::note) with an upper note on at least half its
//      frames gets their median on its frames without one, where it lies above the frame's
//      pitch (fill_notes).
//  0a. Attacks (attack_s): in such a note whose upper notes agree on two thirds of them, a
//      frame within attack_s of the note's first frame whose upper note is more than half
//      a semitone from the median gets the median.
//  0b. Chords (tie_chords): a rolled chord reaches the refinement as a short lower pair
//      right before its held upper pair, and the first voice of each was decoded alone. The
//      lower pair's first voice moves to the string below the upper pair's lower note when
//      the two pairs share that note (one finger holds it on one string), or two below when
//      the four notes differ: the string (open within open_tolerance_cents, else the
//      fingertip nearest the new contact, by IK) where both of its notes are playable.
//  0c. Octaves (bow_octaves), with step 0 in pass 1: a first-voice note heard as one note
//      (no upper note on half its frames) whose bow rests on its string and the next higher one on
//      at least half its frames gets the octave above the frame's pitch on those frames. An
//      octave's upper partials are all the lower note's even partials, so the sound alone hears one
//      note (docs/accuracy.md, "Double stops"); a bow on two strings says two sound.
//   5. IK: that finger's tip to the contact by the hand layer's bounded IK (MCP, PIP, DIP
//      within the joint limits, regularised toward the refined pose); a fifth's finger is
//      left where the first voice put it (its pad covers both strings).
// Frames are independent but for the notes of step 4; the result does not depend on the
// thread count.
#pragma once

#include <array>
#include <limits>
#include <optional>
#include <vector>

#include "arco/refine/contact_annotation.h"
#include "arco/refine/refine.h"
#include "arco/util/number_range.h"
#include "arco/util/status.h"

namespace arco::refine {

// Declared ranges of DoubleStopRefineOptions (Validate()).
inline constexpr NumberRange kOpenToleranceRangeCents = Closed(0, 100);
inline constexpr NumberRange kSpanRangeSemitones = Closed(0, 24);
inline constexpr NumberRange kTipDistanceRangeMm = Closed(0, 500);
inline constexpr NumberRange kChordWindowRangeS = Closed(0, 2);
inline constexpr NumberRange kAttackRangeS = Closed(0, 1);

struct DoubleStopRefineOptions {
  double open_tolerance_cents = 40.0;  // an upper note this near its open string is open
  double max_span_semitones = 7.5;     // the two stops along the fingerboard (an octave: 5-7)
  double fifth_semitones = 0.5;        // stops this close: one finger may stop both strings
  double max_tip_distance_mm = 60.0;   // the chosen fingertip's distance to its contact
  int max_iterations = 15;             // of the second finger's IK
  // A first-voice note with an upper note on at least half its frames keeps the median of
  // them on its other frames (the tracker's window misses the second note near the ends).
  bool fill_notes = true;
  // Step 0a: a first-voice note whose upper notes mostly agree (two thirds within half a
  // semitone of their median) gives that median to the frames of its first attack_s that
  // heard another (0: off). A bowed string's new note takes 50-150 ms to settle into its
  // periodic motion and the tracker's window (up to 0.2 s on the double bass) straddles
  // the onset: there the upper note of an octave or a sixth is heard a tone off or as the
  // lower note's own partial (docs/accuracy.md, "A double stop's attack").
  double attack_s = 0.25;
  // A rolled chord's lower pair (a double-stop note of at most chord_lower_max_s, ending at
  // most chord_gap_s before the next longer double-stop note, its upper pair) is put on the
  // strings its upper pair leaves it (step 0b): below the shared note's string, or the two
  // below a 4-note chord's upper pair.
  bool tie_chords = true;
  double chord_gap_s = 0.2;
  double chord_lower_max_s = 0.5;
  // Step 00: no second voice where the bow is seen on one string.
  bool bow_gate = true;
  // Step 0c: an octave above the first voice on the frames of a note heard as one note but
  // bowed on two strings on at least half its frames.
  bool bow_octaves = true;
  // Before the refinement (pipeline/refine_stage.h, AddDoubleStops): a frame whose bow rests
  // on two strings takes the pair the tracker heard as played on them.
  bool bow_pairs = true;
  Status Validate() const;
};

struct DoubleStopRefineSummary {
  int frames = 0;                    // frames with an upper note and a first voice
  int bow_one_string = 0;            // frames whose upper note the bow ruled out (step 00)
  int bow_octaves = 0;               // frames given an octave the bow plays (step 0c)
  int attack_frames = 0;             // upper notes replaced by their note's (step 0a)
  // Frames whose two notes are the pair heard on the strings the bow rests on (set by the
  // pipeline, pipeline/refine_stage.h AddDoubleStops, before the refinement).
  int bow_pairs = 0;
  int pressed = 0, open_string = 0;  // second voices assigned
  int one_finger_fifths = 0;         // pressed by the first voice's finger
  int first_fingers_changed = 0;     // first-voice frames given another finger (step 4)
  int chord_frames_moved = 0;        // first-voice frames of chords' lower pairs moved (0b)
  int uncertain = 0;                 // no playable string / hand
  int joint_limit_violations = 0;    // refined poses outside the limits (must stay 0)
};

struct DoubleStopRefineResult {
  std::vector<FrameContact> first;                  // the first voice, its fingers per step 4
  std::vector<FrameContact> second;                 // one per frame (kRest: none)
  std::vector<std::optional<hand::HandPose>> hand;  // the hand with the second finger
  DoubleStopRefineSummary summary;
};

// `first` is Refine(input, ...)'s result; upper_f0_hz one per frame (0 = none);
// bow_inclination_deg the bow's inclination across the strings per frame while it is on
// them (refine/bowing.h's BowingFrame::inclination_deg), NaN where it is not seen or is
// lifted, or empty when the take has no bow. Throws std::invalid_argument on sizes that
// differ or invalid options.
DoubleStopRefineResult RefineSecondVoice(const RefineInput& input,
                                         const RefineResult& first,
                                         const std::vector<double>& upper_f0_hz,
                                         const DoubleStopRefineOptions& options,
                                         const std::vector<double>& bow_inclination_deg = {});

// Where a bow inclined `inclination_deg` across the strings rests (steps 00 and 0c): on the
// string or the pair of adjacent strings whose inclination is nearest (a pair's is the mean
// of its two strings', InstrumentModel::BowInclinationRad: the chord of the bridge's arch
// through both). {0, 0} for an unknown inclination.
struct BowRest {
  int string = 0;         // 1 = highest; the lower of a pair
  int second_string = 0;  // the pair's upper string (string - 1); 0 on one string
  // How far the bow's inclination lies from that rest's own (degrees): a string and the
  // pairs beside it are about 10 degrees apart, so a small value is a clear rest.
  double off_deg = std::numeric_limits<double>::quiet_NaN();
};
BowRest BowRestOf(const InstrumentModel& model, double inclination_deg);

}  // namespace arco::refine
