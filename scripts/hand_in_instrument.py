#!/usr/bin/python3
"""The left hand in the instrument's frame, against SPD's (issue 26's one-camera measure).

One camera places the instrument and the hand at a depth it cannot measure (the nominal
instrument's size sets it), so the hand is compared where a player's hand is judged: in
the instrument's own frame (origin the bridge's middle, x to the nut's, y across the
strings), ours in the frame of our instrument, SPD's in the frame of SPD's.

usage: hand_in_instrument.py RESULT_DIR TRUTH_POINTS3D [METHOD ...]
Prints per method: the median over frames of the 21 joints' mean error (mm), the fraction
of all frames within 15 mm, and the fraction of frames with a hand; then where that error
lies: the wrist's median signed offset along the strings (+: toward the nut), across them
and off the top, and the median error left once each frame's mean offset (the hand's
translation) is taken away (the hand's orientation and shape); then (paper, arco) the
contact point against SPD's, each in its own instrument's frame (the truth folder's
contact.csv beside TRUTH_POINTS3D). As a module:
left_hand_in_instrument(result_dir, truth_points3d, method) -> those three numbers;
left_hand_error_parts(result_dir, truth_points3d, method) -> (wrist offset x, y, z,
error without the translation); contact_in_instrument(result_dir, truth_points3d, method)
-> (mean, median, fraction within 5 mm, frames).
"""
import json
import os
import sys

import numpy as np


def _frame(points, col):
    nut_l, nut_r = points[:, col("nut_l")], points[:, col("nut_r")]
    br_l, br_r = points[:, col("bridge_l")], points[:, col("bridge_r")]
    nut, bridge = 0.5 * (nut_l + nut_r), 0.5 * (br_l + br_r)
    x = nut - bridge
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    across = (nut_l - nut_r) + (br_l - br_r)
    y = across - np.sum(across * x, 1, keepdims=True) * x
    y /= np.linalg.norm(y, axis=1, keepdims=True)
    return bridge, np.stack([x, y, np.cross(x, y)], 1)


def _in_frame(points, bridge, rows):
    return np.einsum("fij,fpj->fpi", rows, points - bridge[:, None])


def _hands_in_frame(result_dir, truth_points3d, method):
    names = json.load(open(result_dir + "/result.json"))["keypoint_names"]
    col = names.index
    hand = list(range(col("left_hand_wrist"), col("left_hand_wrist") + 21))
    truth = np.load(truth_points3d)  # its first columns are the result's layout
    ours = np.load("%s/%s/points3d.npy" % (result_dir, method))
    want = _in_frame(truth[:, hand], *_frame(truth, col))
    got = _in_frame(ours[:, hand], *_frame(ours, col))
    return got, want


def left_hand_error_parts(result_dir, truth_points3d, method):
    got, want = _hands_in_frame(result_dir, truth_points3d, method)
    offset = got - want
    framed = np.isfinite(offset).all(axis=(1, 2))
    if not framed.any():
        return float("nan"), float("nan"), float("nan"), float("nan")
    offset = offset[framed]
    wrist = np.median(offset[:, 0], axis=0)
    shape = offset - offset.mean(axis=1, keepdims=True)
    without_translation = np.median(np.linalg.norm(shape, axis=2).mean(axis=1))
    return float(wrist[0]), float(wrist[1]), float(wrist[2]), float(without_translation)


def left_hand_in_instrument(result_dir, truth_points3d, method):
    got, want = _hands_in_frame(result_dir, truth_points3d, method)
    distances = np.linalg.norm(got - want, axis=2)
    counted = np.isfinite(distances).sum(1)
    error = np.where(counted > 0, np.nansum(distances, 1) / np.maximum(counted, 1), np.nan)
    fitted = np.isfinite(error)
    if not fitted.any():
        return float("nan"), 0.0, 0.0
    return (float(np.median(error[fitted])), float(np.sum(error[fitted] <= 15) / len(error)),
            float(fitted.mean()))


def contact_in_instrument(result_dir, truth_points3d, method):
    """The method's contact point against SPD's, each in its own instrument's frame, over
    the frames both call pressed: (mean, median, fraction within 5 mm, frames)."""
    import csv
    names = json.load(open(result_dir + "/result.json"))["keypoint_names"]
    col = names.index
    ours = np.load("%s/%s/points3d.npy" % (result_dir, method))
    truth = np.load(truth_points3d)
    ours_frame, truth_frame = _frame(ours, col), _frame(truth, col)
    got_rows = list(csv.DictReader(open("%s/%s/contacts.csv" % (result_dir, method))))
    want_rows = list(csv.DictReader(open(os.path.join(os.path.dirname(truth_points3d),
                                                      "contact.csv"))))
    point = lambda r: np.array([float(r["contact_%s_mm" % c]) for c in "xyz"])
    errors = []
    for f, (got, want) in enumerate(zip(got_rows, want_rows)):
        if got["state"] != "pressed" or want["state"] != "pressed":
            continue
        g = ours_frame[1][f] @ (point(got) - ours_frame[0][f])
        w = truth_frame[1][f] @ (point(want) - truth_frame[0][f])
        if np.isfinite(g).all() and np.isfinite(w).all():
            errors.append(np.linalg.norm(g - w))
    if not errors:
        return float("nan"), float("nan"), 0.0, 0
    errors = np.array(errors)
    return (float(errors.mean()), float(np.median(errors)), float(np.mean(errors <= 5)),
            len(errors))


if __name__ == "__main__":
    for m in sys.argv[3:] or ["vision", "paper", "arco"]:
        median, within, fitted = left_hand_in_instrument(sys.argv[1], sys.argv[2], m)
        print("%-6s median %.1f mm, within 15 mm on %.3f of frames, a hand on %.3f"
              % (m, median, within, fitted))
        x, y, z, shape = left_hand_error_parts(sys.argv[1], sys.argv[2], m)
        print("%-6s wrist off by %+.1f / %+.1f / %+.1f mm (along toward the nut / across / off "
              "the top), %.1f mm once each frame's translation is taken away"
              % (m, x, y, z, shape))
        if os.path.exists("%s/%s/contacts.csv" % (sys.argv[1], m)) and m != "vision":
            mean, median, within, n = contact_in_instrument(sys.argv[1], sys.argv[2], m)
            print("%-6s contact %.2f mm from SPD's in the instrument's frame (median %.2f), "
                  "within 5 mm on %.3f of the %d frames both call pressed"
                  % (m, mean, median, within, n))
