"""arco.Instrument and arco.contact_point against the instrument model's physics."""
import numpy as np
import pytest

import arco


@pytest.mark.parametrize("name", ["violin", "viola", "cello", "double_bass"])
def test_ideal_string_positions(name):
    model = arco.Instrument(name)
    assert model.name == name and model.num_strings == 4
    L = model.string_length_mm
    for s in range(1, 5):
        f_open = model.open_hz(s)
        open_ = arco.contact_point(model, s, f_open)
        assert open_["kind"] == "open_string" and not open_["stopped"]
        assert open_["stop_from_bridge_mm"] == pytest.approx(L)
        assert np.isnan(open_["contact_from_bridge_mm"])
        octave = arco.contact_point(model, s, 2 * f_open)
        assert octave["kind"] == "stopped" and octave["string"] == s
        assert octave["contact_from_bridge_mm"] == pytest.approx(L / 2)
        assert octave["fraction_from_bridge"] == pytest.approx(0.5)
        assert octave["cents_from_open"] == pytest.approx(1200)
        fifth = arco.contact_point(name, s, 1.5 * f_open)  # by name too
        assert fifth["contact_from_bridge_mm"] == pytest.approx(L / 1.5)


def test_arrays_and_kinds():
    cello = arco.Instrument("cello")
    a = cello.open_hz(1)
    assert cello.open_note_name(1) == "A3" and a == pytest.approx(220)
    f0 = np.array([[0.0, a, 2 * a], [a / 2, 4 * a, 100 * a]])
    c = arco.contact_point(cello, 1, f0)
    assert c["f0_hz"].shape == c["contact_from_bridge_mm"].shape == f0.shape
    assert c["kind"].tolist() == [["no_pitch", "open_string", "stopped"],
                                  ["below_string", "stopped", "above_range"]]
    np.testing.assert_array_equal(c["stopped"], [[False, False, True], [False, True, False]])
    np.testing.assert_allclose(c["contact_from_bridge_mm"][0, 2], cello.string_length_mm / 2)
    np.testing.assert_allclose(c["contact_from_bridge_mm"][1, 1], cello.string_length_mm / 4)


def test_tuning_and_correction():
    baroque = arco.Instrument("cello", a4_hz=415)
    assert baroque.open_hz(1) == pytest.approx(207.5)
    plain = arco.contact_point("cello", 2, 2 * arco.Instrument("cello").open_hz(2))
    corrected = arco.contact_point("cello", 2, 2 * arco.Instrument("cello").open_hz(2),
                                   physical_correction=True)
    # Pressing makes the note sharp: the finger sits a little nearer the nut (farther from
    # the bridge), by millimetres, not centimetres.
    assert 0 < corrected["stop_from_bridge_mm"] - plain["stop_from_bridge_mm"] < 10


def test_bad_inputs():
    with pytest.raises(ValueError, match=r"string number 5 outside 1..4 \(1 = highest\)"):
        arco.contact_point("cello", 5, 220.0)
    with pytest.raises(ValueError, match="unknown instrument 'banjo'"):
        arco.contact_point("banjo", 1, 220.0)
    with pytest.raises(ValueError, match="open_tolerance_cents"):
        arco.contact_point("cello", 1, 220.0, open_tolerance_cents=float("nan"))
    with pytest.raises(ValueError, match="open_tolerance_cents"):
        arco.contact_point("cello", 1, 220.0, open_tolerance_cents=150)
    with pytest.raises(ValueError, match="a4_hz"):
        arco.Instrument("cello", a4_hz=float("nan"))


def test_strided_and_integer_inputs():
    f0 = np.array([220.0, 0.0, 440.0, 0.0, 880.0, 0.0])
    strided = arco.contact_point("cello", 1, f0[::2])
    np.testing.assert_allclose(strided["contact_from_bridge_mm"][1:],
                               arco.contact_point("cello", 1, [440, 880])["contact_from_bridge_mm"])
    assert arco.contact_point("cello", 1, 440)["fraction_from_bridge"] == pytest.approx(0.5)
