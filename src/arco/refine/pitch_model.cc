#include "arco/refine/pitch_model.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "arco/util/stats.h"

namespace arco::refine {
namespace {

double Cents(double f0_hz) { return 1200.0 * std::log2(f0_hz / 440.0); }

// Builds notes frame by frame (header comment of pitch_model.h).
class Segmenter {
 public:
  Segmenter(const std::vector<FramePitch>& pitch,
            const PitchModelOptions& options,
            PitchAnalysis* out)
      : pitch_(pitch), options_(options), out_(out) {}

  // A weak frame (low confidence) continues the open note when it agrees with it; true when
  // it was taken.
  bool Continue(int64_t f, double cents) {
    if (members_.empty() || !pending_.empty()) return false;
    if (std::abs(cents - Centre(members_cents_)) > options_.note_change_cents) return false;
    Add(f, cents);
    return true;
  }

  void Push(int64_t f, double cents) {
    if (members_.empty()) {
      Add(f, cents);
      return;
    }
    const double centre = Centre(members_cents_);
    const double dev = std::abs(cents - centre);
    if (pending_.empty()) {
      if (dev <= options_.note_change_cents) {
        Add(f, cents);
      } else {
        pending_.push_back(f);
        pending_cents_.push_back(cents);
      }
    } else {
      // While a change is pending, a frame goes to whichever pitch it is closer to.
      const double pending_centre = Median(pending_cents_);
      if (dev <= std::abs(cents - pending_centre)) {
        DropPendingAsOutliers();
        Add(f, cents);
      } else {
        pending_.push_back(f);
        pending_cents_.push_back(cents);
      }
    }
    if (static_cast<int>(pending_.size()) >= options_.note_change_frames) {
      const std::vector<int64_t> frames = pending_;
      const std::vector<double> cents_list = pending_cents_;
      pending_.clear();
      pending_cents_.clear();
      Close();
      for (size_t i = 0; i < frames.size(); ++i) Add(frames[i], cents_list[i]);
    }
  }

  // Ends the current note (a rest, an untrusted frame, the end of the clip).
  void Close() {
    DropPendingAsOutliers(/*count=*/false);
    if (members_.empty()) return;
    NoteSpan note;
    note.first_frame = members_.front();
    note.last_frame = members_.back();
    note.f0_hz = 440.0 * std::exp2(Median(all_cents_) / 1200.0);
    note.modulation_cents =
        members_.size() >= 2
            ? 0.5 * (InterpolatedQuantile(all_cents_, 0.9) - InterpolatedQuantile(all_cents_, 0.1))
            : 0.0;
    double conf = 0;
    for (int64_t f : members_) conf += pitch_[static_cast<size_t>(f)].confidence;
    note.mean_confidence = conf / static_cast<double>(members_.size());
    note.outlier_frames = outliers_;
    const bool long_enough = note.num_frames() >= options_.min_note_frames;
    const bool stable = static_cast<double>(outliers_) <=
                        options_.max_outlier_fraction * static_cast<double>(note.num_frames());
    note.usable = long_enough && stable;
    const FrameAudioState state = note.usable    ? FrameAudioState::kNote
                                  : !long_enough ? FrameAudioState::kShortNote
                                                 : FrameAudioState::kUnstableNote;
    const int index = static_cast<int>(out_->notes.size());
    for (int64_t f : members_) {
      out_->frame_state[static_cast<size_t>(f)] = state;
      out_->note_of_frame[static_cast<size_t>(f)] = index;
    }
    out_->notes.push_back(note);
    members_.clear();
    members_cents_.clear();
    all_cents_.clear();
    outliers_ = 0;
  }

 private:
  void Add(int64_t f, double cents) {
    members_.push_back(f);
    all_cents_.push_back(cents);
    members_cents_.push_back(cents);
    if (static_cast<int>(members_cents_.size()) > options_.median_window_frames) {
      members_cents_.erase(members_cents_.begin());
    }
  }
  double Centre(const std::vector<double>& window) const { return Median(window); }
  // Pending frames that never became a note: outliers. They count against the note's
  // stability only when the note went on after them (not when a rest ends it).
  void DropPendingAsOutliers(bool count = true) {
    for (int64_t f : pending_)
      out_->frame_state[static_cast<size_t>(f)] = FrameAudioState::kOutlier;
    if (count) outliers_ += static_cast<int>(pending_.size());
    pending_.clear();
    pending_cents_.clear();
  }

  const std::vector<FramePitch>& pitch_;
  const PitchModelOptions& options_;
  PitchAnalysis* out_;
  std::vector<int64_t> members_;
  std::vector<double> members_cents_;  // the latest median_window_frames members
  std::vector<double> all_cents_;      // every member
  std::vector<int64_t> pending_;
  std::vector<double> pending_cents_;
  int outliers_ = 0;
};

}  // namespace

Status PitchModelOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(contact.Validate());
  if (!(min_confidence >= 0 && min_confidence <= 1)) {
    return Status::Error("pitch model: min_confidence must be in [0, 1]");
  }
  if (!(min_confidence_in_note >= 0 && min_confidence_in_note <= min_confidence)) {
    return Status::Error("pitch model: min_confidence_in_note must be in [0, min_confidence]");
  }
  if (!(note_change_cents > 0 && std::isfinite(note_change_cents))) {
    return Status::Error("pitch model: note_change_cents must be > 0");
  }
  if (note_change_frames < 1) return Status::Error("pitch model: note_change_frames must be >= 1");
  if (median_window_frames < 1) {
    return Status::Error("pitch model: median_window_frames must be >= 1");
  }
  if (min_note_frames < 1) return Status::Error("pitch model: min_note_frames must be >= 1");
  if (!(max_outlier_fraction >= 0 && max_outlier_fraction <= 1)) {
    return Status::Error("pitch model: max_outlier_fraction must be in [0, 1]");
  }
  if (!(jump_cents > 0 && std::isfinite(jump_cents))) {
    return Status::Error("pitch model: jump_cents must be > 0");
  }
  if (jump_window_frames < 2) return Status::Error("pitch model: jump_window_frames must be >= 2");
  if (max_jumps_in_window < 0) {
    return Status::Error("pitch model: max_jumps_in_window must be >= 0");
  }
  if (!(vibrato_min_cents >= 0 && std::isfinite(vibrato_min_cents))) {
    return Status::Error("pitch model: vibrato_min_cents must be >= 0");
  }
  return Status::Ok();
}

const char* FrameAudioStateName(FrameAudioState state) {
  switch (state) {
    case FrameAudioState::kRest:
      return "rest";
    case FrameAudioState::kLowConfidence:
      return "low_confidence";
    case FrameAudioState::kJumping:
      return "jumping";
    case FrameAudioState::kOutlier:
      return "outlier";
    case FrameAudioState::kShortNote:
      return "short_note";
    case FrameAudioState::kUnstableNote:
      return "unstable_note";
    case FrameAudioState::kNote:
      return "note";
    case FrameAudioState::kBoundary:
      return "boundary";
  }
  return "?";
}

PitchAnalysis AnalysePitch(const std::vector<FramePitch>& pitch, const PitchModelOptions& options) {
  const Status status = options.Validate();
  if (!status.ok()) throw std::invalid_argument(status.message());
  PitchAnalysis out;
  out.frame_state.assign(pitch.size(), FrameAudioState::kRest);
  out.note_of_frame.assign(pitch.size(), -1);
  const size_t n = pitch.size();
  std::vector<uint8_t> trusted(n, 0);
  for (size_t f = 0; f < n; ++f) {
    const FramePitch& p = pitch[f];
    const bool voiced = std::isfinite(p.f0_hz) && p.f0_hz > 0;
    if (!voiced) continue;
    if (!(p.confidence >= options.min_confidence)) {  // NaN confidence is not trusted
      out.frame_state[f] = FrameAudioState::kLowConfidence;
      continue;
    }
    trusted[f] = 1;
  }
  // Jumps between consecutive trusted frames, counted over sliding windows.
  std::vector<int> jump_prefix(n + 1, 0);  // jumps between frames (f - 1, f) for f < i
  for (size_t f = 0; f < n; ++f) {
    const bool jump =
        f > 0 && trusted[f] && trusted[f - 1] &&
        std::abs(Cents(pitch[f].f0_hz) - Cents(pitch[f - 1].f0_hz)) >= options.jump_cents;
    jump_prefix[f + 1] = jump_prefix[f] + (jump ? 1 : 0);
  }
  const int64_t w = options.jump_window_frames;
  std::vector<uint8_t> jumping(n, 0);
  for (int64_t start = 0; start + w <= static_cast<int64_t>(n); ++start) {
    // Pairs inside [start, start + w): jumps at frames start + 1 .. start + w - 1.
    const int jumps =
        jump_prefix[static_cast<size_t>(start + w)] - jump_prefix[static_cast<size_t>(start + 1)];
    if (jumps > options.max_jumps_in_window) {
      for (int64_t f = start; f < start + w; ++f) jumping[static_cast<size_t>(f)] = 1;
    }
  }
  Segmenter segmenter(pitch, options, &out);
  for (size_t f = 0; f < n; ++f) {
    if (trusted[f] && jumping[f]) {
      out.frame_state[f] = FrameAudioState::kJumping;
      trusted[f] = 0;
    }
    if (!trusted[f]) {
      // Hysteresis: a weak but agreeing frame continues a note; anything else ends it.
      const bool weak = out.frame_state[f] == FrameAudioState::kLowConfidence &&
                        pitch[f].confidence >= options.min_confidence_in_note;
      if (weak && segmenter.Continue(static_cast<int64_t>(f), Cents(pitch[f].f0_hz))) continue;
      segmenter.Close();
      continue;
    }
    segmenter.Push(static_cast<int64_t>(f), Cents(pitch[f].f0_hz));
  }
  segmenter.Close();
  return out;
}

namespace {

bool PlaceContact(const InstrumentModel& model,
                  const std::vector<StringSegment>& strings_in_world,
                  const Contact& c,
                  Candidate* out) {
  if (!c.stopped() || static_cast<int>(strings_in_world.size()) != model.num_strings()) {
    return false;
  }
  const StringSegment& seg = strings_in_world[static_cast<size_t>(c.string - 1)];
  out->string = c.string;
  out->point_in_world = seg.PointAtFraction(c.fraction_from_bridge);
  out->from_nut_mm = model.string_length_mm() - c.contact_from_bridge_mm;
  out->semitones_above_open = c.cents_from_open / 100.0;
  return out->point_in_world.allFinite();
}

}  // namespace

bool ContactOnString(const InstrumentModel& model,
                     const std::vector<StringSegment>& strings_in_world,
                     int string,
                     double f0_hz,
                     const ContactOptions& options,
                     Candidate* out) {
  return PlaceContact(model, strings_in_world, ContactPoint(model, string, f0_hz, options), out);
}

FrameCandidates CandidatesForPitch(const InstrumentModel& model,
                                   const std::vector<StringSegment>& strings_in_world,
                                   double f0_hz,
                                   const ContactOptions& options) {
  FrameCandidates out;
  for (int s = 1; s <= model.num_strings(); ++s) {
    const Contact c = ContactPoint(model, s, f0_hz, options);
    if (c.kind == ContactKind::kOpenString) {
      out.open_strings.push_back(s);
    } else if (c.stopped()) {
      Candidate cand;
      if (PlaceContact(model, strings_in_world, c, &cand)) {
        out.stopped.push_back(cand);
      }
    }
  }
  return out;
}

}  // namespace arco::refine
