#include "arco/media/frame_times.h"

extern "C" {
#include <libavformat/avformat.h>
#include <libavutil/log.h>
}

#include <algorithm>
#include <cstdio>

namespace arco::media {

StatusOr<FrameTimes> ReadFrameTimes(const std::string& path) {
  av_log_set_level(AV_LOG_QUIET);
  AVFormatContext* format = nullptr;
  if (avformat_open_input(&format, path.c_str(), nullptr, nullptr) < 0) {
    return Status::Error(path + ": cannot open");
  }
  struct Closer {
    AVFormatContext** f;
    ~Closer() { avformat_close_input(f); }
  } closer{&format};
  if (avformat_find_stream_info(format, nullptr) < 0) {
    return Status::Error(path + ": cannot read stream info");
  }
  const int index = av_find_best_stream(format, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
  if (index < 0) return Status::Error(path + ": no video stream");
  AVStream* stream = format->streams[index];
  FrameTimes out;
  // The rate VideoReader uses (video_file.cc).
  const AVRational rate = av_guess_frame_rate(format, stream, nullptr);
  if (rate.num > 0 && rate.den > 0) out.fps = av_q2d(rate);
  const double tb = av_q2d(stream->time_base);
  AVPacket* packet = av_packet_alloc();
  std::vector<int64_t> pts;
  while (av_read_frame(format, packet) >= 0) {
    if (packet->stream_index == index) {
      const int64_t t = packet->pts != AV_NOPTS_VALUE ? packet->pts : packet->dts;
      if (t != AV_NOPTS_VALUE) pts.push_back(t);
    }
    av_packet_unref(packet);
  }
  av_packet_free(&packet);
  std::sort(pts.begin(), pts.end());
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  for (int64_t t : pts) out.time_s.push_back(double(t - pts.front()) * tb);
  if (out.time_s.size() >= 2) {
    out.min_step_s = 1e300;
    for (size_t i = 1; i < out.time_s.size(); ++i) {
      const double step = out.time_s[i] - out.time_s[i - 1];
      out.min_step_s = std::min(out.min_step_s, step);
      out.max_step_s = std::max(out.max_step_s, step);
      if (out.fps > 0 && step >= kTimestampJumpPeriods / out.fps) {
        out.jumps.push_back({out.time_s[i], step});
      }
    }
  }
  return out;
}

std::string DescribeTimestampJumps(const std::string& path, const FrameTimes& times) {
  if (times.jumps.empty()) return "";
  const auto largest = std::max_element(
      times.jumps.begin(), times.jumps.end(), [](const TimestampJump& a, const TimestampJump& b) {
        return a.step_s < b.step_s;
      });
  char text[256];
  std::snprintf(text,
                sizeof text,
                ": timestamps jump %zu time%s (the largest by %.3f s, %.1f frames at %.6g fps, "
                "before %.3f s): not a constant frame rate (a pause, dropped frames?); the capture "
                "lays frames at n / fps",
                times.jumps.size(),
                times.jumps.size() == 1 ? "" : "s",
                largest->step_s,
                largest->step_s * times.fps,
                times.fps,
                largest->at_s);
  return path + text;
}

}  // namespace arco::media
