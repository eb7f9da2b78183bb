// RunDetectStage on captures made by CreateCapture from a real photo (opencv-doc's
// messi5.jpg): rotation into the calibration's orientation, determinism across thread
// counts and chunking, the instrument slots and other frames kept, and bad input that
// changes nothing.
#include "arco/capture/detect_stage.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "arco/calibration/calibration_file.h"
#include "arco/capture/capture_new.h"
#include "arco/detect/models_for_test.h"
#include "arco/detect/wholebody.h"
#include "arco/media/video_reader.h"
#include "arco/media/video_writer.h"
#include "arco/mocap/capture.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/json_io.h"
#include "arco/util/npy.h"

namespace arco::capture {
namespace {

namespace fs = std::filesystem;
constexpr char kMessi[] = "/usr/share/doc/opencv-doc/examples/data/messi5.jpg";

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

Camera MakeCamera(const std::string& name, int width, int height) {
  Camera c;
  c.name = name;
  c.width = width;
  c.height = height;
  c.fx = c.fy = 600;
  c.cx = (width - 1) / 2.0;
  c.cy = (height - 1) / 2.0;
  return c;
}

class DetectStageTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ARCO_REQUIRE_MODELS();
    if (!fs::exists(kMessi)) GTEST_SKIP() << kMessi << " missing (Debian's opencv-doc)";
    auto reader = media::VideoReader::Open(kMessi);
    ASSERT_TRUE(reader.ok()) << reader.status().message();
    auto image = reader->ReadFrame(0);
    ASSERT_TRUE(image.ok());
    photo_ = *image;
    // cam0: three frames of the photo as it is; cam1: the same frames stored turned
    // 270 degrees clockwise, so its rotate_deg 90 gives back the calibration's image.
    fs::create_directories(dir_ / "cam0");
    fs::create_directories(dir_ / "cam1");
    const media::Image stored = media::RotateClockwise(photo_, 270);
    for (int k = 1; k <= 3; ++k) {
      ASSERT_TRUE(
          media::WriteImageFile(dir_ / ("cam0/f" + std::to_string(k) + ".png"), photo_).ok());
      ASSERT_TRUE(
          media::WriteImageFile(dir_ / ("cam1/f" + std::to_string(k) + ".png"), stored).ok());
    }
  }

  // A capture of both cameras at `capture`, for `instrument`.
  void MakeCapture(const std::string& capture, const std::string& instrument = "none") {
    Rig rig;
    rig.units = "mm";
    rig.cameras = {MakeCamera("cam0", photo_.width, photo_.height),
                   MakeCamera("cam1", photo_.width, photo_.height)};
    ASSERT_TRUE(calibration::SaveCalibration(dir_ / "cal.json", rig).ok());
    CaptureNewOptions o;
    o.calibration = dir_ / "cal.json";
    o.inputs = {{"cam0", dir_ / "cam0", true}, {"cam1", dir_ / "cam1", true}};
    o.rotate_deg["cam1"] = 90;
    o.fps = 30;
    o.instrument = instrument;
    o.output_dir = capture;
    auto made = CreateCapture(o);
    ASSERT_TRUE(made.ok()) << made.status().message();
  }

  NpyArray<float> Keypoints(const std::string& capture) {
    auto a = ReadNpy<float>(capture + "/keypoints2d.npy");
    EXPECT_TRUE(a.ok()) << a.status().message();
    return a.ok() ? *a : NpyArray<float>{};
  }

  testing::TempDir dir_;
  media::Image photo_;
};

TEST_F(DetectStageTest, FindsThePlayerInEveryCameraAfterRotation) {
  const std::string capture = dir_ / "capture";
  MakeCapture(capture);
  DetectStageOptions o;
  o.capture_dir = capture;
  o.num_threads = 1;
  auto summary = RunDetectStage(o);
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  EXPECT_EQ(summary->layout, "coco_wholebody_133");
  ASSERT_EQ(summary->cameras.size(), 2u);
  for (const auto& c : summary->cameras) {
    EXPECT_EQ(c.frames, 3);
    EXPECT_EQ(c.tracker.frames_with_person, 3) << c.camera;
  }
  // Tracking: the detector runs once per chunk and camera, not per frame.
  EXPECT_EQ(summary->total.detector_runs, 2);

  const NpyArray<float> k = Keypoints(capture);
  ASSERT_EQ(k.shape, (std::vector<int64_t>{3, 2, wholebody::kNumPoints, 3}));
  // The rotated camera sees exactly the same pixels once turned: the same keypoints,
  // in the calibration's (unrotated) image.
  int body_found = 0;
  for (int64_t f = 0; f < 3; ++f)
    for (int64_t p = 0; p < wholebody::kNumPoints; ++p)
      for (int c = 0; c < 3; ++c) {
        const float a = k.data[((f * 2 + 0) * wholebody::kNumPoints + p) * 3 + c];
        const float b = k.data[((f * 2 + 1) * wholebody::kNumPoints + p) * 3 + c];
        if (std::isnan(a)) {
          EXPECT_TRUE(std::isnan(b));
          continue;
        }
        EXPECT_EQ(a, b) << "frame " << f << " point " << p;
        if (c == 2 && p < 17 && a > 0.5f) ++body_found;
      }
  EXPECT_GT(body_found, 3 * 12);

  // capture.json now names the keypoints and the layout.
  auto manifest = ReadCaptureManifest(capture);
  ASSERT_TRUE(manifest.ok());
  EXPECT_EQ(manifest->keypoints2d, "keypoints2d.npy");
  EXPECT_EQ(manifest->layout, "coco_wholebody_133");
  EXPECT_EQ(manifest->cameras[1].rotate_deg, 90);
  // detect.json: the options as applied and the counts.
  auto report = ReadJsonFile(capture + "/detect.json");
  ASSERT_TRUE(report.ok()) << report.status().message();
  EXPECT_EQ((*report)["options"]["pose_model"], "full");
  EXPECT_EQ((*report)["summary"]["cameras"][1]["frames_with_person"], 3);
  // The hands' check across views needs 3 cameras: skipped, and says so.
  EXPECT_EQ((*report)["options"]["hands"]["max_error_hand_fraction"], 0.08);
  EXPECT_EQ((*report)["summary"]["hands"]["ran"], false);
  EXPECT_EQ((*report)["summary"]["hands"]["skipped"], "fewer cameras than hands.min_views");
  EXPECT_FALSE((*report)["summary"]["hands"].contains("wall_s"));  // not deterministic
}

TEST_F(DetectStageTest, SameBytesForAnyThreadCount) {
  std::string bytes[2];
  for (int threads : {1, 2}) {
    const std::string capture = dir_ / ("capture" + std::to_string(threads));
    MakeCapture(capture);
    DetectStageOptions o;
    o.capture_dir = capture;
    o.num_threads = threads;
    o.chunk_frames = 2;  // items of 2 and 1 frames per camera
    auto summary = RunDetectStage(o);
    ASSERT_TRUE(summary.ok()) << summary.status().message();
    EXPECT_EQ(summary->total.detector_runs, 4);  // 2 chunks x 2 cameras
    bytes[threads - 1] =
        ReadBytes(capture + "/keypoints2d.npy") + ReadBytes(capture + "/detect.json");
  }
  ASSERT_FALSE(bytes[0].empty());
  EXPECT_EQ(bytes[0], bytes[1]);
}

// Frames are decoded ahead on a thread beside each worker (detect_stage.cc): the
// tracker must still see every frame once, in order, in a buffer the next read does not
// touch. Frames that differ (the photo shifted further right each time) make a frame
// given twice, skipped, swapped or overwritten while tracked show in the keypoints.
TEST_F(DetectStageTest, DecodingAheadGivesTheTrackerEveryFrameInOrder) {
  constexpr int kFrames = 5;
  fs::create_directories(dir_ / "moving");
  std::vector<media::Image> frames;
  for (int k = 0; k < kFrames; ++k) {
    media::Image shifted = media::MakeImage(photo_.width, photo_.height, photo_.format);
    const size_t shift = static_cast<size_t>(12 * k) * photo_.channels();
    for (int y = 0; y < photo_.height; ++y) {
      std::memcpy(shifted.row(y) + shift, photo_.row(y), photo_.row_bytes() - shift);
    }
    ASSERT_TRUE(
        media::WriteImageFile(dir_ / ("moving/f" + std::to_string(k + 1) + ".png"), shifted).ok());
    frames.push_back(std::move(shifted));
  }
  Rig rig;
  rig.units = "mm";
  rig.cameras = {MakeCamera("cam0", photo_.width, photo_.height)};
  ASSERT_TRUE(calibration::SaveCalibration(dir_ / "cal1.json", rig).ok());
  CaptureNewOptions c;
  c.calibration = dir_ / "cal1.json";
  c.inputs = {{"cam0", dir_ / "moving", true}};
  c.fps = 30;
  c.output_dir = dir_ / "capture";
  ASSERT_TRUE(CreateCapture(c).ok());
  DetectStageOptions o;
  o.capture_dir = c.output_dir;
  o.num_threads = 1;
  auto summary = RunDetectStage(o);
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  const NpyArray<float> k = Keypoints(c.output_dir);
  ASSERT_EQ(k.shape, (std::vector<int64_t>{kFrames, 1, wholebody::kNumPoints, 3}));

  // The same frames through one tracker, one after the other, without the stage.
  detect::WholeBodyOptions d;
  auto tracker = detect::WholeBodyTracker::Create(d);
  ASSERT_TRUE(tracker.ok()) << tracker.status().message();
  int found = 0;
  for (int f = 0; f < kFrames; ++f) {
    auto expected = tracker->Track(frames[f]);
    ASSERT_TRUE(expected.ok());
    for (int p = 0; p < wholebody::kNumPoints; ++p) {
      const float* got = &k.data[(static_cast<size_t>(f) * wholebody::kNumPoints + p) * 3];
      const detect::ScoredPoint& e = expected->points[p];
      if (std::isnan(e.x_px)) {
        EXPECT_TRUE(std::isnan(got[0])) << "frame " << f << " point " << p;
        continue;
      }
      ++found;
      EXPECT_EQ(got[0], e.x_px) << "frame " << f << " point " << p;
      EXPECT_EQ(got[1], e.y_px) << "frame " << f << " point " << p;
      EXPECT_EQ(got[2], e.score) << "frame " << f << " point " << p;
    }
  }
  EXPECT_GT(found, kFrames * 17);

  // Decoding in turn (the option off) writes the same bytes.
  const std::string ahead = ReadBytes(c.output_dir + "/keypoints2d.npy");
  o.decode_ahead = false;
  auto in_turn = RunDetectStage(o);
  ASSERT_TRUE(in_turn.ok()) << in_turn.status().message();
  EXPECT_EQ(ReadBytes(c.output_dir + "/keypoints2d.npy"), ahead);
  EXPECT_GE(in_turn->decode_wait_s, in_turn->decode_s);  // all of it waited for
  o.decode_ahead = true;

  // A frame that cannot be decoded, read ahead while the one before it is tracked: the
  // error reaches the caller and nothing is written.
  const std::string npy_before = ReadBytes(c.output_dir + "/keypoints2d.npy");
  std::ofstream(dir_ / "moving/f4.png", std::ios::binary | std::ios::trunc) << "not a png";
  auto broken = RunDetectStage(o);
  EXPECT_FALSE(broken.ok());
  EXPECT_EQ(ReadBytes(c.output_dir + "/keypoints2d.npy"), npy_before);
}

TEST_F(DetectStageTest, KeepsInstrumentSlotsAndFramesOutsideTheRange) {
  const std::string capture = dir_ / "capture";
  MakeCapture(capture, "cello");
  auto manifest = ReadCaptureManifest(capture);
  ASSERT_TRUE(manifest.ok());
  const KeypointLayout* layout = FindKeypointLayout("spd_cello");
  ASSERT_NE(layout, nullptr);
  const int64_t points = static_cast<int64_t>(layout->names.size());
  ASSERT_GT(points, wholebody::kNumPoints);
  // Keypoints already there (as `arco track` would leave them): every value 7.
  NpyArray<float> old;
  old.shape = {3, 2, points, 3};
  old.data.assign(static_cast<size_t>(3 * 2 * points * 3), 7.0f);
  ASSERT_TRUE(WriteNpy(capture + "/keypoints2d.npy", old).ok());
  manifest->keypoints2d = "keypoints2d.npy";
  manifest->layout = "spd_cello";
  ASSERT_TRUE(WriteCaptureManifest(capture, *manifest).ok());

  DetectStageOptions o;
  o.capture_dir = capture;
  o.first_frame = 2;
  o.last_frame = 3;
  auto summary = RunDetectStage(o);
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  EXPECT_TRUE(summary->kept_other_points);
  const NpyArray<float> k = Keypoints(capture);
  ASSERT_EQ(k.shape, old.shape);
  for (int64_t f = 0; f < 3; ++f)
    for (int v = 0; v < 2; ++v)
      for (int64_t p = 0; p < points; ++p) {
        const float x = k.data[((f * 2 + v) * points + p) * 3];
        if (f == 0 || p >= wholebody::kNumPoints) {
          EXPECT_EQ(x, 7.0f) << "frame " << f << " view " << v << " point " << p;
        } else if (p < 17) {
          EXPECT_NE(x, 7.0f) << "frame " << f << " point " << p;  // detected anew
        }
      }
}

TEST_F(DetectStageTest, BadInputChangesNothing) {
  const std::string capture = dir_ / "capture";
  MakeCapture(capture);
  const std::string manifest_before = ReadBytes(capture + "/capture.json");
  DetectStageOptions o;
  o.capture_dir = capture;

  // A missing model file names it and scripts/setup.
  o.detector.models_dir = dir_ / "no-models";
  auto missing_model = RunDetectStage(o);
  ASSERT_FALSE(missing_model.ok());
  EXPECT_NE(missing_model.status().message().find("scripts/setup"), std::string::npos)
      << missing_model.status().message();
  o.detector.models_dir.clear();

  // Frames outside the capture.
  o.first_frame = 2;
  o.last_frame = 9;
  auto outside = RunDetectStage(o);
  ASSERT_FALSE(outside.ok());
  EXPECT_NE(outside.status().message().find("outside the capture's frames 1:3"), std::string::npos)
      << outside.status().message();
  o.first_frame = o.last_frame = -1;

  // A camera's images gone: the error names the folder.
  fs::rename(dir_ / "cam1", dir_ / "cam1-moved");
  auto gone = RunDetectStage(o);
  ASSERT_FALSE(gone.ok());
  EXPECT_NE(gone.status().message().find("cam1"), std::string::npos) << gone.status().message();
  fs::rename(dir_ / "cam1-moved", dir_ / "cam1");

  // A calibration whose camera is another size than the video after rotation.
  Rig rig;
  rig.units = "mm";
  rig.cameras = {MakeCamera("cam0", photo_.width, photo_.height),
                 MakeCamera("cam1", photo_.height, photo_.width)};
  const std::string calibration = capture + "/calibration.json";
  const std::string calibration_before = ReadBytes(calibration);
  ASSERT_TRUE(calibration::SaveCalibration(calibration, rig).ok());
  auto size = RunDetectStage(o);
  ASSERT_FALSE(size.ok());
  EXPECT_NE(size.status().message().find("after rotate_deg 90"), std::string::npos)
      << size.status().message();

  // Nothing was written by any of them.
  EXPECT_FALSE(fs::exists(capture + "/keypoints2d.npy"));
  EXPECT_FALSE(fs::exists(capture + "/detect.json"));
  EXPECT_EQ(ReadBytes(capture + "/capture.json"), manifest_before);
  for (const auto& entry : fs::directory_iterator(capture)) {
    EXPECT_NE(entry.path().filename().string()[0], '.') << entry.path();
  }
}

TEST(DetectStageOptionsTest, RangesNameTheField) {
  DetectStageOptions o;
  EXPECT_FALSE(o.Validate().ok());  // no capture
  o.capture_dir = "c";
  EXPECT_TRUE(o.Validate().ok());
  o.chunk_frames = 0;
  EXPECT_NE(o.Validate().message().find("chunk_frames"), std::string::npos);
  o.chunk_frames = 10;
  o.num_threads = -1;
  EXPECT_NE(o.Validate().message().find("num_threads"), std::string::npos);
  o.num_threads = 0;
  o.first_frame = 5;
  o.last_frame = 4;
  EXPECT_NE(o.Validate().message().find("before first_frame"), std::string::npos);
  o.last_frame = -1;
  o.detector.min_hand_presence = std::nan("");
  EXPECT_NE(o.Validate().message().find("min_hand_presence"), std::string::npos);
  o.detector.min_hand_presence = 0.5;
  o.hands.max_error_hand_fraction = -1;
  EXPECT_NE(o.Validate().message().find("hands: max_error_hand_fraction"), std::string::npos)
      << o.Validate().message();
}

}  // namespace
}  // namespace arco::capture
