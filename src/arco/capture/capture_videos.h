// The videos of a capture made by `arco capture new`, checked before a stage decodes
// them (`arco detect`, `arco track`): every camera has a video, it opens, its frame size
// after rotate_deg is its calibration camera's, and the last frame the camera recorded
// in [first, last] is inside it. One line naming the file on each failure.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "arco/camera/camera.h"
#include "arco/media/image.h"
#include "arco/media/video_reader.h"
#include "arco/mocap/capture.h"
#include "arco/util/status.h"

namespace arco::capture {

struct CaptureVideo {
  std::string camera;  // the capture camera's name
  std::string video;   // resolved path
  int rotate_deg = 0;  // clockwise turn of decoded frames to the calibration's image
  Camera calibration;  // the calibration camera it matches (name, else serial)
  int64_t video_frames = 0;
};

// In the manifest's camera order. `first`, `last`: global frame numbers checked.
StatusOr<std::vector<CaptureVideo>> OpenCaptureVideos(const std::string& capture_dir,
                                                      const CaptureManifest& manifest,
                                                      int64_t first,
                                                      int64_t last);

// One camera's video (manifest index `view`), with the same checks; `calibration` is its
// calibration camera (MatchCaptureCameras). For a stage that needs only one camera
// (`arco overlay`): the others need no video.
StatusOr<CaptureVideo> OpenCaptureVideo(const std::string& capture_dir,
                                        const CaptureManifest& manifest,
                                        int view,
                                        const Camera& calibration,
                                        const std::string& calibration_path,
                                        int64_t first,
                                        int64_t last);

// The one way a stage reads a capture camera's frames by the capture's frame number (`arco
// detect`, `arco track`, `arco overlay`): the manifest maps frame g to the camera's video
// frame (none where it dropped it), the reader seeks only when g is not the next frame,
// and the picture is turned by rotate_deg unless the caller turns it itself. Opened on the
// first read (a worker may hold readers it never uses).
class CaptureFrameReader {
 public:
  CaptureFrameReader(const CaptureManifest& manifest,
                     int view,
                     CaptureVideo video,
                     media::VideoReaderOptions options = {});
  // Frame g into *frame: false when the camera dropped it (*frame untouched). An error
  // naming the video when it does not open, cannot seek, or ends before the frame.
  StatusOr<bool> Read(int64_t g, media::Image* frame, bool rotate = true);
  const CaptureVideo& video() const { return video_; }

 private:
  const CaptureManifest* manifest_;
  int view_;
  CaptureVideo video_;
  media::VideoReaderOptions options_;
  std::optional<media::VideoReader> reader_;
  media::Image decoded_;  // reused when the frame is turned
};

}  // namespace arco::capture
