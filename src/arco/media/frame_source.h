// Internal to media/: one FrameSource per kind of input behind VideoReader.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "arco/media/video_reader.h"

namespace arco::media {

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  const VideoProperties& properties() const { return properties_; }
  int64_t next_frame() const { return next_frame_; }
  virtual StatusOr<bool> Read(Image* frame) = 0;
  virtual Status Seek(int64_t index) = 0;

 protected:
  // The common range check of Seek, with the file name in the message.
  Status CheckIndex(int64_t index) const;

  VideoProperties properties_;
  int64_t next_frame_ = 0;
};

// A video (or single image) file decoded by FFmpeg's libav*. `count_frames`: count
// the packets when the container does not give the frame count (otherwise 0).
StatusOr<std::unique_ptr<FrameSource>> OpenVideoFile(const std::string& path,
                                                     const VideoReaderOptions& options,
                                                     bool count_frames);

// Image files as frames 0, 1, ...; `path` (the folder or the file) names the source.
StatusOr<std::unique_ptr<FrameSource>> OpenImageFiles(const std::string& path,
                                                      std::vector<std::string> files,
                                                      const VideoReaderOptions& options);

// Output size for a coded size under options.max_width (see VideoReaderOptions).
void ScaledSize(int coded_width, int coded_height, int max_width, int* width, int* height);

}  // namespace arco::media
