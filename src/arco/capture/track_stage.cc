#include "arco/capture/track_stage.h"

#include <chrono>
#include <string>
#include <utility>

#include "arco/capture/track_steps.h"
#include "arco/util/file_io.h"
#include "arco/util/npy.h"
#include "arco/util/output_set.h"

namespace arco::capture {

StatusOr<TrackLabelsFile> ParseTrackLabelsSpec(const std::string& text) {
  const size_t eq = text.find('=');
  const auto bad = [&] {
    return Status::Error("--labels \"" + text +
                         "\" must look like CAMERA=FILE or CAMERA@FRAME=FILE");
  };
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) return bad();
  TrackLabelsFile f;
  f.path = text.substr(eq + 1);
  std::string camera = text.substr(0, eq);
  const size_t at = camera.rfind('@');
  if (at != std::string::npos) {
    const std::string frame = camera.substr(at + 1);
    if (frame.empty() || frame.size() > 12 ||
        frame.find_first_not_of("0123456789") != std::string::npos) {
      return bad();
    }
    f.frame = std::stoll(frame);
    camera = camera.substr(0, at);
  }
  if (camera.empty()) return bad();
  f.camera = camera;
  return f;
}

Status TrackStageOptions::Validate() const {
  if (capture_dir.empty()) return Status::Error("capture_dir is empty");
  if (labels.empty()) return Status::Error("labels is empty (labelme files of two views)");
  if (labels_frame < -1) return Status::Error("labels_frame must be -1 (the first) or >= 0");
  ARCO_RETURN_IF_ERROR(CheckInRange("num_threads", num_threads, Closed(0, 1024)));
  track::InstrumentTrackerOptions t = tracker;
  t.num_threads = 1;
  ARCO_RETURN_IF_ERROR(t.Validate().WithContext("tracker"));
  ARCO_RETURN_IF_ERROR(bow.Validate().WithContext("bow"));
  ARCO_RETURN_IF_ERROR(CheckInRange("bow_hand_min_score", bow_hand_min_score, Closed(0, 1)));
  ARCO_RETURN_IF_ERROR(CheckInRange("bow_hand_min_points", bow_hand_min_points, Closed(1, 21)));
  return Status::Ok();
}

Json ToJson(const TrackStageOptions& o) {
  Json labels = Json::array();
  for (const auto& l : o.labels) {
    labels.push_back({{"camera", l.camera}, {"frame", l.frame}, {"file", l.path}});
  }
  return Json{{"labels", labels},
              {"labels_frame", o.labels_frame},
              {"track_bow", o.track_bow},
              {"bow", ToJson(o.bow)},
              {"bow_hand_min_score", o.bow_hand_min_score},
              {"bow_hand_min_points", o.bow_hand_min_points},
              {"tracker", ToJson(o.tracker)}};
}

Json ToJson(const TrackStageSummary& s) {
  Json cameras = Json::array();
  for (const auto& c : s.cameras) {
    cameras.push_back({{"camera", c.camera},
                       {"frames", c.frames},
                       {"lost_frames", c.lost_frames},
                       {"reacquired", c.reacquired},
                       {"mean_inliers", c.mean_inliers},
                       {"mean_residual_px", c.mean_residual_px},
                       {"bow_lost_frames", c.bow_lost_frames}});
  }
  return Json{{"layout", s.layout},
              {"first_frame", s.first_frame},
              {"last_frame", s.last_frame},
              {"template_frame", s.template_frame},
              {"tracked_points", s.tracked_points},
              {"untracked_points", s.untracked_points},
              {"label_rms_px", s.label_rms_px},
              {"frames_without_pose", s.frames_without_pose},
              {"bow_tracked", s.bow_tracked},
              {"bow_frames_without_pose", s.bow_frames_without_pose},
              {"bow_hand_frames", s.bow_hand_frames},
              {"kept_other_points", s.kept_other_points},
              {"units", s.units},
              {"mm_per_unit", s.mm_per_unit},
              {"cameras", cameras},
              {"warnings", s.warnings},
              {"decode_s", s.decode_s},
              {"track_s", s.track_s},
              {"bow_s", s.bow_s},
              {"wall_s", s.wall_s}};
}

StatusOr<TrackStageSummary> RunTrackStage(const TrackStageOptions& options, Progress& progress) {
  const auto start = std::chrono::steady_clock::now();
  ARCO_RETURN_IF_ERROR(options.Validate());
  TrackStageSummary summary;
  // Every check before any frame is decoded: the capture, the labels, the templates, the
  // keypoints kept, the outputs.
  ARCO_ASSIGN_OR_RETURN(const TrackCapture capture, OpenTrackCapture(options.capture_dir));
  ARCO_ASSIGN_OR_RETURN(const TrackLabels labels,
                        ReadTrackLabels(options, capture, &summary.warnings));
  ARCO_ASSIGN_OR_RETURN(const TrackTemplates templates,
                        MakeTrackTemplates(options, capture, labels, &summary));
  ARCO_ASSIGN_OR_RETURN(NpyArray<float> keypoints, StartTrackKeypoints(capture, &summary));
  OutputSet outputs;
  TrackOutputPaths paths;
  ARCO_ASSIGN_OR_RETURN(paths.keypoints,
                        outputs.AddFile(JoinPath(capture.dir, kTrackKeypointsFile)));
  ARCO_ASSIGN_OR_RETURN(paths.manifest, outputs.AddFile(capture.manifest_path));
  ARCO_ASSIGN_OR_RETURN(paths.report, outputs.AddFile(JoinPath(capture.dir, kTrackReportFile)));
  // The work, then the outputs, all or none.
  ARCO_ASSIGN_OR_RETURN(
      const TrackRun run,
      TrackCaptureFrames(options, capture, labels, templates, keypoints, progress, &summary));
  ARCO_RETURN_IF_ERROR(WriteTrackOutputs(
      options, capture, labels, templates, run, std::move(keypoints), paths, &summary));
  ARCO_RETURN_IF_ERROR(outputs.Commit());
  summary.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace arco::capture
