// Writes a synthetic capture in arco's capture format (mocap/capture.h,
// docs/formats.md) plus its truth (docs/synth.md):
//
//   OUT/capture.json        manifest: instrument, fps, frames, calibration, audio, 2D keypoints
//   OUT/calibration.json    the rig scaled to mm (arco JSON); the world frame of everything
//   OUT/keypoints2d.npy     (frames, views, points, 3) float32 [x_px, y_px, score]
//   OUT/audio.wav           rendered performance (absent with --no-audio)
//   OUT/performance.mid     the MIDI the audio was rendered from
//   OUT/truth/truth.json    summary, options, layouts, stage, sample tuning
//   OUT/truth/points3d.npy  (frames, layout + 13, 3) float64 mm: the capture layout plus
//                           SPD's contact-stage points (strings, contact, playing finger)
//   OUT/truth/left_hand_pose.npy, right_hand_pose.npy
//                           (frames, 26): wrist angle-axis (3, rad), wrist (3, mm), 20 joint
//                           angles (rad) of arco's default hand model (hand/hand_model.h)
//   OUT/truth/instrument_pose.npy  (frames, 4, 4) world_from_instrument (mm)
//   OUT/truth/contact.csv   frame,time_s,state,string,finger,note,f0_hz,contact_x_mm,...
//   OUT/truth/pitch.csv     frame,time_s,f0_hz,confidence,voiced (arco pitch's format)
//   OUT/truth/notes.csv     one row per note: timing, pitch, fingering, expression
//
// Rows are video frames: row i is at time_s = i / fps on the audio's clock
// (manifest frame numbers start at 1, audio offset 0). The folder is built under a hidden
// temporary name and moved into place (util/atomic_dir.h), so a failure leaves nothing and
// an old capture is replaced only once the new one is complete.
#pragma once

#include <string>

#include "arco/synth/audio_render.h"
#include "arco/synth/synth.h"
#include "arco/util/status.h"

namespace arco::synth {

struct WriteOptions {
  bool audio = true;
  AudioRenderOptions audio_render;
  bool overwrite = false;          // replace an existing non-empty output folder
  std::string calibration_source;  // original calibration path, recorded in truth.json
};

struct WriteSummary {
  AudioRenderSummary audio;
  int64_t bytes = 0;
};

// An existing non-empty OUT is replaced only with options.overwrite and only when it holds
// a capture.json (an arco capture); "OUT/" and "OUT" are the same folder.
Status WriteCapture(const SyntheticCapture& capture,
                    const std::string& out_dir,
                    const WriteOptions& options,
                    WriteSummary* summary = nullptr);

// WriteCapture's checks of OUT, for the command to make before synthesising.
Status CheckCaptureOutput(const std::string& out_dir, const WriteOptions& options);

}  // namespace arco::synth
