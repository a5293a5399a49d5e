"""Fixed parts never move, in every planning mode, and default supports under gravity
come off last (docs/planning.md, "Fixed parts").

The table-top scene, answers by hand: a table (4 x 4 x 1) on the ground, a box (2 x 2 x
1) on it, a lid (2 x 2 x 0.2) on the box, and a wall (0.5 x 2 x 3) standing on the table
against the box's +x side and the lid's. The wall is free upwards, along +x and along
±y; the lid upwards, along -x and ±y; the box along -x and ±y (the lid is on it, the
wall at its side). Declared fixed, the table and the wall stay: only the box and the lid
move, and the assembly order starts on the table and the wall. Not declared, the wall
would leave at the first step (with the box and the lid along ±y; under gravity alone,
its centre the highest).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from assemblykit.errors import UnknownNameError
from assemblykit.io.polygons import load_polygons
from assemblykit.model.assembly import Assembly, Part
from assemblykit.planning.multimove import plan_voxels
from assemblykit.planning.multimove_mesh import plan_meshes
from assemblykit.planning.planner import plan
from assemblykit.planning.screw import plan_with_screws
from assemblykit.planning.stability import Gravity
from cli_runs import run
from plan_checks import assert_steps_clear
from stability_blocks import box

FIXED = ("table", "wall")
PLANAR = Path(__file__).resolve().parents[2] / "src" / "assemblykit" / "examples" / "planar"


def table_top() -> Assembly:
    """The module docstring's table, box, lid and wall."""
    return Assembly(
        [
            Part("table", box((4, 4, 1), (0, 0, 0))),
            Part("box", box((2, 2, 1), (1, 1, 1))),
            Part("lid", box((2, 2, 0.2), (1, 1, 2))),
            Part("wall", box((0.5, 2, 3), (3, 1, 1))),
        ]
    )


def moved(steps: list[dict]) -> list[str]:
    """Every part moved by the JSON ``steps``, in order."""
    return [name for step in steps for name in step["parts"]]


@pytest.mark.parametrize(
    "options",
    [
        {},
        {"one_at_a_time": True},
        {"gravity": Gravity()},
        {"gravity": Gravity(fixed=FIXED)},
    ],
    ids=["default", "one-at-a-time", "gravity", "gravity-fixed"],
)
def test_fixed_parts_never_move_and_start_the_assembly_order(options):
    assembly = table_top()
    result = plan(assembly, fixed=FIXED, **options)
    assert result.feasible and result.fixed == FIXED
    assert sorted(moved(result.to_dict()["steps"])) == ["box", "lid"]
    assert result.steps[-1].rest == FIXED
    assert result.order[0] == FIXED
    assert result.to_dict()["order"][0] == list(FIXED)
    assert_steps_clear(assembly, result)


def test_one_set_per_step_takes_the_lid_before_the_box():
    # one part per step, or under gravity: the box is under the lid, so the lid first
    for options in ({"one_at_a_time": True}, {"gravity": Gravity()}):
        result = plan(table_top(), fixed=FIXED, **options)
        assert [s.parts for s in result.steps] == [("lid",), ("box",)]
        assert result.order == (FIXED, ("box",), ("lid",))


def test_without_fixed_parts_the_wall_leaves_first():
    assert "wall" in plan(table_top()).steps[0].parts
    assert plan(table_top(), gravity=Gravity()).steps[0].parts == ("wall",)


def test_multi_move_and_rigid_plans_leave_the_fixed_parts():
    assembly = table_top()
    multi = plan_meshes(assembly, fixed=FIXED)
    data = multi.to_dict()
    assert multi.feasible and sorted(moved(data["steps"])) == ["box", "lid"]
    node = data["separations"]
    while node["left"] is not None:
        node = node["left"]
    assert node["parts"] == list(FIXED) and node["status"] == "fixed"
    rigid = plan_with_screws(assembly, fixed=FIXED).to_dict()
    assert rigid["feasible"] and sorted(moved(rigid["steps"])) == ["box", "lid"]


@pytest.mark.slow
def test_a_fixed_hook_is_never_turned_out():
    # the hook behind a lip of tests/planning/test_screw.py leaves only by a turn; fixed,
    # it stays, and the base cannot be turned off it
    from planning.test_screw import hooked

    result = plan_with_screws(hooked(), fixed=["hook"])
    assert not result.feasible and result.screws == ()
    assert result.to_dict()["stuck"] == ["base", "hook"]


def test_a_fixed_peg_stays_and_the_hook_leaves_it_in_the_plane():
    # the peg leaves the hook only between atan(1/3) and 45 degrees (docs/planning.md,
    # "Planar assemblies"); the peg fixed, the hook leaves it the opposite way
    hook = load_polygons(PLANAR / "hook.yaml")
    result = plan(hook, fixed=["peg"])
    assert [(s.parts, s.rest) for s in result.steps] == [(("hook",), ("peg",))]
    assert result.order == (("peg",), ("hook",))
    assert result.steps[0].direction[0] < 0 and result.steps[0].direction[1] < 0


def test_voxel_pieces_fixed_stay_and_the_others_leave_them():
    # a row of cells along x: big (x = 0, 1) and small (x = 2) on top of c (x = 0..2,
    # one row up in y). Unfixed, small goes +x first; small fixed, big and c leave it
    # along -x; small and c fixed, big leaves them along -x (small blocks +x)
    names = ["big", "small", "c"]
    cells = [[[0, 0, 0], [1, 0, 0]], [[2, 0, 0]], [[0, 1, 0], [1, 1, 0], [2, 1, 0]]]
    voxels = [np.array(c) for c in cells]
    free = plan_voxels(names, voxels).to_dict()["steps"]
    assert (free[0]["parts"], free[0]["direction"]) == (["small"], [1.0, 0.0, 0.0])
    one = plan_voxels(names, voxels, fixed=["small"]).to_dict()
    assert one["feasible"] and "small" not in moved(one["steps"])
    assert one["steps"][0]["parts"] == ["big", "c"]
    two = plan_voxels(names, voxels, fixed=["small", "c"]).to_dict()
    assert [(s["parts"], s["direction"]) for s in two["steps"]] == [(["big"], [-1.0, 0.0, 0.0])]
    assert two["separations"]["left"]["status"] == "fixed"


def test_an_unknown_fixed_part_is_named():
    with pytest.raises(UnknownNameError, match="floor"):
        plan(table_top(), fixed=["floor"])
    with pytest.raises(UnknownNameError, match="floor"):
        plan_meshes(table_top(), fixed=["floor"])


def noisy_stack() -> Assembly:
    """Three unit cubes stacked, every coordinate raised by sin(π) (about 1.2e-16), and
    a post (1 x 1 x 6) on the ground beside them: both the bottom cube and the post rest
    on the lowest plane, within the length tolerance; the post's centre is the highest."""
    noise = math.sin(math.pi)
    return Assembly(
        [
            Part("bottom", box((1, 1, 1), (0, 0, noise))),
            Part("middle", box((1, 1, 1), (0, 0, 1 + noise))),
            Part("top", box((1, 1, 1), (0, 0, 2 + noise))),
            Part("post", box((1, 1, 6), (1.5, 0, 0))),
        ]
    )


def test_default_supports_come_off_last_whatever_the_noise():
    assembly = noisy_stack()
    result = plan(assembly, gravity=Gravity())
    assert result.gravity is not None and result.gravity.fixed == ("bottom", "post")
    # the cubes on the bottom one come off first, top down; then the bottom cube; the
    # post, the heavier support, stays
    assert [s.parts for s in result.steps] == [("top",), ("middle",), ("bottom",)]
    assert result.feasible and result.gravity.stable
    assert_steps_clear(assembly, result)


def test_the_command_never_moves_fixed_parts(capsys, tmp_path):
    for part in table_top().parts.values():
        part.mesh.export(tmp_path / f"{part.name}.stl")
    fixed = ("--fixed", "table", "--fixed", "wall")
    modes = ((), ("--gravity",), ("--one-at-a-time",), ("--moves", "multi"), ("--moves", "rigid"))
    for mode in modes:
        code, out, err = run(capsys, "plan", str(tmp_path), *mode, *fixed, "--json")
        assert code == 0, err
        data = json.loads(out)
        assert data["feasible"] and sorted(moved(data["steps"])) == ["box", "lid"], mode
        if "order" in data:
            assert data["order"][0] == list(FIXED)
