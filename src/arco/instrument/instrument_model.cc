#include "arco/instrument/instrument_model.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <stdexcept>

#include "arco/registry/keypoint_layout.h"

namespace arco {
namespace {

// Typical sizes. String lengths: DOMAIN.md section 5 (SPD uses 695 mm cello, 328 mm
// violin). Spacings are centre-to-centre of the outer strings on common setups (violin
// nut slots about 5.5 mm apart, Mayson "Violin Making" 1909; bridge about 11.3 mm; cello
// nut about 7.7 mm, bridge about 15.7 mm apart); the real frame-128 SPD labels measure
// 23.9 mm at the nut and 48.2 mm at the bridge on the cello. String heights above the
// fingerboard end: cello 4.0-5.5 mm (A) and 6.5-8.0 mm (C) depending on steel or gut
// strings (ICS cello setup notes), violin about 3.5 (E) and 5.5 mm (G); at the nut
// 0.5-0.75 mm on cello. Bridge arch radius: on SPD's real cello01 take the bow on the A
// string is inclined 30.2 degrees (median of 262 frames; docs/bowing.md) at 23.5 mm from
// the centre line, so R = 23.5 / sin(30.2 deg) = 46.8 mm; the other instruments are
// given the same ratio of radius to bridge spacing, an assumption no real take here
// checks. All of these vary per instrument: override them in the options.
// Open strings, names and keypoint layouts: registry/instruments.h.
struct Spec {
  InstrumentKind kind;
  double string_length_mm;
  double nut_spacing_mm;
  double bridge_spacing_mm;
  StringSetup setup;
};

// StringSetup fields: nut height, end height high, end height low, fingerboard length,
// EA/T, pad centre offset, bridge arch radius.
const Spec kSpecs[] = {
    {InstrumentKind::kViolin, 328.0, 16.5, 34.0, {0.4, 3.5, 5.5, 270.0, 100.0, 4.0, 34.0}},
    {InstrumentKind::kViola, 370.0, 17.5, 37.0, {0.5, 4.0, 6.0, 290.0, 100.0, 4.5, 37.0}},
    {InstrumentKind::kCello, 695.0, 23.0, 47.0, {0.6, 4.5, 7.0, 580.0, 100.0, 5.0, 46.8}},
    {InstrumentKind::kDoubleBass, 1050.0, 31.0, 85.0, {1.0, 6.0, 9.0, 880.0, 100.0, 6.0, 85.0}},
};

const Spec& SpecFor(InstrumentKind kind) {
  for (const Spec& spec : kSpecs) {
    if (spec.kind == kind) return spec;
  }
  throw std::invalid_argument("unknown InstrumentKind value");
}

Status CheckPerString(const std::vector<double>& values,
                      int num_strings,
                      const char* what,
                      bool allow_negative) {
  if (values.empty()) return Status::Ok();
  if (static_cast<int>(values.size()) != num_strings) {
    return Status::Error(std::string(what) + " has " + std::to_string(values.size()) +
                         " values; the instrument has " + std::to_string(num_strings) + " strings");
  }
  for (size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i]) || (!allow_negative && values[i] < 0)) {
      return Status::Error(std::string(what) + " for string " + std::to_string(i + 1) +
                           " is not a valid value");
    }
  }
  return Status::Ok();
}

double OrDefault(double value, double fallback) { return value > 0 ? value : fallback; }

}  // namespace

double MidiToHz(double midi_note, double a4_hz) {
  return a4_hz * std::pow(2.0, (midi_note - 69.0) / 12.0);
}

double CentsBetween(double reference_hz, double f_hz) {
  return 1200.0 * std::log2(f_hz / reference_hz);
}

Status TuningOptions::Validate(int num_strings) const {
  ARCO_RETURN_IF_ERROR(CheckInRange("tuning: a4_hz", a4_hz, kA4RangeHz));
  ARCO_RETURN_IF_ERROR(CheckPerString(offset_cents, num_strings, "tuning offset_cents", true));
  ARCO_RETURN_IF_ERROR(CheckPerString(open_hz, num_strings, "tuning open_hz", false));
  for (double c : offset_cents) {
    ARCO_RETURN_IF_ERROR(CheckInRange("tuning: offset_cents", c, kTuningOffsetRangeCents));
  }
  return Status::Ok();
}

Status RangeOptions::Validate(int num_strings) const {
  if (!(semitones_above_open > 0.0 && semitones_above_open <= 60.0)) {
    return Status::Error("range: semitones_above_open must be in (0, 60], got " +
                         std::to_string(semitones_above_open));
  }
  return CheckPerString(max_hz, num_strings, "range max_hz", false);
}

Status InstrumentOptions::Validate() const {
  (void)SpecFor(kind);  // throws on an out-of-range enum value
  const int n = 4;
  ARCO_RETURN_IF_ERROR(tuning.Validate(n));
  ARCO_RETURN_IF_ERROR(range.Validate(n));
  const double lengths[] = {string_length_mm,
                            nut_spacing_mm,
                            bridge_spacing_mm,
                            setup.height_at_nut_mm,
                            setup.height_at_fingerboard_end_high_mm,
                            setup.height_at_fingerboard_end_low_mm,
                            setup.fingerboard_length_mm,
                            setup.stiffness_over_tension,
                            setup.pad_centre_offset_mm,
                            setup.bridge_arch_radius_mm};
  for (double v : lengths) {
    if (!std::isfinite(v) || v < 0) {
      return Status::Error("instrument options: lengths must be finite and >= 0 (0 = typical)");
    }
  }
  return Status::Ok();
}

StatusOr<InstrumentModel> InstrumentModel::Create(const InstrumentOptions& options) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  const Spec& spec = SpecFor(options.kind);
  const InstrumentInfo& info = GetInstrumentInfo(options.kind);
  InstrumentModel m;
  m.kind_ = options.kind;
  const int n = 4;
  m.open_hz_.resize(n);
  m.max_hz_.resize(n);
  m.open_note_names_.resize(n);
  for (int s = 1; s <= n; ++s) {
    const int low_index = n - s;  // string 4 is the lowest
    double f =
        MidiToHz(info.open_midi_low_to_high[static_cast<size_t>(low_index)], options.tuning.a4_hz);
    if (!options.tuning.offset_cents.empty()) {
      f *= std::pow(2.0, options.tuning.offset_cents[s - 1] / 1200.0);
    }
    if (!options.tuning.open_hz.empty() && options.tuning.open_hz[s - 1] > 0) {
      f = options.tuning.open_hz[s - 1];
    }
    m.open_hz_[s - 1] = f;
    m.open_note_names_[s - 1] = info.open_notes_low_to_high[static_cast<size_t>(low_index)];
    double top = f * std::pow(2.0, options.range.semitones_above_open / 12.0);
    if (!options.range.max_hz.empty() && options.range.max_hz[s - 1] > 0) {
      top = options.range.max_hz[s - 1];
    }
    if (!(top > f)) {
      return Status::Error("range: the top of string " + std::to_string(s) +
                           " is not above its open frequency");
    }
    m.max_hz_[s - 1] = top;
  }
  m.string_length_mm_ = OrDefault(options.string_length_mm, spec.string_length_mm);
  m.nut_spacing_mm_ = OrDefault(options.nut_spacing_mm, spec.nut_spacing_mm);
  m.bridge_spacing_mm_ = OrDefault(options.bridge_spacing_mm, spec.bridge_spacing_mm);
  const StringSetup& in = options.setup;
  const StringSetup& typ = spec.setup;
  m.setup_.height_at_nut_mm = OrDefault(in.height_at_nut_mm, typ.height_at_nut_mm);
  m.setup_.height_at_fingerboard_end_high_mm =
      OrDefault(in.height_at_fingerboard_end_high_mm, typ.height_at_fingerboard_end_high_mm);
  m.setup_.height_at_fingerboard_end_low_mm =
      OrDefault(in.height_at_fingerboard_end_low_mm, typ.height_at_fingerboard_end_low_mm);
  m.setup_.fingerboard_length_mm = OrDefault(in.fingerboard_length_mm, typ.fingerboard_length_mm);
  m.setup_.stiffness_over_tension =
      OrDefault(in.stiffness_over_tension, typ.stiffness_over_tension);
  m.setup_.pad_centre_offset_mm = OrDefault(in.pad_centre_offset_mm, typ.pad_centre_offset_mm);
  m.setup_.bridge_arch_radius_mm = OrDefault(in.bridge_arch_radius_mm, typ.bridge_arch_radius_mm);
  if (!(m.setup_.bridge_arch_radius_mm > 0.5 * m.bridge_spacing_mm_)) {
    return Status::Error(
        "instrument options: bridge_arch_radius_mm must exceed half the bridge spacing");
  }
  if (m.setup_.fingerboard_length_mm >= m.string_length_mm_) {
    return Status::Error(
        "instrument options: fingerboard_length_mm must be shorter than the "
        "string length");
  }
  // The instrument's points follow the body in its SPD layout; the bow's frog and tip
  // are the "bow" group, the rigid ones the "instrument" group.
  const KeypointLayout* layout = FindKeypointLayout(info.spd_layout);
  if (!layout) throw std::logic_error(std::string("no keypoint layout ") + info.spd_layout);
  m.keypoint_names_.assign(layout->names.begin() + wholebody::kNumPoints, layout->names.end());
  for (int index : *layout->Group("instrument")) {
    m.rigid_keypoints_.push_back(index - wholebody::kNumPoints);
  }
  return m;
}

StatusOr<InstrumentModel> InstrumentModel::Create(std::string_view name) {
  ARCO_ASSIGN_OR_RETURN(InstrumentKind kind, ParseInstrumentKind(name));
  InstrumentOptions options;
  options.kind = kind;
  return Create(options);
}

void InstrumentModel::CheckString(int string) const {
  if (string < 1 || string > num_strings()) {
    throw std::invalid_argument("string number " + std::to_string(string) + " outside 1.." +
                                std::to_string(num_strings()) + " (1 = highest)");
  }
}

double InstrumentModel::open_hz(int string) const {
  CheckString(string);
  return open_hz_[string - 1];
}

double InstrumentModel::max_hz(int string) const {
  CheckString(string);
  return max_hz_[string - 1];
}

const std::string& InstrumentModel::open_note_name(int string) const {
  CheckString(string);
  return open_note_names_[string - 1];
}

// Position across the strings from the low side: 0 for the lowest, 1 for the highest.
static double AcrossFromLow(int string, int num_strings) {
  return static_cast<double>(num_strings - string) / (num_strings - 1);
}

double InstrumentModel::LateralOffsetAtNutMm(int string) const {
  CheckString(string);
  return (0.5 - AcrossFromLow(string, num_strings())) * nut_spacing_mm_;
}

double InstrumentModel::LateralOffsetAtBridgeMm(int string) const {
  CheckString(string);
  return (0.5 - AcrossFromLow(string, num_strings())) * bridge_spacing_mm_;
}

double InstrumentModel::BowInclinationRad(int string) const {
  // The arch z(y) = sqrt(R^2 - y^2) has the slope dz/dy = -y / sqrt(R^2 - y^2) at the
  // string's lateral offset y, i.e. the angle asin(-y / R).
  return std::asin(-LateralOffsetAtBridgeMm(string) / setup_.bridge_arch_radius_mm);
}

double InstrumentModel::StringHeightMm(int string, double from_nut_mm) const {
  CheckString(string);
  const double t = AcrossFromLow(string, num_strings());
  const double end =
      setup_.height_at_fingerboard_end_low_mm +
      t * (setup_.height_at_fingerboard_end_high_mm - setup_.height_at_fingerboard_end_low_mm);
  const double u = std::clamp(from_nut_mm / setup_.fingerboard_length_mm, 0.0, 1.0);
  return setup_.height_at_nut_mm + u * (end - setup_.height_at_nut_mm);
}

int InstrumentModel::KeypointIndex(std::string_view name) const {
  for (int k = 0; k < static_cast<int>(keypoint_names_.size()); ++k) {
    if (keypoint_names_[k] == name) return k;
  }
  return -1;
}

int InstrumentModel::SpdOrderToString(int spd_position) const {
  if (spd_position < 0 || spd_position >= num_strings()) {
    throw std::invalid_argument("SPD string position outside 0.." +
                                std::to_string(num_strings() - 1));
  }
  return num_strings() - spd_position;
}

}  // namespace arco
