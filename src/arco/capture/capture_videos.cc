#include "arco/capture/capture_videos.h"

#include "arco/calibration/calibration_file.h"
#include "arco/capture/capture_checks.h"
#include "arco/media/video_reader.h"
#include "arco/util/file_io.h"

namespace arco::capture {

StatusOr<std::vector<CaptureVideo>> OpenCaptureVideos(const std::string& dir,
                                                      const CaptureManifest& manifest,
                                                      int64_t first,
                                                      int64_t last) {
  const std::string manifest_path = CaptureManifestPath(dir);
  const std::string calibration_path = ResolveCapturePath(dir, manifest.calibration);
  StatusOr<Calibration> calibration = calibration::LoadCalibration(calibration_path);
  if (!calibration.ok()) return calibration.status().WithContext(manifest_path + ": calibration");
  ARCO_ASSIGN_OR_RETURN(const std::vector<int> rig_index,
                        MatchCaptureCameras(dir, manifest, calibration->rig, calibration_path));
  std::vector<CaptureVideo> videos(manifest.cameras.size());
  for (size_t v = 0; v < videos.size(); ++v) {
    ARCO_ASSIGN_OR_RETURN(videos[v],
                          OpenCaptureVideo(dir,
                                           manifest,
                                           static_cast<int>(v),
                                           calibration->rig.cameras[rig_index[v]],
                                           calibration_path,
                                           first,
                                           last));
  }
  return videos;
}

StatusOr<CaptureVideo> OpenCaptureVideo(const std::string& dir,
                                        const CaptureManifest& manifest,
                                        int v,
                                        const Camera& calibration,
                                        const std::string& calibration_path,
                                        int64_t first,
                                        int64_t last) {
  const std::string manifest_path = CaptureManifestPath(dir);
  const CaptureCamera& cam = manifest.cameras.at(v);
  CaptureVideo in;
  in.camera = cam.name;
  if (cam.video.empty()) {
    return Status::Error(manifest_path + ": camera " + cam.name +
                         " has no video (make the capture with `arco capture new --video "
                         "CAMERA=FILE`)");
  }
  in.video = ResolveCapturePath(dir, cam.video);
  in.rotate_deg = cam.rotate_deg;
  in.calibration = calibration;
  const int width = in.calibration.width, height = in.calibration.height;
  ARCO_ASSIGN_OR_RETURN(media::VideoReader reader, media::VideoReader::Open(in.video));
  const media::VideoProperties& p = reader.properties();
  const bool swap = in.rotate_deg == 90 || in.rotate_deg == 270;
  const int w = swap ? p.height : p.width, h = swap ? p.width : p.height;
  if (w != width || h != height) {
    return Status::Error(in.video + ": frames are " + std::to_string(w) + "x" + std::to_string(h) +
                         " after rotate_deg " + std::to_string(in.rotate_deg) + ", camera " +
                         cam.name + " of " + calibration_path + " is " + std::to_string(width) +
                         "x" + std::to_string(height));
  }
  in.video_frames = p.frame_count;
  // The last global frame this camera recorded must be in its video.
  for (int64_t g = last; g >= first; --g) {
    const int64_t n = manifest.VideoFrameNumber(v, g);
    if (n < 0) continue;
    if (n > in.video_frames) {
      return Status::Error(in.video + ": has " + std::to_string(in.video_frames) +
                           " frames, capture frame " + std::to_string(g) + " is its frame " +
                           std::to_string(n) + " (" + manifest_path + ")");
    }
    break;
  }
  return in;
}

CaptureFrameReader::CaptureFrameReader(const CaptureManifest& manifest,
                                       int view,
                                       CaptureVideo video,
                                       media::VideoReaderOptions options)
    : manifest_(&manifest), view_(view), video_(std::move(video)), options_(options) {}

StatusOr<bool> CaptureFrameReader::Read(int64_t g, media::Image* frame, bool rotate) {
  const int64_t n = manifest_->VideoFrameNumber(view_, g);  // 1-based, -1: dropped
  if (n < 0) return false;
  if (!reader_) {
    ARCO_ASSIGN_OR_RETURN(media::VideoReader r, media::VideoReader::Open(video_.video, options_));
    reader_.emplace(std::move(r));
  }
  if (reader_->next_frame() != n - 1) ARCO_RETURN_IF_ERROR(reader_->Seek(n - 1));
  const bool turn = rotate && video_.rotate_deg != 0;
  ARCO_ASSIGN_OR_RETURN(const bool more, reader_->Read(turn ? &decoded_ : frame));
  if (!more) {
    return Status::Error(video_.video + ": frame " + std::to_string(n - 1) +
                         " could not be read (the video ends early)");
  }
  if (turn) *frame = media::RotateClockwise(decoded_, video_.rotate_deg);
  return true;
}

}  // namespace arco::capture
