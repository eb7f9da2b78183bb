#include "arco/capture/import_keypoints.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "arco/calibration/calibration_file.h"
#include "arco/capture/capture_checks.h"
#include "arco/mocap/capture.h"
#include "arco/mocap/mmpose_json.h"
#include "arco/mocap/openpose_json.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/util/check.h"
#include "arco/util/file_io.h"
#include "arco/util/json_io.h"
#include "arco/util/npy.h"
#include "arco/util/output_set.h"

namespace arco::capture {
namespace {

constexpr char kKeypointsFile[] = "keypoints2d.npy";

}  // namespace

Eigen::Vector2d RotateDecodedPixel(const Eigen::Vector2d& pixel,
                                   int rotate_deg,
                                   const Eigen::Vector2i& rotated_size) {
  // Pixel centres at integers: turning a W x H image clockwise by 90 degrees sends the
  // centre (x, y) to (H - 1 - y, x), and H is the turned image's width.
  const double w = rotated_size.x() - 1.0, h = rotated_size.y() - 1.0;
  switch (rotate_deg) {
    case 90:
      return {w - pixel.y(), pixel.x()};
    case 180:
      return {w - pixel.x(), h - pixel.y()};
    case 270:
      return {pixel.y(), h - pixel.x()};
    default:
      return pixel;
  }
}

Status ImportKeypointsOptions::Validate() const {
  if (capture_dir.empty()) return Status::Error("capture_dir is empty");
  if (format != "mmpose" && format != "openpose") {
    return Status::Error("format is \"" + format + "\"; must be mmpose or openpose");
  }
  if (!pixels.empty() && pixels != "decoded" && pixels != "calibration") {
    return Status::Error("pixels is \"" + pixels + "\"; must be decoded or calibration");
  }
  if (sources.empty()) return Status::Error("sources: give every camera's keypoints");
  std::set<std::string> cameras;
  for (const ImportKeypointsSource& s : sources) {
    if (s.camera.empty() || s.path.empty()) {
      return Status::Error("sources: a camera or a path is empty");
    }
    if (!cameras.insert(s.camera).second) {
      return Status::Error("sources: camera " + s.camera + " is given twice");
    }
  }
  return Status::Ok();
}

StatusOr<ImportKeypointsSummary> ImportKeypoints(const ImportKeypointsOptions& o) {
  ARCO_RETURN_IF_ERROR(o.Validate());
  ARCO_ASSIGN_OR_RETURN(CaptureManifest m, ReadCaptureManifest(o.capture_dir));
  const std::string manifest_path = CaptureManifestPath(o.capture_dir);
  if (!m.keypoints2d.empty() && !o.overwrite) {
    return Status::Error(manifest_path + ": already names 2D keypoints (" + m.keypoints2d +
                         "); overwrite replaces them");
  }
  ImportKeypointsSummary out;
  ARCO_ASSIGN_OR_RETURN(out.layout, DetectionLayoutName(m.instrument));
  const KeypointLayout* layout = FindKeypointLayout(out.layout);
  ARCO_CHECK(layout != nullptr);
  // Every camera once, in the manifest's view order.
  std::vector<const ImportKeypointsSource*> by_view(m.cameras.size(), nullptr);
  for (const ImportKeypointsSource& s : o.sources) {
    const int v = m.FindCamera(s.camera);
    if (v < 0) {
      return Status::Error(manifest_path + ": no camera \"" + s.camera + "\" (given for " + s.path +
                           ")");
    }
    if (by_view[static_cast<size_t>(v)]) {
      return Status::Error(manifest_path + ": camera \"" + m.cameras[v].name +
                           "\" is given twice (" + s.path + ")");
    }
    by_view[static_cast<size_t>(v)] = &s;
  }
  for (size_t v = 0; v < m.cameras.size(); ++v) {
    if (!by_view[v]) {
      return Status::Error(manifest_path + ": camera \"" + m.cameras[v].name +
                           "\" has no keypoints; give every camera's");
    }
  }
  // A rotated camera's decoded pixels are turned into the calibration's image, whose size
  // the calibration gives.
  std::vector<Eigen::Vector2i> image_size(m.cameras.size(), Eigen::Vector2i::Zero());
  bool rotated = false;
  for (const CaptureCamera& c : m.cameras) rotated = rotated || c.rotate_deg != 0;
  if (rotated && o.pixels.empty()) {
    for (const CaptureCamera& c : m.cameras) {
      if (c.rotate_deg == 0) continue;
      return Status::Error(manifest_path + ": camera \"" + c.name + "\" has rotate_deg " +
                           std::to_string(c.rotate_deg) +
                           "; say whether the keypoints' pixels are in the decoded frames "
                           "(pixels = decoded: they are turned the same way) or already in "
                           "the calibration's image (pixels = calibration)");
    }
  }
  if (rotated && o.pixels == "decoded") {
    const std::string calibration_path = ResolveCapturePath(o.capture_dir, m.calibration);
    StatusOr<Calibration> calibration = calibration::LoadCalibration(calibration_path);
    if (!calibration.ok()) return calibration.status().WithContext(manifest_path + ": calibration");
    ARCO_ASSIGN_OR_RETURN(
        const std::vector<int> cameras,
        MatchCaptureCameras(o.capture_dir, m, calibration->rig, calibration_path));
    for (size_t v = 0; v < m.cameras.size(); ++v) {
      const Camera& cam = calibration->rig.cameras[static_cast<size_t>(cameras[v])];
      image_size[v] = {cam.width, cam.height};
    }
  }
  // Declared before the work: both or neither.
  const std::string keypoints_name = m.keypoints2d.empty() ? kKeypointsFile : m.keypoints2d;
  OutputSet outputs;
  ARCO_ASSIGN_OR_RETURN(const std::string npy_tmp,
                        outputs.AddFile(ResolveCapturePath(o.capture_dir, keypoints_name)));
  ARCO_ASSIGN_OR_RETURN(const std::string manifest_tmp, outputs.AddFile(manifest_path));

  const int64_t frames = m.frame_count;
  const int64_t views = static_cast<int64_t>(m.cameras.size());
  const int64_t points = layout->size();
  NpyArray<float> k;
  k.shape = {frames, views, points, 3};
  k.data.assign(static_cast<size_t>(frames * views * points * 3), NAN);
  const int64_t last = m.frame_first + m.frame_count - 1;
  for (int64_t v = 0; v < views; ++v) {
    const ImportKeypointsSource& s = *by_view[static_cast<size_t>(v)];
    ARCO_ASSIGN_OR_RETURN(
        const CameraDetections d,
        o.format == "mmpose" ? ReadMmposeKeypoints(s.path) : ReadOpenPoseKeypoints(s.path));
    out.report.scores_clamped += d.scores_clamped;
    // The camera's video frames up to the capture's last global frame.
    int64_t video_frames = 0;
    for (int64_t g = last; g >= 0 && video_frames == 0; --g) {
      video_frames = std::max<int64_t>(0, m.VideoFrameNumber(static_cast<int>(v), g));
    }
    const int64_t have = static_cast<int64_t>(d.frames.size());
    std::error_code ec;
    const bool folder = std::filesystem::is_directory(s.path, ec);
    if (have > video_frames || (folder && have != video_frames)) {
      return Status::Error(s.path + ": " + std::to_string(have) + " frames of keypoints, but " +
                           "camera " + m.cameras[v].name + " has " + std::to_string(video_frames) +
                           " video frames up to global frame " + std::to_string(last) + " (" +
                           manifest_path + ")");
    }
    for (int64_t f = 0; f < frames; ++f) {
      const int64_t video_frame = m.VideoFrameNumber(static_cast<int>(v), m.frame_first + f);
      if (video_frame < 1) continue;  // dropped: NaN
      const int64_t index = video_frame - 1;
      if (index >= have || d.frames[index].people.empty()) {
        ++out.report.frames_without_person;
        continue;
      }
      const DetectedFrame& frame = d.frames[index];
      if (frame.people.size() > 1) ++out.report.frames_with_several;
      const DetectedPerson& person = frame.people[static_cast<size_t>(SelectPerson(frame))];
      ++out.report.people_kept;
      // The layout begins with COCO-WholeBody's 133 points (registry/keypoint_layout.h).
      for (int p = 0; p < wholebody::kNumPoints; ++p) {
        const Eigen::Vector3d& row = person.keypoints[static_cast<size_t>(p)];
        if (!row.allFinite()) continue;
        float* at = &k.data[static_cast<size_t>(((f * views + v) * points + p) * 3)];
        const Eigen::Vector2d pixel =
            o.pixels == "decoded"
                ? RotateDecodedPixel(row.head<2>(), m.cameras[v].rotate_deg, image_size[v])
                : Eigen::Vector2d(row.head<2>());
        at[0] = static_cast<float>(pixel.x());
        at[1] = static_cast<float>(pixel.y());
        at[2] = static_cast<float>(row.z());
      }
    }
  }
  if (out.report.scores_clamped > 0) {
    out.warnings.push_back(std::to_string(out.report.scores_clamped) +
                           " scores outside [0, 1] were clamped into it");
  }
  m.keypoints2d = keypoints_name;
  m.layout = out.layout;
  m.keypoint_names.clear();
  ARCO_RETURN_IF_ERROR(
      ParseCaptureManifest(CaptureManifestToJson(m).dump(), manifest_path).status());
  ARCO_RETURN_IF_ERROR(WriteNpy(npy_tmp, k));
  ARCO_RETURN_IF_ERROR(WriteJsonFile(manifest_tmp, CaptureManifestToJson(m)));
  ARCO_RETURN_IF_ERROR(outputs.Commit());
  out.frames = frames;
  out.views = views;
  out.points = points;
  return out;
}

}  // namespace arco::capture
