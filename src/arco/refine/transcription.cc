#include "arco/refine/transcription.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include "arco/refine/arco_decode.h"
#include "arco/refine/hand_position.h"
#include "arco/util/stats.h"

namespace arco::refine {

namespace {

// The majority state, string and finger of the frames first..last of `contacts` that
// `belongs` accepts (pressed, open, else uncertain: ties to pressed, then open), into
// `row`'s counts, state, string and finger, with the median from_nut_mm of the frames in
// that span pressed by that string and finger. Returns whether the state is pressed.
template <typename Belongs>
bool VoteNote(const std::vector<FrameContact>& contacts,
              int64_t first,
              int64_t last,
              const Belongs& belongs,
              NoteFingering* row) {
  std::map<std::pair<int, int>, int> pressed_votes;  // (string, finger) -> frames
  std::map<int, int> open_votes;
  first = std::max<int64_t>(first, 0);
  last = std::min<int64_t>(last, static_cast<int64_t>(contacts.size()) - 1);
  for (int64_t f = first; f <= last; ++f) {
    const FrameContact& c = contacts[static_cast<size_t>(f)];
    if (!belongs(c)) continue;
    if (c.state == ContactState::kPressed) {
      ++row->pressed_frames;
      ++pressed_votes[{c.string, c.finger}];
    } else if (c.state == ContactState::kOpenString) {
      ++row->open_frames;
      ++open_votes[c.string];
    } else {
      ++row->uncertain_frames;
    }
  }
  if (row->pressed_frames > 0 && row->pressed_frames >= row->open_frames &&
      row->pressed_frames >= row->uncertain_frames) {
    row->state = "pressed";
    int best = -1;
    for (const auto& [key, votes] : pressed_votes) {  // ordered: ties to the lower key
      if (votes > best) {
        best = votes;
        row->string = key.first;
        row->finger = key.second;
      }
    }
    std::vector<double> from_nut;
    for (int64_t f = first; f <= last; ++f) {
      const FrameContact& c = contacts[static_cast<size_t>(f)];
      if (c.pressed() && c.string == row->string && c.finger == row->finger &&
          std::isfinite(c.from_nut_mm)) {
        from_nut.push_back(c.from_nut_mm);
      }
    }
    if (!from_nut.empty()) row->from_nut_mm = UpperMedian(from_nut);  // a measured position
    return true;
  }
  if (row->open_frames > 0 && row->open_frames >= row->uncertain_frames) {
    row->state = "open";
    int best = -1;
    for (const auto& [string, votes] : open_votes) {
      if (votes > best) {
        best = votes;
        row->string = string;
      }
    }
  } else {
    row->state = "uncertain";
  }
  return false;
}

}  // namespace

std::vector<NoteFingering> Transcribe(const InstrumentModel& model,
                                      const PitchAnalysis& analysis,
                                      const std::vector<FrameContact>& contacts,
                                      double fps,
                                      double a4_hz) {
  std::vector<NoteFingering> out;
  out.reserve(analysis.notes.size());
  for (size_t i = 0; i < analysis.notes.size(); ++i) {
    const NoteSpan& note = analysis.notes[i];
    NoteFingering row;
    row.note = static_cast<int>(i);
    row.first_frame = note.first_frame;
    row.last_frame = note.last_frame;
    row.onset_s = static_cast<double>(note.first_frame) / fps;
    row.duration_s = static_cast<double>(note.num_frames()) / fps;
    row.f0_hz = note.f0_hz;
    const double midi = 69.0 + 12.0 * std::log2(note.f0_hz / a4_hz);
    row.midi_note = static_cast<int>(std::lround(midi));
    row.cents_off = 100.0 * (midi - row.midi_note);
    const int index = static_cast<int>(i);
    if (VoteNote(
            contacts,
            note.first_frame,
            note.last_frame,
            [index](const FrameContact& c) { return c.note == index; },
            &row)) {
      // The hand position, set below from the whole sequence (hand_position.h).
      row.position_semitones = CentsBetween(model.open_hz(row.string), note.f0_hz) / 100.0;
    }
    out.push_back(row);
  }
  // Stopped notes: position_semitones holds the pitch above the open string until here;
  // the hand positions are decoded over the whole sequence (hand_position.h).
  std::vector<StoppedNote> stopped;
  std::vector<size_t> stopped_rows;
  for (size_t i = 0; i < out.size(); ++i) {
    if (out[i].state != "pressed") continue;
    stopped.push_back({out[i].position_semitones, out[i].finger});
    stopped_rows.push_back(i);
  }
  const std::vector<double> positions = HandPositionsSemitones(model.kind(), stopped);
  for (size_t k = 0; k < stopped_rows.size(); ++k) {
    out[stopped_rows[k]].position_semitones = positions[k];
  }
  return out;
}

std::vector<NoteFingering> TranscribeSecondVoice(const InstrumentModel& model,
                                                 const std::vector<NoteFingering>& first,
                                                 const std::vector<FrameContact>& second,
                                                 double a4_hz) {
  std::vector<NoteFingering> out;
  for (const NoteFingering& lower : first) {
    NoteFingering row;
    row.note = lower.note;
    row.first_frame = lower.first_frame;
    row.last_frame = lower.last_frame;
    row.onset_s = lower.onset_s;
    row.duration_s = lower.duration_s;
    std::vector<double> f0;
    int64_t frames = 0, heard = 0;
    for (int64_t f = lower.first_frame; f <= lower.last_frame; ++f) {
      if (f < 0 || f >= static_cast<int64_t>(second.size())) continue;
      ++frames;
      const FrameContact& c = second[static_cast<size_t>(f)];
      if (c.state == ContactState::kRest) continue;
      ++heard;
      if (c.f0_hz > 0) f0.push_back(c.f0_hz);
    }
    if (f0.empty() || 2 * heard < frames) continue;
    row.f0_hz = UpperMedian(f0);
    const double midi = 69.0 + 12.0 * std::log2(row.f0_hz / a4_hz);
    row.midi_note = static_cast<int>(std::lround(midi));
    row.cents_off = 100.0 * (midi - row.midi_note);
    const bool pressed = VoteNote(
        second,
        lower.first_frame,
        lower.last_frame,
        [](const FrameContact& c) { return c.state != ContactState::kRest; },
        &row);
    if (pressed) {
      row.position_semitones =
          lower.state == "pressed"
              ? lower.position_semitones
              : HandPositionsSemitones(
                    model.kind(),
                    {{CentsBetween(model.open_hz(row.string), row.f0_hz) / 100.0, row.finger}})
                    .front();
    }
    out.push_back(row);
  }
  return out;
}

}  // namespace arco::refine
