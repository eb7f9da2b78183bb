// Pitch <-> finger position on a string (the paper's Eq. 2, P = F L_fund / L_vib).
//
// Distances are measured ALONG THE STRING FROM THE BRIDGE, in mm. For the ideal string
// (Mersenne's law, f = sqrt(T/mu) / (2 l); Fletcher & Rossing, "The Physics of Musical
// Instruments", 2nd ed. 1998, ch. 2) the vibrating length that sounds f is
//     L_vib = L * f_open / f,
// so the octave sits exactly half way and two octaves a quarter of the way from the bridge.
//
// Optional physical correction (ContactOptions::physical_correction), off by default:
// 1. Pressing the string onto the fingerboard. At a stop x from the bridge (d = L - x from
//    the nut) the string is pushed down by its height h(d) above the board (string heights
//    in StringSetup, linear along the fingerboard). It becomes two straight pieces
//    a = sqrt(x^2 + h^2) and b = sqrt(d^2 + h^2), so it stretches by delta = a + b - L and,
//    by Hooke's law, its tension rises to T' = T (1 + (EA/T) delta / L). With Mersenne's law
//        f / f_open = (L / a) * sqrt(1 + (EA/T) delta / L).
//    Pressing makes a note sharp (a few cents mid-string on a cello with EA/T = 100), so the
//    finger sits slightly nearer the nut than the ideal formula says. The same stretching
//    model is used for intonation compensation of fretted instruments. Ignored: bending
//    stiffness (inharmonicity, < 1 cent for these strings), the change of mass per length.
// 2. The finger pad. The string vibrates from the bridge to the bridge-side edge of the
//    finger's contact patch; the pad centre (what a hand model's fingertip approximates)
//    lies StringSetup::pad_centre_offset_mm further toward the nut.
// ContactPoint and PitchAtContact are exact inverses of each other with or without the
// correction (the corrected inverse is solved by bisection to 1e-9 mm), except that the
// corrected model keeps the stop at least max(5 mm, 2 x pad offset) from the nut (the
// finger's contact patch must fit): pitches less than about half a semitone above the
// open string that ContactOptions still calls stopped are clamped there.
#pragma once

#include <vector>

#include "arco/instrument/instrument_model.h"
#include "arco/util/status.h"

namespace arco {

struct ContactOptions {
  // Within this many cents of the open string the note is taken as the open string (no
  // finger). Must be below 100 (a semitone is the first stopped note). The SPD code uses
  // |f_open / f - 1| < 0.04, about 68 cents.
  double open_tolerance_cents = 40.0;
  // A pitch up to this many cents above a string's range top still counts as in range
  // (the SPD code allows 50 cents).
  double range_tolerance_cents = 50.0;
  bool physical_correction = false;  // see the header comment

  // Errors: tolerances negative, non-finite, or open_tolerance_cents >= 100.
  Status Validate() const;
};

// Why a pitch does or does not give a finger contact on a string.
enum class ContactKind {
  kStopped,      // a finger stops the string: contact_from_bridge_mm is valid
  kOpenString,   // within open_tolerance_cents of the open string: no finger contact
  kBelowString,  // lower than the open string: not playable on this string
  kAboveRange,   // above the string's playable range (+ tolerance)
  kNoPitch,      // f0 not finite or <= 0 (unvoiced frame)
};
const char* ContactKindName(ContactKind kind);

struct Contact {
  ContactKind kind = ContactKind::kNoPitch;
  int string = 0;  // 1 = highest
  double f0_hz = 0;
  double cents_from_open = 0;  // NaN for kNoPitch
  // Bridge to the point where the string stops vibrating (the vibrating length). The
  // string length for kOpenString; NaN unless kStopped or kOpenString.
  double stop_from_bridge_mm = 0;
  // Bridge to the finger-pad centre; equals stop_from_bridge_mm without the physical
  // correction. NaN unless kStopped.
  double contact_from_bridge_mm = 0;
  // contact_from_bridge_mm / string length: the fraction of the nut - bridge segment
  // (0 at the bridge, 1 at the nut), for StringSegment::PointAtFraction. NaN unless kStopped.
  double fraction_from_bridge = 0;

  bool stopped() const { return kind == ContactKind::kStopped; }
};

// Where a finger must press on `string` (1 = highest) to sound f0_hz. Never throws for any
// f0_hz (NaN gives kNoPitch); throws std::invalid_argument for a bad string number or
// options that fail Validate().
Contact ContactPoint(const InstrumentModel& model,
                     int string,
                     double f0_hz,
                     const ContactOptions& options = {});

// The inverse: the pitch sounded when the finger-pad centre is contact_from_bridge_mm from
// the bridge. NaN when that point is not on the stoppable part of the string (beyond the
// nut; with the correction also within the pad offset of the bridge or closer to the nut
// than the clamp described above).
double PitchAtContact(const InstrumentModel& model,
                      int string,
                      double contact_from_bridge_mm,
                      const ContactOptions& options = {});

// ContactPoint on every string, string 1 first (the candidates of the paper's step 5:
// keep those with stopped() or kOpenString).
std::vector<Contact> ContactCandidates(const InstrumentModel& model,
                                       double f0_hz,
                                       const ContactOptions& options = {});

}  // namespace arco
