#include "arco/refine/hand_position.h"

#include <cmath>
#include <cstdlib>

#include "arco/util/viterbi.h"

namespace arco::refine {
namespace {

constexpr double kShiftCost = 1.0;             // per change of hand position
constexpr double kShiftCostPerSemitone = 0.1;  // and per semitone shifted
constexpr double kExtensionCost = 0.4;         // per note with an extended hand frame

}  // namespace

std::vector<double> HandPositionsSemitones(InstrumentKind kind,
                                           const std::vector<StoppedNote>& notes) {
  std::vector<std::vector<FingerSpan>> reach(notes.size());
  std::vector<int> num_states(notes.size());
  for (size_t i = 0; i < notes.size(); ++i) {
    reach[i] = FingerReaches(kind, notes[i].finger);
    num_states[i] = static_cast<int>(reach[i].size());
  }
  // Candidate k of note t: the position with finger reaching reach[t][k] (largest first).
  auto position = [&](size_t t, int k) {
    return notes[t].semitones_on_string - reach[t][static_cast<size_t>(k)].offset_semitones;
  };
  const ViterbiPath path = DecodeViterbi(
      num_states,
      [&](size_t t, int k) {
        return reach[t][static_cast<size_t>(k)].extended ? kExtensionCost : 0.0;
      },
      [&](size_t t, int j, int k) {
        const long shift = std::lround(position(t, k)) - std::lround(position(t - 1, j));
        return shift == 0 ? 0.0 : kShiftCost + kShiftCostPerSemitone * std::labs(shift);
      });
  std::vector<double> out(notes.size());
  for (size_t t = 0; t < notes.size(); ++t) out[t] = position(t, path.states[t]);
  return out;
}

}  // namespace arco::refine
