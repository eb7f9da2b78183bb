// The checks of an opened capture's inputs (CaptureContext), one function each, for the
// commands that read them (arco run's PreflightRun in run_capture.h, arco triangulate, arco
// calibrate check/refine, arco overlay); the checks that need only the manifest
// (MatchCaptureCameras, the audio check) are capture/capture_checks.h's. Errors are one line naming
// the file and the field (docs/architecture.md, "Validation rules").
#pragma once

#include <string>
#include <vector>

#include "arco/camera/rig.h"
#include "arco/capture/capture_checks.h"
#include "arco/mocap/capture.h"
#include "arco/pipeline/capture_context.h"
#include "arco/pipeline/triangulate_stage.h"
#include "arco/util/status.h"

namespace arco::pipeline {

// The capture's calibration (`calibration` in capture.json) is readable and holds every
// capture camera.
Status CheckCaptureCalibration(const std::string& capture_dir, const CaptureManifest& manifest);
// The same check, keeping what it read: capture->calibration, view_to_camera and the
// fingerprint of the bytes it parsed (capture->inputs["calibration"]): the file is read
// once.
Status LoadCaptureCalibration(CaptureContext* capture);

// The audio check (capture/capture_checks.h), decoding capture.audio_bytes when read
// (OpenCaptureAudio).
StatusOr<capture::CaptureAudioCheck> CheckCaptureAudio(const CaptureContext& capture);

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
