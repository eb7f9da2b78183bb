#include "arco/eval/evaluate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "arco/audio/pitch_tracker.h"
#include "arco/hand/kinematics.h"
#include "arco/pipeline/result_folder.h"
#include "arco/refine/contacts_csv.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/synth/truth_folder.h"
#include "arco/util/file_io.h"
#include "arco/util/npy.h"

namespace arco::eval {
namespace {

// Stages in the order the ablation table lists them; others follow by name.
const std::vector<std::string> kMethodOrder = {"triangulation", "vision", "paper", "arco"};

// Points of `array` (F, P, 3) re-indexed into `names` by keypoint name.
StatusOr<PointSequence> ToSequence(const NpyArray<double>& array,
                                   const std::vector<std::string>& array_names,
                                   const std::vector<std::string>& names,
                                   const std::string& source) {
  if (array.shape.size() != 3 || array.shape[2] != 3) {
    return Status::Error(source + ": expected an array of shape (frames, points, 3)");
  }
  if (static_cast<int64_t>(array_names.size()) != array.shape[1]) {
    return Status::Error(source + ": " + std::to_string(array.shape[1]) +
                         " points but the layout names " + std::to_string(array_names.size()));
  }
  std::map<std::string, int> index;
  for (size_t i = 0; i < array_names.size(); ++i) index[array_names[i]] = static_cast<int>(i);
  PointSequence s(static_cast<int>(array.shape[0]), static_cast<int>(names.size()));
  for (size_t p = 0; p < names.size(); ++p) {
    auto it = index.find(names[p]);
    if (it == index.end()) continue;
    for (int f = 0; f < s.num_frames; ++f) {
      s.set(
          f,
          static_cast<int>(p),
          Eigen::Vector3d(
              array.at(f, it->second, 0), array.at(f, it->second, 1), array.at(f, it->second, 2)));
    }
  }
  return s;
}

std::string Fmt(double v, int digits = 2) {
  if (std::isnan(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.*f", digits, v);
  return buf;
}

}  // namespace

HandJointLimitsDeg DefaultLeftHandLimits() {
  const auto model = hand::HandModel::Default(hand::HandSide::kLeft);
  const hand::JointLimitsDeg& lim = model.limits_deg();
  HandJointLimitsDeg out;
  for (int f = 0; f < 5; ++f) {
    const auto finger = static_cast<hand::Finger>(f);
    out.min_deg[f][0] = lim[hand::DofIndex(finger, hand::FingerDof::kMiddleFlex)].min_deg;
    out.max_deg[f][0] = lim[hand::DofIndex(finger, hand::FingerDof::kMiddleFlex)].max_deg;
    out.min_deg[f][1] = lim[hand::DofIndex(finger, hand::FingerDof::kDistalFlex)].min_deg;
    out.max_deg[f][1] = lim[hand::DofIndex(finger, hand::FingerDof::kDistalFlex)].max_deg;
  }
  const hand::HandPointsMm rest = hand::ForwardKinematicsInWrist(model, hand::HandPose{});
  Eigen::Vector3d pts[kNumHand];
  for (int k = 0; k < kNumHand; ++k) pts[k] = rest[k];
  HandFlexionDeg(pts, /*left=*/true, out.rest_deg);
  return out;
}

ContactTrack ContactTrackFromRows(const std::vector<refine::ContactRow>& rows, int num_frames) {
  ContactTrack t;
  t.string.assign(static_cast<size_t>(num_frames), 0);
  t.finger.assign(static_cast<size_t>(num_frames), 0);
  t.point_mm.assign(static_cast<size_t>(num_frames), Eigen::Vector3d::Constant(NAN));
  for (const refine::ContactRow& row : rows) {
    if (row.frame >= num_frames) continue;
    const auto f = static_cast<size_t>(row.frame);
    t.string[f] = row.string;
    t.finger[f] = row.finger;
    t.point_mm[f] = row.point_mm;
  }
  return t;
}

// The voices of a method's contacts.csv (first) and contacts_2.csv (second, may be null):
// a pressed row sounds its string, an open row its open_string with finger 0.
std::vector<FrameVoices> MethodVoices(const std::vector<refine::ContactRow>& first,
                                      const std::vector<refine::ContactRow>& second,
                                      int num_frames) {
  std::vector<FrameVoices> v(static_cast<size_t>(num_frames));
  for (int k = 0; k < 2; ++k) {
    for (const refine::ContactRow& row : k == 0 ? first : second) {
      if (row.frame >= num_frames) continue;
      FrameVoices& fv = v[static_cast<size_t>(row.frame)];
      if (row.state == "pressed") {
        fv.string[k] = row.string;
        fv.finger[k] = row.finger;
      } else if (row.state == "open" || row.state == "open_string") {
        fv.string[k] = row.open_string;
      }
    }
  }
  return v;
}

// The voices of a truth with double stops: contact.csv's row (an open string's from
// notes.csv) and contact_2.csv's (an open upper note on the string above the lower's).
std::vector<FrameVoices> TruthVoices(const synth::TruthFolder& tf, int num_frames) {
  std::vector<FrameVoices> v(static_cast<size_t>(num_frames));
  auto note_string = [&](int note) {
    return note >= 0 && note < static_cast<int>(tf.notes.size())
               ? tf.notes[static_cast<size_t>(note)].string
               : 0;
  };
  for (int k = 0; k < 2; ++k) {
    for (const refine::ContactRow& row : k == 0 ? tf.contacts : tf.second_contacts) {
      if (row.frame >= num_frames) continue;
      FrameVoices& fv = v[static_cast<size_t>(row.frame)];
      if (row.state == "pressed") {
        fv.string[k] = row.string;
        fv.finger[k] = row.finger;
      } else if (row.state == "open_string") {
        fv.string[k] = std::max(0, note_string(row.note) - k);
      }
    }
  }
  return v;
}

StatusOr<ContactTrack> ReadContactCsv(const std::string& path, int num_frames) {
  ARCO_ASSIGN_OR_RETURN(const std::vector<refine::ContactRow> rows, refine::ReadContactsCsv(path));
  return ContactTrackFromRows(rows, num_frames);
}

Status EvalRequest::Validate() const {
  for (double mm : metrics.pck_thresholds_mm) {
    ARCO_RETURN_IF_ERROR(CheckInRange("pck_thresholds_mm", mm, kPckThresholdRangeMm));
  }
  ARCO_RETURN_IF_ERROR(CheckInRange(
      "joint_limit_tolerance_deg", joint_limit_tolerance_deg, kJointLimitToleranceRangeDeg));
  for (int64_t frame : truth_frames) {
    ARCO_RETURN_IF_ERROR(
        CheckInRange("truth_frames", static_cast<double>(frame), kTruthFrameRange));
  }
  return Status::Ok();
}

StatusOr<EvalReport> Evaluate(const EvalRequest& r) {
  ARCO_RETURN_IF_ERROR(r.Validate());
  EvalReport report;
  const pipeline::ResultFolder result(r.result_dir);
  ARCO_ASSIGN_OR_RETURN(const std::vector<pipeline::PointStage> point_stages, result.PointStages());
  ARCO_ASSIGN_OR_RETURN(const pipeline::ResultHeader header, result.ReadHeader());
  const std::vector<std::string>& result_names = header.keypoint_names;
  report.units = header.units;
  report.fps = header.fps;
  if (report.units != "mm")
    report.warnings.push_back("result units are '" + report.units + "', not mm");

  // Truth.
  PointSequence truth;
  ContactTrack truth_contact;
  std::vector<std::string> truth_names;
  std::vector<double> truth_f0;
  std::vector<bool> truth_scored;
  std::vector<refine::BowingFrame> truth_bowing;  // empty: no bow-arm truth
  std::vector<FrameVoices> truth_voices;          // empty: no double stops in the truth
  EvalOptions options = r.metrics;
  const bool folder = r.labels.empty();
  if (folder && !std::filesystem::is_directory(r.truth)) {
    return Status::Error(
        r.truth + ": not a truth folder (give labelled frames as labels JSON with truth_frames)");
  }
  if (folder) {
    report.truth_kind = "synthetic";
    ARCO_ASSIGN_OR_RETURN(const synth::TruthFolder tf, synth::ReadTruthFolder(r.truth));
    const std::string& layout_name = tf.manifest.truth_layout;
    const KeypointLayout* layout = FindKeypointLayout(layout_name);
    if (!layout)
      return Status::Error(synth::TruthManifestPath(r.truth) + ": unknown truth layout '" +
                           layout_name + "'");
    truth_names = layout->names;
    ARCO_ASSIGN_OR_RETURN(
        truth,
        ToSequence(tf.points3d, truth_names, truth_names, synth::TruthPoints3dPath(r.truth)));
    truth_contact = ContactTrackFromRows(tf.contacts, truth.num_frames);
    if (tf.HasDoubleStops()) truth_voices = TruthVoices(tf, truth.num_frames);
    const KeypointLayout* capture_layout = FindKeypointLayout(tf.manifest.layout);
    options.num_instrument_points = capture_layout ? capture_layout->size() - kNumWholeBody : 0;
    options.instrument_first = kNumWholeBody;
    for (size_t i = 0; i < truth_names.size(); ++i) {
      if (truth_names[i] == "string4_top") options.string_points_first = static_cast<int>(i);
    }
    truth_bowing = tf.bowing;
    for (const audio::PitchFrame& f : tf.pitch) {
      truth_f0.push_back(f.voiced ? f.f0_hz : 0.0);
      truth_scored.push_back(f.confidence > 0);  // confidence 0: not scored
    }
  } else {
    // Labelled views triangulated by `arco triangulate --view`: one JSON per frame.
    report.truth_kind = "labels";
    if (r.truth_frames.size() != r.labels.size()) {
      return Status::Error("give one truth_frames entry per labels JSON (" +
                           std::to_string(r.labels.size()) + " files, " +
                           std::to_string(r.truth_frames.size()) + " frames)");
    }
    if (result_names.empty()) {
      return Status::Error(result.ManifestPath() + ": no keypoint_names");
    }
    const int64_t first = header.frame_first;
    const int64_t count = header.frame_count;
    truth_names = result_names;
    truth = PointSequence(static_cast<int>(count), static_cast<int>(truth_names.size()));
    std::map<std::string, int> index;
    for (size_t i = 0; i < truth_names.size(); ++i) index[truth_names[i]] = static_cast<int>(i);
    for (size_t k = 0; k < r.labels.size(); ++k) {
      const std::string& path = r.labels[k];
      ARCO_ASSIGN_OR_RETURN(const Json lj, ReadJsonFile(path));
      if (!lj.contains("points") || !lj["points"].is_array())
        return Status::Error(path + ": no \"points\" array");
      const int64_t row = r.truth_frames[k] - first;
      if (row < 0 || row >= count) {
        return Status::Error(path + ": truth_frames entry " + std::to_string(r.truth_frames[k]) +
                             " is outside the result's frames " + std::to_string(first) + ".." +
                             std::to_string(first + count - 1));
      }
      int matched = 0;
      for (const Json& p : lj["points"]) {
        if (!p.is_object() || !p.contains("name") || !p["name"].is_string() || !p.contains("xyz") ||
            !p["xyz"].is_array() || p["xyz"].size() != 3) {
          continue;
        }
        auto it = index.find(CanonicalKeypointName(p["name"].get<std::string>()));
        if (it == index.end()) continue;
        const Eigen::Vector3d xyz(JsonNumberOrNaN(p["xyz"][0]),
                                  JsonNumberOrNaN(p["xyz"][1]),
                                  JsonNumberOrNaN(p["xyz"][2]));
        truth.set(static_cast<int>(row), it->second, xyz);
        ++matched;
      }
      if (matched == 0)
        return Status::Error(path + ": no labelled point matches the result's keypoints");
      if (lj.value("units", std::string()) != report.units) {
        report.warnings.push_back(path + ": truth units '" + lj.value("units", std::string()) +
                                  "' differ from the result's");
      }
    }
    truth_contact.string.assign(static_cast<size_t>(count), 0);
    truth_contact.finger.assign(static_cast<size_t>(count), 0);
    truth_contact.point_mm.assign(static_cast<size_t>(count), Eigen::Vector3d::Constant(NAN));
    options.instrument_first = kNumWholeBody;
    options.num_instrument_points =
        std::max(0, static_cast<int>(truth_names.size()) - kNumWholeBody);
  }
  if (!options.limits) options.limits = DefaultLeftHandLimits();
  options.joint_limit_tolerance_deg = r.joint_limit_tolerance_deg;
  // The truth's own hand against arco's limits: a real hand (a recorded take) should violate
  // none; a count here says the limits are too narrow for real players.
  if (kLeftHandFirst + kNumHand <= truth.num_points) {
    report.truth_joint_limit_violations = CountJointLimitViolations(
        truth, kLeftHandFirst, true, *options.limits, options.joint_limit_tolerance_deg);
  }
  report.contact_frames = 0;
  for (int f = 0; f < truth_contact.num_frames(); ++f)
    report.contact_frames += truth_contact.pressed(f);

  // Methods: the stages with 3D points, in the ablation table's order, then by name.
  std::vector<const pipeline::PointStage*> stages;
  for (const std::string& m : kMethodOrder) {
    for (const pipeline::PointStage& p : point_stages) {
      if (p.name == m) stages.push_back(&p);
    }
  }
  for (const pipeline::PointStage& p : point_stages) {
    if (std::find(kMethodOrder.begin(), kMethodOrder.end(), p.name) == kMethodOrder.end())
      stages.push_back(&p);
  }
  for (const pipeline::PointStage* stage : stages) {
    const std::string& path = stage->points3d_path;
    ARCO_ASSIGN_OR_RETURN(const NpyArray<double> rp, ReadNpy<double>(path));
    std::vector<std::string> names = result_names;
    if (!stage->keypoint_names.empty()) names = stage->keypoint_names;
    if (names.empty() && rp.shape.size() == 3 &&
        rp.shape[1] <= static_cast<int64_t>(truth_names.size())) {
      names.assign(truth_names.begin(), truth_names.begin() + rp.shape[1]);  // same layout prefix
    }
    ARCO_ASSIGN_OR_RETURN(const PointSequence rs, ToSequence(rp, names, truth_names, path));
    if (rs.num_frames != truth.num_frames) {
      return Status::Error(path + ": " + std::to_string(rs.num_frames) +
                           " frames but the truth has " + std::to_string(truth.num_frames));
    }
    std::optional<ContactTrack> contact;
    std::vector<refine::ContactRow> contact_rows, second_rows;
    if (!stage->contacts_path.empty()) {
      ARCO_ASSIGN_OR_RETURN(contact_rows, refine::ReadContactsCsv(stage->contacts_path));
      contact = ContactTrackFromRows(contact_rows, truth.num_frames);
    }
    report.methods.push_back(EvaluateMethod(
        stage->name, truth, truth_contact, rs, contact ? &*contact : nullptr, options));
    // Both notes of double stops, when the truth has some (and the method a second voice).
    if (!truth_voices.empty()) {
      std::optional<std::vector<FrameVoices>> voices;
      if (!stage->second_contacts_path.empty()) {
        ARCO_ASSIGN_OR_RETURN(second_rows, refine::ReadContactsCsv(stage->second_contacts_path));
        voices = MethodVoices(contact_rows, second_rows, truth.num_frames);
      }
      ScoreDoubleStops(truth_voices, voices ? &*voices : nullptr, &report.methods.back());
    }
    if (!stage->bowing_path.empty() && !truth_bowing.empty()) {
      ARCO_ASSIGN_OR_RETURN(const std::vector<refine::BowingFrame> bowing,
                            refine::ReadBowingCsv(stage->bowing_path));
      if (bowing.size() != truth_bowing.size()) {
        return Status::Error(stage->bowing_path + ": " + std::to_string(bowing.size()) +
                             " frames but the truth has " + std::to_string(truth_bowing.size()));
      }
      ScoreBowing(truth_bowing, bowing, &report.methods.back());
    }
  }
  if (report.methods.empty())
    return Status::Error(r.result_dir + ": no stage with 3D points to evaluate");
  report.truth_frames = report.methods.front().frames;

  // Pitch.
  std::string pitch_path = r.pitch_csv;
  if (pitch_path.empty() && FileExists(result.PitchPath())) pitch_path = result.PitchPath();
  if (!pitch_path.empty() && !truth_f0.empty()) {
    ARCO_ASSIGN_OR_RETURN(const std::vector<audio::PitchFrame> est,
                          audio::ReadPitchCsv(pitch_path));
    std::vector<double> e(truth_f0.size(), 0.0);
    for (const auto& f : est) {
      if (f.frame >= 0 && f.frame < static_cast<int64_t>(e.size()) && f.voiced)
        e[static_cast<size_t>(f.frame)] = f.f0_hz;
    }
    report.pitch = EvaluatePitch(truth_f0, e, &truth_scored);
    report.truth_f0_hz = truth_f0;
    report.estimate_f0_hz = e;
  }
  return report;
}

Json ToJson(const EvalRequest& r) {
  return {{"pck_thresholds_mm", r.metrics.pck_thresholds_mm},
          {"joint_limit_tolerance_deg", r.joint_limit_tolerance_deg},
          {"truth_frames", r.truth_frames}};
}

Json EvalReport::ToJson(const EvalOptions& options) const {
  Json j;
  j["format"] = "arco-eval";
  j["version"] = 1;
  j["truth"] = {
      {"kind", truth_kind},
      {"frames", truth_frames},
      {"contact_frames", contact_frames},
      {"joint_limit_violations",
       truth_joint_limit_violations < 0 ? Json(nullptr) : Json(truth_joint_limit_violations)},
      {"units", units}};
  j["protocol"] = {
      {"hand", "left hand, 20 joints after aligning the wrists by translation (Jin et al. 2024)"},
      {"contact_frames",
       "frames whose truth presses a note (rests, open strings, unvoiced excluded)"},
      {"contact_deviation",
       "playing fingertip (truth's finger) to the truth contact point, world frame"},
      {"left_hand_world",
       "left hand joints to the truth in the world, no alignment; by group: wrist, base (thumb "
       "CMC, MCPs), middle (thumb MCP, PIPs), distal (thumb IP, DIPs), tip; playing_tip: the "
       "truth's playing fingertip on contact frames"}};
  j["methods"] = Json::object();
  for (const MethodMetrics& m : methods) {
    Json mj;
    mj["frames"] = m.frames;
    mj["mpjpe_hand_mm"] = JsonFromDouble(m.mpjpe_hand_mm);
    mj["mpjpe_note_finger_mm"] = JsonFromDouble(m.mpjpe_note_finger_mm);
    mj["contact_deviation_mm"] = JsonFromDouble(m.contact_deviation_mm);
    mj["contact_deviation_median_mm"] = JsonFromDouble(m.contact_deviation_median_mm);
    for (size_t i = 0; i < m.pck.size() && i < options.pck_thresholds_mm.size(); ++i) {
      char key[32];
      std::snprintf(key, sizeof(key), "pck_%gmm", options.pck_thresholds_mm[i]);
      mj[key] = JsonFromDouble(m.pck[i]);
    }
    mj["string_accuracy"] = JsonFromDouble(m.string_accuracy);
    mj["finger_accuracy"] = JsonFromDouble(m.finger_accuracy);
    mj["joint_limit_violations"] =
        m.joint_limit_violations < 0 ? Json(nullptr) : Json(m.joint_limit_violations);
    mj["mpjpe_body_mm"] = JsonFromDouble(m.mpjpe_body_mm);
    mj["instrument_error_mm"] = JsonFromDouble(m.instrument_error_mm);
    mj["string_error_mm"] = JsonFromDouble(m.string_error_mm);
    mj["missing_hand_fraction"] = m.missing_hand_fraction;
    mj["left_hand_world_mm"] = JsonFromDouble(m.left_hand_world_mm);
    static const char* kGroups[5] = {"wrist", "base", "middle", "distal", "tip"};
    for (int g = 0; g < 5; ++g)
      mj["left_group_world_mm"][kGroups[g]] = JsonFromDouble(m.left_group_world_mm[g]);
    mj["playing_tip_world_mm"] = JsonFromDouble(m.playing_tip_world_mm);
    mj["contact_point_error_mm"] = JsonFromDouble(m.contact_point_error_mm);
    mj["bow_direction_accuracy"] = JsonFromDouble(m.bow_direction_accuracy);
    mj["bow_string_accuracy"] = JsonFromDouble(m.bow_string_accuracy);
    mj["sounding_point_error_mm"] = JsonFromDouble(m.sounding_point_error_mm);
    if (m.double_stop_truth) {  // only for a truth with double stops: other reports as before
      mj["double_stop_frames"] = m.double_stop_frames;
      mj["double_stop_string_accuracy"] = JsonFromDouble(m.double_stop_string_accuracy);
      mj["double_stop_finger_accuracy"] = JsonFromDouble(m.double_stop_finger_accuracy);
      mj["false_double_stop_frames"] =
          m.false_double_stop_frames >= 0 ? Json(m.false_double_stop_frames) : Json(nullptr);
    }
    j["methods"][m.method] = mj;
  }
  if (pitch) {
    j["pitch"] = {{"frames", pitch->frames},
                  {"truth_voiced_frames", pitch->truth_voiced_frames},
                  {"rpa50", JsonFromDouble(pitch->rpa50)},
                  {"rpa25", JsonFromDouble(pitch->rpa25)},
                  {"voicing_recall", JsonFromDouble(pitch->voicing_recall)},
                  {"voicing_false_alarm", JsonFromDouble(pitch->voicing_false_alarm)},
                  {"median_abs_cents", JsonFromDouble(pitch->median_abs_cents)}};
  } else {
    j["pitch"] = nullptr;
  }
  j["warnings"] = warnings;
  return j;
}

std::string EvalReport::MarkdownTable(const EvalOptions& options) const {
  std::ostringstream out;
  out << "| method | hand MPJPE (mm) | note finger MPJPE (mm) | contact dev. (mm) |";
  for (double t : options.pck_thresholds_mm) out << " PCK@" << t << " |";
  out << " string acc. | finger acc. | limit violations | body MPJPE (mm) | instrument err. (mm) "
         "|\n|---|---|---|---|";
  for (size_t i = 0; i < options.pck_thresholds_mm.size(); ++i) out << "---|";
  out << "---|---|---|---|---|\n";
  for (const MethodMetrics& m : methods) {
    out << "| " << m.method << " | " << Fmt(m.mpjpe_hand_mm) << " | " << Fmt(m.mpjpe_note_finger_mm)
        << " | " << Fmt(m.contact_deviation_mm) << " |";
    for (double p : m.pck) out << " " << Fmt(p, 3) << " |";
    out << " " << Fmt(m.string_accuracy, 3) << " | " << Fmt(m.finger_accuracy, 3) << " | "
        << (m.joint_limit_violations < 0 ? std::string("-")
                                         : std::to_string(m.joint_limit_violations))
        << " | " << Fmt(m.mpjpe_body_mm) << " | " << Fmt(m.instrument_error_mm) << " |\n";
  }
  if (pitch) {
    out << "\npitch: RPA50 " << Fmt(pitch->rpa50, 3) << ", RPA25 " << Fmt(pitch->rpa25, 3)
        << ", voicing recall " << Fmt(pitch->voicing_recall, 3) << ", false alarm "
        << Fmt(pitch->voicing_false_alarm, 3) << ", median error " << Fmt(pitch->median_abs_cents)
        << " cents\n";
  }
  return out.str();
}

}  // namespace arco::eval
