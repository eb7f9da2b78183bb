#include "arco/mocap/spd_import.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "arco/registry/instruments.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/util/file_io.h"
#include "arco/util/json_io.h"

namespace arco {
namespace {

constexpr int kBodyPoints = wholebody::kNumPoints;

// The instrument's points in its SPD layout (registry): cello 9, violin 7.
int InstrumentPoints(const std::string& instrument) {
  const KeypointLayout* layout =
      FindKeypointLayout(GetInstrumentInfo(*ParseInstrumentKind(instrument)).spd_layout);
  return layout->size() - kBodyPoints;
}

std::string FramePath(const std::string& dir, const std::string& serial, int64_t number) {
  return JoinPath(JoinPath(dir, serial), std::to_string(number) + ".json");
}

int64_t FileNumber(const std::vector<int64_t>* drops, int64_t global, bool* dropped) {
  *dropped = false;
  if (!drops) return global;
  const auto it = std::lower_bound(drops->begin(), drops->end(), global);
  *dropped = it != drops->end() && *it == global;
  return global - (it - drops->begin());
}

std::string FormatNumber(double v) {
  if (std::isnan(v)) return "NaN";
  if (std::isinf(v)) return v > 0 ? "Infinity" : "-Infinity";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  return buf;
}

}  // namespace

StatusOr<std::vector<Eigen::Vector3d>> ParseSpdFrame(const std::string& text,
                                                     const std::string& source) {
  ARCO_ASSIGN_OR_RETURN(Json j, ParseJsonLenient(text, source));
  if (!j.is_array()) return Status::Error(source + ": expected an array of [x, y, score] rows");
  std::vector<Eigen::Vector3d> rows;
  rows.reserve(j.size());
  for (size_t i = 0; i < j.size(); ++i) {
    const Json& r = j[i];
    if (!r.is_array() || r.size() != 3) {
      return Status::Error(source + ": row " + std::to_string(i) + " is not [x, y, score]");
    }
    Eigen::Vector3d v;
    for (int k = 0; k < 3; ++k) {
      if (!r[k].is_number() && !r[k].is_null()) {
        return Status::Error(source + ": row " + std::to_string(i) + " holds a non-number");
      }
      v[k] = JsonNumberOrNaN(r[k]);
    }
    rows.push_back(v);
  }
  return rows;
}

StatusOr<SpdSummary> ParseSpdSummary(const std::string& text, const std::string& source) {
  ARCO_ASSIGN_OR_RETURN(Json j, ParseJsonLenient(text, source));
  if (!j.is_object()) return Status::Error(source + ": an SPD summary must be a JSON object");
  SpdSummary s;
  for (const auto& [key, out] : {std::pair<const char*, int64_t*>{"StartFrame", &s.start_frame},
                                 {"EndFrame", &s.end_frame}}) {
    const auto it = j.find(key);
    if (it == j.end() || it->is_null()) continue;
    if (!it->is_number_integer()) {
      return Status::Error(source + ": \"" + key + "\" must be an integer");
    }
    *out = it->get<int64_t>();
  }
  const auto log = j.find("FrameDropIDLog");
  if (log != j.end() && !log->is_null()) {
    if (!log->is_object()) {
      return Status::Error(source + ": \"FrameDropIDLog\" must map serials to frame lists");
    }
    for (const auto& [serial, frames] : log->items()) {
      auto& drops = s.frame_drops[serial];
      if (frames.is_null()) continue;
      if (!frames.is_array()) {
        return Status::Error(source + ": FrameDropIDLog[\"" + serial + "\"] must be a list");
      }
      for (const Json& f : frames) {
        if (!f.is_number_integer()) {
          return Status::Error(source + ": FrameDropIDLog[\"" + serial + "\"] holds a non-integer");
        }
        drops.push_back(f.get<int64_t>());
      }
      std::sort(drops.begin(), drops.end());
      drops.erase(std::unique(drops.begin(), drops.end()), drops.end());
    }
  }
  return s;
}

StatusOr<SpdSummary> ReadSpdSummary(const std::string& path) {
  ARCO_ASSIGN_OR_RETURN(std::string text, ReadFileToString(path));
  return ParseSpdSummary(text, path);
}

Status SpdImportOptions::Validate() const {
  if (instrument != "cello" && instrument != "violin") {
    return Status::Error("SPD import: instrument must be cello or violin");
  }
  if (human_dir.empty()) return Status::Error("SPD import: the human keypoint folder is required");
  if (serials.empty()) return Status::Error("SPD import: no camera serials given");
  if (frame_last < frame_first) return Status::Error("SPD import: frame_last < frame_first");
  if (frame_last - frame_first >= 10000000) return Status::Error("SPD import: too many frames");
  return Status::Ok();
}

StatusOr<NpyArray<double>> ImportSpdKeypoints(const SpdImportOptions& o, SpdImportReport* report) {
  ARCO_RETURN_IF_ERROR(o.Validate());
  const int64_t instrument_points = InstrumentPoints(o.instrument);
  const int64_t points = kBodyPoints + instrument_points;
  const int64_t frames = o.frame_last - o.frame_first + 1;
  const int64_t views = static_cast<int64_t>(o.serials.size());
  NpyArray<double> out;
  out.shape = {frames, views, points, 3};
  out.data.assign(static_cast<size_t>(frames * views * points * 3),
                  std::numeric_limits<double>::quiet_NaN());
  SpdImportReport r;
  auto read_rows = [&](const std::string& path,
                       bool* missing) -> StatusOr<std::vector<Eigen::Vector3d>> {
    *missing = !FileExists(path);
    if (*missing) {
      if (o.require_all_files) return Status::Error(path + ": missing SPD keypoint file");
      ++r.files_missing;
      return std::vector<Eigen::Vector3d>();
    }
    ++r.files_read;
    ARCO_ASSIGN_OR_RETURN(std::string text, ReadFileToString(path));
    return ParseSpdFrame(text, path);
  };
  for (int64_t v = 0; v < views; ++v) {
    const std::string& serial = o.serials[v];
    const auto drops_it = o.frame_drops.find(serial);
    const std::vector<int64_t>* drops =
        drops_it == o.frame_drops.end() ? nullptr : &drops_it->second;
    for (int64_t f = 0; f < frames; ++f) {
      bool dropped = false;
      const int64_t number = FileNumber(drops, o.frame_first + f, &dropped);
      if (dropped) {
        ++r.frames_dropped;
        continue;
      }
      bool missing = false;
      const std::string human_path = FramePath(o.human_dir, serial, number);
      ARCO_ASSIGN_OR_RETURN(auto human, read_rows(human_path, &missing));
      if (!missing && human.size() != static_cast<size_t>(kBodyPoints) &&
          human.size() != static_cast<size_t>(points)) {
        return Status::Error(human_path + ": " + std::to_string(human.size()) + " rows; expected " +
                             std::to_string(kBodyPoints) + " or " + std::to_string(points));
      }
      for (size_t p = 0; p < human.size(); ++p) {
        for (int k = 0; k < 3; ++k) out.at(f, v, static_cast<int64_t>(p), k) = human[p][k];
      }
      if (o.instrument_dir.empty()) continue;
      const std::string inst_path = FramePath(o.instrument_dir, serial, number);
      ARCO_ASSIGN_OR_RETURN(auto inst, read_rows(inst_path, &missing));
      if (!missing && inst.size() != static_cast<size_t>(instrument_points)) {
        return Status::Error(inst_path + ": " + std::to_string(inst.size()) + " rows; expected " +
                             std::to_string(instrument_points) + " " + o.instrument + " points");
      }
      for (size_t p = 0; p < inst.size(); ++p) {
        for (int k = 0; k < 3; ++k)
          out.at(f, v, kBodyPoints + static_cast<int64_t>(p), k) = inst[p][k];
      }
    }
  }
  if (report) *report = r;
  return out;
}

Status ExportSpdKeypoints(const SpdImportOptions& o, const NpyArray<double>& k) {
  ARCO_RETURN_IF_ERROR(o.Validate());
  const int64_t instrument_points = InstrumentPoints(o.instrument);
  const int64_t points = kBodyPoints + instrument_points;
  const int64_t frames = o.frame_last - o.frame_first + 1;
  const int64_t views = static_cast<int64_t>(o.serials.size());
  if (k.shape != std::vector<int64_t>{frames, views, points, 3}) {
    return Status::Error("SPD export: keypoints must have shape (frames, serials, " +
                         std::to_string(points) + ", 3)");
  }
  auto write_rows = [&](const std::string& path, int64_t f, int64_t v, int64_t begin, int64_t end) {
    std::string text = "[";
    for (int64_t p = begin; p < end; ++p) {
      text += (p > begin ? ", [" : "[") + FormatNumber(k.at(f, v, p, 0)) + ", " +
              FormatNumber(k.at(f, v, p, 1)) + ", " + FormatNumber(k.at(f, v, p, 2)) + "]";
    }
    return AtomicWriteFile(path, text + "]");
  };
  for (int64_t v = 0; v < views; ++v) {
    const std::string& serial = o.serials[v];
    const auto drops_it = o.frame_drops.find(serial);
    const std::vector<int64_t>* drops =
        drops_it == o.frame_drops.end() ? nullptr : &drops_it->second;
    ARCO_RETURN_IF_ERROR(MakeDirectories(JoinPath(o.human_dir, serial)));
    if (!o.instrument_dir.empty()) {
      ARCO_RETURN_IF_ERROR(MakeDirectories(JoinPath(o.instrument_dir, serial)));
    }
    for (int64_t f = 0; f < frames; ++f) {
      bool dropped = false;
      const int64_t number = FileNumber(drops, o.frame_first + f, &dropped);
      if (dropped) continue;
      if (o.instrument_dir.empty()) {
        ARCO_RETURN_IF_ERROR(write_rows(FramePath(o.human_dir, serial, number), f, v, 0, points));
        continue;
      }
      ARCO_RETURN_IF_ERROR(
          write_rows(FramePath(o.human_dir, serial, number), f, v, 0, kBodyPoints));
      ARCO_RETURN_IF_ERROR(
          write_rows(FramePath(o.instrument_dir, serial, number), f, v, kBodyPoints, points));
    }
  }
  return Status::Ok();
}

}  // namespace arco
