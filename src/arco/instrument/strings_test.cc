#include "arco/instrument/strings.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "arco/instrument/contact.h"

namespace arco {
namespace {

const InstrumentModel& Cello() {
  static const InstrumentModel model = *InstrumentModel::Create("cello");
  return model;
}

// A cello in a known pose: instrument-frame edge points (mm) mapped into a Metashape-like
// world (1 unit = 2020 mm). Labels follow SPD: nut_l / bridge_l on the low side (+y).
struct Scene {
  SimMatrix3d truth;  // world_from_instrument
  StringEdges edges;
  Eigen::Vector3d performer;  // behind the top plate (z < 0 in the instrument frame)
};

Scene MakeScene(double label_nut_mm = 23.9, double label_bridge_mm = 48.2) {
  Scene s;
  s.truth.rotation = (Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, -1, 0.4).normalized()) *
                      Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitX()))
                         .toRotationMatrix();
  s.truth.translation = Eigen::Vector3d(0.12, -0.4, 2.3);
  s.truth.scale = 1.0 / 2020.0;
  s.edges.nut_l = s.truth * Eigen::Vector3d(695, label_nut_mm / 2, 0);
  s.edges.nut_r = s.truth * Eigen::Vector3d(695, -label_nut_mm / 2, 0);
  s.edges.bridge_l = s.truth * Eigen::Vector3d(0, label_bridge_mm / 2, 0);
  s.edges.bridge_r = s.truth * Eigen::Vector3d(0, -label_bridge_mm / 2, 0);
  s.performer = s.truth * Eigen::Vector3d(350, 20, -250);
  return s;
}

FrontHint Performer(const Eigen::Vector3d& p) { return {FrontHint::Kind::kPerformerPoint, p}; }

TEST(GeometryFromEdges, RecoversFrameScaleAndRealSpacing) {
  const Scene scene = MakeScene();
  auto g = GeometryFromEdges(Cello(), scene.edges, Performer(scene.performer));
  ASSERT_TRUE(g.ok()) << g.status().message();
  EXPECT_FALSE(g->order.ambiguous) << g->order.warning;
  EXPECT_TRUE(g->order.labels_agree);
  EXPECT_NEAR(g->order.front_margin_mm, 250.0, 1e-6);
  EXPECT_NEAR(g->world_from_instrument.scale, scene.truth.scale, 1e-15);
  EXPECT_LT((g->world_from_instrument.rotation - scene.truth.rotation).norm(), 1e-12);
  EXPECT_LT((g->world_from_instrument.translation - scene.truth.translation).norm(), 1e-12);
  ASSERT_EQ(g->strings.size(), 4u);
  for (int s = 1; s <= 4; ++s) {
    const StringSegment& in = g->strings_in_instrument[s - 1];
    EXPECT_EQ(in.string, s);
    EXPECT_NEAR(in.nut.y(), Cello().LateralOffsetAtNutMm(s), 1e-9);
    EXPECT_NEAR(in.bridge.y(), Cello().LateralOffsetAtBridgeMm(s), 1e-9);
    EXPECT_NEAR(in.nut.x(), 695.0, 1e-9);
    EXPECT_NEAR(in.bridge.x(), 0.0, 1e-9);
    EXPECT_LT((g->strings[s - 1].nut - scene.truth * in.nut).norm(), 1e-12);
  }
  // The C string (4) is on the +y (low) side, i.e. next to nut_l.
  EXPECT_LT((g->strings[3].nut - scene.edges.nut_l).norm(),
            (g->strings[0].nut - scene.edges.nut_l).norm());
  // Outer strings 23 mm apart at the nut, not the 23.9 mm label width.
  const double nut_mm =
      (g->strings[3].nut - g->strings[0].nut).norm() / g->world_from_instrument.scale;
  EXPECT_NEAR(nut_mm, Cello().nut_spacing_mm(), 1e-9);
}

TEST(GeometryFromEdges, OctaveContactIsHalfWayInThreeD) {
  const Scene scene = MakeScene();
  auto g = GeometryFromEdges(Cello(), scene.edges, Performer(scene.performer));
  ASSERT_TRUE(g.ok());
  const Contact c = ContactPoint(Cello(), 2, 2 * Cello().open_hz(2));
  const StringSegment& d = g->strings[1];
  const Eigen::Vector3d p = d.PointAtFraction(c.fraction_from_bridge);
  EXPECT_NEAR((p - d.nut).norm(), (p - d.bridge).norm(), 1e-12);
  EXPECT_NEAR(g->world_from_instrument.InverseMap(p).x(), 347.5, 1e-6);
}

TEST(GeometryFromEdges, SwappedLabelsGiveTheSameStrings) {
  const Scene scene = MakeScene();
  StringEdges swapped{
      scene.edges.nut_r, scene.edges.nut_l, scene.edges.bridge_r, scene.edges.bridge_l};
  auto a = GeometryFromEdges(Cello(), scene.edges, Performer(scene.performer));
  auto b = GeometryFromEdges(Cello(), swapped, Performer(scene.performer));
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_FALSE(b->order.labels_agree);
  EXPECT_FALSE(b->order.warning.empty());
  for (int s = 0; s < 4; ++s) {
    EXPECT_LT((a->strings[s].nut - b->strings[s].nut).norm(), 1e-12);
    EXPECT_LT((a->strings[s].bridge - b->strings[s].bridge).norm(), 1e-12);
  }
  // Swapped at one end only: the order still comes from geometry.
  StringEdges half{
      scene.edges.nut_r, scene.edges.nut_l, scene.edges.bridge_l, scene.edges.bridge_r};
  auto c = GeometryFromEdges(Cello(), half, Performer(scene.performer));
  ASSERT_TRUE(c.ok());
  EXPECT_FALSE(c->order.labels_agree);
  for (int s = 0; s < 4; ++s) EXPECT_LT((a->strings[s].nut - c->strings[s].nut).norm(), 1e-12);
}

TEST(GeometryFromEdges, MirroredSceneReversesOrderAgainstLabels) {
  // A mirror image of the scene (labels unchanged) is a cello whose low side is where
  // the labels say "r": geometry must put string 4 next to nut_r.
  Scene scene = MakeScene();
  const Eigen::Matrix3d mirror = Eigen::Vector3d(-1, 1, 1).asDiagonal();
  for (Eigen::Vector3d* p : {&scene.edges.nut_l,
                             &scene.edges.nut_r,
                             &scene.edges.bridge_l,
                             &scene.edges.bridge_r,
                             &scene.performer}) {
    *p = mirror * *p;
  }
  auto g = GeometryFromEdges(Cello(), scene.edges, Performer(scene.performer));
  ASSERT_TRUE(g.ok());
  EXPECT_FALSE(g->order.labels_agree);
  EXPECT_LT((g->strings[3].nut - scene.edges.nut_r).norm(),
            (g->strings[3].nut - scene.edges.nut_l).norm());
  EXPECT_NEAR(g->world_from_instrument.rotation.determinant(), 1.0, 1e-12);
}

TEST(GeometryFromEdges, HintSideDecidesTheOrder) {
  const Scene scene = MakeScene();
  const Eigen::Vector3d front = scene.truth * Eigen::Vector3d(350, 0, 400);
  auto by_performer = GeometryFromEdges(Cello(), scene.edges, Performer(scene.performer));
  auto by_front = GeometryFromEdges(Cello(), scene.edges, {FrontHint::Kind::kFrontPoint, front});
  auto by_dir = GeometryFromEdges(
      Cello(), scene.edges, {FrontHint::Kind::kFrontDirection, scene.truth.rotation.col(2)});
  // The same point claimed as the performer's side flips the order.
  auto wrong = GeometryFromEdges(Cello(), scene.edges, Performer(front));
  ASSERT_TRUE(by_performer.ok() && by_front.ok() && by_dir.ok() && wrong.ok());
  EXPECT_LT((by_front->strings[3].nut - by_performer->strings[3].nut).norm(), 1e-12);
  EXPECT_LT((by_dir->strings[3].nut - by_performer->strings[3].nut).norm(), 1e-12);
  EXPECT_FALSE(wrong->order.labels_agree);
  EXPECT_LT((wrong->strings[0].nut - by_performer->strings[3].nut).norm(), 1e-12);
}

TEST(GeometryFromEdges, HintInThePlaneIsAmbiguous) {
  const Scene scene = MakeScene();
  auto g = GeometryFromEdges(
      Cello(), scene.edges, Performer(scene.truth * Eigen::Vector3d(350, 300, 5)));
  ASSERT_TRUE(g.ok());
  EXPECT_TRUE(g->order.ambiguous);
  EXPECT_NE(g->order.warning.find("ambiguous"), std::string::npos);
  auto d = GeometryFromEdges(
      Cello(), scene.edges, {FrontHint::Kind::kFrontDirection, scene.truth.rotation.col(1)});
  ASSERT_TRUE(d.ok());
  EXPECT_TRUE(d->order.ambiguous);
}

TEST(GeometryFromEdges, EvenSpacingReproducesSpdFractions) {
  const Scene scene = MakeScene();
  StringGeometryOptions options;
  options.spacing = StringGeometryOptions::Spacing::kEvenBetweenLabels;
  auto g = GeometryFromEdges(Cello(), scene.edges, Performer(scene.performer), options);
  ASSERT_TRUE(g.ok());
  EXPECT_LT((g->strings[3].nut - scene.edges.nut_l).norm(), 1e-12);
  EXPECT_LT((g->strings[0].bridge - scene.edges.bridge_r).norm(), 1e-12);
  EXPECT_NEAR(g->strings_in_instrument[2].nut.y(), 23.9 / 6, 1e-9);
}

TEST(GeometryFromEdges, DegenerateInputIsAnError) {
  const Scene scene = MakeScene();
  const FrontHint hint = Performer(scene.performer);
  StringEdges e = scene.edges;
  e.nut_l.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(GeometryFromEdges(Cello(), e, hint).ok());
  e = scene.edges;
  e.nut_l = e.bridge_l;
  e.nut_r = e.bridge_r;
  auto coincident = GeometryFromEdges(Cello(), e, hint);
  ASSERT_FALSE(coincident.ok());
  EXPECT_NE(coincident.status().message().find("coincide"), std::string::npos);
  e = scene.edges;
  e.nut_r = e.nut_l;
  e.bridge_r = e.bridge_l;
  EXPECT_FALSE(GeometryFromEdges(Cello(), e, hint).ok());
  e = scene.edges;
  e.nut_r = e.nut_l;  // one degenerate end: still strings, with a warning
  auto one = GeometryFromEdges(Cello(), e, hint);
  ASSERT_TRUE(one.ok());
  EXPECT_FALSE(one->order.warning.empty());
  EXPECT_FALSE(
      GeometryFromEdges(Cello(), scene.edges, Performer(Eigen::Vector3d::Constant(NAN))).ok());
  EXPECT_FALSE(GeometryFromEdges(Cello(),
                                 scene.edges,
                                 {FrontHint::Kind::kFrontDirection, Eigen::Vector3d::Zero()})
                   .ok());
  StringGeometryOptions bad;
  bad.world_units_per_mm = -1;
  EXPECT_FALSE(GeometryFromEdges(Cello(), scene.edges, hint, bad).ok());
}

TEST(WorldFromInstrument, MatchesSim3d) {
  const Scene scene = MakeScene();
  const Sim3d sim = scene.truth.ToSim3d();
  const Eigen::Vector3d p(100, -5, 20);
  EXPECT_LT((sim * p - scene.truth * p).norm(), 1e-12);
  const SimMatrix3d back(sim);
  EXPECT_LT((back * p - scene.truth * p).norm(), 1e-12);
  EXPECT_LT((back.InverseMap(scene.truth * p) - p).norm(), 1e-9);
}

TEST(StringsInWorld, MatchesTheGeometry) {
  const Scene scene = MakeScene();
  auto g = GeometryFromEdges(Cello(), scene.edges, Performer(scene.performer));
  ASSERT_TRUE(g.ok());
  const auto strings = StringsInWorld(g->strings_in_instrument, g->world_from_instrument);
  for (int s = 0; s < 4; ++s) {
    EXPECT_LT((strings[s].nut - g->strings[s].nut).norm(), 1e-12);
    EXPECT_LT((strings[s].bridge - g->strings[s].bridge).norm(), 1e-12);
  }
}

}  // namespace
}  // namespace arco
