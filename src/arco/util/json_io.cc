#include "arco/util/json_io.h"

#include <cmath>
#include <limits>
#include <string>

#include "arco/util/file_io.h"

namespace arco {
namespace {

// Marker strings ParseJsonMarkingNonFinite puts in place of the tokens: a control
// character no JSON text written by a person starts a string with.
constexpr char kMarkerPrefix = '\x01';

// Replaces NaN/Infinity/-Infinity tokens outside strings by `null` padded with
// spaces, so byte offsets in parse errors still point at the original text; with `mark`,
// by marker strings instead (offsets after them shift).
std::string ReplaceNonFiniteTokens(const std::string& text, bool mark = false) {
  std::string out = text;
  bool in_string = false;
  for (size_t i = 0; i < out.size(); ++i) {
    const char c = out[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
      continue;
    }
    auto replace = [&](size_t start, size_t len) {
      out.replace(start, len, "null" + std::string(len - 4, ' '));
    };
    if (mark) {
      for (const char* token : {"-Infinity", "Infinity", "NaN"}) {
        const size_t len = std::char_traits<char>::length(token);
        if (out.compare(i, len, token) != 0) continue;
        const std::string marker = std::string("\"\\u0001") + token + "\"";  // kMarkerPrefix
        out.replace(i, len, marker);
        i += marker.size() - 1;
        break;
      }
      continue;
    }
    if (out.compare(i, 3, "NaN") == 0) {
      // "NaN" is 3 chars, one short of "null": widen into a preceding sign or fail over.
      if (i > 0 && (out[i - 1] == '-' || out[i - 1] == '+')) {
        replace(i - 1, 4);
      } else {
        out.replace(i, 3, "null");
        // Length changed by one; offsets after this point shift. Acceptable.
      }
      continue;
    }
    if (out.compare(i, 9, "-Infinity") == 0) {
      replace(i, 9);
      i += 8;
      continue;
    }
    if (out.compare(i, 8, "Infinity") == 0) {
      replace(i, 8);
      i += 7;
      continue;
    }
  }
  return out;
}

}  // namespace

StatusOr<Json> ParseJsonLenient(const std::string& text, const std::string& source) {
  // Json::exception covers parse errors and number overflow (e.g. 1e400).
  try {
    return Json::parse(ReplaceNonFiniteTokens(text));
  } catch (const Json::exception& e) {
    return Status::Error(source + ": malformed JSON (" + e.what() + ")");
  }
}

StatusOr<Json> ParseJsonMarkingNonFinite(const std::string& text, const std::string& source) {
  try {
    return Json::parse(ReplaceNonFiniteTokens(text, /*mark=*/true));
  } catch (const Json::exception& e) {
    return Status::Error(source + ": malformed JSON (" + e.what() + ")");
  }
}

std::string NonFiniteToken(const Json& value) {
  if (!value.is_string()) return "";
  const std::string& s = value.get_ref<const std::string&>();
  if (s.empty() || s[0] != kMarkerPrefix) return "";
  const std::string token = s.substr(1);
  return token == "NaN" || token == "Infinity" || token == "-Infinity" ? token : "";
}

StatusOr<Json> ReadJsonFile(const std::string& path) {
  ARCO_ASSIGN_OR_RETURN(std::string text, ReadFileToString(path));
  return ParseJsonLenient(text, path);
}

Status WriteJsonFile(const std::string& path, const Json& json, int indent) {
  std::string text;
  try {
    text = json.dump(indent);
  } catch (const Json::exception& e) {
    return Status::Error(path + ": cannot serialise JSON: " + e.what());
  }
  text.push_back('\n');
  return AtomicWriteFile(path, text);
}

double JsonNumberOrNaN(const Json& value) {
  if (value.is_number()) return value.get<double>();
  return std::numeric_limits<double>::quiet_NaN();
}

Json JsonFromDouble(double value) {
  if (!std::isfinite(value)) return Json(nullptr);
  return Json(value);
}

}  // namespace arco
