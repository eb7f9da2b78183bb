#include "arco/synth/audio_render.h"

#include <sndfile.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <tuple>
#include <vector>

#include "arco/audio/audio_reader.h"
#include "arco/audio/harmonic_fit.h"
#include "arco/synth/random.h"
#include "arco/util/file_io.h"
#include "arco/util/stats.h"

namespace arco::synth {
namespace {

constexpr double kProbeNoteS = 0.8, kProbeGapS = 0.4;

std::string Quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

Status RunFluidsynth(const AudioRenderOptions& o, const std::string& midi, const std::string& wav) {
  std::error_code ec;
  std::filesystem::remove(wav, ec);
  const std::string cmd = "fluidsynth -ni -q -R 0 -C 0 -r " + std::to_string(o.sample_rate_hz) +
                          " -F " + Quote(wav) + " " + Quote(o.soundfont) + " " + Quote(midi) +
                          " >/dev/null 2>&1";
  if (std::system(cmd.c_str()) != 0 || !FileExists(wav)) {
    return Status::Error(wav + ": fluidsynth failed (is the fluidsynth package installed?)");
  }
  return Status::Ok();
}

StatusOr<std::vector<float>> ReadMonoSamples(const std::string& wav, int* sample_rate_hz) {
  ARCO_ASSIGN_OR_RETURN(auto reader, audio::OpenAudio(wav));
  *sample_rate_hz = reader->info().sample_rate_hz;
  std::vector<float> samples, block(1 << 15);
  while (true) {
    ARCO_ASSIGN_OR_RETURN(const int64_t got, reader->ReadMono(block.data(), 1 << 15));
    if (got == 0) break;
    samples.insert(samples.end(), block.begin(), block.begin() + got);
  }
  return samples;
}

// Pitch contour of each key's sample, rendered alone (unbent) and measured with
// the harmonic-peak fit (audio/harmonic_fit.h), not with arco's pitch tracker:
// the rendered audio is the truth arco's tracker is scored against, so its
// tuning must not depend on that tracker's own biases.
StatusOr<std::map<int, SampleContour>> MeasureContours(const std::map<int, double>& key_duration_s,
                                                       int program,
                                                       double a4_hz,
                                                       const AudioRenderOptions& o,
                                                       const std::string& work_dir) {
  audio::MidiFile probe;
  audio::MidiTrack track;
  track.program = program;
  double t = 0.1;
  std::vector<std::tuple<int, double, double>> probes;  // key, onset, duration
  for (const auto& [key, dur] : key_duration_s) {
    const double d = std::clamp(dur + 0.1, kProbeNoteS, 20.0);
    track.controls.push_back({t, 120, 0});
    track.notes.push_back({t, t + d, key, 80});
    probes.emplace_back(key, t, d);
    t += d + kProbeGapS;
  }
  probe.tracks.push_back(track);
  const std::string midi = JoinPath(work_dir, "tuning_probe.mid");
  const std::string wav = JoinPath(work_dir, "tuning_probe.wav");
  ARCO_RETURN_IF_ERROR(audio::WriteMidiFile(midi, probe));
  ARCO_RETURN_IF_ERROR(RunFluidsynth(o, midi, wav));
  int rate = 0;
  ARCO_ASSIGN_OR_RETURN(const std::vector<float> samples, ReadMonoSamples(wav, &rate));
  std::map<int, SampleContour> contours;
  for (const auto& [key, onset, dur] : probes) {
    SampleContour c;
    const double expected = a4_hz * std::pow(2.0, (key - 69) / 12.0);
    const int n = static_cast<int>(dur / c.step_s);
    c.cents.assign(static_cast<size_t>(n), NAN);
    const int window = audio::HarmonicFitWindow(rate, expected);
    audio::HarmonicPeakFit fit(rate, window);
    std::vector<double> valid;
    for (int j = 0; j < n; ++j) {
      if (j * c.step_s < 0.06) continue;  // the attack is unreliable
      // Sample time tau is heard at onset + latency + tau (window centred there).
      const double time = onset + o.latency_s + j * c.step_s;
      const int64_t start = std::llround(time * rate) - window / 2;
      if (start < 0 || start + window > static_cast<int64_t>(samples.size())) continue;
      const double f0 = fit.F0Hz(samples.data() + start, window, expected);
      if (!std::isfinite(f0)) continue;
      const double cents = 1200 * std::log2(f0 / expected);
      if (std::abs(cents) > 60) continue;  // slides into the note
      c.cents[static_cast<size_t>(j)] = cents;
      valid.push_back(cents);
    }
    if (valid.size() < 20) continue;  // not measurable: leave this key uncompensated
    c.median_cents = UpperMedianInPlace(valid.begin(), valid.end());
    // Holes (attack, unvoiced rows) take the nearest earlier value, else the median.
    double last = c.median_cents;
    for (double& v : c.cents) {
      if (std::isnan(v)) {
        v = last;
      } else {
        last = v;
      }
    }
    contours[key] = std::move(c);
  }
  std::error_code ec;
  std::filesystem::remove(wav, ec);
  std::filesystem::remove(midi, ec);
  return contours;
}

Status AddRoomNoise(const std::string& wav, double dbfs, uint64_t seed) {
  SF_INFO info{};
  SNDFILE* in = sf_open(wav.c_str(), SFM_READ, &info);
  if (!in) return Status::Error(wav + ": cannot read the rendered audio");
  std::vector<float> samples(static_cast<size_t>(info.frames * info.channels));
  const sf_count_t got = sf_readf_float(in, samples.data(), info.frames);
  sf_close(in);
  if (got != info.frames) return Status::Error(wav + ": short read of the rendered audio");
  // Brownish room noise: white Gaussian through a one-pole low-pass (~1 kHz),
  // scaled to the requested RMS.
  Rng rng = Rng::Stream(seed, 303);
  const double a = std::exp(-2 * 3.141592653589793 * 1000.0 / info.samplerate);
  const double gain = std::pow(10.0, dbfs / 20.0) / std::sqrt((1 - a) / (1 + a));
  double state = 0;
  for (sf_count_t i = 0; i < info.frames; ++i) {
    state = a * state + (1 - a) * rng.Normal();
    for (int c = 0; c < info.channels; ++c) {
      float& s = samples[static_cast<size_t>(i * info.channels + c)];
      s = static_cast<float>(std::clamp(s + gain * state, -1.0, 1.0));
    }
  }
  const std::string tmp = wav + ".noise.wav";
  SF_INFO out_info = info;
  out_info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
  SNDFILE* out = sf_open(tmp.c_str(), SFM_WRITE, &out_info);
  if (!out) return Status::Error(tmp + ": cannot write: " + sf_strerror(nullptr));
  const sf_count_t put = sf_writef_float(out, samples.data(), info.frames);
  sf_close(out);
  std::error_code ec;
  if (put != info.frames) {
    std::filesystem::remove(tmp, ec);
    return Status::Error(tmp + ": short write");
  }
  std::filesystem::rename(tmp, wav, ec);
  if (ec) return Status::Error(wav + ": " + ec.message());
  return Status::Ok();
}

}  // namespace

Status AudioRenderOptions::Validate() const {
  if (sample_rate_hz < 8000 || sample_rate_hz > 192000)
    return Status::Error("audio rate must be 8-192 kHz");
  if (!(bend_step_s > 0 && bend_step_s <= 0.05))
    return Status::Error("bend step must be in (0, 0.05] s");
  if (!(latency_s >= 0 && latency_s < 0.1)) return Status::Error("latency must be in [0, 0.1) s");
  if (!(room_noise_dbfs <= 0 && room_noise_dbfs > -200)) {
    return Status::Error("room noise must be in (-200, 0] dBFS (0 = none)");
  }
  if (soundfont.empty()) return Status::Error("no soundfont given");
  return Status::Ok();
}

double SampleContour::At(double sample_time_s) const {
  if (cents.empty()) return 0;
  const double x = std::max(0.0, sample_time_s / step_s);
  const auto i = static_cast<size_t>(x);
  if (i + 1 >= cents.size()) return cents.back();
  const double u = x - static_cast<double>(i);
  return cents[i] + u * (cents[i + 1] - cents[i]);
}

audio::MidiFile PerformanceToMidi(const Performance& perf,
                                  int gm_program,
                                  const std::map<int, SampleContour>& contours,
                                  const AudioRenderOptions& o) {
  audio::MidiFile file;
  audio::MidiTrack track;
  track.name = "arco synth";
  track.program = gm_program;
  // The upper notes of double stops on a second channel: pitch bends are per channel.
  audio::MidiTrack second = track;
  second.name = "arco synth, double stops' upper notes";
  second.channel = 1;
  auto add = [&](const PerformedNote& n, int key, bool upper, audio::MidiTrack* out) {
    const double lead = o.latency_s;
    const double onset = std::max(0.0, n.note.onset_s - lead);
    const double offset = std::max(onset + 0.01, n.note.offset_s - lead);
    auto it = contours.find(key);
    const SampleContour* contour = it == contours.end() ? nullptr : &it->second;
    out->controls.push_back({onset, 120, 0});
    out->notes.push_back({onset, offset, key, n.note.velocity});
    // The first bend goes with the note-on; then every bend_step_s. The sample
    // plays at 2^(bend/12) of its speed, so its own time runs at that rate.
    double sample_time_s = 0;
    for (double t = n.note.onset_s; t < n.note.offset_s; t += o.bend_step_s) {
      const double cents = (upper ? n.SecondCentsAt(t) : n.CentsAt(t)) -
                           (contour ? contour->At(sample_time_s) : 0.0);
      out->bends.push_back({std::max(0.0, t - lead), cents / 100.0});
      sample_time_s += o.bend_step_s * std::pow(2.0, cents / 1200.0);
    }
  };
  for (const PerformedNote& n : perf.notes) {
    add(n, n.note.midi_note, false, &track);
    if (n.note.IsDoubleStop()) add(n, n.note.second_midi_note, true, &second);
  }
  file.tracks.push_back(track);
  if (!second.notes.empty()) file.tracks.push_back(second);
  return file;
}

Status RenderPerformanceAudio(const Performance& perf,
                              int gm_program,
                              const AudioRenderOptions& o,
                              const std::string& work_dir,
                              const std::string& midi_path,
                              const std::string& wav_path,
                              uint64_t seed,
                              AudioRenderSummary* summary) {
  ARCO_RETURN_IF_ERROR(o.Validate());
  if (!FileExists(o.soundfont)) return Status::Error(o.soundfont + ": soundfont not found");
  std::map<int, SampleContour> contours;
  if (o.tune_soundfont) {
    std::map<int, double> key_duration_s;
    for (const PerformedNote& n : perf.notes) {
      for (int key : {n.note.midi_note, n.note.second_midi_note}) {
        if (key <= 0) continue;
        double& d = key_duration_s[key];
        d = std::max(d, n.note.offset_s - n.note.onset_s);
      }
    }
    ARCO_ASSIGN_OR_RETURN(contours,
                          MeasureContours(key_duration_s, gm_program, perf.a4_hz, o, work_dir));
  }
  ARCO_RETURN_IF_ERROR(
      audio::WriteMidiFile(midi_path, PerformanceToMidi(perf, gm_program, contours, o)));
  ARCO_RETURN_IF_ERROR(RunFluidsynth(o, midi_path, wav_path));
  if (o.room_noise_dbfs < 0) ARCO_RETURN_IF_ERROR(AddRoomNoise(wav_path, o.room_noise_dbfs, seed));
  if (summary) {
    for (const auto& [key, c] : contours) summary->key_offset_cents[key] = c.median_cents;
    summary->duration_s = perf.duration_s;
    summary->midi_path = midi_path;
  }
  return Status::Ok();
}

}  // namespace arco::synth
