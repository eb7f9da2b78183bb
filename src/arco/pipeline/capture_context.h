// A capture folder opened for the stages after triangulation: its manifest, keypoint
// layout and instrument model (mocap/capture.h owns the capture folder's format).
#pragma once

#include <memory>
#include <string>

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
  // keypoints2d.npy as doubles, once read (PreflightRun reads it, and `arco run`'s stages
  // use it instead of reading the file again: 2 x 59 MB for a one-minute 20-camera take);
  // null: not read yet (ReadKeypoints2d reads the file).
  std::shared_ptr<const NpyArray<double>> keypoints2d;
  // The fingerprints of the capture's files as checked and read (PreflightRun): what the
  // stages record in result.json and compare with the triangulation's (capture_inputs.h).
  CaptureInputs inputs;
};

// capture.keypoints2d when set, else the file read (ReadCaptureKeypoints2d).
StatusOr<std::shared_ptr<const NpyArray<double>>> ReadKeypoints2d(const CaptureContext& capture);

// Errors name capture.json: an unreadable manifest, no instrument ("none"), a layout
// without the instrument's points or without whole-body hands.
StatusOr<CaptureContext> OpenCapture(const std::string& capture_dir);

}  // namespace arco::pipeline
