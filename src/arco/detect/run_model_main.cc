// Test helper for tools/tflite_onnx/agreement_test.py, which compares cv::dnn with the
// numpy reference executor of the TFLite graph (the python side has no image decoder):
//
// detect_run_model MODEL INPUT.npy OUT_DIR [THREADS [RUNTIME]]
//   runs one registry model's ONNX file (models folder: $ARCO_MODELS_DIR or the default)
//   on an NHWC float32 input of shape (1, H, W, 3) with RUNTIME (auto, xnnpack, opencv;
//   default auto); writes OUT_DIR/<output name>.npy and OUT_DIR/runtime.txt (the runtime
//   that ran it).
// detect_run_model crop IMAGE CX CY SIDE_PX ANGLE_DEG SIZE RANGE OUT.npy [OUT.png]
//   writes the square crop of side SIDE_PX centred on (CX, CY), rotated by ANGLE_DEG
//   (counter-clockwise, so the crop's up is the image's direction rotated by it), resized
//   to SIZE x SIZE with bilinear interpolation and black outside the image, as a
//   (1, SIZE, SIZE, 3) float32 RGB array in RANGE ("0,1" or "-1,1").
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "arco/detect/network.h"
#include "arco/util/npy.h"

namespace {

int Crop(int argc, char** argv) {
  using namespace arco;
  if (argc != 10 && argc != 11) {
    std::fprintf(stderr,
                 "usage: detect_run_model crop IMAGE CX CY SIDE_PX ANGLE_DEG SIZE RANGE OUT.npy "
                 "[OUT.png]\n");
    return 2;
  }
  const cv::Mat bgr = cv::imread(argv[2], cv::IMREAD_COLOR);
  if (bgr.empty()) {
    std::fprintf(stderr, "detect_run_model: error: %s: cannot read the image\n", argv[2]);
    return 1;
  }
  const double cx = std::stod(argv[3]), cy = std::stod(argv[4]), side = std::stod(argv[5]);
  const double angle_deg = std::stod(argv[6]);
  const int size = std::stoi(argv[7]);
  const std::string range = argv[8];
  // Maps the crop's pixel centres onto the image: scale, rotate about the crop centre.
  cv::Mat to_crop = cv::getRotationMatrix2D(
      cv::Point2f(static_cast<float>(cx), static_cast<float>(cy)), -angle_deg, size / side);
  to_crop.at<double>(0, 2) += size / 2.0 - cx;
  to_crop.at<double>(1, 2) += size / 2.0 - cy;
  // Pixel centres (docs/architecture.md): the crop covers SIDE_PX around (CX, CY), so
  // crop pixel u has its centre at CX + (u + 0.5 - SIZE / 2) * SIDE_PX / SIZE.
  to_crop.at<double>(0, 2) -= 0.5;
  to_crop.at<double>(1, 2) -= 0.5;
  cv::Mat crop;
  cv::warpAffine(bgr,
                 crop,
                 to_crop,
                 cv::Size(size, size),
                 cv::INTER_LINEAR,
                 cv::BORDER_CONSTANT,
                 cv::Scalar(0, 0, 0));
  if (argc == 11) cv::imwrite(argv[10], crop);
  NpyArray<float> out;
  out.shape = {1, size, size, 3};
  out.data.resize(static_cast<size_t>(size) * size * 3);
  const bool signed_range = range == "-1,1";
  if (!signed_range && range != "0,1") {
    std::fprintf(stderr, "detect_run_model: error: RANGE must be 0,1 or -1,1\n");
    return 2;
  }
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const cv::Vec3b p = crop.at<cv::Vec3b>(y, x);
      for (int c = 0; c < 3; ++c) {
        const float v = p[2 - c];  // BGR -> RGB
        out.data[(static_cast<size_t>(y) * size + x) * 3 + c] =
            signed_range ? v / 127.5f - 1.0f : v / 255.0f;
      }
    }
  }
  Status written = WriteNpy(argv[9], out);
  if (!written.ok()) {
    std::fprintf(stderr, "detect_run_model: error: %s\n", written.message().c_str());
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace arco;
  if (argc >= 2 && std::string(argv[1]) == "crop") return Crop(argc, argv);
  if (argc < 4 || argc > 6) {
    std::fprintf(stderr, "usage: detect_run_model MODEL INPUT.npy OUT_DIR [THREADS [RUNTIME]]\n");
    return 2;
  }
  auto fail = [](const Status& status) {
    std::fprintf(stderr, "detect_run_model: error: %s\n", status.message().c_str());
    return 1;
  };
  StatusOr<detect::ModelId> id = detect::ParseModelName(argv[1]);
  if (!id.ok()) return fail(id.status());
  detect::NetworkOptions options;
  if (argc >= 5) options.num_threads = std::stoi(argv[4]);
  if (argc == 6) {
    StatusOr<detect::InferenceRuntime> runtime = detect::ParseInferenceRuntime(argv[5]);
    if (!runtime.ok()) return fail(runtime.status());
    options.runtime = *runtime;
  }
  StatusOr<detect::Network> network =
      detect::Network::Load(*id, detect::DefaultModelsDir(), options);
  if (!network.ok()) return fail(network.status());
  StatusOr<NpyArray<float>> input = ReadNpy<float>(argv[2]);
  if (!input.ok()) return fail(input.status());
  const detect::ModelInfo& info = network->info();
  if (input->shape != std::vector<int64_t>{1, info.input_height, info.input_width, 3}) {
    return fail(Status::Error(std::string(argv[2]) + ": expected shape (1, " +
                              std::to_string(info.input_height) + ", " +
                              std::to_string(info.input_width) + ", 3)"));
  }
  Status run = network->Run(input->data.data(), input->data.size());
  if (!run.ok()) return fail(run);
  for (size_t k = 0; k < info.outputs.size(); ++k) {
    const detect::Tensor& tensor = network->outputs()[k];
    NpyArray<float> out;
    out.shape.assign(tensor.shape.begin(), tensor.shape.end());
    out.data = tensor.data;
    Status written = WriteNpy(std::string(argv[3]) + "/" + info.outputs[k].name + ".npy", out);
    if (!written.ok()) return fail(written);
  }
  std::FILE* f = std::fopen((std::string(argv[3]) + "/runtime.txt").c_str(), "w");
  if (f == nullptr) return fail(Status::Error(std::string(argv[3]) + "/runtime.txt: cannot write"));
  std::fprintf(f, "%s\n", network->runtime_name());
  std::fclose(f);
  return 0;
}
