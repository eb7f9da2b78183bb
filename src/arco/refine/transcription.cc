#include "arco/refine/transcription.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include "arco/refine/arco_decode.h"
#include "arco/refine/hand_position.h"
#include "arco/util/stats.h"

namespace arco::refine {

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
    std::map<std::pair<int, int>, int> pressed_votes;  // (string, finger) -> frames
    std::map<int, int> open_votes;
    std::vector<double> from_nut;
    for (int64_t f = note.first_frame; f <= note.last_frame; ++f) {
      const FrameContact& c = contacts[static_cast<size_t>(f)];
      if (c.note != static_cast<int>(i)) continue;
      if (c.state == ContactState::kPressed) {
        ++row.pressed_frames;
        ++pressed_votes[{c.string, c.finger}];
      } else if (c.state == ContactState::kOpenString) {
        ++row.open_frames;
        ++open_votes[c.string];
      } else {
        ++row.uncertain_frames;
      }
    }
    if (row.pressed_frames > 0 && row.pressed_frames >= row.open_frames &&
        row.pressed_frames >= row.uncertain_frames) {
      row.state = "pressed";
      int best = -1;
      for (const auto& [key, votes] : pressed_votes) {  // ordered: ties to the lower key
        if (votes > best) {
          best = votes;
          row.string = key.first;
          row.finger = key.second;
        }
      }
      for (int64_t f = note.first_frame; f <= note.last_frame; ++f) {
        const FrameContact& c = contacts[static_cast<size_t>(f)];
        if (c.pressed() && c.string == row.string && c.finger == row.finger &&
            std::isfinite(c.from_nut_mm)) {
          from_nut.push_back(c.from_nut_mm);
        }
      }
      if (!from_nut.empty()) {
        row.from_nut_mm = UpperMedian(from_nut);  // one of the measured positions
      }
      // The hand position, set below from the whole sequence (hand_position.h).
      row.position_semitones = CentsBetween(model.open_hz(row.string), note.f0_hz) / 100.0;
    } else if (row.open_frames > 0 && row.open_frames >= row.uncertain_frames) {
      row.state = "open";
      int best = -1;
      for (const auto& [string, votes] : open_votes) {
        if (votes > best) {
          best = votes;
          row.string = string;
        }
      }
    } else {
      row.state = "uncertain";
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
    std::map<std::pair<int, int>, int> pressed_votes;  // (string, finger) -> frames
    std::map<int, int> open_votes;
    std::vector<double> f0;
    int64_t frames = 0;
    for (int64_t f = lower.first_frame; f <= lower.last_frame; ++f) {
      if (f < 0 || f >= static_cast<int64_t>(second.size())) continue;
      ++frames;
      const FrameContact& c = second[static_cast<size_t>(f)];
      if (c.state == ContactState::kRest) continue;
      if (c.f0_hz > 0) f0.push_back(c.f0_hz);
      if (c.state == ContactState::kPressed) {
        ++row.pressed_frames;
        ++pressed_votes[{c.string, c.finger}];
      } else if (c.state == ContactState::kOpenString) {
        ++row.open_frames;
        ++open_votes[c.string];
      } else {
        ++row.uncertain_frames;
      }
    }
    const int64_t heard = row.pressed_frames + row.open_frames + row.uncertain_frames;
    if (f0.empty() || 2 * heard < frames) continue;
    row.f0_hz = UpperMedian(f0);
    const double midi = 69.0 + 12.0 * std::log2(row.f0_hz / a4_hz);
    row.midi_note = static_cast<int>(std::lround(midi));
    row.cents_off = 100.0 * (midi - row.midi_note);
    if (row.pressed_frames > 0 && row.pressed_frames >= row.open_frames &&
        row.pressed_frames >= row.uncertain_frames) {
      row.state = "pressed";
      int best = -1;
      for (const auto& [key, votes] : pressed_votes) {  // ordered: ties to the lower key
        if (votes > best) {
          best = votes;
          row.string = key.first;
          row.finger = key.second;
        }
      }
      std::vector<double> from_nut;
      for (int64_t f = lower.first_frame; f <= lower.last_frame; ++f) {
        if (f < 0 || f >= static_cast<int64_t>(second.size())) continue;
        const FrameContact& c = second[static_cast<size_t>(f)];
        if (c.pressed() && c.string == row.string && c.finger == row.finger &&
            std::isfinite(c.from_nut_mm)) {
          from_nut.push_back(c.from_nut_mm);
        }
      }
      if (!from_nut.empty()) row.from_nut_mm = UpperMedian(from_nut);
      row.position_semitones =
          lower.state == "pressed"
              ? lower.position_semitones
              : HandPositionsSemitones(
                    model.kind(),
                    {{CentsBetween(model.open_hz(row.string), row.f0_hz) / 100.0, row.finger}})
                    .front();
    } else if (row.open_frames > 0 && row.open_frames >= row.uncertain_frames) {
      row.state = "open";
      int best = -1;
      for (const auto& [string, votes] : open_votes) {
        if (votes > best) {
          best = votes;
          row.string = string;
        }
      }
    } else {
      row.state = "uncertain";
    }
    out.push_back(row);
  }
  return out;
}

}  // namespace arco::refine
