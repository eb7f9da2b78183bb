// A complete capture manifest for tests (every field set, a dropped-frame list): the
// capture folder's tests and the result folder's tests start from the same one.
#pragma once

#include "arco/mocap/capture.h"

namespace arco::testing {

inline CaptureManifest SampleManifest() {
  CaptureManifest m;
  m.name = "cello_1113_scale";
  m.instrument = "cello";
  m.fps = 30;
  m.frame_first = 128;
  m.frame_count = 4;
  m.tuning_a4_hz = 442;
  m.calibration = "calibration.xml";
  m.audio = "audio.wav";
  m.audio_offset_s = 1.25;
  m.keypoints2d = "keypoints2d.npy";
  m.layout = "spd_cello";
  m.cameras = {{"cam0", "21334181", "videos/21334181.avi", {129, 131}},  // inside frames 128..131
               {"cam1", "21334237", "", {}}};
  return m;
}

}  // namespace arco::testing
