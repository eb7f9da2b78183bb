// Options of the stages and of RunCapture: defaults are valid, bad values are one readable
// error naming the option, caught before any work.
#include <gtest/gtest.h>

#include "arco/pipeline/run_capture.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"

namespace arco::pipeline {
namespace {

RunOptions Valid() {
  RunOptions o;
  o.capture_dir = "capture";
  o.result_dir = "result";
  return o;
}

void ExpectInvalid(const RunOptions& o, const std::string& words) {
  const Status s = o.Validate();
  ASSERT_FALSE(s.ok()) << "expected an error about " << words;
  EXPECT_NE(s.message().find(words), std::string::npos) << s.message();
}

TEST(RunOptions, DefaultsAreValid) {
  EXPECT_TRUE(Valid().Validate().ok()) << Valid().Validate().message();
  EXPECT_TRUE(Valid().ForTriangulate().Validate().ok());
  EXPECT_TRUE(Valid().ForInstrument().Validate().ok());
  EXPECT_TRUE(Valid().ForHands().Validate().ok());
  EXPECT_TRUE(Valid().ForPitch().Validate().ok());
  EXPECT_TRUE(Valid().ForRefine(refine::RefineMode::kPaper).Validate().ok());
}

TEST(RunOptions, EveryNestedOptionIsValidated) {
  RunOptions o = Valid();
  o.capture_dir.clear();
  ExpectInvalid(o, "capture_dir");
  o = Valid();
  o.result_dir.clear();
  ExpectInvalid(o, "result_dir");
  o = Valid();
  o.num_threads = -1;
  ExpectInvalid(o, "num_threads");
  o = Valid();
  o.triangulate.triangulation.point.min_score = -1;
  ExpectInvalid(o, "triangulate");
  o = Valid();
  o.hands.chunk_frames = 0;
  ExpectInvalid(o, "hands: chunk_frames");
  o = Valid();
  o.instrument.smoothing.max_fill_gap_frames = -1;
  ExpectInvalid(o, "instrument: smoothing");
  o = Valid();
  o.refine.pitch.min_confidence = 2;
  ExpectInvalid(o, "refine");
}

TEST(RunOptions, TheRunsFoldersAndThreadsReachEveryStage) {
  RunOptions o = Valid();
  o.num_threads = 3;
  EXPECT_EQ(o.ForTriangulate().capture_dir, "capture");
  EXPECT_EQ(o.ForTriangulate().triangulation.num_threads, 3);
  EXPECT_EQ(o.ForInstrument().result_dir, "result");
  EXPECT_EQ(o.ForHands().num_threads, 3);
  EXPECT_EQ(o.ForRefine(refine::RefineMode::kVision).refine.mode, refine::RefineMode::kVision);
  EXPECT_EQ(o.ForRefine(refine::RefineMode::kVision).refine.num_threads, 3);
}

TEST(RunCapture, InvalidOptionsWriteNothing) {
  arco::testing::TempDir dir;
  RunOptions o = Valid();
  o.capture_dir = dir / "capture";
  o.result_dir = dir / "result";
  o.hands.chunk_frames = 0;
  auto r = RunCapture(o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("chunk_frames"), std::string::npos);
  EXPECT_FALSE(FileExists(o.result_dir));
}

}  // namespace
}  // namespace arco::pipeline
