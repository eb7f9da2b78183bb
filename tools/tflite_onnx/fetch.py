#!/usr/bin/python3
"""Extracts the TFLite models from the packed npm packages and converts them to ONNX.

fetch.py PACKAGE_DIR OUT_DIR: PACKAGE_DIR holds the `npm pack` tarballs (scripts/fetch_models);
OUT_DIR receives tflite/NAME.tflite and NAME.onnx. A model is either a file of the
package or a byte range of its packed `.data` file, listed in the loader script's
`loadPackage({"files": [{"filename", "start", "end"}, ...]})` call. The TFLite files are
checked against SHA256SUMS before conversion, so only the pinned bytes are converted.
"""

import hashlib
import json
import os
import re
import sys
import tarfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from to_onnx import convert_file  # noqa: E402

HOLISTIC = "mediapipe-holistic-0.5.1675471629.tgz"
HANDS = "mediapipe-hands-0.4.1675469240.tgz"

# The landmark models' outputs arco reads (src/arco/detect/model_registry.cc): the landmarks
# and the presence score. The pose models' segmentation mask and heatmaps and the hand
# models' handedness and world landmarks are dropped with the layers only they need
# (to_onnx.py), so they are not computed on every frame.
LANDMARKS_AND_PRESENCE = ["Identity", "Identity_1"]

# name: (tarball, where: "file" or the packed-assets stem, outputs kept: None for all)
MODELS = {
    "pose_detection": (HOLISTIC, "holistic_solution_packed_assets", None),
    "pose_landmark_lite": (HOLISTIC, "file", LANDMARKS_AND_PRESENCE),
    "pose_landmark_full": (HOLISTIC, "file", LANDMARKS_AND_PRESENCE),
    "pose_landmark_heavy": (HOLISTIC, "file", LANDMARKS_AND_PRESENCE),
    "hand_landmark_full": (HOLISTIC, "holistic_solution_packed_assets", LANDMARKS_AND_PRESENCE),
    "hand_recrop": (HOLISTIC, "holistic_solution_packed_assets", None),
    "palm_detection_full": (HOLISTIC, "holistic_solution_packed_assets", None),
    "hand_landmark_lite": (HANDS, "file", LANDMARKS_AND_PRESENCE),
}


def read_member(tar, name):
    member = tar.extractfile("package/" + name)
    if member is None:
        raise SystemExit("fetch.py: %s: no package/%s" % (tar.name, name))
    return member.read()


def packed_files(tar, stem):
    """{basename: bytes} of the files packed into STEM.data, per the loader's byte ranges."""
    loader = read_member(tar, stem + "_loader.js").decode("utf-8")
    match = re.search(r'loadPackage\((\{"files":.*?\})\);', loader, re.S)
    if match is None:
        raise SystemExit("fetch.py: %s_loader.js: no loadPackage({\"files\": ...}) call" % stem)
    data = read_member(tar, stem + ".data")
    out = {}
    for entry in json.loads(match.group(1))["files"]:
        start, end = int(entry["start"]), int(entry["end"])
        if not 0 <= start <= end <= len(data):
            raise SystemExit("fetch.py: %s.data: range %d-%d outside its %d bytes"
                             % (stem, start, end, len(data)))
        out[os.path.basename(entry["filename"])] = data[start:end]
    return out


def main():
    package_dir, out_dir = sys.argv[1], sys.argv[2]
    sums_path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "SHA256SUMS")
    expected = {}
    with open(sums_path) as f:
        for line in f:
            digest, path = line.split()
            expected[path] = digest
    os.makedirs(os.path.join(out_dir, "tflite"), exist_ok=True)
    tars = {}
    packed = {}
    for name, (tarball, where, keep) in sorted(MODELS.items()):
        if tarball not in tars:
            tars[tarball] = tarfile.open(os.path.join(package_dir, tarball))
        tar = tars[tarball]
        filename = name + ".tflite"
        if where == "file":
            data = read_member(tar, filename)
        else:
            key = (tarball, where)
            if key not in packed:
                packed[key] = packed_files(tar, where)
            if filename not in packed[key]:
                raise SystemExit("fetch.py: %s.data holds no %s" % (where, filename))
            data = packed[key][filename]
        rel = "tflite/" + filename
        digest = hashlib.sha256(data).hexdigest()
        if digest != expected.get(rel):
            raise SystemExit("fetch.py: %s: SHA-256 %s, expected %s (tools/tflite_onnx/SHA256SUMS)"
                             % (rel, digest, expected.get(rel)))
        with open(os.path.join(out_dir, rel), "wb") as f:
            f.write(data)
        convert_file(os.path.join(out_dir, rel), os.path.join(out_dir, name + ".onnx"), name, keep)


if __name__ == "__main__":
    main()
