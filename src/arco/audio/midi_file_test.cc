// MIDI writing: round trip through the reader, tick arithmetic, bend values.
#include "arco/audio/midi_file.h"

#include <gtest/gtest.h>

namespace arco::audio {
namespace {

TEST(EncodeMidi, RoundTripsNotesProgramsAndBends) {
  MidiFile file;
  MidiTrack cello;
  cello.program = 42;
  cello.channel = 0;
  cello.notes = {{0.5, 1.5, 48, 90}, {1.5, 2.0, 50, 70}};
  cello.bends = {{0.5, 0.0}, {1.0, 0.5}, {1.2, -2.0}, {1.3, -5.0}};  // -5 clamps to -2
  MidiTrack violin;
  violin.program = 40;
  violin.channel = 1;
  violin.notes = {{0.25, 0.75, 76, 100}};
  file.tracks = {cello, violin};
  auto parsed = ParseMidi(EncodeMidi(file));
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  EXPECT_EQ(parsed->format, 1);
  EXPECT_EQ(parsed->ticks_per_quarter, 960);
  EXPECT_EQ(parsed->us_per_quarter, 500000);
  std::vector<MidiEvent> notes_on, bends, programs, rpn;
  for (const auto& e : parsed->events) {
    if (e.type == 0x90) notes_on.push_back(e);
    if (e.type == 0xE0) bends.push_back(e);
    if (e.type == 0xC0) programs.push_back(e);
    if (e.type == 0xB0 && e.data1 == 6) rpn.push_back(e);
  }
  ASSERT_EQ(notes_on.size(), 3u);
  EXPECT_EQ(notes_on[0].tick, 960);  // 0.5 s at 1920 ticks/s
  EXPECT_EQ(notes_on[0].data1, 48);
  EXPECT_EQ(notes_on[0].data2, 90);
  EXPECT_EQ(notes_on[2].channel, 1);
  EXPECT_EQ(notes_on[2].tick, 480);
  ASSERT_EQ(programs.size(), 2u);
  EXPECT_EQ(programs[0].data1, 42);
  EXPECT_EQ(programs[1].data1, 40);
  ASSERT_EQ(rpn.size(), 2u);
  EXPECT_EQ(rpn[0].data2, 2);  // bend range 2 semitones
  ASSERT_EQ(bends.size(), 4u);
  auto value = [](const MidiEvent& e) { return e.data1 | (e.data2 << 7); };
  EXPECT_EQ(value(bends[0]), 8192);
  EXPECT_EQ(value(bends[1]), 8192 + 2048);
  EXPECT_EQ(value(bends[2]), 0);
  EXPECT_EQ(value(bends[3]), 0);
  // At the same tick the bend precedes the note on (notes start at their pitch).
  size_t bend_index = 0, on_index = 0;
  for (size_t i = 0; i < parsed->events.size(); ++i) {
    const auto& e = parsed->events[i];
    if (e.track == 0 && e.tick == 960 && e.type == 0xE0) bend_index = i;
    if (e.track == 0 && e.tick == 960 && e.type == 0x90) on_index = i;
  }
  EXPECT_LT(bend_index, on_index);
}

TEST(EncodeMidi, RejectsInvalidFields) {
  MidiFile file;
  EXPECT_THROW(EncodeMidi(file), std::invalid_argument);  // no tracks
  MidiTrack t;
  t.notes = {{1.0, 0.5, 60, 80}};
  file.tracks = {t};
  EXPECT_THROW(EncodeMidi(file), std::invalid_argument);  // offset before onset
  file.tracks[0].notes = {{0.0, 0.5, 200, 80}};
  EXPECT_THROW(EncodeMidi(file), std::invalid_argument);
  file.tracks[0].notes = {};
  file.tracks[0].channel = 16;
  EXPECT_THROW(EncodeMidi(file), std::invalid_argument);
}

TEST(ParseMidi, MalformedInputIsAnError) {
  EXPECT_FALSE(ParseMidi("").ok());
  EXPECT_FALSE(ParseMidi("MThd").ok());
  MidiFile file;
  MidiTrack t;
  t.notes = {{0.0, 0.5, 60, 80}};
  file.tracks = {t};
  const std::string bytes = EncodeMidi(file);
  for (size_t cut = 1; cut < bytes.size(); ++cut) {
    auto parsed = ParseMidi(bytes.substr(0, cut));
    if (parsed.ok()) ADD_FAILURE() << "truncated at " << cut << " parsed";
  }
}

}  // namespace
}  // namespace arco::audio
