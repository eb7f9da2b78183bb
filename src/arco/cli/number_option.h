// Every numeric flag of every command is added through AddNumber, with its declared range
// (util/number_range.h): the range is checked on the text as given, before CLI11 converts
// it, so NaN, infinities, values that would wrap an unsigned ("-1" for a seed), huge values
// and text are rejected with one line naming the flag, the value and the range
// ("--fps: nan is not a finite number in (0, 1000]"), and `--help` shows the range after
// the type ("FLOAT:(0, 1000]"). app_test.cc fails for a numeric flag added without one.
#pragma once

#include <string>
#include <type_traits>
#include <vector>

#include <CLI/CLI.hpp>

#include "arco/util/number_range.h"

namespace arco::cli {

// The name of the range validator on a numeric option (CLI::Option::get_validator).
inline constexpr char kRangeValidatorName[] = "range";

// Checks one value's text: a number (a whole number when `integer`), finite, in `range`.
CLI::Validator RangeValidator(const NumberRange& range, bool integer);

template <typename T>
struct NumberElement {
  using type = T;
};
template <typename T>
struct NumberElement<std::vector<T>> {
  using type = T;
};

// cmd->add_option(flags, value, description) with `range` checked on every value given
// (each element of a list).
template <typename T>
CLI::Option* AddNumber(CLI::App* cmd,
                       const std::string& flags,
                       T& value,
                       const std::string& description,
                       const NumberRange& range) {
  using Element = typename NumberElement<T>::type;
  static_assert(std::is_arithmetic_v<Element> && !std::is_same_v<Element, bool>,
                "AddNumber is for numbers; flags and text use add_flag / add_option");
  return cmd->add_option(flags, value, description)
      ->check(RangeValidator(range, std::is_integral_v<Element>));
}

}  // namespace arco::cli

namespace arco::cli {

// Ranges several commands share (one definition each).
inline constexpr NumberRange kThreadsRange = Closed(0, 1024);     // 0 = all cores
inline constexpr NumberRange kVideoFpsRange = AboveZero(1000);    // frames per second
inline constexpr NumberRange kFractionRange = Closed(0, 1);       // confidences, rates
inline constexpr NumberRange kAudioTimeRangeS = Closed(-86400, 86400);  // offsets: +-1 day
inline constexpr NumberRange kFrameCountRange = Closed(0, 1e9);   // frame numbers and counts
// --min-confidence of run and refine: not below the pitch model's in-note threshold
// (refine::PitchModelOptions::min_confidence_in_note, 0.2), which Validate() requires.
inline constexpr NumberRange kMinConfidenceRange = Closed(0.2, 1);

// Throws CLI::ValidationError with `status`'s message (a command's Validate() in its
// parse-complete callback, so that a bad combination fails the parse, before any work).
inline void ThrowIfInvalid(const Status& status) {
  if (!status.ok()) throw CLI::ValidationError(status.message());
}

}  // namespace arco::cli
