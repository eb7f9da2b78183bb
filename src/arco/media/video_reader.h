// Reading video frames by index: a video file (anything FFmpeg's libav* decode), a
// folder of images (one frame per file) or a single image (one frame).
//
//   ARCO_ASSIGN_OR_RETURN(auto reader, media::VideoReader::Open("cam03.mp4"));
//   reader.properties().fps_hz, .frame_count, .rotation_deg ...
//   ARCO_RETURN_IF_ERROR(reader.Seek(1200));   // the next Read returns frame 1200
//   media::Image frame;
//   ARCO_ASSIGN_OR_RETURN(bool more, reader.Read(&frame));
//
// Frame n is the picture shown at time n / fps after the first frame, as a
// constant-frame-rate player shows it: for an ordinary video that is simply the n-th
// decoded frame; a gap in the timestamps (a dropped frame, a variable-rate AVI such as
// opencv-doc's tree.avi, 68 pictures on a 444-frame timeline) repeats the previous
// picture, and a second picture within one frame period is dropped. Frames without
// timestamps are taken in decoding order. This keeps frame n at video time n / fps,
// the contract of pitch.csv and sync.
//
// Seek(n) seeks the container to the key frame before frame n's timestamp, decodes
// forward and checks each decoded frame's pts until the one shown at n; if the
// demuxer lands after n it aims earlier, and without timestamps it decodes from the
// start. Short forward seeks just decode forward. Either way Seek(n) + Read gives
// exactly what sequential reading gives at n (tests: random seeks on generated
// ffv1/mpeg4/h264 videos with B-frames and on opencv-doc's AVIs).
//
// Frames are returned as stored in the file (coded orientation, coded size unless
// options.max_width scales them down); properties().rotation_deg says how a player
// would turn them for display. EXIF orientation of images is not applied.
//
// Errors (unreadable file, no video stream, frame out of range, decode failure) are
// Status messages that begin with the file name.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "arco/media/image.h"
#include "arco/util/status.h"

namespace arco::media {

struct Rational {
  int num = 0, den = 1;
  double ToDouble() const { return den != 0 ? static_cast<double>(num) / den : 0.0; }
};

enum class FrameCountSource {
  kContainer,       // the container's frame count (e.g. MP4's sample count)
  kCountedPackets,  // the container does not say (Matroska, AVI without index...):
                    // counted by reading (not decoding) the stream's packets at Open
  kImageFiles,      // image folder: the number of image files
};

struct VideoProperties {
  std::string path;
  std::string codec;  // decoder name: "h264", "ffv1", "png", ...
  Rational fps;       // nominal frame rate; 0/1 when unknown
  double fps_hz = 0;  // fps as a double
  // Frames on the timeline (for a variable-rate Matroska file, counted packets: the
  // pictures, which may be fewer).
  int64_t frame_count = 0;
  FrameCountSource frame_count_source = FrameCountSource::kContainer;
  int width = 0, height = 0;              // of the frames Read returns (after max_width scaling)
  int coded_width = 0, coded_height = 0;  // as stored in the file
  // Clockwise rotation a player applies for display (from the stream's display
  // matrix side data, rounded to a multiple of 90): 0, 90, 180 or 270.
  int rotation_deg = 0;
  double duration_s = 0;  // frame_count / fps (0 when the frame rate is unknown)
};

// Two frame rates are the same when within 0.1 % (29.97 vs 30000/1001 written rounded):
// the one comparison of a rate the user gives with a container's (arco capture new,
// arco sync), where a disagreement is an error, never a silent override.
bool SameFrameRate(double a_hz, double b_hz);

struct VideoReaderOptions {
  PixelFormat format = PixelFormat::kRgb8;
  // > 0: frames wider than this are scaled down to this width (area averaging), the
  // height keeping the aspect ratio (rounded, at least 2). 0: coded size.
  int max_width = 0;
  // Frame rate reported for image folders and single images, which carry none.
  Rational image_fps{0, 1};
  // FFmpeg decoder threads. 1 decodes on the calling thread, frame by frame.
  int decoder_threads = 1;
  Status Validate() const;
};

class FrameSource;  // video_source.h: one implementation per kind of input

class VideoReader {
 public:
  // `path`: a video file, a folder of images (files with an image extension, in
  // natural order: frame2.png before frame10.png) or one image file.
  static StatusOr<VideoReader> Open(const std::string& path,
                                    const VideoReaderOptions& options = {});

  VideoReader(VideoReader&&) noexcept;
  VideoReader& operator=(VideoReader&&) noexcept;
  ~VideoReader();

  const VideoProperties& properties() const;
  // Index of the frame the next Read returns.
  int64_t next_frame() const;
  // Reads the next frame into *frame (reusing its buffer); false after the last one.
  StatusOr<bool> Read(Image* frame);
  // The next Read returns frame `index`; an error when it is outside
  // [0, frame_count) or cannot be found.
  Status Seek(int64_t index);
  // Seek(index) and Read.
  StatusOr<Image> ReadFrame(int64_t index);

 private:
  explicit VideoReader(std::unique_ptr<FrameSource> source);
  std::unique_ptr<FrameSource> source_;
};

}  // namespace arco::media
