"""arco.read_result on a real `arco run` output."""
import json
import re
import shutil

import numpy as np
import pytest

import arco
from conftest import run_arco


def test_read_result(result):
    r = arco.read_result(str(result))
    manifest = json.loads((result / "result.json").read_text())
    assert r["result"] == manifest
    F = manifest["frames"]["count"] if isinstance(manifest["frames"], dict) else manifest["frames"]
    assert set(r["points3d"]) == set(r["keypoint_names"]) == {"triangulation", "vision", "paper", "arco"}
    assert r["keypoint_names"]["triangulation"] == manifest["keypoint_names"]
    for stage, points in r["points3d"].items():
        assert points.shape == (F, len(r["keypoint_names"][stage]), 3)
        np.testing.assert_array_equal(points, np.load(result / stage / "points3d.npy"))
    assert set(r["contacts"]) == {"paper", "arco"}
    for method, c in r["contacts"].items():
        rows = np.genfromtxt(result / method / "contacts.csv", delimiter=",", names=True,
                             dtype=None, encoding="utf-8")
        np.testing.assert_array_equal(c["frame"], np.arange(F))
        assert c["contact_mm"].shape == (F, 3)
        np.testing.assert_array_equal(c["state"], rows["state"])
        np.testing.assert_array_equal(c["string"], rows["string"])
        np.testing.assert_array_equal(c["finger"], rows["finger"])
        np.testing.assert_allclose(c["contact_mm"][:, 0], rows["contact_x_mm"], atol=1e-3)
        assert (c["state"] == "pressed").any()
    pitch = np.genfromtxt(result / "pitch.csv", delimiter=",", names=True)
    assert len(r["pitch"]["frame"]) == F
    np.testing.assert_allclose(r["pitch"]["f0_hz"], pitch["f0_hz"])
    np.testing.assert_array_equal(r["pitch"]["voiced"], pitch["voiced"].astype(bool))
    assert r["hand_params"].shape == (F, 26)
    inst = r["instrument"]
    assert inst["name"] == "cello" and inst["strings_mm"].shape == (F, 4, 2, 3)
    # The placed strings are as long as the model's, in mm.
    lengths = np.linalg.norm(inst["strings_mm"][:, :, 0] - inst["strings_mm"][:, :, 1], axis=-1)
    np.testing.assert_allclose(np.nanmedian(lengths), arco.Instrument("cello").string_length_mm,
                               rtol=1e-3)


def test_triangulation_only_result(triangulated):
    r = arco.read_result(triangulated)
    assert set(r["points3d"]) == {"triangulation"}
    assert r["contacts"] == {} and r["pitch"] is None and r["instrument"] is None
    assert r["hand_params"] is None


def test_bad_folders(tmp_path):
    with pytest.raises(OSError, match="no such result folder"):
        arco.read_result(tmp_path / "missing")
    with pytest.raises(OSError, match="result.json: not found"):
        arco.read_result(tmp_path)
    (tmp_path / "result.json").write_text("[1, 2")
    with pytest.raises(RuntimeError, match="result.json"):
        arco.read_result(tmp_path)


def test_a_result_whose_capture_changed_is_refused(arco_bin, capture, tmp_path):
    """docs/architecture.md, "Results are tied to their inputs": read_result re-hashes the
    capture files the result was made from, like every `arco` reader."""
    shutil.copytree(capture, tmp_path / "cap")
    p = run_arco(arco_bin, "triangulate", tmp_path / "cap", "-o", tmp_path / "res", "--threads", 2)
    assert p.returncode == 0, p.stderr
    assert set(arco.read_result(tmp_path / "res")["points3d"]) == {"triangulation"}
    npy = tmp_path / "cap" / "keypoints2d.npy"
    data = bytearray(npy.read_bytes())
    data[-1] ^= 1
    npy.write_bytes(bytes(data))
    with pytest.raises(RuntimeError, match=re.escape(
            f"{npy} changed since the result {tmp_path / 'res'} was made (re-run `arco run`)")):
        arco.read_result(tmp_path / "res")
