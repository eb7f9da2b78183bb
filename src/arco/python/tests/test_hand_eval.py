"""arco.HandModel (forward kinematics, bounded fingertip IK), arco.evaluate_pitch and arco.evaluate."""
import json

import numpy as np
import pytest

import arco

LEFT_HAND = slice(91, 112)  # COCO-WholeBody left hand in the result's points


def test_forward_kinematics_reproduces_the_result(result):
    r = arco.read_result(result)
    model = arco.HandModel("left", rest_points_mm=r["rest_points_mm"])
    np.testing.assert_allclose(model.bone_lengths_mm[1:], r["bone_lengths_mm"][1:], rtol=1e-12)
    np.testing.assert_array_equal(model.rest_points_mm, r["rest_points_mm"])
    # The performer's palm: the bases are not the average hand's, even sized to the bones.
    sized = arco.HandModel("left", r["bone_lengths_mm"])
    assert np.abs(sized.rest_points_mm[[1, 5, 9, 13, 17]] - r["rest_points_mm"][[1, 5, 9, 13, 17]]).max() > 0.05
    for method in ["vision", "paper", "arco"]:
        params = np.load(result / method / "hand_params.npy")
        points = model.forward_kinematics(params)
        assert points.shape == (len(params), 21, 3)
        np.testing.assert_allclose(points, r["points3d"][method][:, LEFT_HAND], atol=1e-9)
    # Any leading shape; a NaN row gives NaN points.
    params = np.load(result / "arco" / "hand_params.npy")[:6].reshape(2, 3, 26).copy()
    params[1, 2, 7] = np.nan
    points = model.forward_kinematics(params)
    assert points.shape == (2, 3, 21, 3)
    assert np.isnan(points[1, 2]).all() and np.isfinite(points[0]).all()


def test_fingertip_ik_reaches_and_respects_limits():
    model = arco.HandModel("left")
    assert model.side == "left" and len(model.keypoint_names) == 21 and len(model.dof_names) == 20
    lo, hi = model.limits_rad.T
    pose = np.zeros(26)
    pose[3:6] = [10.0, 20.0, 30.0]
    pose[6:] = np.clip(0.3, lo, hi)
    bent = pose.copy()
    index_pip, index_dip = 6 + 4 * 1 + 2, 6 + 4 * 1 + 3
    bent[index_pip] += 0.4
    bent[index_dip] += 0.2
    target = model.forward_kinematics(bent)[8]  # index tip
    ik = model.fingertip_ik(pose, 1, target)
    assert ik["converged"] and ik["final_distance_mm"] < 1e-3 < ik["initial_distance_mm"]
    np.testing.assert_allclose(model.forward_kinematics(ik["params"])[8], target, atol=1e-3)
    changed = np.flatnonzero(np.abs(ik["params"] - pose) > 1e-12)
    assert set(changed) <= {index_pip, index_dip}  # only PIP and DIP are free
    # A target out of reach: the solution stays inside the limits.
    far = model.fingertip_ik(pose, 1, target + [0, 0, 80.0], joints="all")
    assert far["final_distance_mm"] > 1
    assert np.all(far["params"][6:] >= lo - 1e-9) and np.all(far["params"][6:] <= hi + 1e-9)
    # Small steps: no angle moves more than max_change_deg.
    small = model.fingertip_ik(pose, 1, target, max_change_deg=5)
    assert np.max(np.abs(small["params"] - pose)) <= np.radians(5) + 1e-9


def test_hand_bad_inputs():
    model = arco.HandModel()
    with pytest.raises(ValueError, match=r"params must be \(\.\.\., 26\)"):
        model.forward_kinematics(np.zeros((4, 25)))
    with pytest.raises(ValueError, match="joints must be pip_dip"):
        model.fingertip_ik(np.zeros(26), 1, np.zeros(3), joints="knuckles")
    with pytest.raises(ValueError, match="finger 7 outside"):
        model.fingertip_ik(np.zeros(26), 7, np.zeros(3))
    with pytest.raises(ValueError, match="reference_weight_mm_per_rad"):
        model.fingertip_ik(np.zeros(26), 1, np.zeros(3), reference_weight_mm_per_rad=np.nan)
    with pytest.raises(ValueError, match="side must be left or right"):
        arco.HandModel("middle")
    with pytest.raises(ValueError, match=r"bone_lengths_mm must be \(21,\)"):
        arco.HandModel("left", np.ones(20))
    with pytest.raises(ValueError, match=r"rest_points_mm must be \(21, 3\)"):
        arco.HandModel("left", rest_points_mm=np.ones((20, 3)))
    with pytest.raises(ValueError, match="not both"):
        arco.HandModel("left", np.ones(21) * 30, rest_points_mm=np.zeros((21, 3)))


def test_evaluate_pitch():
    truth = np.array([220.0, 0.0, 440.0, 330.0, 330.0])
    est = np.array([221.0, 0.0, 0.0, 330.0 * 2 ** (30 / 1200), 330.0 * 2 ** (60 / 1200)])
    m = arco.evaluate_pitch(truth, est)
    assert m["frames"] == 5 and m["truth_voiced_frames"] == 4
    assert m["rpa50"] == pytest.approx(2 / 4) and m["rpa25"] == pytest.approx(1 / 4)
    assert m["voicing_recall"] == pytest.approx(3 / 4) and m["voicing_false_alarm"] == 0
    m2 = arco.evaluate_pitch(truth, est, scored=[True, True, False, True, False])
    assert m2["frames"] == 3 and m2["rpa50"] == pytest.approx(1.0)
    with pytest.raises(ValueError, match="one length"):
        arco.evaluate_pitch(truth, est[:3])


def test_evaluate_matches_arco_eval(arco_bin, capture, result, tmp_path):
    from conftest import cli_error, run_arco
    p = run_arco(arco_bin, "eval", result, "--truth", capture / "truth", "--pck-mm", 5, 15,
                 "-o", tmp_path / "eval.json")
    assert p.returncode == 0, p.stderr
    expected = json.loads((tmp_path / "eval.json").read_text())
    got = arco.evaluate(result, capture / "truth", pck_thresholds_mm=[5, 15])
    assert got == expected
    assert set(got["methods"]) >= {"vision", "paper", "arco"}
    with pytest.raises(ValueError, match="pck_thresholds_mm"):
        arco.evaluate(result, capture / "truth", pck_thresholds_mm=[np.nan])
    with pytest.raises(OSError) as e:
        arco.evaluate(tmp_path / "missing", capture / "truth")
    assert str(e.value) == cli_error(run_arco(arco_bin, "eval", tmp_path / "missing",
                                              "--truth", capture / "truth"))


def test_evaluate_pitch_strided():
    both = np.array([[220.0, 221.0], [330.0, 0.0], [440.0, 440.0]])
    m = arco.evaluate_pitch(both[:, 0], both[:, 1])
    assert m["frames"] == 3 and m["rpa50"] == pytest.approx(2 / 3)
