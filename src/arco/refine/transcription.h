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

}  // namespace arco::refine
