// A capture folder opened once for every stage of `arco run`: its manifest, keypoint
// layout, calibration (with each view's camera), 2D keypoints and instrument model, and
// the fingerprints of the files they came from (mocap/capture.h owns the capture folder's
// format). PreflightRun (run_capture.h) fills it; the stages read the capture only
// through it, so no capture file is opened twice (docs/architecture.md, "The pipeline").
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "arco/audio/audio_reader.h"
#include "arco/camera/calibration_io.h"
#include "arco/camera/camera.h"
#include "arco/instrument/instrument_model.h"
#include "arco/mocap/capture.h"
#include "arco/pipeline/capture_inputs.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/util/npy.h"
#include "arco/util/status.h"

namespace arco::pipeline {

struct CaptureContext {
  std::string capture_dir;
  CaptureManifest manifest;
  KeypointLayout layout;
  std::shared_ptr<const InstrumentModel> instrument;
  // The capture's calibration (capture.json "calibration") and the calibration camera of
  // each view, in the manifest's order (MatchCaptureCameras, capture_checks.h); empty
  // until loaded (LoadCaptureCalibration).
  Calibration calibration;
  std::vector<int> view_to_camera;
  // keypoints2d.npy as doubles, once read (PreflightRun reads it, and `arco run`'s stages
  // use it instead of reading the file again: 2 x 59 MB for a one-minute 20-camera take);
  // null: not read yet (ReadKeypoints2d reads the file).
  std::shared_ptr<const NpyArray<double>> keypoints2d;
  // audio.file's bytes, once read (PreflightRun, files up to kMaxAudioInMemoryBytes): the
  // audio check, the fingerprint and the pitch stage decode these instead of opening the
  // file again; null: not read (OpenCaptureAudio opens the file).
  std::shared_ptr<const std::string> audio_bytes;
  // The fingerprints of the capture's files as checked and read (PreflightRun): what the
  // stages record in result.json and compare with the triangulation's (capture_inputs.h).
  CaptureInputs inputs;
};

// The one conversion of world coordinates to millimetres (the instrument stage's metric
// scale, world units per mm): every coordinate divided by it. Cameras keep their
// projection (cam_from_world translation / s: the same pixels for points / s).
NpyArray<double> PointsInMm(const NpyArray<double>& points_in_world, double world_units_per_mm);
// The same for one point (each coordinate divided, as PointsInMm does, so that both give
// the same bits).
inline Eigen::Vector3d PointInMm(const Eigen::Vector3d& point_in_world, double world_units_per_mm) {
  return point_in_world / world_units_per_mm;
}
// The cameras of the capture's views (view_to_camera) with the world in mm.
std::vector<Camera> ViewCamerasInMm(const CaptureContext& capture, double world_units_per_mm);

// Reads keypoints2d.npy once into capture->keypoints2d: checked (CheckCaptureKeypoints2d's
// checks and messages), parsed and fingerprinted (capture->inputs["keypoints2d"]) from the
// same bytes.
Status LoadCaptureKeypoints2d(CaptureContext* capture);

// capture.keypoints2d when set, else the file read (ReadCaptureKeypoints2d).
StatusOr<std::shared_ptr<const NpyArray<double>>> ReadKeypoints2d(const CaptureContext& capture);

// Larger audio files are streamed from disk by each reader instead (a one-hour 48 kHz
// 24-bit stereo take is about 1 GB).
inline constexpr int64_t kMaxAudioInMemoryBytes = int64_t{256} << 20;

// Reads the capture's audio.file into capture->audio_bytes when it is a regular file no
// larger than kMaxAudioInMemoryBytes (else leaves it null; a missing or unreadable file
// is the audio check's error, not this one's).
void ReadCaptureAudioBytes(CaptureContext* capture);

// A reader of the capture's audio: decoded from audio_bytes when libsndfile reads them,
// else the file opened by audio::OpenAudio (FFmpeg's containers, large files). `path` is
// the resolved audio.file, which messages name either way.
StatusOr<std::unique_ptr<audio::AudioReader>> OpenCaptureAudio(const CaptureContext& capture,
                                                               const std::string& path);

// Reads capture.json once (inputs["capture.json"]: the fingerprint of the bytes parsed).
// Errors name capture.json: an unreadable manifest, no instrument ("none"), a layout
// without the instrument's points or without whole-body hands.
StatusOr<CaptureContext> OpenCapture(const std::string& capture_dir);

}  // namespace arco::pipeline
