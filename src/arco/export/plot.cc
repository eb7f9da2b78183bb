#include "arco/export/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "arco/export/export.h"
#include "arco/media/video_writer.h"
#include "arco/pipeline/result_folder.h"
#include "arco/refine/contact_annotation.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/synth/truth_folder.h"
#include "arco/util/file_io.h"
#include "arco/util/stats.h"

namespace arco::exporter {
namespace {

constexpr PlotRgb kBlack = {0, 0, 0};
constexpr PlotRgb kGrid = {225, 225, 225};
constexpr PlotRgb kAxis = {90, 90, 90};
constexpr PlotRgb kPitchRgb = {40, 40, 40};
// One colour per string (1 = the highest), and per error series.
constexpr PlotRgb kSeries[] = {
    {31, 119, 180}, {255, 127, 14}, {44, 160, 44}, {214, 39, 40}, {148, 103, 189}, {140, 86, 75}};
constexpr double kFontPx = 14;

std::string Num(double v, const char* fmt = "%.6g") {
  char buf[64];
  std::snprintf(buf, sizeof(buf), fmt, v);
  return buf;
}

// A linear plot area: values [x_min, x_max] x [y_min, y_max] onto a pixel rectangle.
struct Axes {
  double left = 0, top = 0, width = 0, height = 0;  // px
  double x_min = 0, x_max = 1, y_min = 0, y_max = 1;
  double X(double x) const { return left + (x - x_min) / (x_max - x_min) * width; }
  double Y(double y) const { return top + height - (y - y_min) / (y_max - y_min) * height; }
};

PlotShape Line(std::vector<Eigen::Vector2d> points, const PlotRgb& rgb, double width) {
  PlotShape s;
  s.kind = PlotShape::Kind::kPolyline;
  s.points = std::move(points);
  s.stroke = rgb;
  s.size = width;
  return s;
}

PlotShape Label(const std::string& text, Eigen::Vector2d at, int align, double px = kFontPx) {
  PlotShape s;
  s.kind = PlotShape::Kind::kText;
  s.points = {at};
  s.text = text;
  s.align = align;
  s.size = px;
  s.stroke = kBlack;
  return s;
}

// Ticks at 1, 2 or 5 x 10^k spacing, about `count` of them.
std::vector<double> Ticks(double lo, double hi, int count) {
  const double raw = (hi - lo) / std::max(1, count);
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  double step = p;
  for (const double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * p >= raw) {
      step = m * p;
      break;
    }
  }
  std::vector<double> t;
  for (double v = std::ceil(lo / step) * step; v <= hi + 1e-9 * step; v += step) {
    t.push_back(std::abs(v) < 1e-9 * step ? 0.0 : v);  // no "-0"
  }
  return t;
}

// The frame, grid and labels of an area; y ticks given (value, label).
void AddAxes(PlotScene& scene,
             const Axes& a,
             const std::string& title,
             const std::string& x_label,
             const std::string& y_label,
             const std::vector<std::pair<double, std::string>>& y_ticks) {
  for (const double x : Ticks(a.x_min, a.x_max, 10)) {
    scene.shapes.push_back(Line({{a.X(x), a.top}, {a.X(x), a.top + a.height}}, kGrid, 1));
    scene.shapes.push_back(Label(Num(x), {a.X(x), a.top + a.height + 18}, 0));
  }
  for (const auto& [y, text] : y_ticks) {
    scene.shapes.push_back(Line({{a.left, a.Y(y)}, {a.left + a.width, a.Y(y)}}, kGrid, 1));
    scene.shapes.push_back(Label(text, {a.left - 6, a.Y(y) + 5}, 1));
  }
  PlotShape frame;
  frame.kind = PlotShape::Kind::kRect;
  frame.points = {{a.left, a.top}, {a.left + a.width, a.top + a.height}};
  frame.stroke = kAxis;
  frame.css_class = "plot-area";
  frame.data = {{"x-min", Num(a.x_min, "%.17g")},
                {"x-max", Num(a.x_max, "%.17g")},
                {"y-min", Num(a.y_min, "%.17g")},
                {"y-max", Num(a.y_max, "%.17g")}};
  scene.shapes.push_back(frame);
  scene.shapes.push_back(Label(title, {a.left, a.top - 12}, -1, 18));
  scene.shapes.push_back(Label(x_label, {a.left + a.width / 2, a.top + a.height + 40}, 0));
  scene.shapes.push_back(Label(y_label, {8, a.top - 12}, -1));
}

Axes MakeAxes(const PlotOptions& o) {
  Axes a;
  a.left = 80;
  a.top = 50;
  a.width = o.width - 110;
  a.height = o.height - 110;
  return a;
}

std::string NoteLabel(const refine::NoteFingering& n) {
  const std::string name = refine::MidiNoteName(n.midi_note);
  if (n.state == "pressed") {
    return name + " s" + std::to_string(n.string) + " f" + std::to_string(n.finger);
  }
  if (n.state == "open") return name + " s" + std::to_string(n.string) + " open";
  return name + " ?";
}

std::vector<std::pair<std::string, std::string>> NoteData(const refine::NoteFingering& n) {
  return {{"name", refine::MidiNoteName(n.midi_note)},
          {"state", n.state},
          {"string", std::to_string(n.string)},
          {"finger", std::to_string(n.finger)},
          {"onset-s", Num(n.onset_s, "%.17g")},
          {"duration-s", Num(n.duration_s, "%.17g")},
          {"midi", std::to_string(n.midi_note)},
          {"cents", Num(n.cents_off, "%.3f")},
          {"from-nut-mm", Num(n.from_nut_mm, "%.17g")}};
}

PlotRgb StringRgb(int string) { return kSeries[std::max(0, string - 1) % 6]; }

double Midi(double f0_hz, double a4_hz) { return 69 + 12 * std::log2(f0_hz / a4_hz); }

PlotScene PitchPlot(const PlotOptions& o,
                    const std::vector<audio::PitchFrame>& pitch,
                    const std::vector<refine::NoteFingering>& notes,
                    double a4_hz,
                    double duration_s) {
  PlotScene scene{"pitch", o.width, o.height, {}};
  Axes a = MakeAxes(o);
  double lo = 1e9, hi = -1e9;
  for (const auto& f : pitch) {
    if (f.voiced && f.f0_hz > 0) {
      lo = std::min(lo, Midi(f.f0_hz, a4_hz));
      hi = std::max(hi, Midi(f.f0_hz, a4_hz));
    }
  }
  for (const auto& n : notes) {
    lo = std::min(lo, n.midi_note - 0.5);
    hi = std::max(hi, n.midi_note + 0.5);
  }
  if (lo > hi) lo = 48, hi = 72;
  a.y_min = std::floor(lo) - 1;
  a.y_max = std::ceil(hi) + 2;  // room for the labels above the highest note
  a.x_min = 0;
  a.x_max = std::max(duration_s, 1e-3);
  std::vector<std::pair<double, std::string>> y_ticks;
  const int step = a.y_max - a.y_min > 30 ? 2 : 1;
  for (int m = static_cast<int>(a.y_min); m <= a.y_max; m += step) {
    y_ticks.push_back({m, refine::MidiNoteName(m)});
  }
  AddAxes(scene, a, "Pitch and notes (" + o.method + ")", "time (s)", "note", y_ticks);
  // The pitch track, broken at unvoiced frames.
  std::vector<Eigen::Vector2d> run;
  auto flush = [&] {
    if (run.size() >= 2) scene.shapes.push_back(Line(run, kPitchRgb, 1.5));
    run.clear();
  };
  for (const auto& f : pitch) {
    const double m = f.voiced && f.f0_hz > 0 ? Midi(f.f0_hz, a4_hz) : NAN;
    if (!std::isfinite(m) || m < a.y_min || m > a.y_max || f.time_s > a.x_max) {
      flush();
      continue;
    }
    run.push_back({a.X(f.time_s), a.Y(m)});
  }
  flush();
  for (const auto& n : notes) {
    PlotShape r;
    r.kind = PlotShape::Kind::kRect;
    r.points = {{a.X(n.onset_s), a.Y(n.midi_note + 0.35)},
                {a.X(n.onset_s + n.duration_s), a.Y(n.midi_note - 0.35)}};
    r.stroke = StringRgb(n.string);
    r.filled = true;
    r.fill = StringRgb(n.string);
    r.outlined = false;
    r.css_class = "note";
    r.data = NoteData(n);
    scene.shapes.push_back(r);
    scene.shapes.push_back(
        Label(NoteLabel(n), {a.X(n.onset_s), a.Y(n.midi_note + 0.35) - 4}, -1, 12));
  }
  return scene;
}

PlotScene FingerboardPlot(const PlotOptions& o,
                          const std::vector<refine::NoteFingering>& notes,
                          int strings,
                          double string_length_mm) {
  PlotScene scene{"fingerboard", o.width, o.height, {}};
  Axes a = MakeAxes(o);
  a.x_min = -30;  // room for the open strings left of the nut
  a.x_max = string_length_mm;
  a.y_min = strings + 0.5;  // string 1 (the highest) at the top
  a.y_max = 0.5;
  std::vector<std::pair<double, std::string>> y_ticks;
  for (int s = 1; s <= strings; ++s) y_ticks.push_back({s, "string " + std::to_string(s)});
  AddAxes(
      scene, a, "Where each note was played (" + o.method + ")", "from the nut (mm)", "", y_ticks);
  for (int s = 1; s <= strings; ++s) {
    scene.shapes.push_back(Line({{a.X(0), a.Y(s)}, {a.X(a.x_max), a.Y(s)}}, kAxis, 2));
  }
  scene.shapes.push_back(Line({{a.X(0), a.top}, {a.X(0), a.top + a.height}}, kBlack, 4));  // nut
  for (const auto& n : notes) {
    const bool pressed = n.state == "pressed" && std::isfinite(n.from_nut_mm);
    const bool open = n.state == "open";
    if ((!pressed && !open) || n.string < 1 || n.string > strings) continue;
    const double x = pressed ? n.from_nut_mm : -15;
    PlotShape c;
    c.kind = PlotShape::Kind::kCircle;
    c.points = {{a.X(x), a.Y(n.string)}};
    c.size = 9;
    c.stroke = StringRgb(n.string);
    c.filled = pressed;
    c.fill = StringRgb(n.string);
    c.size = 9;
    c.css_class = "note";
    c.data = NoteData(n);
    scene.shapes.push_back(c);
    scene.shapes.push_back(
        Label(pressed ? std::to_string(n.finger) : "0", {a.X(x), a.Y(n.string) + 5}, 0, 12));
    scene.shapes.push_back(
        Label(refine::MidiNoteName(n.midi_note), {a.X(x), a.Y(n.string) - 14}, 0, 12));
  }
  return scene;
}

struct ErrorSeries {
  std::string name;
  std::vector<double> error_mm;  // per frame, NaN where none
};

PlotScene ErrorPlot(const PlotOptions& o, const std::vector<ErrorSeries>& series, double fps) {
  PlotScene scene{"errors", o.width, o.height, {}};
  Axes a = MakeAxes(o);
  double hi = 1;
  size_t frames = 1;
  for (const auto& s : series) {
    frames = std::max(frames, s.error_mm.size());
    for (const double e : s.error_mm) {
      if (std::isfinite(e)) hi = std::max(hi, e);
    }
  }
  a.x_min = 0;
  a.x_max = std::max(1.0, static_cast<double>(frames - 1)) / fps;
  a.y_min = 0;
  a.y_max = hi * 1.1;
  std::vector<std::pair<double, std::string>> y_ticks;
  for (const double y : Ticks(a.y_min, a.y_max, 8)) y_ticks.push_back({y, Num(y)});
  AddAxes(scene,
          a,
          "Per-frame error against the truth (median over the joints)",
          "time (s)",
          "mm",
          y_ticks);
  for (size_t i = 0; i < series.size(); ++i) {
    const PlotRgb rgb = kSeries[i % 6];
    std::vector<Eigen::Vector2d> run;
    auto flush = [&] {
      if (run.size() >= 2) {
        PlotShape l = Line(run, rgb, 1.5);
        l.css_class = "series";
        l.data = {{"name", series[i].name}};
        scene.shapes.push_back(l);
      }
      run.clear();
    };
    for (size_t f = 0; f < series[i].error_mm.size(); ++f) {
      const double e = series[i].error_mm[f];
      if (!std::isfinite(e)) {
        flush();
        continue;
      }
      run.push_back({a.X(f / fps), a.Y(e)});
    }
    flush();
    const double y = a.top + 20 + 20 * i;
    scene.shapes.push_back(
        Line({{a.left + a.width - 230, y - 5}, {a.left + a.width - 200, y - 5}}, rgb, 3));
    scene.shapes.push_back(Label(series[i].name, {a.left + a.width - 190, y}, -1));
  }
  return scene;
}

// Median over `names` of |points - truth| per frame (names absent in either are skipped).
std::vector<double> FrameErrors(const NpyArray<double>& points,
                                const std::vector<std::string>& point_names,
                                const NpyArray<double>& truth,
                                const std::vector<std::string>& truth_names,
                                const std::vector<std::string>& names) {
  std::vector<std::pair<int, int>> pairs;
  for (const auto& n : names) {
    const auto p = std::find(point_names.begin(), point_names.end(), n);
    const auto t = std::find(truth_names.begin(), truth_names.end(), n);
    if (p != point_names.end() && t != truth_names.end()) {
      pairs.push_back(
          {static_cast<int>(p - point_names.begin()), static_cast<int>(t - truth_names.begin())});
    }
  }
  const int64_t frames = std::min(points.shape[0], truth.shape[0]);
  std::vector<double> out(frames, NAN);
  std::vector<double> e;
  for (int64_t f = 0; f < frames; ++f) {
    e.clear();
    for (const auto& [p, t] : pairs) {
      const Eigen::Vector3d d = pipeline::PointAt(points, f, p) - pipeline::PointAt(truth, f, t);
      if (d.allFinite()) e.push_back(d.norm());
    }
    if (!e.empty()) out[f] = Median(e);
  }
  return out;
}

}  // namespace

Status PlotOptions::Validate() const {
  if (result_dir.empty()) return Status::Error("result_dir is empty");
  bool known = false;
  for (const auto& m : ExportMethodNames()) known = known || m == method;
  if (!known) return Status::Error("method: '" + method + "' is not arco, paper or vision");
  if (width < 400 || width > 8000 || height < 300 || height > 8000) {
    return Status::Error("width and height must be in [400, 8000] x [300, 8000] px");
  }
  return Status::Ok();
}

StatusOr<std::vector<PlotScene>> BuildPlots(const PlotOptions& o) {
  ARCO_RETURN_IF_ERROR(o.Validate());
  ExportOptions export_options;
  export_options.result_dir = o.result_dir;
  export_options.method = o.method;
  ARCO_ASSIGN_OR_RETURN(const ExportData data, LoadExportData(export_options));
  const pipeline::ResultFolder folder(o.result_dir);
  ARCO_ASSIGN_OR_RETURN(const auto notes, folder.ReadFingering(o.method));
  if (notes.empty()) {
    return Status::Error(folder.FingeringPath(o.method) + ": no notes (" + o.method +
                         " has no fingering: plot arco or paper)");
  }
  ARCO_ASSIGN_OR_RETURN(const auto pitch, folder.ReadPitch());
  double a4_hz = 440, string_length_mm = 0;
  int strings = 0;
  if (!data.strings_mm.shape.empty()) {
    const auto& s = data.strings_mm;
    strings = static_cast<int>(s.shape[1]);
    std::vector<double> lengths;
    for (int64_t f = 0; f < s.shape[0]; ++f) {
      for (int64_t i = 0; i < s.shape[1]; ++i) {
        const Eigen::Vector3d nut(s.at(f, i, 0, 0), s.at(f, i, 0, 1), s.at(f, i, 0, 2));
        const Eigen::Vector3d bridge(s.at(f, i, 1, 0), s.at(f, i, 1, 1), s.at(f, i, 1, 2));
        if ((bridge - nut).allFinite()) lengths.push_back((bridge - nut).norm());
      }
    }
    if (!lengths.empty()) string_length_mm = Median(lengths);
    ARCO_ASSIGN_OR_RETURN(const pipeline::InstrumentRecord inst, folder.ReadInstrument());
    a4_hz = inst.a4_hz;
  }
  for (const auto& n : notes) {
    strings = std::max(strings, n.string);
    if (std::isfinite(n.from_nut_mm))
      string_length_mm = std::max(string_length_mm, n.from_nut_mm + 50);
  }
  if (string_length_mm <= 0) string_length_mm = 700;
  const double duration_s = static_cast<double>(data.frames()) / data.fps;
  std::vector<PlotScene> scenes;
  scenes.push_back(PitchPlot(o, pitch, notes, a4_hz, duration_s));
  scenes.push_back(FingerboardPlot(o, notes, std::max(strings, 1), string_length_mm));

  // The error plot, when the capture has a synthetic truth.
  ARCO_ASSIGN_OR_RETURN(const pipeline::ResultHeader header, folder.ReadHeader());
  const std::string truth_dir = JoinPath(header.capture_dir, synth::kTruthFolderName);
  if (!header.capture_dir.empty() && FileExists(synth::TruthManifestPath(truth_dir))) {
    ARCO_ASSIGN_OR_RETURN(const synth::TruthFolder truth, synth::ReadTruthFolder(truth_dir));
    const KeypointLayout* truth_layout = FindKeypointLayout(truth.manifest.truth_layout);
    if (truth_layout == nullptr) {
      return Status::Error(synth::TruthManifestPath(truth_dir) + ": unknown truth_layout '" +
                           truth.manifest.truth_layout + "'");
    }
    std::vector<std::string> left_hand, body;
    for (const auto& n : truth_layout->names) {
      if (n.rfind("left_hand_", 0) == 0) left_hand.push_back(n);
    }
    for (int k = 0; k < 17; ++k) body.push_back(truth_layout->names[k]);  // COCO body
    std::vector<ErrorSeries> series;
    ARCO_ASSIGN_OR_RETURN(const auto stages, folder.PointStages());
    for (const auto& stage : stages) {
      ARCO_ASSIGN_OR_RETURN(const auto points, folder.ReadPoints3d(stage.name));
      const std::vector<std::string>& names =
          stage.keypoint_names.empty() ? header.keypoint_names : stage.keypoint_names;
      if (points.shape.size() != 3 || points.shape[1] != static_cast<int64_t>(names.size())) {
        continue;
      }
      const bool triangulation = stage.name == pipeline::kTriangulationStage;
      // The triangulation is in world units; the methods in mm.
      if (triangulation) continue;
      series.push_back(
          {stage.name + " left hand",
           FrameErrors(points, names, truth.points3d, truth_layout->names, left_hand)});
      if (stage.name == o.method) {
        series.push_back({stage.name + " body",
                          FrameErrors(points, names, truth.points3d, truth_layout->names, body)});
      }
    }
    if (!series.empty()) scenes.push_back(ErrorPlot(o, series, data.fps));
  }
  return scenes;
}

StatusOr<PlotSummary> WritePlots(const PlotOptions& options, const std::string& dir) {
  ARCO_ASSIGN_OR_RETURN(const std::vector<PlotScene> scenes, BuildPlots(options));
  PlotSummary summary;
  for (const PlotScene& scene : scenes) {
    ARCO_RETURN_IF_ERROR(AtomicWriteFile(JoinPath(dir, scene.name + ".svg"), PlotSvg(scene)));
    ARCO_RETURN_IF_ERROR(
        media::WriteImageFile(JoinPath(dir, scene.name + ".png"), RasterisePlot(scene)));
    summary.files.push_back(scene.name + ".svg");
    summary.files.push_back(scene.name + ".png");
    if (scene.name == "errors") summary.errors = true;
    if (scene.name == "pitch") {
      for (const auto& s : scene.shapes) summary.notes += s.css_class == "note";
    }
  }
  return summary;
}

}  // namespace arco::exporter
