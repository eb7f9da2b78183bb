// On-disk capture and result folders (documented in docs/formats.md).
//
//   CAPTURE_DIR/capture.json        manifest (this header's CaptureManifest)
//   CAPTURE_DIR/keypoints2d.npy     (frames, views, points, 3) [x_px, y_px, score],
//                                   float32/float64, NaN = missing; views in the
//                                   manifest's camera order; pixels in the calibration's
//                                   image (OpenCV convention, origin at the centre of
//                                   the top-left pixel)
//   RESULT_DIR/result.json          what each stage wrote, with options and summaries
//   RESULT_DIR/triangulation/*.npy  points3d.npy (F, P, 3) and per-point quality
//   RESULT_DIR/<stage>/...          later stages (hand, vision, paper, arco, eval)
// Paths inside manifests are relative to the folder holding the manifest.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "arco/mocap/triangulate_sequence.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/util/file_io.h"
#include "arco/util/json_io.h"
#include "arco/util/npy.h"
#include "arco/util/status.h"

namespace arco {

inline constexpr char kCaptureManifestName[] = "capture.json";
inline constexpr char kResultManifestName[] = "result.json";

// capture.json's ranges (ParseCaptureManifest).
inline constexpr double kMaxCaptureFps = 10000;
inline constexpr int64_t kMaxCaptureFrames = 100000000;              // frames.count
inline constexpr int64_t kMaxCaptureFrameNumber = int64_t{1} << 40;  // frames.first
inline constexpr double kMaxCameraOffsetS = 86400;                   // |cameras[].offset_s|
inline constexpr double kMaxCameraDriftPpm = 10000;                  // |cameras[].drift_ppm|

struct CaptureCamera {
  std::string name;                     // matches a calibration camera's name or serial
  std::string serial;                   // optional
  std::string video;                    // optional: video file, image folder or image
  std::vector<int64_t> dropped_frames;  // global frame numbers this camera did not record
  // Clockwise rotation (0, 90, 180, 270) applied to the video's decoded frames (coded
  // orientation, media::VideoReader) to get the calibration's image; SPD's are 90.
  int rotate_deg = 0;
  // Where this camera's clock sits on the capture's (`arco capture new --sync audio`;
  // docs/formats.md): its global frame g was exposed at capture time
  //   offset_s + (1 + drift_ppm * 1e-6) * (g - 1) / fps,
  // where the capture's frame g is at (g - 1) / fps. Both 0 (absent in capture.json):
  // the camera's frames are the capture's (hardware-synced rigs, SPD).
  double offset_s = 0;
  double drift_ppm = 0;
  bool OnCaptureClock() const { return offset_s == 0 && drift_ppm == 0; }
};

struct CaptureManifest {
  int version = 1;
  std::string name;
  std::string instrument = "none";  // cello, violin, viola, double_bass or none
  double fps = 30.0;
  int64_t frame_first = 1;  // global number of the first frame in the arrays
  int64_t frame_count = 0;
  double tuning_a4_hz = 440.0;
  std::string calibration;      // calibration file (any format arco reads)
  std::string audio;            // optional audio file
  double audio_offset_s = 0.0;  // audio time of frame `frame_first`'s timestamp (mid-exposure)
  double audio_sync_confidence = NAN;       // arco sync's confidence in audio_offset_s (NaN: none)
  std::string keypoints2d;                  // optional .npy of 2D keypoints
  std::string layout;                       // keypoint layout name, or "custom" with keypoint_names
  std::vector<std::string> keypoint_names;  // only for layout "custom"
  std::vector<CaptureCamera> cameras;

  // The layout of the keypoint arrays (built-in or custom); empty name when unknown.
  StatusOr<KeypointLayout> Layout() const;
  // Index of a camera by name or serial, -1 when absent.
  int FindCamera(const std::string& id) const;
  // Global frames number the synchronised frames of the recording from 1 (SPD's
  // convention); a camera's video holds only the frames it recorded, so global frame g
  // is its video frame g - (its drops before g), 1-based (SPD's FrameDropIDLog rule).
  // -1 when the camera dropped g.
  int64_t VideoFrameNumber(int view, int64_t global_frame) const;
  // The camera's own global frame (fractional) exposed at the capture's global frame
  // `capture_frame` (cameras[].offset_s, drift_ppm); the frame itself for a camera on the
  // capture's clock.
  double CameraFrameAt(int view, double capture_frame) const;
};

// `source` names the manifest in error messages.
StatusOr<CaptureManifest> ParseCaptureManifest(const std::string& text, const std::string& source);
StatusOr<CaptureManifest> ReadCaptureManifest(const std::string& capture_dir);
Json CaptureManifestToJson(const CaptureManifest& manifest);
Status WriteCaptureManifest(const std::string& capture_dir, const CaptureManifest& manifest);

// The manifest of a capture folder: CAPTURE_DIR/capture.json (how every message names it).
std::string CaptureManifestPath(const std::string& capture_dir);

// Path of a manifest entry: relative entries are resolved against `dir` (the writers
// store them with PathRelativeTo, util/file_io.h).
std::string ResolveCapturePath(const std::string& dir, const std::string& entry);

// The layout a detector or an importer writes for a capture of this instrument:
// coco_wholebody_133 for "none", else the instrument's SPD layout (spd_cello,
// spd_violin: COCO-WholeBody then the instrument's points, left NaN by a body detector).
StatusOr<std::string> DetectionLayoutName(const std::string& instrument);

// Ok when the manifest names 2D keypoints; else one line naming capture.json that says
// how to make them (a capture from videos has none until `arco detect` or
// `arco capture import-keypoints` writes them). Every reader of the keypoints calls it.
Status CheckCaptureHasKeypoints2d(const std::string& capture_dir, const CaptureManifest& manifest);

// Checks the 2D keypoints named by the manifest from the .npy header alone (before any
// work): the file is readable, its dtype float32/float64 (any other is an error naming
// the dtype: integer pixels are a writer's mistake, not converted) and its shape
// (frames.count, cameras, layout size, 3).
Status CheckCaptureKeypoints2d(const std::string& capture_dir, const CaptureManifest& manifest);
// The dtype rule of 2D keypoints (a file's and the Python bindings' arrays): float32 or
// float64; an error naming `source` and `dtype` otherwise.
Status CheckKeypoints2dDtype(const std::string& source, const std::string& dtype, bool is_float);
// Reads the 2D keypoints named by the manifest after CheckCaptureKeypoints2d. Frames a
// camera dropped are set to NaN. A camera with an offset or a drift (not OnCaptureClock()) is
// then sampled at the capture's frame times (ResampleCameraKeypoints), unless `times` is
// kAsRecorded: the rows as stored, each camera's own frames (for a stage that rewrites
// the file: `arco detect`, `arco track`).
enum class KeypointTimes { kCaptureFrames, kAsRecorded };
StatusOr<NpyArray<double>> ReadCaptureKeypoints2d(
    const std::string& capture_dir,
    const CaptureManifest& manifest,
    KeypointTimes times = KeypointTimes::kCaptureFrames);
// The file's bytes, read once (CheckCaptureHasKeypoints2d first; a missing file or a
// folder is an error naming it), for ParseCaptureKeypoints2d and a fingerprint of the
// same bytes.
StatusOr<FileBytes> ReadCaptureKeypoints2dBytes(const std::string& capture_dir,
                                                const CaptureManifest& manifest);
// CheckCaptureKeypoints2d and ReadCaptureKeypoints2d on those bytes: the same checks,
// messages and array.
StatusOr<NpyArray<double>> ParseCaptureKeypoints2d(
    std::string_view bytes,
    const std::string& capture_dir,
    const CaptureManifest& manifest,
    KeypointTimes times = KeypointTimes::kCaptureFrames);

// Row f of `keypoints` (F, V, P, 3) for view `view` holds the camera's own global frame
// frame_first + f; afterwards it holds the camera at the capture's frame
// frame_first + f, interpolated linearly between the two nearest frames it recorded
// (x and y; the score is the lower of the two). NaN where either neighbour is missing
// or the time is outside what the camera recorded. Nothing changes for an OnCaptureClock()
// camera, so that hardware-synced captures read bit-identically.
void ResampleCameraKeypoints(const CaptureManifest& manifest,
                             int view,
                             NpyArray<double>* keypoints);

}  // namespace arco
