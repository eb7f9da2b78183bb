#include "arco/audio/test_music.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>

#include "arco/audio/audio_reader.h"
#include "arco/registry/instruments.h"
#include "arco/util/file_io.h"

namespace arco::audio::testing {
namespace {

struct Range {
  int low, high, program;
};

// From the lowest open string (registry/instruments.h) to a top note that keeps the
// music in the soundfont's well-sampled range.
Range RangeOf(const std::string& instrument) {
  const StatusOr<InstrumentKind> parsed = ParseInstrumentKind(instrument);
  const InstrumentKind kind = parsed.ok() ? *parsed : InstrumentKind::kCello;
  const InstrumentInfo& info = GetInstrumentInfo(kind);
  int high = 76;                                       // cello E5
  if (kind == InstrumentKind::kViolin) high = 98;      // D7 (2349 Hz)
  if (kind == InstrumentKind::kViola) high = 84;       // C6
  if (kind == InstrumentKind::kDoubleBass) high = 55;  // G3
  return {info.open_midi_low_to_high[0], high, info.gm_program};
}

// Bend (semitones) in effect at time t: the last bend event at or before t.
double BendAt(const MidiTrack& track, double t) {
  double bend = 0;
  for (const auto& b : track.bends) {
    if (b.time_s <= t + 1e-9)
      bend = b.semitones;
    else
      break;
  }
  return bend;
}

}  // namespace

TestMusic MakeTestMusic(const std::string& instrument, int notes, uint32_t seed) {
  TestMusic music;
  music.instrument = instrument;
  const Range range = RangeOf(instrument);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  MidiTrack track;
  track.program = range.program;
  track.name = instrument;
  double t = 0.5;
  for (int i = 0; i < notes; ++i) {
    // Sweep the range up and down with random steps so every register is used.
    const double phase = static_cast<double>(i) / std::max(1, notes - 1);
    const double centre =
        range.low + (range.high - range.low) * (1.0 - std::abs(2.0 * phase - 1.0));
    int midi = static_cast<int>(std::lround(centre + (unit(rng) - 0.5) * 6.0));
    midi = std::clamp(midi, range.low, range.high);
    const double duration = 0.45 + 0.5 * unit(rng);
    MidiNote note{t, t + duration, midi, 90};
    track.notes.push_back(note);
    track.bends.push_back({t, 0.0});
    // All Sound Off before each note: the sampled release of the previous note
    // would otherwise ring under this one (a two-note chord, not monophonic
    // truth). The previous note's note-off at the same tick comes first.
    if (i > 0) track.controls.push_back({t, 120, 0});
    if (i % 3 == 1) {  // vibrato: a bend every 10 ms
      const double rate = 5.0 + 1.5 * unit(rng), extent = 0.2 + 0.2 * unit(rng);
      for (double u = 0.01; u < duration; u += 0.01) {
        track.bends.push_back({t + u, extent * std::sin(2.0 * M_PI * rate * u)});
      }
    } else if (i % 10 == 4) {  // glide: up a whole tone over the middle third
      for (double u = duration / 3; u < duration; u += 0.01) {
        const double x = std::min(1.0, (u - duration / 3) / (duration / 3));
        track.bends.push_back({t + u, 2.0 * x});
      }
    }
    t += duration;
    if (i % 6 == 5) t += 1.0;  // rest
  }
  std::stable_sort(
      track.bends.begin(), track.bends.end(), [](const MidiPitchBend& a, const MidiPitchBend& b) {
        return a.time_s < b.time_s;
      });
  music.duration_s = t + 1.0;
  music.midi.bend_range_semitones = 2.0;
  music.midi.tracks.push_back(track);
  return music;
}

TruthVoicing TestMusic::Voicing(double time_s) const {
  const double t = time_s - kFluidsynthLatencyS;
  const auto& notes = midi.tracks[0].notes;
  for (size_t i = 0; i < notes.size(); ++i) {
    const auto& n = notes[i];
    if (t >= n.onset_s + 0.06 && t <= n.offset_s - 0.03) {
      const bool mute = i < silent.size() && silent[i];
      return mute ? TruthVoicing::kUnscored : TruthVoicing::kVoiced;
    }
  }
  for (const auto& n : notes) {
    if (t >= n.onset_s - 0.01 && t < n.offset_s + 0.7) return TruthVoicing::kUnscored;
  }
  return t < 0 ? TruthVoicing::kUnscored : TruthVoicing::kUnvoiced;
}

double TestMusic::F0Hz(double time_s) const {
  if (Voicing(time_s) != TruthVoicing::kVoiced) return 0.0;
  const double t = time_s - kFluidsynthLatencyS;
  const auto& track = midi.tracks[0];
  for (const auto& n : track.notes) {
    if (t >= n.onset_s && t < n.offset_s) {
      return 440.0 * std::exp2((n.midi_note + BendAt(track, t) - 69.0) / 12.0);
    }
  }
  return 0.0;
}

double TestMusic::SoundF0Hz(double time_s) const {
  const double f0 = F0Hz(time_s);
  if (f0 <= 0) return 0.0;
  const double t = time_s - kFluidsynthLatencyS;
  const auto& track = midi.tracks[0];
  for (const auto& n : track.notes) {
    if (t < n.onset_s || t >= n.offset_s) continue;
    auto it = key_contours.find(n.midi_note);
    if (it == key_contours.end()) return 0.0;
    // tau = integral of 2^(bend / 12) from the onset (bends are steps).
    double tau = 0, from = n.onset_s, bend = BendAt(track, n.onset_s);
    for (const auto& b : track.bends) {
      if (b.time_s <= n.onset_s + 1e-9) continue;
      if (b.time_s > t) break;
      tau += (b.time_s - from) * std::exp2(bend / 12.0);
      from = b.time_s;
      bend = b.semitones;
    }
    tau += (t - from) * std::exp2(bend / 12.0);
    const double cents = it->second.At(tau);
    return std::isfinite(cents) ? f0 * std::exp2(cents / 1200.0) : 0.0;
  }
  return 0.0;
}

Status WriteTruthCsv(const std::string& path, const TestMusic& music, double rate_hz, bool sound) {
  return AtomicWriteWith(path, [&](std::ostream& out) {
    out << "time_s,f0_hz,voicing\n";
    char line[96];
    for (int64_t i = 0; i / rate_hz < music.duration_s; ++i) {
      const double t = i / rate_hz;
      const TruthVoicing v = music.Voicing(t);
      int code = v == TruthVoicing::kVoiced ? 1 : (v == TruthVoicing::kUnvoiced ? 0 : -1);
      const double f0 = sound ? music.SoundF0Hz(t) : music.F0Hz(t);
      if (code == 1 && f0 <= 0) code = -1;
      std::snprintf(line, sizeof(line), "%.6f,%.4f,%d\n", t, f0, code);
      out << line;
    }
    return Status::Ok();
  });
}

Status MarkSilentNotes(const std::string& wav_path, TestMusic* music) {
  ARCO_ASSIGN_OR_RETURN(auto reader, OpenAudio(wav_path));
  const double rate = reader->info().sample_rate_hz;
  std::vector<float> samples, block(1 << 15);
  while (true) {
    ARCO_ASSIGN_OR_RETURN(const int64_t n, reader->ReadMono(block.data(), 1 << 15));
    if (n == 0) break;
    samples.insert(samples.end(), block.begin(), block.begin() + n);
  }
  const auto& notes = music->midi.tracks[0].notes;
  music->silent.assign(notes.size(), 0);
  for (size_t i = 0; i < notes.size(); ++i) {
    const int64_t a = static_cast<int64_t>((notes[i].onset_s + 0.06 + kFluidsynthLatencyS) * rate);
    const int64_t b = std::min<int64_t>(static_cast<int64_t>(samples.size()),
                                        static_cast<int64_t>((notes[i].offset_s - 0.03) * rate));
    double energy = 0;
    for (int64_t k = a; k < b; ++k) energy += double(samples[k]) * samples[k];
    const double rms = b > a ? std::sqrt(energy / (b - a)) : 0.0;
    music->silent[i] = rms < std::pow(10.0, -45.0 / 20.0);
  }
  return Status::Ok();
}

Status RenderWithFluidsynth(const std::string& midi_path,
                            const std::string& wav_path,
                            int sample_rate_hz) {
  if (!FileExists(kSoundfont)) return Status::Error(std::string(kSoundfont) + ": no soundfont");
  const std::string command = "fluidsynth -ni -q -R 0 -C 0 -g 1.0 -r " +
                              std::to_string(sample_rate_hz) + " -F '" + wav_path + "' '" +
                              kSoundfont + "' '" + midi_path + "' >/dev/null 2>&1";
  if (std::system(command.c_str()) != 0 || !FileExists(wav_path)) {
    return Status::Error(wav_path + ": fluidsynth rendering failed");
  }
  return Status::Ok();
}

}  // namespace arco::audio::testing
