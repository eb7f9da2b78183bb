#include "arco/refine/bowing.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "arco/testing/temp_dir.h"
#include "arco/util/npy.h"

namespace arco::refine {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A world frame unlike the instrument's: rotated, shifted.
struct Scene {
  InstrumentModel model;
  Eigen::Matrix3d world_from_instrument;
  Eigen::Vector3d origin{400, -250, 900};
  std::vector<StringSegment> strings;  // flat, as arco's strings are (strings.h)

  explicit Scene(InstrumentKind kind) : model(MakeModel(kind)) {
    world_from_instrument = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
    for (int s = 1; s <= model.num_strings(); ++s) {
      StringSegment seg;
      seg.string = s;
      seg.bridge = World({0, model.LateralOffsetAtBridgeMm(s), 0});
      seg.nut = World({model.string_length_mm(), model.LateralOffsetAtNutMm(s), 0});
      strings.push_back(seg);
    }
  }
  static InstrumentModel MakeModel(InstrumentKind kind) {
    InstrumentOptions o;
    o.kind = kind;
    return InstrumentModel::Create(o).value();
  }
  Eigen::Vector3d World(const Eigen::Vector3d& p) const {
    return world_from_instrument * p + origin;
  }
  Eigen::Vector3d WorldDir(const Eigen::Vector3d& d) const { return world_from_instrument * d; }
  // The top of string s on a real arched bridge at `from_bridge_mm` along the strings: a
  // circle of the model's arch radius through the strings, its crown at height 0.
  Eigen::Vector3d ArchTop(int s, double from_bridge_mm) const {
    const double r = model.setup().bridge_arch_radius_mm;
    const double y = model.LateralOffsetAtBridgeMm(s);
    return {from_bridge_mm, y, std::sqrt(r * r - y * y) - r};
  }
};

// Height of the line p + a d above the arched string s at the string's x (instrument mm).
double Clearance(const Scene& scene, const Eigen::Vector3d& p, const Eigen::Vector3d& d, int s) {
  const Eigen::Vector3d top = scene.ArchTop(s, p.x());
  const double a = (top.y() - p.y()) / d.y();
  return p.z() + a * d.z() - top.z();
}

BowingInput OneFrame(const Scene& scene, const Eigen::Vector3d& frog_in, const Eigen::Vector3d& tip_in) {
  BowingInput in;
  in.frog_in_world_mm = {scene.World(frog_in)};
  in.tip_in_world_mm = {scene.World(tip_in)};
  in.strings_in_world_mm = {scene.strings};
  return in;
}

// A bow that rests on one string of a real (arched) bridge touches only it: the analysis,
// which sees flat strings as arco does, names that string from the bow's inclination, and
// reads the sounding point and the place on the bow.
TEST(AnalyzeBowing, NamesTheStringABowRestsOnOverAnArchedBridge) {
  for (InstrumentKind kind : {InstrumentKind::kCello, InstrumentKind::kViolin}) {
    const Scene scene(kind);
    for (int s = 1; s <= scene.model.num_strings(); ++s) {
      const double sounding = 0.08 * scene.model.string_length_mm();
      const Eigen::Vector3d contact = scene.ArchTop(s, sounding);
      // The tangent at the string: rotate the bow across the strings until both
      // neighbours clear it (found by search, not from the analysis' formula).
      double best_angle = 0, best_margin = -1e9;
      for (double deg = -60; deg <= 60; deg += 0.05) {
        const Eigen::Vector3d d(0, -std::cos(deg * kPi / 180), std::sin(deg * kPi / 180));
        double margin = 1e9;
        for (int o = 1; o <= scene.model.num_strings(); ++o) {
          if (o != s) margin = std::min(margin, Clearance(scene, contact, d, o));
        }
        if (margin > best_margin) best_margin = margin, best_angle = deg;
      }
      ASSERT_GT(best_margin, 0.5) << "string " << s;
      const Eigen::Vector3d d(0, -std::cos(best_angle * kPi / 180), std::sin(best_angle * kPi / 180));
      const double bow = 640;
      const BowingInput in = OneFrame(scene, contact - 0.3 * bow * d, contact + 0.7 * bow * d);
      const BowingResult r = AnalyzeBowing(scene.model, in, {}).value();
      ASSERT_EQ(r.frames.size(), 1u);
      const BowingFrame& f = r.frames[0];
      EXPECT_TRUE(f.seen);
      EXPECT_EQ(f.string, s) << scene.model.name() << " inclination " << f.inclination_deg;
      EXPECT_EQ(f.second_string, 0);
      // The flat string lies below the arched top by at most the arch's sag.
      EXPECT_LT(f.lift_mm, 12);
      EXPECT_NEAR(f.sounding_point_mm, sounding, 1.0);
      EXPECT_NEAR(f.bow_position, 0.3, 0.01);
      EXPECT_NEAR(f.skew_deg, 0, 1e-6);
    }
  }
}

// A line through the tops of two neighbouring strings touches both: a double stop.
TEST(AnalyzeBowing, ABowOnTwoStringsIsADoubleStop) {
  const Scene scene(InstrumentKind::kCello);
  for (int s = 1; s < 4; ++s) {
    const Eigen::Vector3d a = scene.ArchTop(s, 55), b = scene.ArchTop(s + 1, 55);
    const Eigen::Vector3d d = (b - a).normalized();
    const Eigen::Vector3d mid = 0.5 * (a + b);
    const BowingResult r =
        AnalyzeBowing(scene.model, OneFrame(scene, mid - 300 * d, mid + 340 * d), {}).value();
    const BowingFrame& f = r.frames[0];
    EXPECT_TRUE((f.string == s && f.second_string == s + 1) ||
                (f.string == s + 1 && f.second_string == s))
        << "strings " << s << "+" << s + 1 << ": " << f.string << " " << f.second_string
        << " at " << f.inclination_deg << " deg";
  }
}

// Piecewise straight strokes with turns between frames: every frame gets its stroke's
// direction, the changes are found at their instants, the speed is the stroke's.
TEST(AnalyzeBowing, DirectionsAndBowChangesOfStraightStrokes) {
  const Scene scene(InstrumentKind::kCello);
  const double fps = 30;
  // Turns (s) and the contact's place on the bow between them (mm from the frog).
  const std::vector<double> turns = {0.517, 1.262, 1.71, 2.488};
  const std::vector<double> places = {100, 500, 150, 420, 90, 300};  // at 0, turns, end
  const double end_s = 3.0;
  auto place_at = [&](double t) {
    std::vector<double> knots = {0};
    knots.insert(knots.end(), turns.begin(), turns.end());
    knots.push_back(end_s);
    for (size_t i = 0; i + 1 < knots.size(); ++i) {
      if (t <= knots[i + 1]) {
        const double u = (t - knots[i]) / (knots[i + 1] - knots[i]);
        return places[i] + u * (places[i + 1] - places[i]);
      }
    }
    return places.back();
  };
  const Eigen::Vector3d contact = scene.ArchTop(1, 60);
  const double incl = scene.model.BowInclinationRad(1);
  const Eigen::Vector3d d(0, -std::cos(incl), -std::sin(incl));  // frog -> tip
  BowingInput in;
  in.fps = fps;
  const int n = static_cast<int>(end_s * fps);
  for (int f = 0; f < n; ++f) {
    const double along = place_at(f / fps);
    in.frog_in_world_mm.push_back(scene.World(contact - along * d));
    in.tip_in_world_mm.push_back(scene.World(contact + (640 - along) * d));
    in.strings_in_world_mm.push_back(scene.strings);
  }
  const BowingResult r = AnalyzeBowing(scene.model, in, {}).value();
  ASSERT_EQ(r.change_times_s.size(), turns.size());
  for (size_t i = 0; i < turns.size(); ++i) EXPECT_NEAR(r.change_times_s[i], turns[i], 1e-3);
  int wrong = 0;
  for (int f = 0; f < n; ++f) {
    const double t = f / fps;
    const double v = place_at(t + 1e-6) - place_at(t - 1e-6);
    const BowDirection truth = v > 0 ? BowDirection::kDown : BowDirection::kUp;
    wrong += r.frames[static_cast<size_t>(f)].direction != truth;
    EXPECT_EQ(r.frames[static_cast<size_t>(f)].string, 1);
  }
  EXPECT_EQ(wrong, 0);
  // Speed of the first stroke: 400 mm in 0.517 s.
  EXPECT_NEAR(r.frames[5].bow_speed_mm_per_s, 400 / 0.517, 1e-6);
  int changes = 0;
  for (const BowingFrame& f : r.frames) changes += f.bow_change;
  EXPECT_EQ(changes, 4);
  EXPECT_EQ(r.summary.bow_changes, 4);
}

// A slow down-bow (75 mm/s) whose tracked place on the bow jitters by +-1.5 mm in a
// 4-frame pattern: one frame's central difference reads 30 mm/s on half the frames, under
// the 50 mm/s of a still bow, but the bow moves; then the bow stops, with the same jitter,
// and has no direction.
TEST(AnalyzeBowing, ASlowBowsJitterIsNoStop) {
  const Scene scene(InstrumentKind::kCello);
  const double fps = 30;
  const Eigen::Vector3d contact = scene.ArchTop(2, 60);
  const double incl = scene.model.BowInclinationRad(2);
  const Eigen::Vector3d d(0, -std::cos(incl), -std::sin(incl));  // frog -> tip
  BowingInput in;
  in.fps = fps;
  const int moving = 30, n = 46;
  for (int f = 0; f < n; ++f) {
    const double jitter = (f / 2) % 2 == 0 ? 1.5 : -1.5;
    const double along = 200 + 75.0 / fps * std::min(f, moving) + jitter;
    in.frog_in_world_mm.push_back(scene.World(contact - along * d));
    in.tip_in_world_mm.push_back(scene.World(contact + (640 - along) * d));
    in.strings_in_world_mm.push_back(scene.strings);
  }
  const BowingResult r = AnalyzeBowing(scene.model, in, {}).value();
  EXPECT_TRUE(r.change_times_s.empty());
  int slow_frames = 0;
  for (int f = 2; f < moving - 1; ++f) {  // frame 1's window holds two slow readings
    const BowingFrame& bf = r.frames[static_cast<size_t>(f)];
    slow_frames += bf.bow_speed_mm_per_s < 50;
    EXPECT_EQ(bf.direction, BowDirection::kDown) << f << " at " << bf.bow_speed_mm_per_s;
  }
  EXPECT_GE(slow_frames, 10);  // the frames whose own speed reads still
  for (int f = moving + 2; f < n; ++f) {
    EXPECT_EQ(r.frames[static_cast<size_t>(f)].direction, BowDirection::kNone) << f;
  }
}

// Notes: the bow's string against the fingered one, and changes against the onsets.
TEST(AnalyzeBowing, NotesFlagABowOnAnotherStringThanTheFingeredOne) {
  const Scene scene(InstrumentKind::kCello);
  BowingInput in;
  const Eigen::Vector3d contact = scene.ArchTop(2, 60);
  const double incl = scene.model.BowInclinationRad(2);
  const Eigen::Vector3d d(0, -std::cos(incl), -std::sin(incl));
  for (int f = 0; f < 20; ++f) {
    const double along = 100 + 20.0 * f;
    in.frog_in_world_mm.push_back(scene.World(contact - along * d));
    in.tip_in_world_mm.push_back(scene.World(contact + (640 - along) * d));
    in.strings_in_world_mm.push_back(scene.strings);
  }
  NoteFingering agree, disagree;
  agree.note = 0, agree.first_frame = 0, agree.last_frame = 9, agree.string = 2;
  disagree.note = 1, disagree.first_frame = 10, disagree.last_frame = 19, disagree.string = 1;
  disagree.onset_s = 10 / 30.0;
  in.notes = {agree, disagree};
  const BowingResult r = AnalyzeBowing(scene.model, in, {}).value();
  ASSERT_EQ(r.notes.size(), 2u);
  EXPECT_TRUE(r.notes[0].strings_agree);
  EXPECT_FALSE(r.notes[1].strings_agree);
  EXPECT_EQ(r.notes[1].bow_string, 2);
  EXPECT_EQ(r.notes[0].direction, BowDirection::kDown);
  EXPECT_NEAR(r.notes[0].mean_speed_mm_per_s, 600, 1e-6);
  EXPECT_EQ(r.summary.notes_string_disagree, 1);
  EXPECT_EQ(r.summary.bow_changes, 0);
  // The same in two parts: the frames once, the notes added (again: replaced, not doubled).
  BowingResult parts = AnalyzeBowStrokes(scene.model, in, {}).value();
  EXPECT_TRUE(parts.notes.empty());
  EXPECT_EQ(parts.summary.notes, 0);
  EXPECT_EQ(parts.summary.frames_on_string, r.summary.frames_on_string);
  AddBowingNotes({agree}, {}, &parts);
  AddBowingNotes(in.notes, {}, &parts);
  ASSERT_EQ(parts.notes.size(), 2u);
  EXPECT_EQ(parts.notes[1].bow_string, 2);
  EXPECT_FALSE(parts.notes[1].strings_agree);
  EXPECT_EQ(parts.summary.notes, 2);
  EXPECT_EQ(parts.summary.notes_string_disagree, 1);
  EXPECT_EQ(parts.summary.bow_changes_at_onsets, r.summary.bow_changes_at_onsets);
}

TEST(AnalyzeBowing, OffTheStringsUnseenAndBadInput) {
  const Scene scene(InstrumentKind::kCello);
  const Eigen::Vector3d contact = scene.ArchTop(3, 60) + Eigen::Vector3d(0, 0, 45);
  const double incl = scene.model.BowInclinationRad(3);
  const Eigen::Vector3d d(0, -std::cos(incl), -std::sin(incl));
  BowingInput in = OneFrame(scene, contact - 300 * d, contact + 340 * d);
  in.frog_in_world_mm.push_back(Eigen::Vector3d::Constant(kNaN));
  in.tip_in_world_mm.push_back(scene.World(contact));
  in.strings_in_world_mm.push_back(scene.strings);
  in.frog_in_world_mm.push_back(scene.World(contact - 300 * d));
  in.tip_in_world_mm.push_back(scene.World(contact + 340 * d));
  in.strings_in_world_mm.push_back({});  // no instrument pose
  const BowingResult r = AnalyzeBowing(scene.model, in, {}).value();
  EXPECT_TRUE(r.frames[0].seen);
  EXPECT_EQ(r.frames[0].string, 0);
  EXPECT_GT(r.frames[0].lift_mm, 30);
  EXPECT_TRUE(std::isnan(r.frames[0].sounding_point_mm));
  EXPECT_FALSE(r.frames[1].seen);
  EXPECT_FALSE(r.frames[2].seen);
  EXPECT_EQ(r.summary.frames_seen, 1);

  BowingInput bad = in;
  bad.tip_in_world_mm.pop_back();
  EXPECT_FALSE(AnalyzeBowing(scene.model, bad, {}).ok());
  BowingOptions options;
  options.max_lift_mm = -1;
  const auto status = AnalyzeBowing(scene.model, in, options);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.status().message().find("max_lift_mm"), std::string::npos);
}

TEST(BowingCsv, RoundTripsAndRejectsBadRows) {
  const arco::testing::TempDir temp;
  const std::filesystem::path dir = temp.path();
  std::vector<BowingFrame> frames(3);
  frames[0].string = 1, frames[0].direction = BowDirection::kDown, frames[0].sounding_point_mm = 52.5;
  frames[1].string = 2, frames[1].second_string = 3, frames[1].direction = BowDirection::kUp;
  frames[1].sounding_point_mm = 40;
  const std::string path = (dir / "bowing.csv").string();
  ASSERT_TRUE(WriteBowingCsv(path, frames).ok());
  const auto back = ReadBowingCsv(path);
  ASSERT_TRUE(back.ok()) << back.status().message();
  ASSERT_EQ(back->size(), 3u);
  EXPECT_EQ((*back)[0].direction, BowDirection::kDown);
  EXPECT_EQ((*back)[1].second_string, 3);
  EXPECT_EQ((*back)[2].direction, BowDirection::kNone);
  EXPECT_DOUBLE_EQ((*back)[0].sounding_point_mm, 52.5);
  EXPECT_TRUE(std::isnan((*back)[2].sounding_point_mm));

  const std::pair<const char*, const char*> bad[] = {
      {"frame,string,direction,sounding_point_mm\n0,1,sideways,50\n", "direction"},
      {"frame,string,direction,sounding_point_mm\n0,9,down,50\n", "string"},
      {"frame,string,direction,sounding_point_mm\n1,1,down,50\n", "frame"},
      {"frame,string,direction,sounding_point_mm\n0,1,down,-4\n", "sounding_point_mm"},
      {"frame,string,direction\n0,1,down\n", "sounding_point_mm"},
      {"frame,string,direction,sounding_point_mm\n0,1,down\n", "fields"},
  };
  for (const auto& [text, what] : bad) {
    std::ofstream(path) << text;
    const auto r = ReadBowingCsv(path);
    ASSERT_FALSE(r.ok()) << text;
    EXPECT_NE(r.status().message().find(path), std::string::npos) << r.status().message();
    EXPECT_NE(r.status().message().find(what), std::string::npos) << r.status().message();
  }
}

// SPD's real cello take (their 3D: the bow's frog and tip on the stick, the strings lowest
// first): the bow is on the A string wherever a finger presses it (DOMAIN.md: every pressed
// frame of this half is on the A string), and it moves in strokes.
TEST(AnalyzeBowing, RealTakeBowIsOnTheStringSpdPlays) {
  const auto take = ReadNpy<double>(std::string(ARCO_SHARED_DATA_DIR) +
                                    "/spd/cello01_first_half_results.npy");
  ASSERT_TRUE(take.ok()) << take.status().message();
  const NpyArray<double>& a = *take;
  ASSERT_EQ(a.shape, (std::vector<int64_t>{330, 155, 3}));
  const InstrumentModel cello = Scene::MakeModel(InstrumentKind::kCello);
  auto point = [&](int64_t f, int64_t k) {
    return Eigen::Vector3d(a.at(f, k, 0), a.at(f, k, 1), a.at(f, k, 2));
  };
  BowingInput in;
  for (int64_t f = 0; f < a.shape[0]; ++f) {
    in.frog_in_world_mm.push_back(point(f, 140));
    in.tip_in_world_mm.push_back(point(f, 141));
    std::vector<StringSegment> strings(4);
    for (int k = 0; k < 4; ++k) {  // SPD: C, G, D, A (top = nut end, bottom = bridge end)
      StringSegment& s = strings[static_cast<size_t>(3 - k)];
      s.string = 4 - k;
      s.nut = point(f, 142 + 2 * k);
      s.bridge = point(f, 143 + 2 * k);
    }
    in.strings_in_world_mm.push_back(strings);
  }
  const BowingResult r = AnalyzeBowing(cello, in, {}).value();
  int pressed = 0, on_a = 0;
  for (int64_t f = 0; f < a.shape[0]; ++f) {
    if (!std::isfinite(a.at(f, 150, 0))) continue;
    ++pressed;
    on_a += r.frames[static_cast<size_t>(f)].string == 1;
  }
  EXPECT_EQ(pressed, 262);
  EXPECT_GE(on_a, 0.97 * pressed) << on_a << " of " << pressed;
  // Strokes: the contact's place on SPD's bow (read off their points, docs/bowing.md) runs
  // from 0.16 of the bow to 0.85 by frame 130 (many notes slurred in one down-bow), back
  // to 0.22 by frame 211, to 0.71 by 259, then toward the frog: three bow changes.
  ASSERT_EQ(r.change_times_s.size(), 3u);
  const double turns_s[] = {130 / 30.0, 211 / 30.0, 259 / 30.0};
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(r.change_times_s[static_cast<size_t>(i)], turns_s[i], 0.15);
  // The sounding point lies between the bridge and the fingerboard's end.
  EXPECT_GT(r.summary.median_sounding_point_mm, 20);
  EXPECT_LT(r.summary.median_sounding_point_mm, 115);
}

}  // namespace
}  // namespace arco::refine
