// Stage 5 of `arco run` and all of `arco refine` (run.h): the refinement's input read back
// from the result folder, so both commands refine exactly the same data.
#include <cmath>
#include <sstream>

#include "arco/audio/pitch_tracker.h"
#include "arco/cli/run_stages.h"
#include "arco/util/file_io.h"

namespace arco::cli::internal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Status Expect(bool ok, const std::string& path, const std::string& what) {
  return ok ? Status::Ok() : Status::Error(path + ": " + what);
}

// The note rows of the audio layer's notes.csv (audio::WriteNotesCsv): onset, offset and
// median pitch; glides and other kinds are skipped.
StatusOr<std::vector<refine::AudioNote>> ReadAudioNotes(const std::string& path) {
  ARCO_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line) || line.rfind("kind,onset_s,offset_s,median_f0_hz", 0) != 0) {
    return Status::Error(path + ": not a notes.csv (bad header)");
  }
  std::vector<refine::AudioNote> notes;
  int line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.empty() || line.rfind("note,", 0) != 0) continue;
    refine::AudioNote n;
    if (std::sscanf(line.c_str(), "note,%lf,%lf,%lf", &n.onset_s, &n.offset_s, &n.f0_hz) != 3 ||
        !(std::isfinite(n.onset_s) && std::isfinite(n.offset_s) && n.offset_s >= n.onset_s &&
          n.f0_hz > 0 && std::isfinite(n.f0_hz)) ||
        (!notes.empty() && n.onset_s < notes.back().onset_s)) {
      return Status::Error(path + ": line " + std::to_string(line_number) + ": malformed note row");
    }
    notes.push_back(n);
  }
  return notes;
}

}  // namespace

StatusOr<RefineInputs> LoadRefineInputs(const std::string& result_dir) {
  ARCO_ASSIGN_OR_RETURN(Json manifest, ReadResultManifest(result_dir));
  const std::string manifest_path = JoinPath(result_dir, kResultManifestName);
  if (!manifest.contains("stages") || !manifest["stages"].contains("hand")) {
    return Status::Error(manifest_path + ": no hand stage (run `arco run` first)");
  }
  ARCO_ASSIGN_OR_RETURN(const double s, WorldUnitsPerMm(manifest, result_dir));
  const Json& inst = manifest["stages"]["instrument"];
  ARCO_ASSIGN_OR_RETURN(InstrumentKind kind,
                        ParseInstrumentKind(inst.value("instrument", std::string())));
  InstrumentOptions io;
  io.kind = kind;
  io.tuning.a4_hz = JsonNumberOrNaN(inst.value("a4_hz", Json(440.0)));
  StatusOr<InstrumentModel> model = InstrumentModel::Create(io);
  if (!model.ok()) return model.status().WithContext(manifest_path);
  RefineInputs out;
  out.instrument = std::make_shared<const InstrumentModel>(std::move(model).value());
  const InstrumentModel& m = *out.instrument;
  const double fps = JsonNumberOrNaN(manifest.value("fps", Json()));

  // Triangulated points (world units) -> mm; the instrument keypoints from the template.
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> base, ReadResultPoints3d(result_dir, "triangulation"));
  const std::string strings_path = JoinPath(result_dir, "instrument/strings.npy");
  const std::string placed_path = JoinPath(result_dir, "instrument/keypoints.npy");
  const std::string hands_path = JoinPath(result_dir, "hand/hand_params.npy");
  const std::string bones_path = JoinPath(result_dir, "hand/bone_lengths_mm.npy");
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> strings, ReadNpy<double>(strings_path));
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> placed, ReadNpy<double>(placed_path));
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> params, ReadNpy<double>(hands_path));
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> bones, ReadNpy<double>(bones_path));
  const int64_t frames = base.shape.empty() ? 0 : base.shape[0];
  const int64_t num_k = static_cast<int64_t>(m.keypoint_names().size());
  const int64_t num_base = 133 + num_k;
  ARCO_RETURN_IF_ERROR(
      Expect(base.shape.size() == 3 && base.shape[1] == num_base && base.shape[2] == 3,
             JoinPath(result_dir, "triangulation/points3d.npy"),
             "expected (frames, " + std::to_string(num_base) + ", 3)"));
  ARCO_RETURN_IF_ERROR(Expect(strings.shape == std::vector<int64_t>{frames, m.num_strings(), 2, 3},
                              strings_path,
                              "expected (frames, strings, 2, 3)"));
  ARCO_RETURN_IF_ERROR(Expect(placed.shape == std::vector<int64_t>{frames, num_k, 3},
                              placed_path,
                              "expected (frames, instrument keypoints, 3)"));
  ARCO_RETURN_IF_ERROR(Expect(bones.shape == std::vector<int64_t>{hand::kNumHandKeypoints},
                              bones_path,
                              "expected 21 bone lengths"));
  ARCO_RETURN_IF_ERROR(Expect(!params.shape.empty() && params.shape[0] == frames,
                              hands_path,
                              "frame count differs from the triangulation's"));
  ARCO_ASSIGN_OR_RETURN(out.input.vision_hand, refine::HandsFromParams(params, hands_path));

  hand::BoneLengthsMm lengths{};
  for (int k = 0; k < hand::kNumHandKeypoints; ++k)
    lengths[static_cast<size_t>(k)] = bones.data[static_cast<size_t>(k)];
  StatusOr<hand::HandModel> hand_model =
      hand::HandModel::Default(hand::HandSide::kLeft).WithBoneLengths(lengths);
  if (!hand_model.ok()) return hand_model.status().WithContext(bones_path);

  NpyArray<double> base_mm = base;
  for (double& v : base_mm.data) v /= s;
  for (int64_t f = 0; f < frames; ++f) {
    for (int64_t k = 0; k < num_k; ++k) {
      if (!std::isfinite(placed.at(f, k, 0))) continue;  // bow points, frames without a pose
      for (int c = 0; c < 3; ++c) base_mm.at(f, 133 + k, c) = placed.at(f, k, c);
    }
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

  out.input.instrument = out.instrument.get();
  out.input.hand_model = *hand_model;
  out.input.strings_in_world_mm = seg;
  out.input.fps = fps > 0 ? fps : 30.0;
  out.input.a4_hz = io.tuning.a4_hz;
  out.input.pitch.assign(static_cast<size_t>(frames), refine::FramePitch{});
  out.has_pitch = manifest["stages"].contains("pitch");
  if (out.has_pitch) {
    const std::string pitch_path = JoinPath(result_dir, "pitch.csv");
    ARCO_ASSIGN_OR_RETURN(std::vector<audio::PitchFrame> pitch, audio::ReadPitchCsv(pitch_path));
    ARCO_RETURN_IF_ERROR(Expect(
        static_cast<int64_t>(pitch.size()) == frames,
        pitch_path,
        "has " + std::to_string(pitch.size()) + " rows for " + std::to_string(frames) + " frames"));
    for (int64_t f = 0; f < frames; ++f) {
      const audio::PitchFrame& p = pitch[static_cast<size_t>(f)];
      out.input.pitch[static_cast<size_t>(f)] = {p.voiced ? p.f0_hz : 0.0, p.confidence};
    }
    if (!pitch.empty()) out.input.start_s = pitch.front().time_s;
    // notes.csv: the onsets for arco's note boundaries (result folders of older versions
    // have none: frames are then assigned by their own pitch).
    const std::string notes_path = JoinPath(result_dir, "notes.csv");
    if (FileExists(notes_path)) {
      ARCO_ASSIGN_OR_RETURN(out.input.audio_notes, ReadAudioNotes(notes_path));
    }
  }
  out.spd.instrument = out.instrument.get();
  out.spd.hand_model = *hand_model;
  out.spd.base_points_mm = std::move(base_mm);
  out.spd.strings_in_world_mm = std::move(seg);
  return out;
}

StatusOr<refine::RefineSummary> RefineAndWrite(const std::string& result_dir,
                                               const RefineInputs& inputs,
                                               const refine::RefineOptions& options) {
  if (options.mode != refine::RefineMode::kVision && !inputs.has_pitch) {
    return Status::Error(JoinPath(result_dir, kResultManifestName) +
                         ": no pitch stage (the capture has no audio); only vision can be written");
  }
  const refine::RefineResult r = refine::Refine(inputs.input, options);
  refine::MethodOutput out;
  out.method = refine::RefineModeName(options.mode);
  out.layout = refine::SpdContactLayoutName(*inputs.instrument);
  out.points3d = refine::BuildSpdPoints(
      inputs.spd, r.hand, options.mode == refine::RefineMode::kVision ? nullptr : &r.contacts);
  out.hands = r.hand;
  out.contacts = r.contacts;
  out.fingering = r.fingering;
  const refine::RefineSummary& s = r.summary;
  out.options = {{"mode", out.method},
                 {"min_confidence", options.pitch.min_confidence},
                 {"binding_cents", options.paper.binding_cents},
                 {"ik_joints",
                  hand::FingerIkJointsName(options.mode == refine::RefineMode::kPaper
                                               ? hand::FingerIkJoints::kPipDip
                                               : options.ik.joints)},
                 {"max_residual_mm", options.ik.max_residual_mm},
                 {"audio_onsets",
                  options.mode == refine::RefineMode::kArco && options.decode.audio_onsets &&
                      !inputs.input.audio_notes.empty()}};
  out.summary = {{"frames", s.frames},
                 {"frames_with_hand", s.frames_with_hand},
                 {"pressed", s.pressed},
                 {"open_string", s.open_string},
                 {"rest", s.rest},
                 {"uncertain", s.uncertain},
                 {"notes", s.notes},
                 {"usable_notes", s.usable_notes},
                 {"corrected_frames", s.corrected_frames},
                 {"rejected_out_of_reach", s.rejected_out_of_reach},
                 {"before_onset", s.before_onset},
                 {"note_boundary", s.note_boundary},
                 {"mean_tip_distance_vision_mm", JsonFromDouble(s.mean_tip_distance_vision_mm)},
                 {"mean_tip_distance_refined_mm", JsonFromDouble(s.mean_tip_distance_refined_mm)},
                 {"joint_limit_violations", s.joint_limit_violations}};
  ARCO_RETURN_IF_ERROR(refine::WriteMethodResult(result_dir, out));
  return s;
}

}  // namespace arco::cli::internal
