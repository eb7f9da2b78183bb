// The declared range of a numeric option: every number an options struct or a CLI flag
// takes has one, and a value outside it (NaN and infinities included) is rejected with one
// line naming the field or flag, the value and the range (docs/architecture.md,
// "Validation rules"). Options structs check their fields with CheckInRange in Validate();
// the CLI declares the same range on the flag (cli/number_option.h), so `--help` shows it.
#pragma once

#include <limits>
#include <string>
#include <string_view>

#include "arco/util/status.h"

namespace arco {

struct NumberRange {
  double min = 0;
  double max = 0;
  bool min_open = false;  // (min, ...: min itself is outside
  bool max_open = false;  // ..., max): max itself is outside

  // False for NaN and for infinities (every range is finite).
  bool Contains(double value) const;
  // "[0, 1]", "(0, 1000]", "[-120, 0]".
  std::string ToString() const;
};

// Closed [min, max] and half-open (min, max].
constexpr NumberRange Closed(double min, double max) { return {min, max, false, false}; }
constexpr NumberRange AboveZero(double max) { return {0, max, true, false}; }

// The largest integer a double holds exactly (2^53): the top of an integer range that must
// not wrap (seeds, counts).
inline constexpr double kMaxExactInteger = 9007199254740992.0;

// `value` formatted for a message ("nan", "inf", "-3", "0.25", "1e+300").
std::string NumberText(double value);

// Ok, or "FIELD must be a finite number in RANGE, got VALUE".
Status CheckInRange(std::string_view field, double value, const NumberRange& range);

}  // namespace arco
