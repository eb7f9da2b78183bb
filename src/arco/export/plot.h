// `arco plot`: a result's figures (docs/export.md, "Plots"), each built once as a scene
// description (PlotScene: lines, rectangles, circles, text in pixels) and written by two
// writers, SVG text (PlotSvg) and a PNG raster drawn with OpenCV (RasterisePlot), so the
// two files always show the same figure.
//
//   pitch.svg/.png        the tracked pitch over time (semitones, from pitch.csv) with the
//                         method's notes (fingering.csv): one mark per note spanning its
//                         onset and duration at its MIDI note, labelled with its name,
//                         string and finger
//   fingerboard.svg/.png  where every note was played: one mark per pressed note at its
//                         distance from the nut on its string, open strings at the nut
//   errors.svg/.png       (only when the capture has a synthetic truth folder) the
//                         per-frame error of each method's left hand and the
//                         triangulated body against the truth (median over the joints)
//
// SVG marks carry their data for readers: each note is <rect class="note"> (pitch) or
// <circle class="note"> (fingerboard) with data-name, data-string, data-finger and
// data-onset-s, data-midi or data-from-nut-mm; each plot area is <rect class="plot-area">
// with data-x-min/max and data-y-min/max, its values at its left/right and bottom/top
// edges (linear axes), so a mark's position maps back to its value.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "arco/media/image.h"
#include "arco/util/status.h"

namespace arco::exporter {

using PlotRgb = std::array<uint8_t, 3>;

struct PlotShape {
  enum class Kind { kPolyline, kRect, kCircle, kText };
  Kind kind = Kind::kPolyline;
  // Polyline: its vertices; rect: two opposite corners; circle and text: one point (text:
  // the baseline's anchor). Pixels, y down, origin at the top-left corner.
  std::vector<Eigen::Vector2d> points;
  double size = 1;  // polyline and outline width; circle radius; text height (px)
  PlotRgb stroke = {0, 0, 0};
  bool filled = false;
  PlotRgb fill = {255, 255, 255};
  bool outlined = true;  // rect and circle: draw the outline
  std::string text;
  int align = -1;                                         // text: -1 start, 0 middle, 1 end
  std::string css_class;                                  // SVG class ("" none)
  std::vector<std::pair<std::string, std::string>> data;  // SVG data-* attributes
};

struct PlotScene {
  std::string name;  // file stem: "pitch", "fingerboard", "errors"
  int width = 0, height = 0;
  std::vector<PlotShape> shapes;
};

std::string PlotSvg(const PlotScene& scene);
media::Image RasterisePlot(const PlotScene& scene);  // RGB8, width x height

struct PlotOptions {
  std::string result_dir;
  std::string method = "arco";     // whose fingering is plotted
  int width = 1200, height = 600;  // px of each figure
  Status Validate() const;
};

// The figures of a result. Errors (naming the file): no result, a method without
// fingering, no pitch.csv.
StatusOr<std::vector<PlotScene>> BuildPlots(const PlotOptions& options);

struct PlotSummary {
  std::vector<std::string> files;  // names written into the folder
  int notes = 0;
  bool errors = false;  // a truth folder was found and the error plot drawn
};
// Builds the figures and writes NAME.svg and NAME.png of each into `dir` (an existing,
// empty folder: a caller wanting an atomic output passes an OutputSet temporary).
StatusOr<PlotSummary> WritePlots(const PlotOptions& options, const std::string& dir);

}  // namespace arco::exporter
