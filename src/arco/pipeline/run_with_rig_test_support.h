// Test support for the calibration tests (calibration_refine_test,
// calibration_from_instrument_test): how well `arco run` does with an estimated rig.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "arco/calibration/calibration_file.h"
#include "arco/eval/evaluate.h"
#include "arco/pipeline/run_capture.h"

namespace arco::pipeline::testing {

// `arco run` on a copy of the capture (in dir/capture) with `rig` as its calibration,
// scored against the capture's truth folder: eval's arco method (empty on a failure,
// which is reported as a test failure).
inline eval::MethodMetrics RunWithRig(const std::string& capture,
                                      const Rig& rig,
                                      const std::string& dir) {
  const std::string copy = dir + "/capture";
  std::filesystem::copy(capture, copy, std::filesystem::copy_options::recursive);
  EXPECT_TRUE(calibration::SaveCalibration(copy + "/calibration.json", rig).ok());
  RunOptions o;
  o.capture_dir = copy;
  o.result_dir = dir + "/result";
  o.num_threads = 2;
  auto summary = RunCapture(o);
  EXPECT_TRUE(summary.ok()) << summary.status().message();
  if (!summary.ok()) return {};
  eval::EvalRequest request;
  request.result_dir = o.result_dir;
  request.truth = copy + "/truth";
  auto report = eval::Evaluate(request);
  EXPECT_TRUE(report.ok()) << report.status().message();
  if (!report.ok()) return {};
  for (const auto& m : report->methods)
    if (m.method == "arco") return m;
  ADD_FAILURE() << "no arco method";
  return {};
}

}  // namespace arco::pipeline::testing
