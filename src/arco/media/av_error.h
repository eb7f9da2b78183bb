// Internal to media/, FFmpeg's one owner (docs/architecture.md): FFmpeg's text for one of
// its error codes, for the messages that name the file and what failed.
#pragma once

extern "C" {
#include <libavutil/error.h>
}

#include <string>

namespace arco::media {

inline std::string AvError(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {0};
  av_strerror(code, text, sizeof(text));
  return text;
}

}  // namespace arco::media
