"""``assemblykit.load_assembly`` reads the 2D polygon files ``plan`` reads: it returns
the polygon assembly the command plans, and still reads a YAML manifest as a 3D
assembly."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import assemblykit
from assemblykit.errors import InputError
from assemblykit.io.polygons import load_polygons
from assemblykit.model.polygons import PolygonAssembly
from cli_runs import run

PLANAR = Path(assemblykit.__file__).parent / "examples" / "planar"


@pytest.mark.parametrize("name", ["hook.yaml", "bottle.yaml", "three_hands.yaml"])
def test_a_polygon_file_is_the_assembly_plan_plans(name: str) -> None:
    loaded = assemblykit.load_assembly(PLANAR / name)
    assert isinstance(loaded, assemblykit.PolygonAssembly)
    assert isinstance(loaded, PolygonAssembly)
    drawn = load_polygons(PLANAR / name)
    assert loaded.names == drawn.names and loaded.source == drawn.source
    assert all((loaded.polygons[n] == drawn.polygons[n]).all() for n in drawn.names)


def test_the_command_and_the_function_give_the_same_plan(capsys) -> None:
    hook = PLANAR / "hook.yaml"
    code, out, _ = run(capsys, "plan", str(hook), "--json")
    shown = json.loads(out)
    planned = assemblykit.plan(assemblykit.load_assembly(hook))
    assert code == 0 and shown["feasible"] and len(shown["steps"]) == len(planned.steps) == 1
    assert shown["steps"][0]["parts"] == list(planned.steps[0].parts) == ["peg"]
    assert shown["steps"][0]["direction"] == pytest.approx(planned.steps[0].direction, abs=1e-6)
    assert planned.to_dict() == assemblykit.plan(load_polygons(hook)).to_dict()


def test_a_manifest_is_still_a_3d_assembly() -> None:
    hinge = Path(assemblykit.__file__).parent / "examples" / "motion" / "hinge" / "hinge.yaml"
    assert isinstance(assemblykit.load_assembly(hinge), assemblykit.Assembly)


def test_a_bad_polygon_names_the_file_and_the_part(tmp_path: Path) -> None:
    bad = tmp_path / "flat.yaml"
    bad.write_text("parts:\n  a: [[0, 0], [1, 0]]\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"parts\.a") as raised:
        assemblykit.load_assembly(bad)
    assert "flat.yaml" in str(raised.value)
