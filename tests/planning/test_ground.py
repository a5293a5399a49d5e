"""Block assemblies are planned on the ground they stand on (docs/planning.md, "The
ground").

The scene, answers by hand: two legs (1 x 1 x 2) on the ground at x = 0 and x = 3, and
a slab (4 x 1 x 1) across them. Nothing is declared: the legs rest on the lowest plane,
so they are the supports. On the ground they stay, and the one step lifts the slab
along +z (it could slide along ±y too; of equal steps a lift comes first). Floating,
the slab is the largest part, the base that stays, and the legs leave it. Declared with
``is_support``, only the declared leg is a support.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from assemblykit.errors import SchemaError
from assemblykit.geometry.overlaps import resolve_overlaps
from assemblykit.io.assembly import load_assembly
from assemblykit.planning.planner import plan
from cli_runs import run
from compas_documents import block
from datasets import shared_assembly
from plan_checks import assert_steps_clear

SCENE = {
    "leg_a": ((0, 0, 0), (1, 1, 2)),
    "leg_b": ((3, 0, 0), (4, 1, 2)),
    "slab": ((0, 0, 2), (4, 1, 3)),
}


def compas_file(folder: Path, supports: dict[str, object] | None = None) -> Path:
    """The scene as a COMPAS 2 assembly, ``is_support`` set on the nodes ``supports``
    names."""
    node = {}
    for name, (low, high) in SCENE.items():
        node[name] = {"block": block(low, high)}
        if supports and name in supports:
            node[name]["is_support"] = supports[name]
    document = {
        "dtype": "compas_assembly.datastructures/Assembly",
        "data": {"graph": {"dtype": "compas.datastructures/Graph", "data": {"node": node}}},
    }
    path = folder / "table.json"
    path.write_text(json.dumps(document))
    return path


def test_the_blocks_on_the_lowest_plane_are_the_supports_unless_some_are_declared(tmp_path):
    assert load_assembly(compas_file(tmp_path)).supports == ("leg_a", "leg_b")
    declared = compas_file(tmp_path, {"leg_b": True, "slab": False})
    assert load_assembly(declared).supports == ("leg_b",)
    assert shared_assembly("compas_assembly/arch_assembly.json").supports == ("0", "29")


def test_a_support_that_is_not_true_or_false_is_refused_naming_its_node(tmp_path):
    with pytest.raises(SchemaError, match=r"is_support is 'yes'") as error:
        load_assembly(compas_file(tmp_path, {"leg_a": "yes"}))
    assert "node.leg_a" in str(error.value)


def test_on_the_ground_the_legs_stay_and_the_slab_is_lifted(tmp_path):
    assembly = load_assembly(compas_file(tmp_path))
    result = plan(assembly)
    assert result.feasible and result.ground == ("leg_a", "leg_b")
    assert result.fixed == ("leg_a", "leg_b")
    assert [step.parts for step in result.steps] == [("slab",)]
    assert np.allclose(result.steps[0].direction, [0, 0, 1])
    assert result.order == (("leg_a", "leg_b"), ("slab",))
    assert_steps_clear(assembly, result)


def test_floating_the_slab_is_the_base_and_the_legs_leave_it(tmp_path):
    assembly = load_assembly(compas_file(tmp_path))
    result = plan(assembly, ground=False)
    assert result.feasible and result.ground == () and result.fixed == ()
    assert {name for step in result.steps for name in step.parts} == {"leg_a", "leg_b"}
    assert_steps_clear(assembly, result)


@pytest.mark.parametrize("one_at_a_time", [False, True])
def test_no_step_of_the_arch_goes_down_through_the_ground(one_at_a_time):
    assembly = shared_assembly("compas_assembly/arch_assembly.json")
    result = plan(assembly, one_at_a_time=one_at_a_time)
    assert result.feasible and result.ground == ("0", "29")
    moved = {name for step in result.steps for name in step.parts}
    assert moved == set(assembly.names) - {"0", "29"}
    tol = assembly.tolerance()
    assert all(step.direction[2] >= -tol.angle for step in result.steps)
    if one_at_a_time:
        # a block at a time from the crown down, each lifted (14 and 15 are mirror
        # images: which one goes first is a float tie)
        assert all(len(step.parts) == 1 for step in result.steps)
        assert result.steps[0].parts in (("14",), ("15",))
        assert all(step.direction[2] > 1 - tol.angle for step in result.steps[:5])


def test_a_part_joined_to_a_support_stands_on_the_ground(tmp_path):
    assembly = load_assembly(compas_file(tmp_path))
    joined = resolve_overlaps(assembly, [("leg_a", "slab")])
    (name,) = joined.joined
    assert joined.supports == tuple(n for n in joined.names if n in {"leg_b", name})


def test_the_plan_command_says_where_the_blocks_stand_and_floats_them_when_asked(capsys, tmp_path):
    path = compas_file(tmp_path)
    code, out, err = run(capsys, "plan", str(path), "--json")
    assert code == 0, err
    assert json.loads(out)["ground"] == ["leg_a", "leg_b"]
    code, out, err = run(capsys, "plan", str(path), "--json", "--floating")
    assert code == 0, err
    assert json.loads(out)["ground"] == []
    code, out, _ = run(capsys, "plan", str(path))
    assert "on the ground under leg_a, leg_b" in " ".join(out.split())
