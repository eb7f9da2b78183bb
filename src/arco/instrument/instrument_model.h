// Bowed-string instrument models: violin, viola, cello, double bass.
//
// Conventions (docs/DOMAIN.md sections 3 and 5):
// - Strings are numbered from the HIGHEST: string 1 is the cello's A, the violin's E;
//   string 4 is the lowest (cello C, violin G). Arrays indexed by string use
//   index = string - 1. (The SPD contact stage writes strings from the lowest, string 4,
//   to the highest, string 1: convert with SpdOrderToString().)
// - Lengths are in millimetres, frequencies in Hz, pitch offsets in cents
//   (100 cents = one equal-tempered semitone).
// - Lateral string offsets are measured from the instrument's centre line, positive toward
//   the LOW-string side (the +y axis of the instrument frame, see strings.h).
//
// The model is immutable once created (Create validates the options); the typical sizes
// come from DOMAIN.md section 5 and common luthier setups (see instrument_model.cc).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "arco/registry/instruments.h"
#include "arco/util/status.h"

namespace arco {

// InstrumentKind, ParseInstrumentKind and InstrumentKindName: registry/instruments.h.

// Open-string tuning. Standard tuning is equal temperament from `a4_hz`; scordatura per
// string either as an offset in cents or as an explicit frequency.
struct TuningOptions {
  double a4_hz = 440.0;  // concert pitch; baroque 415, some orchestras 442-443
  // Per-string offsets in cents from standard tuning, index = string - 1 (string 1 =
  // highest). Empty = none. E.g. Kodaly's cello sonata: {0, 0, -100, -100} (G->F#, C->B).
  std::vector<double> offset_cents;
  // Explicit open-string frequencies, index = string - 1; 0 = not given (use the standard
  // frequency plus offset_cents). Empty = none.
  std::vector<double> open_hz;

  // Errors: a4_hz outside [300, 600] Hz, vectors of the wrong length, non-finite values,
  // negative explicit frequencies.
  Status Validate(int num_strings) const;
};

// Where the playable range of each string ends.
struct RangeOptions {
  double semitones_above_open = 24.0;  // two octaves, as the SPD authors (E5 -> E7 on violin)
  // Per-string explicit top frequency (index = string - 1), 0 = use semitones_above_open.
  // E.g. violin E string beyond E7: {3520, 0, 0, 0}.
  std::vector<double> max_hz;
  Status Validate(int num_strings) const;
};

// Setup values used only by the optional physical correction of contact points
// (contact.h). Typical values per instrument are filled in by InstrumentModel::Create
// when left at 0; see instrument_model.cc for their sources.
struct StringSetup {
  double height_at_nut_mm = 0;  // string above the fingerboard at the nut
  // Height at the end of the fingerboard, for the highest and the lowest string (the other
  // strings are interpolated linearly by position).
  double height_at_fingerboard_end_high_mm = 0;
  double height_at_fingerboard_end_low_mm = 0;
  double fingerboard_length_mm = 0;  // measured from the nut along the strings
  // Axial stiffness over tension, E*A/T (dimensionless): how much a string's tension rises
  // when pressing it down stretches it (contact.h). Order of 10^2 for steel-core strings.
  double stiffness_over_tension = 0;
  // Distance from the string's stopping point (bridge-side edge of the finger's contact
  // patch) to the centre of the finger pad, toward the nut: about half the patch width.
  double pad_centre_offset_mm = 0;
  // Radius of the bridge's top arch through the strings (the curve that lets the bow
  // touch one string at a time): the inclination of a bow on each string
  // (InstrumentModel::BowInclinationRad).
  double bridge_arch_radius_mm = 0;
};

struct InstrumentOptions {
  InstrumentKind kind = InstrumentKind::kCello;
  TuningOptions tuning;
  RangeOptions range;
  // 0 = the instrument's typical value (DOMAIN.md section 5 and instrument_model.cc).
  double string_length_mm = 0;   // vibrating length of the open string, nut to bridge
  double nut_spacing_mm = 0;     // centre of the lowest to centre of the highest string
  double bridge_spacing_mm = 0;  // same, on the bridge
  StringSetup setup;             // zero fields = typical values

  Status Validate() const;
};

class InstrumentModel {
 public:
  // Fills typical values for zero fields, validates, precomputes open frequencies.
  static StatusOr<InstrumentModel> Create(const InstrumentOptions& options);
  // Standard instrument by name (ParseInstrumentKind), A4 = 440 Hz.
  static StatusOr<InstrumentModel> Create(std::string_view name);

  InstrumentKind kind() const { return kind_; }
  const char* name() const { return InstrumentKindName(kind_); }
  int num_strings() const { return static_cast<int>(open_hz_.size()); }

  // All per-string accessors take string = 1..num_strings() (1 = highest) and throw
  // std::invalid_argument otherwise.
  double open_hz(int string) const;
  double max_hz(int string) const;
  // Standard note name of the open string, e.g. "A3" (before scordatura).
  const std::string& open_note_name(int string) const;
  // Lateral offset of the string from the centre line at the nut / bridge, positive toward
  // the low-string side. Strings are evenly spaced centre to centre within the spacing.
  double LateralOffsetAtNutMm(int string) const;
  double LateralOffsetAtBridgeMm(int string) const;

  double string_length_mm() const { return string_length_mm_; }
  double nut_spacing_mm() const { return nut_spacing_mm_; }
  double bridge_spacing_mm() const { return bridge_spacing_mm_; }
  const StringSetup& setup() const { return setup_; }
  // String height above the fingerboard at a distance from the nut (linear from the nut to
  // the fingerboard end, constant beyond), interpolated between high and low strings.
  double StringHeightMm(int string, double from_nut_mm) const;
  // Inclination of a bow that touches only `string`: the tangent to the bridge's arch
  // (a circle of setup().bridge_arch_radius_mm through the strings) at the string,
  // measured across the strings (the instrument frame's y-z plane) from the string plane
  // toward the front (+z) as y decreases: positive on the high-string side, 0 at the
  // centre line. A bow line with direction u has the inclination atan(u_z / u_y).
  double BowInclinationRad(int string) const;

  // SPD instrument keypoints, in SPD order (DOMAIN.md section 3): the points after the
  // body in the instrument's spd_* keypoint layout (registry/keypoint_layout.h). Cello and
  // double bass: scroll_top, nut_l, nut_r, bridge_l, bridge_r, tail_gut, end_pin, frog,
  // tip; violin and viola: scroll_top, nut_l, nut_r, bridge_l, bridge_r, frog, tip.
  const std::vector<std::string>& keypoint_names() const { return keypoint_names_; }
  // Index into keypoint_names(), or -1.
  int KeypointIndex(std::string_view name) const;
  // Keypoints fixed to the instrument body (all but the bow's frog and tip): the ones a
  // rigid template may use.
  const std::vector<int>& rigid_keypoints() const { return rigid_keypoints_; }
  int nut_l() const { return KeypointIndex("nut_l"); }
  int nut_r() const { return KeypointIndex("nut_r"); }
  int bridge_l() const { return KeypointIndex("bridge_l"); }
  int bridge_r() const { return KeypointIndex("bridge_r"); }

  // SPD writes strings lowest first: SPD position 0 is string num_strings().
  int SpdOrderToString(int spd_position) const;

 private:
  void CheckString(int string) const;

  InstrumentKind kind_ = InstrumentKind::kCello;
  std::vector<double> open_hz_;  // index = string - 1
  std::vector<double> max_hz_;
  std::vector<std::string> open_note_names_;
  double string_length_mm_ = 0;
  double nut_spacing_mm_ = 0;
  double bridge_spacing_mm_ = 0;
  StringSetup setup_;
  std::vector<std::string> keypoint_names_;
  std::vector<int> rigid_keypoints_;
};

// Equal-tempered frequency of a MIDI note: a4_hz * 2^((midi - 69) / 12).
double MidiToHz(double midi_note, double a4_hz = 440.0);
// Signed interval from `reference_hz` to `f_hz` in cents: 1200 log2(f / reference).
double CentsBetween(double reference_hz, double f_hz);

}  // namespace arco
