// `arco info`: build and library facts (a quick check that set-up worked).
#include <Eigen/Core>
#include <cstdio>

#include "arco/cli/command.h"

namespace arco::cli {
namespace {

std::function<int()> SetupInfo(CLI::App& app) {
  app.add_subcommand("info", "Print version and the versions of linked libraries");
  return [] {
    std::printf("arco 0.1.0\nEigen %d.%d.%d\n", EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION,
                EIGEN_MINOR_VERSION);
    return 0;
  };
}

}  // namespace
ARCO_REGISTER_COMMAND(info, 1000, SetupInfo);
}  // namespace arco::cli
