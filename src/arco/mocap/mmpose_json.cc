#include "arco/mocap/mmpose_json.h"

#include <cmath>
#include <filesystem>

#include "arco/registry/keypoint_layout.h"
#include "arco/util/file_io.h"
#include "arco/util/json_io.h"

namespace arco {
namespace {

// Point counts read: COCO-WholeBody, or a prefix of it (COCO body; body and feet).
bool KnownCount(size_t n) {
  return n == static_cast<size_t>(wholebody::kNumPoints) ||
         n == static_cast<size_t>(wholebody::kNumBody) ||
         n == static_cast<size_t>(wholebody::kNumBody + wholebody::kNumFeet);
}

// A number, NaN for null (a bare NaN token reads as null); false for anything else.
bool NumberOrNull(const Json& v, double* out) {
  if (v.is_null()) {
    *out = NAN;
    return true;
  }
  if (!v.is_number()) return false;
  *out = v.get<double>();
  return true;
}

class Reader {
 public:
  explicit Reader(const std::string& source) : source_(source) {}

  Status Bad(const std::string& where, const std::string& what) const {
    return Status::Error(source_ + ": " + where + " " + what);
  }

  StatusOr<DetectedPerson> Instance(const Json& j, const std::string& where, int64_t* clamped) {
    if (!j.is_object()) return Bad(where, "must be an object with \"keypoints\"");
    const auto kp = j.find("keypoints");
    if (kp == j.end() || !kp->is_array()) {
      return Bad(where + ".keypoints", "must be an array of [x, y]");
    }
    if (!KnownCount(kp->size())) {
      return Bad(where + ".keypoints",
                 "has " + std::to_string(kp->size()) +
                     " points; expected 133 (COCO-WholeBody), 17 (COCO) or 23 (COCO + feet)");
    }
    const auto scores = j.find("keypoint_scores");
    const bool has_scores = scores != j.end() && !scores->is_null();
    if (has_scores && (!scores->is_array() || scores->size() != kp->size())) {
      return Bad(where + ".keypoint_scores",
                 "must be an array of " + std::to_string(kp->size()) + " scores");
    }
    DetectedPerson person;
    person.keypoints.assign(wholebody::kNumPoints, Eigen::Vector3d::Constant(NAN));
    for (size_t i = 0; i < kp->size(); ++i) {
      const Json& p = (*kp)[i];
      const std::string at = where + ".keypoints[" + std::to_string(i) + "]";
      // [x, y] (MMPose), or [x, y, score] (some converters).
      if (!p.is_array() || (p.size() != 2 && p.size() != 3)) {
        return Bad(at, "must be [x, y]");
      }
      double x, y, s = NAN;
      if (!NumberOrNull(p[0], &x) || !NumberOrNull(p[1], &y) ||
          (p.size() == 3 && !NumberOrNull(p[2], &s))) {
        return Bad(at, "must hold numbers");
      }
      if (has_scores && !NumberOrNull((*scores)[i], &s)) {
        return Bad(where + ".keypoint_scores[" + std::to_string(i) + "]", "must be a number");
      }
      if (!has_scores && p.size() == 2) {
        return Bad(where, "has no \"keypoint_scores\"");
      }
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(s)) continue;  // missing
      person.keypoints[i] = {x, y, ClampScore(s, clamped)};
    }
    if (const auto box = j.find("bbox"); box != j.end() && !box->is_null()) {
      // [[x0, y0, x1, y1]] (split_instances keeps the (1, 4) array) or flat.
      const Json* b = &*box;
      if (b->is_array() && b->size() == 1 && (*b)[0].is_array()) b = &(*b)[0];
      if (!b->is_array() || b->size() != 4) {
        return Bad(where + ".bbox", "must be [x0, y0, x1, y1]");
      }
      for (int c = 0; c < 4; ++c) {
        if (!NumberOrNull((*b)[c], &person.box[c])) {
          return Bad(where + ".bbox", "must hold numbers");
        }
      }
    }
    return person;
  }

  StatusOr<DetectedFrame> Instances(const Json& list, const std::string& where, int64_t* clamped) {
    if (!list.is_array()) return Bad(where, "must be an array of instances");
    DetectedFrame frame;
    for (size_t i = 0; i < list.size(); ++i) {
      ARCO_ASSIGN_OR_RETURN(DetectedPerson person,
                            Instance(list[i], where + "[" + std::to_string(i) + "]", clamped));
      frame.people.push_back(std::move(person));
    }
    return frame;
  }

  // [{"frame_id", "instances"}, ...]: frame frame_id - first_id.
  Status Frames(const Json& list,
                const std::string& where,
                int64_t first_id,
                CameraDetections* out) {
    std::vector<bool> seen;
    for (size_t i = 0; i < list.size(); ++i) {
      const Json& entry = list[i];
      const std::string at = where + "[" + std::to_string(i) + "]";
      if (!entry.is_object()) return Bad(at, "must be {\"frame_id\", \"instances\"}");
      const auto id = entry.find("frame_id");
      if (id == entry.end() || !id->is_number_integer()) {
        return Bad(at + ".frame_id", "must be an integer");
      }
      const auto instances = entry.find("instances");
      if (instances == entry.end()) return Bad(at, "has no \"instances\"");
      if (id->is_number_unsigned() && id->get<uint64_t>() > uint64_t{1} << 40) {
        return Bad(at + ".frame_id", "is too large");
      }
      const int64_t frame = id->get<int64_t>() - first_id;
      if (frame < 0 || frame > int64_t{1} << 30) {
        return Bad(at + ".frame_id",
                   "is " + std::to_string(id->get<int64_t>()) + "; frames count from " +
                       std::to_string(first_id) + " in this form");
      }
      const size_t f = static_cast<size_t>(frame);
      if (f >= seen.size()) {
        seen.resize(f + 1, false);
        out->frames.resize(f + 1);
      }
      if (seen[f]) return Bad(at + ".frame_id", "repeats frame " + id->dump());
      seen[f] = true;
      ARCO_ASSIGN_OR_RETURN(out->frames[f],
                            Instances(*instances, at + ".instances", &out->scores_clamped));
    }
    return Status::Ok();
  }

 private:
  std::string source_;
};

// A list of per-frame entries (each {"frame_id", "instances"}) rather than instances.
bool IsFrameList(const Json& list) {
  return list.is_array() && !list.empty() && list[0].is_object() && list[0].contains("frame_id");
}

}  // namespace

StatusOr<CameraDetections> ParseMmposeJson(const std::string& text, const std::string& source) {
  ARCO_ASSIGN_OR_RETURN(const Json j, ParseJsonLenient(text, source));
  Reader reader(source);
  CameraDetections out;
  if (j.is_object()) {
    const auto info = j.find("instance_info");
    if (info == j.end() || !info->is_array()) {
      return Status::Error(source +
                           ": not MMPose predictions (an object without an \"instance_info\" "
                           "array)");
    }
    if (IsFrameList(*info)) {
      ARCO_RETURN_IF_ERROR(reader.Frames(*info, "instance_info", 1, &out));  // the demo: from 1
    } else {
      out.frames.resize(1);
      ARCO_ASSIGN_OR_RETURN(out.frames[0],
                            reader.Instances(*info, "instance_info", &out.scores_clamped));
    }
    return out;
  }
  if (!j.is_array()) {
    return Status::Error(source + ": not MMPose predictions (expected an array or an object)");
  }
  if (IsFrameList(j)) {
    ARCO_RETURN_IF_ERROR(reader.Frames(j, "", 0, &out));  // MMPoseInferencer: from 0
  } else {
    out.frames.resize(1);
    ARCO_ASSIGN_OR_RETURN(out.frames[0], reader.Instances(j, "", &out.scores_clamped));
  }
  return out;
}

StatusOr<CameraDetections> ReadMmposeKeypoints(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_directory(path, ec)) {
    ARCO_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
    return ParseMmposeJson(text, path);
  }
  ARCO_ASSIGN_OR_RETURN(const std::vector<std::string> files, ListFrameFiles(path, ".json"));
  CameraDetections out;
  for (const std::string& file : files) {
    ARCO_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(file));
    ARCO_ASSIGN_OR_RETURN(CameraDetections one, ParseMmposeJson(text, file));
    if (one.frames.size() != 1) {
      return Status::Error(file + ": holds " + std::to_string(one.frames.size()) +
                           " frames; a folder holds one file per frame");
    }
    out.frames.push_back(std::move(one.frames[0]));
    out.scores_clamped += one.scores_clamped;
  }
  return out;
}

}  // namespace arco
