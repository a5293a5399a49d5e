"""Tests of static equilibrium under gravity and of planning with it, on blocks whose
answers are computed by hand (a block on a slope, an overhanging stack, a corbelled
arch, a leaning pair) and on the bundled COMPAS arch and ASAP beam. Every plan is checked
again state by state from its JSON."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
import trimesh

from assemblykit.errors import InputError, UnknownNameError
from assemblykit.io.assembly import load_assembly
from assemblykit.model.assembly import Assembly, Part
from assemblykit.planning.planner import plan
from assemblykit.planning.stability import (
    CONE_SIDES,
    FRICTION_STEPS,
    Gravity,
    contact_points,
    equilibrium,
    equilibrium_model,
    gravity_direction,
    lowest_parts,
)
from assemblykit.tolerance import Tolerance
from datasets import dataset, shared_assembly
from plan_checks import assert_steps_clear
from stability_blocks import block_on_slope, box, corbels, overhanging_stack, whole_residuals

MU = 0.5
RESOLUTION = MU / 2**FRICTION_STEPS


def assert_every_state_stands(assembly: Assembly, data: dict, friction: float = MU) -> None:
    """Re-run the whole equilibrium program (never a shortcut from an earlier balance)
    on every state of a plan's JSON, with every vertex of the contact polygons: the
    whole assembly, and at each step what remains with the parts the step holds."""
    model = equilibrium_model(assembly, friction=friction)
    every = dataclasses.replace(model, corners=np.ones_like(model.corners))
    fixed = every.mask(every.fixed)
    assert every.stands(every.mask(None), fixed, local=False)
    for step in data["steps"]:
        rest = every.mask(step["rest"])
        held = rest & (fixed | every.mask(step["held"]))
        assert every.stands(rest, held, local=False), step
        assert len(step["held"]) <= data["gravity"]["holds"]


@pytest.mark.parametrize("degrees", [25.0, 30.0])
def test_a_block_on_a_slope_stands_iff_the_slope_is_within_the_friction_angle(degrees):
    # tan 25 deg = 0.466 <= 0.5 < tan 30 deg = 0.577 (atan 0.5 = 26.57 deg)
    assembly = block_on_slope(degrees)
    found = equilibrium(assembly, friction=MU)
    assert found.fixed == ("slope",)
    assert found.stands is (math.tan(math.radians(degrees)) <= MU)
    assert found.would_fall == (() if found.stands else ("block",))


def test_the_friction_a_block_on_a_slope_needs_is_the_slopes_tangent():
    model = equilibrium_model(block_on_slope(25.0), friction=MU)
    present = model.mask(None)
    needed = model.friction_needed(present, model.mask(["slope"]))
    assert needed is not None
    # what a balance needs, its tangential forces spread: the tangent, to the solver's accuracy
    assert abs(needed - math.tan(math.radians(25.0))) <= 1e-6


@pytest.mark.parametrize(("overhang", "stands"), [(0.4, True), (0.6, False)])
def test_an_overhanging_top_stands_iff_its_centre_is_over_its_support(overhang, stands):
    # the top's centre is at x = overhang + 0.5; the middle block spans x in [0, 1]
    found = equilibrium(overhanging_stack(overhang))
    assert found.fixed == ("bottom",)
    assert found.stands is stands
    assert found.would_fall == (() if stands else ("top",))


def test_a_part_touching_nothing_falls():
    assembly = Assembly(
        [Part("ground", box((2, 2, 1), (0, 0, 0))), Part("floating", box((1, 1, 1), (0, 0, 3)))]
    )
    found = equilibrium(assembly)
    assert found.would_fall == ("floating",) and found.residuals == (1.0,)


def test_a_held_part_does_not_fall():
    assert equilibrium(overhanging_stack(0.6), held=["top"]).stands


def test_the_corbelled_arch_stands_only_when_complete():
    assembly = corbels(keystone=True)
    model = equilibrium_model(assembly, friction=MU)
    assert model.fixed == ("ground",)
    assert model.check().stands
    assert set(model.check(set(assembly.names) - {"keystone"}).would_fall) == {
        "corbel_l",
        "corbel_r",
    }
    assert {"keystone", "corbel_r"} <= set(
        model.check(set(assembly.names) - {"corbel_l"}).would_fall
    )
    # by hand: the corbels' overturning moment 1.4 x 0.1 + 0.2 x 0.8 = 0.3 needs a thrust
    # N >= 0.3 from the keystone; the keystone's half weight 0.2 <= mu N and the pillar's
    # friction N <= mu 1.6 give the least mu at N^2 = 0.32: mu = 1 / (2 sqrt 2) = 0.354
    present = model.mask(None)
    needed = model.friction_needed(present, model.mask(["ground"]))
    assert needed is not None
    assert 1 / (2 * math.sqrt(2)) <= needed <= 1 / (2 * math.sqrt(2)) + RESOLUTION


def test_the_arch_plan_needs_three_holds():
    assembly = corbels(keystone=True)
    falling = plan(assembly, gravity=Gravity(holds=1)).to_dict()
    assert falling["gravity"]["stable"] is False
    assert falling["gravity"]["stands"] is True
    assert not falling["steps"][0]["stands"] and falling["steps"][0]["would_fall"]

    data = plan(assembly, gravity=Gravity(holds=3)).to_dict()
    assert data["feasible"] and data["gravity"]["stable"]
    assert [step["parts"] for step in data["steps"][:3]] == [
        ["keystone"],
        ["corbel_l"],
        ["corbel_r"],
    ]
    assert [sorted(step["held"]) for step in data["steps"][:3]] == [
        ["corbel_l", "corbel_r", "keystone"],
        ["corbel_l", "corbel_r"],
        ["corbel_r"],
    ]
    assert data["steps"][0]["would_fall"] == ["corbel_l", "corbel_r"]
    assert "ground" not in {name for step in data["steps"] for name in step["parts"]}
    assert_every_state_stands(assembly, data)
    # assembled in reverse: the keystone last, inserted downwards, both corbels held
    last = data["assembly_steps"][-1]
    assert last["parts"] == ["keystone"]
    assert last["direction"] == [0.0, 0.0, -1.0]
    assert sorted(last["held"]) == ["corbel_l", "corbel_r", "keystone"]


def test_a_leaning_pair_needs_one_hold():
    assembly = corbels(keystone=False)
    # by hand: overturning moment 1.8 x 0.1 = 0.18 = N x 1 at most, N <= mu 1.8: mu >= 0.1
    model = equilibrium_model(assembly, friction=MU)
    needed = model.friction_needed(model.mask(None), model.mask(["ground"]))
    assert needed is not None and 0.1 <= needed <= 0.1 + RESOLUTION
    data = plan(assembly, gravity=Gravity(holds=2)).to_dict()
    first = data["steps"][0]
    assert len(first["held"]) == 2 and set(first["held"]) == {"corbel_l", "corbel_r"}
    assert first["would_fall"] == [n for n in ("corbel_l", "corbel_r") if n not in first["parts"]]
    assert all(len(step["held"]) == 1 for step in data["steps"][1:])
    assert data["gravity"]["stable"]
    assert_every_state_stands(assembly, data)


def test_without_gravity_the_plan_is_unchanged_and_one_at_a_time_splits_steps():
    assembly = corbels(keystone=True)
    free = plan(assembly).to_dict()
    assert free["gravity"] is None
    assert all("held" not in step for step in free["steps"])
    one = plan(assembly, one_at_a_time=True).to_dict()
    assert all(len(step["parts"]) == 1 for step in one["steps"])
    assert sorted(n for step in one["steps"] for n in step["parts"]) == sorted(
        n for step in free["steps"] for n in step["parts"]
    )
    assert len(free["steps"]) < len(one["steps"]) == len(assembly.names) - 1


def test_gravity_directions_and_lowest_parts():
    assert gravity_direction("-z").tolist() == [0.0, 0.0, -1.0]
    assert gravity_direction("+y").tolist() == [0.0, 1.0, 0.0]
    assert gravity_direction("0, 0, -2").tolist() == [0.0, 0.0, -1.0]
    with pytest.raises(InputError, match="--gravity"):
        gravity_direction("up")
    assembly = overhanging_stack(0.4)
    tol = assembly.tolerance()
    assert lowest_parts(assembly, [0, 0, -1], tol) == ("bottom",)
    assert lowest_parts(assembly, [0, 0, 1], tol) == ("top",)
    with pytest.raises(UnknownNameError):
        equilibrium(assembly, fixed=["nothing"])


def test_the_compas_arch_is_planned_with_its_holds_listed():
    assembly = shared_assembly("compas_assembly/arch_assembly.json")
    result = plan(assembly, gravity=Gravity(holds=3), max_and_or_parts=0)
    data = result.to_dict()
    assert data["feasible"] and data["gravity"]["stable"]
    assert data["gravity"]["fixed"] == ["0", "29"]
    # a crown block goes first (14 and 15 are mirror images: which one is a float tie),
    # and every step but the last few holds the parts that would fall
    assert data["steps"][0]["parts"] in (["14"], ["15"])
    assert all(set(step["would_fall"]) or len(step["held"]) == 1 for step in data["steps"])
    assert_every_state_stands(assembly, data)


def test_declared_fixed_parts_are_never_moved():
    """The arch's springers declared fixed (a fixture): the 28 other blocks come off one
    at a time and the springers stay, so the assembly order starts on them."""
    assembly = shared_assembly("compas_assembly/arch_assembly.json")
    data = plan(assembly, gravity=Gravity(holds=3, fixed=("0", "29")), max_and_or_parts=0).to_dict()
    assert data["feasible"] and data["gravity"]["fixed"] == ["0", "29"]
    moved = [name for step in data["steps"] for name in step["parts"]]
    assert sorted(moved, key=int) == [str(k) for k in range(1, 29)]
    assert data["steps"][-1]["rest"] == ["0", "29"]
    assert {"0", "29"}.isdisjoint(n for s in data["assembly_steps"] for n in s["parts"])
    assert_every_state_stands(assembly, data)


@pytest.mark.slow
def test_the_asap_beam_comes_apart_beams_first_without_holds():
    assembly = shared_assembly("asap_beam_assembly")
    data = plan(assembly, gravity=Gravity(), max_and_or_parts=0).to_dict()
    assert [set(step["parts"]) for step in data["steps"]][:2] in ([{"0"}, {"1"}], [{"1"}, {"0"}])
    assert {n for step in data["steps"][2:] for n in step["parts"]} == {"2", "3"}
    assert all(step["held"] == step["parts"] for step in data["steps"])
    assert data["gravity"]["stable"]
    assert_every_state_stands(assembly, data)
    assert [step["parts"] for step in data["assembly_steps"]] == [
        step["parts"] for step in reversed(data["steps"])
    ]


def compas_forces(path) -> tuple[list[tuple[str, str, np.ndarray, np.ndarray]], float]:
    """The interface forces that compas_cra solved and stored in a COMPAS assembly file:
    per point (pushing block, pushed block, point, force), and the largest ratio of
    friction to compression among them."""
    edges = json.loads(path.read_text())["data"]["graph"]["data"]["edge"]
    found, ratio = [], 0.0
    for u, neighbours in edges.items():
        for v, edge in neighbours.items():
            for interface in edge["interfaces"] or ():
                data = interface["data"]
                frame = data["frame"]["data"]
                x, y = np.array(frame["xaxis"]), np.array(frame["yaxis"])
                for point, force in zip(data["points"], data["forces"], strict=True):
                    normal = force["c_np"] - force["c_nn"]
                    vector = normal * np.cross(x, y) + force["c_u"] * x + force["c_v"] * y
                    found.append((u, v, np.array(point["data"]), vector))
                    ratio = max(ratio, math.hypot(force["c_u"], force["c_v"]) / normal)
    return found, ratio


def test_an_independent_solution_of_the_arch_agrees_with_the_program():
    # compas_cra's stored interface forces, a solution found by another solver, balance
    # every free block's weight (density 1, at its volume centroid) as this model states
    # them; their points are this model's force points, so any friction whose inscribed
    # pyramid holds them (ratio / cos(pi / 8)) must let the program find the arch standing
    path = dataset("compas_assembly/arch_assembly.json")
    assembly = load_assembly(path)
    forces, ratio = compas_forces(path)
    wrench = {name: np.zeros(6) for name in assembly.names}
    for name, part in assembly.parts.items():
        weight = np.array([0.0, 0.0, -part.volume])
        wrench[name] += np.r_[weight, np.cross(part.mesh.center_mass, weight)]
    for pushing, pushed, point, force in forces:
        wrench[pushed] += np.r_[force, np.cross(point, force)]
        wrench[pushing] -= np.r_[force, np.cross(point, force)]
    model = equilibrium_model(assembly)
    free = [name for name in assembly.names if name not in model.fixed]
    assert max(np.abs(wrench[name]).max() / assembly.parts[name].volume for name in free) < 1e-4
    ours = contact_points(assembly, [0, 0, -1]).points
    assert all(np.linalg.norm(ours - point, axis=1).min() < 1e-6 for _, _, point, _ in forces)
    enough = ratio / math.cos(math.pi / CONE_SIDES)
    assert 0.1 < enough < MU
    assert equilibrium_model(assembly, friction=enough).check().stands
    needed = model.friction_needed(model.mask(None), model.mask(model.fixed))
    assert needed is not None and needed <= enough + RESOLUTION


@pytest.mark.parametrize(
    "steps",
    [
        pytest.param(2, marks=pytest.mark.early),
        pytest.param(20, marks=[pytest.mark.slow, pytest.mark.early]),
    ],
)
def test_the_cross_vault_planned_with_gravity_stands_step_by_step_from_the_top(steps: int):
    """The first ``steps`` steps of the cross vault's plan under gravity with one hold
    (the grip): 2 in the default tier, 20 in the slow one; the whole plan, minutes
    long, is a benchmark (``bench_stability.py --crossvault-plan``). Each block leaves
    alone, held by its grip and nothing more, and each state is decided again by a fresh
    model's whole program (none of the plan's shortcuts: balances and certificates kept,
    regions, the friction search's start): a state said to stand stands with the least
    friction said to be needed (and so with more), and on up to four steps spread over them
    not with one resolution less, even on every polygon vertex (not only the corners).
    The vault stands whole only once its crown joints are contacts (the tolerance), on
    fixed blocks that are not its crown. Taken down from the top, the vault stands for
    its first 77 steps (docs/planning.md, "Under gravity"); which of two mirror-image
    blocks goes first follows a rounding rule (docs/architecture.md, "Tolerances"), so
    the count of standing states is a bound and every verdict is checked."""
    assembly = shared_assembly("compas_assembly/crossvault_assembly.json")
    tol = Tolerance.relative(5e-5)
    data = plan(assembly, tol, gravity=Gravity(), max_and_or_parts=0, max_steps=steps).to_dict()
    moved = [name for step in data["steps"] for name in step["parts"]]
    assert len(data["steps"]) == steps and not data["feasible"] and not data["stuck"]
    assert sorted(data["unfinished"]) == sorted(set(assembly.names) - set(moved))
    assert data["gravity"]["stands"] and len(data["gravity"]["fixed"]) == 4
    crown = {"5", "6", "7", "8", "9", "10", "11", "12", "13", "14"}
    assert not crown & set(data["gravity"]["fixed"])
    assert all(step["held"] == step["parts"] and len(step["parts"]) == 1 for step in data["steps"])
    assert len(set(moved)) == steps and not set(moved) & set(data["gravity"]["fixed"])

    model = equilibrium_model(assembly, friction=MU, tol=tol)
    every = dataclasses.replace(model, corners=np.ones_like(model.corners))
    fixed = model.mask(data["gravity"]["fixed"])
    spread = set(np.linspace(0, steps - 1, 4).round().astype(int).tolist())
    for number, step in enumerate(data["steps"]):
        rest = model.mask(step["rest"])
        if step["stands"]:
            assert step["would_fall"] == []
            needed = step["friction_needed"]
            assert needed is not None and 0 <= needed <= MU
            assert model.stands(rest, rest & fixed, needed, local=False), step["parts"]
            if number in spread and needed > 0:
                # falling on every polygon vertex, it falls on the corners the plan uses
                assert not every.stands(rest, rest & fixed, needed - RESOLUTION, local=False)
        else:
            # a state said to fall does not stand; a part left unbalanced by the whole
            # program by more than ten times the tolerance is named; a part named is
            # unbalanced by a tenth of it at least
            assert not every.stands(rest, rest & fixed, local=False), step["parts"]
            residual = whole_residuals(every, rest, rest & fixed)
            named = set(step["would_fall"])
            assert {n for n, r in residual.items() if r > 10 * every.threshold} <= named
            assert all(residual[n] > every.threshold / 10 for n in named)
            assert named and step["friction_needed"] is None
    assert sum(step["stands"] for step in data["steps"]) >= steps - steps // 8


def test_the_arch_on_its_springers_names_what_falls_at_each_falling_step():
    """With one hold (the grip alone) and the springers fixed, the arch's plan has
    falling steps; each names the blocks the whole slack program, written out
    independently (:func:`whole_residuals`), leaves unbalanced, and a standing step
    names none (how many programs the plan solves for it is a figure of
    benchmarks/bench_stability.py)."""
    assembly = shared_assembly("compas_assembly/arch_assembly.json")
    data = plan(assembly, gravity=Gravity(fixed=("0", "29")), max_and_or_parts=0).to_dict()
    assert data["feasible"] and not data["gravity"]["stable"]
    model = equilibrium_model(assembly, friction=MU, fixed=["0", "29"])
    every = dataclasses.replace(model, corners=np.ones_like(model.corners))
    fixed = every.mask(["0", "29"])
    falling = [step for step in data["steps"] if not step["stands"]]
    assert falling and all(not step["would_fall"] for step in data["steps"] if step["stands"])
    for step in falling:
        rest = every.mask(step["rest"])
        residual = whole_residuals(every, rest, rest & fixed)
        named = set(step["would_fall"])
        assert named and {n for n, r in residual.items() if r > 10 * every.threshold} <= named
        assert all(residual[n] > every.threshold / 10 for n in named)
        # the margin of the verdict: the largest share of a weight left unbalanced
        assert step["unbalanced"] > step["fall_threshold"] == every.threshold
        assert max(residual.values()) / 5 <= step["unbalanced"] <= 5 * max(residual.values())
    assert all(step["unbalanced"] is None for step in data["steps"] if step["stands"])


def test_under_gravity_parts_lift_and_never_leave_through_the_ground():
    # gravity along -y: a slab on the ground (y from 0 to 1) with a pin standing in a
    # through hole, flush with the ground, and a nut lying loose on the slab. Taking the
    # pin out downwards would pass through the ground the slab stands on; the pin lifts
    # out along +y, and the nut lifts rather than sliding off sideways
    slab = trimesh.boolean.difference(
        [box((6, 1, 6), (-3, 0, -3)), box((1, 3, 1), (-0.5, -1, -0.5))], engine="manifold"
    )
    pin = box((1, 2, 1), (-0.5, 0, -0.5))
    nut = box((1, 0.5, 1), (1.5, 1, 1.5))
    assembly = Assembly([Part("slab", slab), Part("pin", pin), Part("nut", nut)])
    result = plan(assembly, gravity=Gravity(direction=(0.0, -1.0, 0.0)), max_and_or_parts=0)
    assert result.feasible and {s.parts for s in result.steps} == {("pin",), ("nut",)}
    for step in result.steps:
        np.testing.assert_allclose(step.direction, [0.0, 1.0, 0.0], atol=1e-9)
    assert_steps_clear(assembly, result)
