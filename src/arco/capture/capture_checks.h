// The checks of a capture folder that need only its manifest, for the commands that make
// or read capture folders without `arco run`'s opened capture (importers, `arco detect`,
// `arco track`, `arco pitch --capture`). pipeline/capture_checks.h holds the checks of an
// opened capture (CaptureContext) and calls these. Errors are one line naming the file and
// the field (docs/architecture.md, "Validation rules").
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "arco/audio/audio_reader.h"
#include "arco/camera/rig.h"
#include "arco/mocap/capture.h"
#include "arco/util/status.h"

namespace arco::capture {

// The calibration camera of each capture camera (by name, else serial), in the manifest's
// order. Error naming capture.json, the camera and the calibration file for one absent.
StatusOr<std::vector<int>> MatchCaptureCameras(const std::string& capture_dir,
                                               const CaptureManifest& manifest,
                                               const Rig& rig,
                                               const std::string& calibration_path);

// What the audio check learnt (for messages and tests).
struct CaptureAudioCheck {
  std::string path;       // resolved audio.file
  double duration_s = 0;  // decoded length
  std::string format;     // the decoder's name for it
};

// Opens the resolved audio.file (audio::OpenAudio, or bytes already read).
using CaptureAudioOpener =
    std::function<StatusOr<std::unique_ptr<audio::AudioReader>>(const std::string& path)>;

// The capture's audio (`audio.file`) exists, opens and decodes (its first samples; the
// length from the header, or by decoding it all when the container does not say), and
// `audio.offset_s` puts at least one video frame inside it: an offset at or after the
// audio's end, or one whose last frame comes before the audio starts, is an error naming
// capture.json's audio.offset_s (frames partly outside are the pitch stage's warning).
// A capture without audio passes. `open` reads the file (audio::OpenAudio when empty).
StatusOr<CaptureAudioCheck> CheckCaptureAudio(const std::string& capture_dir,
                                              const CaptureManifest& manifest,
                                              const CaptureAudioOpener& open = {});

// `path` (named by capture.json's `field`, written there as `entry`) exists and is a file.
Status CheckCaptureInputFile(const std::string& capture_dir,
                             const std::string& field,
                             const std::string& entry,
                             const std::string& path);

}  // namespace arco::capture
