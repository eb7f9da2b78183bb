// Reader of MMPose's 2D predictions (RTMPose, RTMW, DWPose and the other COCO-WholeBody
// models it runs) into CameraDetections (mocap/detections.h). Every form MMPose 1.x
// writes:
//
//   per image   MMPoseInferencer(pred_out_dir): [instance, ...]
//               demo/topdown_demo_with_mmdet.py --save-predictions:
//               {"meta_info": {...}, "instance_info": [instance, ...]}
//   per video   MMPoseInferencer: [{"frame_id": 0, "instances": [instance, ...]}, ...]
//               (frame_id from 0)
//               the demo: {"meta_info": {...}, "instance_info": [{"frame_id": 1,
//               "instances": [...]}, ...]} (frame_id from 1, as it counts frames)
//   instance    {"keypoints": [[x, y], ...], "keypoint_scores": [s, ...],
//                "bbox": [[x0, y0, x1, y1]] (or flat), "bbox_score": s}
//
// Keypoints are COCO-WholeBody's 133, or its first 17 (COCO body) or 23 (body and
// feet); the rest stay NaN. A null / NaN coordinate or score is a missing point. A
// per-video file may skip frames (they have no person); a frame_id given twice, or
// before the first, is an error. Errors name the file and the entry
// ("instance_info[3].instances[0].keypoints[5]").
#pragma once

#include <string>

#include "arco/mocap/detections.h"
#include "arco/util/status.h"

namespace arco {

// One file: a per-image file gives one frame, a per-video file one per frame_id.
StatusOr<CameraDetections> ParseMmposeJson(const std::string& text, const std::string& source);

// A per-video or per-image file, or a folder of per-image files (*.json, natural
// order: one frame each, file k = video frame k).
StatusOr<CameraDetections> ReadMmposeKeypoints(const std::string& path);

}  // namespace arco
