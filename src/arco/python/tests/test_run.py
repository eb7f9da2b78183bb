"""arco.run and arco.refine against `arco run` / `arco refine` on the same capture."""
import json
import shutil

import numpy as np
import pytest

import arco
from conftest import run_arco

# Files whose bytes depend only on the inputs and the options (result.json also records the
# capture's path and timings, checked field by field below).
COMPARED = [
    "triangulation/points3d.npy",
    "hand/hand_params.npy",
    "pitch.csv",
    "vision/points3d.npy",
    "paper/points3d.npy",
    "paper/contacts.csv",
    "arco/points3d.npy",
    "arco/contacts.csv",
    "arco/bowing.csv",
]


def test_run_writes_what_the_command_writes(capture, result, tmp_path):
    out = tmp_path / "result"
    summary = arco.run(capture, out, num_threads=1)
    assert summary["result_dir"] == str(out)
    assert [m["mode"] for m in summary["methods"]] == ["vision", "paper", "arco"]
    assert set(summary["timings_s"]) == {"triangulate", "instrument", "hands", "pitch", "refine"}
    assert all(t >= 0 for t in summary["timings_s"].values())
    for name in COMPARED:
        assert (out / name).read_bytes() == (result / name).read_bytes(), name
    mine = json.loads((out / "result.json").read_text())
    theirs = json.loads((result / "result.json").read_text())
    assert mine["stages"].keys() == theirs["stages"].keys()
    assert mine["frames"] == theirs["frames"]
    # The summary is the one result.json records for the arco method.
    arco_summary = summary["methods"][2]
    assert arco_summary["pressed"] > 0
    assert arco_summary["joint_limit_violations"] == 0


def test_run_never_replaces_a_result_unless_asked(capture, result, tmp_path):
    out = tmp_path / "result"
    shutil.copytree(result, out)
    before = (out / "arco" / "points3d.npy").read_bytes()
    with pytest.raises(RuntimeError, match="overwrite"):
        arco.run(capture, out)
    assert (out / "arco" / "points3d.npy").read_bytes() == before
    arco.run(capture, out, overwrite=True, num_threads=2)
    assert (out / "arco" / "points3d.npy").read_bytes() == before  # same for any thread count


def test_run_bad_input(capture, tmp_path):
    with pytest.raises(OSError):
        arco.run(tmp_path / "missing", tmp_path / "out")
    with pytest.raises(ValueError, match="num_threads|threads"):
        arco.run(capture, tmp_path / "out", num_threads=-1)
    assert not (tmp_path / "out").exists()


def test_refine_matches_the_command(arco_bin, result, tmp_path):
    mine, theirs = tmp_path / "mine", tmp_path / "theirs"
    shutil.copytree(result, mine)
    shutil.copytree(result, theirs)
    p = run_arco(arco_bin, "refine", theirs, "--mode", "paper", "--min-confidence", 0.7)
    assert p.returncode == 0, p.stderr
    summary = arco.refine(mine, mode="paper", min_confidence=0.7)
    assert summary["mode"] == "paper"
    for name in ["paper/points3d.npy", "paper/contacts.csv"]:
        assert (mine / name).read_bytes() == (theirs / name).read_bytes(), name
    # Another confidence threshold changes the paper's contacts.
    default = arco.refine(mine, mode="paper")
    assert (default["pressed"], default["uncertain"]) != (summary["pressed"], summary["uncertain"])
    with pytest.raises(ValueError, match="mode"):
        arco.refine(mine, mode="wrong")
    with pytest.raises(OSError):
        arco.refine(tmp_path / "missing")
