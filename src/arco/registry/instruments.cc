#include "arco/registry/instruments.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>
#include <stdexcept>

namespace arco {
namespace {

std::string Lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

const std::vector<InstrumentInfo>& AllInstruments() {
  // Open strings: DOMAIN.md section 5. GM programs 40-43 (0-based). Pitch search ranges:
  // see PitchSearchRange. Hand frames: docs/synth.md (fingering).
  static const auto* instruments = new std::vector<InstrumentInfo>{
      {InstrumentKind::kViolin,
       "violin",
       {55, 62, 69, 76},
       {"G3", "D4", "A4", "E5"},
       40,
       "spd_violin",
       {180.0, 4200.0, 32000},
       {{1, 0, false},
        {2, 1, false},
        {2, 2, false},
        {3, 3, false},
        {3, 4, false},
        {4, 5, false},
        {4, 6, true}}},
      {InstrumentKind::kViola,
       "viola",
       {48, 55, 62, 69},
       {"C3", "G3", "D4", "A4"},
       41,
       "spd_violin",
       {120.0, 2800.0, 24000},
       {{1, 0, false},
        {2, 1, false},
        {2, 2, false},
        {3, 3, false},
        {3, 4, false},
        {4, 5, false},
        {4, 6, true}}},
      {InstrumentKind::kCello,
       "cello",
       {36, 43, 50, 57},
       {"C2", "G2", "D3", "A3"},
       42,
       "spd_cello",
       {60.0, 2000.0, 16000},
       {{1, 0, false},
        {2, 1, false},
        {3, 2, false},
        {4, 3, false},
        {2, 2, true},
        {3, 3, true},
        {4, 4, true}},
       /*frame_spacing_in_mm=*/true},
      // Simandl: in the lower positions the bass hand spans a whole tone (a semitone is
      // about 59 mm at the nut of a 1050 mm string, against 39 mm on the cello), stopped
      // by fingers 1, 2 and 4; the third finger stops with the fourth.
      {InstrumentKind::kDoubleBass,
       "double_bass",
       {28, 33, 38, 43},
       {"E1", "A1", "D2", "G2"},
       43,
       "spd_cello",
       {38.0, 1200.0, 16000},
       {{1, 0, false}, {2, 1, false}, {4, 2, false}},
       /*frame_spacing_in_mm=*/true},
  };
  return *instruments;
}

const InstrumentInfo& GetInstrumentInfo(InstrumentKind kind) {
  for (const InstrumentInfo& info : AllInstruments()) {
    if (info.kind == kind) return info;
  }
  throw std::invalid_argument("unknown InstrumentKind value");
}

StatusOr<InstrumentKind> ParseInstrumentKind(std::string_view name) {
  const std::string n = Lower(name);
  if (n == "violin") return InstrumentKind::kViolin;
  if (n == "viola") return InstrumentKind::kViola;
  if (n == "cello" || n == "violoncello") return InstrumentKind::kCello;
  if (n == "double_bass" || n == "double-bass" || n == "doublebass" || n == "bass" ||
      n == "contrabass") {
    return InstrumentKind::kDoubleBass;
  }
  return Status::Error("unknown instrument '" + std::string(name) +
                       "' (known: violin, viola, cello, double_bass)");
}

const char* InstrumentKindName(InstrumentKind kind) { return GetInstrumentInfo(kind).name; }

double FingerOffsetSemitones(InstrumentKind kind, int finger) {
  const std::vector<FingerSpan>& frame = GetInstrumentInfo(kind).hand_frame;
  const int k = std::clamp(finger, 0, 4);
  if (k == 0) return 0;
  for (int f = k; f <= 4; ++f) {
    int offset = -1;
    for (const FingerSpan& span : frame) {
      if (span.finger == f && !span.extended) offset = std::max(offset, span.offset_semitones);
    }
    if (offset >= 0) return offset;
  }
  throw std::logic_error("instrument hand frame without a fourth finger");
}

double HandPositionSemitones(InstrumentKind kind, int finger, double stop_semitones) {
  const double offset = FingerOffsetSemitones(kind, finger);
  if (!GetInstrumentInfo(kind).frame_spacing_in_mm) return stop_semitones - offset;
  constexpr double kFirstPositionSemitones = 2.0;  // finger 1 in the first position
  const double remaining = std::exp2(-stop_semitones / 12.0) +
                           std::exp2(-kFirstPositionSemitones / 12.0) -
                           std::exp2(-(kFirstPositionSemitones + offset) / 12.0);
  return -12.0 * std::log2(remaining);
}

std::vector<FingerSpan> FingerReaches(InstrumentKind kind, int finger) {
  const int k = std::clamp(finger, 0, 4);
  const int largest = static_cast<int>(FingerOffsetSemitones(kind, finger));
  std::vector<FingerSpan> closed{{k, largest, false}}, extended;
  for (const FingerSpan& span : GetInstrumentInfo(kind).hand_frame) {
    if (span.finger != k || span.offset_semitones == largest) continue;
    (span.extended ? extended : closed).push_back(span);
  }
  auto larger = [](const FingerSpan& a, const FingerSpan& b) {
    return a.offset_semitones > b.offset_semitones;
  };
  std::sort(closed.begin() + 1, closed.end(), larger);
  std::sort(extended.begin(), extended.end(), larger);
  closed.insert(closed.end(), extended.begin(), extended.end());
  return closed;
}

}  // namespace arco
