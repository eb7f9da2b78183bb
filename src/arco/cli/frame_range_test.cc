#include "arco/cli/frame_range.h"

#include <gtest/gtest.h>

namespace arco::cli {
namespace {

TEST(ParseFrameRange, BothSidesOneSideOrNone) {
  int64_t first = -1, last = -1;
  ASSERT_TRUE(ParseFrameRange("12:345", &first, &last).ok());
  EXPECT_EQ(first, 12);
  EXPECT_EQ(last, 345);
  first = last = -1;
  ASSERT_TRUE(ParseFrameRange(":7", &first, &last).ok());
  EXPECT_EQ(first, -1);
  EXPECT_EQ(last, 7);
  ASSERT_TRUE(ParseFrameRange("3:", &first, &last).ok());
  EXPECT_EQ(first, 3);
  EXPECT_EQ(last, 7);
  first = last = -1;
  ASSERT_TRUE(ParseFrameRange("", &first, &last).ok());
  EXPECT_EQ(first, -1);
  EXPECT_EQ(last, -1);
}

TEST(ParseFrameRange, RejectsWhatIsNotTwoWholeNumbers) {
  for (const char* text :
       {"5", "a:b", "-1:4", "1:+4", " 1:4", "1.5:4", "1:2:3", "9999999999999:1"}) {
    int64_t first = -1, last = -1;
    const Status status = ParseFrameRange(text, &first, &last);
    ASSERT_FALSE(status.ok()) << text;
    EXPECT_EQ(status.message(),
              std::string("--frames \"") + text + "\" must look like FIRST:LAST (frame numbers)");
  }
}

// The flag the user typed, not the options' fields ("last_frame 2 is before first_frame 5").
TEST(ParseFrameRange, RejectsLastBeforeFirstNamingTheFlag) {
  int64_t first = -1, last = -1;
  const Status status = ParseFrameRange("5:2", &first, &last);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(), "--frames \"5:2\": LAST is before FIRST");
  first = last = -1;
  EXPECT_TRUE(ParseFrameRange("5:5", &first, &last).ok());
}

}  // namespace
}  // namespace arco::cli
