// The steps of `arco track` (RunTrackStage, track_stage.h), each a function from what the
// step before gave: the capture opened and checked, the labels read, the templates
// triangulated from them, the tracking loop over the frames, and the outputs written.
// Internal to arco_capture: the CLI and the tests call RunTrackStage.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "arco/camera/camera.h"
#include "arco/capture/capture_videos.h"
#include "arco/capture/track_stage.h"
#include "arco/mocap/capture.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/track/instrument_tracker.h"
#include "arco/util/npy.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::capture {

inline constexpr char kTrackKeypointsFile[] = "keypoints2d.npy";
inline constexpr char kTrackReportFile[] = "track.json";

// The capture as checked before any frame is decoded.
struct TrackCapture {
  std::string dir;
  std::string manifest_path;
  CaptureManifest manifest;
  std::string layout_name;
  const KeypointLayout* layout = nullptr;
  const std::vector<int>* instrument_slots = nullptr;  // never empty
  const std::vector<int>* bow_slots = nullptr;         // null: the layout has no bow
  int64_t first = 0, last = 0;                         // global frames
  std::vector<CaptureVideo> inputs;                    // per view, the manifest's order
  std::vector<Camera> cameras;                         // per view, the calibration's units
  int views() const { return static_cast<int>(inputs.size()); }
};

// capture.json read; an instrument, its layout with instrument points, frames, and every
// camera's video checked (OpenCaptureVideos).
StatusOr<TrackCapture> OpenTrackCapture(const std::string& capture_dir);

// Per labelled frame: [view][point], NaN where not labelled.
using LabelsByFrame = std::map<int64_t, std::vector<std::vector<Eigen::Vector2d>>>;

struct TrackLabels {
  std::vector<std::string> names;      // instrument points, layout order
  std::vector<std::string> bow_names;  // frog, tip (empty: the layout has no bow)
  LabelsByFrame labelled;              // instrument points
  LabelsByFrame bow_labelled;          // the bow's points
  std::string files;                   // the label files, for messages
};

// The labelme files read and checked (cameras known, frames inside the capture and
// recorded, image sizes, labels inside the image, no point labelled twice, at least one
// name of the instrument per file). Labels that name no point are warnings.
StatusOr<TrackLabels> ReadTrackLabels(const TrackStageOptions& options,
                                      const TrackCapture& capture,
                                      std::vector<std::string>* warnings);

// The rigid bodies the trackers follow, in mm.
struct TrackTemplates {
  int64_t template_frame = -1;              // the labelled frame with the most views
  track::RigidTemplate body;                // the instrument
  std::optional<track::RigidTemplate> bow;  // when frog and tip are labelled in two views
  double mm_per_unit = 1;                   // of the calibration's world
  std::vector<Camera> cameras;              // the views' cameras with the world in mm
};

// Labels -> templates: the instrument's from the template frame's labels (triangulated;
// one camera: the instrument's model posed by them), the world scaled to mm (the
// calibration's units, else the labelled string length; one camera: a unit that is not
// metric is taken as mm, with a warning), the bow's (checked for a bow's length; not from
// one camera). Sets the summary's template fields, units and warnings.
StatusOr<TrackTemplates> MakeTrackTemplates(const TrackStageOptions& options,
                                            const TrackCapture& capture,
                                            const TrackLabels& labels,
                                            TrackStageSummary* summary);

// keypoints2d.npy's array to write: the capture's own (each camera's frames as
// recorded) when it has the same layout (summary->kept_other_points), else NaN.
StatusOr<NpyArray<float>> StartTrackKeypoints(const TrackCapture& capture,
                                              TrackStageSummary* summary);

// Per global frame (from capture.first): the instrument's and the bow's tracking.
struct TrackRun {
  std::vector<track::TrackFrame> instrument;
  std::vector<track::TrackFrame> bow;  // empty frames when the bow is not tracked
};

// The tracking loop: forwards from the template frame to the last, then backwards to the
// first. `keypoints` (StartTrackKeypoints) gives the right hand, the bow's prior. Sets
// the summary's decode_s, track_s, bow_s and bow_hand_frames.
StatusOr<TrackRun> TrackCaptureFrames(const TrackStageOptions& options,
                                      const TrackCapture& capture,
                                      const TrackLabels& labels,
                                      const TrackTemplates& templates,
                                      const NpyArray<float>& keypoints,
                                      Progress& progress,
                                      TrackStageSummary* summary);

// Where the outputs go (OutputSet's temporary files).
struct TrackOutputPaths {
  std::string keypoints;  // keypoints2d.npy
  std::string manifest;   // capture.json
  std::string report;     // track.json
};

// The tracked points into `keypoints`, the summary's per-camera and per-frame counts,
// then keypoints2d.npy, capture.json and track.json written to `paths`.
Status WriteTrackOutputs(const TrackStageOptions& options,
                         const TrackCapture& capture,
                         const TrackLabels& labels,
                         const TrackTemplates& templates,
                         const TrackRun& run,
                         NpyArray<float> keypoints,
                         const TrackOutputPaths& paths,
                         TrackStageSummary* summary);

}  // namespace arco::capture
