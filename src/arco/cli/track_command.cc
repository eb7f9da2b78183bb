// `arco track CAPTURE --labels CAMERA=LABELME.json ...`: the instrument's points in every
// camera and frame from labels of one frame in two views (capture/track_stage.h,
// docs/track.md).
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "arco/capture/track_stage.h"
#include "arco/cli/command.h"
#include "arco/cli/flag_names.h"
#include "arco/cli/number_option.h"
#include "arco/cli/progress.h"
#include "arco/util/output_set.h"

namespace arco::cli {
namespace {

inline constexpr FieldFlag kTrackFlags[] = {{"num_threads", "--threads"},
                                            {"labels_frame", "--labels-frame"},
                                            {"track_bow off", "--no-bow"},
                                            {"max_features_per_view", "--max-features"},
                                            {"keyframe_interval", "--keyframe-interval"},
                                            {"inlier_px", "--inlier-px"}};

struct TrackArgs {
  capture::TrackStageOptions o;
  std::vector<std::string> labels;
  int64_t labels_frame = -1;
};

void ApplyAndValidate(TrackArgs& a) {
  a.o.labels.clear();
  for (const std::string& text : a.labels) {
    auto spec = capture::ParseTrackLabelsSpec(text);
    ThrowIfInvalid(spec.status());
    a.o.labels.push_back(*spec);
  }
  a.o.labels_frame = a.labels_frame;
  const Status valid = a.o.Validate();
  if (!valid.ok()) ThrowIfInvalid(Status::Error(WithFlagNames(valid.message(), kTrackFlags)));
}

int RunTrack(const TrackArgs& a) {
  ProgressBar bar("track");
  auto summary = capture::RunTrackStage(a.o, bar);
  bar.Finish();
  if (!summary.ok()) return PrintError(WithFlagNames(summary.status().message(), kTrackFlags));
  const auto& s = *summary;
  for (const auto& w : s.warnings) {
    std::fprintf(stderr, "arco: warning: %s\n", WithFlagNames(w, kTrackFlags).c_str());
  }
  std::printf("tracked frames %lld:%lld in %zu cameras from labels of frame %lld (layout %s)\n",
              static_cast<long long>(s.first_frame),
              static_cast<long long>(s.last_frame),
              s.cameras.size(),
              static_cast<long long>(s.template_frame),
              s.layout.c_str());
  std::string points;
  for (const auto& p : s.tracked_points) points += (points.empty() ? "" : " ") + p;
  std::printf("  points: %s (labels agree to %.2f px)\n", points.c_str(), s.label_rms_px);
  if (s.units != "mm") {
    std::printf("  world in %s units: %.4g mm per unit%s\n",
                s.units.c_str(),
                s.mm_per_unit,
                s.units == "m" ? "" : " (the labelled nut-bridge distance as the string length)");
  }
  for (const auto& c : s.cameras) {
    std::printf(
        "  %-12s %6lld frames  inliers %6.1f  residual %5.2f px  lost %lld  "
        "re-acquired %lld\n",
        c.camera.c_str(),
        static_cast<long long>(c.frames),
        c.mean_inliers,
        c.mean_residual_px,
        static_cast<long long>(c.lost_frames),
        static_cast<long long>(c.reacquired));
  }
  if (s.frames_without_pose > 0) {
    std::printf("  %lld frames without a pose (predicted, low scores)\n",
                static_cast<long long>(s.frames_without_pose));
  }
  int64_t view_frames = 0;
  for (const auto& c : s.cameras) view_frames += c.frames;
  std::printf("time %.1f s: tracking %.1f ms, decoding %.1f ms per view-frame\n",
              s.wall_s,
              view_frames > 0 ? 1e3 * (s.track_s - s.decode_s) / view_frames : 0.0,
              view_frames > 0 ? 1e3 * s.decode_s / view_frames : 0.0);
  if (s.bow_tracked) {
    std::printf("  of which the bow %.1f ms per view-frame; the right hand seen in %lld frames\n",
                view_frames > 0 ? 1e3 * s.bow_s / view_frames : 0.0,
                static_cast<long long>(s.bow_hand_frames));
  }
  std::printf("wrote %s/keypoints2d.npy, track.json and capture.json\n",
              NormalizeOutputPath(a.o.capture_dir).c_str());
  return 0;
}

std::function<int()> SetupTrack(CLI::App& app) {
  auto* sub = app.add_subcommand(
      "track",
      "The instrument's points in every camera and frame of a capture from labels of one "
      "frame in two views, or in its one view for a one-camera capture (docs/track.md), into "
      "its keypoints2d.npy");
  auto a = std::make_shared<TrackArgs>();
  track::InstrumentTrackerOptions& t = a->o.tracker;
  sub->add_option("capture", a->o.capture_dir, "Capture folder made by `arco capture new`")
      ->required();
  sub->add_option("--labels",
                  a->labels,
                  "CAMERA=LABELME.json (labels of --labels-frame) or CAMERA@FRAME=LABELME.json; "
                  "at least two views (one for a one-camera capture)")
      ->required();
  AddNumber(sub,
            "--labels-frame",
            a->labels_frame,
            "Capture frame the labels are on (-1 = the capture's first frame); a camera synced "
            "by sound shows it in its own frame nearest that moment (docs/track.md)",
            Closed(-1, 1e12))
      ->capture_default_str();
  AddNumber(sub,
            "--threads",
            a->o.num_threads,
            "Worker threads (0 = all cores); results do not change",
            kThreadsRange)
      ->capture_default_str();
  AddNumber(
      sub, "--max-features", t.max_features_per_view, "Corners tracked per view", Closed(8, 5000))
      ->capture_default_str();
  AddNumber(sub,
            "--keyframe-interval",
            t.keyframe_interval,
            "Re-match the labelled frame's patches every N frames (0 = never; always after a "
            "loss)",
            Closed(0, 100000))
      ->capture_default_str();
  AddNumber(sub,
            "--inlier-px",
            t.pose.inlier_px,
            "A tracked corner farther than this from the pose's projection is an outlier",
            AboveZero(1000))
      ->capture_default_str();
  sub->add_flag("--bow,!--no-bow",
                a->o.track_bow,
                "Track the bow from its frog and tip labels (the default when both are labelled "
                "in two views), as a thin line of fixed length posed from all views at once, "
                "the right hand (from `arco detect`) as its frog's prior; --no-bow keeps the "
                "bow's slots as they were (docs/track.md)");
  sub->parse_complete_callback([a] { ApplyAndValidate(*a); });
  return [a]() { return RunTrack(*a); };
}

}  // namespace
ARCO_REGISTER_COMMAND(track, 19, SetupTrack);
}  // namespace arco::cli
