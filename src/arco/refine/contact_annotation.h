// What the refinement says about the left hand at every frame (the contact annotation)
// and per note (the fingering transcription). Conventions:
// - string: 1 = highest (cello A, violin E) .. num_strings = lowest; 0 = none.
// - finger: 1 = index .. 4 = little (the string player's numbering, = hand::Finger); 0 =
//   none. The thumb is never a playing finger here.
// - Points in the world, millimetres; NaN when absent.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

#include "arco/util/status.h"

namespace arco::refine {

enum class RefineMode {
  kVision,  // the fitted hand as is, no audio
  kPaper,   // Jin et al. 2024 as published (paper_decode.h)
  kArco,    // arco's decoding and bounded IK (arco_decode.h, finger_ik.h)
};
const char* RefineModeName(RefineMode mode);  // "vision", "paper", "arco"
StatusOr<RefineMode> ParseRefineMode(std::string_view name);

enum class ContactState {
  kPressed,     // a finger stops a string at point_in_world_mm
  kOpenString,  // an open string sounds: no finger contact (string = that string)
  kRest,        // nothing sounds
  kUncertain,   // something sounds but no contact is trusted (reason says why)
};
const char* ContactStateName(ContactState state);  // "pressed", "open", "rest", "uncertain"

enum class ContactReason {
  kNone,           // pressed or open string with everything available
  kUnvoiced,       // rest
  kLowConfidence,  // pitch tracker not confident (noise, polyphony)
  kUnstablePitch,  // an outlier frame or a note that keeps jumping (polyphony, octave errors)
  kShortNote,      // a note too short to trust
  kUnplayable,     // no string of the instrument produces this pitch
  kNoInstrument,   // no strings in this frame
  kNoHand,         // no fitted hand in this frame (pressed: contact known, hand not corrected)
  kOutOfReach,     // lift test: the finger cannot reach the contact (arco mode)
  // Informational reasons on pressed frames (arco mode):
  kBeforeOnset,   // just before the note's first trusted pitch: the finger lands before the
                  // sound, and a tracker needs a frame or two to lock onto a new note
  kHandShifted,   // the finger alone could not reach: the whole hand moved (bounded)
  kNoteBoundary,  // the frame's own pitch is not trusted (a note change), the audio's onset
                  // places it in this note: a lower-confidence contact (note_boundaries.h)
};
constexpr int kNumContactReasons = 12;
const char* ContactReasonName(ContactReason reason);

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct FrameContact {
  ContactState state = ContactState::kRest;
  ContactReason reason = ContactReason::kUnvoiced;
  int string = 0;
  int finger = 0;
  int note = -1;  // index into the pitch analysis' notes, -1 for none
  Eigen::Vector3d point_in_world_mm = Eigen::Vector3d::Constant(kNaN);
  double from_nut_mm = kNaN;              // along the string
  double f0_hz = 0;                       // the frame's pitch (0 when unvoiced)
  double confidence = 0;                  // the pitch tracker's
  double tip_distance_vision_mm = kNaN;   // fitted (vision) fingertip to the contact
  double tip_distance_refined_mm = kNaN;  // refined fingertip to the contact

  bool pressed() const { return state == ContactState::kPressed; }
};

// One note of the fingering transcription.
struct NoteFingering {
  int note = 0;  // index into the pitch analysis' notes
  int64_t first_frame = 0, last_frame = 0;
  double onset_s = 0, duration_s = 0;
  double f0_hz = 0;      // median of the note
  int midi_note = 0;     // nearest equal-tempered note at the capture's A4
  double cents_off = 0;  // f0 relative to that note (intonation)
  std::string state;     // "pressed", "open" or "uncertain" (majority of its frames)
  int string = 0;
  int finger = 0;
  // Hand position in semitones above the open string where finger 1 would stop (1 = half
  // position, 2 = first position ...; synth/fingering.h's convention); NaN unless pressed.
  double position_semitones = kNaN;
  double from_nut_mm = kNaN;  // median contact along the string
  int pressed_frames = 0, open_frames = 0, uncertain_frames = 0;
};

// "C2", "F#3", ... for a MIDI note number.
std::string MidiNoteName(int midi_note);

}  // namespace arco::refine
