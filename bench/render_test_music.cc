// Writes the benchmark music for bench/pitch_peers.sh: for each instrument a
// seeded melody (test_music.h) as MIDI, its per-frame truth CSV and the
// fluidsynth rendering, plus INSTRUMENT_truth_sound.csv: the same frames with
// f0 corrected by each key's measured sound (sound_truth.h). usage: render_test_music OUT_DIR
// [NOTES] [SEED]
#include <cstdio>
#include <cstdlib>
#include <string>

#include "arco/audio/test_music.h"
#include "arco/util/file_io.h"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: render_test_music OUT_DIR [NOTES] [SEED]\n");
    return 2;
  }
  const std::string dir = argv[1];
  const int notes = argc > 2 ? std::atoi(argv[2]) : 60;
  const unsigned seed = argc > 3 ? static_cast<unsigned>(std::atoi(argv[3])) : 11;
  if (!arco::MakeDirectories(dir).ok()) return 1;
  for (const char* instrument : {"cello", "violin", "viola", "bass"}) {
    auto music = arco::audio::testing::MakeTestMusic(instrument, notes, seed);
    const std::string base = arco::JoinPath(dir, instrument);
    arco::Status s = arco::audio::WriteMidiFile(base + ".mid", music.midi);
    if (s.ok()) s = arco::audio::testing::RenderWithFluidsynth(base + ".mid", base + ".wav");
    if (s.ok()) s = arco::audio::testing::MarkSilentNotes(base + ".wav", &music);
    if (s.ok()) s = arco::audio::testing::WriteTruthCsv(base + "_truth.csv", music, 100.0);
    if (s.ok()) s = arco::audio::testing::MeasureKeyContours(dir, &music);
    if (s.ok()) {
      s = arco::audio::testing::WriteTruthCsv(base + "_truth_sound.csv", music, 100.0, true);
    }
    if (!s.ok()) {
      std::fprintf(stderr, "render_test_music: %s\n", s.message().c_str());
      return 1;
    }
    std::printf("%s.wav %.1f s\n", base.c_str(), music.duration_s);
  }
  return 0;
}
