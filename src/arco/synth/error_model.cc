#include "arco/synth/error_model.h"

namespace arco::synth {

const std::vector<ErrorModelInfo>& ErrorModels() {
  static const std::vector<ErrorModelInfo> models = {
      {"synth",
       "today's defaults: noise, outliers, drop-outs, occlusion, finger lift, shared jitter"},
      {"clean", "1 px noise only"},
      {"shared", "synth + a smooth per-finger 3D offset shared by all views (5 mm at the tip)"},
      {"behind", "synth + fingers hidden in views that see the back of the left hand"},
      {"confusion", "synth + neighbouring left fingers confused in 3% of view-frames"},
      {"harsh", "shared + behind + confusion, 3 px noise, 3% outliers"},
  };
  return models;
}

StatusOr<DetectionOptions> ErrorModelOptions(const std::string& name) {
  DetectionOptions o;
  const bool shared = name == "shared" || name == "harsh";
  const bool behind = name == "behind" || name == "harsh";
  const bool confusion = name == "confusion" || name == "harsh";
  if (name == "clean") {
    o.noise_px = 1.0;
    o.outlier_rate = 0;
    o.occlusion_rate = 0;
    o.finger_bias_mm = 0;
    o.jitter_mm = 0;
    o.geometric_occlusion = false;
    return o;
  }
  if (name != "synth" && !shared && !behind && !confusion) {
    std::string known;
    for (const ErrorModelInfo& m : ErrorModels()) known += (known.empty() ? "" : ", ") + m.name;
    return Status::Error("unknown error model '" + name + "' (known: " + known + ")");
  }
  if (shared) o.finger_offset_mm = 5.0;
  if (behind) o.hand_back_max_deg = 60.0;
  if (confusion) o.finger_confusion_rate = 0.03;
  if (name == "harsh") {
    o.noise_px = 3.0;
    o.outlier_rate = 0.03;
  }
  return o;
}

Json ErrorModelJson(const std::string& name, const DetectionOptions& o) {
  return Json{{"name", name},
              {"noise_px", o.noise_px},
              {"outlier_rate", o.outlier_rate},
              {"occlusion_rate", o.occlusion_rate},
              {"geometric_occlusion", o.geometric_occlusion},
              {"finger_bias_mm", o.finger_bias_mm},
              {"jitter_mm", o.jitter_mm},
              {"jitter_time_s", o.jitter_time_s},
              {"instrument_noise_scale", o.instrument_noise_scale},
              {"bow_noise_scale", o.bow_noise_scale},
              {"finger_offset_mm", o.finger_offset_mm},
              {"finger_offset_time_s", o.finger_offset_time_s},
              {"hand_back_max_deg", o.hand_back_max_deg},
              {"finger_confusion_rate", o.finger_confusion_rate}};
}

}  // namespace arco::synth
