#include "arco/mocap/capture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>

#include "arco/mocap/sample_manifest.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"

namespace arco {
namespace {

using arco::testing::SampleManifest;
using testing::TempDir;

TEST(KeypointLayout, BuiltInLayoutsHaveSpdSizesAndNames) {
  auto size = [](const char* n) { return FindKeypointLayout(n)->size(); };
  EXPECT_EQ(size("coco_wholebody_133"), 133);
  EXPECT_EQ(size("hand_21"), 21);
  EXPECT_EQ(size("spd_cello"), 142);
  EXPECT_EQ(size("spd_violin"), 140);
  EXPECT_EQ(size("contact_13"), 13);
  EXPECT_EQ(size("spd_cello_contact"), 155);
  EXPECT_EQ(size("spd_violin_contact"), 153);
  EXPECT_EQ(FindKeypointLayout("nope"), nullptr);
  const KeypointLayout& cello = *FindKeypointLayout("spd_cello_contact");
  EXPECT_EQ(cello.Find("left_wrist"), 9);
  EXPECT_EQ(cello.Find("left_hand_wrist"), 91);
  EXPECT_EQ(cello.Find("left_hand_index_tip"), 99);
  EXPECT_EQ(cello.Find("right_hand_little_tip"), 132);
  EXPECT_EQ(cello.Find("scroll_top"), 133);
  EXPECT_EQ(cello.Find("nut_l"), 134);
  EXPECT_EQ(cello.Find("tip"), 141);
  EXPECT_EQ(cello.Find("string4_top"), 142);
  EXPECT_EQ(cello.Find("contact"), 150);
  EXPECT_EQ(cello.Find("finger_tip"), 154);
  const KeypointLayout& violin = *FindKeypointLayout("spd_violin_contact");
  EXPECT_EQ(violin.Find("frog"), 138);
  EXPECT_EQ(violin.Find("string4_top"), 140);
  EXPECT_EQ(violin.Group("bow")->size(), 2u);
  EXPECT_EQ(violin.Group("left_hand")->front(), 91);
  EXPECT_EQ(violin.Group("all")->size(), 153u);
  EXPECT_EQ(violin.Group("tail"), nullptr);
  EXPECT_EQ(CanonicalKeypointName("tip_plate"), "tip");
}

TEST(CaptureManifest, WriteThenReadRoundTrips) {
  TempDir dir;
  const CaptureManifest m = SampleManifest();
  ASSERT_TRUE(WriteCaptureManifest(dir.path(), m).ok());
  auto r = ReadCaptureManifest(dir.path());
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(CaptureManifestToJson(*r), CaptureManifestToJson(m));
  EXPECT_EQ(r->cameras[0].dropped_frames, (std::vector<int64_t>{129, 131}));
  EXPECT_EQ(r->FindCamera("21334237"), 1);
  EXPECT_EQ(r->FindCamera("cam0"), 0);
  EXPECT_EQ(r->FindCamera("cam9"), -1);
  EXPECT_TRUE(std::isnan(r->audio_sync_confidence));  // not written unless arco sync set it
  CaptureManifest synced = m;
  synced.audio_sync_confidence = 0.87;
  ASSERT_TRUE(WriteCaptureManifest(dir.path(), synced).ok());
  auto s = ReadCaptureManifest(dir.path());
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->audio_sync_confidence, 0.87);
}

TEST(CaptureManifest, VideoFrameNumbersSkipDroppedFrames) {
  const CaptureManifest m = SampleManifest();  // cam0 dropped 129 and 131
  EXPECT_EQ(m.VideoFrameNumber(0, 128), 128);
  EXPECT_EQ(m.VideoFrameNumber(0, 129), -1);
  EXPECT_EQ(m.VideoFrameNumber(0, 130), 129);
  EXPECT_EQ(m.VideoFrameNumber(0, 301), 299);
  EXPECT_EQ(m.VideoFrameNumber(1, 301), 301);
}

TEST(CaptureManifest, MalformedManifestsNameTheFileAndProblem) {
  const Json good = CaptureManifestToJson(SampleManifest());
  auto parse_with = [&](auto edit) {
    Json j = good;
    edit(j);
    return ParseCaptureManifest(j.dump(), "cap/capture.json");
  };
  auto expect_error = [](const StatusOr<CaptureManifest>& r, const std::string& words) {
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.status().message().find("cap/capture.json"), std::string::npos);
    EXPECT_NE(r.status().message().find(words), std::string::npos) << r.status().message();
  };
  expect_error(parse_with([](Json& j) { j.erase("fps"); }), "fps");
  expect_error(parse_with([](Json& j) { j["fps"] = "thirty"; }), "fps");
  expect_error(parse_with([](Json& j) { j["fps"] = -1; }), "fps");
  expect_error(parse_with([](Json& j) { j["format"] = "other"; }), "format");
  expect_error(parse_with([](Json& j) { j["version"] = 2; }), "version");
  expect_error(parse_with([](Json& j) { j["instrument"] = "lute"; }), "instrument");
  expect_error(parse_with([](Json& j) { j["frames"]["count"] = 1.5; }), "count");
  expect_error(parse_with([](Json& j) { j["cameras"] = Json::array(); }), "cameras");
  expect_error(parse_with([](Json& j) { j["cameras"][1]["name"] = "cam0"; }), "twice");
  expect_error(parse_with([](Json& j) { j["cameras"][0]["dropped_frames"] = {1.5}; }),
               "dropped_frames");
  expect_error(parse_with([](Json& j) { j["keypoints2d"]["layout"] = "nope"; }), "nope");
  expect_error(parse_with([](Json& j) { j["keypoints2d"]["layout"] = "custom"; }),
               "keypoint_names");
  expect_error(parse_with([](Json& j) { j.erase("calibration"); }), "calibration");
  expect_error(parse_with([](Json& j) { j["audio"]["sync_confidence"] = 1.5; }), "sync_confidence");
  // An SPD layout of another instrument family (issue 24): refused in the reader, so every
  // command's preflight stops on it; the family's other instrument and "none" are fine.
  expect_error(parse_with([](Json& j) {
                 j["instrument"] = "violin";
                 j["keypoints2d"]["layout"] = "spd_cello";
               }),
               "\"keypoints2d.layout\" is \"spd_cello\", but \"instrument\" is \"violin\", "
               "whose points are spd_violin");
  expect_error(parse_with([](Json& j) {
                 j["instrument"] = "cello";
                 j["keypoints2d"]["layout"] = "spd_violin_contact";
               }),
               "spd_cello");
  for (const char* instrument : {"double_bass", "none"}) {
    const auto ok = parse_with([&](Json& j) {
      j["instrument"] = instrument;
      j["keypoints2d"]["layout"] = "spd_cello";
    });
    EXPECT_TRUE(ok.ok()) << instrument << ": " << ok.status().message();
  }
  expect_error(ParseCaptureManifest("{\"format\": ", "cap/capture.json"), "malformed JSON");
  expect_error(
      ParseCaptureManifest("{\"format\": \"arco-capture\", \"fps\": NaN}", "cap/capture.json"), "");
  expect_error(ParseCaptureManifest("[1, 2]", "cap/capture.json"), "object");
  EXPECT_FALSE(ReadCaptureManifest("/nonexistent/dir").ok());
}

// issue 11: values that were accepted silently, each rejected naming the file and field.
TEST(CaptureManifest, ContentOutsideItsRangeNamesTheField) {
  const Json good = CaptureManifestToJson(SampleManifest());
  auto message = [&](auto edit) -> std::string {
    Json j = good;
    edit(j);
    auto r = ParseCaptureManifest(j.dump(), "cap/capture.json");
    return r.ok() ? "accepted" : r.status().message();
  };
  EXPECT_EQ(message([](Json& j) { j["frames"]["first"] = -5; }),
            "cap/capture.json: \"frames.first\" is -5; must be in [0, 2^40] (global frame "
            "numbers, 1 for the recording's first frame)");
  EXPECT_EQ(message([](Json& j) { j["frames"]["count"] = -1; }),
            "cap/capture.json: \"frames.count\" is -1; must be in [0, 1e8]");
  EXPECT_EQ(message([](Json& j) { j["cameras"][0]["dropped_frames"] = {-3}; }),
            "cap/capture.json: \"cameras[0].dropped_frames\" holds frame -3, outside 0..131 "
            "(frames.first + frames.count - 1)");
  EXPECT_EQ(message([](Json& j) { j["cameras"][1]["dropped_frames"] = {99999}; }),
            "cap/capture.json: \"cameras[1].dropped_frames\" holds frame 99999, outside 0..131 "
            "(frames.first + frames.count - 1)");
  EXPECT_EQ(message([](Json& j) {
              j["cameras"][0]["dropped_frames"] = {130, 129, 130};
            }),
            "cap/capture.json: \"cameras[0].dropped_frames\" lists frame 130 twice");
  EXPECT_EQ(message([](Json& j) { j["fps"] = 0; }),
            "cap/capture.json: \"fps\" is 0; must be in (0, 10000] frames per second");
  EXPECT_EQ(message([](Json& j) { j["fps"] = "30"; }),
            "cap/capture.json: \"fps\" is \"30\"; must be a number");
  EXPECT_EQ(message([](Json& j) { j["audio"]["file"] = ""; }),
            "cap/capture.json: \"audio.file\" is empty; must name an audio file");
  EXPECT_EQ(message([](Json& j) { j["cameras"][1]["rotate_deg"] = 45; }),
            "cap/capture.json: \"cameras[1].rotate_deg\" is 45; must be 0, 90, 180 or 270");
  EXPECT_EQ(message([](Json& j) { j["cameras"][1]["rotate_deg"] = "90"; }),
            "cap/capture.json: \"cameras[1].rotate_deg\" is \"90\"; must be an integer");
  // Any order is accepted and sorted.
  EXPECT_EQ(message([](Json& j) { j["cameras"][0]["dropped_frames"] = {131, 128}; }), "accepted");
}

// A camera's rotation and video reference round-trip; 0 is not written.
TEST(CaptureManifest, RotationRoundTrips) {
  CaptureManifest m = SampleManifest();
  m.cameras[0].video = "../videos/21334181.avi";
  m.cameras[0].rotate_deg = 90;
  const Json j = CaptureManifestToJson(m);
  EXPECT_EQ(j["cameras"][0]["rotate_deg"], 90);
  EXPECT_FALSE(j["cameras"][1].contains("rotate_deg"));
  const auto r = ParseCaptureManifest(j.dump(), "capture.json");
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->cameras[0].rotate_deg, 90);
  EXPECT_EQ(r->cameras[1].rotate_deg, 0);
  EXPECT_EQ(r->cameras[0].video, "../videos/21334181.avi");
  EXPECT_EQ(ResolveCapturePath("caps/one", r->cameras[0].video), "caps/one/../videos/21334181.avi");
}

TEST(DetectionLayoutName, FollowsTheInstrument) {
  EXPECT_EQ(*DetectionLayoutName("none"), "coco_wholebody_133");
  EXPECT_EQ(*DetectionLayoutName("cello"), "spd_cello");
  EXPECT_EQ(*DetectionLayoutName("viola"), "spd_violin");
  EXPECT_FALSE(DetectionLayoutName("lute").ok());
}

// JSON has no NaN: a Python-written NaN / Infinity is named as such, not as a missing field.
TEST(CaptureManifest, NonFiniteTokensAreNamedNotMissing) {
  const std::string good = CaptureManifestToJson(SampleManifest()).dump();
  auto with = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    auto r = ParseCaptureManifest(text, "cap/capture.json");
    return r.ok() ? std::string("accepted") : r.status().message();
  };
  EXPECT_EQ(with("\"fps\":30.0", "\"fps\":NaN"),
            "cap/capture.json: \"fps\" is NaN; must be a finite number");
  EXPECT_EQ(with("\"fps\":30.0", "\"fps\":Infinity"),
            "cap/capture.json: \"fps\" is Infinity; must be a finite number");
  EXPECT_EQ(with("\"fps\":30.0", "\"fps\":-Infinity"),
            "cap/capture.json: \"fps\" is -Infinity; must be a finite number");
  EXPECT_EQ(with("\"offset_s\":1.25", "\"offset_s\":NaN"),
            "cap/capture.json: \"audio.offset_s\" is NaN; must be a finite number");
  EXPECT_EQ(with("\"first\":128", "\"first\":NaN"),
            "cap/capture.json: \"frames.first\" is NaN; must be an integer");
  EXPECT_EQ(with("\"name\":\"cam0\"", "\"name\":NaN"),
            "cap/capture.json: \"cameras[0].name\" is NaN; must be a string");
}

TEST(CaptureKeypoints, IntegerDtypeIsRejectedNamingIt) {
  TempDir dir;
  CaptureManifest m = SampleManifest();
  ASSERT_TRUE(WriteCaptureManifest(dir.path(), m).ok());
  NpyArray<int32_t> k;
  k.shape = {4, 2, 142, 3};
  k.data.assign(4 * 2 * 142 * 3, 5);
  ASSERT_TRUE(WriteNpy(dir / "keypoints2d.npy", k).ok());
  const Status checked = CheckCaptureKeypoints2d(dir.path(), m);
  ASSERT_FALSE(checked.ok());
  EXPECT_EQ(checked.message(),
            (dir / "keypoints2d.npy") +
                ": dtype int32; keypoints2d must be float32 or float64 (x_px, y_px, score; NaN = "
                "missing)");
  EXPECT_FALSE(ReadCaptureKeypoints2d(dir.path(), m).ok());
}

TEST(CaptureKeypoints, ShapeIsCheckedAndDroppedFramesBecomeNaN) {
  TempDir dir;
  CaptureManifest m = SampleManifest();
  ASSERT_TRUE(WriteCaptureManifest(dir.path(), m).ok());
  NpyArray<float> k;
  k.shape = {4, 2, 142, 3};
  k.data.assign(4 * 2 * 142 * 3, 5.0f);
  ASSERT_TRUE(WriteNpy(dir / "keypoints2d.npy", k).ok());
  auto r = ReadCaptureKeypoints2d(dir.path(), m);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_TRUE(std::isnan(r->at(1, 0, 7, 0)));  // global 129 = frame index 1, dropped by cam0
  EXPECT_EQ(r->at(1, 1, 7, 0), 5.0);
  EXPECT_EQ(r->at(0, 0, 7, 0), 5.0);
  k.shape = {4, 2, 133, 3};
  k.data.resize(4 * 2 * 133 * 3);
  ASSERT_TRUE(WriteNpy(dir / "keypoints2d.npy", k).ok());
  r = ReadCaptureKeypoints2d(dir.path(), m);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("keypoints2d.npy"), std::string::npos);
  EXPECT_NE(r.status().message().find("(4, 2, 142, 3)"), std::string::npos);
}

// `arco run` reads the file once and parses the bytes (issue 25): the same array, bit for
// bit, and the same one-line errors, as reading the file.
TEST(CaptureKeypoints, ParsingTheBytesIsReadingTheFile) {
  TempDir dir;
  CaptureManifest m = SampleManifest();
  ASSERT_TRUE(WriteCaptureManifest(dir.path(), m).ok());
  NpyArray<float> k;
  k.shape = {4, 2, 142, 3};
  k.data.resize(4 * 2 * 142 * 3);
  for (size_t i = 0; i < k.data.size(); ++i) k.data[i] = 0.25f * static_cast<float>(i % 977);
  ASSERT_TRUE(WriteNpy(dir / "keypoints2d.npy", k).ok());
  auto bytes = ReadCaptureKeypoints2dBytes(dir.path(), m);
  ASSERT_TRUE(bytes.ok()) << bytes.status().message();
  auto parsed = ParseCaptureKeypoints2d(bytes->view(), dir.path(), m);
  auto read = ReadCaptureKeypoints2d(dir.path(), m);
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ASSERT_TRUE(read.ok());
  ASSERT_EQ(parsed->shape, read->shape);
  ASSERT_EQ(parsed->data.size(), read->data.size());
  EXPECT_EQ(std::memcmp(parsed->data.data(), read->data.data(), read->data.size() * 8), 0);
  EXPECT_TRUE(std::isnan(parsed->at(1, 0, 7, 0)));  // dropped by cam0, as when read

  // A wrong shape, a wrong dtype, a truncated file: the messages of the file's reader.
  k.shape = {4, 2, 133, 3};
  k.data.resize(4 * 2 * 133 * 3);
  ASSERT_TRUE(WriteNpy(dir / "keypoints2d.npy", k).ok());
  bytes = ReadCaptureKeypoints2dBytes(dir.path(), m);
  ASSERT_TRUE(bytes.ok());
  EXPECT_EQ(ParseCaptureKeypoints2d(bytes->view(), dir.path(), m).status().message(),
            ReadCaptureKeypoints2d(dir.path(), m).status().message());
  NpyArray<int32_t> ints;
  ints.shape = {4, 2, 142, 3};
  ints.data.assign(4 * 2 * 142 * 3, 5);
  ASSERT_TRUE(WriteNpy(dir / "keypoints2d.npy", ints).ok());
  bytes = ReadCaptureKeypoints2dBytes(dir.path(), m);
  ASSERT_TRUE(bytes.ok());
  const Status dtype = ParseCaptureKeypoints2d(bytes->view(), dir.path(), m).status();
  EXPECT_FALSE(dtype.ok());
  EXPECT_EQ(dtype.message(), ReadCaptureKeypoints2d(dir.path(), m).status().message());
  k.shape = {4, 2, 142, 3};
  k.data.resize(4 * 2 * 142 * 3);
  ASSERT_TRUE(WriteNpy(dir / "keypoints2d.npy", k).ok());
  bytes = ReadCaptureKeypoints2dBytes(dir.path(), m);
  ASSERT_TRUE(bytes.ok());
  const std::string_view cut = bytes->view().substr(0, bytes->view().size() - 100);
  ASSERT_TRUE(AtomicWriteFile(dir / "keypoints2d.npy", std::string(cut)).ok());
  const Status truncated = ParseCaptureKeypoints2d(cut, dir.path(), m).status();
  EXPECT_FALSE(truncated.ok());
  EXPECT_EQ(truncated.message(), ReadCaptureKeypoints2d(dir.path(), m).status().message());

  // No file, or a folder in its place: one line naming it.
  std::filesystem::remove(dir / "keypoints2d.npy");
  EXPECT_EQ(ReadCaptureKeypoints2dBytes(dir.path(), m).status().message(),
            (dir / "keypoints2d.npy") + ": file not found");
  std::filesystem::create_directory(dir / "keypoints2d.npy");
  EXPECT_EQ(ReadCaptureKeypoints2dBytes(dir.path(), m).status().message(),
            (dir / "keypoints2d.npy") + ": is a directory, expected a file");
}

// A camera's clock on the capture's (cameras[].offset_s, drift_ppm) round-trips; 0 is
// not written, so a hardware-synced capture's manifest is unchanged.
TEST(CaptureManifest, CameraClockRoundTripsAndIsCheckedForRange) {
  CaptureManifest m = SampleManifest();
  m.cameras[1].offset_s = 0.35012;
  m.cameras[1].drift_ppm = -31.5;
  const Json j = CaptureManifestToJson(m);
  EXPECT_FALSE(j["cameras"][0].contains("offset_s"));
  EXPECT_FALSE(j["cameras"][0].contains("drift_ppm"));
  EXPECT_EQ(j["cameras"][1]["offset_s"], 0.35012);
  const auto r = ParseCaptureManifest(j.dump(), "capture.json");
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->cameras[0].offset_s, 0.0);
  EXPECT_TRUE(r->cameras[0].OnCaptureClock());
  EXPECT_EQ(r->cameras[1].offset_s, 0.35012);
  EXPECT_EQ(r->cameras[1].drift_ppm, -31.5);
  Json bad = j;
  bad["cameras"][1]["offset_s"] = "0.3";
  auto e = ParseCaptureManifest(bad.dump(), "cap/capture.json");
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.status().message(),
            "cap/capture.json: \"cameras[1].offset_s\" is \"0.3\"; must be a number");
  bad = j;
  bad["cameras"][1]["drift_ppm"] = 20000;
  e = ParseCaptureManifest(bad.dump(), "cap/capture.json");
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.status().message(),
            "cap/capture.json: \"cameras[1].drift_ppm\" is 20000; must be in [-10000, 10000] ppm");
}

// A point moving at constant speed: camera 1 started 0.0123 s after the capture's clock
// and runs slow by 40 ppm, so its frame g shows the point at its own instant. Sampled at
// the capture's frame times, both views show the point at the same instant (a bow at
// 1 m/s is not triangulated from moments apart).
TEST(CaptureKeypoints, CameraWithAnOffsetIsSampledAtTheCaptureFrameTimes) {
  CaptureManifest m = SampleManifest();
  m.frame_first = 1;
  m.frame_count = 30;
  m.cameras[0].dropped_frames = {};
  m.cameras[1].offset_s = 0.0123;
  m.cameras[1].drift_ppm = 40;
  const auto x_at = [](double time_s) { return 100.0 + 900.0 * time_s; };  // px
  NpyArray<double> k;
  k.shape = {30, 2, 3, 3};
  k.data.assign(30 * 2 * 3 * 3, 0.0);
  for (int64_t f = 0; f < 30; ++f) {
    const double capture_s = f / m.fps;
    const double camera1_s = 0.0123 + (1 + 40e-6) * f / m.fps;
    for (int64_t p = 0; p < 3; ++p) {
      k.at(f, 0, p, 0) = x_at(capture_s);
      k.at(f, 1, p, 0) = x_at(camera1_s);
      k.at(f, 0, p, 1) = k.at(f, 1, p, 1) = 50.0 + p;
      k.at(f, 0, p, 2) = 0.9;
      k.at(f, 1, p, 2) = f == 10 ? 0.4 : 0.8;
    }
  }
  k.at(20, 1, 2, 0) = NAN;  // one missing detection
  const NpyArray<double> before = k;
  ResampleCameraKeypoints(m, 0, &k);
  // A camera on the capture's clock is untouched (bit for bit; the NaN too).
  ASSERT_EQ(k.data.size(), before.data.size());
  EXPECT_EQ(std::memcmp(k.data.data(), before.data.data(), k.data.size() * sizeof(double)), 0);
  ResampleCameraKeypoints(m, 1, &k);
  // Frame 0 is before camera 1 started: nothing there.
  for (int c = 0; c < 3; ++c) EXPECT_TRUE(std::isnan(k.at(0, 1, 0, c))) << c;
  for (int64_t f = 1; f < 30; ++f) {
    for (int64_t p = 0; p < 2; ++p) {
      EXPECT_NEAR(k.at(f, 1, p, 0), k.at(f, 0, p, 0), 1e-9) << f;  // the same instant
      EXPECT_NEAR(k.at(f, 1, p, 1), 50.0 + p, 1e-12);
    }
  }
  // Frames 10 and 11 are between camera 1's frames 9, 10 and 10, 11: the lower score.
  EXPECT_EQ(k.at(10, 1, 0, 2), 0.4);
  EXPECT_EQ(k.at(11, 1, 0, 2), 0.4);
  EXPECT_EQ(k.at(12, 1, 0, 2), 0.8);
  // A missing neighbour leaves the sample missing.
  EXPECT_TRUE(std::isnan(k.at(20, 1, 2, 0)));
  EXPECT_TRUE(std::isnan(k.at(21, 1, 2, 0)));
  EXPECT_FALSE(std::isnan(k.at(22, 1, 2, 0)));
}

// The camera's own frame at a capture frame: its clock's start and rate.
TEST(CaptureManifest, CameraFrameAtFollowsTheCameraClock) {
  CaptureManifest m = SampleManifest();
  m.fps = 30;
  m.cameras[1].offset_s = 1.1;  // started 33 frames after the capture's zero
  EXPECT_EQ(m.CameraFrameAt(0, 129.0), 129.0);
  EXPECT_NEAR(m.CameraFrameAt(1, 34.0), 1.0, 1e-12);
  EXPECT_NEAR(m.CameraFrameAt(1, 100.5), 67.5, 1e-12);
  m.cameras[1].offset_s = 0;
  m.cameras[1].drift_ppm = 50;  // 60 s of capture are 60 / (1 + 50e-6) s of its frames
  EXPECT_NEAR(m.CameraFrameAt(1, 1801.0), 1.0 + 1800.0 / (1 + 50e-6), 1e-9);
}

// The reader samples at the capture's frame times; a stage that rewrites the file reads
// the rows as recorded.
TEST(CaptureKeypoints, ReaderSamplesAtCaptureTimesUnlessAskedForTheRecordedRows) {
  TempDir dir;
  CaptureManifest m = SampleManifest();
  m.cameras[0].dropped_frames = {};
  m.cameras[1].offset_s = 0.5 / m.fps;  // half a frame late
  ASSERT_TRUE(WriteCaptureManifest(dir.path(), m).ok());
  NpyArray<float> k;
  k.shape = {4, 2, 142, 3};
  k.data.assign(4 * 2 * 142 * 3, 1.0f);
  for (int64_t f = 0; f < 4; ++f) k.data[static_cast<size_t>(((f * 2 + 1) * 142) * 3)] = 10.0f * f;
  ASSERT_TRUE(WriteNpy(dir / "keypoints2d.npy", k).ok());
  auto capture = ReadCaptureKeypoints2d(dir.path(), m);
  ASSERT_TRUE(capture.ok()) << capture.status().message();
  EXPECT_TRUE(std::isnan(capture->at(0, 1, 0, 0)));  // before the camera's first frame
  EXPECT_NEAR(capture->at(1, 1, 0, 0), 5.0, 1e-9);   // between its frames 0 and 1
  EXPECT_NEAR(capture->at(3, 1, 0, 0), 25.0, 1e-9);
  EXPECT_EQ(capture->at(2, 0, 0, 0), 1.0);
  auto recorded = ReadCaptureKeypoints2d(dir.path(), m, KeypointTimes::kAsRecorded);
  ASSERT_TRUE(recorded.ok());
  EXPECT_EQ(recorded->at(0, 1, 0, 0), 0.0);
  EXPECT_EQ(recorded->at(3, 1, 0, 0), 30.0);
}

}  // namespace
}  // namespace arco
