#include "arco/util/number_range.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace arco {

bool NumberRange::Contains(double value) const {
  if (!std::isfinite(value)) return false;
  const bool above_min = min_open ? value > min : value >= min;
  const bool below_max = max_open ? value < max : value <= max;
  return above_min && below_max;
}

std::string NumberText(double value) {
  char text[64];
  if (std::isfinite(value) && value == std::floor(value) && std::abs(value) <= 1e16) {
    std::snprintf(text, sizeof text, "%.0f", value);  // whole numbers in full: 1000, 2^53
    return text;
  }
  // Otherwise the shortest form that reads back as the same double (2^53 in full, 0.2 not 0.2000...1).
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, value);
    if (!std::isfinite(value) || std::strtod(text, nullptr) == value) break;
  }
  return text;
}

std::string NumberRange::ToString() const {
  return std::string(min_open ? "(" : "[") + NumberText(min) + ", " + NumberText(max) +
         (max_open ? ")" : "]");
}

Status CheckInRange(std::string_view field, double value, const NumberRange& range) {
  if (range.Contains(value)) return Status::Ok();
  return Status::Error(std::string(field) + " must be a finite number in " + range.ToString() +
                       ", got " + NumberText(value));
}

}  // namespace arco
