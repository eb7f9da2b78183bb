#include "arco/refine/arco_decode.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "arco/instrument/instrument_model.h"
#include "arco/util/parallel.h"
#include "arco/util/stats.h"
#include "arco/util/viterbi.h"

namespace arco::refine {
namespace {

// A pitch within half a semitone of a note is that note (the nearest-note rounding).
constexpr double kHalfSemitoneCents = 50.0;

// One camera (RefineInput::one_view_camera_centre_mm): the lifted hand's depth is what the
// view lacks, so a candidate is compared with the hand scaled about the camera's centre
// until finger k's tip is as far from the camera as the candidate. Every point stays on
// its ray (the image is unchanged); the depth is the candidate's own, and what is left of
// tip - contact is the image's evidence, in mm at the contact's distance.
hand::HandPointsMm AtCandidateDistance(const hand::HandPointsMm& points,
                                       const Eigen::Vector3d& centre,
                                       const Eigen::Vector3d& contact,
                                       int finger) {
  const Eigen::Vector3d& tip = points[hand::TipKeypoint(static_cast<hand::Finger>(finger))];
  const double tip_distance = (tip - centre).norm();
  if (!(tip_distance > 0)) return points;
  const double scale = (contact - centre).norm() / tip_distance;
  hand::HandPointsMm scaled;
  for (size_t j = 0; j < points.size(); ++j) scaled[j] = centre + scale * (points[j] - centre);
  return scaled;
}

// The vision hand as a candidate of finger k at `contact` sees it: as fitted, or with one
// camera and options.one_view_along_rays, at the candidate's distance (above).
hand::HandPointsMm CandidateHand(const DecodeContext& context,
                                 const hand::HandPointsMm& points,
                                 const Eigen::Vector3d& contact,
                                 int finger,
                                 const ArcoDecodeOptions& options) {
  const auto& centre = context.input->one_view_camera_centre_mm;
  if (!centre || !options.one_view_along_rays) return points;
  return AtCandidateDistance(points, *centre, contact, finger);
}

struct State {
  int string = 0;
  int finger = 0;                 // 0 = open string
  double position_semitones = 0;  // finger 1's semitone above the open string (stopped)
  double cost = 0;                // emission
};

// The states of one note and their emission costs.
std::vector<State> NoteStates(const DecodeContext& context,
                              const NoteSpan& note,
                              const ArcoDecodeOptions& options,
                              const PitchModelOptions& pitch_options,
                              const std::array<double, 5>& lift_max_mm) {
  const InstrumentModel& model = *context.input->instrument;
  // One camera, along the rays (ArcoDecodeOptions::one_view_lateral_weight): the image's
  // evidence across the string in full, a tip far above the string plane not stopping it.
  const bool along_rays =
      context.input->one_view_camera_centre_mm.has_value() && options.one_view_along_rays;
  ArcoDecodeOptions one_view;
  if (along_rays) {
    one_view = options;
    one_view.lateral_weight = options.one_view_lateral_weight;
  }
  const ArcoDecodeOptions& emission = along_rays ? one_view : options;
  const double above_margin_mm =
      along_rays ? options.one_view_above_margin_mm : std::numeric_limits<double>::infinity();
  std::vector<State> states;
  std::vector<double> distances, orders;
  // The string the bow's pair puts the note on (RefineInput::bowed_pair_lower_string), when
  // most of its trusted frames have one and agree.
  int bowed = 0;
  if (options.bowed_pair_string && !context.input->bowed_pair_lower_string.empty()) {
    std::array<int, 9> votes{};
    int trusted = 0;
    for (int64_t f = note.first_frame; f <= note.last_frame; ++f) {
      const size_t i = static_cast<size_t>(f);
      if (context.analysis->frame_state[i] != FrameAudioState::kNote) continue;
      ++trusted;
      const int b = context.input->bowed_pair_lower_string[i];
      if (b > 0 && b < static_cast<int>(votes.size())) ++votes[static_cast<size_t>(b)];
    }
    for (int b = 1; b < static_cast<int>(votes.size()); ++b) {
      if (2 * votes[static_cast<size_t>(b)] > trusted) bowed = b;
    }
  }
  for (int s = 1; s <= model.num_strings(); ++s) {
    const Contact median_contact = ContactPoint(model, s, note.f0_hz, pitch_options.contact);
    if (median_contact.kind == ContactKind::kOpenString) {
      State open;
      open.string = s;
      open.cost = options.open_cost_mm;
      if (note.modulation_cents > pitch_options.vibrato_min_cents)
        open.cost += options.infeasible_cost;
      states.push_back(open);
      continue;
    }
    if (!median_contact.stopped()) continue;
    for (int k = 1; k <= 4; ++k) {
      distances.clear();
      orders.clear();
      for (int64_t f = note.first_frame; f <= note.last_frame; ++f) {
        const size_t i = static_cast<size_t>(f);
        if (context.analysis->frame_state[i] != FrameAudioState::kNote) continue;
        if (!context.has_strings[i] || !context.vision_points[i]) continue;
        Candidate cand;
        if (!ContactOnString(model,
                             context.strings(static_cast<int>(f)),
                             s,
                             context.input->pitch[i].f0_hz,
                             pitch_options.contact,
                             &cand)) {
          continue;
        }
        double d = 0, o = 0;
        FrameCosts(
            CandidateHand(context, *context.vision_points[i], cand.point_in_world, k, options),
            StringFrameOf(context.strings(static_cast<int>(f)), s),
            cand.point_in_world,
            k,
            emission,
            &d,
            &o,
            above_margin_mm);
        distances.push_back(d);
        orders.push_back(o);
      }
      State st;
      st.string = s;
      st.finger = k;
      const double stop_semitones = median_contact.cents_from_open / 100.0;
      st.position_semitones = options.hand_frame_in_mm
                                  ? HandPositionSemitones(model.kind(), k, stop_semitones)
                                  : stop_semitones - FingerOffsetSemitones(model.kind(), k);
      if (!distances.empty()) {
        const double d = Median(distances);
        st.cost = d + options.order_weight * Median(orders);
        // One camera with the sound's decision kept: the lift test decides nothing here
        // either (ArcoDecodeOptions::one_view_keep_out_of_reach); D itself still counts.
        const bool gate = !(along_rays && options.one_view_keep_out_of_reach);
        if (gate && d > lift_max_mm[static_cast<size_t>(k)]) st.cost += options.infeasible_cost;
      }
      states.push_back(st);
    }
  }
  // On the bowed pair's lower string only, where the note can be played there.
  if (bowed > 0 && std::any_of(states.begin(), states.end(), [&](const State& st) {
        return st.string == bowed;
      })) {
    states.erase(
        std::remove_if(
            states.begin(), states.end(), [&](const State& st) { return st.string != bowed; }),
        states.end());
  }
  return states;
}

// 1 / sin^2 of the strings' angle to the one camera's ray, in [1, one_view_max_shift_factor]
// (the input has a one-view camera centre).
double ForeshorteningFactor(const DecodeContext& context, const ArcoDecodeOptions& options) {
  const auto& centre = context.input->one_view_camera_centre_mm;
  if (!(options.one_view_max_shift_factor > 1)) return 1.0;
  std::vector<double> sines;
  for (int f = 0; f < context.num_frames(); ++f) {
    if (!context.has_strings[static_cast<size_t>(f)]) continue;
    Eigen::Vector3d nut = Eigen::Vector3d::Zero(), bridge = Eigen::Vector3d::Zero();
    for (const StringSegment& s : context.strings(f)) {
      nut += s.nut;
      bridge += s.bridge;
    }
    const Eigen::Vector3d along = (nut - bridge).normalized();
    const Eigen::Vector3d ray =
        (0.5 * (nut + bridge) / static_cast<double>(context.strings(f).size()) - *centre)
            .normalized();
    const double sine = along.cross(ray).norm();
    if (std::isfinite(sine)) sines.push_back(sine);
  }
  if (sines.empty()) return 1.0;
  const double sine = Median(sines);
  return std::clamp(1.0 / (sine * sine), 1.0, options.one_view_max_shift_factor);
}

// One camera (header comment, "One camera"): one_view_shift_cost_factor times 1 / sin^2 of
// the angle between the strings and the camera's ray to their middle (the median over the
// frames with strings), the latter at most one_view_max_shift_factor; 1 with several
// cameras.
double OneViewShiftFactor(const DecodeContext& context, const ArcoDecodeOptions& options) {
  const auto& centre = context.input->one_view_camera_centre_mm;
  if (!centre) return 1.0;
  return options.one_view_shift_cost_factor * ForeshorteningFactor(context, options);
}

double TransitionCost(const NoteSpan& from_note,
                      const NoteSpan& to_note,
                      const State& a,
                      const State& b,
                      const ArcoDecodeOptions& options,
                      double fps) {
  const bool same_state = a.string == b.string && a.finger == b.finger;
  if (same_state) return 0.0;
  const double gap_s = static_cast<double>(to_note.first_frame - from_note.last_frame - 1) / fps;
  const double factor = gap_s >= options.rest_gap_s ? options.rest_factor : 1.0;
  const double interval_cents = std::abs(1200.0 * std::log2(to_note.f0_hz / from_note.f0_hz));
  if (interval_cents < options.same_pitch_cents) return factor * options.same_pitch_change_cost;
  double cost = options.string_cross_cost * std::abs(a.string - b.string);
  if (a.finger > 0 && b.finger > 0) {
    cost += options.shift_cost_per_semitone * std::abs(a.position_semitones - b.position_semitones);
  }
  return factor * cost;
}

// The contact of one frame of a decoded note (state, string, finger) at pitch f0_hz.
void AssignFrame(const DecodeContext& context,
                 const ArcoDecodeOptions& options,
                 int string,
                 int finger,
                 double f0_hz,
                 const PitchModelOptions& pitch_options,
                 const std::array<double, 5>& lift_max_mm,
                 int64_t f,
                 FrameContact* fc) {
  const size_t i = static_cast<size_t>(f);
  if (finger == 0) {
    fc->state = ContactState::kOpenString;
    fc->reason = ContactReason::kNone;
    fc->string = string;
    return;
  }
  if (!context.has_strings[i]) {
    fc->reason = ContactReason::kNoInstrument;
    return;
  }
  Candidate cand;
  if (!ContactOnString(*context.input->instrument,
                       context.strings(static_cast<int>(f)),
                       string,
                       f0_hz,
                       pitch_options.contact,
                       &cand)) {
    fc->reason = ContactReason::kUnplayable;
    return;
  }
  SetPressed(cand, finger, fc);
  const auto& points = context.vision_points[i];
  if (!points) {
    fc->reason = ContactReason::kNoHand;
    return;
  }
  const int tip = hand::TipKeypoint(static_cast<hand::Finger>(finger));
  fc->tip_distance_vision_mm =
      (CandidateHand(context, *points, cand.point_in_world, finger, options)[tip] -
       cand.point_in_world)
          .norm();
  if (fc->tip_distance_vision_mm > lift_max_mm[static_cast<size_t>(finger)]) {
    fc->reason = ContactReason::kOutOfReach;
    // One camera: the decision stands (ArcoDecodeOptions::one_view_keep_out_of_reach).
    const bool keep =
        options.one_view_keep_out_of_reach && context.input->one_view_camera_centre_mm.has_value();
    if (!keep) fc->state = ContactState::kUncertain;  // lift test: string and finger as info
  }
}

}  // namespace

void FrameCosts(const hand::HandPointsMm& points,
                const StringFrame& sf,
                const Eigen::Vector3d& contact,
                int finger,
                const ArcoDecodeOptions& options,
                double* distance,
                double* order,
                double above_margin_mm) {
  const Eigen::Vector3d v = points[hand::TipKeypoint(static_cast<hand::Finger>(finger))] - contact;
  const double a = v.dot(sf.along);
  const double n = v.dot(sf.normal);
  const double l = (v - a * sf.along - n * sf.normal).norm();
  // Which string: where the hand is across the neck, the median over the four fingertips of
  // their signed offsets across the strings (one finger's lift-induced error cannot move it).
  const Eigen::Vector3d across = sf.along.cross(sf.normal);
  std::array<double, 4> offsets{};
  for (int j = 1; j <= 4; ++j) {
    offsets[static_cast<size_t>(j - 1)] =
        (points[hand::TipKeypoint(static_cast<hand::Finger>(j))] - contact).dot(across);
  }
  const double hand_across = MedianInPlace(offsets.begin(), offsets.end());
  const double wl = options.lateral_weight, wn = options.normal_weight;
  const double wh = options.hand_lateral_weight;
  // n > 0: off the board. Beyond either margin the height counts in full.
  const double beyond =
      std::max(0.0, -n - options.below_margin_mm) + std::max(0.0, n - above_margin_mm);
  *distance = std::sqrt(a * a + wl * wl * l * l + wn * wn * n * n + beyond * beyond +
                        wh * wh * hand_across * hand_across);
  double violation = 0;
  for (int j = 1; j <= 4; ++j) {
    if (j == finger) continue;
    const double aj =
        (points[hand::TipKeypoint(static_cast<hand::Finger>(j))] - contact).dot(sf.along);
    violation += j < finger ? std::max(0.0, -aj - options.order_margin_mm)
                            : std::max(0.0, aj - options.order_margin_mm);
  }
  *order = violation;
}

std::vector<FrameContact> DecodeArco(const DecodeContext& context,
                                     const ArcoDecodeOptions& options,
                                     const PitchModelOptions& pitch_options,
                                     const std::array<double, 5>& lift_max_mm,
                                     int num_threads) {
  const RefineInput& input = *context.input;
  const int n = context.num_frames();
  std::vector<FrameContact> out(static_cast<size_t>(n));
  for (int f = 0; f < n; ++f) out[static_cast<size_t>(f)] = AudioOnlyContact(context, f);

  const std::vector<NoteSpan>& notes = context.analysis->notes;
  const bool audio_onsets = options.audio_onsets && !input.audio_notes.empty();
  std::vector<int> usable;
  for (int i = 0; i < static_cast<int>(notes.size()); ++i) {
    if (notes[static_cast<size_t>(i)].usable) usable.push_back(i);
  }
  // Emissions, note by note in parallel (each note writes its own slot).
  std::vector<std::vector<State>> states(usable.size());
  ParallelFor(
      static_cast<int64_t>(usable.size()),
      num_threads,
      [&](int64_t u, int) {
        states[static_cast<size_t>(u)] =
            NoteStates(context,
                       notes[static_cast<size_t>(usable[static_cast<size_t>(u)])],
                       options,
                       pitch_options,
                       lift_max_mm);
      },
      1);

  // Viterbi over the usable notes (notes without any state are skipped: unplayable).
  std::vector<int> chain;
  for (size_t u = 0; u < usable.size(); ++u) {
    if (!states[u].empty()) chain.push_back(static_cast<int>(u));
  }
  std::vector<int> num_states(chain.size());
  for (size_t c = 0; c < chain.size(); ++c) {
    num_states[c] = static_cast<int>(states[static_cast<size_t>(chain[c])].size());
  }
  auto state_at = [&](size_t c, int k) -> const State& {
    return states[static_cast<size_t>(chain[c])][static_cast<size_t>(k)];
  };
  auto note_at = [&](size_t c) -> const NoteSpan& {
    return notes[static_cast<size_t>(usable[static_cast<size_t>(chain[c])])];
  };
  // One camera: the hand's shifts cost more, the more the view foreshortens the strings.
  ArcoDecodeOptions transition_options = options;
  transition_options.shift_cost_per_semitone *= OneViewShiftFactor(context, options);
  const std::vector<int> chosen = DecodeViterbi(
                                      num_states,
                                      [&](size_t c, int k) { return state_at(c, k).cost; },
                                      [&](size_t c, int j, int k) {
                                        return TransitionCost(note_at(c - 1),
                                                              note_at(c),
                                                              state_at(c - 1, j),
                                                              state_at(c, k),
                                                              transition_options,
                                                              input.fps);
                                      })
                                      .states;

  // Frames of the decoded notes.
  std::vector<uint8_t> decoded_note(notes.size(), 0);
  for (size_t c = 0; c < chain.size(); ++c) {
    const int note_index = usable[static_cast<size_t>(chain[c])];
    decoded_note[static_cast<size_t>(note_index)] = 1;
    const NoteSpan& note = notes[static_cast<size_t>(note_index)];
    const State& st = states[static_cast<size_t>(chain[c])][static_cast<size_t>(chosen[c])];
    for (int64_t f = note.first_frame; f <= note.last_frame; ++f) {
      const size_t i = static_cast<size_t>(f);
      const FrameAudioState a = context.analysis->frame_state[i];
      if (a == FrameAudioState::kNote) {
        AssignFrame(context,
                    options,
                    st.string,
                    st.finger,
                    out[i].f0_hz,
                    pitch_options,
                    lift_max_mm,
                    f,
                    &out[i]);
      } else if (a == FrameAudioState::kBoundary) {
        // The frame's own pitch straddles the change: the note's pitch instead.
        AssignFrame(context,
                    options,
                    st.string,
                    st.finger,
                    note.f0_hz,
                    pitch_options,
                    lift_max_mm,
                    f,
                    &out[i]);
        if (out[i].reason == ContactReason::kNone) out[i].reason = ContactReason::kNoteBoundary;
      }
    }
    if (st.finger == 0) continue;
    // The finger lands before the sound: untrusted frames just before the onset, where the
    // fitted fingertip is about as near the contact as during the note itself.
    std::vector<double> note_distances;
    for (int64_t f = note.first_frame; f <= note.last_frame; ++f) {
      const double d = out[static_cast<size_t>(f)].tip_distance_vision_mm;
      if (out[static_cast<size_t>(f)].note == note_index && std::isfinite(d))
        note_distances.push_back(d);
    }
    if (note_distances.empty()) continue;
    const double lead_max_mm = std::min(lift_max_mm[static_cast<size_t>(st.finger)],
                                        Median(note_distances) + options.onset_lead_margin_mm);
    // The pitch of the note's first trusted frame (boundary frames before it have none).
    double onset_hz = note.f0_hz;
    for (int64_t f = note.first_frame; f <= note.last_frame; ++f) {
      if (context.analysis->frame_state[static_cast<size_t>(f)] == FrameAudioState::kNote) {
        onset_hz = input.pitch[static_cast<size_t>(f)].f0_hz;
        break;
      }
    }
    // A gap of untrusted frames no longer than onset_lead_frames after a stopped frame on
    // this note's string (header comment): its frames that hear the note skip the
    // fitted-tip test.
    bool bridged = false;
    if (options.bridge_short_gaps) {
      int64_t g = note.first_frame - 1;
      while (g >= 0 && g >= note.first_frame - options.onset_lead_frames &&
             !out[static_cast<size_t>(g)].pressed() &&
             out[static_cast<size_t>(g)].state != ContactState::kOpenString) {
        --g;
      }
      const FrameContact* before = g >= 0 ? &out[static_cast<size_t>(g)] : nullptr;
      bridged = before && g < note.first_frame - 1 && before->pressed() && before->finger > 0 &&
                before->string == st.string;
    }
    for (int64_t f = note.first_frame - 1;
         f >= 0 && f >= note.first_frame - options.onset_lead_frames;
         --f) {
      const size_t i = static_cast<size_t>(f);
      const FrameAudioState a = context.analysis->frame_state[i];
      // Weak frames that merely continued the previous note are the transition too.
      // With the audio's onsets the note boundaries are known (note_boundaries.h): the
      // frames still with the previous note sound it, so neither rule below applies.
      const bool weak_member = !audio_onsets && a == FrameAudioState::kNote &&
                               input.pitch[i].confidence < pitch_options.min_confidence;
      const bool untrusted = a == FrameAudioState::kRest || a == FrameAudioState::kLowConfidence ||
                             a == FrameAudioState::kOutlier || a == FrameAudioState::kShortNote ||
                             weak_member;
      // The sound lags the hand by up to a frame at a note change: the previous note's last
      // frame goes to this note when the fitted hand clearly plays this one already.
      const bool handover = !audio_onsets && f == note.first_frame - 1 &&
                            a == FrameAudioState::kNote && out[i].pressed() &&
                            out[i].note != note_index;
      if (!untrusted && !handover) break;
      FrameContact lead = out[i];
      lead.note = note_index;
      AssignFrame(
          context, options, st.string, st.finger, onset_hz, pitch_options, lift_max_mm, f, &lead);
      // Only where the fitted finger is already near its contact (not still on its way),
      // and nearer than to the previous note's contact; in a short gap that hears the note
      // whatever the fitted hand says (header comment).
      if (!lead.pressed()) break;
      // The tracker hears this note there, if not confidently (half a semitone).
      const bool hears_note =
          input.pitch[i].f0_hz > 0 &&
          std::abs(CentsBetween(onset_hz, input.pitch[i].f0_hz)) <= kHalfSemitoneCents;
      const bool bridge = bridged && untrusted && hears_note;
      if (!bridge && !(lead.tip_distance_vision_mm <= lead_max_mm)) break;
      const double margin = untrusted ? 0.0 : options.handover_margin_mm;
      if (out[i].pressed() &&
          !(lead.tip_distance_vision_mm < out[i].tip_distance_vision_mm - margin)) {
        break;
      }
      if (lead.reason == ContactReason::kNone) lead.reason = ContactReason::kBeforeOnset;
      out[i] = lead;
    }
  }
  // Glides (header comment): transition frames between two notes on the same string.
  if (options.glide_frames > 0) {
    auto transition = [&](int f) {
      const FrameContact& c = out[static_cast<size_t>(f)];
      return c.reason == ContactReason::kNoteBoundary || c.reason == ContactReason::kBeforeOnset;
    };
    // A note's own frame: pressed, stopped, not a transition (never modified below).
    auto anchor = [&](int f) {
      const FrameContact& c = out[static_cast<size_t>(f)];
      return c.pressed() && c.finger > 0 && !transition(f) && c.f0_hz > 0 &&
             c.point_in_world_mm.allFinite();
    };
    for (int f = 0; f < n; ++f) {
      const FrameContact& c = out[static_cast<size_t>(f)];
      if (!c.pressed() || c.finger == 0 || !transition(f)) continue;
      int p = -1, q = -1;
      for (int g = f - 1; g >= 0 && g >= f - options.glide_frames; --g) {
        if (anchor(g)) {
          p = g;
          break;
        }
      }
      for (int g = f + 1; g < n && g <= f + options.glide_frames; ++g) {
        if (anchor(g)) {
          q = g;
          break;
        }
      }
      if (p < 0 || q < 0) continue;
      const FrameContact& cp = out[static_cast<size_t>(p)];
      const FrameContact& cq = out[static_cast<size_t>(q)];
      if (cp.note == cq.note || cp.string != c.string || cq.string != c.string) continue;
      // The glide is heard: the frame's own pitch, trusted, between the two notes'.
      const double lo = std::min(cp.f0_hz, cq.f0_hz), hi = std::max(cp.f0_hz, cq.f0_hz);
      const FramePitch& own = input.pitch[static_cast<size_t>(f)];
      if (!(own.f0_hz >= lo && own.f0_hz <= hi && own.confidence >= pitch_options.min_confidence))
        continue;
      FrameContact glide = c;
      AssignFrame(
          context, options, c.string, c.finger, own.f0_hz, pitch_options, lift_max_mm, f, &glide);
      if (!glide.pressed()) continue;  // the lift test: keep the note's contact
      glide.reason = c.reason;
      out[static_cast<size_t>(f)] = glide;
    }
  }
  // Usable notes that no string can play.
  for (int note_index : usable) {
    if (decoded_note[static_cast<size_t>(note_index)]) continue;
    const NoteSpan& note = notes[static_cast<size_t>(note_index)];
    for (int64_t f = note.first_frame; f <= note.last_frame; ++f) {
      FrameContact& fc = out[static_cast<size_t>(f)];
      if (fc.state == ContactState::kUncertain && fc.reason == ContactReason::kNone) {
        fc.reason = ContactReason::kUnplayable;
      }
    }
  }
  return out;
}

}  // namespace arco::refine
