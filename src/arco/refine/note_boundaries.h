// Note boundaries from the audio's onsets (arco mode).
//
// At a note change the video-rate pitch track is at its worst: the analysis window of the
// frame at the change straddles the onset (a pitch between the two notes, or the old one),
// the confidence collapses for a frame or two, and a fast note may keep a single trusted
// frame (a "short note"). The hand, however, is already on the new note: the finger lands
// before the bow speaks. The audio layer's notes (audio/notes.h, from the fine pitch track
// at several hops per video frame) locate the onset to a fraction of a frame.
//
// ApplyAudioNoteBoundaries assigns every video frame to the note sounding at the frame's
// time: for each audio note A (window [onset_A - tol, min(offset_A, next onset) - tol))
// the pitch-model note N with the same pitch (within match_cents) and a trusted
// frame inside the window is extended, frame by frame outward from its own frames, over
// the window's frames whose own pitch is not trusted: rests (a dropped frame), low
// confidence, outliers, short notes of another pitch, and weak frames that merely
// continued the previous note by hysteresis after its last trusted frame. Trusted frames
// of another note, polyphony (kJumping) and unstable notes are never taken. Taken frames
// get FrameAudioState::kBoundary, and so do the note's first frames (within straddle_s of
// the onset) whose pitch is off the note's (the window straddles the change: a pitch
// between the notes, or an attack transient). A short note whose extension reaches
// min_note_frames becomes usable. tol (onset_tolerance_s) absorbs the fine track's own lag behind
// the true onset (about a quarter to half a video frame).
#pragma once

#include <vector>

#include "arco/refine/pitch_model.h"

namespace arco::refine {

struct NoteBoundaryOptions {
  double onset_tolerance_s = 0.017;  // a frame this much before an audio onset is in the note
  double match_cents = 50.0;         // audio note and pitch-model note are the same note
  // The note's own frames within straddle_s after the onset whose pitch is farther than
  // straddle_cents from the note's (the analysis window still hears the change) become
  // boundary frames too: they take the note's pitch and are no evidence for its finger.
  double straddle_s = 0.034;
  double straddle_cents = 30.0;
};

// frame_time_s(f) = start_s + f / fps (the pitch track's timing contract,
// audio/pitch_tracker.h). `audio_notes` in time order. Modifies `analysis` in place.
void ApplyAudioNoteBoundaries(const std::vector<AudioNote>& audio_notes,
                              double start_s,
                              double fps,
                              const std::vector<FramePitch>& pitch,
                              const PitchModelOptions& pitch_options,
                              const NoteBoundaryOptions& options,
                              PitchAnalysis* analysis);

}  // namespace arco::refine
