#include "arco/export/export.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstring>
#include <random>

#include "arco/body/skeleton_fit.h"
#include "arco/export/plot.h"
#include "arco/registry/keypoint_layout.h"

namespace arco::exporter {
namespace {

// A spd_cello_contact-named sequence: a rigid body moving and turning, a gap in one
// point, so every bone length is constant and the BVH fit is exact.
ExportData RigidData(int64_t frames) {
  const KeypointLayout* layout = FindKeypointLayout("spd_cello_contact");
  EXPECT_NE(layout, nullptr);
  ExportData d;
  d.method = "arco";
  d.keypoint_names = layout->names;
  d.fps = 30;
  d.points_mm.shape = {frames, static_cast<int64_t>(layout->names.size()), 3};
  d.points_mm.data.resize(frames * layout->names.size() * 3);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-400, 400);
  std::vector<Eigen::Vector3d> shape(layout->names.size());
  for (auto& p : shape) p = Eigen::Vector3d(u(rng), u(rng), u(rng) + 1000);
  for (int64_t f = 0; f < frames; ++f) {
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(0.05 * f, Eigen::Vector3d(0.3, 1, 0.2).normalized()).toRotationMatrix();
    for (size_t p = 0; p < shape.size(); ++p) {
      const Eigen::Vector3d x = r * shape[p] + Eigen::Vector3d(2.0 * f, 0, 0);
      for (int k = 0; k < 3; ++k) d.points_mm.at(f, p, k) = x[k];
    }
  }
  const int tip = d.Find("left_hand_index_tip");
  if (frames > 2) {
    for (int k = 0; k < 3; ++k) d.points_mm.at(2, tip, k) = NAN;
  }
  return d;
}

TEST(ExportOptions, RejectsUnknownFormatAndMethod) {
  ExportOptions o;
  o.result_dir = "r";
  EXPECT_TRUE(o.Validate().ok());
  o.format = "fbx";
  EXPECT_NE(o.Validate().message().find("format"), std::string::npos);
  o.format = "bvh";
  o.method = "triangulation";
  EXPECT_NE(o.Validate().message().find("method"), std::string::npos);
  o.method = "paper";
  o.result_dir = "";
  EXPECT_FALSE(o.Validate().ok());
}

TEST(ExportOptions, TheOutputsExtensionIsTheFormats) {
  ExportOptions o;
  o.result_dir = "r";
  o.format = "bvh";
  o.output = "x.glb";
  EXPECT_EQ(o.Validate().message(),
            "x.glb: a bvh export is named .bvh, not .glb (rename the output, or choose the format "
            "its extension names)");
  for (const auto& [format, good, bad] :
       std::vector<std::array<std::string, 3>>{{"csv", "a/b.CSV", "b.txt"},
                                               {"trc", "b.trc", "b.csv"},
                                               {"c3d", "b.c3d", "b.trc"},
                                               {"gltf", "b.glb", "b.gltf"},
                                               {"glb", "x.y/b.glb", "x.glb/b"},
                                               {"bvh", "b.bvh", "b.glb"}}) {
    o.format = format;
    o.output = good;
    EXPECT_TRUE(o.Validate().ok()) << format << " " << good;
    o.output = bad;
    EXPECT_FALSE(o.Validate().ok()) << format << " " << bad;
  }
}

TEST(ParseExportFormat, NamesEveryFormat) {
  for (const char* name : {"csv", "trc", "c3d", "gltf", "bvh"}) {
    auto f = ParseExportFormat(name);
    ASSERT_TRUE(f.ok());
    EXPECT_STREQ(ExportFormatName(*f), name);
  }
  EXPECT_TRUE(ParseExportFormat("glb").ok());
  EXPECT_FALSE(ParseExportFormat("CSV").ok());
}

TEST(CsvText, OneRowPerFramePointWithEmptyGaps) {
  const ExportData d = RigidData(4);
  const std::string csv = CsvText(d);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 4 * d.points());
  EXPECT_NE(csv.find("\n3,0.066667,left_hand_index_tip,,,,0,,\n"), std::string::npos);
}

TEST(TrcText, HeaderNamesEveryMarker) {
  const ExportData d = RigidData(3);
  const std::string trc = TrcText(d, "a.trc");
  EXPECT_EQ(trc.rfind("PathFileType\t4\t(X/Y/Z)\ta.trc\n", 0), 0u);
  EXPECT_NE(trc.find("\tmm\t"), std::string::npos);
  EXPECT_NE(trc.find("\tleft_hand_index_pip\t"), std::string::npos);
}

TEST(C3dBytes, HeaderAndBlocks) {
  const ExportData d = RigidData(5);
  auto c3d = C3dBytes(d);
  ASSERT_TRUE(c3d.ok());
  ASSERT_EQ(c3d->size() % 512, 0u);
  EXPECT_EQ((*c3d)[0], 2);
  EXPECT_EQ(static_cast<unsigned char>((*c3d)[1]), 0x50);
  EXPECT_EQ(static_cast<unsigned char>((*c3d)[2]) | (static_cast<unsigned char>((*c3d)[3]) << 8),
            d.points());
  float scale;
  std::memcpy(&scale, c3d->data() + 12, 4);
  EXPECT_EQ(scale, -1.0f);
}

TEST(C3dBytes, RefusesMoreFramesThanTheHeaderHolds) {
  ExportData d;
  d.keypoint_names = {"nose"};
  d.points_mm.shape = {70000, 1, 3};
  d.points_mm.data.assign(70000 * 3, 1.0);
  auto c3d = C3dBytes(d);
  ASSERT_FALSE(c3d.ok());
  EXPECT_NE(c3d.status().message().find("70000 frames"), std::string::npos);
}

TEST(GlbBytes, MagicAndLength) {
  const ExportData d = RigidData(3);
  const std::string glb = GlbBytes(d);
  ASSERT_GE(glb.size(), 20u);
  EXPECT_EQ(glb.substr(0, 4), "glTF");
  uint32_t length;
  std::memcpy(&length, glb.data() + 8, 4);
  EXPECT_EQ(length, glb.size());
  EXPECT_NE(glb.find("\"left_hand_index_tip\""), std::string::npos);
}

TEST(ExportBvh, RigidMotionFitsExactly) {
  const ExportData d = RigidData(20);
  auto bvh = ExportBvh(d);
  ASSERT_TRUE(bvh.ok()) << bvh.status().message();
  EXPECT_LT(bvh->body_median_mm, 1e-6);
  EXPECT_LT(bvh->left_hand_median_mm, 1e-6);
  EXPECT_LT(bvh->right_hand_median_mm, 1e-6);
  for (const auto& r : bvh->residuals) EXPECT_LT(r.max_mm, 1e-6) << r.name;
  EXPECT_NE(bvh->text.find("JOINT left_hand_little_dip"), std::string::npos);
  EXPECT_NE(bvh->text.find("Frames: 20\n"), std::string::npos);
}

// `arco run` gives the arco method's body and right hand a skeleton of fixed bone lengths
// (body/skeleton_fit.h) on the BVH's own tree, so the BVH reproduces them exactly even
// when the triangulated points were noisy (their bones changing length by millimetres).
TEST(ExportBvh, SkeletonFittedPointsFitExactly) {
  ExportData d = RigidData(30);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 3.0);
  for (double& v : d.points_mm.data) v += noise(rng);
  const ExportData noisy = d;
  auto raw = ExportBvh(noisy);
  ASSERT_TRUE(raw.ok());
  EXPECT_GT(raw->body_median_mm, 1.0);  // noisy points: no fixed skeleton reproduces them
  EXPECT_GT(raw->right_hand_median_mm, 1.0);
  auto fit = body::FitSkeleton(d.points_mm, d.keypoint_names, {}, body::SkeletonFitOptions{});
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  d.points_mm = fit->points_mm;
  auto bvh = ExportBvh(d);
  ASSERT_TRUE(bvh.ok()) << bvh.status().message();
  EXPECT_LT(bvh->body_median_mm, 1e-6);
  EXPECT_LT(bvh->right_hand_median_mm, 1e-6);
  for (const auto& r : bvh->residuals) {
    if (r.name.rfind("left_hand_", 0) == 0)
      continue;  // noisy, not fitted: left to arco's hand model
    if (d.Find(r.name) >= wholebody::kNumPoints) continue;  // the instrument and bow
    EXPECT_LT(r.max_mm, 1e-6) << r.name;
  }
}

TEST(ExportBvh, NeedsTheHands) {
  ExportData d = RigidData(2);
  d.keypoint_names[d.Find("right_hand_thumb_tip")] = "something_else";
  auto bvh = ExportBvh(d);
  ASSERT_FALSE(bvh.ok());
  EXPECT_NE(bvh.status().message().find("right_hand_thumb_tip"), std::string::npos);
}

TEST(LoadExportData, MissingResultNamesTheFile) {
  ExportOptions o;
  o.result_dir = "/nonexistent/result";
  auto d = LoadExportData(o);
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.status().message().find("/nonexistent/result"), std::string::npos);
}

}  // namespace
}  // namespace arco::exporter

namespace arco::exporter {
namespace {

// One scene, two writers: the SVG names what the raster shows.
TEST(Plot, SvgAndRasterDrawTheSameScene) {
  PlotScene scene{"t", 400, 300, {}};
  PlotShape r;
  r.kind = PlotShape::Kind::kRect;
  r.points = {{100, 50}, {200, 90}};
  r.filled = true;
  r.fill = {10, 200, 30};
  r.outlined = false;
  r.css_class = "note";
  r.data = {{"name", "C#2"}};
  scene.shapes.push_back(r);
  PlotShape c;
  c.kind = PlotShape::Kind::kCircle;
  c.points = {{300, 200}};
  c.size = 9;
  c.filled = true;
  c.fill = {200, 0, 0};
  c.stroke = {200, 0, 0};
  scene.shapes.push_back(c);
  PlotShape t;
  t.kind = PlotShape::Kind::kText;
  t.points = {{20, 280}};
  t.text = "a<b & c";
  t.size = 14;
  scene.shapes.push_back(t);
  const std::string svg = PlotSvg(scene);
  EXPECT_NE(svg.find("<rect class=\"note\" data-name=\"C#2\" x=\"100.000\" y=\"50.000\" "
                     "width=\"100.000\" height=\"40.000\" fill=\"#0ac81e\""),
            std::string::npos)
      << svg;
  EXPECT_NE(svg.find("cx=\"300.000\" cy=\"200.000\" r=\"9\" fill=\"#c80000\""), std::string::npos);
  EXPECT_NE(svg.find(">a&lt;b &amp; c</text>"), std::string::npos);
  const media::Image png = RasterisePlot(scene);
  ASSERT_EQ(png.width, 400);
  ASSERT_EQ(png.height, 300);
  EXPECT_EQ(png.at(150, 70, 0), 10);  // the rectangle's fill
  EXPECT_EQ(png.at(150, 70, 1), 200);
  EXPECT_EQ(png.at(300, 200, 0), 200);  // the disc
  EXPECT_EQ(png.at(300, 200, 1), 0);
  EXPECT_EQ(png.at(5, 5, 0), 255);  // background
  int ink = 0;                      // the text is drawn near its anchor
  for (int y = 265; y < 285; ++y) {
    for (int x = 20; x < 90; ++x) ink += png.at(x, y, 0) < 128;
  }
  EXPECT_GT(ink, 20);
}

}  // namespace
}  // namespace arco::exporter
