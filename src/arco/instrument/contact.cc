#include "arco/instrument/contact.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace arco {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// f / f_open for a stop x mm from the bridge (header comment, item 1).
double CorrectedRatio(const InstrumentModel& model, int string, double stop_from_bridge_mm) {
  const double length = model.string_length_mm();
  const double x = stop_from_bridge_mm;
  const double d = length - x;
  const double h = model.StringHeightMm(string, d);
  const double a = std::hypot(x, h);
  const double b = std::hypot(d, h);
  const double stretch_mm = a + b - length;
  const double q = model.setup().stiffness_over_tension;
  return (length / a) * std::sqrt(1.0 + q * stretch_mm / length);
}

// Closest stop to the nut the corrected model accepts: the finger's contact patch (twice
// the pad-centre offset) must fit between the nut and the stop, and at least 5 mm. Nearer
// the nut the straight-segment stretch model breaks down (it would make a stop at the nut
// itself sound sharper than one a few mm away).
double MinStopFromNutMm(const InstrumentModel& model) {
  return std::max(5.0, 2.0 * model.setup().pad_centre_offset_mm);
}

// Stop position sounding `ratio` = f / f_open under the corrected model, by bisection on
// [tiny, L - MinStopFromNutMm], where the ratio falls monotonically toward the nut. Pitches
// below what that last stop gives (less than about half a semitone above the open string)
// are clamped to it.
double CorrectedStop(const InstrumentModel& model, int string, double ratio) {
  const double length = model.string_length_mm();
  double lo = 1e-6 * length;  // ratio very large here
  double hi = length - MinStopFromNutMm(model);
  if (CorrectedRatio(model, string, hi) >= ratio) return hi;
  for (int i = 0; i < 200 && hi - lo > 1e-10; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (CorrectedRatio(model, string, mid) > ratio) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

void ValidateOrThrow(const ContactOptions& options) {
  const Status status = options.Validate();
  if (!status.ok()) throw std::invalid_argument(status.message());
}

}  // namespace

Status ContactOptions::Validate() const {
  if (!std::isfinite(open_tolerance_cents) || open_tolerance_cents < 0 ||
      open_tolerance_cents >= 100.0) {
    return Status::Error("contact options: open_tolerance_cents must be in [0, 100)");
  }
  if (!std::isfinite(range_tolerance_cents) || range_tolerance_cents < 0) {
    return Status::Error("contact options: range_tolerance_cents must be >= 0");
  }
  return Status::Ok();
}

const char* ContactKindName(ContactKind kind) {
  switch (kind) {
    case ContactKind::kStopped:
      return "stopped";
    case ContactKind::kOpenString:
      return "open_string";
    case ContactKind::kBelowString:
      return "below_string";
    case ContactKind::kAboveRange:
      return "above_range";
    case ContactKind::kNoPitch:
      return "no_pitch";
  }
  return "unknown";
}

Contact ContactPoint(const InstrumentModel& model,
                     int string,
                     double f0_hz,
                     const ContactOptions& options) {
  ValidateOrThrow(options);
  const double open_hz = model.open_hz(string);  // throws on a bad string number
  Contact c;
  c.string = string;
  c.f0_hz = f0_hz;
  c.stop_from_bridge_mm = kNaN;
  c.contact_from_bridge_mm = kNaN;
  c.fraction_from_bridge = kNaN;
  if (!std::isfinite(f0_hz) || f0_hz <= 0) {
    c.kind = ContactKind::kNoPitch;
    c.cents_from_open = kNaN;
    return c;
  }
  c.cents_from_open = CentsBetween(open_hz, f0_hz);
  const double length = model.string_length_mm();
  if (std::abs(c.cents_from_open) <= options.open_tolerance_cents) {
    c.kind = ContactKind::kOpenString;
    c.stop_from_bridge_mm = length;
    return c;
  }
  if (c.cents_from_open < 0) {
    c.kind = ContactKind::kBelowString;
    return c;
  }
  if (CentsBetween(model.max_hz(string), f0_hz) > options.range_tolerance_cents) {
    c.kind = ContactKind::kAboveRange;
    return c;
  }
  c.kind = ContactKind::kStopped;
  const double ratio = f0_hz / open_hz;
  if (options.physical_correction) {
    c.stop_from_bridge_mm = CorrectedStop(model, string, ratio);
    c.contact_from_bridge_mm = c.stop_from_bridge_mm + model.setup().pad_centre_offset_mm;
  } else {
    c.stop_from_bridge_mm = length / ratio;  // L_vib = L f_open / f
    c.contact_from_bridge_mm = c.stop_from_bridge_mm;
  }
  c.fraction_from_bridge = c.contact_from_bridge_mm / length;
  return c;
}

double PitchAtContact(const InstrumentModel& model,
                      int string,
                      double contact_from_bridge_mm,
                      const ContactOptions& options) {
  ValidateOrThrow(options);
  const double open_hz = model.open_hz(string);
  const double length = model.string_length_mm();
  if (!std::isfinite(contact_from_bridge_mm) || contact_from_bridge_mm > length) return kNaN;
  if (!options.physical_correction) {
    if (contact_from_bridge_mm <= 0) return kNaN;
    return open_hz * length / contact_from_bridge_mm;
  }
  const double stop = contact_from_bridge_mm - model.setup().pad_centre_offset_mm;
  if (stop <= 0 || stop > length - MinStopFromNutMm(model)) return kNaN;
  return open_hz * CorrectedRatio(model, string, stop);
}

std::vector<Contact> ContactCandidates(const InstrumentModel& model,
                                       double f0_hz,
                                       const ContactOptions& options) {
  std::vector<Contact> out;
  out.reserve(model.num_strings());
  for (int s = 1; s <= model.num_strings(); ++s) {
    out.push_back(ContactPoint(model, s, f0_hz, options));
  }
  return out;
}

}  // namespace arco
