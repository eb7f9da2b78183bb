// `arco capture new` on small generated videos (media/test_video.h), image folders and
// single images, with a calibration written for them.
#include "arco/capture/capture_new.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "arco/audio/test_signals.h"
#include "arco/calibration/calibration_file.h"
#include "arco/media/test_video.h"
#include "arco/mocap/capture.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"

namespace arco::capture {
namespace {

namespace fs = std::filesystem;
using arco::testing::TempDir;
using media::testing::IndexVideo;

Camera MakeCamera(const std::string& name, const std::string& serial, int width, int height) {
  Camera c;
  c.name = name;
  c.serial = serial;
  c.width = width;
  c.height = height;
  c.fx = c.fy = 100;
  c.cx = (width - 1) / 2.0;
  c.cy = (height - 1) / 2.0;
  return c;
}

// cam0 (serial 111) sees 128x96 frames; cam1 (serial 222) is a portrait camera whose
// 128x96 frames are turned 90 degrees to 96x128.
std::string WriteCalibration(const TempDir& dir) {
  Rig rig;
  rig.units = "m";
  rig.cameras = {MakeCamera("cam0", "111", 128, 96), MakeCamera("cam1", "222", 96, 128)};
  const std::string path = dir / "rig.json";
  EXPECT_TRUE(calibration::SaveCalibration(path, rig).ok());
  return path;
}

std::string WriteVideo(const TempDir& dir, const std::string& name, int frames) {
  IndexVideo v;
  v.frames = frames;
  const std::string path = dir / name;
  const Status written = media::testing::WriteIndexVideo(path, v);
  EXPECT_TRUE(written.ok()) << written.message();
  return path;
}

CaptureNewOptions TwoCameras(const TempDir& dir, int frames0 = 10, int frames1 = 10) {
  CaptureNewOptions o;
  o.calibration = WriteCalibration(dir);
  o.inputs = {{"cam0", WriteVideo(dir, "a.mkv", frames0), false},
              {"222", WriteVideo(dir, "b.mkv", frames1), false}};  // by serial
  o.rotate_deg = {{"222", 90}};
  o.output_dir = dir / "capture";
  return o;
}

// The error names `file` first, and nothing was written.
void ExpectFailsNaming(const CaptureNewOptions& o, const std::string& file) {
  const auto r = CreateCapture(o);
  ASSERT_FALSE(r.ok()) << "accepted; expected an error naming " << file;
  EXPECT_EQ(r.status().message().rfind(file + ": ", 0), 0u) << r.status().message();
  EXPECT_EQ(r.status().message().find('\n'), std::string::npos) << r.status().message();
  EXPECT_FALSE(fs::exists(o.output_dir)) << "an output was left behind";
}

TEST(CreateCapture, ReferencesTheVideosAndReadsBack) {
  TempDir dir;
  const CaptureNewOptions o = TwoCameras(dir);
  const auto r = CreateCapture(o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->frames, 10);
  EXPECT_DOUBLE_EQ(r->fps, 30);
  EXPECT_EQ(r->layout, "coco_wholebody_133");
  ASSERT_EQ(r->cameras.size(), 2u);
  EXPECT_EQ(r->cameras[1].rotate_deg, 90);

  const auto m = ReadCaptureManifest(o.output_dir);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_DOUBLE_EQ(m->fps, 30);
  EXPECT_EQ(m->frame_first, 1);
  EXPECT_EQ(m->frame_count, 10);
  EXPECT_EQ(m->instrument, "none");
  ASSERT_EQ(m->cameras.size(), 2u);
  EXPECT_EQ(m->cameras[0].name, "cam0");
  EXPECT_EQ(m->cameras[1].name, "cam1");
  EXPECT_EQ(m->cameras[1].serial, "222");
  EXPECT_EQ(m->cameras[0].rotate_deg, 0);
  EXPECT_EQ(m->cameras[1].rotate_deg, 90);
  // Absolute paths given stay absolute.
  EXPECT_EQ(m->cameras[0].video, o.inputs[0].path);
  EXPECT_TRUE(m->keypoints2d.empty());
  EXPECT_TRUE(fs::exists(ResolveCapturePath(o.output_dir, m->calibration)));
  EXPECT_TRUE(calibration::LoadCalibration(ResolveCapturePath(o.output_dir, m->calibration)).ok());
  // No keypoints yet: the readers say what to run.
  const Status none = CheckCaptureKeypoints2d(o.output_dir, *m);
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.message().find("arco detect"), std::string::npos) << none.message();
  EXPECT_EQ(none.message().rfind(JoinPath(o.output_dir, "capture.json") + ": ", 0), 0u);
}

// One camera without a calibration (one phone): calibration.json is made from its video,
// turned by its rotation, with a phone's default focal length and the camera's frame as
// the world. Two cameras need one.
TEST(CreateCapture, OneCameraWithoutACalibrationGetsOneFromItsVideo) {
  TempDir dir;
  CaptureNewOptions o;
  o.inputs = {{"phone", WriteVideo(dir, "a.mkv", 10), false}};
  o.rotate_deg = {{"phone", 90}};
  o.output_dir = dir / "capture";
  const auto r = CreateCapture(o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_NE(r->calibration_made.find("camera phone from its video: 96x128"), std::string::npos)
      << r->calibration_made;
  const auto m = ReadCaptureManifest(o.output_dir);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->calibration, "calibration.json");
  const auto c = calibration::LoadCalibration(ResolveCapturePath(o.output_dir, m->calibration));
  ASSERT_TRUE(c.ok()) << c.status().message();
  ASSERT_EQ(c->rig.cameras.size(), 1u);
  const Camera& cam = c->rig.cameras[0];
  EXPECT_EQ(c->rig.units, "mm");
  EXPECT_EQ(cam.name, "phone");
  EXPECT_EQ(cam.width, 96);  // the 128x96 frames turned by 90 degrees
  EXPECT_EQ(cam.height, 128);
  // 67 degrees across the longer side: 64 / tan(33.5 deg).
  EXPECT_NEAR(cam.fx, 64 / std::tan(33.5 * M_PI / 180), 1e-9);
  EXPECT_EQ(cam.fx, cam.fy);
  EXPECT_DOUBLE_EQ(cam.cx, 47.5);
  EXPECT_DOUBLE_EQ(cam.cy, 63.5);
  EXPECT_TRUE(cam.cam_from_world.rotation.isIdentity(0));
  EXPECT_TRUE(cam.cam_from_world.translation.isZero(0));

  CaptureNewOptions two = TwoCameras(dir);
  two.calibration.clear();
  two.output_dir = dir / "two";
  const auto refused = CreateCapture(two);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().message().rfind("calibration is missing: 2 cameras need one", 0), 0u)
      << refused.status().message();
  EXPECT_FALSE(fs::exists(two.output_dir));
}

// Relative paths are stored relative to the capture folder, so they resolve from it.
TEST(CreateCapture, RelativePathsResolveFromTheCapture) {
  TempDir dir;
  CaptureNewOptions o = TwoCameras(dir);
  const fs::path before = fs::current_path();
  fs::current_path(dir.path());
  o.inputs[0].path = "a.mkv";
  o.inputs[1].path = "./b.mkv";
  o.output_dir = "captures/session/";
  ASSERT_TRUE(audio::testing::WriteWav("take.wav", std::vector<float>(4410, 0.1f), 44100).ok());
  o.audio = "take.wav";
  const auto r = CreateCapture(o);
  const auto m = ReadCaptureManifest("captures/session");
  fs::current_path(before);
  ASSERT_TRUE(r.ok()) << r.status().message();
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->cameras[0].video, "../../a.mkv");
  EXPECT_EQ(m->cameras[1].video, "../../b.mkv");
  EXPECT_EQ(m->audio, "../../take.wav");
  EXPECT_EQ(m->audio_offset_s, 0);
  EXPECT_EQ(m->name, "session");
  EXPECT_TRUE(fs::exists(ResolveCapturePath(dir / "captures/session", m->cameras[0].video)));
}

TEST(CreateCapture, ImageFolderAndFrameRate) {
  TempDir dir;
  CaptureNewOptions o = TwoCameras(dir, 3, 3);
  IndexVideo v;
  ASSERT_TRUE(MakeDirectories(dir / "frames").ok());
  for (int k : {0, 1, 2}) {
    // Natural order: 9 before 10 before 100.
    const std::string name = std::vector<std::string>{"f9.png", "f10.png", "f100.png"}[k];
    ASSERT_TRUE(media::testing::WriteIndexPng(dir / ("frames/" + name), v, k).ok());
  }
  o.inputs[0] = {"cam0", dir / "frames", true};
  // The video gives the rate; a different fps is refused naming the video.
  auto r = CreateCapture(o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_DOUBLE_EQ(r->fps, 30);
  EXPECT_EQ(r->frames, 3);
  fs::remove_all(o.output_dir);
  o.fps = 25;
  ExpectFailsNaming(o, o.inputs[1].path);
  // Images alone: fps is needed.
  o.inputs.resize(1);
  o.rotate_deg.clear();
  o.fps = 0;
  ExpectFailsNaming(o, dir / "frames");
  o.fps = 25;
  r = CreateCapture(o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_DOUBLE_EQ(r->fps, 25);
  EXPECT_EQ(r->frames, 3);
  // A single image is a 1-frame video.
  ASSERT_TRUE(media::testing::WriteIndexPng(dir / "one.png", v, 0).ok());
  o.inputs = {{"cam0", dir / "one.png", false}};
  o.output_dir = dir / "single";
  r = CreateCapture(o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->frames, 1);
}

TEST(CreateCapture, DroppedFramesMakeTheCountsAgree) {
  TempDir dir;
  CaptureNewOptions o = TwoCameras(dir, 10, 8);
  ExpectFailsNaming(o, o.inputs[1].path);  // 8 vs 10 frames
  o.dropped_frames = {{"222", {7, 3}}};
  auto r = CreateCapture(o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->frames, 10);
  auto m = ReadCaptureManifest(o.output_dir);
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(m->cameras[1].dropped_frames, (std::vector<int64_t>{3, 7}));
  EXPECT_EQ(m->VideoFrameNumber(1, 8), 6);
  // One drop too few: 8 + 1 != 10, named.
  o.overwrite = true;
  o.dropped_frames = {{"222", {3}}};
  const auto bad = CreateCapture(o);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("8 frames + 1 dropped = 9"), std::string::npos)
      << bad.status().message();
  // From an SPD summary, by serial.
  o.dropped_frames.clear();
  ASSERT_TRUE(AtomicWriteFile(dir / "s_summary.json",
                              "{\"StartFrame\": 1, \"EndFrame\": 10, \"FrameDropIDLog\": "
                              "{\"111\": null, \"222\": [3, 7]}}")
                  .ok());
  o.spd_summary = dir / "s_summary.json";
  r = CreateCapture(o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  m = ReadCaptureManifest(o.output_dir);
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(m->cameras[1].dropped_frames, (std::vector<int64_t>{3, 7}));
  EXPECT_TRUE(m->cameras[0].dropped_frames.empty());
  // A drop after the recording's end.
  ASSERT_TRUE(
      AtomicWriteFile(dir / "s_summary.json", "{\"FrameDropIDLog\": {\"222\": [3, 70]}}").ok());
  fs::remove_all(o.output_dir);
  ExpectFailsNaming(o, o.spd_summary);
}

TEST(CreateCapture, BadInputsNameTheFileAndWriteNothing) {
  TempDir dir;
  {  // a camera the calibration lacks
    CaptureNewOptions o = TwoCameras(dir);
    o.inputs[1].camera = "cam7";
    o.rotate_deg.clear();
    ExpectFailsNaming(o, o.calibration);
  }
  {  // size mismatch: cam1 without its rotation
    CaptureNewOptions o = TwoCameras(dir);
    o.rotate_deg.clear();
    ExpectFailsNaming(o, o.inputs[1].path);
    o.rotate_deg = {{"222", 180}};
    ExpectFailsNaming(o, o.inputs[1].path);
  }
  {  // unreadable: not a video
    CaptureNewOptions o = TwoCameras(dir);
    ASSERT_TRUE(AtomicWriteFile(dir / "text.mkv", "not a video\n").ok());
    o.inputs[0].path = dir / "text.mkv";
    ExpectFailsNaming(o, o.inputs[0].path);
    o.inputs[0].path = dir / "missing.mkv";
    ExpectFailsNaming(o, o.inputs[0].path);
  }
  {  // truncated: an AVI whose header announces frames the file no longer holds
    CaptureNewOptions o = TwoCameras(dir);
    IndexVideo v;
    v.container = "avi";
    v.codec = "mpeg4";
    v.frames = 10;
    ASSERT_TRUE(media::testing::WriteIndexVideo(dir / "cut.avi", v).ok());
    const auto size = fs::file_size(dir / "cut.avi");
    fs::resize_file(dir / "cut.avi", size / 2);
    o.inputs[0].path = dir / "cut.avi";
    ExpectFailsNaming(o, o.inputs[0].path);
  }
  {  // an empty image folder, and a folder given as a video
    CaptureNewOptions o = TwoCameras(dir);
    ASSERT_TRUE(MakeDirectories(dir / "empty").ok());
    o.inputs[0] = {"cam0", dir / "empty", true};
    ExpectFailsNaming(o, dir / "empty");
    o.inputs[0] = {"cam0", dir / "empty", false};
    ExpectFailsNaming(o, dir / "empty");
  }
  {  // an unreadable audio file
    CaptureNewOptions o = TwoCameras(dir);
    ASSERT_TRUE(AtomicWriteFile(dir / "noise.wav", "RIFF....").ok());
    o.audio = dir / "noise.wav";
    ExpectFailsNaming(o, o.audio);
  }
}

TEST(CreateCapture, OverwriteOnlyReplacesACapture) {
  TempDir dir;
  CaptureNewOptions o = TwoCameras(dir);
  ASSERT_TRUE(CreateCapture(o).ok());
  EXPECT_FALSE(CreateCapture(o).ok());  // exists
  o.overwrite = true;
  o.instrument = "cello";
  const auto r = CreateCapture(o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->layout, "spd_cello");
  EXPECT_EQ(ReadCaptureManifest(o.output_dir)->instrument, "cello");
  ASSERT_TRUE(MakeDirectories(dir / "photos").ok());
  ASSERT_TRUE(AtomicWriteFile(dir / "photos/a.jpg", "precious").ok());
  o.output_dir = dir / "photos";
  EXPECT_FALSE(CreateCapture(o).ok());
  EXPECT_TRUE(fs::exists(dir / "photos/a.jpg"));
}

TEST(CaptureNewOptions, ValidateNamesTheField) {
  CaptureNewOptions good;
  good.calibration = "c.json";
  good.output_dir = "out";
  good.inputs = {{"cam0", "a.mkv", false}, {"cam1", "b.mkv", false}};
  ASSERT_TRUE(good.Validate().ok());
  auto expect_bad = [](const CaptureNewOptions& o, const std::string& field) {
    const Status s = o.Validate();
    ASSERT_FALSE(s.ok()) << field;
    EXPECT_NE(s.message().find(field), std::string::npos) << s.message();
  };
  CaptureNewOptions o = good;
  o.inputs.clear();
  expect_bad(o, "inputs");
  o = good;
  o.inputs[1].camera = "cam0";
  expect_bad(o, "inputs");
  o = good;
  o.rotate_deg = {{"cam0", 45}};
  expect_bad(o, "rotate_deg");
  o.rotate_deg = {{"cam9", 90}};
  expect_bad(o, "rotate_deg");
  o = good;
  o.dropped_frames = {{"cam0", {0}}};
  expect_bad(o, "dropped_frames");
  o.dropped_frames = {{"cam0", {4, 4}}};
  expect_bad(o, "dropped_frames");
  o.dropped_frames = {{"cam0", {4}}};
  o.spd_summary = "s.json";
  expect_bad(o, "spd_summary");
  o = good;
  o.fps = -1;
  expect_bad(o, "fps");
  o.fps = NAN;
  expect_bad(o, "fps");
  o = good;
  o.instrument = "banjo";
  expect_bad(o, "instrument");
  o = good;
  o.output_dir.clear();
  expect_bad(o, "output_dir");
  o = good;
  o.sync_max_seconds = 0;
  expect_bad(o, "sync_max_seconds");
  o.sync_max_seconds = NAN;
  expect_bad(o, "sync_max_seconds");
}

}  // namespace
}  // namespace arco::capture
