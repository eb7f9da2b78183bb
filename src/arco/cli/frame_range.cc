#include "arco/cli/frame_range.h"

namespace arco::cli {

Status ParseFrameRange(const std::string& text, int64_t* first, int64_t* last) {
  if (text.empty()) return Status::Ok();
  const auto bad = [&] {
    return Status::Error("--frames \"" + text + "\" must look like FIRST:LAST (frame numbers)");
  };
  const size_t colon = text.find(':');
  if (colon == std::string::npos) return bad();
  // At most 12 digits: no overflow, no sign, no spaces (std::stoll would accept those).
  const auto number = [](const std::string& s, int64_t* out) {
    if (s.empty()) return true;
    if (s.size() > 12 || s.find_first_not_of("0123456789") != std::string::npos) return false;
    *out = std::stoll(s);
    return true;
  };
  if (!number(text.substr(0, colon), first) || !number(text.substr(colon + 1), last)) {
    return bad();
  }
  // Said here, in the flag's words: the options structs' own check names their fields.
  if (*first >= 0 && *last >= 0 && *last < *first) {
    return Status::Error("--frames \"" + text + "\": LAST is before FIRST");
  }
  return Status::Ok();
}

}  // namespace arco::cli
