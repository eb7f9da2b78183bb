#include "arco/mocap/detections.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "arco/util/file_io.h"

namespace arco {

double DetectedPerson::BoxArea() const {
  if (box.allFinite()) {
    return std::max(0.0, box[2] - box[0]) * std::max(0.0, box[3] - box[1]);
  }
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  for (const Eigen::Vector3d& p : keypoints) {
    if (!p.allFinite() || !(p.z() > 0)) continue;
    x0 = std::min(x0, p.x());
    y0 = std::min(y0, p.y());
    x1 = std::max(x1, p.x());
    y1 = std::max(y1, p.y());
  }
  if (!(x1 >= x0)) return 0;
  return (x1 - x0) * (y1 - y0);
}

int SelectPerson(const DetectedFrame& frame) {
  int best = -1;
  double best_area = -1;
  for (size_t i = 0; i < frame.people.size(); ++i) {
    const double area = frame.people[i].BoxArea();
    if (area > best_area) {
      best = static_cast<int>(i);
      best_area = area;
    }
  }
  return best;
}

double ClampScore(double score, int64_t* clamped) {
  if (std::isnan(score)) return score;
  if (score >= 0 && score <= 1) return score;
  ++*clamped;
  return score < 0 ? 0.0 : 1.0;
}

StatusOr<std::vector<std::string>> ListFrameFiles(const std::string& dir,
                                                  const std::string& suffix) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return Status::Error(dir + ": not a folder");
  std::vector<std::string> names;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() > suffix.size() &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0 &&
        it->is_regular_file(ec)) {
      names.push_back(name);
    }
  }
  if (ec) return Status::Error(dir + ": cannot list the folder (" + ec.message() + ")");
  if (names.empty()) return Status::Error(dir + ": no *" + suffix + " files");
  std::sort(names.begin(), names.end(), NaturalLess);
  std::vector<std::string> paths;
  for (const std::string& name : names) paths.push_back(JoinPath(dir, name));
  return paths;
}

}  // namespace arco
