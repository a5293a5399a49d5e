"""The ``assemblykit blocking`` command (docs/blocking.md)."""

from __future__ import annotations

import json

import pytest

from assemblykit.cli import main
from datasets import dataset

POLYGONS = """parts:
  base: [[0, 0], [4, 0], [4, 1], [0, 1]]
  left: [[0, 1], [1, 1], [1, 3], [0, 3]]
  right: [[3, 1], [4, 1], [4, 3], [3, 3]]
"""


def run(args, capsys) -> tuple[int, str, str]:
    try:
        main(args)
        code = 0
    except SystemExit as done:
        code = done.code
    out = capsys.readouterr()
    return code, out.out, out.err


def test_json_on_planar_polygons(tmp_path, capsys):
    path = tmp_path / "fig.yaml"
    path.write_text(POLYGONS)
    code, out, _ = run(["blocking", str(path), "--json"], capsys)
    assert code == 0
    result = json.loads(out)
    assert result["parts"] == ["base", "left", "right"]
    assert result["contacts"] == 2
    # one contact direction (horizontal segments): 2 points + 2 arcs
    assert result["regions"] == {"vertices": 2, "edges": 2, "faces": 0}
    removable = {tuple(r["parts"]): r["directions"] for r in result["removable"]}
    assert ("left",) in removable and ("left", "right") not in removable
    assert any(abs(d[0]) < 1e-12 and d[1] == pytest.approx(1.0) for d in removable[("left",)])


def test_png(tmp_path, capsys):
    path = tmp_path / "fig.yaml"
    path.write_text(POLYGONS)
    png = tmp_path / "ndbg.png"
    code, _, _ = run(["blocking", str(path), "--png", str(png)], capsys)
    assert code == 0
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_bad_input_is_one_line_exit_2(tmp_path, capsys):
    path = tmp_path / "bad.yaml"
    path.write_text("parts:\n  a: [[0, 0], [1, 0]]\n")
    code, _, err = run(["blocking", str(path)], capsys)
    assert code == 2
    assert err.count("\n") == 1 and "bad.yaml" in err
    code, _, err = run(["blocking", str(path), "--motion", "sideways"], capsys)
    # a usage error: one line, what was wrong with which option and the help to read
    assert code == 2 and err.count("\n") == 1 and "'--motion'" in err
    assert err.startswith("assemblykit: ") and "'assemblykit blocking --help'" in err


def test_extended_on_the_compas_stack(capsys):
    stack = dataset("compas_assembly/stack_assembly.json")
    code, out, _ = run(["blocking", str(stack), "--motion", "extended", "--json"], capsys)
    assert code == 0
    result = json.loads(out)
    assert len(result["parts"]) == 10 and result["contacts"] == 9
    assert result["regions"]["faces"] > 0
    # the whole stack minus its bottom block lifts off upwards in some region
    lifted = [r for r in result["removable"] if len(r["parts"]) == 9]
    assert any(d[2] > 0.99 for r in lifted for d in r["directions"])
