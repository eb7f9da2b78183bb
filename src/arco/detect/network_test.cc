#include "arco/detect/network.h"

#include <gtest/gtest.h>

namespace arco::detect {
namespace {

TEST(NetworkLoad, MissingFileNamesItAndScriptsSetup) {
  StatusOr<Network> network = Network::Load(ModelId::kPoseDetection, "/nonexistent/models");
  ASSERT_FALSE(network.ok());
  EXPECT_EQ(network.status().message(),
            "/nonexistent/models/pose_detection.onnx: model file not found; run "
            "scripts/setup to fetch and convert the models (docs/detect.md)");
}

}  // namespace
}  // namespace arco::detect
