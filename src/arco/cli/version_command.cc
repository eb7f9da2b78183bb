// `arco info`: build and library facts (a quick check that set-up worked).
#include <Eigen/Core>
#include <cstdio>

#include "arco/cli/build_info.h"
#include "arco/cli/command.h"
#include "arco/util/data_dir.h"

namespace arco::cli {
namespace {

std::function<int()> SetupInfo(CLI::App& app) {
  app.add_subcommand("info",
                     "Print the version, the source revision, the versions of linked libraries "
                     "and the data folder in use");
  return [] {
    const std::string data = DataDir();
    std::printf("%s\nEigen %d.%d.%d\ndata: %s\n",
                VersionLine().c_str(),
                EIGEN_WORLD_VERSION,
                EIGEN_MAJOR_VERSION,
                EIGEN_MINOR_VERSION,
                data.empty() ? "the source tree (a build-tree arco)" : data.c_str());
    return 0;
  };
}

}  // namespace
ARCO_REGISTER_COMMAND(info, 1000, SetupInfo);
}  // namespace arco::cli
