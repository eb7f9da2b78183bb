#include "arco/cli/number_option.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace arco::cli {

CLI::Validator RangeValidator(const NumberRange& range, bool integer) {
  const std::string range_text = range.ToString();
  return CLI::Validator(
      [range, integer, range_text](std::string& text) -> std::string {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        const bool number = !text.empty() && end == text.c_str() + text.size();
        if (!number) {
          return "'" + text + "' is not a " + (integer ? "whole number" : "number") + " in " +
                 range_text;
        }
        if (!std::isfinite(value)) return text + " is not a finite number in " + range_text;
        if (!range.Contains(value)) return text + " is outside " + range_text;
        if (integer && value != std::floor(value)) {
          return text + " is not a whole number in " + range_text;
        }
        return std::string();
      },
      range_text,
      kRangeValidatorName);
}

}  // namespace arco::cli
