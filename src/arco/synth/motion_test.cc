// Re-capture of a recorded take (motion.h) on SPD's real cello01 (first 11 s): the truth is
// the recording moved rigidly into the rig, contacts read from the annotation, the audio
// copied, the error models applied; bad input refused with one line naming the file.
#include "arco/synth/motion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>

#include "arco/camera/calibration_io.h"
#include "arco/hand/hand_model.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/synth/capture_writer.h"
#include "arco/synth/error_model.h"
#include "arco/synth/truth_folder.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"
#include "arco/util/npy.h"

namespace arco::synth {
namespace {

const std::string kSpd = std::string(ARCO_SHARED_DATA_DIR) + "/spd/";
const std::string kTake = kSpd + "cello01_first_half_results.npy";
const std::string kAudio = kSpd + "cello01_first_half.wav";

Rig SpdRig() {
  auto text = ReadFileToString(kSpd + "cello_1113_scale_camera.xml");
  EXPECT_TRUE(text.ok());
  auto cal = ParseMetashapeXml(*text, "cello_1113_scale_camera.xml");
  EXPECT_TRUE(cal.ok()) << cal.status().message();
  return cal->rig;
}

MotionOptions Options(double seconds = 3.0) {
  MotionOptions o;
  o.motion_path = kTake;
  o.audio_path = kAudio;
  o.max_duration_s = seconds;
  return o;
}

Eigen::Vector3d At(const NpyArray<double>& a, int f, int p) {
  return {a.at(f, p, 0), a.at(f, p, 1), a.at(f, p, 2)};
}

TEST(Motion, TruthIsTheRecordingMovedRigidly) {
  auto recorded = ReadNpy<double>(kTake);
  ASSERT_TRUE(recorded.ok());
  auto cap = GenerateFromMotion(SpdRig(), Options());
  ASSERT_TRUE(cap.ok()) << cap.status().message();
  ASSERT_EQ(cap->num_frames, 90);
  ASSERT_EQ(cap->points3d.shape[1], 155);
  EXPECT_EQ(cap->truth_layout, "spd_cello_contact");
  // Distances between any two points are kept (a rigid move), across frames too.
  for (int f : {0, 45, 89}) {
    for (auto [p, q] :
         {std::pair{9, 99}, std::pair{91, 134}, std::pair{140, 141}, std::pair{0, 138}}) {
      EXPECT_NEAR((At(cap->points3d, f, p) - At(cap->points3d, 0, q)).norm(),
                  (At(*recorded, f, p) - At(*recorded, 0, q)).norm(),
                  1e-6);
    }
  }
  // The instrument pose of every frame is a proper rigid transform.
  for (int f = 0; f < cap->num_frames; ++f) {
    const Eigen::Matrix3d r = cap->world_from_instrument[static_cast<size_t>(f)].block<3, 3>(0, 0);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-9);
  }
  // Detections: every camera sees most of the performer.
  EXPECT_EQ(cap->keypoints2d.shape[1], 20);
  int64_t seen = 0;
  for (size_t i = 2; i < cap->keypoints2d.data.size(); i += 3) seen += cap->keypoints2d.data[i] > 0;
  EXPECT_GT(static_cast<double>(seen) / (cap->keypoints2d.size() / 3), 0.7);
}

TEST(Motion, CameraSubsets) {
  MotionOptions o = Options(0.5);
  o.cameras = "2";
  auto two = GenerateFromMotion(SpdRig(), o);
  ASSERT_TRUE(two.ok()) << two.status().message();
  ASSERT_EQ(two->rig_mm.cameras.size(), 2u);
  EXPECT_EQ(two->keypoints2d.shape[1], 2);
  // The two chosen views look at the performer from clearly different directions.
  const Eigen::Vector3d bridge = At(two->points3d, 0, 137);
  const Eigen::Vector3d a = (two->rig_mm.cameras[0].CenterInWorld() - bridge).normalized();
  const Eigen::Vector3d b = (two->rig_mm.cameras[1].CenterInWorld() - bridge).normalized();
  EXPECT_LT(a.dot(b), std::cos(30 * M_PI / 180));
  // The same scene: the truth does not depend on the cameras.
  auto all = GenerateFromMotion(SpdRig(), Options(0.5));
  ASSERT_TRUE(all.ok());
  EXPECT_EQ(all->points3d.data, two->points3d.data);
  const Rig rig = SpdRig();
  o.cameras = rig.cameras[3].name + "," + rig.cameras[7].name + "," + rig.cameras[11].name;
  auto named = GenerateFromMotion(rig, o);
  ASSERT_TRUE(named.ok()) << named.status().message();
  ASSERT_EQ(named->rig_mm.cameras.size(), 3u);
  EXPECT_EQ(named->rig_mm.cameras[1].name, rig.cameras[7].name);
  o.cameras = rig.cameras[3].name + ",cam99";
  EXPECT_NE(GenerateFromMotion(SpdRig(), o).status().message().find("no camera 'cam99'"),
            std::string::npos);
  o.cameras = "40";
  EXPECT_NE(GenerateFromMotion(SpdRig(), o).status().message().find("40 requested"),
            std::string::npos);
}

TEST(Motion, ContactsFromTheAnnotation) {
  auto recorded = ReadNpy<double>(kTake);
  ASSERT_TRUE(recorded.ok());
  auto cap = GenerateFromMotion(SpdRig(), Options(11.0));
  ASSERT_TRUE(cap.ok()) << cap.status().message();
  int pressed = 0;
  for (int f = 0; f < cap->num_frames; ++f) {
    const ContactTruth& c = cap->contact[static_cast<size_t>(f)];
    const bool annotated = std::isfinite(recorded->at(f, 150, 0));
    ASSERT_EQ(c.finger > 0, annotated) << f;
    if (!annotated) continue;
    ++pressed;
    // The playing finger's four joints are the left hand's joints of that finger.
    for (int j = 0; j < 4; ++j) {
      const int k =
          wholebody::kLeftHandFirst + hand::KeypointIndex(static_cast<hand::Finger>(c.finger), j);
      EXPECT_LT((At(cap->points3d, f, k) - At(cap->points3d, f, 151 + j)).norm(), 1e-9);
    }
    // The first half of cello01 is played on the A string (string 1).
    EXPECT_EQ(c.string, 1) << f;
    EXPECT_LT((c.point_mm - At(cap->points3d, f, 150)).norm(), 1e-9);
  }
  EXPECT_EQ(pressed, cap->pressed_frames);
  EXPECT_EQ(pressed, 262);
}

TEST(Motion, WritesACaptureWithTheTakesAudioAndNoInventedTruth) {
  arco::testing::TempDir dir;
  auto cap = GenerateFromMotion(SpdRig(), Options(1.0));
  ASSERT_TRUE(cap.ok()) << cap.status().message();
  WriteOptions w;
  ASSERT_TRUE(WriteCapture(*cap, dir / "cap", w).ok());
  EXPECT_EQ(ReadFileToString(dir / "cap/audio.wav").value(), ReadFileToString(kAudio).value());
  EXPECT_FALSE(std::filesystem::exists(dir / "cap/performance.mid"));
  EXPECT_FALSE(std::filesystem::exists(dir / "cap/truth/pitch.csv"));
  auto truth = ReadTruthFolder(dir / "cap/truth");
  ASSERT_TRUE(truth.ok()) << truth.status().message();
  EXPECT_EQ(truth->manifest.motion_source, kTake);
  EXPECT_EQ(truth->manifest.error_model["name"], "synth");
  EXPECT_EQ(truth->manifest.error_model["finger_bias_mm"], 12.0);
  EXPECT_TRUE(truth->pitch.empty());
  for (const auto& h : truth->left_hand) EXPECT_FALSE(h.has_value());  // not a fit
  ASSERT_EQ(truth->contacts.size(), 30u);
  EXPECT_EQ(truth->contacts[0].state, "pressed");
}

TEST(Motion, SameSeedSameCaptureForAnyThreadCount) {
  MotionOptions a = Options(1.0), b = Options(1.0);
  a.num_threads = 1;
  b.num_threads = 2;
  a.detection = b.detection = ErrorModelOptions("harsh").value();
  auto ca = GenerateFromMotion(SpdRig(), a);
  auto cb = GenerateFromMotion(SpdRig(), b);
  ASSERT_TRUE(ca.ok() && cb.ok());
  // Bit for bit (NaN included: memcmp, not ==).
  ASSERT_EQ(ca->keypoints2d.data.size(), cb->keypoints2d.data.size());
  EXPECT_EQ(std::memcmp(ca->keypoints2d.data.data(),
                        cb->keypoints2d.data.data(),
                        ca->keypoints2d.data.size() * sizeof(float)),
            0);
}

// Each named model changes what it says and nothing else: the new errors draw from their
// own streams, so "synth" points outside the left fingers are identical under "shared".
TEST(Motion, ErrorModelsChangeOnlyTheirErrors) {
  MotionOptions base = Options(1.0), shared = Options(1.0), behind = Options(1.0);
  shared.error_model = "shared";
  shared.detection = ErrorModelOptions("shared").value();
  behind.error_model = "behind";
  behind.detection = ErrorModelOptions("behind").value();
  auto cb = GenerateFromMotion(SpdRig(), base);
  auto cs = GenerateFromMotion(SpdRig(), shared);
  auto ch = GenerateFromMotion(SpdRig(), behind);
  ASSERT_TRUE(cb.ok() && cs.ok() && ch.ok());
  const auto& k = cb->keypoints2d;
  int changed_fingers = 0, changed_other = 0, hidden = 0;
  for (int f = 0; f < k.shape[0]; ++f) {
    for (int v = 0; v < k.shape[1]; ++v) {
      for (int p = 0; p < k.shape[2]; ++p) {
        const bool finger = p > wholebody::kLeftHandFirst &&
                            p < wholebody::kLeftHandFirst + wholebody::kNumHandPoints;
        const float x0 = k.at(f, v, p, 0), x1 = cs->keypoints2d.at(f, v, p, 0);
        const bool differs = !(x0 == x1 || (std::isnan(x0) && std::isnan(x1)));
        (finger ? changed_fingers : changed_other) += differs;
        // Seen from behind: a finger point becomes a low-score guess.
        hidden += finger && ch->keypoints2d.at(f, v, p, 2) < 0.5f && k.at(f, v, p, 2) >= 0.5f;
      }
    }
  }
  // Hand swaps carry finger detections into the right hand's slots: those differ too.
  EXPECT_GT(changed_fingers, 1000);
  EXPECT_LT(changed_other, changed_fingers / 10);
  EXPECT_GT(hidden, 100);
  EXPECT_EQ(cs->error_model["finger_offset_mm"], 5.0);
}

TEST(Motion, FingerConfusionsSwapNeighbouringFingers) {
  MotionOptions clean = Options(1.0), confused = Options(1.0);
  clean.error_model = "clean";
  clean.detection = ErrorModelOptions("clean").value();
  confused.detection = clean.detection;
  confused.detection.finger_confusion_rate = 0.5;
  auto a = GenerateFromMotion(SpdRig(), clean);
  auto b = GenerateFromMotion(SpdRig(), confused);
  ASSERT_TRUE(a.ok() && b.ok());
  const int w = wholebody::kLeftHandFirst;
  int swaps = 0;
  for (int f = 0; f < a->keypoints2d.shape[0]; ++f) {
    for (int v = 0; v < a->keypoints2d.shape[1]; ++v) {
      for (int g = 1; g <= 3; ++g) {  // index-middle, middle-ring, ring-little
        const int tip_g = w + hand::TipKeypoint(static_cast<hand::Finger>(g));
        const int tip_h = tip_g + 4;
        swaps += a->keypoints2d.at(f, v, tip_g, 0) == b->keypoints2d.at(f, v, tip_h, 0) &&
                 a->keypoints2d.at(f, v, tip_h, 0) == b->keypoints2d.at(f, v, tip_g, 0) &&
                 !std::isnan(a->keypoints2d.at(f, v, tip_g, 0));
      }
    }
  }
  const int view_frames = a->keypoints2d.shape[0] * a->keypoints2d.shape[1];
  EXPECT_GT(swaps, view_frames / 4);
  EXPECT_LT(swaps, 3 * view_frames / 4);
}

TEST(Motion, BadInputIsOneLineNamingTheFile) {
  arco::testing::TempDir dir;
  auto recorded = ReadNpy<double>(kTake);
  ASSERT_TRUE(recorded.ok());
  auto run = [&](const MotionOptions& o) { return GenerateFromMotion(SpdRig(), o).status(); };
  // A layout it does not know: 150 points per frame.
  {
    NpyArray<double> cut;
    cut.shape = {10, 150, 3};
    cut.data.assign(10 * 150 * 3, 1.0);
    ASSERT_TRUE(WriteNpy(dir / "cut.npy", cut).ok());
    MotionOptions o = Options();
    o.motion_path = dir / "cut.npy";
    const Status s = run(o);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.message().rfind(o.motion_path + ": shape (10, 150, 3)", 0), 0u) << s.message();
  }
  // A NaN in a body point.
  {
    NpyArray<double> nan = *recorded;
    nan.at(7, 10, 1) = NAN;
    ASSERT_TRUE(WriteNpy(dir / "nan.npy", nan).ok());
    MotionOptions o = Options();
    o.motion_path = dir / "nan.npy";
    const Status s = run(o);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.message().find("nan.npy: frame 7: point 10 (right_wrist) is not finite"),
              std::string::npos)
        << s.message();
  }
  // Part of a contact.
  {
    NpyArray<double> half = *recorded;
    half.at(3, 152, 0) = NAN;
    ASSERT_TRUE(WriteNpy(dir / "half.npy", half).ok());
    MotionOptions o = Options();
    o.motion_path = dir / "half.npy";
    EXPECT_NE(run(o).message().find("frame 3: the contact point"), std::string::npos);
  }
  // An audio shorter than the motion (the whole 11 s take against 1 s of audio).
  {
    MotionOptions o = Options(0);
    o.audio_path = kSpd + "background.wav";  // 20.4 s: long enough
    EXPECT_TRUE(run(o).ok());
  }
  {
    NpyArray<double> longer;
    longer.shape = {700, 155, 3};  // 23.3 s at 30 fps, beyond the 11 s recording
    for (int f = 0; f < 700; ++f)
      for (int p = 0; p < 155 * 3; ++p) longer.data.push_back(recorded->data[(f % 330) * 465 + p]);
    ASSERT_TRUE(WriteNpy(dir / "long.npy", longer).ok());
    MotionOptions o = Options(0);
    o.motion_path = dir / "long.npy";
    const Status s = run(o);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.message().rfind(kAudio + ": ", 0), 0u) << s.message();
    EXPECT_NE(s.message().find("shorter than the motion"), std::string::npos);
  }
  // A rig that does not see the performer: images too small to hold it.
  {
    Rig rig = SpdRig();
    for (Camera& c : rig.cameras) c.width = c.height = 8;
    const auto s = GenerateFromMotion(rig, Options()).status();
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.message().find("sees the placed instrument in 0 camera(s)"), std::string::npos)
        << s.message();
  }
  // An unknown error model.
  {
    MotionOptions o = Options();
    o.error_model = "gentle";
    EXPECT_NE(run(o).message().find("unknown error model 'gentle'"), std::string::npos);
  }
}

}  // namespace
}  // namespace arco::synth
