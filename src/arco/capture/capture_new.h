// A capture folder from videos (`arco capture new`): the manifest (docs/formats.md)
// references each camera's video file, image folder (one image per frame, natural
// order) or single image (a 1-frame video), and holds a copy of the calibration; it has
// no 2D keypoints until `arco detect` or `arco capture import-keypoints` writes them.
//
// Checks, each one line naming the file: every camera is in the calibration; each
// video's size after `rotate_deg` equals its camera's image size; the first and the
// last frame decode (an unreadable or truncated video); frame rates agree; frame counts
// agree once each camera's dropped frames are added back (below).
//
// Frame rate: a video file's comes from its container. `fps` (> 0) is required for
// image folders and single images when no video file gives one, and must agree with
// every container that states a rate (within 0.1 %): it never overrides a container.
//
// Frames: global frames number the recording from 1 (docs/formats.md); a camera's
// video holds every frame it recorded, so its frame count plus its dropped frames is the
// recording's length, which must be the same for every camera. The capture covers the
// whole recording: frames.first = 1, frames.count = that length.
//
// One camera without a calibration (one phone): the capture's calibration.json names the
// camera, takes the image size from its video (turned by rotate_deg) and a phone's
// default focal length (camera/phone_camera.h), principal point at the image centre, no
// distortion, and the camera's frame as the world: what `arco calibrate from-instrument`
// makes of one camera, which replaces it when the focal length is known. Two or more
// cameras need a calibration (their poses cannot be guessed).
//
// Sync (`sync` = kAudio, docs/capture.md): the cameras' clocks are found from their
// sound. Each video's audio track (and the recorder `audio`, when given) is aligned by
// GCC-PHAT (audio/align.h): the clock reference is the recorder when given, else the
// camera whose track aligns best with every other (the highest lowest confidence). The
// capture's clock runs at the reference's rate with its zero at the first frame of the
// camera that started first; each camera's start on it (cameras[].offset_s) and its
// clock's drift (cameras[].drift_ppm) go into capture.json, and the stages sample its 2D
// keypoints at the capture's frame times. The capture's audio is the recorder, else the
// reference camera's video (its track), audio.offset_s its time of the capture's first
// frame. Cameras may then record different lengths: frames.count is the shortest
// recording (frames + dropped frames). Errors name the file: a video without an audio
// track, a silent track, an ambiguous alignment.
//
// Frame times: a video's frames sit on the capture's regular timeline by their container
// timestamps (media::VideoReader: frame n is the picture shown at n / fps); a video whose
// timestamps jump by 1.5 frame periods or more is reported in the summary's warnings
// (the picture before the jump repeats over it), never silently stretched.
//
// Rotation: a camera's rotate_deg is the one given, else the container's display
// rotation (a phone's portrait video), else 0.
#pragma once

#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "arco/util/status.h"

namespace arco::capture {

struct CaptureNewInput {
  std::string camera;   // a calibration camera's name or serial
  std::string path;     // video file or single image; a folder when `images`
  bool images = false;  // a folder of images, one per frame
};

enum class CaptureSync {
  kNone,   // the cameras are synchronised (hardware trigger): frame g is one instant
  kAudio,  // by their sound (above)
};

struct CaptureNewOptions {
  // Any format arco reads; copied into the capture. Empty with one camera (one phone): its
  // calibration is made from its video (below, "One camera without a calibration").
  std::string calibration;
  std::vector<CaptureNewInput> inputs;    // one per camera, in the capture's view order
  std::string audio;                      // optional; referenced, not copied
  std::string instrument = "none";        // cello, violin, viola, double_bass or none
  double fps = 0;                         // 0: from the containers (see above)
  std::map<std::string, int> rotate_deg;  // camera -> 0, 90, 180 or 270 (clockwise)
  // camera -> global frames (from 1) it did not record; or all of them from an SPD
  // SESSION_summary.json's FrameDropIDLog (keyed by serial): one or the other.
  std::map<std::string, std::vector<int64_t>> dropped_frames;
  std::string spd_summary;
  std::string name;        // session name (default: the output folder's name)
  std::string output_dir;  // the capture folder to create
  bool overwrite = false;  // replace an existing capture (a folder with capture.json)
  CaptureSync sync = CaptureSync::kNone;
  double sync_max_seconds = 900;  // kAudio: align at most this much of each recording
  // Readable message naming the field on a bad value or combination.
  Status Validate() const;
};

struct CaptureNewCamera {
  std::string name, serial;
  std::string video;  // as stored in capture.json (relative to the capture folder)
  int64_t frames = 0;
  int width = 0, height = 0;  // decoded (coded) size, before rotate_deg
  int rotate_deg = 0;
  int64_t dropped = 0;
  double offset_s = 0, drift_ppm = 0;  // sync kAudio: its clock on the capture's
  double sync_confidence = NAN;        // ... and the confidence of its alignment
};

struct CaptureNewSummary {
  double fps = 0;
  int64_t frames = 0;  // frames.count: the recording's length
  std::string layout;  // the layout `arco detect` will write
  std::vector<CaptureNewCamera> cameras;
  std::string sync_reference;  // sync kAudio: the recorder's or the camera's name
  // Set when the calibration was made from the one video (no calibration given): what it
  // holds, for the user to check.
  std::string calibration_made;
  // A video whose timestamps jump (media/frame_times.h), one line each naming the file.
  std::vector<std::string> warnings;
};

StatusOr<CaptureNewSummary> CreateCapture(const CaptureNewOptions& options);

}  // namespace arco::capture
