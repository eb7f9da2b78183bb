#include "arco/synth/score.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace arco::synth {
namespace {

// Semitone offsets of the major scale degrees 0..6.
constexpr int kMajor[7] = {0, 2, 4, 5, 7, 9, 11};

// Semitones above the tonic of major-scale degree `d` (any integer, may be < 0).
int MajorDegree(int d) {
  const int octave = (d >= 0) ? d / 7 : -((-d + 6) / 7);
  return 12 * octave + kMajor[d - 7 * octave];
}

// Appends a note lasting `beats` beats; the sound stops a short articulation gap
// before the next onset so every note gets its own bow stroke and onset.
class ScoreBuilder {
 public:
  explicit ScoreBuilder(double beat_s) : beat_s_(beat_s) {}
  void Note(int midi, double beats, int velocity = 80) {
    const double dur = beats * beat_s_;
    const double gap = std::min(0.03, 0.1 * dur);
    score_.notes.push_back({midi, t_, t_ + dur - gap, velocity});
    t_ += dur;
  }
  // Two notes sounding together (a double stop): `high` on the next higher string.
  void DoubleStop(int low, int high, double beats, int velocity = 80) {
    Note(low, beats, velocity);
    score_.notes.back().second_midi_note = high;
  }
  // A 3- or 4-note chord (`midi` lowest first, on adjacent strings), rolled 2+2: the lower
  // pair for `lower_beats`, then the upper pair held for `beats`. A 3-note chord's pairs
  // share its middle note.
  void Chord(const std::vector<int>& midi, double lower_beats, double beats, int velocity = 80) {
    if (midi.size() != 3 && midi.size() != 4) {
      throw std::invalid_argument("ScoreBuilder::Chord: a chord has 3 or 4 notes");
    }
    DoubleStop(midi[0], midi[1], lower_beats, velocity);
    DoubleStop(midi[midi.size() - 2], midi[midi.size() - 1], beats, velocity);
    score_.notes.back().chord_upper_pair = true;
  }
  void Rest(double beats) { t_ += beats * beat_s_; }
  void SetBeat(double beat_s) { beat_s_ = beat_s; }
  Score Finish(const std::string& name) {
    score_.name = name;
    score_.duration_s = t_ + 0.5;  // let the last note ring out
    return std::move(score_);
  }

 private:
  double beat_s_;
  double t_ = 0.25;  // a short silence before the first note
  Score score_;
};

Score ScaleTwoOctaves(const ScoreInstrument& ins, double k) {
  ScoreBuilder b(0.5 * k);
  const int tonic = ins.open_string_midi.front();
  for (int d = 0; d <= 14; ++d) b.Note(tonic + MajorDegree(d), d == 14 ? 2 : 1);
  for (int d = 13; d >= 0; --d) b.Note(tonic + MajorDegree(d), d == 0 ? 2 : 1);
  return b.Finish("scale-2oct");
}

Score Arpeggios(const ScoreInstrument& ins, double k) {
  ScoreBuilder b(0.4 * k);
  const int low = ins.open_string_midi.front();
  const int chord[7] = {0, 4, 7, 12, 16, 19, 24};
  // I, IV, V of the lowest open string's major key, two octaves up and down.
  for (int root : {0, 5, 7}) {
    for (int i = 0; i < 7; ++i) b.Note(low + root + chord[i], i == 6 ? 2 : 1);
    for (int i = 5; i >= 0; --i) b.Note(low + root + chord[i], i == 0 ? 2 : 1);
    b.Rest(1);
  }
  b.Note(low + 12, 3);
  return b.Finish("arpeggios");
}

Score SlowMelody(const ScoreInstrument& ins, double k) {
  ScoreBuilder b(0.6 * k);
  // Tonic a fourth above the second-highest string: the melody lies on the two
  // upper strings, where players sing with vibrato.
  const size_t n = ins.open_string_midi.size();
  const int tonic = ins.open_string_midi[n >= 2 ? n - 2 : 0] + 5;
  // (scale degree, beats): an original cantabile line with long notes.
  const int melody[][2] = {{0, 2},
                           {2, 1},
                           {4, 3},
                           {3, 1},
                           {2, 1},
                           {1, 1},
                           {2, 4},
                           {0, 1},
                           {-1, 1},
                           {1, 2},
                           {4, 3},
                           {3, 1},
                           {2, 1},
                           {1, 1},
                           {5, 3},
                           {4, 1},
                           {2, 2},
                           {1, 2},
                           {0, 4}};
  for (const auto& m : melody) b.Note(tonic + MajorDegree(m[0]), m[1], 70);
  return b.Finish("slow-melody");
}

Score FastPassage(const ScoreInstrument& ins, double k) {
  ScoreBuilder b(0.125 * k);
  const size_t n = ins.open_string_midi.size();
  const int tonic = ins.open_string_midi[n >= 2 ? 1 : 0];
  // Broken thirds up two octaves (string crossings, shifts up the neck) ...
  for (int d = 0; d < 14; ++d) {
    for (int step : {0, 2, 1, 3}) b.Note(tonic + MajorDegree(d + step), 1, 90);
  }
  // ... then a fast scale straight down (shifts down, crossings back).
  for (int d = 16; d >= 0; --d) b.Note(tonic + MajorDegree(d), d == 0 ? 4 : 1, 90);
  return b.Finish("fast-passage");
}

Score OpenStrings(const ScoreInstrument& ins, double k) {
  ScoreBuilder b(0.3 * k);
  // On each string: open, a little stopped figure, open again, then a rest.
  for (int open : ins.open_string_midi) {
    b.Note(open, 2);
    for (int s : {2, 4, 5, 7, 5, 4, 2}) b.Note(open + s, 1);
    b.Note(open, 2);
    b.Rest(2);
  }
  // Alternating open strings with a stopped melody on the neighbouring string.
  const size_t n = ins.open_string_midi.size();
  const int top = ins.open_string_midi[n - 1];
  for (int s : {2, 4, 5, 4}) {
    b.Note(top, 1);
    b.Note(top + s, 1);
  }
  b.Note(top, 4);
  return b.Finish("open-strings");
}

// Sixths, thirds, fifths and octaves on every pair of adjacent strings, lowest pair first;
// before each double stop its upper note sounds alone, and a rest ends each pair. The lower
// note's stop a (semitones above its open string) is the first of kStops that keeps both
// stops playable in one closed hand frame (|a - b| <= hand_span_semitones, or one of them
// an open string): on the cello the octave takes an open lower string, on the double bass
// (tuned in fourths) the sixth and the octave.
Score DoubleStops(const ScoreInstrument& ins, double k) {
  ScoreBuilder b(0.4 * k);
  constexpr int kIntervals[4] = {9, 4, 7, 12};  // major sixth, major third, fifth, octave
  constexpr int kStops[8] = {4, 2, 3, 5, 1, 6, 7, 0};
  const size_t n = ins.open_string_midi.size();
  for (size_t s = 0; s + 1 < n; ++s) {
    const int low_open = ins.open_string_midi[s];
    const int high_open = ins.open_string_midi[s + 1];
    for (int interval : kIntervals) {
      for (int a : kStops) {
        const int stop_b = a + interval - (high_open - low_open);
        const bool open = a == 0 || stop_b == 0;
        if (stop_b < 0 || (!open && std::abs(stop_b - a) > ins.hand_span_semitones)) continue;
        b.Note(low_open + a + interval, 1);
        b.DoubleStop(low_open + a, low_open + a + interval, 2);
        break;
      }
    }
    b.Rest(1);
  }
  return b.Finish("double-stops");
}

// Chords on adjacent strings, each given by its stops (semitones above each string's open
// note, 0 = open) from string `first_string` up, so every instrument gets the same shapes
// in one hand position. Tuned in fifths they are (violin / cello): (0,0,2,3) G major
// G3-D4-B4-G5 / C major C2-G2-E3-C4; (0,0,2) from the second string D major / G major;
// (2,2,4) A major / D major with one finger stopping the fifth; (2,2,4,5) the same with
// its octave on top; (0,2,3) from the second string G / C major. A shape whose stopped
// notes span more than the hand (ScoreInstrument::hand_span_semitones) is left out (the
// double bass, tuned in fourths, keeps those within its span).
struct ChordShape {
  int first_string;
  std::vector<int> stops;
};

// Before each chord its top note sounds alone (a single note between chords, as the
// double-stops piece does), then the chord is rolled: the lower pair briefly (long enough
// for the pitch tracker's window, about 0.3 s at the default tempo), the upper pair held.
constexpr double kChordBeatS = 0.4;
constexpr double kChordLowerPairBeats = 0.75;
constexpr double kChordUpperPairBeats = 2.5;

Score Chords(const ScoreInstrument& ins, double k) {
  ScoreBuilder b(kChordBeatS * k);
  const std::vector<ChordShape> shapes = {
      {0, {0, 0, 2, 3}}, {1, {0, 0, 2}}, {0, {2, 2, 4}}, {0, {2, 2, 4, 5}}, {1, {0, 2, 3}}};
  const int n = static_cast<int>(ins.open_string_midi.size());
  for (const ChordShape& shape : shapes) {
    const int num = static_cast<int>(shape.stops.size());
    if (shape.first_string + num > n) continue;
    int lo = 1000, hi = -1;
    for (int a : shape.stops) {
      if (a == 0) continue;
      lo = std::min(lo, a);
      hi = std::max(hi, a);
    }
    if (hi >= 0 && hi - lo > ins.hand_span_semitones) continue;
    std::vector<int> midi;
    for (int i = 0; i < num; ++i) {
      midi.push_back(ins.open_string_midi[static_cast<size_t>(shape.first_string + i)] +
                     shape.stops[static_cast<size_t>(i)]);
    }
    b.Note(midi.back(), 1);
    b.Chord(midi, kChordLowerPairBeats, kChordUpperPairBeats);
    b.Rest(1);
  }
  return b.Finish("chords");
}

}  // namespace

int ScoreInstrument::LowestMidi() const {
  return open_string_midi.empty() ? 0 : open_string_midi.front();
}

int ScoreInstrument::HighestMidi() const {
  return open_string_midi.empty() ? 0 : open_string_midi.back() + max_semitones_above_open;
}

bool ScoreInstrument::InRange(int midi_note) const {
  for (int open : open_string_midi) {
    if (midi_note >= open && midi_note <= open + max_semitones_above_open) return true;
  }
  return false;
}

std::string BuiltInPieceList() {
  std::string list;
  for (const auto& n : BuiltInPieceNames()) list += (list.empty() ? "" : ", ") + n;
  return list;
}

Status CheckBuiltInPieceName(const std::string& name) {
  const auto& pieces = BuiltInPieceNames();
  if (std::find(pieces.begin(), pieces.end(), name) != pieces.end()) return Status::Ok();
  return Status::Error("piece '" + name + "' is unknown (built-in pieces: " + BuiltInPieceList() +
                       ")");
}

const std::vector<std::string>& BuiltInPieceNames() {
  static const std::vector<std::string> names = {"scale-2oct",
                                                 "arpeggios",
                                                 "slow-melody",
                                                 "fast-passage",
                                                 "open-strings",
                                                 "double-stops",
                                                 "chords"};
  return names;
}

std::string DescribeBuiltInPiece(const std::string& name) {
  if (name == "scale-2oct")
    return "major scale, two octaves up and down from the lowest open string";
  if (name == "arpeggios") return "I, IV and V arpeggios over two octaves";
  if (name == "slow-melody") return "cantabile melody with long vibrato notes on the upper strings";
  if (name == "fast-passage")
    return "sixteenth-note broken thirds and a scale run: shifts and string crossings";
  if (name == "open-strings") return "figures starting and ending on each open string, with rests";
  if (name == "double-stops")
    return "sixths, thirds, fifths and octaves on adjacent strings, each after its upper note "
           "alone";
  if (name == "chords")
    return "3- and 4-note chords on adjacent strings in one hand position, rolled 2+2 (lower "
           "pair briefly, upper pair held), each after its top note alone";
  return "";
}

StatusOr<Score> MakeBuiltInPiece(const std::string& name,
                                 const ScoreInstrument& instrument,
                                 double tempo_scale) {
  if (instrument.open_string_midi.empty()) {
    throw std::invalid_argument("MakeBuiltInPiece: instrument has no strings");
  }
  if (!(tempo_scale > 0.05 && tempo_scale < 20)) {
    return Status::Error("tempo scale " + std::to_string(tempo_scale) + " is outside (0.05, 20)");
  }
  Score score;
  if (name == "scale-2oct") {
    score = ScaleTwoOctaves(instrument, tempo_scale);
  } else if (name == "arpeggios") {
    score = Arpeggios(instrument, tempo_scale);
  } else if (name == "slow-melody") {
    score = SlowMelody(instrument, tempo_scale);
  } else if (name == "fast-passage") {
    score = FastPassage(instrument, tempo_scale);
  } else if (name == "open-strings") {
    score = OpenStrings(instrument, tempo_scale);
  } else if (name == "double-stops") {
    score = DoubleStops(instrument, tempo_scale);
  } else if (name == "chords") {
    score = Chords(instrument, tempo_scale);
  } else {
    return Status::Error("unknown piece '" + name + "' (built-in pieces: " + BuiltInPieceList() +
                         ")");
  }
  ARCO_RETURN_IF_ERROR(ValidateScore(score, instrument, "piece " + name));
  return score;
}

Status ValidateScore(const Score& score,
                     const ScoreInstrument& instrument,
                     const std::string& source) {
  if (score.notes.empty()) return Status::Error(source + ": the score has no notes");
  char buf[256];
  for (size_t i = 0; i < score.notes.size(); ++i) {
    const ScoreNote& n = score.notes[i];
    if (!instrument.InRange(n.midi_note)) {
      std::snprintf(buf,
                    sizeof(buf),
                    "%s: note %d (%s) at %.3f s is outside the %s's range %s (%d) to %s (%d)",
                    source.c_str(),
                    n.midi_note,
                    MidiNoteName(n.midi_note).c_str(),
                    n.onset_s,
                    instrument.name.c_str(),
                    MidiNoteName(instrument.LowestMidi()).c_str(),
                    instrument.LowestMidi(),
                    MidiNoteName(instrument.HighestMidi()).c_str(),
                    instrument.HighestMidi());
      return Status::Error(buf);
    }
    if (!(n.onset_s >= 0) || !(n.offset_s > n.onset_s)) {
      std::snprintf(buf,
                    sizeof(buf),
                    "%s: note %d (%s) at %.3f s has no positive duration",
                    source.c_str(),
                    n.midi_note,
                    MidiNoteName(n.midi_note).c_str(),
                    n.onset_s);
      return Status::Error(buf);
    }
    if (i > 0 && n.onset_s < score.notes[i - 1].offset_s - 1e-9) {
      std::snprintf(buf,
                    sizeof(buf),
                    "%s: note %d (%s) at %.3f s starts before the previous note ends "
                    "(arco synth plays one note at a time)",
                    source.c_str(),
                    n.midi_note,
                    MidiNoteName(n.midi_note).c_str(),
                    n.onset_s);
      return Status::Error(buf);
    }
    if (n.IsDoubleStop() &&
        (n.second_midi_note <= n.midi_note || !instrument.InRange(n.second_midi_note))) {
      std::snprintf(buf,
                    sizeof(buf),
                    "%s: double stop %s+%s at %.3f s: the second note must lie above the first, "
                    "within the %s's range",
                    source.c_str(),
                    MidiNoteName(n.midi_note).c_str(),
                    MidiNoteName(n.second_midi_note).c_str(),
                    n.onset_s,
                    instrument.name.c_str());
      return Status::Error(buf);
    }
    if (n.chord_upper_pair) {
      const ScoreNote* lower = i > 0 ? &score.notes[i - 1] : nullptr;
      if (!n.IsDoubleStop() || lower == nullptr || !lower->IsDoubleStop() ||
          n.midi_note < lower->second_midi_note) {
        std::snprintf(buf,
                      sizeof(buf),
                      "%s: the chord's upper pair at %.3f s must be a double stop following its "
                      "lower pair, at or above that pair's upper note",
                      source.c_str(),
                      n.onset_s);
        return Status::Error(buf);
      }
    }
    if (n.velocity < 1 || n.velocity > 127) {
      return Status::Error(source + ": velocity outside 1..127");
    }
  }
  return Status::Ok();
}

Score TruncateScore(const Score& score, double max_duration_s) {
  if (!(max_duration_s > 0)) return score;
  Score out;
  out.name = score.name;
  for (const ScoreNote& n : score.notes) {
    if (n.onset_s >= max_duration_s) break;
    ScoreNote c = n;
    c.offset_s = std::min(c.offset_s, max_duration_s);
    if (c.offset_s - c.onset_s < 0.05) break;
    out.notes.push_back(c);
  }
  out.duration_s = std::min(score.duration_s, max_duration_s + 0.5);
  if (!out.notes.empty()) out.duration_s = std::max(out.duration_s, out.notes.back().offset_s);
  return out;
}

std::string MidiNoteName(int midi_note) {
  static const char* kNames[12] = {"C", "C#", "D", "D#", "E", "F", "F#", "G", "G#", "A", "A#", "B"};
  const int octave = (midi_note >= 0 ? midi_note / 12 : -((-midi_note + 11) / 12)) - 1;
  const int pc = ((midi_note % 12) + 12) % 12;
  return std::string(kNames[pc]) + std::to_string(octave);
}

double MidiToHz(double midi_note, double a4_hz) {
  return a4_hz * std::pow(2.0, (midi_note - 69.0) / 12.0);
}

}  // namespace arco::synth
