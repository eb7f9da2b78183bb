// `arco track CAPTURE --labels CAMERA=LABELME.json ...` (docs/track.md): the instrument's
// points in every camera and frame of a capture made from videos, from labels of one
// frame in at least two views (a one-camera capture: in its view, the instrument's model
// posed by them, track::PoseTemplateInOneView). The tracking itself is track::InstrumentTracker
// (track/instrument_tracker.h); this stage reads and checks the labels, reads the frames
// through media::VideoReader (turned by rotate_deg), tracks forwards from the labelled
// frame (and backwards when it is not the first) and writes the instrument slots of
// keypoints2d.npy, CAPTURE/track.json and capture.json together.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "arco/track/bow_tracker.h"
#include "arco/track/instrument_tracker.h"
#include "arco/util/json_io.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::capture {

// One labelme file: the labels of `camera` (name or serial) on global frame `frame`
// (-1: TrackStageOptions::labels_frame).
struct TrackLabelsFile {
  std::string camera;
  int64_t frame = -1;
  std::string path;
};

// "CAMERA=FILE" or "CAMERA@FRAME=FILE"; an error naming the text otherwise.
StatusOr<TrackLabelsFile> ParseTrackLabelsSpec(const std::string& text);

struct TrackStageOptions {
  std::string capture_dir;
  std::vector<TrackLabelsFile> labels;
  int64_t labels_frame = -1;                // -1: the capture's first frame
  track::InstrumentTrackerOptions tracker;  // its num_threads is num_threads below
  int num_threads = 0;                      // 0 = all cores; results do not depend on it
  // The bow as a thin rigid body of fixed length from its frog and tip labels
  // (track/bow_tracker.h: line segments, the profile along the stick, the pose from all
  // views at once, the right hand as the frog's prior), when both are labelled in two
  // views. Measured on synthetic renders (capture_track_plane_test,
  // capture_track_bow_test: 0.24 mm median against issue 13's 8 mm), not yet on real
  // footage (docs/track.md). false: the bow's slots keep what the file held.
  bool track_bow = true;
  track::BowTrackerOptions bow;  // its num_threads is num_threads above
  // The right hand (keypoints2d.npy's right_hand slots from `arco detect`) is the bow's
  // prior on the frog in a view when this many of its points score at least
  // bow_hand_min_score (their mean pixel).
  double bow_hand_min_score = 0.3;
  int bow_hand_min_points = 3;
  Status Validate() const;
};

Json ToJson(const TrackStageOptions& options);

struct TrackCameraSummary {
  std::string camera;
  int64_t frames = 0;           // frames read
  int64_t lost_frames = 0;      // frames in which the view had lost the instrument
  int64_t reacquired = 0;       // times it found it again
  int64_t bow_lost_frames = 0;  // frames without a line segment near the predicted bow
  double mean_inliers = 0;      // per frame read
  double mean_residual_px = 0;
};

struct TrackStageSummary {
  std::string layout;
  int64_t first_frame = 0, last_frame = 0;
  int64_t template_frame = 0;               // the labelled frame the template comes from
  std::vector<std::string> tracked_points;  // instrument points with a template point
  // Labelled in fewer than two views (one camera: not labelled, or no place in the model
  // its labels pose, as the end pin).
  std::vector<std::string> untracked_points;
  // The labels' triangulation residual (one camera: against the posed model).
  double label_rms_px = 0;
  // The calibration's unit and millimetres per unit: 1 for "mm", 1000 for "m"; for
  // another unit (Metashape's) the labelled nut-bridge distance against the instrument's
  // string length. The trackers work in mm.
  std::string units;
  double mm_per_unit = 1;
  int64_t frames_without_pose = 0;  // the pose was the prediction
  bool bow_tracked = false;         // frog and tip labelled in two views: the bow slots written
  int64_t bow_frames_without_pose = 0;
  int64_t bow_hand_frames = 0;  // frames read with the right hand in two views or more
  std::vector<TrackCameraSummary> cameras;
  std::vector<std::string> warnings;
  bool kept_other_points = false;  // body/hand slots kept from keypoints2d.npy
  double decode_s = 0, track_s = 0, wall_s = 0;
  double bow_s = 0;  // of track_s, in the bow tracker (wall)
};

Json ToJson(const TrackStageSummary& summary);

// Checks the capture (manifest, calibration, every camera's video) and the labels (files
// readable, cameras known, frames inside the capture, labels inside the image, at least
// two views, names that match the instrument's points) before any frame is decoded;
// then tracks and replaces CAPTURE/keypoints2d.npy (instrument slots, and the bow's when
// its frog and tip are labelled in two views; the other slots kept, NaN in a new file),
// track.json and capture.json together
// (util/output_set.h). Progress: total = frames x cameras.
StatusOr<TrackStageSummary> RunTrackStage(const TrackStageOptions& options,
                                          Progress& progress = NoProgress());

}  // namespace arco::capture
