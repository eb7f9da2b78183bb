// The pretrained networks arco runs (MediaPipe's pose and hand models, Apache-2.0),
// defined once: which file, its input size and value range, and its named outputs.
//
// The files are fetched from the npm registry and converted from TFLite to ONNX by
// scripts/setup (scripts/fetch_models, tools/tflite_onnx/); docs/detect.md lists the
// versions, checksums and the conversion. Every model takes one RGB image crop of
// input_height x input_width (float, NHWC in the TFLite original; the ONNX file's input
// is NCHW) and returns its outputs in TFLite's shapes and element order.
#pragma once

#include <string>
#include <vector>

#include "arco/util/status.h"

namespace arco::detect {

enum class ModelId {
  kPoseDetection,     // person detector (SSD, 2254 anchors)
  kPoseLandmarkLite,  // 33 body + 6 auxiliary landmarks, three sizes
  kPoseLandmarkFull,
  kPoseLandmarkHeavy,
  kHandLandmarkLite,  // 21 hand landmarks, two sizes
  kHandLandmarkFull,
  kHandRecrop,         // refines a pose-derived hand crop (MediaPipe Holistic)
  kPalmDetectionFull,  // palm detector (SSD, 2016 anchors)
};

// Pixel values the network expects: RGB bytes v map to v / 255 ([0, 1]) or
// v / 127.5 - 1 ([-1, 1]).
enum class ValueRange { kZeroToOne, kMinusOneToOne };

struct ModelOutput {
  const char* name;       // what arco calls it, e.g. "landmarks"
  const char* onnx_name;  // the graph's output name (TFLite's tensor name)
  std::vector<int> shape;
  const char* meaning;
};

struct ModelInfo {
  ModelId id;
  const char* name;     // "pose_landmark_full"; also the file stem
  const char* package;  // npm package the TFLite file comes from, "NAME@VERSION"
  int input_width = 0, input_height = 0;
  ValueRange range = ValueRange::kZeroToOne;
  std::vector<ModelOutput> outputs;

  std::string FileName() const;  // "pose_landmark_full.onnx"
  // Index of output `name` in `outputs`; throws std::invalid_argument if unknown.
  int OutputIndex(const std::string& name) const;
};

const std::vector<ModelInfo>& AllModels();
const ModelInfo& GetModelInfo(ModelId id);
// "pose_landmark_full" -> kPoseLandmarkFull; an error naming the known models otherwise.
StatusOr<ModelId> ParseModelName(const std::string& name);

// The models folder: $ARCO_MODELS_DIR when set, else the data folder's models/ (an
// installed arco, util/data_dir.h), else the repository's models/ folder (where
// scripts/setup puts them; fixed at configure time).
std::string DefaultModelsDir();
std::string ModelPath(ModelId id, const std::string& models_dir = DefaultModelsDir());

}  // namespace arco::detect
