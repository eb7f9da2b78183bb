// PreflightRun and its checks on a small hand-written capture (the real SPD calibration,
// a 2-camera keypoint array, a generated WAV): each defect is one error naming the file
// and the field, found before any result folder exists.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "arco/audio/test_signals.h"
#include "arco/pipeline/capture_checks.h"
#include "arco/pipeline/run_capture.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"

namespace arco::pipeline {
namespace {

namespace fs = std::filesystem;
using arco::testing::TempDir;

constexpr int kFrames = 30;  // 1 s at 30 fps

// A capture the preflight accepts: cello, spd_cello, two calibrated cameras, 2 s of audio.
struct TestCapture {
  TempDir dir;
  CaptureManifest manifest;

  TestCapture() {
    fs::copy_file(std::string(ARCO_SHARED_DATA_DIR) + "/spd/cello_1113_scale_camera.xml",
                  dir / "calibration.xml");
    manifest.instrument = "cello";
    manifest.fps = 30;
    manifest.frame_first = 1;
    manifest.frame_count = kFrames;
    manifest.calibration = "calibration.xml";
    manifest.audio = "audio.wav";
    manifest.audio_offset_s = 0.5;
    manifest.keypoints2d = "keypoints2d.npy";
    manifest.layout = "spd_cello";
    manifest.cameras = {{"camera_21334181_1", "21334181", "", {}},
                        {"camera_21334237_1", "21334237", "", {}}};
    Write();
    NpyArray<float> k;
    k.shape = {kFrames, 2, 142, 3};
    k.data.assign(static_cast<size_t>(kFrames * 2 * 142 * 3), 100.0f);
    EXPECT_TRUE(WriteNpy(dir / "keypoints2d.npy", k).ok());
    EXPECT_TRUE(
        audio::testing::WriteWav(dir / "audio.wav", std::vector<float>(88200, 0.1f), 44100).ok());
  }
  void Write() { EXPECT_TRUE(WriteCaptureManifest(dir.path(), manifest).ok()); }
  std::string Manifest() const { return dir / "capture.json"; }
  RunOptions Options() const {
    RunOptions o;
    o.capture_dir = dir.path();
    o.result_dir = dir / "result";
    return o;
  }
  // The preflight's message ("ok" when it passes); no result folder either way.
  std::string Preflight() const {
    auto r = PreflightRun(Options());
    EXPECT_FALSE(fs::exists(dir / "result"));
    return r.ok() ? "ok" : r.status().message();
  }
};

TEST(PreflightRun, AcceptsAGoodCaptureAndCreatesNothing) {
  TestCapture c;
  EXPECT_EQ(c.Preflight(), "ok");
  auto audio = capture::CheckCaptureAudio(c.dir.path(), c.manifest);
  ASSERT_TRUE(audio.ok()) << audio.status().message();
  EXPECT_DOUBLE_EQ(audio->duration_s, 2.0);
  EXPECT_EQ(audio->path, c.dir / "audio.wav");
}

// `arco run` opens the capture for its paths' check and preflights what it opened:
// capture.json is not read again, and the context is the one PreflightRun makes alone.
TEST(PreflightRun, OnAnOpenedCaptureIsThePreflightOfTheFolder) {
  TestCapture c;
  auto opened = OpenCapture(c.dir.path());
  ASSERT_TRUE(opened.ok()) << opened.status().message();
  // capture.json changed after it was opened: the opened manifest is the one preflighted.
  CaptureManifest changed = c.manifest;
  changed.instrument = "none";
  ASSERT_TRUE(WriteCaptureManifest(c.dir.path(), changed).ok());
  auto from_opened = PreflightRun(c.Options(), *opened);
  ASSERT_TRUE(from_opened.ok()) << from_opened.status().message();
  c.Write();
  auto alone = PreflightRun(c.Options());
  ASSERT_TRUE(alone.ok()) << alone.status().message();
  ASSERT_EQ(from_opened->inputs.size(), alone->inputs.size());
  for (const auto& [role, input] : alone->inputs) {
    ASSERT_EQ(from_opened->inputs.count(role), 1u) << role;
    EXPECT_EQ(from_opened->inputs.at(role).file, input.file) << role;
    EXPECT_TRUE(from_opened->inputs.at(role).fingerprint == input.fingerprint) << role;
  }
  EXPECT_EQ(from_opened->manifest.instrument, "cello");
  EXPECT_FALSE(fs::exists(c.dir / "result"));
  // Another folder's capture is a caller bug.
  RunOptions other = c.Options();
  other.capture_dir = c.dir / "elsewhere";
  EXPECT_THROW(PreflightRun(other, *opened).status(), std::invalid_argument);
}

TEST(PreflightRun, AnOffsetOutsideTheAudioNamesCaptureJson) {
  TestCapture c;
  c.manifest.audio_offset_s = 99;
  c.Write();
  EXPECT_EQ(c.Preflight(),
            c.Manifest() + ": audio.offset_s = 99 s is outside the audio (0..2 s, " +
                (c.dir / "audio.wav") + ")");
  c.manifest.audio_offset_s = -1.5;  // the last frame (0.967 s later) still before 0
  c.Write();
  EXPECT_EQ(c.Preflight(),
            c.Manifest() + ": audio.offset_s = -1.5 s puts the last frame at " +
                "-0.533333 s, before the audio starts (0..2 s, " + (c.dir / "audio.wav") + ")");
  c.manifest.audio_offset_s = -0.5;  // partly inside: the pitch stage's warning, not an error
  c.Write();
  EXPECT_EQ(c.Preflight(), "ok");
}

TEST(PreflightRun, MissingOrUndecodableAudioNamesTheField) {
  TestCapture c;
  ASSERT_TRUE(AtomicWriteFile(c.dir / "audio.wav", std::string(3000, 'x')).ok());
  const std::string undecodable = c.Preflight();
  EXPECT_EQ(
      undecodable.rfind(
          c.Manifest() + ": audio.file: " + (c.dir / "audio.wav") + ": cannot decode audio", 0),
      0u)
      << undecodable;
  fs::remove(c.dir / "audio.wav");
  EXPECT_EQ(c.Preflight(),
            c.Manifest() + ": audio.file \"audio.wav\": " + (c.dir / "audio.wav") + " not found");
  c.manifest.audio.clear();  // no audio at all: the vision method only, not an error
  c.Write();
  EXPECT_EQ(c.Preflight(), "ok");
}

TEST(PreflightRun, CalibrationAndCamerasAreChecked) {
  TestCapture c;
  c.manifest.cameras[1] = {"cam_x", "x", "", {}};
  c.Write();
  EXPECT_EQ(c.Preflight(),
            c.Manifest() + ": camera \"cam_x\" is not in " + (c.dir / "calibration.xml"));
  fs::remove(c.dir / "calibration.xml");
  EXPECT_EQ(c.Preflight(),
            c.Manifest() + ": calibration \"calibration.xml\": " + (c.dir / "calibration.xml") +
                " not found");
}

TEST(PreflightRun, KeypointsDtypeAndShapeComeFromTheHeader) {
  TestCapture c;
  NpyArray<int32_t> k;
  k.shape = {kFrames, 2, 142, 3};
  k.data.assign(static_cast<size_t>(kFrames * 2 * 142 * 3), 100);
  ASSERT_TRUE(WriteNpy(c.dir / "keypoints2d.npy", k).ok());
  EXPECT_EQ(c.Preflight(),
            (c.dir / "keypoints2d.npy") +
                ": dtype int32; keypoints2d must be float32 or float64 (x_px, "
                "y_px, score; NaN = missing)");
  NpyArray<float> f;
  f.shape = {kFrames - 1, 2, 142, 3};
  f.data.assign(static_cast<size_t>((kFrames - 1) * 2 * 142 * 3), 1.0f);
  ASSERT_TRUE(WriteNpy(c.dir / "keypoints2d.npy", f).ok());
  EXPECT_EQ(c.Preflight(),
            (c.dir / "keypoints2d.npy") +
                ": shape (29, 2, 142, 3) does not match capture.json (30, 2, 142, "
                "3) (frames.count, cameras, spd_cello points, 3)");
}

// A capture made from videos has no 2D keypoints until arco detect writes them.
TEST(PreflightRun, ACaptureWithoutKeypointsSaysToRunDetect) {
  TestCapture c;
  c.manifest.keypoints2d.clear();
  c.manifest.layout.clear();
  c.Write();
  EXPECT_EQ(c.Preflight(),
            c.Manifest() + ": no 2D keypoints yet (no \"keypoints2d\" entry); run `arco detect " +
                c.dir.path() + "` (or `arco capture import-keypoints`) first");
}

TEST(PreflightRun, TheInstrumentsPointsAndTheOutputAreChecked) {
  TestCapture c;
  c.manifest.layout = "coco_wholebody_133";
  c.Write();
  EXPECT_EQ(c.Preflight().rfind(c.Manifest() + ": layout coco_wholebody_133 has no instrument "
                                               "point ",
                                0),
            0u);
  // The string ends missing (a capture from videos before `arco track`): NaN in every
  // frame, then present in one view only, then in two views of one frame.
  TestCapture e;
  const int kNut = 133 + 1;  // spd_cello: scroll_top, nut_l, nut_r, bridge_l, bridge_r, ...
  NpyArray<float> k;
  k.shape = {kFrames, 2, 142, 3};
  k.data.assign(static_cast<size_t>(kFrames * 2 * 142 * 3), 100.0f);
  const auto point = [&](int f, int v, int p) { return &k.data[((f * 2 + v) * 142 + p) * 3]; };
  for (int f = 0; f < kFrames; ++f)
    for (int v = 0; v < 2; ++v)
      for (int p = kNut; p < kNut + 4; ++p) point(f, v, p)[0] = NAN;
  ASSERT_TRUE(WriteNpy(e.dir / "keypoints2d.npy", k).ok());
  const std::string missing = e.Preflight();
  EXPECT_EQ(missing.rfind((e.dir / "keypoints2d.npy") + ": no frame shows the cello's nut_l, "
                                                        "nut_r, bridge_l and bridge_r in two "
                                                        "views each",
                          0),
            0u)
      << missing;
  for (int p = kNut; p < kNut + 4; ++p) point(7, 0, p)[0] = 100.0f;
  ASSERT_TRUE(WriteNpy(e.dir / "keypoints2d.npy", k).ok());
  EXPECT_NE(e.Preflight(), "ok");
  for (int p = kNut; p < kNut + 4; ++p) point(7, 1, p)[0] = 100.0f;
  ASSERT_TRUE(WriteNpy(e.dir / "keypoints2d.npy", k).ok());
  EXPECT_EQ(e.Preflight(), "ok");

  TestCapture d;
  ASSERT_TRUE(AtomicWriteFile(d.dir / "file", "x").ok());
  RunOptions o = d.Options();
  o.result_dir = d.dir / "file/result";
  auto r = PreflightRun(o);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().message(),
            o.result_dir + ": cannot create folder: " + (d.dir / "file") + " is not a folder");
}

}  // namespace
}  // namespace arco::pipeline
