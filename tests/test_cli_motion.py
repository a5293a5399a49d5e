"""The ``assemblykit motion`` command (docs/motion.md)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import assemblykit
from assemblykit.cli import main

EXAMPLES = Path(assemblykit.__file__).parent / "examples" / "motion"


def _run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    with pytest.raises(SystemExit) as done:
        main(args)
        raise SystemExit(0)
    out, err = capsys.readouterr()
    return int(done.value.code or 0), out, err


def test_motion_json_of_the_hinge(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = _run(["motion", str(EXAMPLES / "hinge" / "hinge.yaml"), "--json"], capsys)
    assert code == 0
    parts = json.loads(out)["parts"]
    assert set(parts) == {"frame", "door"}
    door = parts["door"]
    assert (door["motion"], door["dof"]) == ("revolute", 1)
    assert door["axis"]["direction"] == pytest.approx([0.0, 0.0, 1.0], abs=1e-9)
    assert door["unilateral"]["lift_off"] == [pytest.approx([0.0, 0.0, 1.0], abs=1e-9)]


def test_motion_of_a_subassembly(capsys: pytest.CaptureFixture[str]) -> None:
    path = str(EXAMPLES / "interlock" / "interlock.yaml")
    code, out, _ = _run(["motion", path, "--subassembly", "bar_a,bar_b", "--json"], capsys)
    assert code == 0
    parts = json.loads(out)["parts"]
    assert parts["bar_a"]["motion"] == "fixed"
    assert parts["bar_a+bar_b"]["motion"] == "prismatic"
    assert parts["bar_a+bar_b"]["direction"] == pytest.approx([1.0, 0.0, 0.0], abs=1e-9)


def test_motion_table_and_html(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    html = tmp_path / "gearbox.html"
    path = str(EXAMPLES / "gearbox" / "gearbox.yaml")
    code, out, _ = _run(["motion", path, "--html", str(html)], capsys)
    assert code == 0
    assert "revolute" in out and "Gear train 1: 1 dof" in out
    text = html.read_text()
    assert "gear_4: revolute about line" in text and len(text) > 1_000_000


def test_missing_file_exits_2_with_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = _run(["motion", "no/such/assembly.yaml", "--json"], capsys)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and "no/such/assembly.yaml" in err


def test_unknown_part_in_subassembly_exits_2(capsys: pytest.CaptureFixture[str]) -> None:
    path = str(EXAMPLES / "hinge" / "hinge.yaml")
    code, _, err = _run(["motion", path, "--subassembly", "door,ghost"], capsys)
    assert code == 2
    assert err.count("\n") == 1 and "ghost" in err


def test_empty_subassembly_exits_2(capsys: pytest.CaptureFixture[str]) -> None:
    path = str(EXAMPLES / "hinge" / "hinge.yaml")
    code, _, err = _run(["motion", path, "--subassembly", " , "], capsys)
    assert code == 2 and err.count("\n") == 1


TASKS = Path(assemblykit.__file__).parent / "examples" / "tasks"


@pytest.mark.parametrize("name", ["w4_pin.yaml", "w4_pin.rapt"])
def test_motion_of_a_task_file(name: str, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = _run(["motion", str(TASKS / name), "--json"], capsys)
    assert code == 0
    result = json.loads(out)
    assert result["status"] == "underconstrained"
    pin = result["parts"]["pin@s1"]
    assert (pin["motion"], pin["dof"]) == ("revolute", 1)
    assert pin["axis"] == {"point": [0.0, 0.0, 0.0], "direction": [0.0, 0.0, 1.0]}
    assert pin["relations"] == ["fits pin.shaft plate.hole", "against pin.head plate.top"]


def test_a_task_takes_no_subassembly(capsys: pytest.CaptureFixture[str]) -> None:
    path = str(TASKS / "w4_pin.yaml")
    code, _, err = _run(["motion", path, "--subassembly", "pin,plate"], capsys)
    assert code == 2
    assert len(err.strip().splitlines()) == 1 and "tasks" in err


def test_a_task_file_with_a_bad_relation_exits_2(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        "bodies:\n  a:\n    fixed: true\n"
        "    features: {p: {type: plane, point: [0,0,0], normal: [0,0,1]}}\n"
        "situations:\n  - name: s1\n    relations: [[against, a.p, a.q]]\n"
    )
    code, _, err = _run(["motion", str(bad)], capsys)
    assert code == 2
    assert "bad.yaml" in err and "'q'" in err
