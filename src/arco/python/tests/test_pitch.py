"""arco.track_pitch: the rows `arco pitch` writes, from a numpy signal."""
import wave

import numpy as np
import pytest

import arco
from conftest import cli_error, run_arco


def write_tone(path, rate_hz=44100):
    """A 2.5 s 16-bit mono WAV: silence, 220 Hz, 330 Hz, 146.8 Hz (two harmonics each)."""
    t = np.arange(int(rate_hz * 2.5)) / rate_hz
    f = np.select([t < 1.0, t < 1.8], [220.0, 330.0], 146.83)
    phase = 2 * np.pi * np.cumsum(f) / rate_hz
    x = 0.5 * np.sin(phase) + 0.2 * np.sin(2 * phase)
    x[t < 0.2] = 0
    pcm = np.round(x * 32767).astype("<i2")
    with wave.open(str(path), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(rate_hz)
        w.writeframes(pcm.tobytes())
    return pcm


def read_pitch_csv(path):
    return np.genfromtxt(path, delimiter=",", names=True)


@pytest.mark.parametrize("fps,instrument,extra,kwargs", [
    (25, "cello", [], {}),
    (30, "violin", ["--start-s", 0.1, "--frames", 40], {"start_s": 0.1, "frames": 40}),
    (59.94, "any", ["--hops-per-frame", 3, "--a4", 442], {"hops_per_frame": 3, "a4_hz": 442}),
])
def test_rows_match_arco_pitch(arco_bin, tmp_path, fps, instrument, extra, kwargs):
    pcm = write_tone(tmp_path / "tone.wav")
    p = run_arco(arco_bin, "pitch", tmp_path / "tone.wav", "-o", tmp_path / "pitch.csv",
                 "--fps", fps, "--instrument", instrument, *extra)
    assert p.returncode == 0, p.stderr
    rows = read_pitch_csv(tmp_path / "pitch.csv")
    # libsndfile reads 16-bit PCM as x / 32768.
    got = arco.track_pitch(pcm.astype(np.float32) / 32768, 44100, fps, instrument, **kwargs)
    assert set(got) == {"frame", "time_s", "f0_hz", "confidence", "voiced"}
    assert len(got["frame"]) == len(rows) > 0
    np.testing.assert_array_equal(got["frame"], rows["frame"])
    # pitch.csv holds time_s to 6 decimals, f0_hz and confidence to 4.
    np.testing.assert_allclose(got["time_s"], rows["time_s"], atol=5e-7)
    np.testing.assert_allclose(got["f0_hz"], rows["f0_hz"], atol=5e-5)
    np.testing.assert_allclose(got["confidence"], rows["confidence"], atol=5e-5)
    np.testing.assert_array_equal(got["voiced"], rows["voiced"].astype(bool))
    assert got["voiced"].dtype == bool and got["voiced"].any()


def test_real_stereo_recording_matches_arco_pitch(arco_bin, spd_dir, tmp_path):
    """SPD's cello scale (48 kHz 16-bit stereo): (frames, channels) samples are mixed down
    as the WAV reader does."""
    wav = spd_dir / "background.wav"
    p = run_arco(arco_bin, "pitch", wav, "-o", tmp_path / "pitch.csv")
    assert p.returncode == 0, p.stderr
    rows = read_pitch_csv(tmp_path / "pitch.csv")
    with wave.open(str(wav)) as w:
        rate = w.getframerate()
        pcm = np.frombuffer(w.readframes(w.getnframes()), "<i2").reshape(-1, w.getnchannels())
    assert pcm.shape[1] == 2
    got = arco.track_pitch(pcm.astype(np.float32) / 32768, rate)
    assert len(got["frame"]) == len(rows) == 612
    np.testing.assert_allclose(got["f0_hz"], rows["f0_hz"], atol=5e-5)
    np.testing.assert_allclose(got["confidence"], rows["confidence"], atol=5e-5)
    np.testing.assert_array_equal(got["voiced"], rows["voiced"].astype(bool))
    # The scale starts on the open C string (C2, 65.4 Hz; within 50 cents: attack, tuning).
    first = got["f0_hz"][got["voiced"]][:10]
    np.testing.assert_allclose(np.median(first), 65.41, rtol=0.03)


def test_pitch_values(tmp_path):
    pcm = write_tone(tmp_path / "tone.wav", 48000)
    got = arco.track_pitch(pcm / 32768.0, 48000, 30)  # float64 input is converted
    t, f0 = got["time_s"], got["f0_hz"]
    assert not got["voiced"][t < 0.15].any()
    for lo, hi, hz in [(0.3, 0.9, 220.0), (1.1, 1.7, 330.0), (1.9, 2.4, 146.83)]:
        sel = (t > lo) & (t < hi)
        assert got["voiced"][sel].all()
        np.testing.assert_allclose(f0[sel], hz, rtol=2e-3)


def test_bad_inputs(arco_bin, tmp_path):
    x = np.zeros(8000, np.float32)
    with pytest.raises(ValueError, match=r"samples must be \(frames,\) or \(frames, channels\), got \(2, 2, 2000\)"):
        arco.track_pitch(x.reshape(2, 2, -1), 8000, 30)
    with pytest.raises(ValueError, match="samples have 0 channels"):
        arco.track_pitch(np.zeros((10, 0)), 8000, 30)
    with pytest.raises(ValueError, match="fps must be a finite number"):
        arco.track_pitch(x, 8000, float("nan"))
    with pytest.raises(ValueError, match="fps"):
        arco.track_pitch(x, 8000, 0)
    with pytest.raises(ValueError, match="a4_hz"):
        arco.track_pitch(x, 8000, 30, a4_hz=float("inf"))
    with pytest.raises(ValueError, match="min_f0_hz must be below max_f0_hz"):
        arco.track_pitch(x, 8000, 30, min_f0_hz=500, max_f0_hz=100)
    # Non-finite samples: the readers' check (a float WAV holding them is refused too).
    bad = x.copy()
    bad[4000] = np.nan
    with pytest.raises(ValueError, match=r"samples: sample 4000 \(0.5000 s\) is nan; audio samples must be finite"):
        arco.track_pitch(bad, 8000, 30)
    stereo = np.zeros((8000, 2), np.float32)
    stereo[100, 1] = np.inf
    with pytest.raises(ValueError, match=r"samples: sample 100 \(0.0125 s\) is inf"):
        arco.track_pitch(stereo, 8000, 30)
    with pytest.raises(ValueError, match="sample_rate 10 outside"):
        arco.track_pitch(x, 10, 30)
    # The same one-line message as the CLI.
    write_tone(tmp_path / "tone.wav")
    with pytest.raises(ValueError) as e:
        arco.track_pitch(x, 8000, 30, "banjo")
    assert str(e.value) == cli_error(run_arco(arco_bin, "pitch", tmp_path / "tone.wav",
                                              "--instrument", "banjo", "-o", tmp_path / "p.csv"))
