// Note segmentation, vibrato and glides on pitch tracks with known truth.
#include "arco/audio/notes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"

namespace arco::audio {
namespace {

constexpr double kFps = 120.0;

// A fine track from f0(t) (<= 0: unvoiced), like TrackPitch produces.
std::vector<PitchFrame> Track(const std::function<double(double)>& f0, double seconds) {
  std::vector<PitchFrame> fine;
  for (int j = 0; j < static_cast<int>(seconds * kFps); ++j) {
    PitchFrame f;
    f.frame = j;
    f.time_s = j / kFps;
    const double hz = f0(f.time_s);
    f.voiced = hz > 0;
    f.f0_hz = f.voiced ? hz : 0;
    f.confidence = f.voiced ? 0.9 : 0.0;
    fine.push_back(f);
  }
  return fine;
}

double Hz(double midi, double cents = 0) {
  return 440.0 * std::exp2((midi + cents / 100 - 69) / 12);
}

TEST(SegmentNotes, LegatoScaleWithIntonationAndGaps) {
  // C3 (+10 cents) 0.0-0.5, D3 (-20 cents) 0.5-1.0 (legato), rest, E3 1.2-1.6.
  auto f0 = [](double t) {
    if (t < 0.5) return Hz(48, 10);
    if (t < 1.0) return Hz(50, -20);
    if (t < 1.2) return 0.0;
    if (t < 1.6) return Hz(52);
    return 0.0;
  };
  const auto analysis = SegmentNotes(Track(f0, 2.0), kFps, NoteOptions());
  ASSERT_EQ(analysis.notes.size(), 3u);
  EXPECT_TRUE(analysis.glides.empty());
  const int midi[] = {48, 50, 52};
  const double cents[] = {10, -20, 0};
  const double onset[] = {0.0, 0.5, 1.2}, offset[] = {0.5, 1.0, 1.6};
  for (int i = 0; i < 3; ++i) {
    const Note& n = analysis.notes[i];
    EXPECT_EQ(n.midi_note, midi[i]);
    EXPECT_NEAR(n.cents_from_et, cents[i], 0.01);
    EXPECT_NEAR(n.median_f0_hz, Hz(midi[i], cents[i]), 1e-6);
    // The moving median moves the legato boundary by at most a frame or two.
    EXPECT_NEAR(n.onset_s, onset[i], 2.5 / kFps) << i;
    EXPECT_NEAR(n.offset_s, offset[i], 2.5 / kFps) << i;
    EXPECT_EQ(n.vibrato_rate_hz, 0.0);
  }
  EXPECT_EQ(NoteName(48), "C3");
  EXPECT_EQ(NoteName(61), "C#4");
  EXPECT_EQ(NoteName(36), "C2");
}

TEST(SegmentNotes, VibratoRateAndExtent) {
  for (double rate : {4.5, 6.0, 7.5}) {
    for (double extent : {15.0, 40.0}) {
      auto f0 = [&](double t) { return Hz(57, extent * std::sin(2 * M_PI * rate * t)); };
      const auto analysis = SegmentNotes(Track(f0, 1.5), kFps, NoteOptions());
      ASSERT_EQ(analysis.notes.size(), 1u) << rate << " " << extent;
      const Note& n = analysis.notes[0];
      EXPECT_EQ(n.midi_note, 57);
      EXPECT_NEAR(n.vibrato_rate_hz, rate, 0.1 * rate) << rate;
      EXPECT_NEAR(n.vibrato_extent_cents, extent, 0.15 * extent) << extent;
    }
  }
}

TEST(SegmentNotes, GlideBetweenTwoNotes) {
  // A2 held, 0.2 s portamento up a fifth, E3 held.
  auto f0 = [](double t) {
    if (t < 0.6) return Hz(45);
    if (t < 0.8) return Hz(45 + 7 * (t - 0.6) / 0.2);
    return Hz(52);
  };
  const auto analysis = SegmentNotes(Track(f0, 1.5), kFps, NoteOptions());
  ASSERT_EQ(analysis.glides.size(), 1u);
  const Glide& g = analysis.glides[0];
  EXPECT_NEAR(g.start_s, 0.6, 0.06);
  EXPECT_NEAR(g.end_s, 0.8, 0.06);
  EXPECT_LT(g.start_f0_hz, g.end_f0_hz);
  ASSERT_EQ(analysis.notes.size(), 2u);
  EXPECT_EQ(analysis.notes[0].midi_note, 45);
  EXPECT_EQ(analysis.notes[1].midi_note, 52);
}

TEST(SegmentNotes, SilenceGivesNothingAndBadOptionsThrow) {
  const auto analysis = SegmentNotes(Track([](double) { return 0.0; }, 1.0), kFps, NoteOptions());
  EXPECT_TRUE(analysis.notes.empty());
  EXPECT_TRUE(analysis.glides.empty());
  NoteOptions bad;
  bad.min_note_s = -1;
  EXPECT_FALSE(bad.Validate().ok());
  EXPECT_THROW(SegmentNotes({}, kFps, bad), std::invalid_argument);
}

TEST(NotesToMidi, BendsFollowThePitchInsideNotes) {
  auto f0 = [](double t) { return t < 1.0 ? Hz(57, 30 * std::sin(2 * M_PI * 5 * t)) : 0.0; };
  const auto fine = Track(f0, 1.2);
  const auto analysis = SegmentNotes(fine, kFps, NoteOptions());
  ASSERT_EQ(analysis.notes.size(), 1u);
  const MidiFile file = NotesToMidi(analysis, fine, NoteOptions(), 42);
  ASSERT_EQ(file.tracks.size(), 1u);
  const auto& track = file.tracks[0];
  EXPECT_EQ(track.program, 42);
  ASSERT_EQ(track.notes.size(), 1u);
  EXPECT_EQ(track.notes[0].midi_note, 57);
  ASSERT_GT(track.bends.size(), 50u);
  double max_bend = 0;
  for (const auto& b : track.bends) {
    max_bend = std::max(max_bend, std::abs(b.semitones));
    EXPECT_NEAR(b.semitones * 100, 30 * std::sin(2 * M_PI * 5 * b.time_s), 1.0);
  }
  EXPECT_NEAR(max_bend, 0.30, 0.01);
}

TEST(ReadNotesCsv, ReadsBackTheNotesOfWriteNotesCsv) {
  arco::testing::TempDir dir;
  NoteAnalysis a;
  Note n1;
  n1.onset_s = 0.5;
  n1.offset_s = 0.9;
  n1.median_f0_hz = 220.0;
  n1.midi_note = 57;
  Note n2 = n1;
  n2.onset_s = 1.0;
  n2.offset_s = 1.5;
  n2.median_f0_hz = 246.9;
  a.notes = {n1, n2};
  a.glides.push_back({0.9, 1.0, 220.0, 246.9});
  const std::string path = dir / "notes.csv";
  ASSERT_TRUE(WriteNotesCsv(path, a).ok());
  const auto back = ReadNotesCsv(path);
  ASSERT_TRUE(back.ok()) << back.status().message();
  ASSERT_EQ(back->size(), 2u);  // glides are not read back
  EXPECT_DOUBLE_EQ((*back)[1].onset_s, 1.0);
  EXPECT_DOUBLE_EQ((*back)[1].offset_s, 1.5);
  EXPECT_DOUBLE_EQ((*back)[1].median_f0_hz, 246.9);
}

// What `arco run` hands to the refinement (ParseNotesCsv(FormatNotesCsv(...))) is the
// file's notes, value for value.
TEST(ParseNotesCsv, OfFormatNotesCsvIsWhatTheFileReadsBackAs) {
  arco::testing::TempDir dir;
  NoteAnalysis a;
  for (int i = 0; i < 10; ++i) {
    Note n;
    n.onset_s = 0.123456789 * i;
    n.offset_s = n.onset_s + 0.1 / 3;
    n.median_f0_hz = 110.0 * std::pow(2.0, i / 12.0);
    n.midi_note = 45 + i;
    a.notes.push_back(n);
  }
  a.glides.push_back({0.2, 0.25, 220.0, 246.9});
  const std::string path = dir / "notes.csv";
  ASSERT_TRUE(WriteNotesCsv(path, a).ok());
  EXPECT_EQ(*ReadFileToString(path), FormatNotesCsv(a));
  const auto file = ReadNotesCsv(path);
  const auto memory = ParseNotesCsv(FormatNotesCsv(a), path);
  ASSERT_TRUE(file.ok() && memory.ok());
  ASSERT_EQ(file->size(), memory->size());
  for (size_t i = 0; i < file->size(); ++i) {
    EXPECT_EQ((*file)[i].onset_s, (*memory)[i].onset_s);
    EXPECT_EQ((*file)[i].offset_s, (*memory)[i].offset_s);
    EXPECT_EQ((*file)[i].median_f0_hz, (*memory)[i].median_f0_hz);
  }
}

TEST(ReadNotesCsv, MalformedFilesNameTheFileAndLine) {
  arco::testing::TempDir dir;
  const std::string path = dir / "notes.csv";
  EXPECT_FALSE(ReadNotesCsv(path).ok());  // missing
  ASSERT_TRUE(AtomicWriteFile(path, "frame,time_s\n").ok());
  EXPECT_FALSE(ReadNotesCsv(path).ok());
  const std::string header = std::string(kNotesCsvHeader) + "\n";
  for (const char* row : {"note,0.5,x,220,57,A3,0,0,0,,\n",
                          "note,0.5,0.4,220,57,A3,0,0,0,,\n",
                          "note,0.5,0.6,0,57,A3,0,0,0,,\n",
                          "chord,0.5,0.6,220,57,A3,0,0,0,,\n"}) {
    ASSERT_TRUE(AtomicWriteFile(path, header + row).ok());
    const auto r = ReadNotesCsv(path);
    ASSERT_FALSE(r.ok()) << row;
    EXPECT_EQ(r.status().message().rfind(path + ":2: ", 0), 0u) << r.status().message();
  }
  // A row cut short is refused as pitch.csv's are, though the cells read back are there.
  ASSERT_TRUE(
      AtomicWriteFile(path, header + "note,0.5,0.6,220,57,A3,0,0,0,,\nnote,1.0,1.5,220\n").ok());
  const auto cut = ReadNotesCsv(path);
  ASSERT_FALSE(cut.ok());
  EXPECT_EQ(cut.status().message(), path + ":3: expected 11 fields (as the header), found 4");
  ASSERT_TRUE(AtomicWriteFile(
                  path, header + "note,1.0,1.2,220,57,A3,0,0,0,,\nnote,0.5,0.6,220,57,A3,0,0,0,,\n")
                  .ok());
  EXPECT_FALSE(ReadNotesCsv(path).ok());  // onsets out of order
}

}  // namespace
}  // namespace arco::audio
