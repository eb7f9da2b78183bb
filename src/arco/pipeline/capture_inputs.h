// The capture files a result is made from, each with its fingerprint (util/fingerprint.h),
// so that a reader of the result can tell that the capture changed since (a replaced
// capture, a re-detected keypoints2d.npy, an edited calibration, a re-synced audio
// offset) and refuse instead of mixing the new capture with the old result
// (docs/architecture.md, "Results are tied to their inputs"). The fingerprinted files
// are those the stages read: the manifest, the calibration, the 2D keypoints and the
// audio. The videos are not: no stage reads them (their keypoints2d.npy is what the
// result is made of), and hashing gigabytes of video on every `arco plot` would cost more
// than it tells.
#pragma once

#include <initializer_list>
#include <map>
#include <string>

#include "arco/mocap/capture.h"
#include "arco/util/fingerprint.h"
#include "arco/util/status.h"

namespace arco::pipeline {

// Roles: the keys of result.json "inputs" (docs/formats.md).
inline constexpr char kManifestInput[] = "capture.json";
inline constexpr char kCalibrationInput[] = "calibration";
inline constexpr char kKeypoints2dInput[] = "keypoints2d";
inline constexpr char kAudioInput[] = "audio";

struct CaptureInput {
  // As capture.json names it: relative to the capture folder, or absolute
  // (ResolveCapturePath); "capture.json" for the manifest itself.
  std::string file;
  Fingerprint fingerprint;
};
using CaptureInputs = std::map<std::string, CaptureInput>;  // by role

// The fingerprints of the capture folder's files in `roles` that its manifest names (a
// capture without audio has no "audio" input). Errors name the file (unreadable).
StatusOr<CaptureInputs> FingerprintCaptureInputs(const std::string& capture_dir,
                                                 const CaptureManifest& manifest,
                                                 std::initializer_list<const char*> roles);

// `inputs` restricted to `roles` (those it has).
CaptureInputs SelectInputs(const CaptureInputs& inputs, std::initializer_list<const char*> roles);

}  // namespace arco::pipeline
