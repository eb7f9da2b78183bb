// The pitch-finger model (Jin et al. 2024, Eq. 2; DOMAIN.md sections 1, 2, 5): what the
// audio says about the left hand at every video frame, before any hand is looked at.
//
// Per frame the pitch is classified:
//   rest          unvoiced (f0 <= 0 or NaN): no note sounds, no contact;
//   uncertain     voiced but not trustworthy: confidence below min_confidence, pitch that
//                 keeps jumping between notes (polyphony), a frame whose pitch leaves its
//                 note for too short a time to be a note of its own (a single noisy frame,
//                 an octave blip), a note shorter than min_note_frames, or a note with too
//                 many such outliers. No contact is forced on these frames;
//   note          a stable, confident pitch that belongs to a note (NoteSpan).
//
// Notes come from the audio alone: a note continues while the pitch stays within
// note_change_cents of the note's running median; a new note starts only when at least
// note_change_frames consecutive frames agree on a new pitch, so one wrong frame can never
// start (or flip) a note. Vibrato (typically +-10..50 cents at 5-7 Hz) stays inside a note.
//
// Candidates (Eq. 2, via instrument/contact.h): for a note frame, the contact point on every
// string whose playable range holds the frame's pitch, L_vib = L * f_open / f, placed on that
// frame's own 3D string (never a cached one: the strings move with the instrument). A pitch
// within ContactOptions::open_tolerance_cents of an open string is an open-string candidate:
// no finger contact at all (not a contact at the nut). A pitch no string can produce gives
// no candidate (uncertain, "unplayable").
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "arco/instrument/contact.h"
#include "arco/instrument/instrument_model.h"
#include "arco/instrument/strings.h"
#include "arco/util/status.h"

namespace arco::refine {

// One video frame of the pitch track (audio/pitch_tracker.h PitchFrame carries the same).
struct FramePitch {
  double f0_hz = 0;       // <= 0 or NaN: unvoiced
  double confidence = 0;  // 0..1, the tracker's
};

struct PitchModelOptions {
  ContactOptions contact;       // open-string and range tolerances (instrument/contact.h)
  double min_confidence = 0.5;  // voiced frames below this are uncertain ...
  // ... unless they continue an open note at a pitch that agrees with it (hysteresis: fast
  // passages blur the tracker's confidence between notes).
  double min_confidence_in_note = 0.2;
  // Note segmentation (header comment).
  double note_change_cents = 70.0;     // farther than this from the note's running median ...
  int note_change_frames = 2;          // ... for this many consecutive agreeing frames: new note
  int median_window_frames = 15;       // the running median looks at this many latest frames
  int min_note_frames = 2;             // shorter notes are uncertain (one frame never counts)
  double max_outlier_fraction = 0.25;  // more outlier frames than this: the note is unstable
  // Pitch that keeps jumping (polyphony, a tracker torn between two notes): a frame lying in
  // any window of jump_window_frames frames with more than max_jumps_in_window jumps of at
  // least jump_cents between consecutive frames is unstable and belongs to no note. Fast
  // passages (notes of 3+ frames) make at most about 3 jumps in 11 frames.
  double jump_cents = 100.0;
  int jump_window_frames = 11;
  int max_jumps_in_window = 4;
  // A note whose pitch modulation (half the 10-90 percentile range of its cents) exceeds
  // this vibrates, so it is stopped: an open string cannot vibrate.
  double vibrato_min_cents = 8.0;

  Status Validate() const;
};

enum class FrameAudioState {
  kRest,           // unvoiced
  kLowConfidence,  // voiced, confidence < min_confidence
  kJumping,        // in a stretch where the pitch keeps jumping (polyphony)
  kOutlier,        // left its note for fewer than note_change_frames frames
  kShortNote,      // in a note shorter than min_note_frames
  kUnstableNote,   // in a note with too many outliers
  kNote,           // a usable note frame
  // A frame at a note change whose own pitch is not trusted (the analysis window straddles
  // the onset, the confidence collapses between notes) but which the audio's onsets place
  // inside a usable note (note_boundaries.h, arco mode): it belongs to that note, with the
  // note's pitch, but it never counts as evidence for the note's string and finger.
  kBoundary,
};
const char* FrameAudioStateName(FrameAudioState state);

struct NoteSpan {
  int64_t first_frame = 0;
  int64_t last_frame = 0;       // inclusive
  double f0_hz = 0;             // median over the note's own (non-outlier) frames
  double modulation_cents = 0;  // half the 10-90 percentile range of their cents
  double mean_confidence = 0;
  int outlier_frames = 0;
  bool usable = false;  // long and stable enough (frames then have state kNote)
  int64_t num_frames() const { return last_frame - first_frame + 1; }
};

// A note found by the audio layer on the fine pitch track (audio/notes.h, `notes.csv`):
// its onset is known to a fraction of a video frame. Seconds on the audio's clock.
struct AudioNote {
  double onset_s = 0;
  double offset_s = 0;
  double f0_hz = 0;  // median
};

struct PitchAnalysis {
  std::vector<FrameAudioState> frame_state;  // one per frame
  std::vector<int> note_of_frame;            // index into notes, -1 for none (outliers: -1)
  std::vector<NoteSpan> notes;               // in time order; usable or not
};

// Throws std::invalid_argument for options that fail Validate().
PitchAnalysis AnalysePitch(const std::vector<FramePitch>& pitch, const PitchModelOptions& options);

// A candidate contact on one string for one frame.
struct Candidate {
  int string = 0;  // 1 = highest
  Eigen::Vector3d point_in_world = Eigen::Vector3d::Zero();
  double from_nut_mm = 0;           // along the string, nut to contact
  double semitones_above_open = 0;  // of the frame's pitch on this string
};

struct FrameCandidates {
  std::vector<Candidate> stopped;  // strings with a stopped contact, highest string first
  std::vector<int> open_strings;   // strings whose open pitch matches (no contact)
  bool any() const { return !stopped.empty() || !open_strings.empty(); }
};

// Candidates for one pitch on one frame's strings (index = string - 1, world mm; an empty
// vector gives the open strings only and no stopped candidates). Never throws for any f0.
FrameCandidates CandidatesForPitch(const InstrumentModel& model,
                                   const std::vector<StringSegment>& strings_in_world,
                                   double f0_hz,
                                   const ContactOptions& options);

// The contact point on `string` for f0 on these strings, if that string stops f0.
bool ContactOnString(const InstrumentModel& model,
                     const std::vector<StringSegment>& strings_in_world,
                     int string,
                     double f0_hz,
                     const ContactOptions& options,
                     Candidate* out);

}  // namespace arco::refine
