#include "arco/synth/midi_reader.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>

#include "arco/util/file_io.h"

namespace arco::synth {
namespace {

constexpr double kChordToleranceS = 0.005;
constexpr size_t kMaxEvents = 5'000'000;  // guards against absurd files

// Bounds-checked big-endian reader over the file bytes.
class ByteReader {
 public:
  ByteReader(const std::string& bytes, size_t begin, size_t end)
      : b_(bytes), pos_(begin), end_(end) {}
  bool AtEnd() const { return pos_ >= end_; }
  size_t pos() const { return pos_; }
  bool U8(uint32_t* v) {
    if (pos_ >= end_) return false;
    *v = static_cast<uint8_t>(b_[pos_++]);
    return true;
  }
  bool BigEndian(int n, uint32_t* v) {
    *v = 0;
    for (int i = 0; i < n; ++i) {
      uint32_t byte;
      if (!U8(&byte)) return false;
      *v = (*v << 8) | byte;
    }
    return true;
  }
  // Variable-length quantity (at most 4 bytes, 28 bits).
  bool Vlq(uint32_t* v) {
    *v = 0;
    for (int i = 0; i < 4; ++i) {
      uint32_t byte;
      if (!U8(&byte)) return false;
      *v = (*v << 7) | (byte & 0x7f);
      if (!(byte & 0x80)) return true;
    }
    return false;
  }
  bool Skip(uint32_t n) {
    if (n > end_ - pos_) return false;
    pos_ += n;
    return true;
  }

 private:
  const std::string& b_;
  size_t pos_, end_;
};

struct RawNote {
  uint64_t on_tick, off_tick;
  int midi, velocity;
};

struct TrackData {
  std::vector<RawNote> notes;
  std::vector<std::pair<uint64_t, uint32_t>> tempos;  // tick -> microseconds per quarter
};

Status ParseTrack(ByteReader& r, const std::string& where, TrackData* out) {
  uint64_t tick = 0;
  uint32_t running = 0;
  // Pending note-ons per (channel, key): stack of (tick, velocity).
  std::map<int, std::vector<std::pair<uint64_t, int>>> pending;
  size_t events = 0;
  while (!r.AtEnd()) {
    if (++events > kMaxEvents) return Status::Error(where + ": too many events");
    uint32_t delta, status;
    if (!r.Vlq(&delta) || !r.U8(&status)) return Status::Error(where + ": truncated event");
    tick += delta;
    if (status == 0xff) {  // meta event
      uint32_t type, len;
      if (!r.U8(&type) || !r.Vlq(&len)) return Status::Error(where + ": truncated meta event");
      if (type == 0x51 && len == 3) {
        uint32_t us;
        if (!r.BigEndian(3, &us)) return Status::Error(where + ": truncated tempo");
        if (us == 0) return Status::Error(where + ": tempo of 0 microseconds per quarter note");
        out->tempos.emplace_back(tick, us);
      } else if (!r.Skip(len)) {
        return Status::Error(where + ": meta event runs past the end of the track");
      }
      if (type == 0x2f) break;  // end of track
      continue;
    }
    if (status == 0xf0 || status == 0xf7) {  // sysex
      uint32_t len;
      if (!r.Vlq(&len) || !r.Skip(len)) return Status::Error(where + ": truncated sysex");
      continue;
    }
    uint32_t data1;
    if (status & 0x80) {
      if (status >= 0xf0) return Status::Error(where + ": unexpected system message");
      running = status;
      if (!r.U8(&data1)) return Status::Error(where + ": truncated event");
    } else {
      if (running == 0) return Status::Error(where + ": data byte without a status byte");
      data1 = status;
      status = running;
    }
    const uint32_t kind = status & 0xf0;
    const int channel = static_cast<int>(status & 0x0f);
    uint32_t data2 = 0;
    if (kind != 0xc0 && kind != 0xd0) {
      if (!r.U8(&data2)) return Status::Error(where + ": truncated event");
    }
    if (data1 > 127 || data2 > 127) return Status::Error(where + ": data byte above 127");
    if (channel == 9) continue;  // percussion
    const int key = channel * 128 + static_cast<int>(data1);
    if (kind == 0x90 && data2 > 0) {
      pending[key].emplace_back(tick, static_cast<int>(data2));
    } else if (kind == 0x80 || (kind == 0x90 && data2 == 0)) {
      auto it = pending.find(key);
      if (it != pending.end() && !it->second.empty()) {
        out->notes.push_back(
            {it->second.front().first, tick, static_cast<int>(data1), it->second.front().second});
        it->second.erase(it->second.begin());
      }
    }
  }
  for (auto& [key, ons] : pending) {
    for (auto& [on_tick, velocity] : ons)
      out->notes.push_back({on_tick, tick, key % 128, velocity});
  }
  return Status::Ok();
}

}  // namespace

StatusOr<Score> ParseMidiScore(const std::string& bytes, const std::string& source) {
  ByteReader header(bytes, 0, bytes.size());
  if (bytes.size() < 14 || bytes.compare(0, 4, "MThd") != 0) {
    return Status::Error(source + ": not a Standard MIDI File (no MThd header)");
  }
  header.Skip(4);
  uint32_t header_len, format, num_tracks, division;
  if (!header.BigEndian(4, &header_len) || header_len < 6 || !header.BigEndian(2, &format) ||
      !header.BigEndian(2, &num_tracks) || !header.BigEndian(2, &division) ||
      !header.Skip(header_len - 6)) {
    return Status::Error(source + ": malformed MThd header");
  }
  if (format > 2) return Status::Error(source + ": unknown SMF format " + std::to_string(format));
  if (format == 2)
    return Status::Error(source + ": SMF format 2 (independent songs) is not supported");
  if (division == 0) return Status::Error(source + ": time division of 0 ticks");
  // SMPTE division: negative frames per second in the high byte, ticks per frame low.
  double seconds_per_tick_fixed = 0;
  if (division & 0x8000) {
    const int fps = 256 - static_cast<int>((division >> 8) & 0xff);
    const int ticks_per_frame = static_cast<int>(division & 0xff);
    if (fps <= 0 || ticks_per_frame == 0) return Status::Error(source + ": bad SMPTE division");
    seconds_per_tick_fixed = 1.0 / (fps * ticks_per_frame);
  }
  std::vector<RawNote> notes;
  std::vector<std::pair<uint64_t, uint32_t>> tempos;
  size_t pos = header.pos();
  for (uint32_t t = 0; t < num_tracks && pos < bytes.size(); ++t) {
    ByteReader chunk(bytes, pos, bytes.size());
    uint32_t id, len;
    if (!chunk.BigEndian(4, &id) || !chunk.BigEndian(4, &len) || len > bytes.size() - chunk.pos()) {
      return Status::Error(source + ": track " + std::to_string(t + 1) + " is truncated");
    }
    const size_t body = chunk.pos();
    pos = body + len;
    if (id != 0x4d54726b) continue;  // not "MTrk": skip unknown chunks
    ByteReader track(bytes, body, body + len);
    TrackData data;
    ARCO_RETURN_IF_ERROR(ParseTrack(track, source + ": track " + std::to_string(t + 1), &data));
    notes.insert(notes.end(), data.notes.begin(), data.notes.end());
    tempos.insert(tempos.end(), data.tempos.begin(), data.tempos.end());
  }
  if (notes.empty()) return Status::Error(source + ": no notes (outside the drum channel)");

  // Tempo map: piecewise-linear tick -> seconds (default 120 bpm).
  std::stable_sort(
      tempos.begin(), tempos.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  const double ppq = static_cast<double>(division & 0x7fff);
  auto to_seconds = [&](uint64_t tick) {
    if (seconds_per_tick_fixed > 0) return static_cast<double>(tick) * seconds_per_tick_fixed;
    double s = 0;
    uint64_t last_tick = 0;
    double us_per_quarter = 500000;
    for (const auto& [t, us] : tempos) {
      if (t >= tick) break;
      s += static_cast<double>(t - last_tick) * us_per_quarter * 1e-6 / ppq;
      last_tick = t;
      us_per_quarter = us;
    }
    return s + static_cast<double>(tick - last_tick) * us_per_quarter * 1e-6 / ppq;
  };

  std::stable_sort(notes.begin(), notes.end(), [](const RawNote& a, const RawNote& b) {
    return a.on_tick != b.on_tick ? a.on_tick < b.on_tick : a.midi < b.midi;
  });
  Score score;
  score.name = std::filesystem::path(source).filename().string();
  char buf[256];
  for (const RawNote& raw : notes) {
    ScoreNote n{raw.midi, to_seconds(raw.on_tick), to_seconds(raw.off_tick), raw.velocity};
    if (!score.notes.empty()) {
      ScoreNote& prev = score.notes.back();
      if (n.onset_s - prev.onset_s < kChordToleranceS) {
        std::snprintf(buf,
                      sizeof(buf),
                      "%s: notes %d (%s) and %d (%s) start together at %.3f s: chords and "
                      "double stops are not supported (one note at a time)",
                      source.c_str(),
                      prev.midi_note,
                      MidiNoteName(prev.midi_note).c_str(),
                      n.midi_note,
                      MidiNoteName(n.midi_note).c_str(),
                      n.onset_s);
        return Status::Error(buf);
      }
      prev.offset_s = std::min(prev.offset_s, n.onset_s);
    }
    score.notes.push_back(n);
  }
  // Zero-length notes (note-off at the note-on tick) carry no sound: drop them.
  score.notes.erase(std::remove_if(score.notes.begin(),
                                   score.notes.end(),
                                   [](const ScoreNote& n) { return n.offset_s <= n.onset_s; }),
                    score.notes.end());
  if (score.notes.empty()) return Status::Error(source + ": all notes have zero length");
  score.duration_s = score.notes.back().offset_s + 0.5;
  return score;
}

StatusOr<Score> ReadMidiScore(const std::string& path, const ScoreInstrument& instrument) {
  ARCO_ASSIGN_OR_RETURN(std::string bytes, ReadFileToString(path));
  ARCO_ASSIGN_OR_RETURN(Score score, ParseMidiScore(bytes, path));
  ARCO_RETURN_IF_ERROR(ValidateScore(score, instrument, path));
  return score;
}

}  // namespace arco::synth
