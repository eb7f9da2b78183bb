// Writing videos frame by frame with FFmpeg's libav*: the codebase's one encoder.
//
//   media::VideoWriterOptions options;            // FFV1 in Matroska: lossless
//   options.width = 960;
//   options.height = 540;
//   options.fps = {30, 1};
//   ARCO_ASSIGN_OR_RETURN(auto writer, media::VideoWriter::Open("cam0.mkv", options));
//   for (...) ARCO_RETURN_IF_ERROR(writer.Write(frame));   // RGB8 or Gray8
//   ARCO_RETURN_IF_ERROR(writer.Close());        // flushes the encoder, writes the trailer
//
// Frame k gets the timestamp k / fps (constant frame rate), which is what
// media::VideoReader's frame n means. Frames are converted with swscale to the pixel
// format the codec stores: by default FFV1 stores 8-bit RGB (bgr0) for RGB input and
// gray for gray input, so an RGB8 frame written as FFV1 reads back bit-exact through
// VideoReader; lossy codecs (mpeg4, libx264) store yuv420p, which needs an even width
// and height. The rotation is written as the stream's display matrix (clockwise, as
// VideoProperties::rotation_deg reads it back); frames are stored as given.
//
// The writer writes to the path it is given, directly: callers that need an atomic
// output declare it in util/output_set.h's OutputSet and write to its temporary.
// Errors are Status messages that begin with the file name and give FFmpeg's reason.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "arco/media/image.h"
#include "arco/media/video_reader.h"
#include "arco/util/status.h"

namespace arco::media {

struct VideoWriterOptions {
  // libavformat muxer name ("matroska", "mp4", "avi"); empty: guessed from the file's
  // extension.
  std::string container = "matroska";
  // libavcodec encoder name: "ffv1" (lossless), "mpeg4", "libx264", "libvpx" (VP8, for
  // WebM; the last two when the FFmpeg build has them, see HasVideoEncoder).
  std::string codec = "ffv1";
  int width = 0, height = 0;  // of every frame written, px
  Rational fps{30, 1};
  // Clockwise display rotation: 0, 90, 180 or 270; non-zero needs a QuickTime-family
  // container ("mp4", "mov"; lossless: ffv1 in "mov"), else Open fails.
  int rotation_deg = 0;
  // What Write is given (it accepts both; this picks the stored format when
  // pixel_format is empty, e.g. gray FFV1 for gray frames).
  PixelFormat source_format = PixelFormat::kRgb8;
  // libavutil pixel format the codec stores ("yuv420p", "bgr0", "gray"); empty: the
  // default above.
  std::string pixel_format;
  int gop = 12;      // key frame interval (frames)
  int b_frames = 0;  // B-frames between reference frames (reordered timestamps)
  // Lossy codecs: target bit rate in bit/s; 0 = constant high quality (mpeg4
  // qscale 2, libx264 crf 16, libvpx crf 16 capped at 0.12 bit per pixel).
  int64_t bit_rate = 0;
  int threads = 1;  // encoder threads; 1 encodes on the calling thread
  // Reproducible files: no random ids (Matroska's segment UID) or version strings, so
  // the same frames give the same bytes (libavformat/libavcodec's bitexact flags).
  bool bitexact = true;

  // Sizes, fps, rotation, gop and threads in range; the names are checked at Open.
  Status Validate() const;
};

class VideoWriter {
 public:
  // Creates (or replaces) the file and writes the container header. Errors: invalid
  // options, unknown container or codec, a size the stored pixel format cannot hold
  // (odd sides for yuv420p), a file that cannot be created.
  static StatusOr<VideoWriter> Open(const std::string& path, const VideoWriterOptions& options);

  VideoWriter(VideoWriter&&) noexcept;
  VideoWriter& operator=(VideoWriter&&) noexcept;
  // Closes the file if Close was not called (errors are then lost: call Close).
  ~VideoWriter();

  // Encodes the next frame (RGB8 or Gray8 of the opened size). An error (wrong size,
  // encoding or writing failure) leaves the writer failed: later calls return it.
  Status Write(const Image& frame);
  // Flushes the encoder and writes the trailer; the file is complete afterwards.
  // Calling it again returns the first result.
  Status Close();

  int64_t frames_written() const;
  const std::string& path() const;

 private:
  struct State;
  explicit VideoWriter(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

// Whether this FFmpeg build has the encoder (libx264 is optional).
bool HasVideoEncoder(const std::string& name);

// libavcodec's version (LIBAVCODEC_VERSION_INT): what the encoders' bytes depend on, for
// caches of encoded videos (arco view's).
unsigned CodecLibraryVersion();

// Writes one RGB8 or Gray8 image as a lossless PNG file (through VideoWriter:
// libavformat's image2 muxer). Errors name the file.
Status WriteImageFile(const std::string& path, const Image& image);

}  // namespace arco::media
