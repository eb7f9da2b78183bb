#include "arco/detect/network.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <stdexcept>
#include <system_error>

#include "arco/detect/xnnpack_graph.h"

namespace arco::detect {

struct Network::Impl {
  std::unique_ptr<XnnpackGraph> xnnpack;  // set: XNNPACK runs the network, else cv::dnn
  cv::dnn::Net net;
  std::vector<cv::String> onnx_names;
  cv::Mat blob;  // 1 x 3 x H x W input, allocated once
  std::vector<cv::Mat> results;
};

StatusOr<InferenceRuntime> ParseInferenceRuntime(const std::string& name) {
  if (name == "auto") return InferenceRuntime::kAuto;
  if (name == "xnnpack") return InferenceRuntime::kXnnpack;
  if (name == "opencv") return InferenceRuntime::kOpenCv;
  return Status::Error("unknown inference runtime '" + name + "' (auto, xnnpack or opencv)");
}

const char* InferenceRuntimeName(InferenceRuntime runtime) {
  switch (runtime) {
    case InferenceRuntime::kXnnpack:
      return "xnnpack";
    case InferenceRuntime::kOpenCv:
      return "opencv";
    case InferenceRuntime::kAuto:
      break;
  }
  return "auto";
}

Status NetworkOptions::Validate() const {
  if (num_threads < 1) {
    return Status::Error("NetworkOptions.num_threads must be >= 1, got " +
                         std::to_string(num_threads));
  }
  return Status::Ok();
}

namespace {

// The graph computes every output arco reads and no other. A graph with heads arco does not
// read (a conversion before tools/tflite_onnx kept only the read outputs) computes them on
// every frame: cv::dnn runs every layer up to the last requested one. Refused, so a stale
// models folder is converted again, not silently slow.
Status CheckOutputs(const std::string& path,
                    const ModelInfo& info,
                    const std::vector<std::string>& graph_outputs) {
  for (const ModelOutput& output : info.outputs) {
    if (std::find(graph_outputs.begin(), graph_outputs.end(), output.onnx_name) ==
        graph_outputs.end()) {
      return Status::Error(path + ": the model has no output '" + output.onnx_name + "' (" +
                           info.name + "'s " + output.name +
                           "); run scripts/setup to convert it again");
    }
  }
  std::string extra;
  for (const std::string& name : graph_outputs) {
    bool read = false;
    for (const ModelOutput& output : info.outputs) read = read || name == output.onnx_name;
    if (!read) extra += (extra.empty() ? "'" : ", '") + name + "'";
  }
  if (!extra.empty()) {
    return Status::Error(path + ": the model computes outputs arco does not read (" + extra +
                         "); run scripts/setup to convert it again");
  }
  return Status::Ok();
}

}  // namespace

StatusOr<Network> Network::Load(ModelId id,
                                const std::string& models_dir,
                                const NetworkOptions& options) {
  return LoadFile(id, ModelPath(id, models_dir), options);
}

StatusOr<Network> Network::LoadFile(ModelId id,
                                    const std::string& path,
                                    const NetworkOptions& options) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  const ModelInfo& info = GetModelInfo(id);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return Status::Error(path +
                         ": model file not found; run scripts/setup to fetch and "
                         "convert the models (docs/detect.md)");
  }
  auto impl = std::make_unique<Impl>();
  for (const ModelOutput& output : info.outputs) impl->onnx_names.push_back(output.onnx_name);
  if (options.runtime != InferenceRuntime::kOpenCv) {
    const std::vector<std::string> names(impl->onnx_names.begin(), impl->onnx_names.end());
    Status outputs = Status::Ok();
    StatusOr<std::unique_ptr<XnnpackGraph>> graph =
        XnnpackGraph::Load(path,
                           names,
                           info.input_height,
                           info.input_width,
                           options.num_threads,
                           [&](const std::vector<std::string>& graph_outputs) {
                             outputs = CheckOutputs(path, info, graph_outputs);
                             return outputs;
                           });
    ARCO_RETURN_IF_ERROR(outputs);
    if (graph.ok()) {
      impl->xnnpack = std::move(graph).value();
      return Network(info, path, options, std::move(impl));
    }
    if (options.runtime == InferenceRuntime::kXnnpack) return graph.status();
  }
  try {
    impl->net = cv::dnn::readNetFromONNX(path);
  } catch (const cv::Exception& e) {
    return Status::Error(path + ": cannot read the ONNX model (" + e.err +
                         "); run scripts/setup to fetch and convert it again");
  }
  if (impl->net.empty()) {
    return Status::Error(path + ": the ONNX model holds no layers");
  }
  impl->net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  impl->net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  const std::vector<cv::String> cv_outputs = impl->net.getUnconnectedOutLayersNames();
  ARCO_RETURN_IF_ERROR(
      CheckOutputs(path, info, std::vector<std::string>(cv_outputs.begin(), cv_outputs.end())));
  const int blob_shape[] = {1, 3, info.input_height, info.input_width};
  impl->blob.create(4, blob_shape, CV_32F);
  return Network(info, path, options, std::move(impl));
}

Network::Network(const ModelInfo& info,
                 std::string path,
                 NetworkOptions options,
                 std::unique_ptr<Impl> impl)
    : info_(&info), path_(std::move(path)), options_(options), impl_(std::move(impl)) {
  for (const ModelOutput& output : info.outputs) {
    Tensor tensor;
    tensor.shape = output.shape;
    size_t count = 1;
    for (int d : output.shape) count *= static_cast<size_t>(d);
    tensor.data.assign(count, 0.0f);
    outputs_.push_back(std::move(tensor));
  }
}

Network::Network(Network&&) noexcept = default;
Network& Network::operator=(Network&&) noexcept = default;
Network::~Network() = default;

Status Network::Run(const float* input, size_t input_size, TensorLayout layout) {
  const int height = info_->input_height, width = info_->input_width;
  const size_t plane = static_cast<size_t>(height) * width;
  if (input == nullptr || input_size != 3 * plane) {
    throw std::invalid_argument(std::string(info_->name) + " takes 3 x " + std::to_string(height) +
                                " x " + std::to_string(width) + " floats, got " +
                                std::to_string(input_size));
  }
  if (impl_->xnnpack) {
    if (layout == TensorLayout::kNhwc) {
      ARCO_RETURN_IF_ERROR(impl_->xnnpack->Run(input).WithContext(path_));
    } else {
      nhwc_.resize(3 * plane);
      for (size_t i = 0; i < plane; ++i) {
        for (size_t c = 0; c < 3; ++c) nhwc_[3 * i + c] = input[c * plane + i];
      }
      ARCO_RETURN_IF_ERROR(impl_->xnnpack->Run(nhwc_.data()).WithContext(path_));
    }
    for (size_t k = 0; k < outputs_.size(); ++k) {
      const std::vector<float>& result = impl_->xnnpack->outputs()[k];
      if (result.size() != outputs_[k].data.size()) {
        return Status::Error(path_ + ": output '" + info_->outputs[k].onnx_name + "' has " +
                             std::to_string(result.size()) + " values, expected " +
                             std::to_string(outputs_[k].data.size()));
      }
      std::memcpy(outputs_[k].data.data(), result.data(), result.size() * sizeof(float));
    }
    return Status::Ok();
  }
  float* blob = impl_->blob.ptr<float>();
  if (layout == TensorLayout::kNchw) {
    std::memcpy(blob, input, 3 * plane * sizeof(float));
  } else {
    for (size_t i = 0; i < plane; ++i) {
      blob[i] = input[3 * i];
      blob[plane + i] = input[3 * i + 1];
      blob[2 * plane + i] = input[3 * i + 2];
    }
  }
  if (cv::getNumThreads() != options_.num_threads) cv::setNumThreads(options_.num_threads);
  try {
    impl_->net.setInput(impl_->blob);
    impl_->net.forward(impl_->results, impl_->onnx_names);
  } catch (const cv::Exception& e) {
    return Status::Error(path_ + ": inference failed (" + e.err + ")");
  }
  for (size_t k = 0; k < outputs_.size(); ++k) {
    const cv::Mat& result = impl_->results[k];
    Tensor& tensor = outputs_[k];
    if (result.type() != CV_32F || !result.isContinuous() || result.total() != tensor.data.size()) {
      return Status::Error(path_ + ": output '" + info_->outputs[k].onnx_name + "' has " +
                           std::to_string(result.total()) + " values, expected " +
                           std::to_string(tensor.data.size()));
    }
    std::memcpy(tensor.data.data(), result.ptr<float>(), tensor.data.size() * sizeof(float));
  }
  return Status::Ok();
}

const char* Network::runtime_name() const {
  return InferenceRuntimeName(impl_->xnnpack ? InferenceRuntime::kXnnpack
                                             : InferenceRuntime::kOpenCv);
}

const Tensor& Network::output(const std::string& name) const {
  return outputs_[info_->OutputIndex(name)];
}

}  // namespace arco::detect
