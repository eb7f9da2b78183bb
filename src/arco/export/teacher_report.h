// `arco report`: what a teacher reads from a take, as one self-contained HTML page
// (docs/report.md). Per note: name, string, finger, position, intonation (cents, with the
// vibrato's rate and width), bow direction and sounding point; per passage: shifts,
// intonation trend, vibrato and bowing statistics; the figures of `arco plot` inline (SVG).
//
// Notes are a method's (fingering.csv), their vibrato the audio's (notes.csv), their
// bowing arco's bowing_notes.csv (absent for an older result: the bow columns are empty).
// Every note is one <tr class="note" data-note="N"> and every passage one
// <section class="passage">, so a reader (or a test) can find them.
#pragma once

#include <string>

#include "arco/util/number_range.h"
#include "arco/util/status.h"

namespace arco::exporter {

inline constexpr NumberRange kReportPassageGapRangeS = AboveZero(10);
inline constexpr NumberRange kReportInTuneRangeCents = AboveZero(50);

struct TeacherReportOptions {
  std::string result_dir;
  std::string method = "arco";  // whose fingering and bowing
  // A passage ends at a silence at least this long (or after 10 s of music).
  double passage_gap_s = 0.3;
  // Within this many cents of equal temperament a note is marked in tune (twice this:
  // slightly off; beyond: off).
  double in_tune_cents = 10;
  Status Validate() const;
};

struct TeacherReportSummary {
  int notes = 0;
  int passages = 0;
  int shifts = 0;
  bool bowing = false;  // the method has bowing_notes.csv
};

// The page's text. Errors name the file: no result, a method without fingering.csv,
// malformed files.
StatusOr<std::string> BuildTeacherReport(const TeacherReportOptions& options,
                                         TeacherReportSummary* summary);

}  // namespace arco::exporter
