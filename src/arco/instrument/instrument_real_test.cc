// The instrument layer on the real SPD frame-128 labels (../shared/data/spd): four views
// of session cello_1113_scale, triangulated with the Metashape XML calibration
// (distortion removed), then strings, scale and contacts.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "arco/camera/calibration_io.h"
#include "arco/geometry/triangulation.h"
#include "arco/instrument/contact.h"
#include "arco/instrument/nominal_keypoints.h"
#include "arco/instrument/strings.h"
#include "arco/instrument/template_fit.h"
#include "arco/util/file_io.h"
#include "arco/util/json_io.h"

namespace arco {
namespace {

const char* kSerials[] = {"21334181", "21334190", "21334211", "21334237"};

std::string SpdPath(const std::string& name) {
  return std::string(ARCO_SHARED_DATA_DIR) + "/spd/" + name;
}

struct RealFrame {
  Rig rig;
  std::map<std::string, Eigen::Vector3d> points;  // label -> world (Metashape units)
};

// Triangulates every labelled point seen in at least two of the four views.
RealFrame LoadFrame128() {
  RealFrame out;
  auto text = ReadFileToString(SpdPath("cello_1113_scale_camera.xml"));
  EXPECT_TRUE(text.ok());
  auto calibration = ParseMetashapeXml(*text, "cello_1113_scale_camera.xml");
  EXPECT_TRUE(calibration.ok()) << calibration.status().message();
  out.rig = calibration->rig;
  std::map<std::string, std::vector<DltObservation>> observations;
  std::vector<Eigen::Vector3d> centers;
  for (const char* serial : kSerials) {
    const int cam = out.rig.FindCamera(serial);
    EXPECT_GE(cam, 0) << serial;
    const Camera& camera = out.rig.cameras[cam];
    centers.push_back(camera.CenterInWorld());
    auto json = ReadJsonFile(
        SpdPath("labels_frame128/cello_1113_scale_" + std::string(serial) + "_128.json"));
    EXPECT_TRUE(json.ok());
    for (const Json& shape : (*json)["shapes"]) {
      if (shape["shape_type"] != "point") continue;
      // labelme (Qt) puts the origin at the pixel corner like Metashape; arco's cameras
      // use the pixel centre (camera.h).
      const Eigen::Vector2d pixel(shape["points"][0][0].get<double>() - 0.5,
                                  shape["points"][0][1].get<double>() - 0.5);
      DltObservation o;
      o.projection.leftCols<3>() = camera.cam_from_world.rotation;
      o.projection.col(3) = camera.cam_from_world.translation;
      o.point = camera.PixelToNormalized(pixel);
      observations[shape["label"].get<std::string>()].push_back(o);
    }
  }
  const WorldConditioning conditioning = ConditioningFromCameraCenters(centers);
  for (const auto& [label, obs] : observations) {
    if (obs.size() < 2) continue;
    auto p = TriangulateDlt(obs, conditioning);
    if (p) out.points[label] = *p;
  }
  return out;
}

const RealFrame& Frame128() {
  static const RealFrame frame = LoadFrame128();
  return frame;
}

const InstrumentModel& Cello() {
  static const InstrumentModel model = *InstrumentModel::Create("cello");
  return model;
}

StringEdges Edges(const RealFrame& f) {
  return {
      f.points.at("nut_l"), f.points.at("nut_r"), f.points.at("bridge_l"), f.points.at("bridge_r")};
}

// Camera 21334181 films the cellist from the front (../shared/data/spd/example.jpg).
FrontHint FrontCamera(const RealFrame& f) {
  return {FrontHint::Kind::kFrontPoint,
          f.rig.cameras[f.rig.FindCamera("21334181")].CenterInWorld()};
}

TEST(InstrumentOnRealLabels, ScaleDistancesAndStringOrder) {
  const RealFrame& f = Frame128();
  for (const char* label :
       {"scroll_top", "nut_l", "nut_r", "bridge_l", "bridge_r", "tail_gut", "end_pin"}) {
    ASSERT_TRUE(f.points.count(label)) << label;
  }
  auto g = GeometryFromEdges(Cello(), Edges(f), FrontCamera(f));
  ASSERT_TRUE(g.ok()) << g.status().message();
  EXPECT_FALSE(g->order.ambiguous) << g->order.warning;
  // SPD labels put nut_l / bridge_l on the lowest string (DOMAIN.md section 5).
  EXPECT_TRUE(g->order.labels_agree) << g->order.warning;
  // README: the nut-bridge distance measures about 0.344 Metashape units (695 mm).
  EXPECT_NEAR(g->world_from_instrument.scale * 695.0, 0.344, 0.004);
  // DOMAIN.md section 5 distances at that scale.
  auto mm = [&](const char* a, const char* b) {
    return (f.points.at(a) - f.points.at(b)).norm() / g->world_from_instrument.scale;
  };
  EXPECT_NEAR(mm("nut_l", "nut_r"), 23.9, 1.5);
  EXPECT_NEAR(mm("bridge_l", "bridge_r"), 48.2, 1.5);
  EXPECT_NEAR(mm("bridge_l", "tail_gut"), 377, 8);
  EXPECT_NEAR(mm("tail_gut", "end_pin"), 314, 8);
  // Instrument frame: the end pin is below the bridge (toward -x), the scroll beyond the nut.
  EXPECT_LT(g->world_from_instrument.InverseMap(f.points.at("end_pin")).x(), -600);
  EXPECT_GT(g->world_from_instrument.InverseMap(f.points.at("scroll_top")).x(), 695 + 100);
  // The other frontal-ish views agree on the side; the performer's side would flip it.
  FrontHint behind = FrontCamera(f);
  behind.kind = FrontHint::Kind::kPerformerPoint;
  auto flipped = GeometryFromEdges(Cello(), Edges(f), behind);
  ASSERT_TRUE(flipped.ok());
  EXPECT_FALSE(flipped->order.labels_agree);
}

TEST(InstrumentOnRealLabels, TheNominalShapeIsTheRealCellos) {
  // instrument/nominal_keypoints.h: the places the model does not give are this cello's,
  // in its own frame (x along the strings, z to the front), on the centre line.
  const RealFrame& f = Frame128();
  auto g = GeometryFromEdges(Cello(), Edges(f), FrontCamera(f));
  ASSERT_TRUE(g.ok()) << g.status().message();
  const std::vector<Eigen::Vector3d> nominal = NominalKeypointsInInstrument(Cello());
  for (const char* name : {"scroll_top", "tail_gut", "end_pin"}) {
    const Eigen::Vector3d real = g->world_from_instrument.InverseMap(f.points.at(name));
    const Eigen::Vector3d& n = nominal[static_cast<size_t>(Cello().KeypointIndex(name))];
    std::printf("[ nominal ] %-10s real %7.1f %6.1f %7.1f, nominal %7.1f %6.1f %7.1f mm\n",
                name,
                real.x(),
                real.y(),
                real.z(),
                n.x(),
                n.y(),
                n.z());
    EXPECT_NEAR(n.x(), real.x(), 3.0) << name;
    EXPECT_NEAR(n.z(), real.z(), 3.0) << name;  // the former guesses were 5-164 mm off
    EXPECT_EQ(n.y(), 0.0) << name;
    EXPECT_LT(std::abs(real.y()), 40.0) << name;  // the lean the centre line leaves out
  }
  // A pose from the nominal shape leaves the end pin out: its spike is the player's.
  const std::vector<Eigen::Vector3d> pose = NominalPoseKeypointsInInstrument(Cello());
  for (size_t k = 0; k < pose.size(); ++k) {
    const bool end_pin = Cello().keypoint_names()[k] == "end_pin";
    EXPECT_EQ(pose[k].allFinite(), !end_pin && nominal[k].allFinite()) << k;
    if (!end_pin && nominal[k].allFinite()) {
      EXPECT_EQ(pose[k], nominal[k]) << k;
    }
  }
}

TEST(InstrumentOnRealLabels, OctaveIsHalfWayAlongTheRealString) {
  const RealFrame& f = Frame128();
  auto g = GeometryFromEdges(Cello(), Edges(f), FrontCamera(f));
  ASSERT_TRUE(g.ok());
  for (int s = 1; s <= 4; ++s) {
    const Contact c = ContactPoint(Cello(), s, 2 * Cello().open_hz(s));
    ASSERT_TRUE(c.stopped());
    const StringSegment& seg = g->strings[s - 1];
    const Eigen::Vector3d p = seg.PointAtFraction(c.fraction_from_bridge);
    EXPECT_NEAR((p - seg.nut).norm(), (p - seg.bridge).norm(), 1e-12);
    EXPECT_NEAR(g->world_from_instrument.InverseMap(p).x(), 347.5, 0.5);
  }
  // The C string runs next to the labelled nut_l / bridge_l.
  EXPECT_LT((g->strings[3].nut - f.points.at("nut_l")).norm(),
            (g->strings[0].nut - f.points.at("nut_l")).norm());
}

TEST(InstrumentOnRealLabels, TemplateFitOnAJitteredRealShape) {
  // A clip made of the real triangulated shape moved rigidly each frame, with 1.5 mm
  // noise and some missing points: the fit must give back the real frame's scale,
  // strings and order.
  const RealFrame& f = Frame128();
  const double u = 0.344 / 695.0;
  std::mt19937 rng(128);
  std::normal_distribution<double> noise(0.0, 1.5 * u);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<Eigen::Matrix3Xd> clip;
  std::vector<FrontHint> hints;
  const Eigen::Vector3d center = 0.5 * (f.points.at("nut_l") + f.points.at("bridge_r"));
  for (int i = 0; i < 120; ++i) {
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(0.02 * std::sin(0.1 * i), Eigen::Vector3d(0.3, 1, 0.2).normalized())
            .toRotationMatrix();
    const Eigen::Vector3d t(0.01 * std::sin(0.05 * i), 0.0, 0.005 * std::cos(0.07 * i));
    Eigen::Matrix3Xd kp = Eigen::Matrix3Xd::Constant(3, 9, NAN);
    for (int k = 0; k < 7; ++k) {
      const Eigen::Vector3d& p = f.points.at(Cello().keypoint_names()[k]);
      kp.col(k) =
          r * (p - center) + center + t + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
      if (uniform(rng) < 0.1) kp.col(k).setConstant(NAN);
    }
    clip.push_back(kp);
    const Eigen::Vector3d cam = FrontCamera(f).value;
    hints.push_back({FrontHint::Kind::kFrontPoint, r * (cam - center) + center + t});
  }
  auto fit = FitInstrument(Cello(), clip, hints);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_TRUE(fit->instrument.order.labels_agree);
  EXPECT_FALSE(fit->instrument.order.ambiguous) << fit->instrument.order.warning;
  EXPECT_NEAR(fit->instrument.world_units_per_mm * 695.0, 0.344, 0.004);
  EXPECT_LT(fit->summary.median_rms_residual_mm, 3.0);
  auto single = GeometryFromEdges(Cello(), Edges(f), FrontCamera(f));
  ASSERT_TRUE(single.ok());
  for (int s = 0; s < 4; ++s) {
    const Eigen::Vector3d a = fit->instrument.strings_in_instrument[s].nut;
    const Eigen::Vector3d b = single->strings_in_instrument[s].nut;
    EXPECT_LT((a - b).norm(), 2.0) << s;
  }
}

}  // namespace
}  // namespace arco
