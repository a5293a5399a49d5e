"""The least friction a state needs (:meth:`EquilibriumModel.friction_needed`: what a
balance found needs, not a multiple of the resolution) and, for a state that falls,
whether it tips over or slides (:meth:`EquilibriumModel.tips`), on blocks computed by
hand; each answer is checked by a linear program written out here from the contact
points alone (:func:`independent_stands`, HiGHS), not from the model's matrices."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.optimize import linprog

from assemblykit.model.assembly import Assembly, Part
from assemblykit.planning.planner import plan
from assemblykit.planning.stability import (
    CONE_SIDES,
    FRICTION_STEPS,
    EquilibriumMemory,
    Gravity,
    GravityReport,
    StepStability,
    contact_points,
    equilibrium_model,
)
from stability_blocks import block_on_slope, box, corbels, overhanging_stack

MU = 0.5
RESOLUTION = MU / 2**FRICTION_STEPS


def independent_stands(assembly: Assembly, fixed: set[str], friction: float | None) -> bool:
    """Whether every part of ``assembly`` but ``fixed`` is in equilibrium under gravity
    along -z (weight = volume at the volume centroid) with compressive forces at the
    contact points: inside the 8-sided pyramid of ``friction`` spanned by
    ``n + friction (cos t u + sin t v)``, or with any tangential force when ``friction``
    is ``None``. Solved by HiGHS's simplex."""
    found = contact_points(assembly, [0, 0, -1])
    free = [name for name in assembly.names if name not in fixed]
    row = {assembly.names.index(name): 6 * k for k, name in enumerate(free)}
    if friction is None:
        per_point = [found.normals, found.u, -found.u, found.v, -found.v]
    else:
        angles = 2 * np.pi * np.arange(CONE_SIDES) / CONE_SIDES
        per_point = [
            found.normals + friction * (math.cos(a) * found.u + math.sin(a) * found.v)
            for a in angles
        ]
    columns = []
    for p, point in enumerate(found.points):
        for directions in per_point:
            column = np.zeros(6 * len(free))
            force = directions[p]
            # the pushed part gets the force, the pushing one its opposite
            for part, sign in ((found.second[p], 1.0), (found.first[p], -1.0)):
                if int(part) in row:
                    at = row[int(part)]
                    column[at : at + 3] += sign * force
                    column[at + 3 : at + 6] += sign * np.cross(point, force)
            columns.append(column)
    load = []
    for name in free:
        part = assembly.parts[name]
        weight = np.array([0.0, 0.0, -part.volume])
        load.append(-np.r_[weight, np.cross(part.mesh.center_mass, weight)])
    result = linprog(
        np.zeros(len(columns)),
        A_eq=np.stack(columns, axis=1),
        b_eq=np.concatenate(load),
        bounds=(0, None),
        method="highs",
    )
    assert result.status in (0, 2), result.message
    return bool(result.status == 0)


def slope_of(tangent: float) -> Assembly:
    """A unit cube on a slope of tangent ``tangent``."""
    return block_on_slope(math.degrees(math.atan(tangent)))


@pytest.mark.parametrize("slope", [0.364, 0.2])
def test_a_block_on_a_slope_needs_exactly_the_slopes_tangent(slope):
    # the pyramid's u axis is the downhill direction: exact for sliding down the slope,
    # where the least multiple of the resolution (0.375 for 0.364) is not
    assembly = slope_of(slope)
    model = equilibrium_model(assembly, friction=MU)
    present = model.mask(None)
    needed = model.friction_needed(present, model.mask(["slope"]))
    assert needed is not None and abs(needed - slope) <= 1e-6
    assert math.isclose(MU - needed, MU - slope, abs_tol=1e-6)
    assert independent_stands(assembly, {"slope"}, slope + 1e-6)
    assert not independent_stands(assembly, {"slope"}, slope - 1e-6)


def least_multiple(assembly: Assembly, fixed: list[str]) -> float:
    """The least multiple of the resolution with which a fresh model's whole program
    finds the state standing: what the search answered before it read the balances."""
    model = equilibrium_model(assembly, friction=MU)
    present, held = model.mask(None), model.mask(fixed)
    k = next(
        k
        for k in range(2**FRICTION_STEPS + 1)
        if model.stands(present, held, k * RESOLUTION, local=False)
    )
    return k * RESOLUTION


@pytest.mark.parametrize(
    ("assembly", "least"),
    [(corbels(keystone=True), 1 / (2 * math.sqrt(2))), (corbels(keystone=False), 0.1)],
    ids=["corbelled arch", "leaning pair"],
)
def test_the_friction_needed_stays_in_the_bracket_of_the_resolution(assembly, least):
    # the hand-computed least friction (tests/planning/test_stability.py) is not above
    # the answer, which is not above the least multiple of the resolution that stands,
    # and the whole program stands with it but not a resolution below
    model, memory = equilibrium_model(assembly, friction=MU), EquilibriumMemory()
    present, fixed = model.mask(None), model.mask(["ground"])
    needed = model.friction_needed(present, fixed, memory=memory)
    assert needed is not None
    assert least - 1e-9 <= needed <= least_multiple(assembly, ["ground"]) + 1e-12
    assert model.stands(present, fixed, needed, local=False)
    assert not model.stands(present, fixed, needed - RESOLUTION, local=False)
    # asked again, the same answer from the balances kept (the search's warm start)
    again = model.friction_needed(present, fixed, memory=memory)
    assert again == pytest.approx(needed, abs=1e-9)


def test_a_state_that_stands_without_friction_needs_none():
    model = equilibrium_model(overhanging_stack(0.4), friction=MU)
    assert model.friction_needed(model.mask(None), model.mask(["bottom"])) == 0.0


def test_a_top_past_its_support_tips_and_a_block_on_a_steep_slope_slides():
    # the top's centre overhangs its support by 0.1: no friction holds it
    stack = overhanging_stack(0.6)
    model = equilibrium_model(stack, friction=MU)
    present, fixed = model.mask(None), model.mask(["bottom"])
    assert model.friction_needed(present, fixed) is None
    assert model.tips(present, fixed)
    assert not independent_stands(stack, {"bottom"}, None)
    # a unit cube on a slope with tan = 0.8 > 0.5 slides, and friction 0.8 holds it;
    # past 45 degrees (tan = 1.2) its centre is beyond its downhill edge: it tips
    for tangent, tips in ((0.8, False), (1.2, True)):
        slope = slope_of(tangent)
        model = equilibrium_model(slope, friction=MU)
        present, fixed = model.mask(None), model.mask(["slope"])
        assert model.friction_needed(present, fixed) is None
        assert model.tips(present, fixed) is tips
        assert independent_stands(slope, {"slope"}, None) is not tips
        assert not independent_stands(slope, {"slope"}, MU)
    assert independent_stands(slope_of(0.8), {"slope"}, 0.8 + 1e-6)


def test_a_step_that_tips_says_so_and_one_that_slides_needs_more_friction():
    # the corbelled arch's keystone taken with one hold: the corbels tip inwards
    data = plan(corbels(keystone=True), gravity=Gravity(holds=1)).to_dict()
    first = data["steps"][0]
    assert not first["stands"] and first["friction_needed"] is None and first["tips"]
    assert all(step["tips"] is False for step in data["steps"] if step["stands"])
    cells = {
        tips: StepStability(
            held=("top",),
            would_fall=("top",),
            stands=False,
            friction_needed=None,
            friction=MU,
            tips=tips,
        ).cells()[2]
        for tips in (True, False)
    }
    assert cells == {True: "tips", False: "more than μ"}


def test_a_part_touching_nothing_tips_and_the_whole_assembly_has_cells():
    assembly = Assembly(
        [Part("ground", box((2, 2, 1), (0, 0, 0))), Part("floating", box((1, 1, 1), (0, 0, 3)))]
    )
    model = equilibrium_model(assembly, friction=MU)
    present, fixed = model.mask(None), model.mask(["ground"])
    assert model.friction_needed(present, fixed) is None and model.tips(present, fixed)
    whole = model.check()
    report = GravityReport(Gravity(), ("ground",), whole, None, stable=False, tips=True)
    assert report.cells() == ["-", "floating", "tips"]
    assert dataclasses.replace(report, tips=False).cells()[2] == "more than μ"
