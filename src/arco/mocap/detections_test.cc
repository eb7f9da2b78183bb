// The MMPose and OpenPose readers on small hand-written files: every form they write,
// the mapping into COCO-WholeBody, the person kept, and malformed files.
#include "arco/mocap/detections.h"

#include <gtest/gtest.h>

#include <cmath>

#include "arco/mocap/mmpose_json.h"
#include "arco/mocap/openpose_json.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"

namespace arco {
namespace {

using arco::testing::TempDir;

const KeypointLayout& Coco() { return *FindKeypointLayout("coco_wholebody_133"); }

// `n` points at (p, 2p) with score 0.5; point 3 null (as NaN is written).
std::string MmInstance(int n, const std::string& extra = "") {
  std::string kp, sc;
  for (int p = 0; p < n; ++p) {
    kp += (p ? "," : "") + (p == 3 ? std::string("[NaN, NaN]")
                                   : "[" + std::to_string(p) + "," + std::to_string(2 * p) + "]");
    sc += (p ? "," : "") + std::string(p == 3 ? "NaN" : "0.5");
  }
  return "{\"keypoints\": [" + kp + "], \"keypoint_scores\": [" + sc + "]" + extra + "}";
}

TEST(ParseMmposeJson, ReadsEveryForm) {
  // Per image: the inferencer's list, and the demo's object.
  for (const std::string& text :
       {"[" + MmInstance(133) + "]",
        "{\"meta_info\": {\"dataset_name\": \"coco_wholebody\"}, \"instance_info\": [" +
            MmInstance(133) + "]}"}) {
    const auto d = ParseMmposeJson(text, "img.json");
    ASSERT_TRUE(d.ok()) << d.status().message();
    ASSERT_EQ(d->frames.size(), 1u);
    ASSERT_EQ(d->frames[0].people.size(), 1u);
    const auto& k = d->frames[0].people[0].keypoints;
    ASSERT_EQ(k.size(), 133u);
    EXPECT_EQ(k[100], Eigen::Vector3d(100, 200, 0.5));
    EXPECT_TRUE(std::isnan(k[3].x()));
  }
  // Per video: the inferencer counts frames from 0, the demo from 1.
  const std::string frames = "{\"frame_id\": F0, \"instances\": [" + MmInstance(17) +
                             "]}, {\"frame_id\": F2, \"instances\": []}";
  auto with = [&](int first) {
    std::string t = frames;
    t.replace(t.find("F0"), 2, std::to_string(first));
    t.replace(t.find("F2"), 2, std::to_string(first + 2));
    return t;
  };
  for (const auto& [text, name] :
       {std::pair{"[" + with(0) + "]", "inferencer"},
        std::pair{"{\"meta_info\": {}, \"instance_info\": [" + with(1) + "]}", "demo"}}) {
    const auto d = ParseMmposeJson(text, "video.json");
    ASSERT_TRUE(d.ok()) << name << ": " << d.status().message();
    ASSERT_EQ(d->frames.size(), 3u) << name;
    ASSERT_EQ(d->frames[0].people.size(), 1u) << name;
    EXPECT_TRUE(d->frames[1].people.empty()) << name;  // skipped frame
    EXPECT_TRUE(d->frames[2].people.empty()) << name;
    const auto& k = d->frames[0].people[0].keypoints;
    EXPECT_EQ(k[16], Eigen::Vector3d(16, 32, 0.5));             // COCO body
    EXPECT_TRUE(std::isnan(k[wholebody::kLeftHandFirst].x()));  // not in a 17-point model
  }
}

TEST(ParseMmposeJson, ClampsScoresAndKeepsTheLargestPerson) {
  const std::string text = "[" + MmInstance(17, ", \"bbox\": [[0, 0, 10, 10]]") + ", " +
                           MmInstance(17, ", \"bbox\": [5, 5, 50, 60]") + "]";
  auto d = ParseMmposeJson(text, "img.json");
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_EQ(SelectPerson(d->frames[0]), 1);
  EXPECT_DOUBLE_EQ(d->frames[0].people[1].BoxArea(), 45.0 * 55.0);
  // Without boxes: the extent of the scored points.
  DetectedFrame f;
  f.people.resize(2);
  f.people[0].keypoints = {{0, 0, 1}, {10, 10, 1}};
  f.people[1].keypoints = {{0, 0, 1}, {100, 100, 0}};  // score 0: not counted
  EXPECT_EQ(SelectPerson(f), 0);
  EXPECT_EQ(SelectPerson(DetectedFrame{}), -1);
  int64_t clamped = 0;
  EXPECT_EQ(ClampScore(3.2, &clamped), 1.0);
  EXPECT_EQ(ClampScore(-0.1, &clamped), 0.0);
  EXPECT_EQ(ClampScore(0.4, &clamped), 0.4);
  EXPECT_TRUE(std::isnan(ClampScore(NAN, &clamped)));
  EXPECT_EQ(clamped, 2);
}

TEST(ParseMmposeJson, MalformedFilesAreOneLineNamingTheFile) {
  const std::vector<std::string> bad = {
      "",
      "not json",
      "42",
      "{\"meta_info\": {}}",
      "{\"instance_info\": 3}",
      "[{\"keypoints\": [[1, 2]], \"keypoint_scores\": [1]}]",  // 1 point
      "[{\"keypoint_scores\": []}]",
      "[{\"keypoints\": 5}]",
      "[" + MmInstance(17).replace(MmInstance(17).find("[0,0]"), 5, "[0]") + "]",
      "[" + MmInstance(17).replace(MmInstance(17).find("[0,0]"), 5, "[\"a\", 0]") + "]",
      "[{\"keypoints\": [[1, 2], [3, 4]]}]",
      "[" + MmInstance(17, ", \"bbox\": [1, 2]") + "]",
      "[" + MmInstance(17, ", \"bbox\": [\"a\", 2, 3, 4]") + "]",
      "[" + MmInstance(17).replace(MmInstance(17).find("0.5"), 3, "\"x\"") + "]",
      "[{\"frame_id\": 0, \"instances\": []}, {\"frame_id\": 0, \"instances\": []}]",
      "[{\"frame_id\": -1, \"instances\": []}]",
      "[{\"frame_id\": 1.5, \"instances\": []}]",
      "[{\"frame_id\": 99999999999999999999, \"instances\": []}]",
      "[{\"frame_id\": 0}]",
      "[{\"frame_id\": 0, \"instances\": 7}]",
      "{\"instance_info\": [{\"frame_id\": 0, \"instances\": []}]}",  // the demo counts from 1
      "[[1, 2]]",
  };
  for (const std::string& text : bad) {
    const auto d = ParseMmposeJson(text, "bad.json");
    ASSERT_FALSE(d.ok()) << "accepted: " << text;
    EXPECT_EQ(d.status().message().rfind("bad.json: ", 0), 0u) << d.status().message();
    EXPECT_EQ(d.status().message().find('\n'), std::string::npos) << d.status().message();
  }
}

TEST(ReadMmposeKeypoints, FolderInNaturalOrder) {
  TempDir dir;
  // 17 points each, x = the file's number.
  for (int k : {10, 2, 1}) {
    std::string kp, sc;
    for (int p = 0; p < 17; ++p) {
      kp += (p ? "," : "") + std::string("[") + std::to_string(k) + ", 0]";
      sc += (p ? "," : "") + std::string("1");
    }
    ASSERT_TRUE(
        AtomicWriteFile(dir / ("frame" + std::to_string(k) + ".json"),
                        "[{\"keypoints\": [" + kp + "], \"keypoint_scores\": [" + sc + "]}]")
            .ok());
  }
  const auto d = ReadMmposeKeypoints(dir.path());
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_EQ(d->frames.size(), 3u);
  EXPECT_EQ(d->frames[0].people[0].keypoints[0].x(), 1);
  EXPECT_EQ(d->frames[1].people[0].keypoints[0].x(), 2);
  EXPECT_EQ(d->frames[2].people[0].keypoints[0].x(), 10);
  TempDir empty_holder;
  const auto none = ReadMmposeKeypoints(empty_holder.path());
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.status().message().rfind(empty_holder.path() + ": ", 0), 0u);
}

std::string Flat(int n, int detected, double x, double y, double c) {
  std::string out;
  for (int i = 0; i < n; ++i) {
    out += (i ? "," : "") +
           (i == detected ? std::to_string(x) + "," + std::to_string(y) + "," + std::to_string(c)
                          : std::string("0,0,0"));
  }
  return out;
}

TEST(ParseOpenPoseFrame, MapsBody25HandsAndFaceToWholeBody) {
  const KeypointLayout& coco = Coco();
  // BODY_25 point k -> the COCO-WholeBody point of that name.
  const std::vector<std::pair<int, std::string>> body25 = {{0, "nose"},
                                                           {2, "right_shoulder"},
                                                           {4, "right_wrist"},
                                                           {5, "left_shoulder"},
                                                           {7, "left_wrist"},
                                                           {9, "right_hip"},
                                                           {11, "right_ankle"},
                                                           {12, "left_hip"},
                                                           {14, "left_ankle"},
                                                           {15, "right_eye"},
                                                           {16, "left_eye"},
                                                           {17, "right_ear"},
                                                           {18, "left_ear"},
                                                           {19, "left_big_toe"},
                                                           {21, "left_heel"},
                                                           {22, "right_big_toe"},
                                                           {24, "right_heel"}};
  for (const auto& [k, name] : body25) {
    const std::string text =
        "{\"people\": [{\"pose_keypoints_2d\": [" + Flat(25, k, 3.5, 4.5, 0.75) + "]}]}";
    const auto f = ParseOpenPoseFrame(text, "f.json");
    ASSERT_TRUE(f.ok()) << f.status().message();
    ASSERT_EQ(f->people.size(), 1u);
    const auto& points = f->people[0].keypoints;
    int found = 0;
    for (size_t p = 0; p < points.size(); ++p) found += std::isfinite(points[p].x());
    EXPECT_EQ(found, 1) << "BODY_25 " << k;
    EXPECT_EQ(points[coco.Find(name)], Eigen::Vector3d(3.5, 4.5, 0.75)) << "BODY_25 " << k;
  }
  // Neck (1) and mid hip (8) have no slot.
  for (int k : {1, 8}) {
    const auto f = ParseOpenPoseFrame(
        "{\"people\": [{\"pose_keypoints_2d\": [" + Flat(25, k, 3, 4, 1) + "]}]}", "f.json");
    ASSERT_TRUE(f.ok());
    for (const auto& p : f->people[0].keypoints) EXPECT_FALSE(std::isfinite(p.x()));
  }
  // Hands in hand_21 order; face's first 68 points.
  const std::string text =
      "{\"people\": [{\"pose_keypoints_2d\": [], \"hand_left_keypoints_2d\": [" +
      Flat(21, 8, 1, 2, 0.5) + "], \"hand_right_keypoints_2d\": [" + Flat(21, 20, 5, 6, 0.5) +
      "], \"face_keypoints_2d\": [" + Flat(70, 30, 7, 8, 0.5) + "]}, {\"pose_keypoints_2d\": []}]}";
  const auto f = ParseOpenPoseFrame(text, "f.json");
  ASSERT_TRUE(f.ok()) << f.status().message();
  ASSERT_EQ(f->people.size(), 2u);
  const auto& points = f->people[0].keypoints;
  EXPECT_EQ(points[coco.Find("left_hand_index_tip")], Eigen::Vector3d(1, 2, 0.5));
  EXPECT_EQ(points[coco.Find("right_hand_little_tip")], Eigen::Vector3d(5, 6, 0.5));
  EXPECT_EQ(points[coco.Find("face_30")], Eigen::Vector3d(7, 8, 0.5));
  // COCO-18 (OpenPose's COCO model): left shoulder is 5 there too, right hip 8.
  const auto c18 = ParseOpenPoseFrame(
      "{\"people\": [{\"pose_keypoints_2d\": [" + Flat(18, 8, 9, 9, 1) + "]}]}", "f.json");
  ASSERT_TRUE(c18.ok()) << c18.status().message();
  EXPECT_EQ(c18->people[0].keypoints[coco.Find("right_hip")], Eigen::Vector3d(9, 9, 1));
}

TEST(ParseOpenPoseFrame, MalformedFilesAreOneLineNamingTheFile) {
  const std::vector<std::string> bad = {
      "",
      "[]",
      "{\"version\": 1.3}",
      "{\"people\": 3}",
      "{\"people\": [7]}",
      "{\"people\": [{\"pose_keypoints_2d\": [1, 2, 3]}]}",
      "{\"people\": [{\"pose_keypoints_2d\": 5}]}",
      "{\"people\": [{\"pose_keypoints_2d\": [" + Flat(25, 0, 1, 1, 1) + ", 4]}]}",
      "{\"people\": [{\"hand_left_keypoints_2d\": [" + Flat(20, 0, 1, 1, 1) + "]}]}",
      "{\"people\": [{\"face_keypoints_2d\": [" + Flat(68, 0, 1, 1, 1) + "]}]}",
      "{\"people\": [{\"pose_keypoints_2d\": [\"a\"" + std::string(",0") +
          Flat(25, 0, 1, 1, 1).substr(1) + "]}]}",
  };
  for (const std::string& text : bad) {
    const auto f = ParseOpenPoseFrame(text, "bad_keypoints.json");
    ASSERT_FALSE(f.ok()) << "accepted: " << text;
    EXPECT_EQ(f.status().message().rfind("bad_keypoints.json: ", 0), 0u) << f.status().message();
    EXPECT_EQ(f.status().message().find('\n'), std::string::npos);
  }
  EXPECT_TRUE(ParseOpenPoseFrame("{\"people\": []}", "f.json").ok());
}

TEST(ReadOpenPoseKeypoints, FolderOfKeypointFilesInNaturalOrder) {
  TempDir dir;
  for (int k : {11, 9, 10}) {
    const std::string text =
        "{\"people\": [{\"pose_keypoints_2d\": [" + Flat(25, 0, k, 0, 1) + "]}]}";
    ASSERT_TRUE(AtomicWriteFile(dir / ("v_" + std::to_string(k) + "_keypoints.json"), text).ok());
  }
  ASSERT_TRUE(AtomicWriteFile(dir / "readme.json", "{}").ok());
  const auto d = ReadOpenPoseKeypoints(dir.path());
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_EQ(d->frames.size(), 3u);
  EXPECT_EQ(d->frames[0].people[0].keypoints[0].x(), 9);
  EXPECT_EQ(d->frames[2].people[0].keypoints[0].x(), 11);
  ASSERT_TRUE(AtomicWriteFile(dir / "v_12_keypoints.json", "{\"people\": [1]}").ok());
  const auto bad = ReadOpenPoseKeypoints(dir.path());
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().message().rfind(dir / "v_12_keypoints.json: ", 0), 0u)
      << bad.status().message();
}

}  // namespace
}  // namespace arco
