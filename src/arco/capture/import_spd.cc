#include "arco/capture/import_spd.h"

#include <algorithm>
#include <filesystem>

#include "arco/calibration/calibration_file.h"
#include "arco/mocap/capture.h"
#include "arco/registry/instruments.h"
#include "arco/util/atomic_dir.h"
#include "arco/util/file_io.h"

namespace arco::capture {
namespace {
namespace fs = std::filesystem;
}  // namespace

StatusOr<ImportSpdSummary> ImportSpdCapture(const ImportSpdOptions& o) {
  if (o.output_dir.empty()) return Status::Error("output_dir is empty");
  FolderReplace replace;
  replace.overwrite = o.overwrite;
  replace.marker = kCaptureManifestName;  // only an arco capture is replaced
  replace.kind = "capture";
  ARCO_RETURN_IF_ERROR(CheckOutputFolder(o.output_dir, replace));  // before the work
  std::error_code ec;
  ARCO_ASSIGN_OR_RETURN(Calibration calibration, calibration::LoadCalibration(o.calibration));
  SpdImportOptions spd;
  spd.instrument = o.instrument;
  spd.human_dir = o.human_dir;
  spd.instrument_dir = o.instrument_dir;
  spd.frame_first = o.frame_first;
  spd.frame_last = o.frame_last;
  if (!o.summary.empty()) {
    ARCO_ASSIGN_OR_RETURN(SpdSummary summary, ReadSpdSummary(o.summary));
    spd.frame_drops = summary.frame_drops;
    if (spd.frame_first == 0) spd.frame_first = summary.start_frame;
    if (spd.frame_last == 0) spd.frame_last = summary.end_frame;
  }
  if (spd.frame_first <= 0 || spd.frame_last <= 0) {
    return Status::Error(
        "give the frame range (frame_first, frame_last) or a summary with StartFrame and "
        "EndFrame");
  }
  // Views: the serials given, else every calibrated camera with a keypoint folder.
  std::vector<int> cameras;
  std::vector<std::string> warnings;
  if (o.serials.empty()) {
    for (size_t c = 0; c < calibration.rig.cameras.size(); ++c) {
      const std::string& serial = calibration.rig.cameras[c].serial;
      if (!serial.empty() && fs::is_directory(JoinPath(o.human_dir, serial), ec)) {
        cameras.push_back(static_cast<int>(c));
      }
    }
    if (cameras.empty()) {
      return Status::Error(o.human_dir + ": no <serial> folder of any camera in " + o.calibration);
    }
    // A keypoint folder of a camera the calibration lacks cannot be triangulated: the
    // import goes on with the calibrated ones (a camera that failed to calibrate should
    // not block a session), but says which it leaves out.
    std::vector<std::string> folders;
    for (fs::directory_iterator it(o.human_dir, ec), end; !ec && it != end; it.increment(ec)) {
      if (it->is_directory(ec)) folders.push_back(it->path().filename().string());
    }
    std::sort(folders.begin(), folders.end());
    for (const std::string& folder : folders) {
      if (calibration.rig.FindCamera(folder) < 0) {
        warnings.push_back(JoinPath(o.human_dir, folder) + ": camera " + folder + " is not in " +
                           o.calibration + "; its keypoints are not imported");
      }
    }
  } else {
    for (const std::string& s : o.serials) {
      const int c = calibration.rig.FindCamera(s);
      if (c < 0) return Status::Error("camera \"" + s + "\" is not in " + o.calibration);
      cameras.push_back(c);
    }
  }
  for (int c : cameras) {
    const Camera& cam = calibration.rig.cameras[c];
    spd.serials.push_back(cam.serial.empty() ? cam.name : cam.serial);
  }
  ImportSpdSummary out;
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> keypoints, ImportSpdKeypoints(spd, &out.files));

  CaptureManifest m;
  m.name =
      o.name.empty() ? fs::path(NormalizeOutputPath(o.output_dir)).filename().string() : o.name;
  m.instrument = o.instrument;
  m.fps = o.fps;
  m.frame_first = spd.frame_first;
  m.frame_count = spd.frame_last - spd.frame_first + 1;
  m.calibration = "calibration" + fs::path(o.calibration).extension().string();
  m.keypoints2d = "keypoints2d.npy";
  ARCO_ASSIGN_OR_RETURN(InstrumentKind kind, ParseInstrumentKind(o.instrument));
  m.layout = GetInstrumentInfo(kind).spd_layout;
  if (!o.audio.empty()) {
    m.audio = "audio" + fs::path(o.audio).extension().string();
    m.audio_offset_s = o.audio_offset_s;
  }
  for (size_t v = 0; v < cameras.size(); ++v) {
    const Camera& cam = calibration.rig.cameras[cameras[v]];
    CaptureCamera cc{cam.name, cam.serial, "", {}};
    if (auto it = spd.frame_drops.find(spd.serials[v]); it != spd.frame_drops.end()) {
      // The session's log covers the whole recording: drops before the first frame still
      // number the video's frames; those after the last name no frame of this capture.
      for (int64_t g : it->second) {
        if (g >= 0 && g <= spd.frame_last) cc.dropped_frames.push_back(g);
      }
      std::sort(cc.dropped_frames.begin(), cc.dropped_frames.end());
      cc.dropped_frames.erase(std::unique(cc.dropped_frames.begin(), cc.dropped_frames.end()),
                              cc.dropped_frames.end());
    }
    m.cameras.push_back(cc);
  }
  ARCO_RETURN_IF_ERROR(ParseCaptureManifest(CaptureManifestToJson(m).dump(), "capture.json")
                           .status());  // the manifest we write must read back

  // Built in a hidden temporary sibling, moved into place once complete.
  auto write_all = [&](const std::string& tmp) -> Status {
    NpyArray<float> k32;
    k32.shape = keypoints.shape;
    k32.data.assign(keypoints.data.begin(), keypoints.data.end());
    ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(tmp, m.keypoints2d), k32));
    fs::copy_file(o.calibration, JoinPath(tmp, m.calibration), ec);
    if (ec) return Status::Error(o.calibration + ": cannot copy (" + ec.message() + ")");
    if (!m.audio.empty()) {
      fs::copy_file(o.audio, JoinPath(tmp, m.audio), ec);
      if (ec) return Status::Error(o.audio + ": cannot copy (" + ec.message() + ")");
    }
    return WriteCaptureManifest(tmp, m);
  };
  ARCO_RETURN_IF_ERROR(AtomicWriteDirectory(o.output_dir, replace, write_all));
  out.frames = keypoints.shape[0];
  out.views = keypoints.shape[1];
  out.points = keypoints.shape[2];
  out.warnings = warnings;
  return out;
}

}  // namespace arco::capture
