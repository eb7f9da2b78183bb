#include "arco/audio/sound_truth.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "arco/audio/audio_reader.h"
#include "arco/audio/test_music.h"
#include "arco/util/file_io.h"

namespace arco::audio::testing {
namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

double KeyContour::At(double tau_s) const {
  if (cents.empty() || !(tau_s >= 0)) return kNaN;
  const double x = tau_s / step_s;
  const size_t i = static_cast<size_t>(std::floor(x));
  if (i + 1 >= cents.size()) return i < cents.size() && x == i ? cents[i] : kNaN;
  const double f = x - i;
  return cents[i] + f * (cents[i + 1] - cents[i]);  // NaN propagates
}

Status MeasureKeyContours(const std::string& work_dir, TestMusic* music) {
  const MidiTrack& played = music->midi.tracks[0];
  // Longest sounding time per key (bends speed playback up by at most 2^(2/12)).
  std::map<int, double> longest_s;
  std::map<int, int> velocity;
  for (const auto& n : played.notes) {
    longest_s[n.midi_note] = std::max(longest_s[n.midi_note], n.offset_s - n.onset_s);
    velocity[n.midi_note] = n.velocity;
  }
  // One rendering with every key alone: onset every slot, All Sound Off before
  // each (as in the music), no bends.
  MidiFile file = music->midi;
  MidiTrack& track = file.tracks[0];
  track.notes.clear();
  track.bends.clear();
  track.controls.clear();
  std::map<int, double> onset_s;
  double t = 0.5;
  for (const auto& [key, length_s] : longest_s) {
    const double duration = 1.15 * length_s + 0.1;
    track.notes.push_back({t, t + duration, key, velocity[key]});
    track.bends.push_back({t, 0.0});
    track.controls.push_back({t, 120, 0});
    onset_s[key] = t;
    t += duration + 1.0;
  }
  const std::string base = JoinPath(work_dir, music->instrument + "_keys");
  ARCO_RETURN_IF_ERROR(WriteMidiFile(base + ".mid", file));
  ARCO_RETURN_IF_ERROR(RenderWithFluidsynth(base + ".mid", base + ".wav"));
  ARCO_ASSIGN_OR_RETURN(auto reader, OpenAudio(base + ".wav"));
  const int rate = reader->info().sample_rate_hz;
  std::vector<float> samples, block(1 << 15);
  while (true) {
    ARCO_ASSIGN_OR_RETURN(const int64_t got, reader->ReadMono(block.data(), 1 << 15));
    if (got == 0) break;
    samples.insert(samples.end(), block.begin(), block.begin() + got);
  }
  music->key_contours.clear();
  for (const auto& note : track.notes) {
    const double nominal_hz = 440.0 * std::exp2((note.midi_note - 69.0) / 12.0);
    const int window = HarmonicFitWindow(rate, nominal_hz);
    HarmonicPeakFit fit(rate, window);
    KeyContour contour;
    const double length_s = note.offset_s - note.onset_s;
    for (int i = 0; i * contour.step_s <= length_s; ++i) {
      const double tau = i * contour.step_s;
      const double centre_s = note.onset_s + kFluidsynthLatencyS + tau;
      const int64_t start = std::llround(centre_s * rate) - window / 2;
      double cents = kNaN;
      if (start >= 0 && start + window <= static_cast<int64_t>(samples.size())) {
        const double f0 = fit.F0Hz(samples.data() + start, window, nominal_hz);
        if (std::isfinite(f0)) cents = 1200.0 * std::log2(f0 / nominal_hz);
      }
      contour.cents.push_back(cents);
    }
    music->key_contours[note.midi_note] = std::move(contour);
  }
  return Status::Ok();
}

}  // namespace arco::audio::testing
