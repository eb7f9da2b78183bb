// Truth self-consistency of Generate(): fingertips on the strings at the pitch's
// contact point, joint limits, determinism, bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>

#include "arco/camera/calibration_io.h"
#include "arco/hand/kinematics.h"
#include "arco/instrument/contact.h"
#include "arco/synth/synth.h"
#include "arco/util/file_io.h"

namespace arco::synth {
namespace {

Rig SpdRig() {
  auto text =
      ReadFileToString(std::string(ARCO_SHARED_DATA_DIR) + "/spd/cello_1113_scale_camera.xml");
  EXPECT_TRUE(text.ok());
  auto cal = ParseMetashapeXml(*text, "cello_1113_scale_camera.xml");
  EXPECT_TRUE(cal.ok()) << cal.status().message();
  return cal->rig;
}

const SyntheticCapture& Cached(const std::string& instrument,
                               const std::string& piece,
                               uint64_t seed) {
  static std::map<std::string, SyntheticCapture> cache;
  const std::string key = instrument + piece + std::to_string(seed);
  auto it = cache.find(key);
  if (it == cache.end()) {
    SynthOptions o;
    o.instrument = instrument;
    o.piece = piece;
    o.seed = seed;
    o.max_duration_s = 4.0;
    auto cap = Generate(SpdRig(), o);
    EXPECT_TRUE(cap.ok()) << cap.status().message();
    it = cache.emplace(key, std::move(*cap)).first;
  }
  return it->second;
}

Eigen::Vector3d Point(const SyntheticCapture& c, int frame, int p) {
  return {c.points3d.at(frame, p, 0), c.points3d.at(frame, p, 1), c.points3d.at(frame, p, 2)};
}

class GenerateTruth : public ::testing::TestWithParam<std::tuple<const char*, const char*>> {};

TEST_P(GenerateTruth, FingertipOnTheStringAtThePitchesContactPoint) {
  const auto [instrument, piece] = GetParam();
  const SyntheticCapture& c = Cached(instrument, piece, 0);
  auto model = InstrumentModel::Create(instrument);
  ASSERT_TRUE(model.ok());
  const int n_capture = static_cast<int>(c.points3d.shape[1]) - 13;
  ASSERT_EQ(static_cast<int>(c.keypoint_names.size()), n_capture);
  EXPECT_EQ(c.keypoint_names[wholebody::kNumPoints + 1], "nut_l");
  ASSERT_GT(c.pressed_frames, c.num_frames / 4);
  for (int f = 0; f < c.num_frames; ++f) {
    const ContactTruth& ct = c.contact[static_cast<size_t>(f)];
    if (ct.finger == 0) continue;
    // 1. The playing fingertip is at the contact point (< 0.1 mm).
    const Eigen::Vector3d tip = Point(
        c, f, wholebody::kLeftHandFirst + hand::TipKeypoint(static_cast<hand::Finger>(ct.finger)));
    EXPECT_LT((tip - ct.point_mm).norm(), 0.1) << "frame " << f;
    // 2. The contact point lies on the string (strings stored nut, bridge; lowest first)...
    const int k = model->num_strings() - ct.string;
    const Eigen::Vector3d nut = Point(c, f, n_capture + 2 * k),
                          bridge = Point(c, f, n_capture + 2 * k + 1);
    const Eigen::Vector3d axis = (nut - bridge).normalized();
    const Eigen::Vector3d rel = ct.point_mm - bridge;
    EXPECT_LT((rel - rel.dot(axis) * axis).norm(), 1e-6) << "frame " << f;
    // 3. ... where the inverse of the pitch-position law gives the truth f0 back.
    const double from_bridge_mm = rel.norm() / (nut - bridge).norm() * model->string_length_mm();
    const double f0 = PitchAtContact(*model, ct.string, from_bridge_mm);
    EXPECT_NEAR(1200 * std::log2(f0 / ct.f0_hz), 0.0, 0.01) << "frame " << f;
    // 4. The contact-stage extras repeat the contact and the finger's tip.
    EXPECT_LT((Point(c, f, n_capture + 8) - ct.point_mm).norm(), 1e-9);
    EXPECT_LT((Point(c, f, n_capture + 12) - tip).norm(), 1e-9);
  }
}

TEST_P(GenerateTruth, HandsWithinJointLimitsAndConsistentWithTheirModel) {
  const auto [instrument, piece] = GetParam();
  const SyntheticCapture& c = Cached(instrument, piece, 0);
  const auto left = hand::HandModel::Default(hand::HandSide::kLeft);
  const auto right = hand::HandModel::Default(hand::HandSide::kRight);
  for (int f = 0; f < c.num_frames; ++f) {
    EXPECT_EQ(hand::CountLimitViolations(left, c.left_hand[static_cast<size_t>(f)]), 0) << f;
    EXPECT_EQ(hand::CountLimitViolations(right, c.right_hand[static_cast<size_t>(f)]), 0) << f;
    const auto pts = hand::ForwardKinematics(left, c.left_hand[static_cast<size_t>(f)]);
    for (int k = 0; k < 21; ++k)
      EXPECT_LT((pts[k] - Point(c, f, wholebody::kLeftHandFirst + k)).norm(), 1e-9);
    EXPECT_LT((Point(c, f, 9) - pts[0]).norm(), 1e-9);  // body wrist = hand wrist
    // Idle fingertips hover above the string plane, never through it.
    const Eigen::Matrix4d& m = c.world_from_instrument[static_cast<size_t>(f)];
    for (int finger = 1; finger <= 4; ++finger) {
      if (finger == c.contact[static_cast<size_t>(f)].finger) continue;
      const Eigen::Vector3d tip = pts[hand::TipKeypoint(static_cast<hand::Finger>(finger))];
      const Eigen::Vector3d in_instrument =
          m.topLeftCorner<3, 3>().transpose() * (tip - m.topRightCorner<3, 1>());
      EXPECT_GT(in_instrument.z(), 0.0)
          << "frame " << f << " finger " << finger << " z " << in_instrument.z() << " playing "
          << c.contact[static_cast<size_t>(f)].finger << " note "
          << c.contact[static_cast<size_t>(f)].note_index;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Pieces,
                         GenerateTruth,
                         ::testing::Values(std::make_tuple("cello", "scale-2oct"),
                                           std::make_tuple("cello", "slow-melody"),
                                           std::make_tuple("violin", "fast-passage"),
                                           std::make_tuple("viola", "open-strings"),
                                           std::make_tuple("double_bass", "arpeggios")));

// Double stops: the upper note's truth contact lies on the next higher string where the
// pitch-position law puts its f0, both fingertips are near their contacts (the hand shares
// what the joints cannot span), and the joints stay in their limits.
TEST(Generate, DoubleStopsPutTheSecondFingerOnTheNextString) {
  const SyntheticCapture& c = Cached("violin", "double-stops", 0);
  auto model = InstrumentModel::Create("violin");
  ASSERT_TRUE(model.ok());
  const auto left = hand::HandModel::Default(hand::HandSide::kLeft);
  const int n_capture = static_cast<int>(c.points3d.shape[1]) - 13;
  EXPECT_GE(c.double_stops, 2);
  int frames = 0;
  for (int f = 0; f < c.num_frames; ++f) {
    const ContactTruth& ct = c.contact[static_cast<size_t>(f)];
    if (!ct.double_stop) continue;
    ++frames;
    const PerformedNote& note = c.performance.notes[static_cast<size_t>(ct.note_index)];
    ASSERT_TRUE(note.note.IsDoubleStop());
    EXPECT_EQ(ct.second_string, model->num_strings() - note.fingering.string_index - 1);
    EXPECT_EQ(ct.second_finger, note.fingering.second_finger);
    EXPECT_NEAR(1200 * std::log2(ct.second_f0_hz / MidiToHz(note.note.second_midi_note)),
                note.SecondCentsAt(f / c.options.fps),
                1e-6);
    EXPECT_EQ(hand::CountLimitViolations(left, c.left_hand[static_cast<size_t>(f)]), 0) << f;
    if (ct.second_finger == 0) continue;
    const int k = model->num_strings() - ct.second_string;
    const Eigen::Vector3d nut = Point(c, f, n_capture + 2 * k),
                          bridge = Point(c, f, n_capture + 2 * k + 1);
    const Eigen::Vector3d axis = (nut - bridge).normalized();
    const Eigen::Vector3d rel = ct.second_point_mm - bridge;
    EXPECT_LT((rel - rel.dot(axis) * axis).norm(), 1e-6) << "frame " << f;
    const double from_bridge_mm = rel.norm() / (nut - bridge).norm() * model->string_length_mm();
    EXPECT_NEAR(1200 * std::log2(PitchAtContact(*model, ct.second_string, from_bridge_mm) /
                                 ct.second_f0_hz),
                0.0,
                0.01);
    const Eigen::Vector3d tip2 = Point(
        c,
        f,
        wholebody::kLeftHandFirst + hand::TipKeypoint(static_cast<hand::Finger>(ct.second_finger)));
    EXPECT_LT((tip2 - ct.second_point_mm).norm(), 15.0) << "frame " << f;
    if (ct.finger > 0) {
      const Eigen::Vector3d tip1 = Point(
          c,
          f,
          wholebody::kLeftHandFirst + hand::TipKeypoint(static_cast<hand::Finger>(ct.finger)));
      EXPECT_LT((tip1 - ct.point_mm).norm(), 15.0) << "frame " << f;
    }
  }
  EXPECT_GT(frames, 30);
  EXPECT_LT(c.max_second_residual_mm, 15.0);
}

// A rolled chord: the truth names the sounding pair at every frame, and the fingers of the
// chord's other pair stay down on their strings where their notes sound (the left hand holds
// the whole chord from its start), within the joints' limits.
TEST(Generate, ChordsHoldTheOtherPairsFingersDown) {
  const SyntheticCapture& c = Cached("cello", "chords", 0);
  auto model = InstrumentModel::Create("cello");
  ASSERT_TRUE(model.ok());
  const auto left = hand::HandModel::Default(hand::HandSide::kLeft);
  const int n_capture = static_cast<int>(c.points3d.shape[1]) - 13;
  const int num_strings = model->num_strings();
  const auto& notes = c.performance.notes;
  int held_checked = 0;
  for (int f = 0; f < c.num_frames; ++f) {
    const ContactTruth& ct = c.contact[static_cast<size_t>(f)];
    if (ct.note_index < 0) continue;
    const size_t i = static_cast<size_t>(ct.note_index);
    const bool upper = notes[i].note.chord_upper_pair;
    const bool lower = i + 1 < notes.size() && notes[i + 1].note.chord_upper_pair;
    if (!upper && !lower) continue;
    ASSERT_TRUE(ct.double_stop) << "frame " << f;
    // (The truth's string is 0 on an open string: only stopped notes have a contact.)
    if (notes[i].fingering.finger > 0) {
      EXPECT_EQ(ct.string, num_strings - notes[i].fingering.string_index);
    }
    EXPECT_EQ(ct.second_string, num_strings - notes[i].fingering.second_string_index);
    EXPECT_EQ(hand::CountLimitViolations(left, c.left_hand[static_cast<size_t>(f)]), 0) << f;
    const PerformedNote& other = notes[upper ? i - 1 : i + 1];
    const std::pair<int, int> other_places[2] = {
        {other.fingering.finger, other.fingering.string_index},
        {other.fingering.second_finger, other.fingering.second_string_index}};
    const int other_midi[2] = {other.note.midi_note, other.note.second_midi_note};
    for (int k = 0; k < 2; ++k) {
      const auto [finger, string_index] = other_places[k];
      if (finger == 0 || finger == ct.finger || finger == ct.second_finger) continue;
      if (other.fingering.finger == other.fingering.second_finger) continue;  // a fifth
      const int string = num_strings - string_index;
      const Contact contact = ContactPoint(*model, string, MidiToHz(other_midi[k]));
      ASSERT_TRUE(contact.stopped());
      const int s = num_strings - string;
      const Eigen::Vector3d nut = Point(c, f, n_capture + 2 * s),
                            bridge = Point(c, f, n_capture + 2 * s + 1);
      const Eigen::Vector3d target = bridge + contact.fraction_from_bridge * (nut - bridge);
      const Eigen::Vector3d tip = Point(
          c, f, wholebody::kLeftHandFirst + hand::TipKeypoint(static_cast<hand::Finger>(finger)));
      EXPECT_LT((tip - target).norm(), 15.0) << "frame " << f << " held finger " << finger;
      ++held_checked;
    }
  }
  EXPECT_GT(held_checked, 10);
}

TEST(Generate, VibratoRocksTheHandInPhaseWithThePitch) {
  const SyntheticCapture& c = Cached("cello", "slow-melody", 0);
  // Within one long vibrato note, the contact moves towards the bridge exactly
  // when the pitch rises: correlation of f0 with -distance-from-bridge is ~1.
  int checked = 0;
  for (size_t i = 0; i < c.performance.notes.size(); ++i) {
    const PerformedNote& n = c.performance.notes[i];
    if (n.vibrato_rate_hz <= 0 || n.note.offset_s > 4.0) continue;
    std::vector<double> pitch, dist;
    for (int f = 0; f < c.num_frames; ++f) {
      const ContactTruth& ct = c.contact[static_cast<size_t>(f)];
      if (ct.note_index != static_cast<int>(i) || ct.finger == 0) continue;
      const Eigen::Matrix4d& m = c.world_from_instrument[static_cast<size_t>(f)];
      const Eigen::Vector3d in_instrument =
          m.topLeftCorner<3, 3>().transpose() * (ct.point_mm - m.topRightCorner<3, 1>());
      pitch.push_back(std::log2(ct.f0_hz));
      dist.push_back(in_instrument.x());
    }
    if (pitch.size() < 10) continue;
    double mp = 0, md = 0;
    for (size_t k = 0; k < pitch.size(); ++k)
      mp += pitch[k] / pitch.size(), md += dist[k] / dist.size();
    double spd = 0, spp = 0, sdd = 0;
    for (size_t k = 0; k < pitch.size(); ++k) {
      spd += (pitch[k] - mp) * (dist[k] - md);
      spp += (pitch[k] - mp) * (pitch[k] - mp);
      sdd += (dist[k] - md) * (dist[k] - md);
    }
    EXPECT_LT(spd / std::sqrt(spp * sdd), -0.999);
    ++checked;
  }
  EXPECT_GE(checked, 1);
}

TEST(Generate, DeterministicBySeed) {
  SynthOptions o;
  o.max_duration_s = 1.5;
  o.num_threads = 1;
  auto a = Generate(SpdRig(), o);
  o.num_threads = 2;
  auto b = Generate(SpdRig(), o);
  o.seed = 1;
  auto c = Generate(SpdRig(), o);
  ASSERT_TRUE(a.ok() && b.ok() && c.ok());
  ASSERT_EQ(a->points3d.data.size(), b->points3d.data.size());
  for (size_t i = 0; i < a->points3d.data.size(); ++i) {
    const double x = a->points3d.data[i], y = b->points3d.data[i];
    ASSERT_TRUE(x == y || (std::isnan(x) && std::isnan(y)))
        << "element " << i << ": " << x << " vs " << y;
  }
  ASSERT_EQ(a->keypoints2d.data.size(), b->keypoints2d.data.size());
  EXPECT_EQ(
      0,
      std::memcmp(
          a->keypoints2d.data.data(), b->keypoints2d.data.data(), a->keypoints2d.data.size() * 4));
  EXPECT_NE(
      0,
      std::memcmp(
          a->keypoints2d.data.data(), c->keypoints2d.data.data(), a->keypoints2d.data.size() * 4));
}

TEST(Generate, CleanDetectionsAreTheProjectionsExceptTheBiasedFinger) {
  SynthOptions o;
  o.max_duration_s = 1.5;
  o.detection.noise_px = 0;
  o.detection.outlier_rate = 0;
  o.detection.occlusion_rate = 0;
  o.detection.geometric_occlusion = false;
  o.detection.jitter_mm = 0;
  auto c = Generate(SpdRig(), o);
  ASSERT_TRUE(c.ok());
  int biased = 0;
  for (int f = 0; f < c->num_frames; ++f) {
    const ContactTruth& ct = c->contact[static_cast<size_t>(f)];
    const int tip = ct.finger > 0 ? wholebody::kLeftHandFirst +
                                        hand::TipKeypoint(static_cast<hand::Finger>(ct.finger))
                                  : -1;
    for (int v = 0; v < static_cast<int>(c->rig_mm.cameras.size()); ++v) {
      for (int p = 0; p < static_cast<int>(c->keypoints2d.shape[2]); ++p) {
        const auto px = c->rig_mm.cameras[static_cast<size_t>(v)].Project(Point(*c, f, p));
        const float x = c->keypoints2d.at(f, v, p, 0), y = c->keypoints2d.at(f, v, p, 1);
        if (std::isnan(x)) continue;  // outside this view
        const double err = (Eigen::Vector2d(x, y) - *px).norm();
        if (p == tip || p == tip - 1) {
          biased += err > 1.0;
        } else {
          EXPECT_LT(err, 1e-3) << "frame " << f << " view " << v << " point " << p;
        }
      }
    }
  }
  EXPECT_GT(biased, 0);
}

TEST(Generate, BadInput) {
  SynthOptions o;
  o.piece = "bolero";
  auto a = Generate(SpdRig(), o);
  ASSERT_FALSE(a.ok());
  EXPECT_NE(a.status().message().find("piece 'bolero' is unknown"), std::string::npos);
  o = {};
  o.instrument = "lute";
  EXPECT_FALSE(Generate(SpdRig(), o).ok());
  Rig one = SpdRig();
  one.cameras.resize(1);
  auto b = Generate(one, {});
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.status().message().find("at least 2"), std::string::npos);
  o = {};
  o.fps = 0;
  EXPECT_FALSE(Generate(SpdRig(), o).ok());
}

TEST(PlaceStage, SpdRigGetsItsMetricScale) {
  auto stage = PlaceStage(SpdRig(), {});
  ASSERT_TRUE(stage.ok());
  // 695 mm nut-bridge / 0.344 Metashape units (../shared/data/spd/README.md).
  EXPECT_NEAR(stage->mm_per_unit, 695.0 / 0.344, 0.01 * 695.0 / 0.344);
  // Up is opposite to the cameras' image rows.
  EXPECT_GT(stage->world_from_performer.rotation.col(1).dot(
                -SpdRig().cameras[0].cam_from_world.rotation.row(1).transpose()),
            0.5);
}

}  // namespace
}  // namespace arco::synth
