// The terminal text of the library's results.
#include "arco/cli/report.h"

#include <gtest/gtest.h>

#include "arco/capture/label_views.h"
#include "arco/cli/audio_report.h"

namespace arco::cli {
namespace {

const std::string kSpd = std::string(ARCO_SHARED_DATA_DIR) + "/spd/";

TEST(FormatLabelViewsReport, RealLabelsScaledToTheCello) {
  capture::LabelViewsOptions o;
  o.calibration = kSpd + "cello_1113_scale_camera.xml";
  for (const char* s : {"21334181", "21334190", "21334211", "21334237"}) {
    o.views.emplace_back(s,
                         kSpd + "labels_frame128/cello_1113_scale_" + std::string(s) + "_128.json");
  }
  o.reference_string_length_mm = 695;
  auto r = capture::TriangulateLabelViews(o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  const std::string report = FormatLabelViewsReport(*r);
  EXPECT_NE(report.find("overall reprojection RMS"), std::string::npos);
  EXPECT_NE(report.find("695 mm"), std::string::npos);
}

TEST(FormatStageLine, OneLinePerStage) {
  pipeline::RunSummary s;
  s.triangulate.triangulation.points = 10;
  s.triangulate.triangulation.triangulated = 9;
  s.triangulate.triangulation.median_rms_reprojection_px = 1.234;
  s.triangulate.units = "m";
  EXPECT_EQ(FormatStageLine(s, {"triangulate", 0}),
            "9 of 10 points, median reprojection 1.23 px (units m)");
  s.pitch.duration_s = 4;
  s.pitch.voiced_fraction = 0.5;
  s.pitch.notes = 7;
  EXPECT_EQ(FormatStageLine(s, {"pitch", 0}), "4.0 s of audio, 50% voiced, 7 notes");
  refine::RefineSummary vision, arco;
  vision.mode = refine::RefineMode::kVision;
  s.methods = {vision, arco};
  EXPECT_EQ(FormatStageLine(s, {"refine", 0}), "wrote vision, arco");
}

TEST(FormatPitchReport, NotesAndWarningsWithTheCommandsFlags) {
  capture::PitchRunOptions o;
  o.output = "p.csv";
  capture::PitchRunResult r;
  r.input = "take.wav";
  r.fine_fps = 120;
  r.notes = 2;
  r.notes_with_vibrato = 1;
  r.summary.warnings = {"no voiced frames: check start_s"};
  const std::string report = FormatPitchReport(o, r);
  EXPECT_NE(report.find("notes: 2 (1 with vibrato)"), std::string::npos) << report;
  // The library names its field; the terminal names the flag the user can give.
  // Warnings go to stderr apart from the report, naming the flag the user can give.
  EXPECT_EQ(report.find("warning"), std::string::npos) << report;
  EXPECT_EQ(PitchWarnings(r), std::vector<std::string>{"no voiced frames: check --start-s"});
  EXPECT_NE(report.find("wrote p.csv"), std::string::npos) << report;
}

}  // namespace
}  // namespace arco::cli
