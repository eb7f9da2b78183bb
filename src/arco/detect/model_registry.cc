#include "arco/detect/model_registry.h"

#include <cstdlib>
#include <stdexcept>

#include "arco/util/data_dir.h"

#ifndef ARCO_MODELS_DIR
#error "ARCO_MODELS_DIR must be defined by the build (src/arco/detect/CMakeLists.txt)"
#endif

namespace arco::detect {
namespace {

constexpr const char* kHolistic = "@mediapipe/holistic@0.5.1675471629";
constexpr const char* kHands = "@mediapipe/hands@0.4.1675469240";

std::vector<ModelOutput> PoseLandmarkOutputs() {
  return {
      {"landmarks",
       "Identity",
       {1, 195},
       "39 x (x, y, z, visibility logit, presence logit), x/y in crop pixels"},
      {"presence", "Identity_1", {1, 1}, "pose presence, sigmoid applied"},
  };
}

std::vector<ModelOutput> HandLandmarkOutputs() {
  return {
      {"landmarks", "Identity", {1, 63}, "21 x (x, y, z), x/y in crop pixels"},
      {"presence", "Identity_1", {1, 1}, "hand presence, sigmoid applied"},
  };
}

std::vector<ModelInfo> MakeModels() {
  const auto zero_one = ValueRange::kZeroToOne;
  return {
      {ModelId::kPoseDetection,
       "pose_detection",
       kHolistic,
       224,
       224,
       ValueRange::kMinusOneToOne,
       {{"boxes",
         "Identity",
         {1, 2254, 12},
         "(cx, cy, w, h) + 4 keypoints, pixels relative to the SSD anchors"},
        {"scores", "Identity_1", {1, 2254, 1}, "score logits"}}},
      {ModelId::kPoseLandmarkLite,
       "pose_landmark_lite",
       kHolistic,
       256,
       256,
       zero_one,
       PoseLandmarkOutputs()},
      {ModelId::kPoseLandmarkFull,
       "pose_landmark_full",
       kHolistic,
       256,
       256,
       zero_one,
       PoseLandmarkOutputs()},
      {ModelId::kPoseLandmarkHeavy,
       "pose_landmark_heavy",
       kHolistic,
       256,
       256,
       zero_one,
       PoseLandmarkOutputs()},
      {ModelId::kHandLandmarkLite,
       "hand_landmark_lite",
       kHands,
       224,
       224,
       zero_one,
       HandLandmarkOutputs()},
      {ModelId::kHandLandmarkFull,
       "hand_landmark_full",
       kHolistic,
       224,
       224,
       zero_one,
       HandLandmarkOutputs()},
      {ModelId::kHandRecrop,
       "hand_recrop",
       kHolistic,
       256,
       256,
       zero_one,
       {{"crop",
         "output_crop",
         {1, 1, 1, 4},
         "2 x (x, y) in crop pixels: the new crop's centre and a point on its edge"}}},
      {ModelId::kPalmDetectionFull,
       "palm_detection_full",
       kHolistic,
       192,
       192,
       zero_one,
       {{"boxes",
         "Identity",
         {1, 2016, 18},
         "(cx, cy, w, h) + 7 keypoints, pixels relative to the SSD anchors"},
        {"scores", "Identity_1", {1, 2016, 1}, "score logits"}}},
  };
}

}  // namespace

std::string ModelInfo::FileName() const { return std::string(name) + ".onnx"; }

int ModelInfo::OutputIndex(const std::string& output_name) const {
  for (size_t i = 0; i < outputs.size(); ++i) {
    if (output_name == outputs[i].name) return static_cast<int>(i);
  }
  throw std::invalid_argument(std::string(name) + " has no output named '" + output_name + "'");
}

const std::vector<ModelInfo>& AllModels() {
  static const std::vector<ModelInfo> kModels = MakeModels();
  return kModels;
}

const ModelInfo& GetModelInfo(ModelId id) {
  for (const ModelInfo& info : AllModels()) {
    if (info.id == id) return info;
  }
  throw std::invalid_argument("unknown detect::ModelId " + std::to_string(static_cast<int>(id)));
}

StatusOr<ModelId> ParseModelName(const std::string& name) {
  std::string known;
  for (const ModelInfo& info : AllModels()) {
    if (name == info.name) return info.id;
    known += std::string(known.empty() ? "" : ", ") + info.name;
  }
  return Status::Error("unknown model '" + name + "' (known: " + known + ")");
}

std::string DefaultModelsDir() {
  const char* env = std::getenv("ARCO_MODELS_DIR");
  if (env != nullptr && env[0] != '\0') return env;
  return DataPath("models", ARCO_MODELS_DIR);
}

std::string ModelPath(ModelId id, const std::string& models_dir) {
  std::string dir = models_dir;
  if (!dir.empty() && dir.back() != '/') dir += '/';
  return dir + GetModelInfo(id).FileName();
}

}  // namespace arco::detect
