// An ONNX graph converted by tools/tflite_onnx, run by XNNPACK (the CPU operator library
// TFLite itself runs MediaPipe's models with) instead of cv::dnn.
//
// Why: OpenCV 4.6's cv::dnn vectorises a depthwise convolution only with a 3 x 3 kernel
// and a wide output, and MediaPipe's landmarkers are mostly 5 x 5 depthwise layers;
// XNNPACK has kernels for every layer these models use (docs/detect.md, "XNNPACK runs the
// models").
//
// The ONNX graph is NCHW (ONNX's order); XNNPACK is NHWC. Each 4-D value is defined in
// XNNPACK as NHWC and the weights are reordered on load; a Transpose to NHWC (which the
// converter puts before a Reshape or at a 4-D output) becomes a no-op on that memory.
// Only the operators the converter emits for the eight models translate (Conv: dense or
// depthwise; Clip, Add, Pad, MaxPool, GlobalAveragePool, Flatten, Gemm, Sigmoid, PRelu,
// Resize (bilinear), DepthToSpace, Identity, Transpose to NHWC, Reshape, a Slice of the
// first channels, and a Concat computing an output); any other is an error naming it, and
// detect::Network then runs the model with cv::dnn.
//
// Threads: with num_threads 1 a forward pass runs on the calling thread only (arco detect
// parallelises over views and frames); more use a pool of the graph's own. XNNPACK
// computes every output element in one place, so the result does not depend on how the
// work is split (network_test.cc checks it bit for bit).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "arco/util/status.h"

namespace arco::detect {

class XnnpackGraph {
 public:
  // Checks the names of every output a graph declares, before it is translated.
  using OutputCheck = std::function<Status(const std::vector<std::string>& graph_outputs)>;

  // Reads `onnx_path`, passes its graph's output names to `check` (its error is returned
  // as it is), and builds the runtime for an NHWC float input of
  // 1 x input_height x input_width x 3 and the graph outputs named `output_names`, each
  // in TFLite's layout. An operator or attribute outside the supported set is an error
  // whose message names it (and the file).
  static StatusOr<std::unique_ptr<XnnpackGraph>> Load(const std::string& onnx_path,
                                                      const std::vector<std::string>& output_names,
                                                      int input_height,
                                                      int input_width,
                                                      int num_threads,
                                                      const OutputCheck& check);
  ~XnnpackGraph();
  XnnpackGraph(const XnnpackGraph&) = delete;
  XnnpackGraph& operator=(const XnnpackGraph&) = delete;

  // Runs one pass on `input_nhwc` (1 x H x W x 3 floats); outputs()[k] then holds output k.
  Status Run(const float* input_nhwc);
  const std::vector<std::vector<float>>& outputs() const { return outputs_; }

 private:
  struct Impl;
  XnnpackGraph();
  std::unique_ptr<Impl> impl_;
  std::vector<std::vector<float>> outputs_;
};

}  // namespace arco::detect
