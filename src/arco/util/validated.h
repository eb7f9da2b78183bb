// Options that passed their Validate(), checked once where a command or call enters
// (docs/architecture.md, "Validation rules"): `arco run` checks its RunOptions when its
// command line is parsed and hands the checked copy to RunCapture, which then does not
// check them again, nor do the stages it calls. Only Check makes one, so a function that
// takes a Validated<Options> needs no check of its own.
#pragma once

#include <utility>

#include "arco/util/status.h"

namespace arco {

template <typename Options>
class Validated {
 public:
  // `options` when options.Validate() is ok; its error otherwise.
  static StatusOr<Validated> Check(Options options) {
    const Status valid = options.Validate();
    if (!valid.ok()) return valid;
    return Validated(std::move(options));
  }

  const Options& get() const { return options_; }
  const Options& operator*() const { return options_; }
  const Options* operator->() const { return &options_; }

 private:
  explicit Validated(Options options) : options_(std::move(options)) {}
  Options options_;
};

}  // namespace arco
