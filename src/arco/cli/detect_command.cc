// `arco detect CAPTURE`: the body and both hands in every camera's video
// (capture/detect_stage.h, docs/detect.md).
#include <cstdio>
#include <memory>
#include <string>

#include "arco/capture/detect_stage.h"
#include "arco/cli/command.h"
#include "arco/cli/flag_names.h"
#include "arco/cli/frame_range.h"
#include "arco/cli/number_option.h"
#include "arco/cli/progress.h"
#include "arco/util/output_set.h"

namespace arco::cli {
namespace {

// Detection options as set by `arco detect` (the library names the fields).
inline constexpr FieldFlag kDetectFlags[] = {
    {"num_threads", "--threads"},
    {"chunk_frames", "--chunk-frames"},
    {"min_detection_score", "--min-detection-score"},
    {"min_pose_presence", "--min-pose-presence"},
    {"min_hand_presence", "--min-hand-presence"},
    {"min_hand_tracking_presence", "--min-hand-tracking-presence"},
    {"hand_reuse_max_change", "--hand-reuse-max-change"},
    {"max_error_hand_fraction", "--hand-gate"}};

struct DetectArgs {
  capture::DetectStageOptions o;
  std::string model = "full";
  std::string hand_model = "full";
  std::string inference = "auto";
  std::string frames;  // FIRST:LAST
  bool no_hand_recrop = false;
  bool no_decode_ahead = false;
  bool no_hand_check = false;
  bool hand_rerun = false;
};

void ApplyAndValidate(DetectArgs& a) {
  auto model = detect::ParsePoseModel(a.model);
  ThrowIfInvalid(model.status());
  a.o.detector.pose_model = *model;
  auto hands = detect::ParseHandModel(a.hand_model);
  ThrowIfInvalid(hands.status());
  a.o.detector.hand_model = *hands;
  auto runtime = detect::ParseInferenceRuntime(a.inference);
  ThrowIfInvalid(runtime.status());
  a.o.detector.runtime = *runtime;
  a.o.detector.hand_recrop = !a.no_hand_recrop;
  a.o.decode_ahead = !a.no_decode_ahead;
  a.o.hands.enabled = !a.no_hand_check;
  a.o.hands.rerun = a.hand_rerun;
  ThrowIfInvalid(ParseFrameRange(a.frames, &a.o.first_frame, &a.o.last_frame));
  const Status valid = a.o.Validate();
  if (!valid.ok()) ThrowIfInvalid(Status::Error(WithFlagNames(valid.message(), kDetectFlags)));
}

int RunDetect(const DetectArgs& a) {
  ProgressBar bar("detect");
  auto summary = capture::RunDetectStage(a.o, bar);
  bar.Finish();
  if (!summary.ok()) return PrintError(summary.status().message());
  const auto& s = *summary;
  const auto percent = [](int64_t part, int64_t whole) {
    return whole > 0 ? 100.0 * static_cast<double>(part) / static_cast<double>(whole) : 0.0;
  };
  std::printf("detected frames %lld:%lld in %zu cameras (layout %s)\n",
              static_cast<long long>(s.first_frame),
              static_cast<long long>(s.last_frame),
              s.cameras.size(),
              s.layout.c_str());
  for (const auto& c : s.cameras) {
    std::printf(
        "  %-12s %6lld frames  person %5.1f%%  left hand %5.1f%%  right hand %5.1f%%  "
        "re-detections %lld%s\n",
        c.camera.c_str(),
        static_cast<long long>(c.frames),
        percent(c.tracker.frames_with_person, c.tracker.frames),
        percent(c.tracker.frames_with_left_hand, c.tracker.frames),
        percent(c.tracker.frames_with_right_hand, c.tracker.frames),
        static_cast<long long>(c.tracker.redetections),
        c.dropped > 0 ? (", " + std::to_string(c.dropped) + " dropped").c_str() : "");
  }
  const int64_t frames = s.total.frames;
  const auto per_frame_ms = [&](double seconds) {
    return frames > 0 ? 1e3 * seconds / frames : 0.0;
  };
  std::printf(
      "time %.1f s: inference %.1f ms, decoding %.1f ms (%.1f ms of it waited for) per "
      "view-frame (all workers)\n",
      s.wall_s,
      per_frame_ms(s.total.inference_s),
      per_frame_ms(s.decode_s),
      per_frame_ms(s.decode_wait_s));
  const capture::HandConsistencySummary& h = s.hands;
  if (h.ran) {
    std::printf(
        "hands across views: %lld checked, %lld views swapped, %lld disagreeing: %lld re-run "
        "on the triangulated hand's crop (%lld then agreed), %lld down-weighted; %lld points "
        "down-weighted in all (%.1f s)\n",
        static_cast<long long>(h.hands_judged),
        static_cast<long long>(h.swapped),
        static_cast<long long>(h.disagreeing),
        static_cast<long long>(h.recropped),
        static_cast<long long>(h.fixed),
        static_cast<long long>(h.hands_down_weighted),
        static_cast<long long>(h.points_down_weighted),
        h.wall_s);
  } else {
    std::printf("hands across views: not checked (%s)\n", h.skipped.c_str());
  }
  if (s.kept_other_points) std::printf("kept the instrument and bow points already there\n");
  std::printf("wrote %s/keypoints2d.npy, detect.json and capture.json\n",
              NormalizeOutputPath(a.o.capture_dir).c_str());
  return 0;
}

std::function<int()> SetupDetect(CLI::App& app) {
  auto* sub = app.add_subcommand(
      "detect",
      "Body and both hands in every camera's video of a capture (MediaPipe models, "
      "docs/detect.md) into its keypoints2d.npy");
  auto a = std::make_shared<DetectArgs>();
  detect::WholeBodyOptions& d = a->o.detector;
  sub->add_option("capture", a->o.capture_dir, "Capture folder made by `arco capture new`")
      ->required();
  sub->add_option("--model", a->model, "Pose landmark model: lite, full or heavy")
      ->check(CLI::IsMember({"lite", "full", "heavy"}))
      ->capture_default_str();
  sub->add_option("--hand-model", a->hand_model, "Hand landmark model: lite or full")
      ->check(CLI::IsMember({"lite", "full"}))
      ->capture_default_str();
  sub->add_option("--inference",
                  a->inference,
                  "Runtime of the models: auto (XNNPACK where a model translates, else "
                  "OpenCV's cv::dnn), xnnpack or opencv (docs/detect.md)")
      ->check(CLI::IsMember({"auto", "xnnpack", "opencv"}))
      ->capture_default_str();
  sub->add_option("--frames",
                  a->frames,
                  "FIRST:LAST global frame numbers to detect (default all; the other frames "
                  "keep what keypoints2d.npy held)");
  AddNumber(sub,
            "--threads",
            a->o.num_threads,
            "Worker threads (0 = all cores); results do not change",
            kThreadsRange)
      ->capture_default_str();
  AddNumber(sub,
            "--chunk-frames",
            a->o.chunk_frames,
            "Frames per work item; tracking restarts with person detection at each chunk",
            capture::kDetectChunkFramesRange)
      ->capture_default_str();
  AddNumber(sub,
            "--min-detection-score",
            d.min_detection_score,
            "Person detections below this score are ignored",
            detect::kWholeBodyScoreRange)
      ->capture_default_str();
  AddNumber(sub,
            "--min-pose-presence",
            d.min_pose_presence,
            "Tracking is lost (and the person detector runs) below this pose presence",
            detect::kWholeBodyScoreRange)
      ->capture_default_str();
  AddNumber(sub,
            "--min-hand-presence",
            d.min_hand_presence,
            "A hand below this presence is left empty (NaN)",
            detect::kWholeBodyScoreRange)
      ->capture_default_str();
  AddNumber(sub,
            "--tile-levels",
            d.detection_tile_levels,
            "When the whole frame finds nobody, search overlapping squares of 1/2 (1) and 1/4 "
            "(2) of the frame for a small person; 0 = whole frame only",
            detect::kWholeBodyTileLevelsRange)
      ->capture_default_str();
  sub->add_flag("--no-hand-recrop",
                a->no_hand_recrop,
                "Hand crops straight from the pose, without hand_recrop's refinement");
  sub->add_flag("--hand-tracking",
                d.hand_tracking,
                "A hand found on the previous frame gets its crop from its own landmarks "
                "(MediaPipe's hand tracking) instead of the pose and hand_recrop, while that "
                "crop lies on the pose's hand (off: it cost the bow hand accuracy on the "
                "plane test, docs/detect.md)");
  AddNumber(sub,
            "--min-hand-tracking-presence",
            d.min_hand_tracking_presence,
            "Hand tracking starts from a hand whose presence reached this",
            detect::kWholeBodyScoreRange)
      ->capture_default_str();
  AddNumber(sub,
            "--hand-reuse-max-change",
            d.hand_reuse_max_change,
            "Skip the hand landmarker and keep the hand it last found while no " +
                std::to_string(detect::kHandReuseBlockPx) + " x " +
                std::to_string(detect::kHandReuseBlockPx) +
                " px block of that crop has changed by more than this mean absolute "
                "difference (8-bit levels); 0 = always run it",
            detect::kWholeBodyHandReuseChangeRange)
      ->capture_default_str();
  AddNumber(sub,
            "--hand-gate",
            a->o.hands.max_error_hand_fraction,
            "A view's hand disagrees with the hand triangulated from all views when its median "
            "reprojection error exceeds this fraction of the hand's size in that view (and "
            "4 px); its points are then down-weighted (score 0.05)",
            capture::kHandGateFractionRange)
      ->capture_default_str();
  sub->add_flag("--no-hand-check",
                a->no_hand_check,
                "Leave each view's hands as detected: no check across the calibrated views "
                "(swaps, re-runs, down-weighting)");
  sub->add_flag("--hand-rerun",
                a->hand_rerun,
                "Before down-weighting a disagreeing hand, re-run the hand landmarker on a crop "
                "around the hand triangulated from the other views and keep it if it then "
                "agrees (decodes the frame again)");
  sub->add_flag("--no-decode-ahead",
                a->no_decode_ahead,
                "Decode each frame just before tracking it instead of on a thread beside "
                "each worker while the previous one is tracked (same results)");
  sub->add_option("--models-dir", d.models_dir, "Folder of the converted models (scripts/setup)");
  sub->parse_complete_callback([a] { ApplyAndValidate(*a); });
  return [a]() { return RunDetect(*a); };
}

}  // namespace
ARCO_REGISTER_COMMAND(detect, 19, SetupDetect);
}  // namespace arco::cli
