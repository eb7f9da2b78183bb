#include "arco/util/npy.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "arco/testing/temp_dir.h"

namespace arco {
namespace {

using arco::testing::PerProcessTempDir;

TEST(Npy, RoundTripsFloatArrayWithNaN) {
  NpyArray<float> a;
  a.shape = {2, 3, 3};
  for (int i = 0; i < 18; ++i) a.data.push_back(static_cast<float>(i) * 0.5f);
  a.data[4] = NAN;
  const std::string path = PerProcessTempDir() + "/a.npy";
  ASSERT_TRUE(WriteNpy(path, a).ok());
  auto b = ReadNpy<float>(path);
  ASSERT_TRUE(b.ok()) << b.status().message();
  EXPECT_EQ(b->shape, a.shape);
  EXPECT_TRUE(std::isnan(b->at(0, 1, 1)));
  EXPECT_FLOAT_EQ(b->at(1, 2, 2), 8.5f);
  // Reading as double converts.
  auto c = ReadNpy<double>(path);
  ASSERT_TRUE(c.ok());
  EXPECT_DOUBLE_EQ(c->at(1, 0, 0), 4.5);
}

TEST(Npy, HeaderIsAlignedAndScalarShapeWorks) {
  NpyArray<int32_t> a;
  a.shape = {4};
  a.data = {1, 2, 3, 4};
  const std::string bytes = SerializeNpy(a);
  const size_t header_len = static_cast<unsigned char>(bytes[8]) | (bytes[9] << 8);
  EXPECT_EQ((10 + header_len) % 64, 0u);
  EXPECT_NE(bytes.find("(4,)"), std::string::npos);
  auto b = ParseNpy<int32_t>(bytes, "mem");
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(b->data, a.data);
}

// A float array read as integers: values beyond the integer type are an error, not an
// undefined conversion (fuzz_npy found -3e231 read as int32).
TEST(Npy, FloatsBeyondTheIntegerRangeAreRejected) {
  NpyArray<double> a;
  a.shape = {4};
  a.data = {1.0, -2147483648.0, 2147483647.9, 3.0};
  auto ok = ParseNpy<int32_t>(SerializeNpy(a), "in.npy");
  ASSERT_TRUE(ok.ok()) << ok.status().message();
  EXPECT_EQ(ok->data[1], -2147483647 - 1);
  EXPECT_EQ(ok->data[2], 2147483647);
  for (double bad : {2147483648.0, -2147483649.0, -3.10504e+231, 1e300}) {
    a.data[3] = bad;
    auto r = ParseNpy<int32_t>(SerializeNpy(a), "bad.npy");
    ASSERT_FALSE(r.ok()) << bad;
    EXPECT_NE(r.status().message().find("bad.npy: value out of the integer range"),
              std::string::npos)
        << r.status().message();
  }
}

TEST(Npy, RejectsTruncatedAndGarbage) {
  NpyArray<double> a;
  a.shape = {10};
  a.data.assign(10, 1.0);
  std::string bytes = SerializeNpy(a);
  EXPECT_FALSE(ParseNpy<double>(bytes.substr(0, bytes.size() - 3), "t.npy").ok());
  EXPECT_FALSE(ParseNpy<double>("hello world", "g.npy").ok());
  EXPECT_FALSE(ParseNpy<double>("", "e.npy").ok());
  auto nan_as_int = NpyArray<float>{{1}, {NAN}};
  EXPECT_FALSE(ParseNpy<int32_t>(SerializeNpy(nan_as_int), "n.npy").ok());
}

TEST(Npy, WriteToMissingFolderFailsAndLeavesNothing) {
  NpyArray<double> a{{1}, {1.0}};
  EXPECT_FALSE(WriteNpy("/nonexistent-dir/x.npy", a).ok());
}

}  // namespace
}  // namespace arco
