#include "arco/synth/synth.h"

#include <algorithm>
#include <cmath>

#include "arco/hand/kinematics.h"
#include "arco/registry/instruments.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/synth/midi_reader.h"
#include "arco/synth/score.h"
#include "arco/synth/synth_instrument.h"

namespace arco::synth {
namespace {

constexpr int kContactExtras = 13;

RigidMatrix3d RotationAbout(const Eigen::Matrix3d& r, const Eigen::Vector3d& pivot) {
  return {r, pivot - r * pivot};
}

}  // namespace

Status SynthOptions::Validate() const {
  // The instrument is the user's option: checked here, before any file is read (the
  // calibration is not to blame for it).
  if (!ParseInstrumentKind(instrument).ok())
    return Status::Error("instrument '" + instrument +
                         "' is unknown (violin, viola, cello, double_bass)");
  // So is a built-in piece's name (a MIDI file is read, and named, later).
  if (midi_path.empty()) ARCO_RETURN_IF_ERROR(CheckBuiltInPieceName(piece));
  if (!(fps >= 1 && fps <= 1000)) return Status::Error("fps must be in [1, 1000]");
  if (!(tempo_scale > 0.05 && tempo_scale < 20))
    return Status::Error("tempo scale must be in (0.05, 20)");
  if (!(max_duration_s >= 0) || !std::isfinite(max_duration_s)) {
    return Status::Error("max_duration_s must be >= 0 s (0 = whole piece)");
  }
  ARCO_RETURN_IF_ERROR(CheckInRange("a4_hz", a4_hz, kA4RangeHz));
  if (num_threads < 0) return Status::Error("threads must be >= 0");
  ARCO_RETURN_IF_ERROR(stage.Validate());
  ARCO_RETURN_IF_ERROR(fingering.Validate());
  ARCO_RETURN_IF_ERROR(expression.Validate());
  ARCO_RETURN_IF_ERROR(left_hand.Validate());
  ARCO_RETURN_IF_ERROR(bow.Validate());
  ARCO_RETURN_IF_ERROR(detection.Validate());
  if (!(sway.torso_deg >= 0 && sway.instrument_deg >= 0 && sway.min_hz > 0 &&
        sway.max_hz >= sway.min_hz)) {
    return Status::Error("sway: amplitudes >= 0 and 0 < min_hz <= max_hz");
  }
  return Status::Ok();
}

StatusOr<SyntheticCapture> Generate(const Rig& rig, const SynthOptions& options) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  SyntheticCapture cap;
  cap.options = options;
  // Instrument and score.
  ARCO_ASSIGN_OR_RETURN(const InstrumentKind kind, ParseInstrumentKind(options.instrument));
  InstrumentOptions io;
  io.kind = kind;
  io.tuning.a4_hz = options.a4_hz;
  ARCO_ASSIGN_OR_RETURN(const InstrumentModel model, InstrumentModel::Create(io));
  cap.instrument_kind = kind;
  const ScoreInstrument score_instrument = ScoreInstrumentFor(model);
  Score score;
  if (!options.midi_path.empty()) {
    ARCO_ASSIGN_OR_RETURN(score, ReadMidiScore(options.midi_path, score_instrument));
    if (options.tempo_scale != 1.0) {
      for (ScoreNote& n : score.notes) {
        n.onset_s *= options.tempo_scale;
        n.offset_s *= options.tempo_scale;
      }
      score.duration_s *= options.tempo_scale;
    }
  } else {
    ARCO_ASSIGN_OR_RETURN(score,
                          MakeBuiltInPiece(options.piece, score_instrument, options.tempo_scale));
  }
  cap.score = TruncateScore(score, options.max_duration_s);
  if (cap.score.notes.empty()) return Status::Error("no notes within the requested duration");
  {
    auto plan = PlanFingering(cap.score, score_instrument, options.fingering);
    if (!plan.ok()) return plan.status().WithContext(cap.score.name);
    cap.fingering = *plan;
  }
  for (const ScoreNote& n : cap.score.notes) cap.double_stops += n.IsDoubleStop() ? 1 : 0;
  ExpressionOptions expression = options.expression;
  expression.a4_hz = options.a4_hz;
  ARCO_ASSIGN_OR_RETURN(cap.performance,
                        MakePerformance(cap.score, cap.fingering, expression, options.seed));

  // Stage and rig in mm.
  ARCO_ASSIGN_OR_RETURN(cap.stage, PlaceStage(rig, options.stage));
  cap.rig_mm = ScaleRigToMm(rig, cap.stage.mm_per_unit);
  const RigidMatrix3d& world_from_performer = cap.stage.world_from_performer;

  // Layout: the SPD layout of the instrument, plus the 13 contact-stage extras in truth.
  const bool violin_like = kind == InstrumentKind::kViolin || kind == InstrumentKind::kViola;
  cap.layout = GetInstrumentInfo(model.kind()).spd_layout;
  cap.truth_layout = cap.layout + "_contact";
  if (const KeypointLayout* layout = FindKeypointLayout(cap.layout))
    cap.keypoint_names = layout->names;
  ARCO_ASSIGN_OR_RETURN(const InstrumentTemplate tmpl, MakeInstrumentTemplate(model));
  const auto& inst_names = model.keypoint_names();
  cap.num_instrument_points = static_cast<int>(inst_names.size());
  const int num_capture_points = wholebody::kNumPoints + cap.num_instrument_points;
  const int num_truth_points = num_capture_points + kContactExtras;
  const int frog = wholebody::kNumPoints + model.KeypointIndex("frog");
  const int tip = wholebody::kNumPoints + model.KeypointIndex("tip");

  // Animators.
  const RigidMatrix3d rest = InstrumentRestPose(kind, tmpl.scale);
  const Eigen::Vector3d pivot = InstrumentPivot(kind, tmpl.scale);
  const hand::HandModel left_model = hand::HandModel::Default(hand::HandSide::kLeft);
  const hand::HandModel right_model = hand::HandModel::Default(hand::HandSide::kRight);
  LeftHandAnimator left(left_model, model, tmpl, cap.performance, options.left_hand);
  const Eigen::Vector3d right_in_instrument = rest.rotation.transpose() * Eigen::Vector3d(-1, 0, 0);
  const BowAnimator bow(
      right_model, model, tmpl, cap.performance, right_in_instrument, options.bow);
  const Sway sway(options.sway, options.seed);

  const double duration_s = std::max(cap.score.duration_s, cap.score.notes.back().offset_s);
  cap.num_frames = static_cast<int>(std::ceil(duration_s * options.fps));
  const int F = cap.num_frames;
  cap.points3d.shape = {F, num_truth_points, 3};
  cap.points3d.data.assign(static_cast<size_t>(cap.points3d.size()), NAN);
  cap.left_hand.resize(static_cast<size_t>(F));
  cap.right_hand.resize(static_cast<size_t>(F));
  cap.contact.resize(static_cast<size_t>(F));
  cap.bowing.resize(static_cast<size_t>(F));
  cap.world_from_instrument.resize(static_cast<size_t>(F));
  std::vector<DetectionFrame> det_frames(static_cast<size_t>(F));

  for (int fr = 0; fr < F; ++fr) {
    const double t = fr / options.fps;
    auto set = [&](int p, const Eigen::Vector3d& x) {
      for (int c = 0; c < 3; ++c) cap.points3d.at(fr, p, c) = x[c];
    };
    const Eigen::Matrix3d torso = sway.TorsoRotation(t);
    RigidMatrix3d performer_from_instrument =
        RotationAbout(sway.InstrumentRotation(t), pivot) * rest;
    if (violin_like)
      performer_from_instrument =
          RigidMatrix3d{torso, Eigen::Vector3d::Zero()} * performer_from_instrument;
    const RigidMatrix3d world_from_instrument = world_from_performer * performer_from_instrument;
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() = world_from_instrument.rotation;
    m.topRightCorner<3, 1>() = world_from_instrument.translation;
    cap.world_from_instrument[static_cast<size_t>(fr)] = m;

    // Left hand (instrument frame -> world).
    const LeftHandFrame lh = left.Next(t);
    cap.max_residual_shift_mm = std::max(cap.max_residual_shift_mm, lh.residual_shift_mm);
    cap.max_second_residual_mm = std::max(cap.max_second_residual_mm, lh.second_residual_mm);
    hand::HandPose lw = lh.pose;
    lw.world_from_wrist = world_from_instrument * lh.pose.world_from_wrist;
    cap.left_hand[static_cast<size_t>(fr)] = lw;
    const hand::HandPointsMm left_pts = hand::ForwardKinematics(left_model, lw);
    for (int k = 0; k < wholebody::kNumHandPoints; ++k)
      set(wholebody::kLeftHandFirst + k, left_pts[k]);

    // Bow and right hand.
    const BowFrame bf = bow.At(t);
    refine::BowingFrame& bow_truth = cap.bowing[static_cast<size_t>(fr)];
    bow_truth.time_s = t;
    bow_truth.seen = true;
    bow_truth.string = bf.string;
    bow_truth.second_string = bf.second_string;
    bow_truth.direction = static_cast<refine::BowDirection>(bf.direction);
    bow_truth.sounding_point_mm = bf.string > 0 ? bf.sounding_point_mm : NAN;
    bow_truth.bow_position = bf.bow_position;
    hand::HandPose rw = bf.right_hand;
    rw.world_from_wrist = world_from_instrument * bf.right_hand.world_from_wrist;
    cap.right_hand[static_cast<size_t>(fr)] = rw;
    const hand::HandPointsMm right_pts = hand::ForwardKinematics(right_model, rw);
    for (int k = 0; k < wholebody::kNumHandPoints; ++k)
      set(wholebody::kRightHandFirst + k, right_pts[k]);

    // Instrument keypoints.
    for (int i = 0; i < cap.num_instrument_points; ++i) {
      const Eigen::Vector3d& p = tmpl.keypoints_mm[static_cast<size_t>(i)];
      if (p.allFinite()) set(wholebody::kNumPoints + i, world_from_instrument * p);
    }
    set(frog, world_from_instrument * bf.frog_mm);
    set(tip, world_from_instrument * bf.tip_mm);

    // Body from the wrists (performer frame).
    const RigidMatrix3d performer_from_world = world_from_performer.Inverse();
    std::array<Eigen::Vector3d, wholebody::kNumPoints> body;
    BodyKeypoints(torso,
                  performer_from_world * left_pts[0],
                  performer_from_world * right_pts[0],
                  violin_like,
                  &body);
    for (int p = 0; p < wholebody::kLeftHandFirst; ++p)
      set(p, world_from_performer * body[static_cast<size_t>(p)]);
    set(wholebody::kLeftWrist, left_pts[0]);  // body wrists are the hands' wrists exactly
    set(wholebody::kRightWrist, right_pts[0]);

    // Contact-stage extras: strings lowest first (nut end, bridge end), contact,
    // playing finger MCP..tip.
    const int n_strings = model.num_strings();
    for (int k = 0; k < n_strings; ++k) {
      const StringSegment& s = tmpl.strings_mm[static_cast<size_t>(n_strings - 1 - k)];
      set(num_capture_points + 2 * k, world_from_instrument * s.nut);
      set(num_capture_points + 2 * k + 1, world_from_instrument * s.bridge);
    }
    ContactTruth& ct = cap.contact[static_cast<size_t>(fr)];
    ct.note_index = lh.note_index;
    ct.f0_hz = lh.f0_hz;
    ct.open_string = lh.note_index >= 0 && lh.finger == 0;
    if (lh.double_stop) {
      ct.double_stop = true;
      ct.second_string = lh.second_string;
      ct.second_finger = lh.second_finger;
      ct.second_f0_hz = lh.second_f0_hz;
      if (lh.second_finger > 0) ct.second_point_mm = world_from_instrument * lh.second_contact_mm;
    }
    DetectionFrame& df = det_frames[static_cast<size_t>(fr)];
    if (lh.finger > 0) {
      ++cap.pressed_frames;
      ct.string = lh.string;
      ct.finger = lh.finger;
      ct.point_mm = world_from_instrument * lh.contact_mm;
      set(num_capture_points + 8, ct.point_mm);
      for (int j = 0; j < 4; ++j) {
        set(num_capture_points + 9 + j,
            left_pts[hand::KeypointIndex(static_cast<hand::Finger>(lh.finger), j)]);
      }
      df.bias_tip =
          wholebody::kLeftHandFirst + hand::TipKeypoint(static_cast<hand::Finger>(lh.finger));
      df.bias_dip = df.bias_tip - 1;
      df.bias_direction = world_from_instrument.rotation.col(2);
    }
    // Detection scene.
    df.points.resize(static_cast<size_t>(num_capture_points));
    for (int p = 0; p < num_capture_points; ++p) {
      df.points[static_cast<size_t>(p)] = Eigen::Vector3d(
          cap.points3d.at(fr, p, 0), cap.points3d.at(fr, p, 1), cap.points3d.at(fr, p, 2));
    }
    df.body_centre =
        world_from_instrument * Eigen::Vector3d(tmpl.body_center_x_mm, 0, tmpl.body_plane_z_mm);
    df.body_axis_x = world_from_instrument.rotation.col(0);
    df.body_axis_y = world_from_instrument.rotation.col(1);
    df.body_half_x = tmpl.body_half_length_mm;
    df.body_half_y = tmpl.body_half_width_mm;
    df.torso_a = world_from_performer * (torso * Eigen::Vector3d(0, 80, -30));
    df.torso_b = world_from_performer * (torso * Eigen::Vector3d(0, 520, -20));
  }
  if (static_cast<int>(cap.keypoint_names.size()) != num_capture_points) {
    return Status::Error("internal: layout " + cap.layout +
                         " does not match the instrument's keypoints");
  }

  DetectionLayout layout;
  layout.num_points = num_capture_points;
  layout.instrument_first = wholebody::kNumPoints;
  layout.bow_points = {frog, tip};
  layout.torso_points = {5, 6, 11, 12};
  cap.keypoints2d = EmulateDetections(cap.rig_mm,
                                      det_frames,
                                      layout,
                                      options.detection,
                                      options.fps,
                                      options.seed,
                                      options.num_threads);
  return cap;
}

}  // namespace arco::synth
