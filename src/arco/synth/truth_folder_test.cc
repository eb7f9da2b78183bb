// The truth folder's writer and reader: a written folder reads back equal, and a malformed
// file is one error naming it.
#include "arco/synth/truth_folder.h"

#include <gtest/gtest.h>

#include <cmath>

#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"

namespace arco::synth {
namespace {

// Two frames. The CSVs print fixed decimals, so every number is exact at that precision.
TruthFolder SmallTruth() {
  TruthFolder t;
  TruthManifest& m = t.manifest;
  m.instrument = "violin";
  m.piece = "scale";
  m.seed = 7;
  m.fps = 4;
  m.frames = 2;
  m.notes = 1;
  m.pressed_frames = 1;
  m.max_residual_shift_mm = 0.5;
  m.layout = "spd_violin";
  m.truth_layout = "spd_violin_contact";
  m.calibration_source = "rig.xml";
  m.mm_per_unit = 1000;
  m.median_camera_distance_mm = 2500.25;
  m.performer_origin_in_world_mm = Eigen::Vector3d(1, -2, 3.5);
  m.hand_model = "default";
  m.noise_px = 2;
  m.outlier_rate = 0.01;
  m.occlusion_rate = 0.05;
  m.finger_bias_mm = 12;
  m.fingering_shifts = 3;
  m.fingering_open_strings = 1;
  m.fingering_string_crossings = 2;
  m.fingering_total_cost = 4.75;
  m.sample_median_offset_cents = {{60, -3.5}, {67, 1.25}};
  t.points3d.shape = {2, 3, 3};
  for (int i = 0; i < 18; ++i) t.points3d.data.push_back(0.1 * i - 0.7);
  hand::HandPose pose;
  pose.SetWristAngleAxis(Eigen::Vector3d(0.2, -0.1, 0.3));
  pose.world_from_wrist.translation = Eigen::Vector3d(10, 20, 30);
  for (int d = 0; d < hand::kNumJointDofs; ++d) pose.angles_rad[static_cast<size_t>(d)] = 0.05 * d;
  t.left_hand = {pose, std::nullopt};
  t.right_hand = {pose, pose};
  Eigen::Matrix4d w = Eigen::Matrix4d::Identity();
  w(0, 3) = 100.5;
  t.world_from_instrument = {Eigen::Matrix4d::Identity(), w};
  refine::ContactRow rest;
  rest.frame = 0;
  rest.state = "rest";
  refine::ContactRow pressed;
  pressed.frame = 1;
  pressed.state = "pressed";
  pressed.string = 2;
  pressed.finger = 3;
  pressed.note = 0;
  pressed.f0_hz = 440.125;
  pressed.point_mm = Eigen::Vector3d(1.5, -2.25, 3.0625);
  t.contacts = {rest, pressed};
  t.pitch = {{0, 0.0, 0.0, 0.0, false}, {1, 0.25, 440.125, 1.0, true}};
  TruthNote n;
  n.onset_s = 0.25;
  n.offset_s = 0.5;
  n.midi_note = 69;
  n.velocity = 90;
  n.string = 2;
  n.finger = 3;
  n.position_semitones = 2;
  n.intonation_cents = -1.5;
  n.vibrato_rate_hz = 5.5;
  n.vibrato_extent_cents = 12.25;
  t.notes = {n};
  return t;
}

TEST(TruthFolder, WrittenFolderReadsBackEqual) {
  arco::testing::TempDir dir;
  const TruthFolder out = SmallTruth();
  ASSERT_TRUE(WriteTruthFolder(dir / "truth", out).ok());
  const auto in = ReadTruthFolder(dir / "truth");
  ASSERT_TRUE(in.ok()) << in.status().message();
  const TruthManifest& a = out.manifest;
  const TruthManifest& b = in->manifest;
  EXPECT_EQ(b.instrument, a.instrument);
  EXPECT_EQ(b.piece, a.piece);
  EXPECT_EQ(b.seed, a.seed);
  EXPECT_EQ(b.fps, a.fps);
  EXPECT_EQ(b.frames, a.frames);
  EXPECT_EQ(b.notes, a.notes);
  EXPECT_EQ(b.pressed_frames, a.pressed_frames);
  EXPECT_EQ(b.max_residual_shift_mm, a.max_residual_shift_mm);
  EXPECT_EQ(b.layout, a.layout);
  EXPECT_EQ(b.truth_layout, a.truth_layout);
  EXPECT_EQ(b.units, a.units);
  EXPECT_EQ(b.calibration_source, a.calibration_source);
  EXPECT_EQ(b.mm_per_unit, a.mm_per_unit);
  EXPECT_EQ(b.median_camera_distance_mm, a.median_camera_distance_mm);
  EXPECT_EQ(b.performer_origin_in_world_mm, a.performer_origin_in_world_mm);
  EXPECT_EQ(b.hand_model, a.hand_model);
  EXPECT_EQ(b.noise_px, a.noise_px);
  EXPECT_EQ(b.outlier_rate, a.outlier_rate);
  EXPECT_EQ(b.occlusion_rate, a.occlusion_rate);
  EXPECT_EQ(b.finger_bias_mm, a.finger_bias_mm);
  EXPECT_EQ(b.fingering_shifts, a.fingering_shifts);
  EXPECT_EQ(b.fingering_open_strings, a.fingering_open_strings);
  EXPECT_EQ(b.fingering_string_crossings, a.fingering_string_crossings);
  EXPECT_EQ(b.fingering_total_cost, a.fingering_total_cost);
  EXPECT_EQ(b.sample_median_offset_cents, a.sample_median_offset_cents);

  EXPECT_EQ(in->points3d.shape, out.points3d.shape);
  EXPECT_EQ(in->points3d.data, out.points3d.data);
  // Hands: the rotation goes through an angle-axis, so it is equal to rounding.
  for (const auto& [got, want] :
       {std::pair{&in->left_hand, &out.left_hand}, std::pair{&in->right_hand, &out.right_hand}}) {
    ASSERT_EQ(got->size(), want->size());
    for (size_t f = 0; f < want->size(); ++f) {
      ASSERT_EQ((*got)[f].has_value(), (*want)[f].has_value()) << f;
      if (!(*want)[f]) continue;
      EXPECT_TRUE((*got)[f]->world_from_wrist.rotation.isApprox(
          (*want)[f]->world_from_wrist.rotation, 1e-14));
      EXPECT_EQ((*got)[f]->world_from_wrist.translation, (*want)[f]->world_from_wrist.translation);
      EXPECT_EQ((*got)[f]->angles_rad, (*want)[f]->angles_rad);
    }
  }
  EXPECT_EQ(in->world_from_instrument, out.world_from_instrument);
  ASSERT_EQ(in->contacts.size(), out.contacts.size());
  for (size_t f = 0; f < out.contacts.size(); ++f) {
    const refine::ContactRow& g = in->contacts[f];
    const refine::ContactRow& w = out.contacts[f];
    EXPECT_EQ(g.frame, w.frame);
    EXPECT_EQ(g.state, w.state);
    EXPECT_EQ(g.string, w.string);
    EXPECT_EQ(g.finger, w.finger);
    EXPECT_EQ(g.note, w.note);
    EXPECT_EQ(g.f0_hz, w.f0_hz);
    for (int k = 0; k < 3; ++k) {
      if (std::isnan(w.point_mm[k]))
        EXPECT_TRUE(std::isnan(g.point_mm[k]));
      else
        EXPECT_EQ(g.point_mm[k], w.point_mm[k]);
    }
  }
  ASSERT_EQ(in->pitch.size(), out.pitch.size());
  for (size_t f = 0; f < out.pitch.size(); ++f) {
    EXPECT_EQ(in->pitch[f].frame, out.pitch[f].frame);
    EXPECT_EQ(in->pitch[f].time_s, out.pitch[f].time_s);
    EXPECT_EQ(in->pitch[f].f0_hz, out.pitch[f].f0_hz);
    EXPECT_EQ(in->pitch[f].confidence, out.pitch[f].confidence);
    EXPECT_EQ(in->pitch[f].voiced, out.pitch[f].voiced);
  }
  ASSERT_EQ(in->notes.size(), 1u);
  const TruthNote& g = in->notes[0];
  const TruthNote& w = out.notes[0];
  EXPECT_EQ(g.onset_s, w.onset_s);
  EXPECT_EQ(g.offset_s, w.offset_s);
  EXPECT_EQ(g.midi_note, w.midi_note);
  EXPECT_EQ(g.velocity, w.velocity);
  EXPECT_EQ(g.string, w.string);
  EXPECT_EQ(g.finger, w.finger);
  EXPECT_EQ(g.position_semitones, w.position_semitones);
  EXPECT_EQ(g.intonation_cents, w.intonation_cents);
  EXPECT_EQ(g.vibrato_rate_hz, w.vibrato_rate_hz);
  EXPECT_EQ(g.vibrato_extent_cents, w.vibrato_extent_cents);

  // Writing what was read gives the same files.
  ASSERT_TRUE(WriteTruthFolder(dir / "again", *in).ok());
  for (const char* file : {"truth.json",
                           "contact.csv",
                           "notes.csv",
                           "pitch.csv",
                           "points3d.npy",
                           "instrument_pose.npy"}) {
    EXPECT_EQ(*ReadFileToString(dir / (std::string("truth/") + file)),
              *ReadFileToString(dir / (std::string("again/") + file)))
        << file;
  }
}

// A truth with double stops: contact_2.csv, notes_2.csv and pitch.csv's f0_2_hz read back;
// a single-note truth has none of them (its files are as before double stops existed).
TEST(TruthFolder, DoubleStopFilesReadBackAndOnlyExistWithDoubleStops) {
  arco::testing::TempDir dir;
  ASSERT_TRUE(WriteTruthFolder(dir / "single", SmallTruth()).ok());
  EXPECT_FALSE(FileExists(dir / "single/contact_2.csv"));
  EXPECT_FALSE(FileExists(dir / "single/notes_2.csv"));
  EXPECT_EQ(ReadFileToString(dir / "single/pitch.csv")->find("f0_2_hz"), std::string::npos);
  EXPECT_EQ(ReadFileToString(dir / "single/truth.json")->find("double_stops"), std::string::npos);
  const auto single = ReadTruthFolder(dir / "single");
  ASSERT_TRUE(single.ok());
  EXPECT_FALSE(single->HasDoubleStops());
  EXPECT_TRUE(single->second_f0_hz.empty());

  TruthFolder t = SmallTruth();
  t.manifest.double_stops = 1;
  refine::ContactRow rest;
  rest.frame = 0;
  rest.state = "rest";
  refine::ContactRow upper = t.contacts[1];
  upper.string = 1;
  upper.finger = 1;
  upper.f0_hz = 659.25;
  upper.point_mm = Eigen::Vector3d(2.5, -4.25, 3.0);
  t.second_contacts = {rest, upper};
  TruthNote n = t.notes[0];
  n.midi_note = 76;
  n.string = 1;
  n.finger = 1;
  t.second_notes = {n};
  t.second_f0_hz = {0.0, 659.25};
  ASSERT_TRUE(WriteTruthFolder(dir / "double", t).ok());
  const auto in = ReadTruthFolder(dir / "double");
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_EQ(in->manifest.double_stops, 1);
  ASSERT_TRUE(in->HasDoubleStops());
  EXPECT_EQ(in->second_contacts[0].state, "rest");
  EXPECT_EQ(in->second_contacts[1].state, "pressed");
  EXPECT_EQ(in->second_contacts[1].string, 1);
  EXPECT_EQ(in->second_contacts[1].finger, 1);
  EXPECT_EQ(in->second_contacts[1].note, 0);
  EXPECT_EQ(in->second_contacts[1].point_mm, upper.point_mm);
  ASSERT_EQ(in->second_notes.size(), 1u);
  EXPECT_EQ(in->second_notes[0].midi_note, 76);
  EXPECT_EQ(in->second_f0_hz, t.second_f0_hz);
  // The first voice is what it was.
  EXPECT_EQ(*ReadFileToString(dir / "double/contact.csv"),
            *ReadFileToString(dir / "single/contact.csv"));

  // contact_2.csv of another length than contact.csv: one error naming it.
  ASSERT_TRUE(AtomicWriteFile(dir / "double/contact_2.csv",
                              "frame,time_s,state,string,finger,note,f0_hz,contact_x_mm,"
                              "contact_y_mm,contact_z_mm\n0,0.0,rest,0,0,-1,0,nan,nan,nan\n")
                  .ok());
  const auto bad = ReadTruthFolder(dir / "double");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("contact_2.csv"), std::string::npos)
      << bad.status().message();
}

// One malformed file at a time: each read fails with one error naming that file.
TEST(TruthFolder, MalformedFilesAreOneErrorNamingTheFile) {
  struct Case {
    const char* file;
    std::string contents;
  };
  const std::vector<Case> cases = {
      {"truth.json", "{\"format\": \"other\"}"},
      {"truth.json", "{\"format\": \"arco-synth-truth\", \"version\": 1, \"fps\": 4}"},
      {"truth.json", "{\"format\": \"arco-synth-truth\", \"version\": 1, \"fps\": \"x\"}"},
      {"contact.csv", "frame,time_s,state\n0,0,rest\n"},
      {"contact.csv",
       "frame,time_s,state,string,finger,note,f0_hz,contact_x_mm,contact_y_mm,contact_z_mm\n"
       "0,0.0,flying,0,0,-1,0,nan,nan,nan\n"},
      {"notes.csv", "note,onset_s\n"},
      {"pitch.csv", "frame,time_s,f0_hz,confidence,voiced\n0,zero,0,0,0\n"},
      {"points3d.npy", "not an npy file"},
  };
  for (const Case& c : cases) {
    arco::testing::TempDir dir;
    ASSERT_TRUE(WriteTruthFolder(dir / "truth", SmallTruth()).ok());
    ASSERT_TRUE(AtomicWriteFile(dir / (std::string("truth/") + c.file), c.contents).ok());
    const auto in = ReadTruthFolder(dir / "truth");
    ASSERT_FALSE(in.ok()) << c.file << ": " << c.contents;
    EXPECT_NE(in.status().message().find(c.file), std::string::npos) << in.status().message();
  }
  // Arrays whose frames disagree with truth.json.
  arco::testing::TempDir dir;
  TruthFolder t = SmallTruth();
  t.world_from_instrument.pop_back();
  ASSERT_TRUE(WriteTruthFolder(dir / "truth", t).ok());
  const auto in = ReadTruthFolder(dir / "truth");
  ASSERT_FALSE(in.ok());
  EXPECT_NE(in.status().message().find("instrument_pose.npy"), std::string::npos)
      << in.status().message();
  EXPECT_FALSE(ReadTruthFolder(dir / "missing").ok());
}

}  // namespace
}  // namespace arco::synth
