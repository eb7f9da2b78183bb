#include "arco/pipeline/refine_stage.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <vector>

#include "arco/body/skeleton_fit.h"
#include "arco/pipeline/capture_context.h"
#include "arco/pipeline/result_folder.h"
#include "arco/refine/double_stop_refine.h"
#include "arco/refine/transcription.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/util/file_io.h"

namespace arco::pipeline {
namespace {

constexpr int kNumWholeBody = wholebody::kNumPoints;

Status Expect(bool ok, const std::string& path, const std::string& what) {
  return ok ? Status::Ok() : Status::Error(path + ": " + what);
}

// The arco method's body and right hand: the triangulated points replaced by a skeleton
// of fixed bone lengths fitted to them (body/skeleton_fit.h; docs/export.md, "BVH").
// Every point weighs the same: weighting by the triangulation's inlier count and
// reprojection RMS made the fit worse on the synthetic takes (body 7.02 -> 7.23 mm by
// views alone, 7.43 mm with the RMS; docs/export.md), plausibly because the points are
// temporally filtered after triangulation, so a frame's RMS no longer describes them.
StatusOr<NpyArray<double>> FitBody(const RefineInputs& inputs, int num_threads) {
  const KeypointLayout* layout =
      FindKeypointLayout(refine::SpdContactLayoutName(*inputs.instrument));
  const NpyArray<double>& base = inputs.spd.base_points_mm;
  if (layout == nullptr || layout->size() < base.shape[1]) {
    return Status::Error("no keypoint layout for the instrument's points");
  }
  const std::vector<std::string> names(layout->names.begin(),
                                       layout->names.begin() + base.shape[1]);
  body::SkeletonFitOptions options;
  options.num_threads = num_threads;
  ARCO_ASSIGN_OR_RETURN(body::SkeletonFitResult fit, body::FitSkeleton(base, names, {}, options));
  return std::move(fit.points_mm);
}

}  // namespace

Status AnalyzeBowArm(const refine::BowingOptions& options, RefineInputs* inputs_out) {
  const RefineInputs& inputs = *inputs_out;
  const InstrumentModel& m = *inputs.instrument;
  const std::vector<std::string>& names = m.keypoint_names();
  const auto frog = std::find(names.begin(), names.end(), "frog");
  const auto tip = std::find(names.begin(), names.end(), "tip");
  if (frog == names.end() || tip == names.end()) {
    return Status::Error(std::string("the ") + m.name() + " layout has no frog and tip");
  }
  const int64_t frog_index = kNumWholeBody + (frog - names.begin());
  const int64_t tip_index = kNumWholeBody + (tip - names.begin());
  const NpyArray<double>& points = inputs.spd.base_points_mm;
  const int64_t frames = points.shape.empty() ? 0 : points.shape[0];
  refine::BowingInput in;
  for (int64_t f = 0; f < frames; ++f) {
    auto point = [&](int64_t k) {
      return Eigen::Vector3d(points.at(f, k, 0), points.at(f, k, 1), points.at(f, k, 2));
    };
    in.frog_in_world_mm.push_back(point(frog_index));
    in.tip_in_world_mm.push_back(point(tip_index));
  }
  in.strings_in_world_mm = inputs.input.strings_in_world_mm;
  in.fps = inputs.input.fps;
  in.start_s = inputs.input.start_s;
  ARCO_ASSIGN_OR_RETURN(refine::BowingResult bow, refine::AnalyzeBowStrokes(m, in, options));
  inputs_out->bow = std::move(bow);
  inputs_out->bowing_options = options;
  return Status::Ok();
}

Status RefineStageOptions::Validate() const {
  if (result_dir.empty()) return Status::Error("result_dir is empty");
  ARCO_RETURN_IF_ERROR(bowing.Validate());
  return refine.Validate();
}

StatusOr<RefineInputs> LoadRefineInputs(const std::string& result_dir,
                                        const refine::BowingOptions& bowing) {
  const ResultFolder result(result_dir);
  ARCO_ASSIGN_OR_RETURN(const bool has_hand, result.HasStage(kHandStage));
  if (!has_hand) {
    return Status::Error(result.ManifestPath() + ": no hand stage (run `arco run` first)");
  }
  ARCO_ASSIGN_OR_RETURN(const ResultHeader header, result.ReadHeader());
  ARCO_ASSIGN_OR_RETURN(const InstrumentRecord instrument, result.ReadInstrument());
  ARCO_ASSIGN_OR_RETURN(const NpyArray<double> base, result.ReadPoints3d(kTriangulationStage));
  ARCO_ASSIGN_OR_RETURN(const HandRecord hand, result.ReadHand());
  StageRecords records;
  records.fps = header.fps;
  records.points3d_in_world = &base;
  records.instrument = &instrument;
  records.hand = &hand;
  ARCO_ASSIGN_OR_RETURN(const bool has_pitch, result.HasStage(kPitchStage));
  std::vector<audio::PitchFrame> pitch;
  if (has_pitch) {
    ARCO_ASSIGN_OR_RETURN(pitch, result.ReadPitch());
    records.pitch = &pitch;
    // notes.csv: the onsets for arco's note boundaries (result folders of older versions
    // have none: frames are then assigned by their own pitch).
    ARCO_ASSIGN_OR_RETURN(records.notes, result.ReadNotes());
  }
  // One camera: its centre, recorded by the triangulation stage.
  ARCO_ASSIGN_OR_RETURN(const Json manifest, result.ReadManifest());
  const Json* centre = nullptr;
  if (manifest.contains("stages") && manifest["stages"].contains(kTriangulationStage) &&
      manifest["stages"][kTriangulationStage].contains("depth") &&
      manifest["stages"][kTriangulationStage]["depth"].contains("camera_centre_in_world"))
    centre = &manifest["stages"][kTriangulationStage]["depth"]["camera_centre_in_world"];
  if (centre != nullptr) {
    if (!centre->is_array() || centre->size() != 3 || !(*centre)[0].is_number() ||
        !(*centre)[1].is_number() || !(*centre)[2].is_number())
      return Status::Error(result.ManifestPath() +
                           ": stages.triangulation.depth.camera_centre_in_world must be 3 numbers");
    records.one_view_camera_centre_in_world = Eigen::Vector3d(
        (*centre)[0].get<double>(), (*centre)[1].get<double>(), (*centre)[2].get<double>());
  }
  ARCO_ASSIGN_OR_RETURN(RefineInputs inputs, MakeRefineInputs(result_dir, records));
  // double_stops.csv (`arco run --double-stops`): the two voices the run refined.
  if (has_pitch) {
    ARCO_RETURN_IF_ERROR(AnalyzeBowArm(bowing, &inputs));
    ARCO_ASSIGN_OR_RETURN(const std::vector<audio::PolyPitchFrame> double_stops,
                          result.ReadDoubleStops());
    if (double_stops.size() > inputs.input.pitch.size()) {
      return Status::Error(result.ManifestPath() + ": double_stops.csv has " +
                           std::to_string(double_stops.size()) + " rows for " +
                           std::to_string(inputs.input.pitch.size()) + " frames");
    }
    if (!double_stops.empty()) {
      AddDoubleStops(double_stops, &inputs, refine::DoubleStopRefineOptions().bow_pairs);
    }
  }
  return inputs;
}

StatusOr<RefineInputs> MakeRefineInputs(const std::string& result_dir,
                                        const StageRecords& records) {
  const ResultFolder result(result_dir);
  const InstrumentRecord& instrument = *records.instrument;
  const double s = instrument.world_units_per_mm;
  RefineInputs out;
  out.instrument = records.model;
  if (!out.instrument) {
    ARCO_ASSIGN_OR_RETURN(InstrumentKind kind, ParseInstrumentKind(instrument.instrument));
    InstrumentOptions io;
    io.kind = kind;
    io.tuning.a4_hz = instrument.a4_hz;
    StatusOr<InstrumentModel> model = InstrumentModel::Create(io);
    if (!model.ok()) return model.status().WithContext(result.ManifestPath());
    out.instrument = std::make_shared<const InstrumentModel>(std::move(model).value());
  }
  const InstrumentModel& m = *out.instrument;

  // Triangulated points (world units) -> mm; the instrument keypoints from the template.
  const NpyArray<double>& base = *records.points3d_in_world;
  const NpyArray<double>& strings = instrument.strings_mm;
  const NpyArray<double>& placed = instrument.keypoints_mm;
  const std::string strings_path = result.InstrumentStringsPath();
  const std::string placed_path = result.InstrumentKeypointsPath();
  const std::string hands_path = result.HandParamsPath();
  const HandRecord& hand = *records.hand;
  const int64_t frames = base.shape.empty() ? 0 : base.shape[0];
  const int64_t num_k = static_cast<int64_t>(m.keypoint_names().size());
  const int64_t num_base = kNumWholeBody + num_k;
  ARCO_RETURN_IF_ERROR(
      Expect(base.shape.size() == 3 && base.shape[1] == num_base && base.shape[2] == 3,
             result.Points3dPath(kTriangulationStage),
             "expected (frames, " + std::to_string(num_base) + ", 3)"));
  ARCO_RETURN_IF_ERROR(Expect(strings.shape == std::vector<int64_t>{frames, m.num_strings(), 2, 3},
                              strings_path,
                              "expected (frames, strings, 2, 3)"));
  ARCO_RETURN_IF_ERROR(Expect(placed.shape == std::vector<int64_t>{frames, num_k, 3},
                              placed_path,
                              "expected (frames, instrument keypoints, 3)"));
  ARCO_RETURN_IF_ERROR(Expect(static_cast<int64_t>(hand.hands.size()) == frames,
                              hands_path,
                              "frame count differs from the triangulation's"));
  out.input.vision_hand = hand.hands;
  StatusOr<hand::HandModel> hand_model =
      hand::HandModel::Default(hand::HandSide::kLeft).WithRestPoints(hand.rest_points_mm);
  if (!hand_model.ok()) {
    return hand_model.status().WithContext(result.BoneLengthsPath());
  }

  NpyArray<double> base_mm = PointsInMm(base, s);
  for (int64_t f = 0; f < frames; ++f) {
    for (int64_t k = 0; k < num_k; ++k) {
      if (!std::isfinite(placed.at(f, k, 0))) continue;  // bow points, frames without a pose
      for (int c = 0; c < 3; ++c) base_mm.at(f, kNumWholeBody + k, c) = placed.at(f, k, c);
    }
  }
  // The left hand as triangulated (before the model fit): how far arco's IK may move the
  // fitted hand (refine.h, RefineInput::detected_left_hand).
  out.input.detected_left_hand.resize(static_cast<size_t>(frames));
  for (int64_t f = 0; f < frames; ++f) {
    hand::HandPointsMm points;
    for (int k = 0; k < hand::kNumHandKeypoints; ++k) {
      const int64_t p = wholebody::kLeftHandFirst + k;
      points[static_cast<size_t>(k)] =
          Eigen::Vector3d(base_mm.at(f, p, 0), base_mm.at(f, p, 1), base_mm.at(f, p, 2));
    }
    out.input.detected_left_hand[static_cast<size_t>(f)] = points;
  }
  std::vector<std::vector<StringSegment>> seg(static_cast<size_t>(frames));
  for (int64_t f = 0; f < frames; ++f) {
    std::vector<StringSegment> frame_strings;
    bool finite = true;
    for (int i = 0; i < m.num_strings(); ++i) {
      StringSegment sgm;
      sgm.string = i + 1;
      sgm.nut =
          Eigen::Vector3d(strings.at(f, i, 0, 0), strings.at(f, i, 0, 1), strings.at(f, i, 0, 2));
      sgm.bridge =
          Eigen::Vector3d(strings.at(f, i, 1, 0), strings.at(f, i, 1, 1), strings.at(f, i, 1, 2));
      finite = finite && sgm.nut.allFinite() && sgm.bridge.allFinite();
      frame_strings.push_back(sgm);
    }
    if (finite) seg[static_cast<size_t>(f)] = std::move(frame_strings);
  }

  const double fps = records.fps;
  out.input.instrument = out.instrument;
  out.input.hand_model = *hand_model;
  out.input.strings_in_world_mm = seg;
  out.input.fps = fps > 0 ? fps : 30.0;
  out.input.a4_hz = instrument.a4_hz;
  if (records.one_view_camera_centre_in_world)
    out.input.one_view_camera_centre_mm = PointInMm(*records.one_view_camera_centre_in_world, s);
  out.input.pitch.assign(static_cast<size_t>(frames), refine::FramePitch{});
  out.has_pitch = records.pitch != nullptr;
  if (out.has_pitch) {
    const std::vector<audio::PitchFrame>& pitch = *records.pitch;
    ARCO_RETURN_IF_ERROR(Expect(
        static_cast<int64_t>(pitch.size()) == frames,
        result.PitchPath(),
        "has " + std::to_string(pitch.size()) + " rows for " + std::to_string(frames) + " frames"));
    for (int64_t f = 0; f < frames; ++f) {
      const audio::PitchFrame& p = pitch[static_cast<size_t>(f)];
      out.input.pitch[static_cast<size_t>(f)] = {p.voiced ? p.f0_hz : 0.0, p.confidence};
    }
    if (!pitch.empty()) out.input.start_s = pitch.front().time_s;
    for (const audio::Note& n : records.notes) {
      out.input.audio_notes.push_back({n.onset_s, n.offset_s, n.median_f0_hz});
    }
  }
  out.spd.instrument = out.instrument;
  out.spd.hand_model = *hand_model;
  out.spd.base_points_mm = std::move(base_mm);
  out.spd.strings_in_world_mm = std::move(seg);
  return out;
}

namespace {

// Within half a semitone (audio/double_stops.h's notes are each within a few cents of the
// single-note tracker's reading of the same note).
bool SameNote(double a_hz, double b_hz) {
  return a_hz > 0 && b_hz > 0 && std::abs(CentsBetween(b_hz, a_hz)) < 50.0;
}

// A note to the nearest semitone (a key: only equality matters, so A4 = 440 Hz will do).
int64_t Semitone(double f0_hz) { return std::llround(CentsBetween(440.0, f0_hz) / 100.0); }

}  // namespace

FrameVoices VoicesOfFrame(const audio::PolyPitchFrame& poly,
                          const refine::FramePitch& heard,
                          const refine::BowRest& rest) {
  FrameVoices out;
  out.first = heard;
  // BowRest: `string` the lower string of the pair, second_string = string - 1 the upper;
  // on_strings[s - 1] holds strings s + 1 and s.
  if (rest.second_string >= 1 && rest.second_string <= audio::kStringPairs) {
    const std::array<audio::PolyNote, 2>& on = poly.on_strings[rest.second_string - 1];
    // An octave where the free analysis heard one note is left to the note's own rule
    // (bow_octaves, double_stop_refine.h step 0c): a single note's 2nd partial is that
    // octave, and a bow crossing between two strings rests on both for a few frames. Not
    // where that one note is neither of the pair's (the double bass's open E1 with E2 on
    // the A string heard as E3, a partial of both).
    const bool lone_octave =
        poly.count != 2 && on[0].f0_hz > 0 &&
        std::abs(12.0 * std::log2(on[1].f0_hz / on[0].f0_hz) - 12.0) < 0.5 &&
        !(poly.count == 1 && !SameNote(poly.notes[0].f0_hz, on[0].f0_hz) &&
          !SameNote(poly.notes[0].f0_hz, on[1].f0_hz));
    if (on[0].f0_hz > 0 && on[1].f0_hz > 0 && !lone_octave) {
      out.first = {on[0].f0_hz, 1.0};
      out.upper_f0_hz = on[1].f0_hz;
      out.bowed_pair_lower_string = rest.string;
      return out;
    }
  }
  if (poly.count != 2) return out;
  // The bow clearly on one string: one note sounds, so a pair the free analysis heard there
  // holds a ghost (an attack's transient, a partial of the note, a rest's noise; the ghost
  // below a cello's B2 flipped the first voice every few frames, and the pitch model took
  // the stretch for a tracker torn between notes and dropped the double stop after it).
  // Unless the single-note tracker hears the pair's lower note, its own reading stays the
  // first voice and there is no second.
  if (rest.string > 0 && rest.second_string == 0 && rest.off_deg <= kOneStringRestDeg &&
      !SameNote(heard.f0_hz, poly.notes[0].f0_hz)) {
    return out;
  }
  out.first = {poly.notes[0].f0_hz, 1.0};
  out.upper_f0_hz = poly.notes[1].f0_hz;
  return out;
}

void ConsistentBowedPairs(int window_frames, std::vector<FrameVoices>* voices) {
  if (window_frames <= 0) return;
  const std::vector<FrameVoices> heard = *voices;
  const int64_t n = static_cast<int64_t>(heard.size());
  auto key = [&](int64_t j) {
    return std::array<int64_t, 2>{Semitone(heard[j].first.f0_hz), Semitone(heard[j].upper_f0_hz)};
  };
  for (int64_t i = 0; i < n; ++i) {
    const int strings = heard[i].bowed_pair_lower_string;
    if (strings <= 0) continue;
    const int64_t lo = std::max<int64_t>(0, i - window_frames);
    const int64_t hi = std::min<int64_t>(n - 1, i + window_frames);
    // The window's pairs on the same two strings: frames per pair, and on which sides.
    std::map<std::array<int64_t, 2>, std::array<int, 3>> support;  // frames, before, after
    for (int64_t k = lo; k <= hi; ++k) {
      if (heard[k].bowed_pair_lower_string != strings) continue;
      std::array<int, 3>& s = support[key(k)];
      ++s[0];
      s[1] += k < i;
      s[2] += k > i;
    }
    const auto own = key(i);
    const int own_support = support[own][0];
    std::array<int64_t, 2> best{};
    int best_support = 0;
    for (const auto& [k, s] : support) {
      if (k == own || s[1] == 0 || s[2] == 0 || s[0] <= own_support) continue;
      if (s[0] > best_support) best = k, best_support = s[0];
    }
    if (best_support == 0) continue;
    auto holds_best = [&](int64_t j) {
      return j >= lo && j <= hi && heard[j].bowed_pair_lower_string == strings && key(j) == best;
    };
    for (int64_t d = 1; d <= window_frames; ++d) {  // its nearest frame, the earlier first
      const int64_t j = holds_best(i - d) ? i - d : holds_best(i + d) ? i + d : -1;
      if (j >= 0) {
        (*voices)[i] = heard[j];
        break;
      }
    }
  }
}

void AddDoubleStops(const std::vector<audio::PolyPitchFrame>& poly,
                    RefineInputs* inputs,
                    bool bow_pairs) {
  std::vector<refine::FramePitch>& pitch = inputs->input.pitch;
  if (poly.size() > pitch.size()) {
    throw std::invalid_argument("AddDoubleStops: more polyphonic frames than video frames");
  }
  inputs->upper_f0_hz.assign(pitch.size(), 0.0);
  inputs->bow_pair_frames = 0;
  inputs->input.bowed_pair_lower_string.clear();
  // Where the bow rests per frame; none when the layout has no bow or its frames differ.
  std::vector<refine::BowRest> rest;
  if (bow_pairs && inputs->instrument != nullptr && inputs->bow) {
    const refine::BowingResult& bow = *inputs->bow;
    if (bow.frames.size() == pitch.size()) {
      for (const refine::BowingFrame& bf : bow.frames) {
        rest.push_back(bf.string > 0 ? refine::BowRestOf(*inputs->instrument, bf.inclination_deg)
                                     : refine::BowRest());
      }
    }
  }
  std::vector<FrameVoices> voices(poly.size());
  for (size_t f = 0; f < poly.size(); ++f) {
    voices[f] = VoicesOfFrame(poly[f], pitch[f], f < rest.size() ? rest[f] : refine::BowRest());
  }
  ConsistentBowedPairs(
      static_cast<int>(std::lround(audio::DoubleStopOptions().consistency_s * inputs->input.fps)),
      &voices);
  for (size_t f = 0; f < poly.size(); ++f) {
    const FrameVoices& v = voices[f];
    pitch[f] = v.first;
    inputs->upper_f0_hz[f] = v.upper_f0_hz;
    if (v.bowed_pair_lower_string > 0) {
      ++inputs->bow_pair_frames;
      inputs->input.bowed_pair_lower_string.resize(pitch.size(), 0);
      inputs->input.bowed_pair_lower_string[f] = v.bowed_pair_lower_string;
    }
  }
}

StatusOr<refine::RefineSummary> RefineAndWrite(const std::string& result_dir,
                                               const RefineInputs& inputs,
                                               const refine::RefineOptions& options) {
  const ResultFolder result(result_dir);
  if (options.mode != refine::RefineMode::kVision && !inputs.has_pitch) {
    return Status::Error(result.ManifestPath() +
                         ": no pitch stage (the capture has no audio); only vision can be written");
  }
  ARCO_ASSIGN_OR_RETURN(const MethodRecord record, RefineMethod(inputs, options));
  ARCO_RETURN_IF_ERROR(result.WriteMethod(record));
  return record.summary;
}

StatusOr<MethodRecord> RefineMethod(const RefineInputs& inputs,
                                    const refine::RefineOptions& options) {
  if (options.mode != refine::RefineMode::kVision && !inputs.has_pitch) {
    throw std::invalid_argument(std::string("RefineMethod: ") +
                                refine::RefineModeName(options.mode) +
                                " needs the pitch stage's inputs");
  }
  refine::RefineResult r = refine::Refine(inputs.input, options);
  // arco's bow arm, analysed once (AnalyzeBowArm): its frames do not depend on the notes
  // (bowing.csv gets the final notes below; the double stops' bow gate, step 00, reads the
  // inclinations).
  std::optional<refine::BowingResult> bow;
  if (options.mode == refine::RefineMode::kArco) {
    if (!inputs.bow) {
      throw std::invalid_argument("RefineMethod: arco needs the bow arm (AnalyzeBowArm)");
    }
    bow = inputs.bow;
  }
  // arco with double stops: the upper notes' strings, fingers and the second finger's IK.
  std::vector<refine::FrameContact> second;
  const refine::DoubleStopRefineOptions double_stop_options;
  refine::DoubleStopRefineSummary double_stop_summary;
  if (options.mode == refine::RefineMode::kArco && !inputs.upper_f0_hz.empty()) {
    // The bow's inclination while it is on the strings (step 00 of double_stop_refine.h).
    std::vector<double> bow_inclination_deg;
    if (bow->frames.size() == r.contacts.size()) {
      for (const refine::BowingFrame& bf : bow->frames) {
        bow_inclination_deg.push_back(bf.string > 0 ? bf.inclination_deg
                                                    : std::numeric_limits<double>::quiet_NaN());
      }
    }
    refine::DoubleStopRefineResult ds = refine::RefineSecondVoice(
        inputs.input, r, inputs.upper_f0_hz, double_stop_options, bow_inclination_deg);
    r.hand = std::move(ds.hand);
    // The pair of fingers may have given first-voice notes another finger: their rows of
    // fingering.csv follow.
    if (ds.summary.first_fingers_changed > 0 || ds.summary.chord_frames_moved > 0) {
      r.contacts = std::move(ds.first);
      r.fingering = refine::Transcribe(
          *inputs.input.instrument, r.analysis, r.contacts, inputs.input.fps, inputs.input.a4_hz);
    }
    second = std::move(ds.second);
    double_stop_summary = ds.summary;
    double_stop_summary.bow_pairs = inputs.bow_pair_frames;
  }
  MethodRecord out;
  out.method = refine::RefineModeName(options.mode);
  out.layout = refine::SpdContactLayoutName(*inputs.instrument);
  // Only arco fits a skeleton to the body and right hand: vision and paper keep the raw
  // triangulation (the paper's method has no body model; vision is its baseline).
  const refine::SpdSources* spd = &inputs.spd;
  refine::SpdSources fitted;
  if (options.mode == refine::RefineMode::kArco) {
    fitted.instrument = inputs.spd.instrument;
    fitted.hand_model = inputs.spd.hand_model;
    fitted.strings_in_world_mm = inputs.spd.strings_in_world_mm;
    ARCO_ASSIGN_OR_RETURN(fitted.base_points_mm, FitBody(inputs, options.num_threads));
    spd = &fitted;
  }
  out.points3d = refine::BuildSpdPoints(
      *spd, r.hand, options.mode == refine::RefineMode::kVision ? nullptr : &r.contacts);
  out.hands = r.hand;
  out.contacts = r.contacts;
  if (!second.empty()) {
    out.second_fingering = refine::TranscribeSecondVoice(
        *inputs.input.instrument, r.fingering, second, inputs.input.a4_hz);
  }
  out.second_contacts = std::move(second);
  out.double_stop_options = double_stop_options;
  out.double_stop_summary = double_stop_summary;
  out.fingering = r.fingering;
  // Recorded as applied: without the audio's notes there are no onsets to use.
  out.options = options;
  if (inputs.input.audio_notes.empty()) out.options.decode.audio_onsets = false;
  out.summary = r.summary;
  if (bow) {
    refine::AddBowingNotes(r.fingering, inputs.bowing_options, &*bow);
    out.bowing = std::move(bow);
    out.bowing_options = inputs.bowing_options;
  }
  return out;
}

StatusOr<refine::RefineSummary> RunRefineStage(const RefineStageOptions& options) {
  ARCO_ASSIGN_OR_RETURN(const Validated<RefineStageOptions> valid,
                        Validated<RefineStageOptions>::Check(options));
  return RunRefineStage(valid);
}

StatusOr<refine::RefineSummary> RunRefineStage(const Validated<RefineStageOptions>& options) {
  ARCO_ASSIGN_OR_RETURN(RefineInputs inputs,
                        LoadRefineInputs(options->result_dir, options->bowing));
  return RefineAndWrite(options->result_dir, inputs, options->refine);
}

}  // namespace arco::pipeline
