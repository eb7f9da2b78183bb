#include "arco/refine/contact_annotation.h"

#include <cctype>

namespace arco::refine {

const char* RefineModeName(RefineMode mode) {
  switch (mode) {
    case RefineMode::kVision:
      return "vision";
    case RefineMode::kPaper:
      return "paper";
    case RefineMode::kArco:
      return "arco";
  }
  return "?";
}

StatusOr<RefineMode> ParseRefineMode(std::string_view name) {
  std::string lower;
  for (char c : name)
    lower.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  if (lower == "vision") return RefineMode::kVision;
  if (lower == "paper") return RefineMode::kPaper;
  if (lower == "arco") return RefineMode::kArco;
  return Status::Error("unknown refinement mode '" + std::string(name) +
                       "' (known: vision, paper, arco)");
}

const char* ContactStateName(ContactState state) {
  switch (state) {
    case ContactState::kPressed:
      return "pressed";
    case ContactState::kOpenString:
      return "open";
    case ContactState::kRest:
      return "rest";
    case ContactState::kUncertain:
      return "uncertain";
  }
  return "?";
}

const char* ContactReasonName(ContactReason reason) {
  switch (reason) {
    case ContactReason::kNone:
      return "";
    case ContactReason::kUnvoiced:
      return "unvoiced";
    case ContactReason::kLowConfidence:
      return "low_confidence";
    case ContactReason::kUnstablePitch:
      return "unstable_pitch";
    case ContactReason::kShortNote:
      return "short_note";
    case ContactReason::kUnplayable:
      return "unplayable";
    case ContactReason::kNoInstrument:
      return "no_instrument";
    case ContactReason::kNoHand:
      return "no_hand";
    case ContactReason::kOutOfReach:
      return "out_of_reach";
    case ContactReason::kBeforeOnset:
      return "before_onset";
    case ContactReason::kHandShifted:
      return "hand_shifted";
    case ContactReason::kNoteBoundary:
      return "note_boundary";
  }
  return "?";
}

std::string MidiNoteName(int midi_note) {
  static const char* kNames[12] = {"C", "C#", "D", "D#", "E", "F", "F#", "G", "G#", "A", "A#", "B"};
  const int pc = ((midi_note % 12) + 12) % 12;
  const int octave = (midi_note - pc) / 12 - 1;
  return std::string(kNames[pc]) + std::to_string(octave);
}

}  // namespace arco::refine
