#!/usr/bin/python3
"""The converter's test: arco's two runtimes (XNNPACK, its default, and cv::dnn) on each
converted ONNX model against the numpy reference executor of its TFLite graph
(reference.py), on real image crops. arco's default choice ("auto") must run every model
with XNNPACK.

Crops come from ../shared/data/spd/example.jpg (a real cellist) and, when opencv-doc is
installed, its messi5.jpg; the C++ helper detect_run_model cuts them (python here has no
image decoder) and runs the ONNX model with arco's detect::Network. Every output must
agree to TOLERANCE, relative to the output's largest magnitude (docs/detect.md).

Models absent: skipped (exit 77) unless $CI is set, where it fails: `make test` runs
scripts/setup, which fetches and converts them.
"""

import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reference import Reference  # noqa: E402
from to_onnx import convert_file  # noqa: E402

# max |arco's runtime - reference| / max |reference| per output; measured worst 8.0e-6 on
# these crops (pose_landmark_heavy's landmarks), docs/detect.md. Set when the pose models still
# kept their segmentation logits (6.7e-5 here, 1.8e-4 on uniform noise).
TOLERANCE = 2e-4

XNNPACK, OPENCV = "xnnpack", "opencv"  # detect_run_model's runtime names

MODELS = {  # name: (input size, value range, output names in registry order)
    "pose_detection": (224, "-1,1", ["boxes", "scores"]),
    "pose_landmark_lite": (256, "0,1", ["landmarks", "presence"]),
    "pose_landmark_full": (256, "0,1", ["landmarks", "presence"]),
    "pose_landmark_heavy": (256, "0,1", ["landmarks", "presence"]),
    "hand_landmark_lite": (224, "0,1", ["landmarks", "presence"]),
    "hand_landmark_full": (224, "0,1", ["landmarks", "presence"]),
    "hand_recrop": (256, "0,1", ["crop"]),
    "palm_detection_full": (192, "0,1", ["boxes", "scores"]),
}

MESSI = "/usr/share/doc/opencv-doc/examples/data/messi5.jpg"


def crops_for(name, data_dir):
    """(label, image, cx, cy, side_px, angle_deg) crops of real photos for model `name`."""
    example = os.path.join(data_dir, "spd", "example.jpg")
    out = []
    if name == "pose_detection":
        out.append(("example whole", example, 1149.5, 1327.5, 2656, 0))
    elif name.startswith("pose_landmark"):
        out.append(("example player", example, 1150, 1350, 2200, 0))
    else:
        # The left hand on the fingerboard (docs/detect.md), fingers pointing left: the
        # crop is turned so that they point up, as the hand models expect.
        out.append(("example left hand", example, 1330, 880, 420, 90))
    if os.path.exists(MESSI):
        out.append(("messi5", MESSI, 273.5, 170.5, 548, 0))
    return out


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--runner", required=True)
    parser.add_argument("--models", required=True)
    parser.add_argument("--data", required=True)
    args = parser.parse_args()

    missing = [n for n in MODELS
               if not (os.path.exists(os.path.join(args.models, n + ".onnx")) and
                       os.path.exists(os.path.join(args.models, "tflite", n + ".tflite")))]
    if missing:
        message = ("models missing in %s (%s): run scripts/setup to fetch and convert them"
                   % (args.models, ", ".join(missing)))
        if os.environ.get("CI"):
            print("FAIL: " + message)
            return 1
        print("SKIPPED: " + message + " (CI is unset)")
        return 77

    env = dict(os.environ, ARCO_MODELS_DIR=args.models)  # the runner reads this folder
    failures = 0
    with tempfile.TemporaryDirectory() as tmp:
        for name, (size, value_range, outputs) in MODELS.items():
            reference = Reference(os.path.join(args.models, "tflite", name + ".tflite"))
            for k, (label, image, cx, cy, side, angle) in enumerate(crops_for(name, args.data)):
                crop = os.path.join(tmp, "input.npy")
                subprocess.run([args.runner, "crop", image, str(cx), str(cy), str(side),
                                str(angle), str(size), value_range, crop], check=True)
                expected = list(reference.run(np.load(crop)).values())
                if k == 0:
                    subprocess.run([args.runner, name, crop, tmp, "1", "auto"], check=True, env=env)
                    with open(os.path.join(tmp, "runtime.txt")) as f:
                        chosen = f.read().strip()
                    if chosen != XNNPACK:
                        print("FAIL %s: arco runs it with %s, not %s" % (name, chosen, XNNPACK))
                        failures += 1
                for runtime in (XNNPACK, OPENCV):
                    subprocess.run([args.runner, name, crop, tmp, "2", runtime], check=True, env=env)
                    failures += compare(name, "%s %s" % (label, runtime), outputs, expected, tmp)
        failures += unread_heads_refused(args, tmp)
    print("worst relative error %.2e (tolerance %.0e); %d failure(s)" % (WORST[0], TOLERANCE, failures))
    return 1 if failures else 0


WORST = [0.0]


def compare(name, label, outputs, expected, tmp):
    """Prints the runner's outputs in `tmp` against `expected`; returns the failures."""
    failures = 0
    parts = []
    for out_name, want in zip(outputs, expected):
        got = np.load(os.path.join(tmp, out_name + ".npy"))
        if got.shape != want.shape:
            print("FAIL %s %s %s: shape %s, reference %s"
                  % (name, label, out_name, got.shape, want.shape))
            failures += 1
            continue
        scale = max(float(np.abs(want).max()), 1e-6)
        error = float(np.abs(got.astype(np.float64) - want).max()) / scale
        WORST[0] = max(WORST[0], error)
        if not error <= TOLERANCE:
            failures += 1
            parts.append("%s %.1e FAIL" % (out_name, error))
        else:
            parts.append("%s %.1e" % (out_name, error))
    print("%-20s %-26s %s" % (name, label, "  ".join(parts)))
    return failures


def unread_heads_refused(args, tmp):
    """A pose model converted with every head (segmentation, heatmaps, world landmarks) must
    be refused by arco's loader, naming the heads, so a stale models folder is converted
    again instead of computing them on every frame. Returns the number of failures."""
    name = "pose_landmark_lite"
    stale = os.path.join(tmp, "stale")
    os.makedirs(stale, exist_ok=True)
    convert_file(os.path.join(args.models, "tflite", name + ".tflite"),
                 os.path.join(stale, name + ".onnx"), name)
    crop = os.path.join(tmp, "input.npy")
    wanted = ("the model computes outputs arco does not read ('Identity_2', 'Identity_3', "
              "'Identity_4'); run scripts/setup to convert it again")
    failures = 0
    for runtime in (XNNPACK, OPENCV):
        run = subprocess.run([args.runner, name, crop, tmp, "1", runtime], capture_output=True,
                             text=True, env=dict(os.environ, ARCO_MODELS_DIR=stale))
        if run.returncode == 0 or wanted not in run.stderr:
            print("FAIL %s with every head, %s: exit %d, stderr %r"
                  % (name, runtime, run.returncode, run.stderr))
            failures += 1
        else:
            print("%-20s %-26s refused: %s" % (name, "with every head " + runtime, wanted))
    return failures


if __name__ == "__main__":
    sys.exit(main())
