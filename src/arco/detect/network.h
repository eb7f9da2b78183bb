// One pretrained network (detect/model_registry.h) run on the CPU by XNNPACK
// (detect/xnnpack_graph.h) or by OpenCV's cv::dnn.
//
// Runtime: by default (kAuto) a graph XNNPACK can run (every model arco converts) is run
// by XNNPACK, faster than cv::dnn and bit-exact for any thread count (docs/detect.md,
// "XNNPACK runs the models"); a graph with an operator the translation lacks by cv::dnn.
// runtime_name() says which.
//
// Load once (reading and preparing the graph is the expensive part), then Run per crop;
// Run writes into output tensors owned by the Network, so the per-crop call allocates
// nothing of ours. OpenCV stays out of this header.
//
// Threads: cv::dnn parallelises inside each layer with OpenCV's thread pool, whose size
// is process-wide (cv::setNumThreads). Run sets it to NetworkOptions::num_threads before
// every forward pass, so the count is always explicit; outputs are the same for any
// count (network_test.cc checks it bit for bit).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "arco/detect/model_registry.h"
#include "arco/util/status.h"

namespace arco::detect {

enum class InferenceRuntime {
  kAuto,     // XNNPACK where the graph translates, else cv::dnn
  kXnnpack,  // XNNPACK only: a graph it cannot run is an error
  kOpenCv,   // cv::dnn only
};

// "auto", "xnnpack", "opencv" (arco detect's --inference).
StatusOr<InferenceRuntime> ParseInferenceRuntime(const std::string& name);
const char* InferenceRuntimeName(InferenceRuntime runtime);

struct NetworkOptions {
  int num_threads = 1;  // threads of one forward pass (cv::dnn's: process-wide); >= 1
  InferenceRuntime runtime = InferenceRuntime::kAuto;
  Status Validate() const;
};

// A dense float tensor, C order.
struct Tensor {
  std::vector<int> shape;
  std::vector<float> data;
};

enum class TensorLayout {
  kNhwc,  // 1 x H x W x 3 (TFLite's order, and an RGB image's)
  kNchw,  // 1 x 3 x H x W (the ONNX graph's)
};

class Network {
 public:
  // Loads models_dir/NAME.onnx. A missing file is one line naming it and pointing to
  // scripts/setup; an unreadable or wrong graph names the file and OpenCV's reason.
  static StatusOr<Network> Load(ModelId id,
                                const std::string& models_dir = DefaultModelsDir(),
                                const NetworkOptions& options = {});
  // Loads `path` as the network `id` describes (its outputs are checked on load).
  static StatusOr<Network> LoadFile(ModelId id,
                                    const std::string& path,
                                    const NetworkOptions& options = {});

  Network(Network&&) noexcept;
  Network& operator=(Network&&) noexcept;
  ~Network();

  const ModelInfo& info() const { return *info_; }
  const std::string& path() const { return path_; }
  // "xnnpack" or "opencv": the runtime that runs this network.
  const char* runtime_name() const;

  // Runs one crop: 3 * input_height * input_width floats in `layout`, values already in
  // info().range. Throws std::invalid_argument on a wrong size; a failure inside
  // cv::dnn is returned as a Status naming the file.
  Status Run(const float* input, size_t input_size, TensorLayout layout = TensorLayout::kNhwc);

  // The outputs of the last Run, in info().outputs order, TFLite shapes.
  const std::vector<Tensor>& outputs() const { return outputs_; }
  // Output by arco's name ("landmarks"); throws std::invalid_argument if unknown.
  const Tensor& output(const std::string& name) const;

 private:
  struct Impl;
  Network(const ModelInfo& info,
          std::string path,
          NetworkOptions options,
          std::unique_ptr<Impl> impl);

  const ModelInfo* info_;
  std::string path_;
  NetworkOptions options_;
  std::unique_ptr<Impl> impl_;
  std::vector<Tensor> outputs_;
  std::vector<float> nhwc_;  // an NCHW input reordered for XNNPACK
};

}  // namespace arco::detect
