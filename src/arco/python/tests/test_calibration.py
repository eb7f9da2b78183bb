"""arco.load_calibration: cameras as numpy attributes, their projection, errors."""
import numpy as np
import pytest

import arco
from conftest import cli_error, run_arco


def project(camera, points):
    """OpenCV's pinhole + k1 k2 p1 p2 k3 model in numpy, from the exported attributes."""
    pc = points @ camera.R.T + camera.t
    x, y = pc[:, 0] / pc[:, 2], pc[:, 1] / pc[:, 2]
    k1, k2, p1, p2, k3 = camera.distortion
    r2 = x * x + y * y
    radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3))
    xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x)
    yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y
    K = camera.K
    return np.stack([K[0, 0] * xd + K[0, 1] * yd + K[0, 2], K[1, 1] * yd + K[1, 2]], axis=1), pc[:, 2]


def test_spd_xml_cameras(spd_dir):
    cal = arco.load_calibration(spd_dir / "cello_1113_scale_camera.xml")
    assert len(cal) == len(cal.cameras) == 20
    assert cal.format == "metashape-xml" and cal.units == "metashape"
    for cam in cal.cameras:
        assert cam.name.startswith("camera_")
        assert cam.size == (2300, 2656) and (cam.width, cam.height) == cam.size
        assert cam.K.shape == (3, 3) and cam.K[2, 2] == 1
        assert cam.distortion.shape == (5,)
        np.testing.assert_allclose(cam.R @ cam.R.T, np.eye(3), atol=1e-9)
        assert np.linalg.det(cam.R) > 0
        np.testing.assert_allclose(cam.center, -cam.R.T @ cam.t, atol=1e-12)
    assert cal.camera("21334181").serial == "21334181"


def test_numpy_projection_matches_camera_project(spd_dir):
    cal = arco.load_calibration(str(spd_dir / "cello_1113_scale_camera.xml"))
    centre = np.mean([c.center for c in cal.cameras], axis=0)
    points = centre + np.random.default_rng(1).uniform(-0.1, 0.1, (50, 3))
    for cam in cal.cameras:
        pixels, depth = project(cam, points)
        expected = cam.project(points)
        front = depth > 0
        np.testing.assert_allclose(expected[front], pixels[front], atol=1e-6)
        assert np.isnan(expected[~front]).all()


def test_save_and_reload(spd_dir, tmp_path):
    cal = arco.load_calibration(spd_dir / "cello_1113_scale_camera.xml")
    cal.save(str(tmp_path / "rig.yaml"))
    again = arco.load_calibration(tmp_path / "rig.yaml")
    assert [c.name for c in again.cameras] == [c.name for c in cal.cameras]
    for a, b in zip(cal.cameras, again.cameras):
        np.testing.assert_allclose(a.K, b.K, rtol=1e-9)
        np.testing.assert_allclose(a.R, b.R, atol=1e-9)


def test_missing_file_is_oserror_with_the_cli_message(arco_bin, tmp_path):
    missing = tmp_path / "missing.xml"
    with pytest.raises(OSError) as e:
        arco.load_calibration(missing)
    assert str(e.value) == cli_error(run_arco(arco_bin, "calibration", "show", missing))


def test_malformed_file_is_runtimeerror(arco_bin, tmp_path):
    bad = tmp_path / "bad.txt"
    bad.write_text("hello")
    with pytest.raises(RuntimeError) as e:
        arco.load_calibration(bad)
    assert str(e.value) == cli_error(run_arco(arco_bin, "calibration", "show", bad))


def test_calibration_from_arrays(spd_dir, tmp_path):
    cal = arco.load_calibration(spd_dir / "cello_1113_scale_camera.xml")
    cameras = [arco.Camera(c.name, c.K, c.distortion, c.R, c.t, c.size, serial=c.serial)
               for c in cal.cameras]
    rebuilt = arco.Calibration(cameras, units=cal.units)
    assert len(rebuilt) == 20 and rebuilt.units == "metashape"
    points = np.mean([c.center for c in cal.cameras], axis=0) + np.zeros((4, 3))
    for a, b in zip(cal.cameras, rebuilt.cameras):
        np.testing.assert_array_equal(a.project(points), b.project(points))
    rebuilt.save(tmp_path / "rig.json", format="arco")
    again = arco.load_calibration(tmp_path / "rig.json")
    assert again.format == "arco-json"
    np.testing.assert_allclose(again.cameras[3].K, cal.cameras[3].K)


def test_camera_bad_arrays(spd_dir):
    c = arco.load_calibration(spd_dir / "cello_1113_scale_camera.xml").cameras[0]
    with pytest.raises(ValueError, match=r"K must be \(3, 3\), got \(3, 4\)"):
        arco.Camera("a", np.zeros((3, 4)), c.distortion, c.R, c.t, c.size)
    with pytest.raises(ValueError, match=r"distortion must be \(5,\), got \(4,\)"):
        arco.Camera("a", c.K, np.zeros(4), c.R, c.t, c.size)
    with pytest.raises(ValueError, match="camera 'a': rotation is not a proper rotation matrix"):
        arco.Camera("a", c.K, c.distortion, 2 * c.R, c.t, c.size)
    with pytest.raises(ValueError, match="camera 'a': focal lengths must be positive"):
        arco.Camera("a", c.K * [[-1], [1], [1]], c.distortion, c.R, c.t, c.size)
    with pytest.raises(ValueError, match="camera 'a': pose is not finite"):
        arco.Camera("a", c.K, c.distortion, c.R, [np.nan, 0, 0], c.size)
    with pytest.raises(ValueError):
        arco.Calibration([c, c])  # duplicate names
