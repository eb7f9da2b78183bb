#include "arco/export/overlay.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <vector>

#include "arco/calibration/calibration_file.h"
#include "arco/capture/capture_videos.h"
#include "arco/export/export.h"
#include "arco/media/video_reader.h"
#include "arco/media/video_writer.h"
#include "arco/mocap/capture.h"
#include "arco/pipeline/capture_checks.h"
#include "arco/pipeline/result_folder.h"
#include "arco/refine/contact_annotation.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/util/file_io.h"

namespace arco::exporter {
namespace {

using Rgb = std::array<uint8_t, 3>;
cv::Scalar Color(const Rgb& c) { return cv::Scalar(c[0], c[1], c[2]); }  // the canvas is RGB

constexpr Rgb kStringRgb = {255, 220, 0};
constexpr Rgb kBodyRgb = {0, 200, 255};
constexpr Rgb kLeftHandRgb = {0, 255, 0};
constexpr Rgb kRightHandRgb = {255, 140, 0};
constexpr Rgb kPointRgb = {255, 255, 255};
constexpr Rgb kContactRgb = {255, 0, 0};
constexpr Rgb kTextRgb = {255, 255, 255};
constexpr Rgb kShadowRgb = {0, 0, 0};

// Bones by keypoint name (COCO-WholeBody body and feet; each hand's 21 points).
std::vector<std::pair<std::string, std::string>> BodyBones() {
  std::vector<std::pair<std::string, std::string>> b = {{"left_shoulder", "right_shoulder"},
                                                        {"left_hip", "right_hip"},
                                                        {"nose", "left_eye"},
                                                        {"nose", "right_eye"},
                                                        {"left_eye", "left_ear"},
                                                        {"right_eye", "right_ear"}};
  for (const std::string s : {"left", "right"}) {
    for (const auto& [a, c] :
         std::vector<std::pair<std::string, std::string>>{{"_shoulder", "_elbow"},
                                                          {"_elbow", "_wrist"},
                                                          {"_shoulder", "_hip"},
                                                          {"_hip", "_knee"},
                                                          {"_knee", "_ankle"},
                                                          {"_ankle", "_heel"},
                                                          {"_ankle", "_big_toe"},
                                                          {"_big_toe", "_small_toe"},
                                                          {"_wrist", "_hand_wrist"}}) {
      b.push_back({s + a, s + c});
    }
  }
  return b;
}

std::vector<std::pair<std::string, std::string>> HandBones(const std::string& side) {
  const std::string h = side + "_hand_";
  std::vector<std::pair<std::string, std::string>> b;
  for (const std::string f : {"thumb", "index", "middle", "ring", "little"}) {
    const std::vector<std::string> j = f == "thumb"
                                           ? std::vector<std::string>{"cmc", "mcp", "ip", "tip"}
                                           : std::vector<std::string>{"mcp", "pip", "dip", "tip"};
    std::string prev = h + "wrist";
    for (const auto& name : j) {
      b.push_back({prev, h + f + "_" + name});
      prev = h + f + "_" + name;
    }
  }
  return b;
}

// frames per second as a rational for the encoder: exact for integer and NTSC-style
// (x/1001) rates, else to 1/1000 fps.
media::Rational FpsRational(double fps) {
  for (const int den : {1, 1001, 1000}) {
    const double num = std::round(fps * den);
    if (std::abs(num / den - fps) <= 1e-9 * fps) return {static_cast<int>(num), den};
  }
  return {static_cast<int>(std::round(fps * 1000)), 1000};
}

std::string Extension(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string e = path.substr(dot + 1);
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

struct Projector {
  Camera camera;
  double world_units_per_mm = 1;
  double scale = 1;
  int width = 0, height = 0;  // output

  // Output pixel of a world point in mm; nullopt when missing, behind the camera, or far
  // outside the image (where the distortion polynomial folds back, a point may land
  // anywhere: those are not drawn).
  std::optional<cv::Point2d> operator()(const Eigen::Vector3d& point_mm) const {
    if (!point_mm.allFinite()) return std::nullopt;
    const Eigen::Vector3d x = point_mm * world_units_per_mm;
    double px[2];
    if (!camera.ProjectToPixel(x.data(), px)) return std::nullopt;
    if (px[0] < -camera.width || px[0] > 2.0 * camera.width || px[1] < -camera.height ||
        px[1] > 2.0 * camera.height) {
      return std::nullopt;
    }
    // Pixel centres: calibration pixel (x, y) covers output [(x - 0.5) s, (x + 0.5) s].
    return cv::Point2d((px[0] + 0.5) * scale - 0.5, (px[1] + 0.5) * scale - 0.5);
  }
};

// cv drawing takes integer points; 4 fractional bits keep sub-pixel positions.
constexpr int kShift = 4;
cv::Point Fixed(const cv::Point2d& p) {
  return cv::Point(static_cast<int>(std::lround(p.x * (1 << kShift))),
                   static_cast<int>(std::lround(p.y * (1 << kShift))));
}

void Text(cv::Mat& canvas, const std::string& text, cv::Point at, double size, int thickness) {
  cv::putText(canvas,
              text,
              at,
              cv::FONT_HERSHEY_SIMPLEX,
              size,
              Color(kShadowRgb),
              thickness + 2,
              cv::LINE_AA);
  cv::putText(
      canvas, text, at, cv::FONT_HERSHEY_SIMPLEX, size, Color(kTextRgb), thickness, cv::LINE_AA);
}

struct Drawing {
  const ExportData* data = nullptr;
  const Projector* project = nullptr;
  std::vector<std::pair<int, int>> body_bones, left_bones, right_bones;
  std::vector<int> points;    // body, feet and hand points drawn as dots
  std::array<int, 5> tips{};  // left thumb, index, middle, ring, little tip
  int contact = -1;
  std::vector<const refine::NoteFingering*> note_of_row;  // per result row, null: none

  void Draw(cv::Mat& canvas, int64_t row) const {
    const double unit = std::max(1.0, canvas.rows / 540.0);  // line widths ~ 1 px at 540p
    const int line = std::max(1, static_cast<int>(std::lround(1.5 * unit)));
    auto at = [&](int k) { return (*project)(data->At(row, k)); };
    // Strings: nut -> bridge as a projected polyline (straight in 3D, curved by the lens).
    if (!data->strings_mm.shape.empty()) {
      const auto& s = data->strings_mm;
      for (int64_t i = 0; i < s.shape[1]; ++i) {
        const Eigen::Vector3d nut(s.at(row, i, 0, 0), s.at(row, i, 0, 1), s.at(row, i, 0, 2));
        const Eigen::Vector3d bridge(s.at(row, i, 1, 0), s.at(row, i, 1, 1), s.at(row, i, 1, 2));
        std::vector<cv::Point> poly;
        constexpr int kSegments = 24;
        for (int k = 0; k <= kSegments; ++k) {
          const auto p = (*project)(nut + (bridge - nut) * (static_cast<double>(k) / kSegments));
          if (p) poly.push_back(Fixed(*p));
        }
        if (poly.size() >= 2) {
          cv::polylines(canvas, poly, false, Color(kStringRgb), line, cv::LINE_AA, kShift);
        }
      }
    }
    auto bones = [&](const std::vector<std::pair<int, int>>& list, const Rgb& rgb) {
      for (const auto& [a, b] : list) {
        const auto pa = at(a), pb = at(b);
        if (pa && pb) {
          cv::line(canvas, Fixed(*pa), Fixed(*pb), Color(rgb), line, cv::LINE_AA, kShift);
        }
      }
    };
    bones(body_bones, kBodyRgb);
    bones(right_bones, kRightHandRgb);
    bones(left_bones, kLeftHandRgb);
    for (const int k : points) {
      if (const auto p = at(k)) {
        cv::circle(canvas,
                   Fixed(*p),
                   static_cast<int>(2 * unit) << kShift,
                   Color(kPointRgb),
                   cv::FILLED,
                   cv::LINE_AA,
                   kShift);
      }
    }
    if (contact >= 0) {
      if (const auto p = at(contact)) {
        cv::circle(canvas,
                   Fixed(*p),
                   static_cast<int>(12 * unit) << kShift,
                   Color(kContactRgb),
                   std::max(2, line),
                   cv::LINE_AA,
                   kShift);
      }
    }
    const refine::NoteFingering* note = note_of_row[row];
    const double text_size = 0.5 * unit;
    const int text_line = std::max(1, static_cast<int>(std::lround(unit)));
    if (note != nullptr) {
      char cents[32];
      std::snprintf(cents, sizeof(cents), "%+.0f c", note->cents_off);
      std::string where;
      if (note->state == "pressed") {
        where =
            "string " + std::to_string(note->string) + ", finger " + std::to_string(note->finger);
      } else if (note->state == "open") {
        where = "open string " + std::to_string(note->string);
      } else {
        where = "string/finger uncertain";
      }
      const int x = static_cast<int>(12 * unit), y = static_cast<int>(32 * unit);
      Text(canvas,
           refine::MidiNoteName(note->midi_note) + " " + cents,
           {x, y},
           2 * text_size,
           2 * text_line);
      Text(canvas, where, {x, y + static_cast<int>(28 * unit)}, text_size, text_line);
    }
    // Finger numbers beside the tips (thumb "T"), then the tips over everything.
    static const char* kFingerLabel[5] = {"T", "1", "2", "3", "4"};
    const int radius = static_cast<int>(std::lround(kOverlayFingertipRadiusPx * 1.0));
    for (int f = 0; f < 5; ++f) {
      if (const auto p = at(tips[f])) {
        Text(canvas,
             kFingerLabel[f],
             cv::Point(static_cast<int>(p->x) + radius + 2, static_cast<int>(p->y) - radius - 2),
             text_size,
             text_line);
      }
    }
    for (int f = 0; f < 5; ++f) {
      if (const auto p = at(tips[f])) {
        cv::circle(canvas,
                   Fixed(*p),
                   radius << kShift,
                   Color(kOverlayFingertipRgb),
                   cv::FILLED,
                   cv::LINE_8,
                   kShift);
      }
    }
  }
};

}  // namespace

Status OverlayOptions::Validate() const {
  if (result_dir.empty()) return Status::Error("result_dir is empty");
  if (camera.empty()) return Status::Error("camera is empty");
  bool known = false;
  for (const auto& m : ExportMethodNames()) known = known || m == method;
  if (!known) return Status::Error("method: '" + method + "' is not arco, paper or vision");
  ARCO_RETURN_IF_ERROR(CheckInRange("scale", scale, kOverlayScaleRange));
  if (first_frame < -1 || last_frame < -1) {
    return Status::Error("first_frame and last_frame must be frame numbers (or -1: all)");
  }
  if (first_frame >= 0 && last_frame >= 0 && last_frame < first_frame) {
    return Status::Error("last_frame " + std::to_string(last_frame) + " is before first_frame " +
                         std::to_string(first_frame));
  }
  return Status::Ok();
}

StatusOr<OverlaySummary> WriteOverlay(const OverlayOptions& options,
                                      const std::string& path,
                                      const std::string& container_hint) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  // The container and codec from the user's file name (the temporary may lack it).
  media::VideoWriterOptions writer_options;
  const std::string ext = Extension(container_hint);
  if (ext == "mp4" || ext == "mov") {
    writer_options.container = ext;
    writer_options.codec = media::HasVideoEncoder("libx264") ? "libx264" : "mpeg4";
  } else if (ext == "mkv") {
    writer_options.container = "matroska";
    writer_options.codec = "ffv1";
  } else if (ext == "webm") {
    // VP8 in WebM: what every browser plays (arco view's videos).
    writer_options.container = "webm";
    writer_options.codec = "libvpx";
  } else if (ext == "avi") {
    writer_options.container = "avi";
    writer_options.codec = "mpeg4";
  } else {
    return Status::Error(container_hint +
                         ": the overlay is a video: .mp4, .mov, .mkv, .avi or .webm");
  }

  ExportOptions export_options;
  export_options.result_dir = options.result_dir;
  export_options.method = options.method;
  ARCO_ASSIGN_OR_RETURN(const ExportData data, LoadExportData(export_options));
  const pipeline::ResultFolder folder(options.result_dir);
  ARCO_ASSIGN_OR_RETURN(const pipeline::ResultHeader header, folder.ReadHeader());
  if (header.capture_dir.empty()) {
    return Status::Error(folder.ManifestPath() + ": names no capture folder");
  }
  ARCO_ASSIGN_OR_RETURN(const CaptureManifest manifest, ReadCaptureManifest(header.capture_dir));
  const int view = manifest.FindCamera(options.camera);
  if (view < 0) {
    std::string names;
    for (const auto& c : manifest.cameras) names += (names.empty() ? "" : ", ") + c.name;
    return Status::Error(CaptureManifestPath(header.capture_dir) + ": no camera '" +
                         options.camera + "' (cameras: " + names + ")");
  }
  const std::string calibration_path = ResolveCapturePath(header.capture_dir, manifest.calibration);
  StatusOr<Calibration> calibration = calibration::LoadCalibration(calibration_path);
  if (!calibration.ok()) {
    return calibration.status().WithContext(CaptureManifestPath(header.capture_dir) +
                                            ": calibration");
  }
  ARCO_ASSIGN_OR_RETURN(const std::vector<int> rig_index,
                        capture::MatchCaptureCameras(
                            header.capture_dir, manifest, calibration->rig, calibration_path));
  const Camera& camera = calibration->rig.cameras[rig_index[view]];

  const int64_t result_last = data.frame_first + data.frames() - 1;
  const int64_t first = options.first_frame < 0 ? data.frame_first : options.first_frame;
  const int64_t last = options.last_frame < 0 ? result_last : options.last_frame;
  if (first < data.frame_first || last > result_last || last < first) {
    return Status::Error("frames " + std::to_string(first) + ":" + std::to_string(last) +
                         " are outside the result's " + std::to_string(data.frame_first) + ":" +
                         std::to_string(result_last) + " (" + folder.ManifestPath() + ")");
  }

  Projector projector;
  projector.camera = camera;
  projector.scale = options.scale;
  ARCO_ASSIGN_OR_RETURN(projector.world_units_per_mm, folder.ReadWorldUnitsPerMm());
  const int image_w = std::max(2, static_cast<int>(std::lround(camera.width * options.scale)));
  const int image_h = std::max(2, static_cast<int>(std::lround(camera.height * options.scale)));
  const bool lossy = writer_options.codec != "ffv1";
  projector.width = lossy ? (image_w + 1) / 2 * 2 : image_w;
  projector.height = lossy ? (image_h + 1) / 2 * 2 : image_h;

  // The background video, when the camera has one.
  OverlaySummary summary;
  summary.camera = manifest.cameras[view].name;
  std::optional<capture::CaptureFrameReader> reader;
  int rotate_deg = 0;
  if (!manifest.cameras[view].video.empty()) {
    ARCO_ASSIGN_OR_RETURN(
        capture::CaptureVideo video,
        capture::OpenCaptureVideo(
            header.capture_dir, manifest, view, camera, calibration_path, first, last));
    rotate_deg = video.rotate_deg;
    summary.video = video.video;
    reader.emplace(manifest, view, std::move(video));
  }

  ARCO_ASSIGN_OR_RETURN(const auto fingering, folder.ReadFingering(options.method));
  Drawing drawing;
  drawing.data = &data;
  drawing.project = &projector;
  auto pairs = [&](const std::vector<std::pair<std::string, std::string>>& names) {
    std::vector<std::pair<int, int>> out;
    for (const auto& [a, b] : names) {
      const int ia = data.Find(a), ib = data.Find(b);
      if (ia >= 0 && ib >= 0) out.push_back({ia, ib});
    }
    return out;
  };
  drawing.body_bones = pairs(BodyBones());
  drawing.left_bones = pairs(HandBones("left"));
  drawing.right_bones = pairs(HandBones("right"));
  for (int k = 0; k < data.points(); ++k) {
    const std::string& n = data.keypoint_names[k];
    const bool face = n.rfind("face", 0) == 0;
    if (k < wholebody::kNumPoints && !face) drawing.points.push_back(k);
  }
  const char* tip_names[5] = {"left_hand_thumb_tip",
                              "left_hand_index_tip",
                              "left_hand_middle_tip",
                              "left_hand_ring_tip",
                              "left_hand_little_tip"};
  for (int f = 0; f < 5; ++f) {
    drawing.tips[f] = data.Find(tip_names[f]);
    if (drawing.tips[f] < 0) {
      return Status::Error(folder.Points3dPath(options.method) + ": the points lack " +
                           tip_names[f]);
    }
  }
  drawing.contact = data.Find("contact");
  drawing.note_of_row.assign(data.frames(), nullptr);
  for (const auto& n : fingering) {
    for (int64_t r = std::max<int64_t>(0, n.first_frame);
         r <= std::min<int64_t>(data.frames() - 1, n.last_frame);
         ++r) {
      drawing.note_of_row[r] = &n;
    }
  }

  writer_options.width = projector.width;
  writer_options.height = projector.height;
  writer_options.fps = FpsRational(manifest.fps);
  ARCO_ASSIGN_OR_RETURN(media::VideoWriter writer, media::VideoWriter::Open(path, writer_options));
  media::Image canvas_image =
      media::MakeImage(projector.width, projector.height, media::PixelFormat::kRgb8);
  cv::Mat canvas(projector.height, projector.width, CV_8UC3, canvas_image.pixels.data());
  media::Image decoded, scaled;
  for (int64_t g = first; g <= last; ++g) {
    canvas.setTo(cv::Scalar(0, 0, 0));
    // The camera's picture nearest the capture's frame g (a camera synced by sound starts
    // and runs on its own clock: docs/formats.md).
    const int64_t own = std::llround(manifest.CameraFrameAt(view, static_cast<double>(g)));
    const bool inside =
        manifest.cameras.at(static_cast<size_t>(view)).OnCaptureClock() ||
        (own >= manifest.frame_first && own < manifest.frame_first + manifest.frame_count);
    bool recorded = false;  // the camera has that frame (it may have dropped it)
    if (reader && inside) {
      ARCO_ASSIGN_OR_RETURN(recorded, reader->Read(own, &decoded, /*rotate=*/false));
    }
    if (recorded) {
      // Scaled down first, then turned: the same picture (area averaging commutes with a
      // quarter turn), and fewer pixels to turn (turning a 6-megapixel frame was a third
      // of the time of `arco view`'s videos, docs/performance.md).
      const bool quarter = rotate_deg == 90 || rotate_deg == 270;
      const int scaled_w = quarter ? image_h : image_w, scaled_h = quarter ? image_w : image_h;
      const media::Image* source = &decoded;
      if (scaled_w != decoded.width || scaled_h != decoded.height) {
        if (scaled.width != scaled_w || scaled.height != scaled_h) {
          scaled = media::MakeImage(scaled_w, scaled_h, media::PixelFormat::kRgb8);
        }
        const cv::Mat from(
            decoded.height, decoded.width, CV_8UC3, const_cast<uint8_t*>(decoded.pixels.data()));
        cv::Mat to(scaled_h, scaled_w, CV_8UC3, scaled.pixels.data());
        cv::resize(from, to, to.size(), 0, 0, cv::INTER_AREA);
        source = &scaled;
      }
      const media::Image turned = media::RotateClockwise(*source, rotate_deg);
      const cv::Mat src(
          turned.height, turned.width, CV_8UC3, const_cast<uint8_t*>(turned.pixels.data()));
      src.copyTo(canvas(cv::Rect(0, 0, image_w, image_h)));
    } else if (reader) {
      ++summary.frames_without_video;
    }
    drawing.Draw(canvas, g - data.frame_first);
    ARCO_RETURN_IF_ERROR(writer.Write(canvas_image));
  }
  ARCO_RETURN_IF_ERROR(writer.Close());
  summary.codec = writer_options.codec;
  summary.width = projector.width;
  summary.height = projector.height;
  summary.fps = writer_options.fps.ToDouble();
  summary.first_frame = first;
  summary.last_frame = last;
  summary.frames = last - first + 1;
  return summary;
}

}  // namespace arco::exporter
