// JSON reading that tolerates the bare `NaN`, `Infinity` and `-Infinity` tokens
// SPD files contain (not valid JSON). They are read as JSON null; use
// JsonNumberOrNaN to read a number that may be null. Writing uses null for NaN.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "arco/util/status.h"

namespace arco {

using Json = nlohmann::json;

// Parses text; `source` names the file in error messages.
StatusOr<Json> ParseJsonLenient(const std::string& text, const std::string& source);
StatusOr<Json> ReadJsonFile(const std::string& path);
// For readers that must tell `"fps": NaN` from an absent field: the tokens become marker
// strings that NonFiniteToken recognises (never null).
StatusOr<Json> ParseJsonMarkingNonFinite(const std::string& text, const std::string& source);
// "NaN", "Infinity" or "-Infinity" for a value ParseJsonMarkingNonFinite read from that
// token; "" for any other value.
std::string NonFiniteToken(const Json& value);
// Pretty JSON written atomically (util/file_io.h).
Status WriteJsonFile(const std::string& path, const Json& json, int indent = 2);

// A number, or quiet NaN for null / a non-number.
double JsonNumberOrNaN(const Json& value);
// A JSON value for a double: null when not finite.
Json JsonFromDouble(double value);

}  // namespace arco
