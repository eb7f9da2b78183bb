// A capture folder opened for the stages after triangulation: its manifest, keypoint
// layout and instrument model (mocap/capture.h owns the capture folder's format).
#pragma once

#include <memory>
#include <string>

#include "arco/instrument/instrument_model.h"
#include "arco/mocap/capture.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/util/status.h"

namespace arco::pipeline {

struct CaptureContext {
  std::string capture_dir;
  CaptureManifest manifest;
  KeypointLayout layout;
  std::shared_ptr<const InstrumentModel> instrument;
};

// Errors name capture.json: an unreadable manifest, no instrument ("none"), a layout
// without the instrument's points or without whole-body hands.
StatusOr<CaptureContext> OpenCapture(const std::string& capture_dir);

}  // namespace arco::pipeline
