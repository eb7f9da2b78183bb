// The fingering transcription: one row per note of the pitch analysis, from the per-frame
// contacts of its frames (majority state, string and finger), with the note's intonation
// relative to equal temperament at the capture's A4 and the hand position it implies.
#pragma once

#include <vector>

#include "arco/instrument/instrument_model.h"
#include "arco/refine/contact_annotation.h"
#include "arco/refine/pitch_model.h"

namespace arco::refine {

std::vector<NoteFingering> Transcribe(const InstrumentModel& model,
                                      const PitchAnalysis& analysis,
                                      const std::vector<FrameContact>& contacts,
                                      double fps,
                                      double a4_hz);

// The second voice of double stops (double_stop_refine.h), one row per first-voice note
// (`first`, Transcribe's rows) whose frames mostly have a second voice (a contact of
// `second` that is not kRest): that note's frames and onset, the second voice's median f0
// (its midi_note and cents_off), and its majority state, string and finger as Transcribe
// has them; position_semitones is the first voice's where it is pressed (one hand stops
// both), else the second note's own. Empty when no note has a second voice.
std::vector<NoteFingering> TranscribeSecondVoice(const InstrumentModel& model,
                                                 const std::vector<NoteFingering>& first,
                                                 const std::vector<FrameContact>& second,
                                                 double a4_hz);

}  // namespace arco::refine
