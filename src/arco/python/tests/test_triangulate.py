"""arco.triangulate: known points through the real SPD rig, and `arco triangulate`'s output."""
import json

import numpy as np
import pytest

import arco
from test_calibration import project


@pytest.fixture(scope="module")
def spd_rig(spd_dir):
    return arco.load_calibration(spd_dir / "cello_1113_scale_camera.xml")


def synthetic_views(cal, points3d):
    """(F, V, P, 3) [x, y, 1] of `points3d` (F, P, 3) in every camera; NaN where the point
    is behind the camera or outside the image."""
    F, P, _ = points3d.shape
    out = np.full((F, len(cal.cameras), P, 3), np.nan)
    for v, cam in enumerate(cal.cameras):
        pixels, depth = project(cam, points3d.reshape(-1, 3))
        seen = (depth > 0) & (pixels[:, 0] >= 0) & (pixels[:, 0] < cam.width) & \
               (pixels[:, 1] >= 0) & (pixels[:, 1] < cam.height)
        pixels[~seen] = np.nan
        out[:, v, :, :2] = pixels.reshape(F, P, 2)
        out[:, v, :, 2] = np.where(seen, 1.0, np.nan).reshape(F, P)
    return out


def test_recovers_known_points(spd_rig):
    # The rig looks at the player near the centroid of the camera centres; 1 unit ~ 2 m.
    centre = np.mean([c.center for c in spd_rig.cameras], axis=0)
    truth = centre + np.random.default_rng(7).uniform(-0.15, 0.15, (4, 30, 3))
    views = synthetic_views(spd_rig, truth)
    r = arco.triangulate(views.astype(np.float32), spd_rig, num_threads=2)
    assert r["points3d"].shape == (4, 30, 3)
    assert r["rms_reprojection_px"].shape == r["num_inliers"].shape == (4, 30)
    assert r["inlier_mask"].shape == (4, 30, 20) and r["inlier_mask"].dtype == bool
    # float32 pixels: about 1e-4 px of rounding, far below a micro-unit in 3D.
    np.testing.assert_allclose(r["points3d"], truth, atol=1e-5)
    assert np.nanmax(r["rms_reprojection_px"]) < 1e-3
    seen = np.isfinite(views[..., 0]).sum(axis=1)
    np.testing.assert_array_equal(r["num_views"], seen)
    np.testing.assert_array_equal(r["num_inliers"], seen)
    np.testing.assert_array_equal(r["inlier_mask"].sum(axis=2), r["num_inliers"])


def test_rejects_outliers_and_low_scores(spd_rig):
    centre = np.mean([c.center for c in spd_rig.cameras], axis=0)
    truth = centre + np.random.default_rng(3).uniform(-0.1, 0.1, (1, 10, 3))
    views = synthetic_views(spd_rig, truth)
    seen = np.isfinite(views[0, :, :, 0])
    bad_view = int(np.argmax(seen.all(axis=1)))  # a camera that sees every point
    views[0, bad_view, :, :2] += 200.0  # a gross outlier in one view
    low_view = (bad_view + 1) % 20
    views[0, low_view, :, 2] = 0.1  # below min_score: not used
    r = arco.triangulate(views, spd_rig)
    np.testing.assert_allclose(r["points3d"], truth, atol=1e-6)
    assert not r["inlier_mask"][0, :, bad_view].any()
    assert not r["inlier_mask"][0, :, low_view].any()
    # With min_score below the low view's score it is used again.
    r2 = arco.triangulate(views, spd_rig, min_score=0.05)
    assert r2["inlier_mask"][0, seen[low_view], low_view].all()


def test_too_few_views_give_nan(spd_rig):
    views = np.full((2, 20, 5, 3), np.nan)
    r = arco.triangulate(views, spd_rig)
    assert np.isnan(r["points3d"]).all() and (r["num_inliers"] == 0).all()


def test_matches_arco_triangulate(capture, triangulated):
    manifest = json.loads((capture / "capture.json").read_text())
    cal = arco.load_calibration(capture / manifest["calibration"])
    keypoints = np.load(capture / "keypoints2d.npy")
    cameras = [c["name"] for c in manifest["cameras"]]
    r = arco.triangulate(keypoints, cal, cameras=cameras, num_threads=2)
    t = triangulated / "triangulation"
    # The same code on the same input: identical, bit for bit.
    np.testing.assert_array_equal(r["points3d"], np.load(t / "points3d_raw.npy"))
    np.testing.assert_array_equal(r["rms_reprojection_px"], np.load(t / "reprojection_rms_px.npy"))
    np.testing.assert_array_equal(r["num_inliers"], np.load(t / "inlier_count.npy"))
    np.testing.assert_array_equal(r["num_views"], np.load(t / "view_count.npy"))
    np.testing.assert_array_equal(r["inlier_mask"], np.load(t / "inlier_mask.npy").astype(bool))
    # A calibration path works too, and serials name cameras as well as names.
    r2 = arco.triangulate(keypoints[:3], str(capture / manifest["calibration"]),
                          cameras=[c["serial"] for c in manifest["cameras"]])
    np.testing.assert_array_equal(r2["points3d"], r["points3d"][:3])


def test_bad_inputs(spd_rig):
    with pytest.raises(ValueError, match=r"keypoints2d must be \(frames, views, points, 3\).*got \(20, 5, 3\)"):
        arco.triangulate(np.zeros((20, 5, 3)), spd_rig)
    with pytest.raises(ValueError, match=r"got \(1, 20, 5, 2\)"):
        arco.triangulate(np.zeros((1, 20, 5, 2)), spd_rig)
    views = np.full((1, 20, 5, 3), np.nan)
    with pytest.raises(ValueError, match="min_score"):
        arco.triangulate(views, spd_rig, min_score=float("nan"))
    with pytest.raises(ValueError, match="max_reprojection_px"):
        arco.triangulate(views, spd_rig, max_reprojection_px=-1)
    with pytest.raises(ValueError, match="21 views, the calibration 20 cameras"):
        arco.triangulate(np.full((1, 21, 5, 3), np.nan), spd_rig)
    with pytest.raises(ValueError, match="no camera 'nope'"):
        arco.triangulate(views[:, :1], spd_rig, cameras=["nope"])
    with pytest.raises(ValueError, match="cameras names 1 cameras, keypoints2d has 20 views"):
        arco.triangulate(views, spd_rig, cameras=[0])
    with pytest.raises(OSError, match="file not found"):
        arco.triangulate(views, "/nonexistent/rig.xml")
    with pytest.raises(TypeError):
        arco.triangulate(views, spd_rig, 0.5)  # options are keyword-only
    # Integer pixels: the dtype rule of keypoints2d.npy (`arco triangulate` refuses them).
    with pytest.raises(ValueError, match="keypoints2d: dtype int64; keypoints2d must be float32 or float64"):
        arco.triangulate(np.zeros((1, 20, 5, 3), np.int64), spd_rig)


def test_any_float_dtype_and_layout(spd_rig):
    centre = np.mean([c.center for c in spd_rig.cameras], axis=0)
    truth = centre + np.random.default_rng(5).uniform(-0.1, 0.1, (2, 6, 3))
    views = synthetic_views(spd_rig, truth)
    ref = arco.triangulate(views, spd_rig)["points3d"]
    fortran = np.asfortranarray(views)
    np.testing.assert_array_equal(arco.triangulate(fortran, spd_rig)["points3d"], ref)
    np.testing.assert_array_equal(arco.triangulate(views.tolist(), spd_rig)["points3d"], ref)
    f32 = arco.triangulate(views.astype(np.float32), spd_rig)["points3d"]
    np.testing.assert_allclose(f32, ref, atol=1e-5)
    # Results own their memory, writable, C-contiguous.
    assert ref.flags.c_contiguous and ref.flags.writeable


def test_concurrent_calls_from_threads(capture):
    """The GIL is released during the work: calls from several Python threads run at once
    and give the same results as one call."""
    from concurrent.futures import ThreadPoolExecutor
    manifest = json.loads((capture / "capture.json").read_text())
    cal = arco.load_calibration(capture / manifest["calibration"])
    keypoints = np.load(capture / "keypoints2d.npy")[:20]
    cameras = [c["name"] for c in manifest["cameras"]]
    ref = arco.triangulate(keypoints, cal, cameras=cameras, num_threads=1)["points3d"]
    signal = np.sin(2 * np.pi * 220 * np.arange(44100) / 44100).astype(np.float32)
    pitch_ref = arco.track_pitch(signal, 44100)["f0_hz"]
    with ThreadPoolExecutor(4) as pool:
        tri = [pool.submit(arco.triangulate, keypoints, cal, cameras=cameras, num_threads=1)
               for _ in range(4)]
        pitch = [pool.submit(arco.track_pitch, signal, 44100) for _ in range(4)]
        for f in tri:
            np.testing.assert_array_equal(f.result()["points3d"], ref)
        for f in pitch:
            np.testing.assert_array_equal(f.result()["f0_hz"], pitch_ref)
