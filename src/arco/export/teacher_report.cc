#include "arco/export/teacher_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <vector>

#include "arco/export/export.h"
#include "arco/export/plot.h"
#include "arco/instrument/instrument_model.h"
#include "arco/pipeline/result_folder.h"
#include "arco/refine/bowing.h"
#include "arco/refine/contact_annotation.h"
#include "arco/util/file_io.h"
#include "arco/util/stats.h"

namespace arco::exporter {
namespace {

constexpr double kMaxPassageS = 10.0;

std::string Html(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string Num(double v, const char* fmt) {
  if (!std::isfinite(v)) return "&ndash;";
  char buf[64];
  std::snprintf(buf, sizeof(buf), fmt, v);
  return buf;
}

std::string Clock(double s) {
  char buf[32];
  const int m = static_cast<int>(s / 60);
  std::snprintf(buf, sizeof(buf), "%d:%05.2f", m, s - 60 * m);
  return buf;
}

const char* FingerName(int finger) {
  static const char* kNames[] = {"open", "1", "2", "3", "4"};
  return finger >= 0 && finger <= 4 ? kNames[finger] : "?";
}

// Least-squares slope of y over x (NaN with fewer than two distinct x).
double Slope(const std::vector<std::pair<double, double>>& xy) {
  double intercept = 0, slope = NAN;
  return FitLine(xy, &intercept, &slope) ? slope : NAN;
}

// The median of the finite values (NaN when there are none).
double FiniteMedian(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }),
          v.end());
  return v.empty() ? NAN : Median(std::move(v));
}

struct Row {
  const refine::NoteFingering* note = nullptr;
  const audio::Note* audio = nullptr;        // its vibrato; null when not found
  const refine::BowingNote* bow = nullptr;   // null without bowing
  const refine::NoteFingering* upper = nullptr;  // a double stop's second voice, or null
  bool shift = false;                        // the hand moved since the previous pressed note
};

const char kStyle[] = R"(
body{font-family:system-ui,sans-serif;margin:2em;color:#222;max-width:1200px}
h1{font-size:1.6em}h2{font-size:1.25em;margin-top:1.6em}
table{border-collapse:collapse;font-size:.9em;margin:.5em 0}
td,th{border-bottom:1px solid #ddd;padding:.25em .6em;text-align:right}
th{background:#f4f4f4}td.name,th.name{text-align:left}
.in-tune{color:#1a7f37}.slightly{color:#9a6700}.off{color:#cf222e;font-weight:600}
.disagree{color:#cf222e;font-weight:600}.shift{background:#fff8c5}
.summary{display:flex;gap:1.5em;flex-wrap:wrap}.summary div{background:#f6f8fa;padding:.6em 1em;border-radius:6px}
.summary b{display:block;font-size:1.3em}figure{margin:1em 0}svg{max-width:100%;height:auto}
)";

}  // namespace

Status TeacherReportOptions::Validate() const {
  if (result_dir.empty()) return Status::Error("result_dir is empty");
  bool known = false;
  for (const auto& m : ExportMethodNames()) known = known || m == method;
  if (!known || method == "vision") {
    return Status::Error("method: '" + method + "' is not arco or paper");
  }
  ARCO_RETURN_IF_ERROR(CheckInRange("passage_gap_s", passage_gap_s, kReportPassageGapRangeS));
  return CheckInRange("in_tune_cents", in_tune_cents, kReportInTuneRangeCents);
}

StatusOr<std::string> BuildTeacherReport(const TeacherReportOptions& options,
                                         TeacherReportSummary* summary) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  const pipeline::ResultFolder result(options.result_dir);
  if (!FileExists(result.ManifestPath())) {
    return Status::Error(result.ManifestPath() + ": not found (not an arco result folder)");
  }
  ARCO_ASSIGN_OR_RETURN(const pipeline::ResultHeader header, result.ReadHeader());
  ARCO_ASSIGN_OR_RETURN(const std::vector<refine::NoteFingering> fingering,
                        result.ReadFingering(options.method));
  if (fingering.empty()) {
    return Status::Error(result.FingeringPath(options.method) +
                         ": no notes (run arco run, or arco refine --mode " + options.method + ")");
  }
  ARCO_ASSIGN_OR_RETURN(const std::vector<refine::NoteFingering> second,
                        result.ReadSecondFingering(options.method));
  ARCO_ASSIGN_OR_RETURN(const std::vector<audio::Note> audio_notes, result.ReadNotes());
  ARCO_ASSIGN_OR_RETURN(const std::vector<refine::BowingNote> bowing,
                        result.ReadBowingNotes(options.method));
  ARCO_ASSIGN_OR_RETURN(const pipeline::InstrumentRecord instrument, result.ReadInstrument());
  InstrumentOptions io;
  ARCO_ASSIGN_OR_RETURN(io.kind, ParseInstrumentKind(instrument.instrument));
  io.tuning.a4_hz = instrument.a4_hz;
  ARCO_ASSIGN_OR_RETURN(const InstrumentModel model, InstrumentModel::Create(io));
  PlotOptions plot_options;
  plot_options.result_dir = options.result_dir;
  plot_options.method = options.method;
  plot_options.width = 1100;
  plot_options.height = 420;
  ARCO_ASSIGN_OR_RETURN(const std::vector<PlotScene> plots, BuildPlots(plot_options));

  std::map<int, const refine::BowingNote*> bow_of;
  for (const refine::BowingNote& b : bowing) bow_of[b.note] = &b;
  std::map<int, const refine::NoteFingering*> upper_of;
  // An uncertain second voice (unplayable with the first, out of the hand's reach) is
  // most often a partial of the first heard as a note: not reported as a double stop.
  for (const refine::NoteFingering& u : second) {
    if (u.state == "pressed" || u.state == "open") upper_of[u.note] = &u;
  }
  std::vector<Row> rows;
  double last_position = NAN;
  for (const refine::NoteFingering& n : fingering) {
    Row r;
    r.note = &n;
    if (n.note >= 0 && n.note < static_cast<int>(audio_notes.size())) {
      r.audio = &audio_notes[static_cast<size_t>(n.note)];
    }
    if (auto it = bow_of.find(n.note); it != bow_of.end()) r.bow = it->second;
    if (auto it = upper_of.find(n.note); it != upper_of.end()) r.upper = it->second;
    if (std::isfinite(n.position_semitones)) {
      r.shift = std::isfinite(last_position) &&
                std::abs(n.position_semitones - last_position) >= 0.75;
      last_position = n.position_semitones;
    }
    rows.push_back(r);
  }
  // Passages: split at silences of passage_gap_s, and after kMaxPassageS of music.
  std::vector<std::pair<size_t, size_t>> passages;  // [first, last) rows
  size_t start = 0;
  for (size_t i = 1; i <= rows.size(); ++i) {
    const bool end = i == rows.size() ||
                     rows[i].note->onset_s - (rows[i - 1].note->onset_s + rows[i - 1].note->duration_s) >=
                         options.passage_gap_s ||
                     rows[i].note->onset_s - rows[start].note->onset_s >= kMaxPassageS;
    if (end) {
      passages.emplace_back(start, i);
      start = i;
    }
  }

  auto tune_class = [&](double cents) {
    const double a = std::abs(cents);
    return a <= options.in_tune_cents ? "in-tune" : a <= 2 * options.in_tune_cents ? "slightly" : "off";
  };
  auto string_name = [&](int s) -> std::string {
    if (s < 1 || s > model.num_strings()) return "&ndash;";
    return Html(model.open_note_name(s));
  };

  // Whole-take figures.
  int in_tune = 0, tuned = 0, vibrato = 0, shifts = 0, disagree = 0, double_stops = 0;
  std::vector<double> abs_cents, rates, widths, sounding;
  for (const Row& r : rows) {
    if (r.note->state == "pressed" || r.note->state == "open") {
      ++tuned;
      in_tune += std::abs(r.note->cents_off) <= options.in_tune_cents;
      abs_cents.push_back(std::abs(r.note->cents_off));
    }
    if (r.audio && r.audio->vibrato_rate_hz > 0) {
      ++vibrato;
      rates.push_back(r.audio->vibrato_rate_hz);
      widths.push_back(r.audio->vibrato_extent_cents);
    }
    shifts += r.shift;
    double_stops += r.upper != nullptr;
    if (r.bow) {
      disagree += !r.bow->strings_agree;
      sounding.push_back(r.bow->sounding_point_mm);
    }
  }

  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
    << "<title>arco report: " << Html(options.result_dir) << "</title><style>" << kStyle
    << "</style></head><body>\n";
  h << "<h1>" << Html(model.name()) << " take: notes, intonation and bowing</h1>\n";
  h << "<p>Result <code>" << Html(options.result_dir) << "</code>, method <b>"
    << Html(options.method) << "</b>; " << header.frame_count << " frames at "
    << Num(header.fps, "%.4g") << " fps (" << Clock(header.frame_count / header.fps)
    << "). Intonation is in cents from equal temperament at A4 = " << Num(io.tuning.a4_hz, "%.5g")
    << " Hz.</p>\n";
  h << "<div class=\"summary\">"
    << "<div><b id=\"notes\">" << rows.size() << "</b>notes</div>"
    << "<div><b>" << in_tune << " of " << tuned << "</b>in tune (&plusmn;"
    << Num(options.in_tune_cents, "%.3g") << " cents)</div>"
    << "<div><b>" << Num(FiniteMedian(abs_cents), "%.1f") << "</b>median cents off</div>"
    << "<div><b>" << vibrato << "</b>notes with vibrato" << (rates.empty() ? "" : ", ")
    << (rates.empty() ? "" : Num(FiniteMedian(rates), "%.1f") + " Hz, &plusmn;" +
                                 Num(FiniteMedian(widths), "%.0f") + " cents")
    << "</div><div><b>" << shifts << "</b>shifts</div>";
  if (double_stops > 0) h << "<div><b>" << double_stops << "</b>double stops</div>";
  if (!bowing.empty()) {
    h << "<div><b>" << Num(FiniteMedian(sounding), "%.0f") << " mm</b>sounding point (median)</div>"
      << "<div><b>" << disagree << "</b>notes bowed on another string</div>";
  }
  h << "</div>\n";

  // Passages.
  int passage_index = 0;
  for (const auto& [first, last] : passages) {
    ++passage_index;
    std::vector<std::pair<double, double>> cents_over_time;
    std::vector<double> p_rates, p_sounding;
    int p_shifts = 0, p_vibrato = 0, p_changes = 0;
    refine::BowDirection previous = refine::BowDirection::kNone;
    for (size_t i = first; i < last; ++i) {
      const Row& r = rows[i];
      if (r.note->state == "pressed" || r.note->state == "open") {
        cents_over_time.emplace_back(r.note->onset_s, r.note->cents_off);
      }
      p_shifts += r.shift;
      if (r.audio && r.audio->vibrato_rate_hz > 0) ++p_vibrato, p_rates.push_back(r.audio->vibrato_rate_hz);
      if (r.bow) {
        p_sounding.push_back(r.bow->sounding_point_mm);
        if (r.bow->direction != refine::BowDirection::kNone) {
          p_changes += previous != refine::BowDirection::kNone && r.bow->direction != previous;
          previous = r.bow->direction;
        }
      }
    }
    std::vector<double> cents;
    for (const auto& [t, c] : cents_over_time) cents.push_back(c);
    const double slope = Slope(cents_over_time);
    const refine::NoteFingering& a = *rows[first].note;
    const refine::NoteFingering& b = *rows[last - 1].note;
    h << "<section class=\"passage\" data-passage=\"" << passage_index << "\"><h2>Passage "
      << passage_index << ": " << Clock(a.onset_s) << "&ndash;" << Clock(b.onset_s + b.duration_s)
      << ", " << (last - first) << " notes</h2>\n<p>";
    h << "Intonation: median " << Num(FiniteMedian(cents), "%+.0f") << " cents";
    if (std::isfinite(slope)) {
      const double drift = slope * (b.onset_s - a.onset_s);
      h << ", " << (std::abs(drift) < options.in_tune_cents ? "steady" : drift > 0 ? "drifting sharp" : "drifting flat")
        << " (" << Num(drift, "%+.0f") << " cents over the passage)";
    }
    h << ". Shifts: " << p_shifts << ". Vibrato on " << p_vibrato << " of " << (last - first)
      << " notes" << (p_rates.empty() ? "" : " (median " + Num(FiniteMedian(p_rates), "%.1f") + " Hz)")
      << ".";
    if (!bowing.empty()) {
      h << " Bow: " << p_changes << " bow change" << (p_changes == 1 ? "" : "s")
        << " between notes, sounding point " << Num(FiniteMedian(p_sounding), "%.0f") << " mm from the bridge.";
    }
    h << "</p>\n<table><tr><th>#</th><th>time</th><th class=\"name\">note</th><th>string</th>"
      << "<th>finger</th><th>position</th><th>cents</th><th>vibrato</th>"
      << "<th class=\"name\">bow</th><th>sounding point</th><th>bow on</th></tr>\n";
    for (size_t i = first; i < last; ++i) {
      const Row& r = rows[i];
      const refine::NoteFingering& n = *r.note;
      // A double stop: both notes, strings, fingers and intonations, lower first.
      const refine::NoteFingering* u = r.upper;
      auto finger = [](const refine::NoteFingering& x) -> std::string {
        return x.state == "pressed" ? FingerName(x.finger) : x.state == "open" ? "open" : "&ndash;";
      };
      h << "<tr class=\"note" << (r.shift ? " shift" : "") << (u ? " double-stop" : "")
        << "\" data-note=\"" << n.note << "\"><td>" << (i + 1) << "</td><td>" << Clock(n.onset_s)
        << "</td><td class=\"name\">" << Html(refine::MidiNoteName(n.midi_note))
        << (u ? " + " + Html(refine::MidiNoteName(u->midi_note)) : "") << "</td><td>"
        << string_name(n.string) << (u ? " + " + string_name(u->string) : "") << "</td><td>"
        << finger(n) << (u ? " + " + finger(*u) : "") << "</td><td>"
        << Num(n.position_semitones, "%.1f") << "</td><td class=\"" << tune_class(n.cents_off)
        << "\">" << Num(n.cents_off, "%+.0f") << (u ? " / " + Num(u->cents_off, "%+.0f") : "")
        << "</td><td>";
      if (r.audio && r.audio->vibrato_rate_hz > 0) {
        h << Num(r.audio->vibrato_rate_hz, "%.1f") << " Hz &plusmn;"
          << Num(r.audio->vibrato_extent_cents, "%.0f") << "&cent;";
      } else {
        h << "&ndash;";
      }
      h << "</td>";
      if (r.bow) {
        h << "<td class=\"name\">" << refine::BowDirectionName(r.bow->direction) << "</td><td>"
          << Num(r.bow->sounding_point_mm, "%.0f") << " mm</td><td"
          << (r.bow->strings_agree ? "" : " class=\"disagree\"") << ">"
          << string_name(r.bow->bow_string)
          << (r.bow->bow_second_string > 0 ? "+" + string_name(r.bow->bow_second_string) : "")
          << "</td>";
      } else {
        h << "<td class=\"name\">&ndash;</td><td>&ndash;</td><td>&ndash;</td>";
      }
      h << "</tr>\n";
    }
    h << "</table></section>\n";
  }

  h << "<h2>Figures</h2>\n";
  for (const PlotScene& scene : plots) {
    if (scene.name == "errors") continue;  // a truth's errors: a developer's figure
    // Inline SVG: the standalone file's XML declaration does not belong inside HTML.
    std::string svg = PlotSvg(scene);
    if (svg.rfind("<?xml", 0) == 0) svg.erase(0, svg.find('\n') + 1);
    h << "<figure class=\"plot\" data-plot=\"" << Html(scene.name) << "\">" << svg
      << "</figure>\n";
  }
  h << "<p>Made by arco from the cameras and the audio (docs/report.md): strings and fingers "
       "from the pitch and the hand, bowing from the tracked bow.</p>\n</body></html>\n";
  if (summary != nullptr) {
    summary->notes = static_cast<int>(rows.size());
    summary->passages = static_cast<int>(passages.size());
    summary->shifts = shifts;
    summary->bowing = !bowing.empty();
  }
  return h.str();
}

}  // namespace arco::exporter
