"""Independent checks of `arco overlay` videos (overlay_cli_test.sh): Python with numpy
and Debian's ffmpeg/ffprobe command-line tools only, nothing of arco's.

  overlay_check.py VIDEO RESULT_DIR CAMERA SCALE FIRST LAST [SOURCE_VIDEO ROTATE_DEG]

Decodes VIDEO with ffmpeg, checks its frame count (LAST - FIRST + 1) and rate (the
capture's fps), projects the method's left fingertips (arco/points3d.npy) into CAMERA with
the calibration's pinhole + Brown-Conrady model (OpenCV's formulas, written out here) and
checks that each projected tip's pixel is the overlay's fingertip colour (magenta) at
several frames. With SOURCE_VIDEO: the overlay's background away from the drawing is the
source video turned clockwise by ROTATE_DEG and scaled by SCALE.
"""
import json
import os
import subprocess
import sys

import numpy as np

video, result, camera, scale, first, last = sys.argv[1:7]
scale, first, last = float(scale), int(first), int(last)
source = sys.argv[7] if len(sys.argv) > 7 else None
rotate = int(sys.argv[8]) if len(sys.argv) > 8 else 0


def probe(path, count_frames=True):
    count = ["-count_frames"] if count_frames else []  # decodes every frame to count them
    out = subprocess.run(
        ["ffprobe", "-v", "error", "-select_streams", "v:0", *count, "-show_entries",
         "stream=width,height,r_frame_rate,nb_read_frames", "-of", "json", path],
        check=True, capture_output=True, text=True).stdout
    return json.loads(out)["streams"][0]


def decode(path, w, h, only=None):
    """Every frame of PATH; with ONLY (frame indices), a dict of just those frames."""
    select = []
    if only is not None:
        only = sorted(set(only))
        select = ["-vf", "select=" + "+".join(f"eq(n\\,{i})" for i in only),
                  "-fps_mode", "passthrough"]
    raw = subprocess.run(["ffmpeg", "-v", "error", "-i", path, *select, "-f", "rawvideo",
                          "-pix_fmt", "rgb24", "-"], check=True, capture_output=True).stdout
    frames = np.frombuffer(raw, np.uint8).reshape(-1, h, w, 3)
    if only is None:
        return frames
    if len(frames) != len(only):
        sys.exit(f"{path}: {len(frames)} of the frames {only} decoded")
    return dict(zip(only, frames))


res = json.load(open(os.path.join(result, "result.json")))
capture_dir = res["capture"]
if not os.path.isabs(capture_dir):
    capture_dir = os.path.join(result, capture_dir)
cap = json.load(open(os.path.join(capture_dir, "capture.json")))
fps = float(cap["fps"]) if not isinstance(cap["fps"], dict) else float(cap["fps"]["value"])
frame_first = int(res["frames"]["first"]) if isinstance(res.get("frames"), dict) else 1
p = probe(video)
num, den = (int(x) for x in p["r_frame_rate"].split("/"))
frames = int(p["nb_read_frames"])
w, h = int(p["width"]), int(p["height"])
errors = []
if frames != last - first + 1:
    errors.append(f"{frames} frames, expected {last - first + 1}")
if abs(num / den - fps) > 1e-9:
    errors.append(f"rate {num}/{den}, capture fps {fps}")

cal = json.load(open(os.path.join(capture_dir, cap["calibration"])))
cam_entry = next(c for c in cap["cameras"] if c["name"] == camera)
c = next(x for x in cal["cameras"] if x["name"] == camera or x.get("serial") == cam_entry.get("serial"))
K = np.array(c["K"], float).reshape(3, 3)
R = np.array(c["R"], float).reshape(3, 3)
t = np.array(c["t"], float)
d = c["distortion"]
units_per_mm = float(res["stages"]["instrument"]["world_units_per_mm"])
names = res["stages"]["arco"]["keypoint_names"]
points = np.load(os.path.join(result, "arco", "points3d.npy"))


def project(x_mm, distort=True):
    xc = R @ (x_mm * units_per_mm) + t
    x, y = xc[0] / xc[2], xc[1] / xc[2]
    r2 = x * x + y * y
    radial = 1 + d["k1"] * r2 + d["k2"] * r2 ** 2 + d["k3"] * r2 ** 3
    xd = x * radial + 2 * d["p1"] * x * y + d["p2"] * (r2 + 2 * x * x)
    yd = y * radial + d["p1"] * (r2 + 2 * y * y) + 2 * d["p2"] * x * y
    if not distort:
        xd, yd = x, y
    u = K[0, 0] * xd + K[0, 1] * yd + K[0, 2]
    v = K[1, 1] * yd + K[1, 2]
    return (u + 0.5) * scale - 0.5, (v + 0.5) * scale - 0.5  # output pixel centres


pix = decode(video, w, h)
tips = [names.index(f"left_hand_{f}_tip") for f in ("thumb", "index", "middle", "ring", "little")]
checked = 0
# Tips whose pinhole-only pixel (no distortion) is off the mark: with MIN_SHIFTED set, at
# least that many, so the check tells a distorted projection from an undistorted one.
shifted = 0
magenta = lambda rgb: rgb[0] > 190 and rgb[1] < 90 and rgb[2] > 190
for k in np.linspace(0, len(pix) - 1, 6).round().astype(int):
    row = first - frame_first + k
    for tip in tips:
        x = points[row, tip]
        if not np.all(np.isfinite(x)):
            continue
        u, v = project(x)
        iu, iv = int(round(u)), int(round(v))
        if not (0 <= iu < w and 0 <= iv < h):
            continue
        rgb = pix[k, iv, iu].astype(int)
        if not magenta(rgb):
            errors.append(f"frame {k}: tip {names[tip]} at ({u:.1f}, {v:.1f}) is {rgb.tolist()}")
        checked += 1
        pu, pv = project(x, distort=False)
        pu, pv = int(round(pu)), int(round(pv))
        if 0 <= pu < w and 0 <= pv < h and not magenta(pix[k, pv, pu].astype(int)):
            shifted += 1
if checked < 10:
    errors.append(f"only {checked} tips checked")
min_shifted = int(os.environ.get("MIN_SHIFTED", "0"))
if shifted < min_shifted:
    errors.append(f"only {shifted} tips where the undistorted projection misses the mark "
                  f"(wanted {min_shifted}): the check cannot see the distortion")
# Not everything is magenta: the corners are not.
for (yy, xx) in ((h - 3, 2), (h - 3, w - 3)):
    if magenta(pix[0, yy, xx].astype(int)):
        errors.append(f"pixel ({xx}, {yy}) is magenta too")

if source:
    sp = probe(source, count_frames=False)  # its size only
    sw, sh = int(sp["width"]), int(sp["height"])
    compared = (0, len(pix) - 1)
    # Only the frames compared (decoding every frame at full size took 10 s).
    src = decode(source, sw, sh, [first - frame_first + k for k in compared])
    turned = lambda img, deg: np.rot90(img, -deg // 90)  # clockwise
    n = int(1 / scale)
    for k in compared:
        # The n x n block means, summed in float (no float copy of the full-size frame).
        img = turned(src[first - frame_first + k], rotate)
        hh, ww = img.shape[0] // n, img.shape[1] // n
        small = img[:hh * n, :ww * n].reshape(hh, n, ww, n, 3).mean(axis=(1, 3), dtype=float)
        out = pix[k, :hh, :ww].astype(float)
        # Compare away from the drawing: the bottom-right quarter's median difference.
        diff = np.median(np.abs(out[hh // 2:, ww // 2:] - small[hh // 2:, ww // 2:]))
        wrong = turned(src[first - frame_first + k], (rotate + 180) % 360)
        wrong = wrong[:hh * n, :ww * n].reshape(hh, n, ww, n, 3).mean(axis=(1, 3), dtype=float)
        diff_wrong = np.median(np.abs(out[hh // 2:, ww // 2:] - wrong[hh // 2:, ww // 2:]))
        if not (diff < 8 and diff_wrong > 3 * diff + 8):
            errors.append(f"frame {k}: background differs from the turned source by {diff:.1f} "
                          f"(the other way round: {diff_wrong:.1f})")

if errors:
    print("\n".join(errors))
    sys.exit(1)
print(f"ok: {frames} frames at {num}/{den} fps, {checked} fingertips on their marks "
      f"({shifted} where a projection without distortion misses)")
