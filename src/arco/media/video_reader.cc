#include "arco/media/video_reader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <system_error>

#include "arco/media/frame_source.h"
#include "arco/util/file_io.h"

namespace arco::media {

bool SameFrameRate(double a_hz, double b_hz) {
  return std::abs(a_hz - b_hz) <= 1e-3 * std::max(a_hz, b_hz);
}
namespace {

bool HasImageExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) {
    return static_cast<char>(std::tolower(c));
  });
  for (const char* known :
       {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".ppm", ".pgm", ".pnm", ".webp"}) {
    if (ext == known) return true;
  }
  return false;
}

class ImageFiles : public FrameSource {
 public:
  ImageFiles(std::vector<std::string> files, const VideoReaderOptions& options)
      : files_(std::move(files)), options_(options) {}

  Status Open(const std::string& path) {
    ARCO_ASSIGN_OR_RETURN(auto first, OpenVideoFile(files_[0], options_, false));
    properties_ = first->properties();
    properties_.path = path;
    properties_.fps = options_.image_fps;
    properties_.fps_hz = options_.image_fps.ToDouble();
    properties_.frame_count = static_cast<int64_t>(files_.size());
    properties_.frame_count_source = FrameCountSource::kImageFiles;
    properties_.rotation_deg = 0;
    properties_.duration_s =
        properties_.fps_hz > 0 ? static_cast<double>(files_.size()) / properties_.fps_hz : 0.0;
    return Status::Ok();
  }

  StatusOr<bool> Read(Image* image) override {
    if (next_frame_ >= static_cast<int64_t>(files_.size())) return false;
    const std::string& file = files_[static_cast<size_t>(next_frame_)];
    ARCO_ASSIGN_OR_RETURN(auto source, OpenVideoFile(file, options_, false));
    const VideoProperties& p = source->properties();
    if (p.coded_width != properties_.coded_width || p.coded_height != properties_.coded_height) {
      return Status::Error(file + ": image size " + std::to_string(p.coded_width) + "x" +
                           std::to_string(p.coded_height) + " differs from the first image's " +
                           std::to_string(properties_.coded_width) + "x" +
                           std::to_string(properties_.coded_height));
    }
    ARCO_ASSIGN_OR_RETURN(const bool got, source->Read(image));
    if (!got) return Status::Error(file + ": no decodable image");
    ++next_frame_;
    return true;
  }

  Status Seek(int64_t index) override {
    ARCO_RETURN_IF_ERROR(CheckIndex(index));
    next_frame_ = index;
    return Status::Ok();
  }

 private:
  std::vector<std::string> files_;
  VideoReaderOptions options_;
};

}  // namespace

Status FrameSource::CheckIndex(int64_t index) const {
  if (index < 0 || index >= properties_.frame_count) {
    return Status::Error(properties_.path + ": frame " + std::to_string(index) +
                         " is outside [0, " + std::to_string(properties_.frame_count) + ")");
  }
  return Status::Ok();
}

void ScaledSize(int coded_width, int coded_height, int max_width, int* width, int* height) {
  if (max_width <= 0 || coded_width <= max_width) {
    *width = coded_width;
    *height = coded_height;
    return;
  }
  *width = max_width;
  *height = std::max(
      2,
      static_cast<int>(std::lround(static_cast<double>(coded_height) * max_width / coded_width)));
}

StatusOr<std::unique_ptr<FrameSource>> OpenImageFiles(const std::string& path,
                                                      std::vector<std::string> files,
                                                      const VideoReaderOptions& options) {
  auto source = std::make_unique<ImageFiles>(std::move(files), options);
  ARCO_RETURN_IF_ERROR(source->Open(path));
  return std::unique_ptr<FrameSource>(std::move(source));
}

Status VideoReaderOptions::Validate() const {
  if (max_width < 0) return Status::Error("max_width must be >= 0");
  if (image_fps.num < 0 || image_fps.den <= 0) {
    return Status::Error("image_fps must be a non-negative num / positive den");
  }
  if (decoder_threads < 0)
    return Status::Error("decoder_threads must be >= 0 (0: FFmpeg's choice)");
  return Status::Ok();
}

StatusOr<VideoReader> VideoReader::Open(const std::string& path,
                                        const VideoReaderOptions& options) {
  ARCO_RETURN_IF_ERROR(options.Validate().WithContext(path));
  namespace fs = std::filesystem;
  std::error_code error;
  std::unique_ptr<FrameSource> source;
  if (fs::is_directory(path, error)) {
    std::vector<std::string> files;
    for (const auto& entry : fs::directory_iterator(path, error)) {
      if (entry.is_regular_file(error) && HasImageExtension(entry.path())) {
        files.push_back(entry.path().string());
      }
    }
    if (error) return Status::Error(path + ": cannot list the folder (" + error.message() + ")");
    if (files.empty()) {
      return Status::Error(path + ": no image files (png, jpg, bmp, tif, ppm, pgm, webp)");
    }
    std::sort(files.begin(), files.end(), NaturalLess);
    ARCO_ASSIGN_OR_RETURN(source, OpenImageFiles(path, std::move(files), options));
  } else if (!fs::exists(path, error)) {
    return Status::Error(path + ": no such file or folder");
  } else if (HasImageExtension(path)) {
    ARCO_ASSIGN_OR_RETURN(source, OpenImageFiles(path, {path}, options));
  } else {
    ARCO_ASSIGN_OR_RETURN(source, OpenVideoFile(path, options, true));
  }
  return VideoReader(std::move(source));
}

VideoReader::VideoReader(std::unique_ptr<FrameSource> source) : source_(std::move(source)) {}
VideoReader::VideoReader(VideoReader&&) noexcept = default;
VideoReader& VideoReader::operator=(VideoReader&&) noexcept = default;
VideoReader::~VideoReader() = default;

const VideoProperties& VideoReader::properties() const { return source_->properties(); }
int64_t VideoReader::next_frame() const { return source_->next_frame(); }
StatusOr<bool> VideoReader::Read(Image* frame) { return source_->Read(frame); }
Status VideoReader::Seek(int64_t index) { return source_->Seek(index); }

StatusOr<Image> VideoReader::ReadFrame(int64_t index) {
  ARCO_RETURN_IF_ERROR(Seek(index));
  Image image;
  ARCO_ASSIGN_OR_RETURN(const bool got, Read(&image));
  if (!got)
    return Status::Error(properties().path + ": frame " + std::to_string(index) + " not found");
  return image;
}

}  // namespace arco::media
