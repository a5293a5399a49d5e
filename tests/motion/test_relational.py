"""Motion of a task's bodies from the relations they take part in (motion/relational.py)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import assemblykit
from assemblykit.io.spec import parse_task
from assemblykit.model.task import Task
from assemblykit.motion.relational import standing_relations, task_motion

PLATE = {
    "fixed": True,
    "features": {
        "top": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]},
        "hole": {"type": "hole", "point": [3, 4, 0], "axis": [0, 0, -1], "radius": 5},
        "hole_2": {"type": "hole", "point": [23, 4, 0], "axis": [0, 0, -1], "radius": 5},
    },
}
PIN = {
    "features": {
        "head": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, -1]},
        "shaft": {"type": "shaft", "point": [0, 0, 0], "axis": [0, 0, -1], "radius": 5},
    }
}


def _task(bodies: dict[str, Any], *situations: list[Any], actions: Any = ()) -> Task:
    steps = [{"name": "s1", "relations": situations[0]}]
    for number, (relations, moves) in enumerate(zip(situations[1:], actions, strict=True)):
        steps.append({"name": f"s{number + 2}", "relations": relations, "actions": moves})
    return parse_task({"units": "mm", "bodies": bodies, "situations": steps}, source="t.yaml")


def test_a_shouldered_pin_in_a_plate_turns_about_the_pin_axis() -> None:
    task = _task(
        {"plate": PLATE, "pin": PIN},
        [["fits", "pin.shaft", "plate.hole"], ["against", "pin.head", "plate.top"]],
    )
    pin = task_motion(task)["pin@s1"]
    data = pin.to_dict()
    assert (pin.kind, pin.dof, data["components"]) == ("revolute", 1, 1)
    # the axis is the hole's line x = 3, y = 4; its foot from the origin is (3, 4, 0)
    assert data["axis"]["point"] == pytest.approx([3.0, 4.0, 0.0], abs=1e-9)
    assert data["axis"]["direction"] == pytest.approx([0.0, 0.0, 1.0], abs=1e-9)
    assert data["touching"] == ["plate"]
    assert data["relations"] == ["fits pin.shaft plate.hole", "against pin.head plate.top"]


def test_without_its_shoulder_the_pin_is_cylindrical() -> None:
    task = _task({"plate": PLATE, "pin": PIN}, [["fits", "pin.shaft", "plate.hole"]])
    assert task_motion(task)["pin@s1"].kind == "cylindrical"


def test_a_block_in_a_corner_slides_along_the_corner_edge() -> None:
    table = {
        "fixed": True,
        "features": {
            "top": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]},
            "wall": {"type": "plane", "point": [0, 0, 0], "normal": [1, 0, 0]},
        },
    }
    block = {
        "features": {
            "bottom": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, -1]},
            "left": {"type": "plane", "point": [0, 0, 0], "normal": [-1, 0, 0]},
        }
    }
    task = _task(
        {"table": table, "block": block},
        [["against", "block.bottom", "table.top"], ["against", "block.left", "table.wall"]],
    )
    data = task_motion(task)["block@s1"].to_dict()
    # planar(z) ∩ planar(x) = translations along their common line, y
    assert (data["motion"], data["dof"], data["components"]) == ("prismatic", 1, 1)
    assert data["direction"] == pytest.approx([0.0, 1.0, 0.0], abs=1e-9)


def test_two_pins_in_two_holes_fix_the_plate_without_swaps() -> None:
    plate = {
        "features": {
            "bottom": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, -1]},
            "a": {"type": "hole", "point": [0, 0, 0], "axis": [0, 0, 1], "radius": 5},
            "b": {"type": "hole", "point": [20, 0, 0], "axis": [0, 0, 1], "radius": 5},
        }
    }
    base = {
        "fixed": True,
        "features": {
            "top": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]},
            "a": {"type": "shaft", "point": [0, 0, 0], "axis": [0, 0, 1], "radius": 5},
            "b": {"type": "shaft", "point": [20, 0, 0], "axis": [0, 0, 1], "radius": 5},
        },
    }
    task = _task(
        {"base": base, "plate": plate},
        [
            ["against", "plate.bottom", "base.top"],
            ["fits", "plate.a", "base.a"],
            ["fits", "plate.b", "base.b"],
        ],
    )
    data = task_motion(task)["plate@s1"].to_dict()
    # the half turn swapping the pins is a surface symmetry, but pairs a with b
    assert (data["motion"], data["dof"], data["components"]) == ("fixed", 0, 1)


def test_a_pinned_link_between_two_pins_is_held_and_the_world_is_not_reported() -> None:
    link = {
        "features": {
            "a": {"type": "hole", "point": [0, 0, 0], "axis": [0, 0, 1], "radius": 5},
            "b": {"type": "hole", "point": [20, 0, 0], "axis": [0, 0, 1], "radius": 5},
        }
    }
    pin = {
        "features": {"shaft": {"type": "shaft", "point": [0, 0, 0], "axis": [0, 0, 1], "radius": 5}}
    }
    ground = {"fixed": True, "features": {"shaft": PIN["features"]["shaft"]}}
    task = _task(
        {"ground": ground, "link": link, "pin": pin},
        [["fits", "link.a", "ground.shaft"], ["fits", "pin.shaft", "link.b"]],
    )
    report = task_motion(task)
    assert set(report.motions) == {"link@s1", "pin@s1"}
    # two parallel cylinders on distinct lines leave translations along z only
    link_motion = report["link@s1"].to_dict()
    assert (link_motion["motion"], link_motion["direction"]) == ("prismatic", [0.0, 0.0, 1.0])
    assert report["link@s1"].touching == ("ground", "pin")
    assert report["pin@s1"].kind == "cylindrical"


def test_relations_stand_until_an_action_moves_one_of_their_bodies() -> None:
    task = _task(
        {"plate": PLATE, "pin": PIN, "cap": PIN},
        [["fits", "pin.shaft", "plate.hole"], ["fits", "cap.shaft", "plate.hole_2"]],
        [["against", "pin.head", "plate.top"]],
        actions=[[["move", "pin", {"along": "pin.shaft"}]]],
    )
    standing = {k: [str(r.kind) for r in v] for k, v in standing_relations(task).items()}
    assert standing == {"s1": ["fits", "fits"], "s2": ["against", "fits"]}
    report = task_motion(task)
    # the moved pin keeps only the restated relation; the cap keeps its fit
    assert (report["pin@s2"].kind, report["cap@s2"].kind) == ("planar", "cylindrical")


def test_non_coset_and_impossible_relations_are_reported_as_ignored() -> None:
    thin = {
        "features": {
            "shaft": {"type": "shaft", "point": [0, 0, 0], "axis": [0, 0, -1], "radius": 4}
        }
    }
    task = _task(
        {"plate": PLATE, "pin": PIN, "thin": thin},
        [
            ["fits", "pin.shaft", "plate.hole"],
            ["perpendicular", "pin.head", "plate.top"],
            ["fits", "thin.shaft", "plate.hole_2"],
        ],
    )
    report = task_motion(task)
    assert report.status == "inconsistent"
    assert report["pin@s1"].kind == "cylindrical"
    assert report["pin@s1"].ignored == (
        "perpendicular pin.head plate.top: not a subgroup of motions",
    )
    assert report["thin@s1"].group is None and report["thin@s1"].kind == "free"
    assert report["thin@s1"].ignored[0].startswith("fits thin.shaft plate.hole_2: cannot hold")


def test_the_public_motion_function_takes_a_task() -> None:
    task = _task({"plate": PLATE, "pin": PIN}, [["fits", "pin.shaft", "plate.hole"]])
    report = assemblykit.motion(task)
    assert report.to_dict()["parts"]["pin@s1"]["motion"] == "cylindrical"
    assert report.to_dict()["source"] == "t.yaml"


def test_bundled_peg_in_block_task() -> None:
    path = assemblykit.__file__.replace("__init__.py", "examples/tasks/peg_in_block.yaml")
    report = task_motion(assemblykit.load_task(path))
    assert report["block@s1"].kind == "fixed"
    peg = report["peg@s1"].to_dict()
    assert peg["motion"] == "cylindrical"
    assert np.allclose(peg["axis"]["point"], [5.0, 5.0, 0.0], atol=1e-9)
    # the block was not moved: its relations with the table still hold in s2
    assert report["block@s2"].kind == "fixed"
