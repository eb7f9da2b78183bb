#include "arco/mocap/labelme.h"

#include <cmath>
#include <set>

#include "arco/util/file_io.h"
#include "arco/util/json_io.h"

namespace arco {

int LabelmeAnnotation::Find(const std::string& label) const {
  for (size_t i = 0; i < points.size(); ++i) {
    if (points[i].label == label) return static_cast<int>(i);
  }
  return -1;
}

StatusOr<LabelmeAnnotation> ParseLabelme(const std::string& text,
                                         const std::string& source,
                                         PixelOrigin file_origin) {
  ARCO_ASSIGN_OR_RETURN(Json j, ParseJsonLenient(text, source));
  if (!j.is_object()) return Status::Error(source + ": a labelme file must be a JSON object");
  LabelmeAnnotation a;
  if (auto it = j.find("imagePath"); it != j.end() && it->is_string()) {
    a.image_path = it->get<std::string>();
  }
  auto size_field = [&](const char* key, int* out) -> Status {
    const auto it = j.find(key);
    if (it == j.end() || it->is_null()) return Status::Ok();
    if (!it->is_number_integer() || it->get<int64_t>() <= 0 || it->get<int64_t>() > 1000000) {
      return Status::Error(source + ": \"" + key + "\" must be a positive integer");
    }
    *out = static_cast<int>(it->get<int64_t>());
    return Status::Ok();
  };
  ARCO_RETURN_IF_ERROR(size_field("imageWidth", &a.image_width));
  ARCO_RETURN_IF_ERROR(size_field("imageHeight", &a.image_height));
  const auto shapes = j.find("shapes");
  if (shapes == j.end() || !shapes->is_array()) {
    return Status::Error(source + ": no \"shapes\" array (not a labelme file?)");
  }
  const double shift = file_origin == PixelOrigin::kCorner ? -0.5 : 0.0;
  std::set<std::string> seen;
  for (size_t i = 0; i < shapes->size(); ++i) {
    const Json& s = (*shapes)[i];
    const std::string where = source + ": shapes[" + std::to_string(i) + "]";
    if (!s.is_object()) return Status::Error(where + " is not an object");
    const auto type = s.find("shape_type");
    if (type == s.end() || !type->is_string() || type->get<std::string>() != "point") continue;
    const auto label = s.find("label");
    if (label == s.end() || !label->is_string() || label->get<std::string>().empty()) {
      return Status::Error(where + ": a point needs a non-empty \"label\"");
    }
    const std::string name = label->get<std::string>();
    const auto pts = s.find("points");
    if (pts == s.end() || !pts->is_array() || pts->size() != 1 || !(*pts)[0].is_array() ||
        (*pts)[0].size() != 2) {
      return Status::Error(where + " (\"" + name + "\"): a point needs \"points\": [[x, y]]");
    }
    const double x = JsonNumberOrNaN((*pts)[0][0]), y = JsonNumberOrNaN((*pts)[0][1]);
    if (!std::isfinite(x) || !std::isfinite(y)) {
      return Status::Error(where + " (\"" + name + "\"): NaN or non-numeric coordinates");
    }
    if (!seen.insert(name).second) {
      return Status::Error(source + ": label \"" + name + "\" is used by more than one point");
    }
    a.points.push_back({name, Eigen::Vector2d(x + shift, y + shift)});
  }
  return a;
}

StatusOr<LabelmeAnnotation> ReadLabelme(const std::string& path, PixelOrigin file_origin) {
  ARCO_ASSIGN_OR_RETURN(std::string text, ReadFileToString(path));
  return ParseLabelme(text, path, file_origin);
}

}  // namespace arco
