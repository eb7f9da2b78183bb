// Named detector error models (`arco synth --error-model NAME`): presets of
// DetectionOptions (detections.h), so a study can name the errors it assumed and a
// re-captured take (motion.h) records them in truth.json. Every model starts from the
// defaults; the caller's explicit options are applied after the preset.
//
//   synth      today's defaults: 2 px noise, 1% outliers and hand swaps, 5% drop-outs,
//              geometric occlusion, 12 mm playing-finger lift, 4 mm smooth per-point 3D
//              error shared by all views
//   clean      1 px noise only (no outliers, drop-outs, lift or shared error)
//   shared     synth + a smooth per-finger 3D offset of the left hand shared by all views
//              (5 mm per axis at the tip, 0.6 s): what triangulation cannot remove
//   behind     synth + the fingers hidden in views that see the back of the left hand
//              (within 60 degrees of its back normal)
//   confusion  synth + neighbouring left fingers confused in 3% of view-frames
//   harsh      shared + behind + confusion, 3 px noise and 3% outliers
#pragma once

#include <string>
#include <vector>

#include "arco/synth/detections.h"
#include "arco/util/json_io.h"
#include "arco/util/status.h"

namespace arco::synth {

struct ErrorModelInfo {
  std::string name;
  std::string description;
};

// Every model, in the order above.
const std::vector<ErrorModelInfo>& ErrorModels();

// The model's options (from the defaults). Error: an unknown name (the message lists the
// known ones).
StatusOr<DetectionOptions> ErrorModelOptions(const std::string& name);

// The model's name and every parameter as applied, for truth.json.
Json ErrorModelJson(const std::string& name, const DetectionOptions& options);

}  // namespace arco::synth
