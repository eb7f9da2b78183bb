// Test support: a generated performance with known truth for the refinement tests. The
// instrument sways rigidly, the left hand is placed by the hand layer's IK so the playing
// fingertip lies exactly on the string at the pitch's contact point (Eq. 2), the idle
// fingers hover above their own places, vibrato rocks the hand along the string. The
// "vision" hand is the truth with the playing finger lifted off the string (its joints
// re-solved to put the tip lift_mm along the front normal) and a little seeded noise on
// every angle and the wrist, as a detector and a hand fit see an unloaded finger.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "arco/hand/ik.h"
#include "arco/hand/kinematics.h"
#include "arco/refine/arco_decode.h"
#include "arco/refine/refine.h"

namespace arco::refine::testing {

struct SceneNote {
  int string = 1;        // 0 = rest
  int finger = 1;        // 0 = open string
  double semitones = 2;  // above the open string (stopped)
  int frames = 20;
  double vibrato_cents = 0;  // half peak-to-peak, 6 Hz
};

struct SceneOptions {
  bool sway = true;
  // The vision hand's playing fingertip sits this far off the string along the front normal
  // (a detector sees an unloaded finger; the hand fit follows it with the finger's joints).
  double lift_mm = 12;
  // ... and this far across the strings (the hand fit follows a lifted tip partly with the
  // finger's abduction: a lateral error of the playing fingertip alone).
  double lift_across_mm = 0;
  double angle_noise_deg = 1;  // on every angle of the vision hand
  double wrist_noise_mm = 0.5;
  uint64_t seed = 1;
};

struct Scene {
  std::shared_ptr<const InstrumentModel> model;  // shared with input.instrument
  RefineInput input;
  std::vector<hand::HandPose> truth_hand;
  std::vector<int> truth_string, truth_finger;  // 0 = none
  std::vector<Eigen::Vector3d> truth_contact;   // NaN when none
  std::vector<SimMatrix3d> world_from_instrument;  // per frame, mm
};

inline std::vector<StringSegment> StringsInInstrument(const InstrumentModel& model) {
  std::vector<StringSegment> out;
  for (int s = 1; s <= model.num_strings(); ++s) {
    StringSegment seg;
    seg.string = s;
    seg.bridge = Eigen::Vector3d(0, model.LateralOffsetAtBridgeMm(s), 0);
    seg.nut = Eigen::Vector3d(model.string_length_mm(), model.LateralOffsetAtNutMm(s), 0);
    out.push_back(seg);
  }
  return out;
}

inline Eigen::Vector3d ContactInInstrument(const InstrumentModel& model,
                                           const std::vector<StringSegment>& strings,
                                           int string,
                                           double f0_hz) {
  const Contact c = ContactPoint(model, string, f0_hz);
  return strings[static_cast<size_t>(string - 1)].PointAtFraction(c.fraction_from_bridge);
}

// A left hand (instrument frame) with `finger` exactly on `contact` and the other fingers
// hovering over their places on `string` (fingers arrive from the high-string side).
inline hand::HandPose PlayingPose(const hand::HandModel& hand_model,
                                  const InstrumentModel& model,
                                  const std::vector<StringSegment>& strings,
                                  int string,
                                  int finger,
                                  double semitones) {
  hand::HandPose pose;
  Eigen::Matrix3d r;
  const Eigen::Vector3d x = -Eigen::Vector3d::UnitX();  // index -> little: toward the bridge
  const Eigen::Vector3d y = Eigen::Vector3d(0, 1, -0.35).normalized();  // distal
  r.col(0) = x;
  r.col(1) = y;
  r.col(2) = x.cross(y);  // palmar: toward the fingerboard
  pose.world_from_wrist.rotation = r;
  for (int k = 1; k <= 4; ++k) {
    pose.angles_rad[4 * k + 0] = 35 * M_PI / 180;  // MCP flexion
    pose.angles_rad[4 * k + 2] = 55 * M_PI / 180;  // PIP
    pose.angles_rad[4 * k + 3] = 25 * M_PI / 180;  // DIP
  }
  const double open_hz = model.open_hz(string);
  auto place = [&](double st) {
    return ContactInInstrument(model, strings, string, open_hz * std::exp2(st / 12.0));
  };
  const Eigen::Vector3d contact = place(semitones);
  const hand::Finger f = static_cast<hand::Finger>(finger);
  pose.world_from_wrist.translation = contact - hand::FingertipInWorld(hand_model, pose, f);
  hand::FingerIkOptions ik;
  ik.joints = hand::FingerIkJoints::kAll;
  hand::FingerIkResult r1 = hand::SolveFingertipIk(hand_model, pose, f, contact, ik);
  pose = r1.pose;
  pose.world_from_wrist.translation += contact - hand::FingertipInWorld(hand_model, pose, f);
  for (int j = 1; j <= 4; ++j) {
    if (j == finger) continue;
    const double st = semitones + FingerOffsetSemitones(model.kind(), j) -
                      FingerOffsetSemitones(model.kind(), finger);
    const Eigen::Vector3d hover = place(std::max(0.5, st)) + Eigen::Vector3d(0, 0, 12);
    pose = hand::SolveFingertipIk(hand_model, pose, static_cast<hand::Finger>(j), hover, ik).pose;
  }
  return pose;
}

inline hand::HandPose ToWorld(const hand::HandPose& in_instrument, const SimMatrix3d& p) {
  hand::HandPose out = in_instrument;
  out.world_from_wrist.rotation = p.rotation * in_instrument.world_from_wrist.rotation;
  out.world_from_wrist.translation = p * in_instrument.world_from_wrist.translation;
  return out;
}

inline Scene MakeScene(InstrumentKind kind,
                       const std::vector<SceneNote>& notes,
                       const SceneOptions& options = {}) {
  InstrumentOptions io;
  io.kind = kind;
  Scene scene;
  scene.model = std::make_shared<const InstrumentModel>(InstrumentModel::Create(io).value());
  const InstrumentModel& model = *scene.model;
  scene.input.instrument = scene.model;
  const hand::HandModel hand_model = hand::HandModel::Default(hand::HandSide::kLeft);
  const std::vector<StringSegment> strings = StringsInInstrument(model);
  std::mt19937 rng(static_cast<uint32_t>(options.seed));
  std::normal_distribution<double> noise(0.0, 1.0);
  const double fps = 30.0;
  hand::HandPose last_pose = PlayingPose(hand_model, model, strings, model.num_strings(), 1, 2);
  int frame = 0;
  for (const SceneNote& note : notes) {
    const bool sounding = note.string > 0;
    const bool stopped = sounding && note.finger > 0;
    const double centre_hz =
        sounding ? model.open_hz(note.string) * std::exp2((stopped ? note.semitones : 0) / 12.0)
                 : 0.0;
    hand::HandPose note_pose = last_pose;
    if (stopped) {
      note_pose = PlayingPose(hand_model, model, strings, note.string, note.finger, note.semitones);
    }
    for (int i = 0; i < note.frames; ++i, ++frame) {
      const double t = frame / fps;
      SimMatrix3d p;
      const double a = options.sway ? 0.05 * std::sin(2 * M_PI * 0.3 * t) : 0.0;
      p.rotation = (Eigen::AngleAxisd(0.3 + a, Eigen::Vector3d::UnitZ()) *
                    Eigen::AngleAxisd(-1.2, Eigen::Vector3d::UnitX()))
                       .toRotationMatrix();
      p.translation = Eigen::Vector3d(100, 200 + (options.sway ? 15 * std::sin(t) : 0), 900);
      scene.world_from_instrument.push_back(p);
      scene.input.strings_in_world_mm.push_back(StringsInWorld(strings, p));
      double f0 = centre_hz;
      if (stopped && note.vibrato_cents > 0) {
        f0 *= std::exp2(note.vibrato_cents * std::sin(2 * M_PI * 6.0 * i / fps) / 1200.0);
      }
      hand::HandPose hp = note_pose;
      Eigen::Vector3d contact = Eigen::Vector3d::Constant(kNaN);
      if (stopped) {  // vibrato rocks the whole hand along the string
        contact = ContactInInstrument(model, strings, note.string, f0);
        hp.world_from_wrist.translation +=
            contact - ContactInInstrument(model, strings, note.string, centre_hz);
      }
      const hand::HandPose truth = ToWorld(hp, p);
      scene.truth_hand.push_back(truth);
      scene.truth_string.push_back(stopped ? note.string : 0);
      scene.truth_finger.push_back(stopped ? note.finger : 0);
      scene.truth_contact.push_back(stopped ? p * contact : contact);
      hand::HandPose vision = truth;
      if (stopped && (options.lift_mm > 0 || options.lift_across_mm != 0)) {
        hand::FingerIkOptions lift;
        lift.joints = hand::FingerIkJoints::kAll;
        const hand::Finger f = static_cast<hand::Finger>(note.finger);
        const Eigen::Vector3d lifted = hand::FingertipInWorld(hand_model, truth, f) +
                                       options.lift_mm * p.rotation.col(2) +
                                       options.lift_across_mm * p.rotation.col(1);
        vision = hand::SolveFingertipIk(hand_model, truth, f, lifted, lift).pose;
      }
      for (double& angle : vision.angles_rad)
        angle += options.angle_noise_deg * M_PI / 180 * noise(rng);
      for (int c = 0; c < 3; ++c)
        vision.world_from_wrist.translation[c] += options.wrist_noise_mm * noise(rng);
      scene.input.vision_hand.push_back(hand::ClampToLimits(hand_model, vision));
      scene.input.pitch.push_back({f0, sounding ? 0.9 : 0.0});
    }
    last_pose = note_pose;
  }
  scene.input.hand_model = hand_model;
  scene.input.fps = fps;
  return scene;
}

// The audio layer's notes for a scene (audio/notes.h): one per sounding scene note, its
// onset `lag_s` after the note's first frame (the fine track's own lag), its offset at the
// note's end, frame 0 at time 0.
inline std::vector<AudioNote> AudioNotesOf(const InstrumentModel& model,
                                           const std::vector<SceneNote>& notes,
                                           double fps,
                                           double lag_s) {
  std::vector<AudioNote> out;
  int frame = 0;
  for (const SceneNote& note : notes) {
    if (note.string > 0) {
      AudioNote a;
      a.onset_s = frame / fps + lag_s;
      a.offset_s = (frame + note.frames) / fps;
      a.f0_hz =
          model.open_hz(note.string) * std::exp2((note.finger > 0 ? note.semitones : 0) / 12.0);
      out.push_back(a);
    }
    frame += note.frames;
  }
  return out;
}

}  // namespace arco::refine::testing
