#include "arco/refine/note_boundaries.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace arco::refine {
namespace {

double Cents(double f0_hz) { return 1200.0 * std::log2(f0_hz / 440.0); }

bool Trusted(const std::vector<FramePitch>& pitch, int64_t f, const PitchModelOptions& o) {
  return pitch[static_cast<size_t>(f)].confidence >= o.min_confidence;
}

// The video frames [first, last] of an audio note's window (header comment); false when
// the window holds no frame.
bool Window(const std::vector<AudioNote>& notes,
            size_t a,
            double start_s,
            double fps,
            double tol,
            int64_t num_frames,
            int64_t* first,
            int64_t* last) {
  const AudioNote& note = notes[a];
  // The same lead at both ends: up to the next note's window or the end of the sound.
  const double begin_s = note.onset_s - tol;
  double end_s = note.offset_s - tol;
  if (a + 1 < notes.size()) end_s = std::min(end_s, notes[a + 1].onset_s - tol);
  const double eps = 1e-9;
  int64_t lo = static_cast<int64_t>(std::ceil((begin_s - start_s) * fps - eps));
  int64_t hi = static_cast<int64_t>(std::floor((end_s - start_s) * fps + eps));
  if (start_s + static_cast<double>(hi) / fps >= end_s - eps) --hi;  // end exclusive
  lo = std::max<int64_t>(lo, 0);
  hi = std::min<int64_t>(hi, num_frames - 1);
  *first = lo;
  *last = hi;
  return lo <= hi;
}

}  // namespace

void ApplyAudioNoteBoundaries(const std::vector<AudioNote>& audio_notes,
                              double start_s,
                              double fps,
                              const std::vector<FramePitch>& pitch,
                              const PitchModelOptions& pitch_options,
                              const NoteBoundaryOptions& options,
                              PitchAnalysis* analysis) {
  PitchAnalysis& an = *analysis;
  const int64_t n = static_cast<int64_t>(an.frame_state.size());
  if (!(fps > 0) || static_cast<int64_t>(pitch.size()) != n) return;
  for (size_t a = 0; a < audio_notes.size(); ++a) {
    const AudioNote& audio = audio_notes[a];
    if (!(audio.f0_hz > 0) || !std::isfinite(audio.onset_s) || !std::isfinite(audio.offset_s)) {
      continue;
    }
    int64_t first = 0, last = 0;
    if (!Window(audio_notes, a, start_s, fps, options.onset_tolerance_s, n, &first, &last)) {
      continue;
    }
    // The pitch-model note with the most trusted frames in the window, at the same pitch.
    int best = -1, best_count = 0;
    for (int64_t f = first; f <= last; ++f) {
      const int idx = an.note_of_frame[static_cast<size_t>(f)];
      const FrameAudioState s = an.frame_state[static_cast<size_t>(f)];
      if (idx < 0 || idx == best) continue;
      if (!(s == FrameAudioState::kNote || s == FrameAudioState::kShortNote)) continue;
      const NoteSpan& cand = an.notes[static_cast<size_t>(idx)];
      if (std::abs(Cents(cand.f0_hz) - Cents(audio.f0_hz)) > options.match_cents) continue;
      int count = 0;
      for (int64_t g = std::max(first, cand.first_frame); g <= std::min(last, cand.last_frame);
           ++g) {
        if (an.note_of_frame[static_cast<size_t>(g)] == idx && Trusted(pitch, g, pitch_options))
          ++count;
      }
      if (count > best_count) {
        best = idx;
        best_count = count;
      }
    }
    if (best < 0) continue;
    NoteSpan& note = an.notes[static_cast<size_t>(best)];
    // A frame the note may take: its own pitch is not trusted, or it is a weak frame that
    // continued the previous note after that note's last trusted frame (the extension runs
    // outward and stops at the first trusted frame, so such frames are always trailing).
    auto takeable = [&](int64_t f) {
      const size_t i = static_cast<size_t>(f);
      switch (an.frame_state[i]) {
        case FrameAudioState::kRest:
        case FrameAudioState::kLowConfidence:
        case FrameAudioState::kOutlier:
          return true;
        case FrameAudioState::kNote:
          return an.note_of_frame[i] != best && !Trusted(pitch, f, pitch_options);
        default:
          return false;
      }
    };
    // The note's own first frames that still hear the change (header comment).
    if (note.usable) {
      for (int64_t f = note.first_frame;
           f <= note.last_frame &&
           start_s + static_cast<double>(f) / fps < audio.onset_s + options.straddle_s;
           ++f) {
        const size_t i = static_cast<size_t>(f);
        if (an.frame_state[i] != FrameAudioState::kNote || an.note_of_frame[i] != best) continue;
        if (std::abs(Cents(pitch[i].f0_hz) - Cents(note.f0_hz)) > options.straddle_cents)
          an.frame_state[i] = FrameAudioState::kBoundary;
      }
    }
    int64_t new_first = note.first_frame, new_last = note.last_frame;
    while (new_first - 1 >= first && takeable(new_first - 1)) --new_first;
    while (new_last + 1 <= last && takeable(new_last + 1)) ++new_last;
    if (new_first == note.first_frame && new_last == note.last_frame) continue;
    const int64_t frames = new_last - new_first + 1;
    if (frames < pitch_options.min_note_frames) continue;  // still too short to trust
    const bool stable = static_cast<double>(note.outlier_frames) <=
                        pitch_options.max_outlier_fraction * static_cast<double>(frames);
    if (!note.usable && !stable) continue;
    // Weak frames taken from the end of the previous note shorten it.
    for (int64_t f = new_first; f < note.first_frame; ++f) {
      const int prev = an.note_of_frame[static_cast<size_t>(f)];
      if (prev < 0 || prev == best) continue;
      NoteSpan& p = an.notes[static_cast<size_t>(prev)];
      p.last_frame = std::min(p.last_frame, f - 1);
      if (p.usable && p.num_frames() < pitch_options.min_note_frames) {
        p.usable = false;
        for (int64_t g = p.first_frame; g <= p.last_frame; ++g)
          an.frame_state[static_cast<size_t>(g)] = FrameAudioState::kShortNote;
      }
    }
    for (int64_t f = new_first; f <= new_last; ++f) {
      const size_t i = static_cast<size_t>(f);
      if (f >= note.first_frame && f <= note.last_frame) {
        if (an.frame_state[i] == FrameAudioState::kShortNote)
          an.frame_state[i] = FrameAudioState::kNote;
        continue;
      }
      an.frame_state[i] = FrameAudioState::kBoundary;
      an.note_of_frame[i] = best;
    }
    note.first_frame = new_first;
    note.last_frame = new_last;
    note.usable = true;
  }
}

}  // namespace arco::refine
