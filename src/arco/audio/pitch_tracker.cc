#include "arco/audio/pitch_tracker.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <sstream>
#include <stdexcept>

#include "arco/audio/sample_stream.h"
#include "arco/registry/instruments.h"
#include "arco/util/csv.h"
#include "arco/util/file_io.h"

namespace arco::audio {

StatusOr<InstrumentRange> InstrumentRangeByName(const std::string& name) {
  if (name == "any") {
    InstrumentRange any{"any", 0, 0, 0};
    for (const InstrumentInfo& info : AllInstruments()) {
      const PitchSearchRange& r = info.pitch_search;
      any.min_f0_hz =
          any.analysis_rate_hz == 0 ? r.min_f0_hz : std::min(any.min_f0_hz, r.min_f0_hz);
      any.max_f0_hz = std::max(any.max_f0_hz, r.max_f0_hz);
      any.analysis_rate_hz = std::max(any.analysis_rate_hz, r.analysis_rate_hz);
    }
    return any;
  }
  const StatusOr<InstrumentKind> kind = ParseInstrumentKind(name);
  if (!kind.ok()) {
    return Status::Error("unknown instrument '" + name +
                         "' (expected violin, viola, cello, double_bass or any)");
  }
  const InstrumentInfo& info = GetInstrumentInfo(*kind);
  return InstrumentRange{info.name,
                         info.pitch_search.min_f0_hz,
                         info.pitch_search.max_f0_hz,
                         info.pitch_search.analysis_rate_hz};
}

Status PitchTrackerOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(CheckInRange("fps", fps, kTrackerFpsRange));
  ARCO_RETURN_IF_ERROR(CheckInRange("start_s", start_s, kTrackerStartRangeS));
  ARCO_RETURN_IF_ERROR(CheckInRange("hops_per_frame", hops_per_frame, kHopsPerFrameRange));
  if (max_frames < -1) return Status::Error("max_frames must be >= -1");
  ARCO_RETURN_IF_ERROR(CheckInRange("a4_hz", a4_hz, kA4RangeHz));
  // Named by the fields that override them (PitchRunOptions, `arco pitch --fmin/--fmax`).
  const double top_hz = range.analysis_rate_hz / 4.0;
  if (!(range.min_f0_hz >= 20 && range.min_f0_hz < range.max_f0_hz && range.max_f0_hz <= top_hz)) {
    return Status::Error("min_f0_hz = " + NumberText(range.min_f0_hz) + " and max_f0_hz = " +
                         NumberText(range.max_f0_hz) + " Hz must satisfy 20 <= min_f0_hz < " +
                         "max_f0_hz <= " + NumberText(top_hz) + " (the " + range.name +
                         "'s analysis rate " + std::to_string(range.analysis_rate_hz) + " Hz / 4)");
  }
  return Status::Ok();
}

StatusOr<PitchTrack> TrackPitch(std::unique_ptr<AudioReader> reader,
                                const PitchTrackerOptions& options,
                                PitchSummary* summary,
                                Progress& progress) {
  const std::clock_t cpu_start = std::clock();
  ARCO_RETURN_IF_ERROR(options.Validate());
  PitchTrack track;
  track.fps = options.fps;
  track.start_s = options.start_s;
  track.hops_per_frame = options.hops_per_frame > 0
                             ? options.hops_per_frame
                             : std::max(1, static_cast<int>(std::ceil(100.0 / options.fps - 1e-9)));
  const int hops = track.hops_per_frame;
  track.fine_fps = options.fps * hops;

  YinOptions yin = options.yin;
  yin.sample_rate_hz = options.range.analysis_rate_hz;
  yin.min_f0_hz = options.range.min_f0_hz;
  yin.max_f0_hz = options.range.max_f0_hz;
  PitchHmmOptions hmm_options = options.hmm;
  hmm_options.min_f0_hz = options.range.min_f0_hz;
  hmm_options.max_f0_hz = options.range.max_f0_hz;
  hmm_options.frame_rate_hz = track.fine_fps;
  YinAnalyzer analyzer(yin);
  const AudioInfo info = reader->info();
  const double rate = yin.sample_rate_hz;
  if (info.frames > 0) {
    const double expected_s = static_cast<double>(info.frames) / info.sample_rate_hz;
    const double rows = (expected_s - options.start_s) * track.fine_fps + 2;
    if (rows > 0 && rows < 1e9) track.fine.reserve(static_cast<size_t>(rows));
  }
  PitchHmm hmm(hmm_options, [&](const DecodedFrame& d) {
    PitchFrame f;
    f.frame = d.index;
    f.time_s = options.start_s + static_cast<double>(d.index) / track.fine_fps;
    f.f0_hz = d.voiced ? d.f0_hz : 0.0;
    f.confidence = d.confidence;
    f.voiced = d.voiced;
    track.fine.push_back(f);
  });
  SampleStream stream(std::move(reader), yin.sample_rate_hz);
  const int window = analyzer.window_length();
  std::vector<float> buffer(static_cast<size_t>(window));
  FrameCandidates candidates;
  const int64_t max_fine = options.max_frames >= 0 ? options.max_frames * hops : -1;
  ARCO_ASSIGN_OR_RETURN(const bool has_audio, stream.Has(0));
  progress.SetTotal(kPitchProgressSteps);
  int64_t steps_done = 0;
  const double expected_s =
      info.frames > 0 ? static_cast<double>(info.frames) / info.sample_rate_hz : -1.0;
  for (int64_t j = 0; has_audio && (max_fine < 0 || j < max_fine); ++j) {
    // Time from j directly (no accumulated hop), centre = nearest sample.
    const double time_s = options.start_s + static_cast<double>(j) / track.fine_fps;
    const int64_t centre = std::llround(time_s * rate);
    if (centre >= 0) {
      ARCO_ASSIGN_OR_RETURN(const bool inside, stream.Has(centre));
      if (!inside) break;
    }
    ARCO_RETURN_IF_ERROR(stream.Read(centre - window / 2, window, buffer.data()));
    analyzer.Analyze(buffer.data(), &candidates);
    hmm.Push(candidates);
    if (expected_s > 0 && j % 256 == 0) {
      const auto steps = static_cast<int64_t>(std::min(1.0, time_s / expected_s) *
                                              static_cast<double>(kPitchProgressSteps));
      if (steps > steps_done) progress.Advance(steps - steps_done), steps_done = steps;
    }
  }
  hmm.Finish();
  for (size_t j = 0; j < track.fine.size(); j += hops) {
    PitchFrame f = track.fine[j];
    f.frame = static_cast<int64_t>(j / hops);
    f.time_s = options.start_s + static_cast<double>(f.frame) / options.fps;
    track.frames.push_back(f);
  }

  if (summary != nullptr) {
    *summary = PitchSummary();
    summary->source_format = info.format;
    summary->source_rate_hz = info.sample_rate_hz;
    summary->source_channels = info.channels;
    summary->analysis_rate_hz = yin.sample_rate_hz;
    summary->duration_s = static_cast<double>(stream.source_samples()) / info.sample_rate_hz;
    summary->frames = static_cast<int64_t>(track.frames.size());
    int64_t voiced = 0;
    for (const auto& f : track.frames) {
      if (!f.voiced) continue;
      summary->min_f0_hz = voiced == 0 ? f.f0_hz : std::min(summary->min_f0_hz, f.f0_hz);
      summary->max_f0_hz = std::max(summary->max_f0_hz, f.f0_hz);
      ++voiced;
    }
    summary->voiced_fraction =
        track.frames.empty() ? 0.0 : static_cast<double>(voiced) / track.frames.size();
    // Only a source that ran out early is truncated; stopping at max_frames is not.
    // A file known at open to be cut short is reported even when the frames asked for end
    // before the cut; otherwise a source that ran out early.
    if (info.missing_frames > 0) {
      summary->warnings.push_back(TruncationWarning(info));
    } else if (stream.finished() && info.frames > 0 && stream.source_samples() < info.frames) {
      summary->warnings.push_back(TruncationWarning(info, stream.source_samples()));
    }
    if (stream.source_samples() == 0) {
      summary->warnings.push_back("empty: the file holds no audio samples");
    } else if (track.frames.empty()) {
      summary->warnings.push_back("empty: no video frame falls inside the audio (check start_s)");
    } else if (voiced == 0) {
      summary->warnings.push_back("no voiced frames: the audio is silent or unpitched");
    }
    summary->cpu_seconds = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  }
  return track;
}

StatusOr<PitchTrack> TrackPitchFile(const std::string& path,
                                    const PitchTrackerOptions& options,
                                    PitchSummary* summary,
                                    Progress& progress) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  ARCO_ASSIGN_OR_RETURN(auto reader, OpenAudio(path));
  auto track = TrackPitch(std::move(reader), options, summary, progress);
  if (!track.ok()) return track.status();
  return track;
}

std::string FormatPitchCsv(const std::vector<PitchFrame>& frames) {
  return FormatPitchCsv(frames, nullptr);
}

std::string FormatPitchCsv(const std::vector<PitchFrame>& frames,
                           const std::vector<double>* second_f0_hz) {
  if (second_f0_hz != nullptr && second_f0_hz->size() != frames.size()) {
    throw std::invalid_argument("FormatPitchCsv: one second f0 per frame");
  }
  std::string out = second_f0_hz != nullptr ? "frame,time_s,f0_hz,confidence,voiced,f0_2_hz\n"
                                            : "frame,time_s,f0_hz,confidence,voiced\n";
  char line[160];
  for (size_t i = 0; i < frames.size(); ++i) {
    const PitchFrame& f = frames[i];
    std::snprintf(line,
                  sizeof(line),
                  "%lld,%.6f,%.4f,%.4f,%d\n",
                  static_cast<long long>(f.frame),
                  f.time_s,
                  f.voiced ? f.f0_hz : 0.0,
                  f.confidence,
                  f.voiced ? 1 : 0);
    out += line;
    if (second_f0_hz != nullptr) {
      out.pop_back();  // the newline
      std::snprintf(line, sizeof(line), ",%.4f\n", (*second_f0_hz)[i]);
      out += line;
    }
  }
  return out;
}

Status WritePitchCsv(const std::string& path, const std::vector<PitchFrame>& frames) {
  return AtomicWriteFile(path, FormatPitchCsv(frames));
}

Status WritePitchCsv(const std::string& path,
                     const std::vector<PitchFrame>& frames,
                     const std::vector<double>* second_f0_hz) {
  return AtomicWriteFile(path, FormatPitchCsv(frames, second_f0_hz));
}

StatusOr<std::vector<PitchFrame>> ReadPitchCsv(const std::string& path) {
  ARCO_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  return ParsePitchCsv(text, path);
}

StatusOr<std::vector<PitchFrame>> ParsePitchCsv(const std::string& text,
                                                const std::string& source) {
  return ParsePitchCsv(text, source, nullptr);
}

StatusOr<std::vector<PitchFrame>> ParsePitchCsv(const std::string& text,
                                                const std::string& source,
                                                std::vector<double>* second_f0_hz) {
  ARCO_ASSIGN_OR_RETURN(const CsvTable table,
                        ParseCsvTable(text,
                                      source,
                                      {"frame", "time_s", "f0_hz", "confidence", "voiced"},
                                      "frame,time_s,f0_hz,confidence,voiced"));
  const int frame_col = table.Column("frame"), time_col = table.Column("time_s"),
            f0_col = table.Column("f0_hz"), confidence_col = table.Column("confidence"),
            voiced_col = table.Column("voiced");
  const int second_col = table.Column("f0_2_hz");  // optional (-1 when absent)
  if (second_f0_hz != nullptr) second_f0_hz->clear();
  std::vector<PitchFrame> frames;
  for (const CsvTable::Row& row : table.rows) {
    PitchFrame f;
    int64_t frame = 0, voiced = 0;
    // Every cell a finite number: an empty cell would read as NaN, a value this format
    // never writes.
    if (!ParseCsvInt(row.cells[frame_col], &frame) ||
        !ParseCsvDouble(row.cells[time_col], &f.time_s) || !std::isfinite(f.time_s) ||
        !ParseCsvDouble(row.cells[f0_col], &f.f0_hz) || !std::isfinite(f.f0_hz) ||
        !ParseCsvDouble(row.cells[confidence_col], &f.confidence) || !std::isfinite(f.confidence) ||
        !ParseCsvInt(row.cells[voiced_col], &voiced) || (voiced != 0 && voiced != 1)) {
      return Status::Error(table.Where(row) +
                           "malformed row (frame, time_s, f0_hz, confidence: "
                           "numbers; voiced: 0 or 1)");
    }
    double second = 0;
    if (second_col >= 0 &&
        (!ParseCsvDouble(row.cells[second_col], &second) || !std::isfinite(second) || second < 0)) {
      return Status::Error(table.Where(row) + "malformed f0_2_hz (a number >= 0)");
    }
    if (second_f0_hz != nullptr) second_f0_hz->push_back(second);
    f.frame = frame;
    f.voiced = voiced != 0;
    frames.push_back(f);
  }
  return frames;
}

}  // namespace arco::audio
