"""Fixtures of the Python module's tests: the `arco` executable, the SPD data, a small
synthetic capture with its `arco triangulate` and `arco run` outputs (made once per run)."""
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[4]


@pytest.fixture(scope="session")
def arco_bin():
    path = pathlib.Path(os.environ.get("ARCO_BIN", ROOT / "build" / "bin" / "arco"))
    if not path.exists():
        pytest.fail(f"{path}: the arco executable is not built (cmake --build build --target arco)")
    return str(path)


@pytest.fixture(scope="session")
def spd_dir():
    path = pathlib.Path(os.environ.get("ARCO_SHARED_DATA_DIR", ROOT.parent / "shared" / "data")) / "spd"
    if not (path / "README.md").exists():
        pytest.fail(f"{path}: SPD data not found (set ARCO_SHARED_DATA_DIR)")
    return path


def run_arco(arco_bin, *args):
    """Runs `arco ARGS`; returns the completed process (stdout, stderr as text)."""
    return subprocess.run([arco_bin, *map(str, args)], capture_output=True, text=True)


def cli_error(process):
    """The one-line message of a failed `arco` command (without "arco: error: ")."""
    assert process.returncode != 0, process.stdout
    lines = [l for l in process.stderr.splitlines() if l.startswith("arco: error: ")]
    assert lines, process.stderr
    return lines[-1][len("arco: error: "):]


@pytest.fixture(scope="session")
def capture(arco_bin, tmp_path_factory):
    """`arco synth --duration-s 2`: a 20-camera capture of the SPD rig with audio."""
    out = tmp_path_factory.mktemp("synth") / "capture"
    p = run_arco(arco_bin, "synth", "-o", out, "--duration-s", 2)
    assert p.returncode == 0, p.stderr
    return out


@pytest.fixture(scope="session")
def triangulated(arco_bin, capture, tmp_path_factory):
    """`arco triangulate CAPTURE -o DIR`."""
    out = tmp_path_factory.mktemp("triangulate") / "result"
    p = run_arco(arco_bin, "triangulate", capture, "-o", out, "--threads", 2)
    assert p.returncode == 0, p.stderr
    return out


@pytest.fixture(scope="session")
def result(arco_bin, capture, tmp_path_factory):
    """`arco run CAPTURE -o DIR`: every stage."""
    out = tmp_path_factory.mktemp("run") / "result"
    p = run_arco(arco_bin, "run", capture, "-o", out, "--threads", 2)
    assert p.returncode == 0, p.stderr
    return out
