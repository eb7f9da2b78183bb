#include "arco/mocap/openpose_json.h"

#include <array>
#include <cmath>
#include <filesystem>

#include "arco/registry/keypoint_layout.h"
#include "arco/util/file_io.h"
#include "arco/util/json_io.h"

namespace arco {
namespace {

// OpenPose's pose models' points in their order (OpenPose's doc/02_output.md), named as
// the COCO-WholeBody points they are; "" has no COCO-WholeBody slot.
constexpr std::array<const char*, 25> kBody25 = {"nose",
                                                 "",
                                                 "right_shoulder",
                                                 "right_elbow",
                                                 "right_wrist",
                                                 "left_shoulder",
                                                 "left_elbow",
                                                 "left_wrist",
                                                 "",
                                                 "right_hip",
                                                 "right_knee",
                                                 "right_ankle",
                                                 "left_hip",
                                                 "left_knee",
                                                 "left_ankle",
                                                 "right_eye",
                                                 "left_eye",
                                                 "right_ear",
                                                 "left_ear",
                                                 "left_big_toe",
                                                 "left_small_toe",
                                                 "left_heel",
                                                 "right_big_toe",
                                                 "right_small_toe",
                                                 "right_heel"};
constexpr std::array<const char*, 18> kCoco18 = {"nose",
                                                 "",
                                                 "right_shoulder",
                                                 "right_elbow",
                                                 "right_wrist",
                                                 "left_shoulder",
                                                 "left_elbow",
                                                 "left_wrist",
                                                 "right_hip",
                                                 "right_knee",
                                                 "right_ankle",
                                                 "left_hip",
                                                 "left_knee",
                                                 "left_ankle",
                                                 "right_eye",
                                                 "left_eye",
                                                 "right_ear",
                                                 "left_ear"};
constexpr int kOpenPoseFacePoints = 70;  // the 68 of COCO-WholeBody's face, then 2 pupils

// Slots of a pose model's points in COCO-WholeBody, looked up by name (-1: none).
template <size_t N>
std::array<int, N> Slots(const std::array<const char*, N>& names) {
  const KeypointLayout* layout = FindKeypointLayout("coco_wholebody_133");
  std::array<int, N> slots;
  for (size_t i = 0; i < N; ++i) slots[i] = names[i][0] ? layout->Find(names[i]) : -1;
  return slots;
}

class FrameReader {
 public:
  FrameReader(const std::string& source, DetectedPerson* person, int64_t* clamped)
      : source_(source), person_(person), clamped_(clamped) {}

  // Reads field `key` of `j` ([x, y, c] x n, n one of `counts`, or empty) into the
  // slots `slot(i)`; *n_read = points read.
  template <typename SlotOf>
  Status Points(const Json& j,
                const std::string& where,
                const char* key,
                std::initializer_list<size_t> counts,
                const SlotOf& slot,
                size_t* n_read = nullptr) {
    const auto it = j.find(key);
    if (it == j.end() || it->is_null()) return Status::Ok();
    const std::string at = where + "." + key;
    if (!it->is_array()) return Bad(at, "must be an array of numbers");
    const size_t size = it->size();
    bool known = size == 0;
    std::string expected;
    for (size_t n : counts) {
      known = known || size == 3 * n;
      expected += (expected.empty() ? "" : " or ") + std::to_string(3 * n) + " (" +
                  std::to_string(n) + " x [x, y, c])";
    }
    if (!known) {
      return Bad(at, "has " + std::to_string(size) + " values; expected " + expected);
    }
    for (size_t i = 0; i < size / 3; ++i) {
      double v[3];
      for (int c = 0; c < 3; ++c) {
        const Json& x = (*it)[3 * i + c];
        if (x.is_null()) {
          v[c] = NAN;
        } else if (x.is_number()) {
          v[c] = x.get<double>();
        } else {
          return Bad(at, "holds " + x.dump().substr(0, 20) + "; must hold numbers");
        }
      }
      const int s = slot(i, size / 3);
      // A confidence of 0 (OpenPose's 0, 0, 0) or a non-finite value: no point.
      if (s < 0 || !(v[2] > 0) || !std::isfinite(v[0]) || !std::isfinite(v[1])) continue;
      person_->keypoints[static_cast<size_t>(s)] = {v[0], v[1], ClampScore(v[2], clamped_)};
    }
    if (n_read) *n_read = size / 3;
    return Status::Ok();
  }

  Status Bad(const std::string& where, const std::string& what) const {
    return Status::Error(source_ + ": " + where + " " + what);
  }

 private:
  std::string source_;
  DetectedPerson* person_;
  int64_t* clamped_;
};

StatusOr<DetectedFrame> ParseFrame(const std::string& text,
                                   const std::string& source,
                                   int64_t* clamped) {
  static const std::array<int, 25> body25 = Slots(kBody25);
  static const std::array<int, 18> coco18 = Slots(kCoco18);
  ARCO_ASSIGN_OR_RETURN(const Json j, ParseJsonLenient(text, source));
  if (!j.is_object()) return Status::Error(source + ": not OpenPose JSON (expected an object)");
  const auto people = j.find("people");
  if (people == j.end() || !people->is_array()) {
    return Status::Error(source + ": not OpenPose JSON (no \"people\" array)");
  }
  DetectedFrame frame;
  for (size_t p = 0; p < people->size(); ++p) {
    const Json& person_json = (*people)[p];
    const std::string where = "people[" + std::to_string(p) + "]";
    if (!person_json.is_object()) {
      return Status::Error(source + ": " + where + " must be an object");
    }
    DetectedPerson person;
    person.keypoints.assign(wholebody::kNumPoints, Eigen::Vector3d::Constant(NAN));
    FrameReader reader(source, &person, clamped);
    ARCO_RETURN_IF_ERROR(
        reader.Points(person_json, where, "pose_keypoints_2d", {25, 18}, [](size_t i, size_t n) {
          return n == 25 ? body25[i] : coco18[i];
        }));
    ARCO_RETURN_IF_ERROR(reader.Points(
        person_json, where, "face_keypoints_2d", {kOpenPoseFacePoints}, [](size_t i, size_t) {
          return i < static_cast<size_t>(wholebody::kNumFace)
                     ? wholebody::kFaceFirst + static_cast<int>(i)
                     : -1;
        }));
    ARCO_RETURN_IF_ERROR(reader.Points(
        person_json,
        where,
        "hand_left_keypoints_2d",
        {static_cast<size_t>(wholebody::kNumHandPoints)},
        [](size_t i, size_t) { return wholebody::kLeftHandFirst + static_cast<int>(i); }));
    ARCO_RETURN_IF_ERROR(reader.Points(
        person_json,
        where,
        "hand_right_keypoints_2d",
        {static_cast<size_t>(wholebody::kNumHandPoints)},
        [](size_t i, size_t) { return wholebody::kRightHandFirst + static_cast<int>(i); }));
    frame.people.push_back(std::move(person));
  }
  return frame;
}

}  // namespace

StatusOr<DetectedFrame> ParseOpenPoseFrame(const std::string& text, const std::string& source) {
  int64_t clamped = 0;
  return ParseFrame(text, source, &clamped);
}

StatusOr<CameraDetections> ReadOpenPoseKeypoints(const std::string& path) {
  std::error_code ec;
  std::vector<std::string> files;
  if (std::filesystem::is_directory(path, ec)) {
    ARCO_ASSIGN_OR_RETURN(files, ListFrameFiles(path, "_keypoints.json"));
  } else {
    files = {path};
  }
  CameraDetections out;
  for (const std::string& file : files) {
    ARCO_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(file));
    ARCO_ASSIGN_OR_RETURN(DetectedFrame frame, ParseFrame(text, file, &out.scores_clamped));
    out.frames.push_back(std::move(frame));
  }
  return out;
}

}  // namespace arco
