"""The stages of `arco run` one by one (arco.open_capture, arco.*_stage, arco.write_result)
against `arco run` on the same capture: every file of the result folder the same bytes."""
import pathlib

import numpy as np
import pytest

import arco


def files(folder):
    folder = pathlib.Path(folder)
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file())


@pytest.fixture(scope="module")
def stages(capture):
    """The capture opened once and every stage run on it, as `arco run --threads 2` runs them."""
    opened = arco.open_capture(capture, num_threads=2)
    triangulation = arco.triangulate_stage(opened)
    instrument = arco.instrument_stage(opened, triangulation)
    hand = arco.hand_stage(opened, triangulation, instrument)
    pitch = arco.pitch_stage(opened)
    methods = arco.refine_stage(opened, triangulation, instrument, hand, pitch)
    return opened, triangulation, instrument, hand, pitch, methods


def test_the_capture_is_opened_once_with_its_inputs(capture, stages):
    opened = stages[0]
    assert opened.capture_dir == str(capture)
    assert opened.has_audio
    assert opened.instrument == "cello"
    k = opened.keypoints2d
    assert k.shape == (opened.frames, len(opened.cameras), k.shape[2], 3)
    assert "frames" in repr(opened)


def test_each_stage_returns_its_record(capture, stages):
    opened, triangulation, instrument, hand, pitch, methods = stages
    frames = opened.frames
    assert triangulation.points3d.shape[0] == frames
    assert triangulation.points3d.shape[2] == 3
    assert triangulation.summary["frames"] == frames
    assert instrument.strings_mm.shape[:1] == (frames,)
    assert instrument.world_units_per_mm > 0
    assert hand.hand_params.shape == (frames, 26)
    assert np.isfinite(hand.hand_params).all(axis=1).mean() > 0.9
    assert pitch.ran and pitch.notes > 0
    assert len(pitch.frames["f0_hz"]) == frames
    assert [m.method for m in methods] == ["vision", "paper", "arco"]
    assert methods[2].summary["mode"] == "arco"
    assert methods[2].points3d.shape[0] == frames


def test_the_stages_write_what_arco_run_writes(stages, result, tmp_path):
    opened, triangulation, instrument, hand, pitch, methods = stages
    out = tmp_path / "result"
    arco.write_result(opened, out, triangulation, instrument, hand, pitch, methods)
    assert files(out) == files(result)
    for name in files(result):  # result.json too: no times, the same capture path
        assert (out / name).read_bytes() == (result / name).read_bytes(), name
    # The records are unchanged by writing: a second folder is the same.
    again = tmp_path / "again"
    arco.write_result(opened, again, triangulation, instrument, hand, pitch, methods)
    assert (again / "triangulation" / "points3d_raw.npy").read_bytes() == (
        result / "triangulation" / "points3d_raw.npy"
    ).read_bytes()
    # And the arrays the records show are the files' numbers.
    assert np.array_equal(
        np.load(result / "triangulation" / "points3d.npy"), triangulation.points3d, equal_nan=True
    )
    assert np.array_equal(
        np.load(result / "hand" / "hand_params.npy"), hand.hand_params, equal_nan=True
    )
    assert np.array_equal(
        np.load(result / "arco" / "points3d.npy"), methods[2].points3d, equal_nan=True
    )


def test_write_result_never_replaces_a_result_unless_asked(stages, result, tmp_path):
    opened, triangulation, instrument, hand, pitch, methods = stages
    out = tmp_path / "result"
    arco.write_result(opened, out, triangulation, instrument, hand, pitch, methods)
    with pytest.raises(RuntimeError, match="overwrite"):
        arco.write_result(opened, out, triangulation, instrument, hand, pitch, methods)
    arco.write_result(opened, out, triangulation, instrument, hand, pitch, methods, overwrite=True)
    assert (out / "arco" / "points3d.npy").read_bytes() == (result / "arco" / "points3d.npy").read_bytes()


def test_open_capture_bad_input(capture, tmp_path):
    with pytest.raises(OSError):
        arco.open_capture(tmp_path / "missing")
    with pytest.raises(ValueError, match="num_threads"):
        arco.open_capture(capture, num_threads=-1)
