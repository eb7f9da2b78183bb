#include "arco/synth/midi_reader.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "arco/synth/test_instruments.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"

namespace arco::synth {
namespace {

using arco::testing::PerProcessTempDir;

// Builds SMF bytes by hand so the reader is tested independently of any writer.
std::string Be(uint32_t v, int n) {
  std::string s;
  for (int i = n - 1; i >= 0; --i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
  return s;
}
std::string Vlq(uint32_t v) {
  std::string s(1, static_cast<char>(v & 0x7f));
  while (v >>= 7) s.insert(s.begin(), static_cast<char>(0x80 | (v & 0x7f)));
  return s;
}
std::string Header(int format, int tracks, int division) {
  return "MThd" + Be(6, 4) + Be(format, 2) + Be(tracks, 2) + Be(division, 2);
}
std::string Track(const std::string& events) {
  const std::string body = events + Vlq(0) + "\xff\x2f" + std::string(1, '\0');
  return "MTrk" + Be(static_cast<uint32_t>(body.size()), 4) + body;
}
std::string Ev(uint32_t delta, std::vector<int> bytes) {
  std::string s = Vlq(delta);
  for (int b : bytes) s.push_back(static_cast<char>(b));
  return s;
}
std::string Tempo(uint32_t delta, uint32_t us) { return Vlq(delta) + "\xff\x51\x03" + Be(us, 3); }

TEST(ParseMidiScore, ReadsFormat0WithTempoAndRunningStatus) {
  // 480 ticks per quarter, 100 bpm (600000 us): a quarter = 0.6 s.
  std::string ev = Tempo(0, 600000);
  ev += Ev(0, {0x90, 48, 90});     // C3 on
  ev += Ev(480, {48, 0});          // running status: note-on vel 0 = off
  ev += Ev(0, {50, 70});           // D3 on (running status)
  ev += Ev(240, {0x80, 50, 0});    // D3 off after an eighth
  ev += Ev(240, {0x99, 36, 100});  // drum channel: ignored
  ev += Ev(0, {0x90, 52, 80});     // E3 on at 1.2 s
  ev += Ev(960, {0x80, 52, 0});
  auto score = ParseMidiScore(Header(0, 1, 480) + Track(ev), "t.mid");
  ASSERT_TRUE(score.ok()) << score.status().message();
  ASSERT_EQ(score->notes.size(), 3u);
  EXPECT_EQ(score->notes[0].midi_note, 48);
  EXPECT_NEAR(score->notes[0].onset_s, 0.0, 1e-12);
  EXPECT_NEAR(score->notes[0].offset_s, 0.6, 1e-12);
  EXPECT_EQ(score->notes[0].velocity, 90);
  EXPECT_NEAR(score->notes[1].offset_s, 0.9, 1e-12);
  EXPECT_NEAR(score->notes[2].onset_s, 1.2, 1e-12);
  EXPECT_NEAR(score->notes[2].offset_s, 2.4, 1e-12);
  EXPECT_EQ(score->name, "t.mid");
}

TEST(ParseMidiScore, Format1TempoChangeInConductorTrack) {
  // Conductor track: 120 bpm, then 60 bpm from tick 960 (2 quarters = 1.0 s).
  const std::string conductor = Track(Tempo(0, 500000) + Tempo(960, 1000000));
  std::string ev = Ev(0, {0x90, 60, 80}) + Ev(960, {0x80, 60, 0});  // 0 .. 1.0 s
  ev += Ev(0, {0x90, 62, 80}) + Ev(480, {0x80, 62, 0});             // 1.0 .. 2.0 s
  auto score = ParseMidiScore(Header(1, 2, 480) + conductor + Track(ev), "f1.mid");
  ASSERT_TRUE(score.ok()) << score.status().message();
  ASSERT_EQ(score->notes.size(), 2u);
  EXPECT_NEAR(score->notes[0].offset_s, 1.0, 1e-12);
  EXPECT_NEAR(score->notes[1].onset_s, 1.0, 1e-12);
  EXPECT_NEAR(score->notes[1].offset_s, 2.0, 1e-12);
}

TEST(ParseMidiScore, CutsOverlapsAndRejectsChords) {
  std::string ev = Ev(0, {0x90, 60, 80}) + Ev(600, {0x90, 62, 80}) + Ev(100, {0x80, 60, 0}) +
                   Ev(400, {0x80, 62, 0});
  auto score = ParseMidiScore(Header(0, 1, 480) + Track(ev), "o.mid");
  ASSERT_TRUE(score.ok()) << score.status().message();
  ASSERT_EQ(score->notes.size(), 2u);
  EXPECT_NEAR(score->notes[0].offset_s, score->notes[1].onset_s, 1e-12);

  std::string chord =
      Ev(0, {0x90, 60, 80}) + Ev(0, {0x90, 64, 80}) + Ev(480, {0x80, 60, 0}) + Ev(0, {0x80, 64, 0});
  auto c = ParseMidiScore(Header(0, 1, 480) + Track(chord), "c.mid");
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("start together at 0.000 s"), std::string::npos)
      << c.status().message();
}

TEST(ParseMidiScore, RejectsMalformedFiles) {
  const std::string good =
      Header(0, 1, 480) + Track(Ev(0, {0x90, 60, 80}) + Ev(480, {0x80, 60, 0}));
  EXPECT_FALSE(ParseMidiScore("", "e.mid").ok());
  EXPECT_FALSE(ParseMidiScore("RIFF0000WAVEfmt ", "w.mid").ok());
  // Every truncation is an error or a valid score, never a crash.
  for (size_t n = 0; n < good.size(); ++n) {
    auto s = ParseMidiScore(good.substr(0, n), "trunc.mid");
    if (s.ok()) {
      EXPECT_FALSE(s->notes.empty());
    }
  }
  // Data byte without status.
  auto d = ParseMidiScore(Header(0, 1, 480) + Track(Ev(0, {60, 80})), "d.mid");
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.status().message().find("d.mid: track 1"), std::string::npos);
  // No notes.
  EXPECT_FALSE(ParseMidiScore(Header(0, 1, 480) + Track(Tempo(0, 500000)), "n.mid").ok());
  EXPECT_FALSE(ParseMidiScore(Header(2, 1, 480) + Track(""), "f2.mid").ok());
  EXPECT_FALSE(ParseMidiScore(Header(0, 1, 0) + Track(""), "z.mid").ok());
}

TEST(ReadMidiScore, NamesTheNoteOutsideTheRange) {
  const std::string bytes =
      Header(0, 1, 480) + Track(Ev(0, {0x90, 57, 80}) + Ev(480, {0x80, 57, 0}) +
                                Ev(0, {0x90, 90, 80}) + Ev(480, {0x80, 90, 0}));
  const std::string path = PerProcessTempDir() + "/high.mid";
  ASSERT_TRUE(AtomicWriteFile(path, bytes).ok());
  auto score = ReadMidiScore(path, testing::Cello());
  ASSERT_FALSE(score.ok());
  EXPECT_EQ(score.status().message(),
            path + ": note 90 (F#6) at 0.500 s is outside the cello's range C2 (36) to A5 (81)");
  EXPECT_TRUE(ReadMidiScore(path, testing::Violin()).ok());
  EXPECT_FALSE(ReadMidiScore(PerProcessTempDir() + "/missing.mid", testing::Cello()).ok());
}

}  // namespace
}  // namespace arco::synth
