// The checks of a capture's inputs, one function each, for every command that reads them
// (arco run's PreflightRun in run_capture.h, arco triangulate, arco pitch --capture, arco
// calibrate check/refine, arco overlay, importers). Errors are one line naming the file
// and the field (docs/architecture.md, "Validation rules").
#pragma once

#include <string>
#include <vector>

#include "arco/camera/rig.h"
#include "arco/mocap/capture.h"
#include "arco/pipeline/capture_context.h"
#include "arco/pipeline/triangulate_stage.h"
#include "arco/util/status.h"

namespace arco::pipeline {

// The calibration camera of each capture camera (by name, else serial), in the manifest's
// order. Error naming capture.json, the camera and the calibration file for one absent.
StatusOr<std::vector<int>> MatchCaptureCameras(const std::string& capture_dir,
                                               const CaptureManifest& manifest,
                                               const Rig& rig,
                                               const std::string& calibration_path);

// The capture's calibration (`calibration` in capture.json) is readable and holds every
// capture camera.
Status CheckCaptureCalibration(const std::string& capture_dir, const CaptureManifest& manifest);
// The same check, keeping what it read: capture->calibration, view_to_camera and the
// fingerprint of the bytes it parsed (capture->inputs["calibration"]): the file is read
// once.
Status LoadCaptureCalibration(CaptureContext* capture);

// What the audio check learnt (for messages and tests).
struct CaptureAudioCheck {
  std::string path;       // resolved audio.file
  double duration_s = 0;  // decoded length
  std::string format;     // the decoder's name for it
};

// The capture's audio (`audio.file`) exists, opens and decodes (its first samples; the
// length from the header, or by decoding it all when the container does not say), and
// `audio.offset_s` puts at least one video frame inside it: an offset at or after the
// audio's end, or one whose last frame comes before the audio starts, is an error naming
// capture.json's audio.offset_s (frames partly outside are the pitch stage's warning).
// A capture without audio passes.
StatusOr<CaptureAudioCheck> CheckCaptureAudio(const std::string& capture_dir,
                                              const CaptureManifest& manifest);
// The same, decoding capture.audio_bytes when read (OpenCaptureAudio).
StatusOr<CaptureAudioCheck> CheckCaptureAudio(const CaptureContext& capture);

// The temporal filters of the triangulation options name groups of `layout` and suit the
// capture's frame rate.
Status CheckTriangulationFilters(const TriangulateStageOptions& options,
                                 const KeypointLayout& layout,
                                 double fps,
                                 const std::string& manifest_path);

// The instrument's string ends (nut_l, nut_r, bridge_l, bridge_r) are seen, each in at
// least two views, in at least one frame: the instrument stage needs them to place the
// strings. A capture made from videos has them only after `arco track` (or an importer);
// without them this is one line naming keypoints2d.npy, before any work. Reads the 2D
// keypoints (their header was checked by CheckCaptureKeypoints2d).
Status CheckCaptureInstrumentPoints(const CaptureContext& capture);

}  // namespace arco::pipeline
