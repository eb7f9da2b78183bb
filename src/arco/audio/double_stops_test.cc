// Double stops: the string prior, single windows, and generated double-stop music with
// known truth (double_stop_music.h) for every instrument.
#include "arco/audio/double_stops.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <tuple>

#include "arco/audio/double_stop_music.h"
#include "arco/audio/double_stops_csv.h"
#include "arco/audio/test_signals.h"

namespace arco::audio {
namespace {

double Cents(double f, double truth) { return 1200.0 * std::log2(f / truth); }

DoubleStopOptions Options(const std::string& instrument) {
  DoubleStopOptions o;
  o.range = *InstrumentRangeByName(instrument);
  return o;
}

TEST(DoubleStopOptions, ValidateRejectsValuesOutsideTheirRanges) {
  EXPECT_TRUE(Options("violin").Validate().ok());
  auto o = Options("cello");
  o.harmonics = 0;
  EXPECT_FALSE(o.Validate().ok());
  o = Options("cello");
  o.second_min_ratio = 1.5;
  EXPECT_FALSE(o.Validate().ok());
  o = Options("cello");
  o.window_s = NAN;
  EXPECT_FALSE(o.Validate().ok());
  o = Options("cello");
  o.consistency_s = 2.5;
  EXPECT_FALSE(o.Validate().ok());
  o = Options("cello");
  o.range.max_f0_hz = 5000;  // above the cello's 16 kHz / 4
  EXPECT_FALSE(o.Validate().ok());
  EXPECT_THROW(DoubleStopAnalyzer{o}, std::invalid_argument);
}

TEST(PlayableDoubleStop, AdjacentStringsWithinTheHandsSpan) {
  const std::array<double, 4> violin = {55, 62, 69, 76};  // G3 D4 A4 E5
  EXPECT_TRUE(PlayableDoubleStop(violin, 59, 67, 7));     // B3-G4 sixth on G-D
  EXPECT_TRUE(PlayableDoubleStop(violin, 55, 62, 7));     // open fifth G-D
  EXPECT_TRUE(PlayableDoubleStop(violin, 57, 69, 7));     // octave A3-A4
  EXPECT_TRUE(PlayableDoubleStop(violin, 69, 69.5, 7));   // near-unison, open + 4th
  EXPECT_FALSE(PlayableDoubleStop(violin, 55, 79, 7));    // two octaves: no two strings
  EXPECT_FALSE(PlayableDoubleStop(violin, 55, 74, 7));    // twelfth (a single note's 3rd partial)
  EXPECT_FALSE(PlayableDoubleStop(violin, 55, 58, 7));    // a third below D4: both on G
  EXPECT_FALSE(PlayableDoubleStop(violin, 62, 60, 7));    // low above high
  EXPECT_TRUE(PlayableDoubleStop(violin, 55, 74, 12));    // a wider span admits it
}

// One window of harmonic tones summed.
std::vector<float> Chord(const std::vector<double>& f0s, int rate, int n) {
  std::vector<float> x(n, 0.0f);
  for (double f : f0s) {
    testing::ToneOptions tone;
    tone.sample_rate_hz = rate;
    tone.harmonics = std::min(15, static_cast<int>(0.45 * rate / f));
    tone.amplitude = 0.2;
    const auto y = testing::RenderTone([f](double) { return f; }, 1.0 * n / rate, tone);
    for (int j = 0; j < n && j < static_cast<int>(y.size()); ++j) x[j] += y[j];
  }
  return x;
}

TEST(DoubleStopAnalyzer, FindsOneNoteAloneAndBothOfAPair) {
  const auto o = Options("violin");
  DoubleStopAnalyzer analyzer(o);
  const int rate = o.range.analysis_rate_hz, n = analyzer.window_length();
  std::array<PolyNote, 2> notes;
  EXPECT_EQ(analyzer.Analyze(Chord({}, rate, n).data(), &notes), 0);  // silence
  for (double f : {196.0, 293.7, 440.0, 880.0, 1318.5}) {
    ASSERT_EQ(analyzer.Analyze(Chord({f}, rate, n).data(), &notes), 1) << f;
    EXPECT_LT(std::abs(Cents(notes[0].f0_hz, f)), 10) << f;
  }
  // Sixth, third, fifth, octave on adjacent strings.
  for (auto [lo, hi] : std::vector<std::pair<double, double>>{
           {246.9, 392.0}, {349.2, 440.0}, {293.7, 440.0}, {220.0, 440.0}}) {
    ASSERT_EQ(analyzer.Analyze(Chord({lo, hi}, rate, n).data(), &notes), 2) << lo << " " << hi;
    EXPECT_LT(std::abs(Cents(notes[0].f0_hz, lo)), 10) << lo;
    EXPECT_LT(std::abs(Cents(notes[1].f0_hz, hi)), 10) << hi;
  }
}

// A bowed string's fundamental can be far weaker than its 2nd partial: the partials below
// are those measured on fluidsynth's violin playing the sixth B3 + G#4 (`arco synth
// --instrument violin --piece double-stops`, 0.1 s Hann, relative to the strongest peak;
// B3's 5th partial and G#4's 3rd share one band and are given to B3). Additive and
// steady, this case is found with or without check (4) (the sampled one, with its
// vibrato, is render_test.cc's RenderedDoubleStops, which fails without it); the second
// half guards the check against a false move: an upper note an octave above a note that
// has nothing below it stays where it is.
TEST(DoubleStopAnalyzer, FindsALowerNoteWhoseFundamentalIsWeak) {
  const auto o = Options("violin");
  DoubleStopAnalyzer analyzer(o);
  const int rate = o.range.analysis_rate_hz, n = analyzer.window_length();
  const double lo = 246.94, hi = 415.30;
  const std::vector<double> low_partials = {0.213, 0.734, 0.212, 0.114, 0.068, 0.138, 0.039, 0.113};
  const std::vector<double> high_partials = {1.0, 0.212, 0.0, 0.065, 0.213};
  std::vector<float> x(static_cast<size_t>(n), 0.0f);
  for (int j = 0; j < n; ++j) {
    const double t = static_cast<double>(j) / rate;
    double v = 0;
    for (size_t k = 0; k < low_partials.size(); ++k) {
      v += 0.05 * low_partials[k] * std::sin(2 * M_PI * lo * (k + 1) * t + 0.3 * k);
    }
    for (size_t k = 0; k < high_partials.size(); ++k) {
      v += 0.05 * high_partials[k] * std::sin(2 * M_PI * hi * (k + 1) * t + 0.7 * k);
    }
    x[static_cast<size_t>(j)] = static_cast<float>(v);
  }
  std::array<PolyNote, 2> notes;
  ASSERT_EQ(analyzer.Analyze(x.data(), &notes), 2);
  EXPECT_LT(std::abs(Cents(notes[0].f0_hz, lo)), 10) << notes[0].f0_hz;
  EXPECT_LT(std::abs(Cents(notes[1].f0_hz, hi)), 10) << notes[1].f0_hz;
  // The same high note with the low note an octave up (B4, a full fundamental): B4 stays.
  for (int j = 0; j < n; ++j) {
    const double t = static_cast<double>(j) / rate;
    double v = 0;
    for (int k = 1; k <= 8; ++k) {
      v += 0.1 / k * std::sin(2 * M_PI * 2 * lo * k * t + 0.3 * k);
      v += 0.1 / k * std::sin(2 * M_PI * hi * k * t + 0.7 * k);
    }
    x[static_cast<size_t>(j)] = static_cast<float>(v);
  }
  ASSERT_EQ(analyzer.Analyze(x.data(), &notes), 2);
  EXPECT_LT(std::abs(Cents(notes[0].f0_hz, hi)), 10) << notes[0].f0_hz;
  EXPECT_LT(std::abs(Cents(notes[1].f0_hz, 2 * lo)), 10) << notes[1].f0_hz;
}

// The pair heard on the strings a bow rests on (PolyPitchFrame::on_strings): the cello's
// open C2 with C3 on the G string, an octave whose upper partials are all the lower note's
// even ones. The free analysis may hear one note; on the C and G strings the pair is the
// octave, and every pair of strings holds only notes its strings can stop (at or above
// their open pitch, below the octave position).
TEST(DoubleStopAnalyzer, HearsThePairOnTheStringsAskedFor) {
  const auto o = Options("cello");
  DoubleStopAnalyzer analyzer(o);
  const int rate = o.range.analysis_rate_hz, n = analyzer.window_length();
  const std::array<double, 4> open_midi = {36, 43, 50, 57};  // C2 G2 D3 A3
  const auto midi = [](double hz) { return 69.0 + 12.0 * std::log2(hz / 440.0); };
  for (auto [lo, hi, upper_string] : std::vector<std::tuple<double, double, int>>{
           {65.41, 130.81, 3},     // open C2 + C3: an octave on the C and G strings
           {98.0, 164.81, 2},      // open G2 + E3: a sixth on the G and D strings
           {146.83, 220.0, 1}}) {  // D3 + A3 open: a fifth on the D and A strings
    std::array<PolyNote, 2> notes;
    std::array<std::array<PolyNote, 2>, kStringPairs> on;
    analyzer.Analyze(Chord({lo, hi}, rate, n).data(), &notes, &on);
    const auto& pair = on[static_cast<size_t>(upper_string - 1)];
    EXPECT_LT(std::abs(Cents(pair[0].f0_hz, lo)), 10) << lo << " " << pair[0].f0_hz;
    EXPECT_LT(std::abs(Cents(pair[1].f0_hz, hi)), 10) << hi << " " << pair[1].f0_hz;
    for (int s = 1; s <= kStringPairs; ++s) {
      const auto& p = on[static_cast<size_t>(s - 1)];
      if (p[0].f0_hz == 0) {
        EXPECT_EQ(p[1].f0_hz, 0) << s;
        continue;
      }
      // Strings s + 1 (below) and s: open_midi low to high at 4 - (s + 1) and 4 - s.
      const double low_stop = midi(p[0].f0_hz) - open_midi[static_cast<size_t>(3 - s)];
      const double high_stop = midi(p[1].f0_hz) - open_midi[static_cast<size_t>(4 - s)];
      EXPECT_GE(low_stop, -0.5) << s;
      EXPECT_LE(low_stop, 12.0) << s;
      EXPECT_GE(high_stop, -0.5) << s;
      EXPECT_LE(high_stop, 12.0) << s;
    }
  }
  // Silence: no pair anywhere.
  std::array<PolyNote, 2> notes;
  std::array<std::array<PolyNote, 2>, kStringPairs> on;
  on[0][0].f0_hz = 1;
  EXPECT_EQ(analyzer.Analyze(Chord({}, rate, n).data(), &notes, &on), 0);
  for (const auto& p : on) EXPECT_EQ(p[0].f0_hz, 0);
}

PolyPitchFrame Pair(double low_hz, double high_hz) {
  PolyPitchFrame f;
  f.count = 2;
  f.notes = {PolyNote{low_hz, 1}, PolyNote{high_hz, 2}};
  return f;
}

PolyPitchFrame Single(double hz) {
  PolyPitchFrame f;
  f.count = 1;
  f.notes = {PolyNote{hz, 1}, PolyNote{}};
  return f;
}

// The viola's third E3 + G#3 (164.8, 207.7 Hz) as the analysis heard it on the synthetic
// double-stop piece: frames of G#4 + B4 (the upper note's 2nd partial, the lower's 3rd)
// and G#3 + E4 (the lower's 2nd) between the true pair.
TEST(ConsistentDoubleStops, APairHeardAsItsPartialsBecomesThePairAround) {
  const PolyPitchFrame third = Pair(164.8, 207.7), partials = Pair(415.3, 493.9),
                       octave_up = Pair(207.7, 329.6);
  std::vector<PolyPitchFrame> frames = {
      third, partials, partials, third, octave_up, third, Single(164.8), partials};
  for (size_t i = 0; i < frames.size(); ++i) frames[i].frame = static_cast<int64_t>(i);
  std::vector<PolyPitchFrame> made = frames;
  ConsistentDoubleStops(3, &made);
  for (int i : {1, 2, 4}) {
    EXPECT_EQ(made[i].count, 2) << i;
    EXPECT_EQ(made[i].notes[0].f0_hz, 164.8) << i;
    EXPECT_EQ(made[i].notes[1].f0_hz, 207.7) << i;
    EXPECT_EQ(made[i].frame, i);  // only the notes are taken
  }
  // The single note is left (the refinement's fill_notes completes notes); the last frame
  // has the true pair on one side only: a note change is not smoothed over.
  EXPECT_EQ(made[6].count, 1);
  EXPECT_EQ(made[7].notes[0].f0_hz, 415.3);
  for (int i : {0, 3, 5}) EXPECT_EQ(made[i].notes[1].f0_hz, 207.7);
  // Window 0: unchanged; a window too short to see the pair on both sides: unchanged.
  std::vector<PolyPitchFrame> same = frames;
  ConsistentDoubleStops(0, &same);
  EXPECT_EQ(same[1].notes[0].f0_hz, 415.3);
  same = {third, partials, partials, partials, third};
  ConsistentDoubleStops(1, &same);
  EXPECT_EQ(same[2].notes[0].f0_hz, 415.3);
}

// A real change of double stop is kept, even where the new pair's notes are partials of the
// old (E3 + G#3 -> G#3 + E4, whose E4 is E3's 2nd partial); so is a pair that no
// neighbour explains.
TEST(ConsistentDoubleStops, KeepsNoteChangesAndPairsNoNeighbourExplains) {
  std::vector<PolyPitchFrame> frames = {Pair(164.8, 207.7),
                                        Pair(164.8, 207.7),
                                        Pair(164.8, 207.7),
                                        Pair(207.7, 329.6),
                                        Pair(207.7, 329.6),
                                        Pair(207.7, 329.6),
                                        Pair(261.6, 392.0),
                                        Pair(207.7, 329.6)};
  std::vector<PolyPitchFrame> made = frames;
  ConsistentDoubleStops(5, &made);
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(made[i].notes[0].f0_hz, frames[i].notes[0].f0_hz) << i;
    EXPECT_EQ(made[i].notes[1].f0_hz, frames[i].notes[1].f0_hz) << i;
  }
}

// A chord's short lower pair D4 + A4 heard right on its middle frames and inverted (A3 + D4:
// A4 is A3's 2nd partial) at its two edges, where the window holds the onsets: A3 + D4 is
// seen on both sides of every middle frame and explains it, but the window hears the pair
// itself on more than twice as many frames, so the pair stays. Where the two readings are
// as frequent (the viola's alternations), the explanation still wins.
TEST(ConsistentDoubleStops, APairHeardOnMostOfTheWindowIsKept) {
  const PolyPitchFrame pair = Pair(293.7, 440.0), inverted = Pair(220.0, 293.7);
  std::vector<PolyPitchFrame> frames = {inverted, pair, pair, pair, pair, pair, pair, inverted};
  std::vector<PolyPitchFrame> made = frames;
  ConsistentDoubleStops(5, &made);
  for (int i = 1; i <= 6; ++i) EXPECT_EQ(made[i].notes[0].f0_hz, 293.7) << i;
  EXPECT_EQ(made[0].notes[0].f0_hz, 220.0);  // a pair on one side only: a note change
  // Alternating, each reading on about half the window's frames: the simpler one.
  frames = {inverted, pair, inverted, pair, inverted, pair, inverted};
  made = frames;
  ConsistentDoubleStops(5, &made);
  for (int i : {1, 3, 5}) EXPECT_EQ(made[i].notes[0].f0_hz, 220.0) << i;
}

// A fundamental is present only as a peak: the band's maximum on the slope of a stronger
// peak outside it (a neighbour's main lobe, an onset's smear) is none; a peak inside the
// band, even a weak one or one at the band's edge, is.
TEST(BandPeak, APeakInsideTheBandNotTheSlopeOfAPeakOutside) {
  const std::vector<double> spectrum = {0.0, 0.1, 0.3, 0.2, 0.5, 1.0, 0.5, 0.1, 0.02, 0.01};
  EXPECT_DOUBLE_EQ(BandPeak(spectrum, 1, 3), 0.3);  // a weak peak inside
  EXPECT_DOUBLE_EQ(BandPeak(spectrum, 2, 2), 0.3);  // one bin wide
  EXPECT_DOUBLE_EQ(BandPeak(spectrum, 3, 4), 0.0);  // 1.0's rising slope
  EXPECT_DOUBLE_EQ(BandPeak(spectrum, 6, 8), 0.0);  // its falling slope
  EXPECT_DOUBLE_EQ(BandPeak(spectrum, 5, 7), 1.0);
  EXPECT_DOUBLE_EQ(BandPeak(spectrum, 8, 9), 0.0);  // the slope up to the spectrum's end
  EXPECT_DOUBLE_EQ(BandPeak(spectrum, 9, 10), -1.0);
}

TEST(SecondNoteHz, TheNoteBesideTheTrackersF0) {
  std::vector<PitchFrame> frames(4);
  for (auto& f : frames) f.voiced = true, f.f0_hz = 440.0;
  frames[3].voiced = false;
  std::vector<PolyPitchFrame> poly(4);
  poly[0].count = 2,
  poly[0].notes = {PolyNote{293.7, 1}, PolyNote{441.0, 1}};  // tracker on the upper
  poly[1].count = 2, poly[1].notes = {PolyNote{440.5, 1}, PolyNote{659.3, 1}};  // on the lower
  poly[2].count = 2, poly[2].notes = {PolyNote{261.6, 1}, PolyNote{349.2, 1}};  // neither matches
  poly[3] = poly[0];                                                            // unvoiced
  const auto second = SecondNoteHz(frames, poly);
  ASSERT_EQ(second.size(), 4u);
  EXPECT_DOUBLE_EQ(second[0], 293.7);
  EXPECT_DOUBLE_EQ(second[1], 659.3);
  EXPECT_EQ(second[2], 0.0);
  EXPECT_EQ(second[3], 0.0);
  EXPECT_EQ(SecondNoteHz(frames, {}).size(), 4u);  // frames past poly's end: 0
}

TEST(PitchCsv, SecondNoteColumnIsOptionalAndRoundTrips) {
  std::vector<PitchFrame> frames(2);
  frames[0] = {0, 0.0, 220.0, 0.9, true};
  frames[1] = {1, 1.0 / 30, 0.0, 0.1, false};
  const std::string plain = FormatPitchCsv(frames);
  EXPECT_EQ(FormatPitchCsv(frames, nullptr), plain);
  EXPECT_EQ(plain.substr(0, plain.find('\n')), "frame,time_s,f0_hz,confidence,voiced");
  const std::vector<double> second = {329.6276, 0.0};
  const std::string text = FormatPitchCsv(frames, &second);
  EXPECT_EQ(text.substr(0, text.find('\n')), "frame,time_s,f0_hz,confidence,voiced,f0_2_hz");
  std::vector<double> read;
  auto rows = ParsePitchCsv(text, "test", &read);
  ASSERT_TRUE(rows.ok()) << rows.status().message();
  ASSERT_EQ(read.size(), 2u);
  EXPECT_DOUBLE_EQ(read[0], 329.6276);
  EXPECT_EQ(read[1], 0.0);
  EXPECT_EQ(FormatPitchCsv(*rows), plain);  // the five columns unchanged
  // A reader that does not ask for the column still reads the file.
  EXPECT_TRUE(ParsePitchCsv(text, "test").ok());
  // Without the column: zeros.
  ASSERT_TRUE(ParsePitchCsv(plain, "test", &read).ok());
  EXPECT_EQ(read, std::vector<double>(2, 0.0));
  const std::vector<double> short_second = {1.0};
  EXPECT_THROW(FormatPitchCsv(frames, &short_second), std::invalid_argument);
  std::string bad = text;
  bad.replace(bad.find("329.6276"), 8, "-1");
  EXPECT_FALSE(ParsePitchCsv(bad, "test", &read).ok());
}

TEST(DoubleStopsCsv, RoundTripsTheFramesTheRefinementUsesAndRejectsBadRows) {
  std::vector<PolyPitchFrame> frames(3);
  for (int i = 0; i < 3; ++i) frames[i].frame = i, frames[i].time_s = 0.5 + i / 30.0;
  frames[1].count = 1, frames[1].notes[0] = {220.01234, 3.0};
  frames[2].count = 2, frames[2].notes = {PolyNote{246.94165, 2.0}, PolyNote{415.30469, 1.0}};
  frames[2].on_strings[1] = {PolyNote{246.94165, 2.0}, PolyNote{415.30469, 1.0}};
  frames[1].on_strings[2] = {PolyNote{110.00004, 1.0}, PolyNote{220.01234, 1.0}};
  const std::string text = FormatDoubleStopsCsv(frames);
  EXPECT_EQ(text.substr(0, text.find('\n')), kDoubleStopsCsvHeader);
  auto read = ParseDoubleStopsCsv(text, "double_stops.csv");
  ASSERT_TRUE(read.ok()) << read.status().message();
  ASSERT_EQ(read->size(), 3u);
  EXPECT_EQ((*read)[0].count, 0);
  EXPECT_EQ((*read)[1].count, 1);
  EXPECT_EQ((*read)[1].notes[0].f0_hz, 220.0123);  // to 1e-4 Hz
  EXPECT_EQ((*read)[2].count, 2);
  EXPECT_EQ((*read)[2].notes[0].f0_hz, 246.9417);
  EXPECT_EQ((*read)[2].notes[1].f0_hz, 415.3047);
  EXPECT_NEAR((*read)[2].time_s, 0.5 + 2 / 30.0, 1e-6);
  EXPECT_EQ((*read)[2].on_strings[1][1].f0_hz, 415.3047);
  EXPECT_EQ((*read)[1].on_strings[2][0].f0_hz, 110.0);
  EXPECT_EQ((*read)[0].on_strings[0][0].f0_hz, 0.0);
  EXPECT_EQ(FormatDoubleStopsCsv(*read), text);  // what is read writes the same text
  // A file from before the on_ columns reads with those pairs 0.
  const auto old = ParseDoubleStopsCsv(
      "frame,time_s,notes,f0_low_hz,f0_high_hz\n0,0.5,2,246.9417,415.3047\n", "old.csv");
  ASSERT_TRUE(old.ok()) << old.status().message();
  EXPECT_EQ((*old)[0].notes[1].f0_hz, 415.3047);
  for (const auto& p : (*old)[0].on_strings) EXPECT_EQ(p[1].f0_hz, 0.0);
  // Bad rows name the file and say what is wrong.
  const auto error = [&](const std::string& from, const std::string& to) {
    std::string bad = text;
    bad.replace(bad.find(from), from.size(), to);
    const auto r = ParseDoubleStopsCsv(bad, "double_stops.csv");
    EXPECT_FALSE(r.ok()) << bad;
    return r.ok() ? std::string() : r.status().message();
  };
  EXPECT_NE(error("415.3047", "200.0000").find("f0_low_hz <= f0_high_hz"), std::string::npos);
  EXPECT_NE(error("\n2,", "\n7,").find("out of order"), std::string::npos);
  EXPECT_NE(error(",1,220.0123", ",3,220.0123").find("notes must be 0, 1 or 2"), std::string::npos);
  EXPECT_NE(error("220.0123", "nan").find("double_stops.csv"), std::string::npos);
  EXPECT_NE(error("110.0000", "330.0000").find("on_3_low_hz"), std::string::npos);
  EXPECT_FALSE(ParseDoubleStopsCsv("frame,time_s,notes\n0,0,0\n", "x.csv").ok());
}

struct MusicScore {
  int64_t double_frames = 0, double_hits = 0;  // sixths, thirds, fifths
  int64_t octave_frames = 0, octave_hits = 0;
  int64_t single_frames = 0, single_hits = 0, single_clean = 0;
  int64_t silent_frames = 0, silent_clean = 0;
};

MusicScore ScoreMusic(const std::string& instrument, uint32_t seed) {
  const auto music = testing::MakeDoubleStopMusic(instrument, 40, seed);
  const auto o = Options(instrument);
  const int rate = 44100;
  const std::string path = testing::TempPath("double_stops_" + instrument + ".wav");
  EXPECT_TRUE(
      testing::WriteWav(path, testing::RenderDoubleStopMusic(music, rate, seed), rate).ok());
  DoubleStopSummary summary;
  const auto frames = TrackDoubleStopsFile(path, o, &summary);
  EXPECT_TRUE(frames.ok()) << frames.status().message();
  MusicScore score;
  if (!frames.ok()) return score;
  EXPECT_EQ(summary.frames, static_cast<int64_t>(frames->size()));
  EXPECT_EQ(summary.silent_frames + summary.single_frames + summary.double_frames, summary.frames);
  for (const auto& f : *frames) {
    double lo = 0, hi = 0;
    const int truth = music.Truth(f.time_s, &lo, &hi, 0.5 * DoubleStopWindowS(o) + 0.01);
    if (truth == 2) {
      const bool octave = std::abs(Cents(hi, lo) - 1200) < 1;
      ++(octave ? score.octave_frames : score.double_frames);
      const bool hit = f.count == 2 && std::abs(Cents(f.notes[0].f0_hz, lo)) < 50 &&
                       std::abs(Cents(f.notes[1].f0_hz, hi)) < 50;
      (octave ? score.octave_hits : score.double_hits) += hit;
    } else if (truth == 1) {
      ++score.single_frames;
      score.single_clean += f.count == 1;
      score.single_hits += f.count >= 1 && std::abs(Cents(f.notes[0].f0_hz, lo)) < 50;
    } else if (truth == 0) {
      ++score.silent_frames;
      score.silent_clean += f.count == 0;
    }
  }
  std::printf(
      "%s: both notes within 50 cents: sixths, thirds, fifths %.4f (%lld frames), "
      "octaves %.4f (%lld); single notes without a second %.4f and within 50 cents "
      "%.4f (%lld); silence %.4f (%lld); cpu %.2f s\n",
      instrument.c_str(),
      1.0 * score.double_hits / score.double_frames,
      static_cast<long long>(score.double_frames),
      1.0 * score.octave_hits / score.octave_frames,
      static_cast<long long>(score.octave_frames),
      1.0 * score.single_clean / score.single_frames,
      1.0 * score.single_hits / score.single_frames,
      static_cast<long long>(score.single_frames),
      1.0 * score.silent_clean / score.silent_frames,
      static_cast<long long>(score.silent_frames),
      summary.cpu_seconds);
  return score;
}

class DoubleStopMusicTest : public ::testing::TestWithParam<std::string> {};

TEST_P(DoubleStopMusicTest, FindsBothNotesOfDoubleStopsAndOneOfSingleNotes) {
  const MusicScore s = ScoreMusic(GetParam(), 27);
  ASSERT_GT(s.double_frames, 200);
  ASSERT_GT(s.octave_frames, 50);
  ASSERT_GT(s.single_frames, 200);
  ASSERT_GT(s.silent_frames, 50);
  EXPECT_GE(s.double_hits, 0.95 * s.double_frames);
  // Octaves: the upper note's partials all fall on the lower's (docs/audio.md, "Double
  // stops"); measured 0.58-0.79 on this seed: a floor, not the target of 0.95.
  EXPECT_GE(s.octave_hits, 0.5 * s.octave_frames);
  EXPECT_GE(s.single_clean, 0.95 * s.single_frames);
  EXPECT_GE(s.single_hits, 0.95 * s.single_frames);
  EXPECT_GE(s.silent_clean, 0.95 * s.silent_frames);
}

INSTANTIATE_TEST_SUITE_P(Instruments,
                         DoubleStopMusicTest,
                         ::testing::Values("violin", "viola", "cello", "double_bass"));

}  // namespace
}  // namespace arco::audio
