"""docs/python.md's example runs as written (its python cells in order, in one namespace),
in a folder holding the capture and the result its shell cell makes."""
import os
import re

from conftest import ROOT


def test_python_md_example(capture, result, tmp_path, capsys):
    text = (ROOT / "docs" / "python.md").read_text()
    cells = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(cells) >= 6
    (tmp_path / "capture").symlink_to(capture)
    (tmp_path / "result").symlink_to(result)
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        namespace = {}
        for cell in cells:
            exec(compile(cell, "docs/python.md", "exec"), namespace)
    finally:
        os.chdir(cwd)
    ns = namespace
    assert abs(ns["back"] - ns["truth"]).max() < 1e-6
    assert ns["ik"]["converged"] and ns["ik"]["final_distance_mm"] < 1e-3
    assert abs(ns["left"] - ns["arco_points"][:, 91:112]).max() < 1e-9
    print(capsys.readouterr().out)
