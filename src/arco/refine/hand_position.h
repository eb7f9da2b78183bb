// The hand position of a transcribed note: position_semitones is where finger 1 stands,
// in semitones above the open string (docs/refine.md; the synthetic truth's notes.csv
// uses the same definition, synth/fingering.h). A stopped note and its finger give it
// directly where the finger reaches one semitone from finger 1 (cello, double bass,
// fingers 1 and 4 of the violin and viola), but the violin's and viola's 2nd and 3rd
// fingers each reach two (1-2 and 3-4 semitones: "low" and "high" 2 and 3), so the
// note alone leaves the position open by a semitone. A player's hand stays where it is
// until it shifts, so the positions of a phrase are decoded together (util/viterbi.h):
// each shift costs 1 plus 0.1 per semitone; ties go to the lowest position (the
// largest reach, FingerOffsetSemitones).
#pragma once

#include <vector>

#include "arco/registry/instruments.h"

namespace arco::refine {

struct StoppedNote {
  double semitones_on_string = 0;  // the sounding pitch above the open string (may be fractional)
  int finger = 1;                  // 1..4
};

// One position per note, in order (semitones_on_string - the chosen reach).
std::vector<double> HandPositionsSemitones(InstrumentKind kind,
                                           const std::vector<StoppedNote>& notes);

}  // namespace arco::refine
