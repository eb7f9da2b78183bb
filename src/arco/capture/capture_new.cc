#include "arco/capture/capture_new.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>

#include "arco/audio/align.h"
#include "arco/audio/audio_reader.h"
#include "arco/calibration/calibration_file.h"
#include "arco/camera/phone_camera.h"
#include "arco/media/audio_decoder.h"
#include "arco/media/frame_times.h"
#include "arco/media/video_reader.h"
#include "arco/mocap/capture.h"
#include "arco/mocap/spd_import.h"
#include "arco/registry/instruments.h"
#include "arco/util/file_io.h"
#include "arco/util/number_range.h"
#include "arco/util/output_set.h"

namespace arco::capture {
namespace {

namespace fs = std::filesystem;

std::string FpsText(double fps) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", fps);
  return text;
}

struct OpenedInput {
  const CaptureNewInput* input = nullptr;
  int calibration_camera = -1;
  media::VideoProperties properties;
  int rotate_deg = 0;
  std::vector<int64_t> drops;  // sorted global frames
};

// Opens one input and decodes its first and last frames: an unreadable or truncated
// file fails here, naming itself.
StatusOr<media::VideoProperties> ProbeInput(const CaptureNewInput& input) {
  std::error_code ec;
  const bool is_folder = fs::is_directory(input.path, ec);
  if (input.images && !is_folder) {
    if (!fs::exists(input.path, ec)) return Status::Error(input.path + ": no such folder");
    return Status::Error(input.path + ": not a folder of images");
  }
  if (!input.images && is_folder) {
    return Status::Error(input.path +
                         ": is a folder, not a video file (a folder of images is an input with "
                         "images set)");
  }
  ARCO_ASSIGN_OR_RETURN(media::VideoReader reader, media::VideoReader::Open(input.path));
  media::VideoProperties p = reader.properties();
  if (p.frame_count <= 0) return Status::Error(input.path + ": holds no frames");
  ARCO_ASSIGN_OR_RETURN(const media::Image first, reader.ReadFrame(0));
  (void)first;
  if (p.frame_count > 1) {
    StatusOr<media::Image> last = reader.ReadFrame(p.frame_count - 1);
    if (!last.ok()) {
      std::string why = last.status().message();
      if (why.rfind(input.path + ": ", 0) == 0) why = why.substr(input.path.size() + 2);
      return Status::Error(input.path + ": announces " + std::to_string(p.frame_count) +
                           " frames but the last cannot be read (truncated?): " + why);
    }
  }
  return p;
}

// The cameras' clocks from their sound (CaptureSync::kAudio; see the header).
struct AudioSync {
  std::vector<double> offset_s, drift_ppm, confidence;  // per camera
  std::string audio;                                    // the capture's audio file
  double audio_offset_s = 0;
  double lowest_confidence = 1;  // of the alignments
  std::string reference;         // the recorder's or the camera's name
};

// t_ref = offset + (1 + drift) t_other, inverted: t_other on t_ref's clock.
audio::AlignResult Inverse(const audio::AlignResult& r) {
  audio::AlignResult inv = r;
  const double scale = 1.0 + r.drift_ppm * 1e-6;
  inv.offset_s = -r.offset_s / scale;
  inv.drift_ppm = r.drift_ppm == 0 ? 0.0 : (1.0 / scale - 1.0) * 1e6;
  return inv;
}

StatusOr<AudioSync> SyncByAudio(const std::vector<OpenedInput>& opened,
                                const CaptureNewOptions& o) {
  audio::AlignOptions align;
  align.max_seconds = o.sync_max_seconds;
  ARCO_RETURN_IF_ERROR(align.Validate());
  const size_t n = opened.size();
  std::vector<audio::AudioTrack> tracks(n);
  std::vector<double> video_start_s(n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    const CaptureNewInput& input = *opened[i].input;
    if (input.images) {
      return Status::Error(input.path +
                           ": a folder of images has no sound; sync audio needs every camera's "
                           "video file with its audio track");
    }
    ARCO_ASSIGN_OR_RETURN(
        tracks[i], audio::LoadAudioTrack(input.path, align.fine_rate_hz, o.sync_max_seconds));
    const double level = audio::TrackLevelDbfs(tracks[i]);
    if (level < audio::kAlignSilentDbfs) {
      char text[160];
      std::snprintf(text,
                    sizeof text,
                    ": the audio track is silent (%.0f dBFS RMS, below %.0f): nothing to sync by",
                    level,
                    audio::kAlignSilentDbfs);
      return Status::Error(input.path + text);
    }
    ARCO_ASSIGN_OR_RETURN(video_start_s[i], media::VideoStartOnAudioClock(input.path));
  }
  // Each camera's alignment to the reference: t_ref = offset + (1 + drift) t_camera_audio.
  std::vector<audio::AlignResult> to_ref(n);
  AudioSync sync;
  if (!o.audio.empty()) {
    ARCO_ASSIGN_OR_RETURN(const audio::AudioTrack recorder,
                          audio::LoadAudioTrack(o.audio, align.fine_rate_hz, o.sync_max_seconds));
    for (size_t i = 0; i < n; ++i) {
      ARCO_ASSIGN_OR_RETURN(to_ref[i], audio::AlignTracks(recorder, tracks[i], align));
    }
    sync.audio = o.audio;
    sync.reference = o.audio;
  } else {
    // Every pair once; the reference is the camera whose worst alignment is the best.
    std::vector<std::vector<StatusOr<audio::AlignResult>>> pair(n);
    for (size_t i = 0; i < n; ++i) {
      pair[i].resize(n, Status::Error("not aligned"));
    }
    for (size_t i = 0; i < n; ++i) {
      for (size_t j = i + 1; j < n; ++j) {
        pair[i][j] = audio::AlignTracks(tracks[i], tracks[j], align);
        if (pair[i][j].ok()) {
          pair[j][i] = Inverse(*pair[i][j]);
        } else {
          pair[j][i] = pair[i][j].status();
        }
      }
    }
    size_t best = 0;
    double best_score = -1;
    for (size_t i = 0; i < n; ++i) {
      double score = 1;
      for (size_t j = 0; j < n; ++j) {
        if (j != i) score = std::min(score, pair[i][j].ok() ? pair[i][j]->confidence : 0.0);
      }
      if (score > best_score) {
        best_score = score;
        best = i;
      }
    }
    for (size_t j = 0; j < n; ++j) {
      if (j == best) {
        to_ref[j].confidence = 1;
        continue;
      }
      if (!pair[best][j].ok()) return pair[best][j].status();
      to_ref[j] = *pair[best][j];
    }
    sync.audio = opened[best].input->path;
    sync.reference = opened[best].input->camera;
  }
  // Each camera's first frame on the reference's clock; the capture's zero is the earliest.
  std::vector<double> start_s(n);
  for (size_t i = 0; i < n; ++i) {
    start_s[i] = to_ref[i].offset_s + (1 + to_ref[i].drift_ppm * 1e-6) * video_start_s[i];
  }
  const double zero_s = *std::min_element(start_s.begin(), start_s.end());
  for (size_t i = 0; i < n; ++i) {
    sync.offset_s.push_back(start_s[i] - zero_s);
    sync.drift_ppm.push_back(to_ref[i].drift_ppm);
    sync.confidence.push_back(to_ref[i].confidence);
    sync.lowest_confidence = std::min(sync.lowest_confidence, to_ref[i].confidence);
  }
  sync.audio_offset_s = zero_s;
  return sync;
}

// A camera's frames as they are shown: its clockwise turn (the option's, else the
// container's) and the size once turned.
struct ShownSize {
  int rotate_deg = 0;
  bool quarter = false;  // turned by 90 or 270 degrees: width and height swap
  int width = 0, height = 0;
};
ShownSize SizeAsShown(const CaptureNewOptions& o,
                      const CaptureNewInput& input,
                      const media::VideoProperties& p) {
  ShownSize shown;
  const auto rotate = o.rotate_deg.find(input.camera);
  shown.rotate_deg = rotate != o.rotate_deg.end() ? rotate->second : p.rotation_deg;
  shown.quarter = shown.rotate_deg == 90 || shown.rotate_deg == 270;
  shown.width = shown.quarter ? p.coded_height : p.coded_width;
  shown.height = shown.quarter ? p.coded_width : p.coded_height;
  return shown;
}

// One camera's calibration from its video (capture_new.h, "One camera without a
// calibration"); `what` says what it holds.
StatusOr<Rig> OneCameraFromItsVideo(const CaptureNewOptions& o, std::string* what) {
  const CaptureNewInput& input = o.inputs.front();
  ARCO_ASSIGN_OR_RETURN(const media::VideoProperties p, ProbeInput(input));
  const ShownSize shown = SizeAsShown(o, input, p);
  const Camera cam = CentredPinhole(input.camera,
                                    shown.width,
                                    shown.height,
                                    FocalPxFromFov(shown.width, shown.height, kPhoneFovDeg));
  Rig rig;
  rig.units = "mm";
  rig.cameras.push_back(cam);
  *what = "camera " + cam.name + " from its video: " + std::to_string(cam.width) + "x" +
          std::to_string(cam.height) + ", focal " + NumberText(std::round(10 * cam.fx) / 10) +
          " px (a phone's default, " + NumberText(kPhoneFovDeg) +
          " deg across the longer side), no distortion, its frame the world";
  return rig;
}

}  // namespace

Status CaptureNewOptions::Validate() const {
  if (output_dir.empty()) return Status::Error("output_dir is empty");
  if (inputs.empty()) return Status::Error("inputs: give at least one camera's video or images");
  if (calibration.empty() && inputs.size() > 1)
    return Status::Error("calibration is missing: " + std::to_string(inputs.size()) +
                         " cameras need one that names them (two phones: docs/phones.md, step 1); "
                         "only a single camera's is made from its video");
  std::set<std::string> cameras;
  for (const CaptureNewInput& input : inputs) {
    if (input.camera.empty()) return Status::Error("inputs: a camera name is empty");
    if (input.path.empty()) return Status::Error("inputs: camera " + input.camera + " has no path");
    if (!cameras.insert(input.camera).second) {
      return Status::Error("inputs: camera " + input.camera + " is given twice");
    }
  }
  if (instrument != "none") {
    const auto kind = ParseInstrumentKind(instrument);
    if (!kind.ok()) return Status::Error("instrument: " + kind.status().message());
  }
  if (fps != 0) ARCO_RETURN_IF_ERROR(CheckInRange("fps", fps, AboveZero(kMaxCaptureFps)));
  for (const auto& [camera, deg] : rotate_deg) {
    if (!cameras.count(camera)) {
      return Status::Error("rotate_deg: camera " + camera + " has no video or images");
    }
    if (deg != 0 && deg != 90 && deg != 180 && deg != 270) {
      return Status::Error("rotate_deg: " + camera + "=" + std::to_string(deg) +
                           "; must be 0, 90, 180 or 270 (clockwise)");
    }
  }
  ARCO_RETURN_IF_ERROR(CheckInRange("sync_max_seconds", sync_max_seconds, Closed(1, 86400)));
  if (!dropped_frames.empty() && !spd_summary.empty()) {
    return Status::Error("dropped_frames and spd_summary: give one or the other");
  }
  for (const auto& [camera, drops] : dropped_frames) {
    if (!cameras.count(camera)) {
      return Status::Error("dropped_frames: camera " + camera + " has no video or images");
    }
    std::vector<int64_t> sorted = drops;
    std::sort(sorted.begin(), sorted.end());
    if (!sorted.empty() && sorted.front() < 1) {
      return Status::Error("dropped_frames: " + camera + " lists frame " +
                           std::to_string(sorted.front()) +
                           "; global frames number the recording from 1");
    }
    const auto twice = std::adjacent_find(sorted.begin(), sorted.end());
    if (twice != sorted.end()) {
      return Status::Error("dropped_frames: " + camera + " lists frame " + std::to_string(*twice) +
                           " twice");
    }
  }
  return Status::Ok();
}

StatusOr<CaptureNewSummary> CreateCapture(const CaptureNewOptions& o) {
  ARCO_RETURN_IF_ERROR(o.Validate());
  FolderReplace replace;
  replace.overwrite = o.overwrite;
  replace.marker = kCaptureManifestName;  // only an arco capture is replaced
  replace.kind = "capture";
  ARCO_RETURN_IF_ERROR(CheckOutputFolder(o.output_dir, replace));  // before the work
  Calibration calibration;
  std::string calibration_made;
  if (o.calibration.empty()) {
    ARCO_ASSIGN_OR_RETURN(calibration.rig, OneCameraFromItsVideo(o, &calibration_made));
  } else {
    ARCO_ASSIGN_OR_RETURN(calibration, calibration::LoadCalibration(o.calibration));
  }
  const Rig& rig = calibration.rig;

  // Cameras first (cheap), then the videos.
  std::vector<OpenedInput> opened;
  for (const CaptureNewInput& input : o.inputs) {
    OpenedInput in;
    in.input = &input;
    in.calibration_camera = rig.FindCamera(input.camera);
    if (in.calibration_camera < 0) {
      std::string known;
      for (const Camera& cam : rig.cameras) known += (known.empty() ? "" : ", ") + cam.name;
      if (known.size() > 200) known = known.substr(0, 197) + "...";
      return Status::Error(o.calibration + ": no camera \"" + input.camera + "\" (given for " +
                           input.path + "; cameras: " + known + ")");
    }
    opened.push_back(in);
  }
  std::set<int> used;
  for (const OpenedInput& in : opened) {
    if (!used.insert(in.calibration_camera).second) {
      return Status::Error(o.calibration + ": camera \"" + in.input->camera +
                           "\" is the same calibration camera as another input");
    }
  }
  SpdSummary summary;
  if (!o.spd_summary.empty()) {
    ARCO_ASSIGN_OR_RETURN(summary, ReadSpdSummary(o.spd_summary));
  }
  if (!o.audio.empty()) {
    auto audio = audio::OpenAudio(o.audio);
    if (!audio.ok()) return audio.status();
  }

  double fps = o.fps;
  const media::VideoProperties* fps_from = nullptr;  // the first container with a rate
  for (OpenedInput& in : opened) {
    const CaptureNewInput& input = *in.input;
    ARCO_ASSIGN_OR_RETURN(in.properties, ProbeInput(input));
    const media::VideoProperties& p = in.properties;
    const Camera& cam = rig.cameras[static_cast<size_t>(in.calibration_camera)];
    const ShownSize shown = SizeAsShown(o, input, p);
    in.rotate_deg = shown.rotate_deg;
    const bool quarter = shown.quarter;
    const int width = shown.width, height = shown.height;
    if (width != cam.width || height != cam.height) {
      return Status::Error(input.path + ": " + std::to_string(p.coded_width) + "x" +
                           std::to_string(p.coded_height) + " frames" +
                           (in.rotate_deg ? " rotated " + std::to_string(in.rotate_deg) +
                                                " deg clockwise are " + std::to_string(width) +
                                                "x" + std::to_string(height)
                                          : std::string()) +
                           ", but camera " + cam.name + " of " + o.calibration + " is " +
                           std::to_string(cam.width) + "x" + std::to_string(cam.height) +
                           (!quarter && height == cam.width && width == cam.height
                                ? " (a camera turned by 90 degrees: give its rotate_deg)"
                                : std::string()));
    }
    // A container's rate is the video's; images carry none.
    const bool has_rate =
        p.frame_count_source != media::FrameCountSource::kImageFiles && p.fps_hz > 0;
    if (has_rate) {
      if (o.fps > 0 && !media::SameFrameRate(o.fps, p.fps_hz)) {
        return Status::Error(input.path + ": " + FpsText(p.fps_hz) +
                             " fps in the container, but fps = " + FpsText(o.fps) +
                             " (fps sets the rate of image folders only)");
      }
      if (fps_from && !media::SameFrameRate(fps_from->fps_hz, p.fps_hz)) {
        return Status::Error(input.path + ": " + FpsText(p.fps_hz) + " fps, but " + fps_from->path +
                             " has " + FpsText(fps_from->fps_hz) + " fps");
      }
      if (!fps_from) fps_from = &p;
      if (fps <= 0) fps = p.fps_hz;
    }
    // Dropped frames: given per camera, or the summary's for the camera's serial/name.
    if (auto it = o.dropped_frames.find(input.camera); it != o.dropped_frames.end()) {
      in.drops = it->second;
    } else if (!o.spd_summary.empty()) {
      for (const std::string& id : {cam.serial, cam.name}) {
        if (id.empty()) continue;
        if (auto s = summary.frame_drops.find(id); s != summary.frame_drops.end()) {
          in.drops = s->second;
          break;
        }
      }
    }
    std::sort(in.drops.begin(), in.drops.end());
    in.drops.erase(std::unique(in.drops.begin(), in.drops.end()), in.drops.end());
  }
  std::vector<std::string> warnings;
  for (const OpenedInput& in : opened) {
    if (in.properties.frame_count_source == media::FrameCountSource::kImageFiles) continue;
    ARCO_ASSIGN_OR_RETURN(const media::FrameTimes times, media::ReadFrameTimes(in.input->path));
    const std::string jumps = media::DescribeTimestampJumps(in.input->path, times);
    if (!jumps.empty()) warnings.push_back(jumps);
  }
  if (fps <= 0) {
    return Status::Error(opened.front().input->path +
                         ": images carry no frame rate and no video gives one; give fps");
  }
  if (fps_from) fps = fps_from->fps_hz;  // the container's exact rate

  // Every camera's recorded frames plus its drops make the same recording.
  const auto recording = [](const OpenedInput& in) {
    return in.properties.frame_count + static_cast<int64_t>(in.drops.size());
  };
  const OpenedInput& reference = opened.front();
  int64_t total = recording(reference);
  AudioSync sync;
  if (o.sync == CaptureSync::kAudio) {
    ARCO_ASSIGN_OR_RETURN(sync, SyncByAudio(opened, o));
    // Cameras started and stopped apart: the capture is as long as the shortest.
    for (const OpenedInput& in : opened) total = std::min(total, recording(in));
  }
  const bool any_drops = std::any_of(
      opened.begin(), opened.end(), [](const OpenedInput& in) { return !in.drops.empty(); });
  for (const OpenedInput& in : opened) {
    if (recording(in) == total || o.sync == CaptureSync::kAudio) continue;
    const auto count = [&](const OpenedInput& x) {
      std::string text = std::to_string(x.properties.frame_count) + " frames";
      if (any_drops) {
        text +=
            " + " + std::to_string(x.drops.size()) + " dropped = " + std::to_string(recording(x));
      }
      return text;
    };
    return Status::Error(in.input->path + ": " + count(in) + ", but camera " +
                         reference.input->camera + "'s " + reference.input->path + " has " +
                         count(reference) +
                         (any_drops ? std::string()
                                    : "; cameras that dropped frames need dropped_frames or an "
                                      "SPD summary"));
  }
  for (OpenedInput& in : opened) {
    if (o.sync == CaptureSync::kAudio) {
      if (!in.drops.empty() && in.drops.back() > recording(in)) {
        const std::string source = o.spd_summary.empty() ? "dropped_frames" : o.spd_summary;
        return Status::Error(source + ": camera " + in.input->camera + " drops frame " +
                             std::to_string(in.drops.back()) + ", after its recording's last (" +
                             std::to_string(recording(in)) + ")");
      }
      // Drops after the capture's last frame are outside it.
      in.drops.erase(std::upper_bound(in.drops.begin(), in.drops.end(), total), in.drops.end());
      continue;
    }
    if (!in.drops.empty() && in.drops.back() > total) {
      const std::string source = o.spd_summary.empty() ? "dropped_frames" : o.spd_summary;
      return Status::Error(source + ": camera " + in.input->camera + " drops frame " +
                           std::to_string(in.drops.back()) + ", after the recording's last (" +
                           std::to_string(total) + ")");
    }
  }

  CaptureManifest m;
  m.name =
      o.name.empty() ? fs::path(NormalizeOutputPath(o.output_dir)).filename().string() : o.name;
  if (o.instrument != "none") {
    ARCO_ASSIGN_OR_RETURN(const InstrumentKind kind, ParseInstrumentKind(o.instrument));
    m.instrument = InstrumentKindName(kind);
  }
  m.fps = fps;
  m.frame_first = 1;
  m.frame_count = total;
  m.calibration = o.calibration.empty()
                      ? std::string("calibration.json")
                      : "calibration" + fs::path(o.calibration).extension().string();
  if (!o.audio.empty()) m.audio = PathRelativeTo(o.audio, o.output_dir);
  CaptureNewSummary out;
  out.warnings = warnings;
  out.calibration_made = calibration_made;
  if (o.sync == CaptureSync::kAudio) {
    m.audio = PathRelativeTo(sync.audio, o.output_dir);
    m.audio_offset_s = sync.audio_offset_s;
    m.audio_sync_confidence = sync.lowest_confidence;
    out.sync_reference = sync.reference;
  }
  out.fps = fps;
  out.frames = total;
  ARCO_ASSIGN_OR_RETURN(out.layout, DetectionLayoutName(m.instrument));
  for (size_t i = 0; i < opened.size(); ++i) {
    const OpenedInput& in = opened[i];
    const Camera& cam = rig.cameras[static_cast<size_t>(in.calibration_camera)];
    CaptureCamera cc;
    if (o.sync == CaptureSync::kAudio) {
      cc.offset_s = sync.offset_s[i];
      cc.drift_ppm = sync.drift_ppm[i];
    }
    cc.name = cam.name;
    cc.serial = cam.serial;
    cc.video = PathRelativeTo(in.input->path, o.output_dir);
    cc.dropped_frames = in.drops;
    cc.rotate_deg = in.rotate_deg;
    m.cameras.push_back(cc);
    out.cameras.push_back({cc.name,
                           cc.serial,
                           cc.video,
                           in.properties.frame_count,
                           in.properties.coded_width,
                           in.properties.coded_height,
                           in.rotate_deg,
                           static_cast<int64_t>(in.drops.size()),
                           cc.offset_s,
                           cc.drift_ppm,
                           o.sync == CaptureSync::kAudio ? sync.confidence[i] : NAN});
  }
  // The manifest we write must read back.
  ARCO_RETURN_IF_ERROR(
      ParseCaptureManifest(CaptureManifestToJson(m).dump(), kCaptureManifestName).status());

  OutputSet outputs;
  ARCO_ASSIGN_OR_RETURN(const std::string tmp, outputs.AddFolder(o.output_dir, replace));
  if (o.calibration.empty()) {
    ARCO_RETURN_IF_ERROR(calibration::SaveCalibration(
        JoinPath(tmp, m.calibration), rig, CalibrationFormat::kArcoJson));
  } else {
    std::error_code ec;
    fs::copy_file(o.calibration, JoinPath(tmp, m.calibration), ec);
    if (ec) return Status::Error(o.calibration + ": cannot copy (" + ec.message() + ")");
  }
  ARCO_RETURN_IF_ERROR(WriteCaptureManifest(tmp, m));
  ARCO_RETURN_IF_ERROR(outputs.Commit());
  return out;
}

}  // namespace arco::capture
