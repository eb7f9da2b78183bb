// Transitional: the keypoint layouts moved to the registry layer
// (arco/registry/keypoint_layout.h). Include that header; this one goes once the
// remaining includes (mocap/capture.h, refine/method_result.*, eval/evaluate.cc) switch.
#pragma once

#include "arco/registry/keypoint_layout.h"
