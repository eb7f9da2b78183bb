// Score instruments for tests (open strings in MIDI numbers, DOMAIN.md section 5).
#pragma once

#include "arco/synth/score.h"

namespace arco::synth::testing {

inline ScoreInstrument Cello() { return {"cello", {36, 43, 50, 57}, 24, 42, 3}; }
inline ScoreInstrument Violin() { return {"violin", {55, 62, 69, 76}, 24, 40, 5}; }
inline ScoreInstrument Viola() { return {"viola", {48, 55, 62, 69}, 24, 41, 5}; }
inline ScoreInstrument Bass() { return {"double_bass", {28, 33, 38, 43}, 24, 43, 2}; }

}  // namespace arco::synth::testing
