#include "arco/detect/network.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <string>
#include <vector>

#include "arco/detect/models_for_test.h"
#include "arco/testing/temp_dir.h"
#include "onnx/onnx_pb.h"

namespace arco::detect {
namespace {

TEST(NetworkLoad, MissingFileNamesItAndScriptsSetup) {
  StatusOr<Network> network = Network::Load(ModelId::kPoseDetection, "/nonexistent/models");
  ASSERT_FALSE(network.ok());
  EXPECT_EQ(network.status().message(),
            "/nonexistent/models/pose_detection.onnx: model file not found; run "
            "scripts/setup to fetch and convert the models (docs/detect.md)");
}

TEST(NetworkLoad, CorruptFileNamesIt) {
  const arco::testing::TempDir temp;
  const std::string& dir = temp.path();
  const std::string path = dir + "/hand_recrop.onnx";
  std::ofstream(path) << "not an onnx model";
  StatusOr<Network> network = Network::Load(ModelId::kHandRecrop, dir);
  ASSERT_FALSE(network.ok());
  EXPECT_EQ(network.status().message().rfind(path + ": cannot read the ONNX model", 0), 0u)
      << network.status().message();
  EXPECT_NE(network.status().message().find("scripts/setup"), std::string::npos);
}

TEST(NetworkLoad, CorruptFileNamesItWithEitherRuntime) {
  const arco::testing::TempDir temp;
  const std::string path = temp.path() + "/hand_landmark_full.onnx";
  std::ofstream(path) << "not an onnx model";
  for (InferenceRuntime runtime : {InferenceRuntime::kXnnpack, InferenceRuntime::kOpenCv}) {
    NetworkOptions options;
    options.runtime = runtime;
    StatusOr<Network> network = Network::Load(ModelId::kHandLandmarkFull, temp.path(), options);
    ASSERT_FALSE(network.ok());
    EXPECT_EQ(network.status().message().rfind(path + ": cannot read the ONNX model", 0), 0u)
        << network.status().message();
    EXPECT_NE(network.status().message().find("scripts/setup"), std::string::npos);
  }
}

// A graph of hand_recrop's input and output with an operator the XNNPACK translation does
// not take (Softmax): input -> GlobalAveragePool -> 1 x 1 Conv to 4 channels -> Softmax ->
// Transpose to NHWC.
void WriteSoftmaxGraph(const std::string& path) {
  onnx::ModelProto model;
  model.set_ir_version(7);
  model.add_opset_import()->set_version(11);
  onnx::GraphProto* g = model.mutable_graph();
  g->set_name("softmax");
  const auto value = [](onnx::ValueInfoProto* v, const std::string& name, std::vector<int> dims) {
    v->set_name(name);
    onnx::TypeProto_Tensor* t = v->mutable_type()->mutable_tensor_type();
    t->set_elem_type(onnx::TensorProto::FLOAT);
    for (int d : dims) t->mutable_shape()->add_dim()->set_dim_value(d);
  };
  value(g->add_input(), "input", {1, 3, 256, 256});
  value(g->add_output(), "output_crop", {1, 1, 1, 4});
  onnx::TensorProto* w = g->add_initializer();
  w->set_name("w");
  w->set_data_type(onnx::TensorProto::FLOAT);
  for (int d : {4, 3, 1, 1}) w->add_dims(d);
  for (int k = 0; k < 12; ++k) w->add_float_data(0.1f * static_cast<float>(k % 5) - 0.2f);
  const auto node =
      [&](const std::string& op, std::vector<std::string> in, const std::string& out) {
        onnx::NodeProto* n = g->add_node();
        n->set_op_type(op);
        n->set_name(op);
        for (const std::string& i : in) n->add_input(i);
        n->add_output(out);
        return n;
      };
  node("GlobalAveragePool", {"input"}, "pooled");
  onnx::AttributeProto* kernel = node("Conv", {"pooled", "w"}, "logits")->add_attribute();
  kernel->set_name("kernel_shape");
  kernel->set_type(onnx::AttributeProto::INTS);
  for (int k : {1, 1}) kernel->add_ints(k);
  onnx::AttributeProto* axis = node("Softmax", {"logits"}, "soft")->add_attribute();
  axis->set_name("axis");
  axis->set_type(onnx::AttributeProto::INT);
  axis->set_i(1);
  onnx::AttributeProto* perm = node("Transpose", {"soft"}, "output_crop")->add_attribute();
  perm->set_name("perm");
  perm->set_type(onnx::AttributeProto::INTS);
  for (int p : {0, 2, 3, 1}) perm->add_ints(p);
  std::ofstream out(path, std::ios::binary);
  ASSERT_TRUE(model.SerializeToOstream(&out));
}

// Asked for XNNPACK, a graph it cannot run is an error naming the file and the operator; by
// default (auto) cv::dnn runs it. Every converted model runs on XNNPACK by default.
TEST(NetworkLoad, AGraphXnnpackCannotRunNamesTheOperatorOrFallsBack) {
  const arco::testing::TempDir temp;
  const std::string path = ModelPath(ModelId::kHandRecrop, temp.path());
  WriteSoftmaxGraph(path);
  NetworkOptions options;
  options.runtime = InferenceRuntime::kXnnpack;
  StatusOr<Network> strict = Network::Load(ModelId::kHandRecrop, temp.path(), options);
  ASSERT_FALSE(strict.ok());
  EXPECT_EQ(strict.status().message(), path + ": operator Softmax 'Softmax' is not supported");
  StatusOr<Network> automatic = Network::Load(ModelId::kHandRecrop, temp.path());
  ASSERT_TRUE(automatic.ok()) << automatic.status().message();
  EXPECT_STREQ(automatic->runtime_name(), "opencv");
  const std::vector<float> input(3 * 256 * 256, 0.5f);
  ASSERT_TRUE(automatic->Run(input.data(), input.size()).ok());
  float sum = 0;
  for (float v : automatic->output("crop").data) sum += v;
  EXPECT_NEAR(sum, 1.0f, 1e-5f);
  ARCO_REQUIRE_MODELS();
  for (const ModelInfo& info : AllModels()) {
    StatusOr<Network> network = Network::Load(info.id, DefaultModelsDir());
    ASSERT_TRUE(network.ok()) << network.status().message();
    EXPECT_STREQ(network->runtime_name(), "xnnpack") << info.name;
  }
}

TEST(InferenceRuntime, NamesParse) {
  for (InferenceRuntime r :
       {InferenceRuntime::kAuto, InferenceRuntime::kXnnpack, InferenceRuntime::kOpenCv}) {
    StatusOr<InferenceRuntime> parsed = ParseInferenceRuntime(InferenceRuntimeName(r));
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(*parsed, r);
  }
  EXPECT_EQ(ParseInferenceRuntime("tflite").status().message(),
            "unknown inference runtime 'tflite' (auto, xnnpack or opencv)");
}

TEST(NetworkOptions, RejectsZeroThreads) {
  NetworkOptions options;
  options.num_threads = 0;
  EXPECT_FALSE(options.Validate().ok());
  StatusOr<Network> network = Network::Load(ModelId::kHandRecrop, "/nonexistent", options);
  ASSERT_FALSE(network.ok());
  EXPECT_NE(network.status().message().find("num_threads"), std::string::npos);
}

TEST(ModelRegistry, NamesAreUniqueAndParse) {
  std::set<std::string> names;
  for (const ModelInfo& info : AllModels()) {
    EXPECT_TRUE(names.insert(info.name).second) << info.name;
    StatusOr<ModelId> id = ParseModelName(info.name);
    ASSERT_TRUE(id.ok());
    EXPECT_EQ(&GetModelInfo(*id), &info);
    EXPECT_GT(info.input_width, 0);
    EXPECT_FALSE(info.outputs.empty());
    EXPECT_EQ(ModelPath(info.id, "/m"), std::string("/m/") + info.name + ".onnx");
  }
  EXPECT_EQ(names.size(), 8u);
  StatusOr<ModelId> bad = ParseModelName("pose_landmark_huge");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("pose_landmark_heavy"), std::string::npos);
  EXPECT_THROW(GetModelInfo(ModelId::kHandLandmarkFull).OutputIndex("boxes"),
               std::invalid_argument);
}

// A square crop of `image` (RGB, float 0..255) of side `side_px` centred on `centre`,
// turned so that the image direction `up` points up in the crop, resized to `size`,
// as NHWC floats in `range`. Pixel centres as in docs/architecture.md.
struct Crop {
  cv::Point2d centre, up, right;
  double side_px = 0;
  int size = 0;
  // The image point of normalised crop coordinates (0..1, x right, y down).
  cv::Point2d ToImage(double x_norm, double y_norm) const {
    return centre + (x_norm - 0.5) * side_px * right - (y_norm - 0.5) * side_px * up;
  }
};

Crop MakeCrop(cv::Point2d centre, cv::Point2d up, double side_px, int size) {
  Crop crop;
  crop.centre = centre;
  crop.up = up / std::hypot(up.x, up.y);
  crop.right = cv::Point2d(-crop.up.y, crop.up.x);
  crop.side_px = side_px;
  crop.size = size;
  return crop;
}

std::vector<float> CutCrop(const cv::Mat& rgb, const Crop& crop, ValueRange range) {
  const double s = crop.side_px / crop.size;
  // Crop pixel (u, v) -> image point, for WARP_INVERSE_MAP.
  const cv::Point2d origin = crop.ToImage(0.5 / crop.size, 0.5 / crop.size);
  cv::Mat to_image = (cv::Mat_<double>(2, 3) << s * crop.right.x,
                      -s * crop.up.x,
                      origin.x,
                      s * crop.right.y,
                      -s * crop.up.y,
                      origin.y);
  cv::Mat out;
  cv::warpAffine(rgb,
                 out,
                 to_image,
                 cv::Size(crop.size, crop.size),
                 cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                 cv::BORDER_CONSTANT,
                 cv::Scalar::all(0));
  std::vector<float> data(static_cast<size_t>(crop.size) * crop.size * 3);
  for (int y = 0; y < crop.size; ++y) {
    const cv::Vec3f* row = out.ptr<cv::Vec3f>(y);
    for (int x = 0; x < crop.size; ++x) {
      for (int c = 0; c < 3; ++c) {
        const float v = row[x][c];
        data[(static_cast<size_t>(y) * crop.size + x) * 3 + c] =
            range == ValueRange::kZeroToOne ? v / 255.0f : v / 127.5f - 1.0f;
      }
    }
  }
  return data;
}

cv::Mat ReadRgb(const std::string& path) {
  cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
  cv::Mat rgb;
  if (bgr.empty()) return rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  rgb.convertTo(rgb, CV_32FC3);
  return rgb;
}

double Sigmoid(double x) { return 1.0 / (1.0 + std::exp(-x)); }

// SSD anchor centres of pose_detection (224 input): strides 8, 16, 32 with 2, 2, 6
// anchors per cell, rows then columns then anchors.
std::vector<cv::Point2d> PoseDetectionAnchors() {
  std::vector<cv::Point2d> anchors;
  const int strides[] = {8, 16, 32};
  const int per_cell[] = {2, 2, 6};
  for (int layer = 0; layer < 3; ++layer) {
    const int grid = 224 / strides[layer];
    for (int y = 0; y < grid; ++y) {
      for (int x = 0; x < grid; ++x) {
        for (int k = 0; k < per_cell[layer]; ++k) {
          anchors.emplace_back((x + 0.5) / grid, (y + 0.5) / grid);
        }
      }
    }
  }
  return anchors;
}

// The real-content chain on a real SPD frame of a cellist: pose detection on the
// whole frame, pose landmarks in the ROI it gives, and the left hand's landmarks in a
// crop derived from the pose's left wrist, index and little-finger points (as MediaPipe
// Holistic does). docs/detect.md quotes the figures.
TEST(NetworkRealImage, CellistPoseAndLeftHand) {
  ARCO_REQUIRE_MODELS();
  const cv::Mat image = ReadRgb(ARCO_SHARED_DATA_DIR "/spd/example.jpg");
  ASSERT_FALSE(image.empty());
  NetworkOptions options;
  options.num_threads = 2;

  // 1. Person detection on the whole frame, letterboxed into a square.
  StatusOr<Network> detector = Network::Load(ModelId::kPoseDetection, DefaultModelsDir(), options);
  ASSERT_TRUE(detector.ok()) << detector.status().message();
  const double side = std::max(image.cols, image.rows);
  const Crop whole = MakeCrop({(image.cols - 1) / 2.0, (image.rows - 1) / 2.0}, {0, -1}, side, 224);
  const std::vector<float> whole_input = CutCrop(image, whole, detector->info().range);
  ASSERT_TRUE(detector->Run(whole_input.data(), whole_input.size()).ok());
  const std::vector<cv::Point2d> anchors = PoseDetectionAnchors();
  const Tensor& boxes = detector->output("boxes");
  const Tensor& scores = detector->output("scores");
  ASSERT_EQ(anchors.size(), scores.data.size());
  size_t best = 0;
  for (size_t i = 1; i < scores.data.size(); ++i) {
    if (scores.data[i] > scores.data[best]) best = i;
  }
  const double score = Sigmoid(scores.data[best]);
  const float* raw = &boxes.data[best * 12];
  auto keypoint = [&](int k) {
    return whole.ToImage(raw[4 + 2 * k] / 224.0 + anchors[best].x,
                         raw[5 + 2 * k] / 224.0 + anchors[best].y);
  };
  const cv::Point2d box_centre =
      whole.ToImage(raw[0] / 224.0 + anchors[best].x, raw[1] / 224.0 + anchors[best].y);
  std::printf("pose_detection: score %.3f, box centre (%.0f, %.0f) px\n",
              score,
              box_centre.x,
              box_centre.y);
  EXPECT_GT(score, 0.5);
  // The detector's box is the player's face and upper body: in the middle of the frame
  // (the cello's labelled box is x 819..1784, y 518..2465 in example.json).
  EXPECT_GT(box_centre.x, 800);
  EXPECT_LT(box_centre.x, 1800);
  EXPECT_GT(box_centre.y, 500);
  EXPECT_LT(box_centre.y, 2400);

  // 2. Pose landmarks in the ROI of keypoints 0 (hip centre) and 1 (the full-body
  // circle's edge): centred on the hips, side 2 * 1.25 * radius, turned hips -> head.
  const cv::Point2d hip = keypoint(0), top = keypoint(1);
  const cv::Point2d hip_to_top = top - hip;
  const double radius = std::hypot(hip_to_top.x, hip_to_top.y);
  const Crop body = MakeCrop(hip, hip_to_top, 2.5 * radius, 256);
  StatusOr<Network> pose = Network::Load(ModelId::kPoseLandmarkFull, DefaultModelsDir(), options);
  ASSERT_TRUE(pose.ok()) << pose.status().message();
  const std::vector<float> body_input = CutCrop(image, body, pose->info().range);
  ASSERT_TRUE(pose->Run(body_input.data(), body_input.size()).ok());
  const double pose_presence = pose->output("presence").data[0];
  std::printf("pose_landmark_full: presence %.3f\n", pose_presence);
  EXPECT_GT(pose_presence, 0.9);
  const std::vector<float>& landmarks = pose->output("landmarks").data;
  auto body_point = [&](int i) {
    return body.ToImage(landmarks[5 * i] / 256.0, landmarks[5 * i + 1] / 256.0);
  };

  // 3. The left hand (MediaPipe's 15 left wrist, 17 left pinky, 19 left index): the
  // middle finger's base estimated as (2 index + pinky) / 3 (the pose's hand points sit
  // near the knuckles), the crop centred on it with a side of 4 wrist-to-middle
  // lengths, turned so that wrist -> middle finger points up.
  const cv::Point2d wrist = body_point(15), pinky = body_point(17), index = body_point(19);
  const cv::Point2d middle = (2.0 * index + pinky) / 3.0;
  const cv::Point2d wrist_to_middle = middle - wrist;
  const double length = std::hypot(wrist_to_middle.x, wrist_to_middle.y);
  std::printf("left wrist (%.0f, %.0f), middle finger (%.0f, %.0f) px\n",
              wrist.x,
              wrist.y,
              middle.x,
              middle.y);
  // On the fingerboard: right of the neck line, between the scroll and the bridge.
  EXPECT_GT(wrist.x, 1150);
  EXPECT_GT(middle.y, 535);
  EXPECT_LT(middle.y, 1610);
  const Crop hand = MakeCrop(middle, wrist_to_middle, 4.0 * length, 224);
  StatusOr<Network> hand_net =
      Network::Load(ModelId::kHandLandmarkFull, DefaultModelsDir(), options);
  ASSERT_TRUE(hand_net.ok()) << hand_net.status().message();
  const std::vector<float> hand_input = CutCrop(image, hand, hand_net->info().range);
  ASSERT_TRUE(hand_net->Run(hand_input.data(), hand_input.size()).ok());
  const double hand_presence = hand_net->output("presence").data[0];
  std::printf("hand_landmark_full: presence %.3f\n", hand_presence);
  EXPECT_GT(hand_presence, 0.9);

  // The four fingertips (hand points 8, 12, 16, 20) press the strings: on the
  // fingerboard, near the line from the nut's centre to the neck's lower end (labelled
  // in example.json), and between them along it; 40 px is about the fingerboard's
  // width here (37 px at the nut, 62 px at the neck's end).
  const cv::Point2d nut = 0.5 * (cv::Point2d(1205.3, 734.8) + cv::Point2d(1242.0, 731.3));
  const cv::Point2d neck_bottom = 0.5 * (cv::Point2d(1140.2, 1102.3) + cv::Point2d(1201.8, 1104.6));
  const cv::Point2d along =
      (neck_bottom - nut) / std::hypot(neck_bottom.x - nut.x, neck_bottom.y - nut.y);
  const double neck_length = std::hypot(neck_bottom.x - nut.x, neck_bottom.y - nut.y);
  const std::vector<float>& hand_points = hand_net->output("landmarks").data;
  for (int tip : {8, 12, 16, 20}) {
    const cv::Point2d p =
        hand.ToImage(hand_points[3 * tip] / 224.0, hand_points[3 * tip + 1] / 224.0);
    const cv::Point2d d = p - nut;
    const double t = d.x * along.x + d.y * along.y;
    const double off_line = std::abs(d.x * along.y - d.y * along.x);
    std::printf(
        "fingertip %d: (%.0f, %.0f) px, %.2f of the way nut -> neck end, %.0f px off the line\n",
        tip,
        p.x,
        p.y,
        t / neck_length,
        off_line);
    EXPECT_GT(t, 0.0) << tip;
    EXPECT_LT(t, neck_length) << tip;
    EXPECT_LT(off_line, 40.0) << tip;
  }

  // hand_recrop on the same pose-derived crop (256 px): its two points (the refined
  // crop's centre and a point on its edge, crop pixels) must stay on this hand.
  StatusOr<Network> recrop = Network::Load(ModelId::kHandRecrop, DefaultModelsDir(), options);
  ASSERT_TRUE(recrop.ok()) << recrop.status().message();
  const Crop recrop_roi = MakeCrop(middle, wrist_to_middle, 4.0 * length, 256);
  const std::vector<float> recrop_input = CutCrop(image, recrop_roi, recrop->info().range);
  ASSERT_TRUE(recrop->Run(recrop_input.data(), recrop_input.size()).ok());
  const std::vector<float>& refined = recrop->output("crop").data;
  const cv::Point2d refined_centre = recrop_roi.ToImage(refined[0] / 256.0, refined[1] / 256.0);
  const cv::Point2d refined_edge = recrop_roi.ToImage(refined[2] / 256.0, refined[3] / 256.0);
  const cv::Point2d hand_middle = 0.5 * (wrist + middle);
  const cv::Point2d centre_offset = refined_centre - hand_middle;
  const cv::Point2d half_side = refined_edge - refined_centre;
  std::printf(
      "hand_recrop: centre (%.0f, %.0f) px, %.2f hand lengths from the hand's middle, "
      "half side %.2f hand lengths\n",
      refined_centre.x,
      refined_centre.y,
      std::hypot(centre_offset.x, centre_offset.y) / length,
      std::hypot(half_side.x, half_side.y) / length);
  EXPECT_LT(std::hypot(centre_offset.x, centre_offset.y), length);
  EXPECT_GT(std::hypot(half_side.x, half_side.y), 0.5 * length);
  EXPECT_LT(std::hypot(half_side.x, half_side.y), 4.0 * length);

  // A crop of the same size on the carpet, far from the player, holds no hand (every
  // test can fail).
  const Crop floor = MakeCrop({300, 2400}, {0, -1}, 4.0 * length, 224);
  const std::vector<float> floor_input = CutCrop(image, floor, hand_net->info().range);
  ASSERT_TRUE(hand_net->Run(floor_input.data(), floor_input.size()).ok());
  std::printf("hand_landmark_full on the carpet: presence %.3f\n",
              hand_net->output("presence").data[0]);
  EXPECT_LT(hand_net->output("presence").data[0], 0.5);
}

// Same outputs, bit for bit, for 1, 2 and 3 threads (XNNPACK) or 1 and 2 (cv::dnn: with 3
// its hand_landmark_full differs in the last bits), and for NHWC and NCHW input; and the
// two runtimes agree with each other (both also agree with the TFLite reference:
// tools/tflite_onnx/agreement_test.py).
TEST(NetworkRun, DeterministicAcrossThreadsAndLayouts) {
  ARCO_REQUIRE_MODELS();
  const cv::Mat image = ReadRgb(ARCO_SHARED_DATA_DIR "/spd/example.jpg");
  ASSERT_FALSE(image.empty());
  struct Case {
    ModelId model;
    Crop crop;
  };
  const Case cases[] = {{ModelId::kPoseLandmarkLite, MakeCrop({1150, 1350}, {0, -1}, 2200, 256)},
                        {ModelId::kHandLandmarkFull, MakeCrop({1150, 1350}, {0, -1}, 2200, 224)}};
  for (const Case& c : cases) {
    const ModelInfo& info = GetModelInfo(c.model);
    const std::vector<float> input = CutCrop(image, c.crop, info.range);
    std::vector<float> nchw(input.size());
    const size_t plane = static_cast<size_t>(info.input_width) * info.input_height;
    for (size_t i = 0; i < plane; ++i) {
      for (size_t ch = 0; ch < 3; ++ch) nchw[ch * plane + i] = input[3 * i + ch];
    }
    std::vector<std::vector<Tensor>> by_runtime;
    for (InferenceRuntime runtime : {InferenceRuntime::kXnnpack, InferenceRuntime::kOpenCv}) {
      std::vector<std::vector<Tensor>> results;
      for (int threads : {1, 2, 3}) {
        if (runtime == InferenceRuntime::kOpenCv && threads == 3) continue;
        NetworkOptions options;
        options.num_threads = threads;
        options.runtime = runtime;
        StatusOr<Network> network = Network::Load(c.model, DefaultModelsDir(), options);
        ASSERT_TRUE(network.ok()) << network.status().message();
        EXPECT_STREQ(network->runtime_name(), InferenceRuntimeName(runtime));
        ASSERT_TRUE(network->Run(input.data(), input.size()).ok());
        results.push_back(network->outputs());
        ASSERT_TRUE(network->Run(nchw.data(), nchw.size(), TensorLayout::kNchw).ok());
        results.push_back(network->outputs());
        EXPECT_THROW((void)network->Run(input.data(), input.size() - 1), std::invalid_argument);
      }
      for (size_t r = 1; r < results.size(); ++r) {
        for (size_t k = 0; k < results[0].size(); ++k) {
          EXPECT_EQ(results[r][k].data, results[0][k].data)
              << info.name << " " << InferenceRuntimeName(runtime) << " run " << r << " output "
              << k;
        }
      }
      by_runtime.push_back(results[0]);
    }
    for (size_t k = 0; k < by_runtime[0].size(); ++k) {
      const std::vector<float>& a = by_runtime[0][k].data;
      const std::vector<float>& b = by_runtime[1][k].data;
      ASSERT_EQ(a.size(), b.size());
      float scale = 1e-6f, worst = 0;
      for (size_t i = 0; i < a.size(); ++i) {
        scale = std::max(scale, std::abs(b[i]));
        worst = std::max(worst, std::abs(a[i] - b[i]));
      }
      // The agreement test's tolerance against the TFLite reference (docs/detect.md).
      EXPECT_LE(worst / scale, 2e-4f) << info.name << " output " << k;
    }
  }
}

}  // namespace
}  // namespace arco::detect
