// Tests on the real models (detect_test): skip only when the models are absent and CI
// is unset; under CI they must run (make test runs scripts/setup, which fetches them).
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "arco/detect/model_registry.h"

namespace arco::detect {

inline bool ModelsPresentOrSkip(std::string* why) {
  for (const ModelInfo& info : AllModels()) {
    const std::string path = ModelPath(info.id);
    if (!std::filesystem::exists(path)) {
      *why = path + " is missing: run scripts/setup to fetch and convert the models";
      const char* ci = std::getenv("CI");
      if (ci != nullptr && ci[0] != '\0') {
        ADD_FAILURE() << *why << " (CI is set, so this is a failure)";
      }
      return false;
    }
  }
  return true;
}

}  // namespace arco::detect

#define ARCO_REQUIRE_MODELS()                                                      \
  do {                                                                             \
    std::string arco_why;                                                          \
    if (!::arco::detect::ModelsPresentOrSkip(&arco_why)) GTEST_SKIP() << arco_why; \
  } while (0)
