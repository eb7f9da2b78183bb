#include "arco/audio/midi_file.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "arco/util/file_io.h"

namespace arco::audio {
namespace {

struct TimedEvent {
  int64_t tick;
  int order;  // at equal ticks: 0 setup, 1 note off, 2 bend, 3 note on
  std::string bytes;
};

void PutVlq(uint32_t value, std::string* out) {
  char buffer[5];
  int n = 0;
  buffer[n++] = static_cast<char>(value & 0x7F);
  while ((value >>= 7) != 0) buffer[n++] = static_cast<char>(0x80 | (value & 0x7F));
  while (n > 0) out->push_back(buffer[--n]);
}

void PutBig(uint32_t value, int bytes, std::string* out) {
  for (int i = bytes - 1; i >= 0; --i) out->push_back(static_cast<char>((value >> (8 * i)) & 0xFF));
}

std::string Chunk(const char* id, const std::string& body) {
  std::string out(id, 4);
  PutBig(static_cast<uint32_t>(body.size()), 4, &out);
  return out + body;
}

std::string Bytes(std::initializer_list<int> values) {
  std::string s;
  for (int v : values) s.push_back(static_cast<char>(v));
  return s;
}

}  // namespace

std::string EncodeMidi(const MidiFile& file) {
  auto fail = [](const std::string& m) { throw std::invalid_argument("EncodeMidi: " + m); };
  if (file.ticks_per_quarter <= 0 || file.ticks_per_quarter > 0x7FFF) fail("bad ticks_per_quarter");
  if (file.us_per_quarter <= 0 || file.us_per_quarter > 0xFFFFFF) fail("bad us_per_quarter");
  if (!(file.bend_range_semitones > 0 && file.bend_range_semitones <= 24)) fail("bad bend range");
  if (file.tracks.empty() || file.tracks.size() > 65535) fail("need 1..65535 tracks");
  const double ticks_per_s = 1e6 / file.us_per_quarter * file.ticks_per_quarter;
  auto tick_of = [&](double t) {
    if (!(t >= 0 && t < 1e6)) fail("times must be in [0, 1e6) s");
    return static_cast<int64_t>(std::llround(t * ticks_per_s));
  };
  std::string body;
  body = Chunk("MThd", [&] {
    std::string h;
    PutBig(1, 2, &h);
    PutBig(static_cast<uint32_t>(file.tracks.size()), 2, &h);
    PutBig(static_cast<uint32_t>(file.ticks_per_quarter), 2, &h);
    return h;
  }());
  for (size_t t = 0; t < file.tracks.size(); ++t) {
    const MidiTrack& track = file.tracks[t];
    if (track.channel < 0 || track.channel > 15) fail("channel must be 0..15");
    if (track.program < 0 || track.program > 127) fail("program must be 0..127");
    const int ch = track.channel;
    std::vector<TimedEvent> events;
    std::string setup;
    if (t == 0) {  // tempo meta event
      setup += Bytes({0xFF, 0x51, 0x03});
      PutBig(static_cast<uint32_t>(file.us_per_quarter), 3, &setup);
      events.push_back({0, 0, setup});
    }
    if (!track.name.empty()) {
      std::string name = Bytes({0xFF, 0x03});
      PutVlq(static_cast<uint32_t>(track.name.size()), &name);
      events.push_back({0, 0, name + track.name});
    }
    // RPN 0 = pitch-bend sensitivity (semitones + cents), then RPN null.
    const int range_semis = static_cast<int>(std::floor(file.bend_range_semitones));
    const int range_cents =
        static_cast<int>(std::lround((file.bend_range_semitones - range_semis) * 100.0));
    for (const std::string& e : {Bytes({0xB0 | ch, 101, 0}),
                                 Bytes({0xB0 | ch, 100, 0}),
                                 Bytes({0xB0 | ch, 6, range_semis}),
                                 Bytes({0xB0 | ch, 38, std::min(99, range_cents)}),
                                 Bytes({0xB0 | ch, 101, 127}),
                                 Bytes({0xB0 | ch, 100, 127}),
                                 Bytes({0xC0 | ch, track.program})}) {
      events.push_back({0, 0, e});
    }
    for (const MidiNote& n : track.notes) {
      if (n.midi_note < 0 || n.midi_note > 127) fail("note must be 0..127");
      if (n.velocity < 1 || n.velocity > 127) fail("velocity must be 1..127");
      if (!(n.offset_s > n.onset_s)) fail("note offset must follow its onset");
      events.push_back({tick_of(n.onset_s), 3, Bytes({0x90 | ch, n.midi_note, n.velocity})});
      events.push_back({tick_of(n.offset_s), 1, Bytes({0x80 | ch, n.midi_note, 0})});
    }
    for (const MidiPitchBend& b : track.bends) {
      const double unit = std::clamp(b.semitones / file.bend_range_semitones, -1.0, 1.0);
      const int value = std::clamp(static_cast<int>(std::lround(8192 + unit * 8192)), 0, 16383);
      events.push_back({tick_of(b.time_s), 2, Bytes({0xE0 | ch, value & 0x7F, value >> 7})});
    }
    for (const MidiControl& c : track.controls) {
      if (c.controller < 0 || c.controller > 127 || c.value < 0 || c.value > 127) {
        fail("controller and value must be 0..127");
      }
      events.push_back({tick_of(c.time_s), 2, Bytes({0xB0 | ch, c.controller, c.value})});
    }
    std::stable_sort(events.begin(), events.end(), [](const TimedEvent& x, const TimedEvent& y) {
      return x.tick != y.tick ? x.tick < y.tick : x.order < y.order;
    });
    std::string data;
    int64_t last = 0;
    for (const TimedEvent& e : events) {
      PutVlq(static_cast<uint32_t>(e.tick - last), &data);
      data += e.bytes;
      last = e.tick;
    }
    data += Bytes({0x00, 0xFF, 0x2F, 0x00});  // end of track
    body += Chunk("MTrk", data);
  }
  return body;
}

Status WriteMidiFile(const std::string& path, const MidiFile& file) {
  return AtomicWriteFile(path, EncodeMidi(file));
}

StatusOr<ParsedMidi> ParseMidi(const std::string& bytes) {
  ParsedMidi out;
  size_t pos = 0;
  auto need = [&](size_t n) { return pos + n <= bytes.size(); };
  auto u8 = [&]() { return static_cast<int>(static_cast<unsigned char>(bytes[pos++])); };
  auto big = [&](int n) {
    uint32_t v = 0;
    for (int i = 0; i < n; ++i) v = (v << 8) | static_cast<uint32_t>(u8());
    return v;
  };
  if (!need(14) || bytes.compare(0, 4, "MThd") != 0) return Status::Error("not a MIDI file");
  pos = 4;
  const uint32_t header_length = big(4);
  if (header_length < 6 || !need(header_length)) return Status::Error("bad MIDI header");
  out.format = static_cast<int>(big(2));
  const int tracks = static_cast<int>(big(2));
  out.ticks_per_quarter = static_cast<int>(big(2));
  pos = 8 + header_length;
  for (int t = 0; t < tracks; ++t) {
    if (!need(8) || bytes.compare(pos, 4, "MTrk") != 0) return Status::Error("missing MTrk chunk");
    pos += 4;
    const uint32_t length = big(4);
    if (!need(length)) return Status::Error("truncated MTrk chunk");
    const size_t end = pos + length;
    int64_t tick = 0;
    int running = 0;
    while (pos < end) {
      uint32_t delta = 0;
      for (int i = 0;; ++i) {
        if (pos >= end || i > 3) return Status::Error("bad delta time");
        const int b = u8();
        delta = (delta << 7) | static_cast<uint32_t>(b & 0x7F);
        if (!(b & 0x80)) break;
      }
      tick += delta;
      if (pos >= end) return Status::Error("truncated event");
      int status = static_cast<unsigned char>(bytes[pos]);
      if (status & 0x80) {
        ++pos;
      } else if (running) {
        status = running;
      } else {
        return Status::Error("data byte without status");
      }
      if (status == 0xFF || status == 0xF0 || status == 0xF7) {
        int type = 0;
        if (status == 0xFF) {
          if (pos >= end) return Status::Error("truncated meta event");
          type = u8();
        }
        uint32_t len = 0;
        for (int i = 0;; ++i) {
          if (pos >= end || i > 3) return Status::Error("bad meta length");
          const int b = u8();
          len = (len << 7) | static_cast<uint32_t>(b & 0x7F);
          if (!(b & 0x80)) break;
        }
        if (pos + len > end) return Status::Error("truncated meta event");
        if (status == 0xFF && type == 0x51 && len == 3) {
          out.us_per_quarter = static_cast<int>(big(3));
        } else {
          pos += len;
        }
        continue;
      }
      running = status;
      MidiEvent e;
      e.tick = tick;
      e.track = t;
      e.type = status & 0xF0;
      e.channel = status & 0x0F;
      const int data_bytes = (e.type == 0xC0 || e.type == 0xD0) ? 1 : 2;
      if (pos + data_bytes > end) return Status::Error("truncated channel event");
      e.data1 = u8();
      if (data_bytes == 2) e.data2 = u8();
      out.events.push_back(e);
    }
    pos = end;
  }
  return out;
}

}  // namespace arco::audio
