#include "arco/audio/notes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "arco/registry/instruments.h"
#include "arco/util/csv.h"
#include "arco/util/file_io.h"
#include "arco/util/stats.h"

namespace arco::audio {
namespace {

struct Vibrato {
  double rate_hz = 0, extent_cents = 0;
};

// Rate and extent of a periodic pitch modulation in `semis` (no NaN), sampled at fps.
Vibrato DetectVibrato(const std::vector<double>& semis, double fps, const NoteOptions& o) {
  Vibrato v;
  const int n = static_cast<int>(semis.size());
  const int lag_min = std::max(2, static_cast<int>(std::floor(fps / o.vibrato_max_rate_hz)));
  const int lag_max = std::min(static_cast<int>(std::ceil(fps / o.vibrato_min_rate_hz)), n * 2 / 3);
  if (lag_max <= lag_min + 1) return v;
  // Remove a straight line (intonation drift over the note), in cents.
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int k = 0; k < n; ++k) sx += k, sy += semis[k], sxx += double(k) * k, sxy += k * semis[k];
  const double den = n * sxx - sx * sx;
  const double slope = den > 0 ? (n * sxy - sx * sy) / den : 0.0;
  const double icpt = (sy - slope * sx) / n;
  std::vector<double> c(n);
  double energy = 0;
  for (int k = 0; k < n; ++k) {
    c[k] = 100.0 * (semis[k] - (icpt + slope * k));
    energy += c[k] * c[k];
  }
  const double extent = std::sqrt(2.0 * energy / n);
  if (extent < o.vibrato_min_extent_cents) return v;
  std::vector<double> r(lag_max + 2, 0.0);
  for (int lag = lag_min - 1; lag <= lag_max + 1 && lag < n; ++lag) {
    double xy = 0, xx = 0, yy = 0;
    for (int k = 0; k + lag < n; ++k)
      xy += c[k] * c[k + lag], xx += c[k] * c[k], yy += c[k + lag] * c[k + lag];
    r[lag] = (xx > 0 && yy > 0) ? xy / std::sqrt(xx * yy) : 0.0;
  }
  int best = -1;
  for (int lag = lag_min; lag <= lag_max && lag + 1 < static_cast<int>(r.size()); ++lag) {
    if (r[lag] >= r[lag - 1] && r[lag] >= r[lag + 1] && (best < 0 || r[lag] > r[best])) best = lag;
  }
  if (best < 0 || r[best] < o.vibrato_min_correlation) return v;
  const double a = r[best - 1], b = r[best], cc = r[best + 1];
  const double curvature = a - 2 * b + cc;
  const double lag = curvature < 0 ? best + 0.5 * (a - cc) / curvature : best;
  v.rate_hz = fps / lag;
  v.extent_cents = extent;
  return v;
}

}  // namespace

Status NoteOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(CheckInRange("a4_hz", a4_hz, kA4RangeHz));
  if (!(min_note_s > 0 && max_gap_s >= 0 && smoothing_s >= 0 && split_semitones > 0)) {
    return Status::Error("note durations and thresholds must be positive");
  }
  if (!(glide_slope_semitones_per_s > 0 && min_glide_s > 0 && min_glide_semitones > 0)) {
    return Status::Error("glide thresholds must be positive");
  }
  if (!(vibrato_min_rate_hz > 0 && vibrato_max_rate_hz > vibrato_min_rate_hz)) {
    return Status::Error("vibrato rates must satisfy 0 < min < max");
  }
  return Status::Ok();
}

std::string NoteName(int midi_note) {
  static const char* kNames[] = {"C", "C#", "D", "D#", "E", "F", "F#", "G", "G#", "A", "A#", "B"};
  const int pitch_class = ((midi_note % 12) + 12) % 12;
  const int octave = (midi_note - pitch_class) / 12 - 1;
  return std::string(kNames[pitch_class]) + std::to_string(octave);
}

NoteAnalysis SegmentNotes(const std::vector<PitchFrame>& fine, double fps, const NoteOptions& o) {
  Status valid = o.Validate();
  if (!valid.ok()) throw std::invalid_argument("NoteOptions: " + valid.message());
  if (!(fps > 0)) throw std::invalid_argument("SegmentNotes: fps must be positive");
  NoteAnalysis out;
  const int n = static_cast<int>(fine.size());
  std::vector<double> semis(n, NAN);
  for (int j = 0; j < n; ++j) {
    if (fine[j].voiced && fine[j].f0_hz > 0)
      semis[j] = 69.0 + 12.0 * std::log2(fine[j].f0_hz / o.a4_hz);
  }
  const int max_gap = static_cast<int>(std::floor(o.max_gap_s * fps + 1e-9));
  const int half = std::max(1, static_cast<int>(std::lround(o.smoothing_s * fps / 2)));
  const int min_note = std::max(1, static_cast<int>(std::ceil(o.min_note_s * fps - 1e-9)));
  const int min_glide = std::max(2, static_cast<int>(std::ceil(o.min_glide_s * fps - 1e-9)));
  const int g = std::max(1, static_cast<int>(std::lround(0.02 * fps)));
  std::vector<double> scratch;
  auto emit_note = [&](int first, int last) {
    std::vector<double> values;
    for (int k = first; k <= last; ++k) {
      if (!std::isnan(semis[k])) values.push_back(semis[k]);
    }
    if (static_cast<int>(values.size()) < min_note) return;
    // Vibrato on the gap-filled pitch curve.
    std::vector<double> curve;
    double previous = values.front();
    for (int k = first; k <= last; ++k) {
      if (!std::isnan(semis[k])) previous = semis[k];
      curve.push_back(previous);
    }
    const double median = Median(values);
    Note note;
    note.onset_s = fine[first].time_s;
    note.offset_s = fine[last].time_s + 1.0 / fps;
    note.median_f0_hz = o.a4_hz * std::exp2((median - 69.0) / 12.0);
    note.midi_note = static_cast<int>(std::lround(median));
    note.cents_from_et = 100.0 * (median - note.midi_note);
    const Vibrato v = DetectVibrato(curve, fps, o);
    note.vibrato_rate_hz = v.rate_hz;
    note.vibrato_extent_cents = v.extent_cents;
    out.notes.push_back(note);
  };

  for (int a = 0; a < n;) {
    if (std::isnan(semis[a])) {
      ++a;
      continue;
    }
    // A voiced run [a, b] with short gaps bridged.
    int b = a, gap = 0;
    for (int j = a + 1; j < n; ++j) {
      if (std::isnan(semis[j])) {
        if (++gap > max_gap) break;
      } else {
        gap = 0;
        b = j;
      }
    }
    const int len = b - a + 1;
    std::vector<double> smooth(len);
    for (int k = 0; k < len; ++k) {
      scratch.clear();
      for (int q = std::max(a, a + k - half); q <= std::min(b, a + k + half); ++q) {
        if (!std::isnan(semis[q])) scratch.push_back(semis[q]);
      }
      smooth[k] = scratch.empty() ? (k > 0 ? smooth[k - 1] : semis[a]) : Median(scratch);
    }
    // Glides: sustained steep slope of the smoothed pitch.
    std::vector<char> gliding(len, 0);
    for (int k = 0; k < len; ++k) {
      const int lo = std::max(0, k - g), hi = std::min(len - 1, k + g);
      if (hi > lo) {
        const double slope = (smooth[hi] - smooth[lo]) * fps / (hi - lo);
        gliding[k] = std::abs(slope) > o.glide_slope_semitones_per_s;
      }
    }
    for (int k = 0; k < len;) {
      if (!gliding[k]) {
        ++k;
        continue;
      }
      int e = k;
      while (e + 1 < len && gliding[e + 1]) ++e;
      const double change = std::abs(smooth[e] - smooth[k]);
      if (e - k + 1 < min_glide || change < o.min_glide_semitones) {
        std::fill(gliding.begin() + k, gliding.begin() + e + 1, 0);
      } else {
        Glide glide;
        glide.start_s = fine[a + k].time_s;
        glide.end_s = fine[a + e].time_s + 1.0 / fps;
        glide.start_f0_hz = o.a4_hz * std::exp2((smooth[k] - 69.0) / 12.0);
        glide.end_f0_hz = o.a4_hz * std::exp2((smooth[e] - 69.0) / 12.0);
        out.glides.push_back(glide);
      }
      k = e + 1;
    }
    // Notes between glides, split with hysteresis around the running centre.
    for (int k = 0; k < len;) {
      if (gliding[k]) {
        ++k;
        continue;
      }
      int start = k;
      double sum = smooth[k];
      int count = 1;
      int j = k + 1;
      for (; j < len && !gliding[j]; ++j) {
        const double centre = sum / count;
        if (std::abs(smooth[j] - centre) > o.split_semitones) {
          int persist = j;
          while (persist < len && !gliding[persist] &&
                 std::abs(smooth[persist] - centre) > o.split_semitones) {
            ++persist;
          }
          if (persist - j >= min_note || persist >= len || gliding[persist]) break;
        }
        sum += smooth[j];
        ++count;
      }
      emit_note(a + start, a + j - 1);
      k = j;
    }
    a = b + 1;
  }
  return out;
}

MidiFile NotesToMidi(const NoteAnalysis& analysis,
                     const std::vector<PitchFrame>& fine,
                     const NoteOptions& o,
                     int gm_program,
                     double bend_range_semitones) {
  MidiFile file;
  file.bend_range_semitones = bend_range_semitones;
  MidiTrack track;
  track.name = "arco pitch";
  track.program = gm_program;
  size_t j = 0;
  for (const Note& note : analysis.notes) {
    MidiNote m;
    m.onset_s = note.onset_s;
    m.offset_s = note.offset_s;
    m.midi_note = std::clamp(note.midi_note, 0, 127);
    track.notes.push_back(m);
    while (j < fine.size() && fine[j].time_s < note.onset_s - 1e-9) ++j;
    double last = 1e9;
    bool first = true;
    for (; j < fine.size() && fine[j].time_s < note.offset_s - 1e-9; ++j) {
      if (!fine[j].voiced || fine[j].f0_hz <= 0) continue;
      const double bend = 69.0 + 12.0 * std::log2(fine[j].f0_hz / o.a4_hz) - m.midi_note;
      if (first || std::abs(bend - last) >= 0.01) {
        // The first bend sits at the onset so the note starts at its pitch.
        track.bends.push_back({first ? note.onset_s : fine[j].time_s, bend});
        last = bend;
        first = false;
      }
    }
  }
  file.tracks.push_back(track);
  return file;
}

int GmProgramForInstrument(const std::string& instrument) {
  const StatusOr<InstrumentKind> kind = ParseInstrumentKind(instrument);
  // "any" and unknown names sound as a cello.
  return GetInstrumentInfo(kind.ok() ? *kind : InstrumentKind::kCello).gm_program;
}

Status WriteNotesCsv(const std::string& path, const NoteAnalysis& analysis) {
  return AtomicWriteFile(path, FormatNotesCsv(analysis));
}

std::string FormatNotesCsv(const NoteAnalysis& analysis) {
  struct Row {
    double onset;
    std::string text;
  };
  std::vector<Row> rows;
  char line[400];
  for (const Note& note : analysis.notes) {
    std::snprintf(line,
                  sizeof(line),
                  "note,%.4f,%.4f,%.3f,%d,%s,%.1f,%.2f,%.1f,,\n",
                  note.onset_s,
                  note.offset_s,
                  note.median_f0_hz,
                  note.midi_note,
                  NoteName(note.midi_note).c_str(),
                  note.cents_from_et,
                  note.vibrato_rate_hz,
                  note.vibrato_extent_cents);
    rows.push_back({note.onset_s, line});
  }
  for (const Glide& g : analysis.glides) {
    std::snprintf(line,
                  sizeof(line),
                  "glide,%.4f,%.4f,,,,,,,%.3f,%.3f\n",
                  g.start_s,
                  g.end_s,
                  g.start_f0_hz,
                  g.end_f0_hz);
    rows.push_back({g.start_s, line});
  }
  std::stable_sort(
      rows.begin(), rows.end(), [](const Row& x, const Row& y) { return x.onset < y.onset; });
  std::string out = std::string(kNotesCsvHeader) + "\n";
  for (const Row& r : rows) out += r.text;
  return out;
}

StatusOr<std::vector<Note>> ReadNotesCsv(const std::string& path) {
  ARCO_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  return ParseNotesCsv(text, path);
}

StatusOr<std::vector<Note>> ParseNotesCsv(const std::string& text, const std::string& source) {
  // The columns read back: kind, onset_s, offset_s, median_f0_hz; every row must still have
  // all of the header's cells (a row cut short is an error, as in pitch.csv).
  ARCO_ASSIGN_OR_RETURN(
      const CsvTable table,
      ParseCsvTable(
          text, source, {"kind", "onset_s", "offset_s", "median_f0_hz"}, kNotesCsvHeader));
  const int kind_col = table.Column("kind"), onset_col = table.Column("onset_s"),
            offset_col = table.Column("offset_s"), f0_col = table.Column("median_f0_hz");
  std::vector<Note> notes;
  for (const CsvTable::Row& row : table.rows) {
    const std::string& kind = row.cells[kind_col];
    if (kind == "glide") continue;
    if (kind != "note")
      return Status::Error(table.Where(row) + "kind '" + kind + "' is neither note nor glide");
    Note n;
    if (!ParseCsvDouble(row.cells[onset_col], &n.onset_s) ||
        !ParseCsvDouble(row.cells[offset_col], &n.offset_s) ||
        !ParseCsvDouble(row.cells[f0_col], &n.median_f0_hz) ||
        !(std::isfinite(n.onset_s) && std::isfinite(n.offset_s) && n.offset_s >= n.onset_s &&
          n.median_f0_hz > 0 && std::isfinite(n.median_f0_hz)) ||
        (!notes.empty() && n.onset_s < notes.back().onset_s)) {
      return Status::Error(table.Where(row) + "malformed note row");
    }
    notes.push_back(n);
  }
  return notes;
}

}  // namespace arco::audio
