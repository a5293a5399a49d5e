"""The first equilibrium program (whether a state's equations alone have a solution) is
solved by Clarabel (:func:`assemblykit.planning.equilibrium_programs.balance`): on states
of the COMPAS arch, stacked and corbelled blocks, a block on a slope and the cross vault, at
several friction coefficients, its verdict must be that of HiGHS's interior point method
(scipy's ``linprog``), the solver it replaced, on every vertex of the contact polygons
where the model keeps only the corners. The slack program solved by pieces and the
verdicts drawn from what an :class:`EquilibriumMemory` keeps are checked here too (the
programs themselves, on matrices written by hand: test_equilibrium_programs.py)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linprog

from assemblykit.errors import NumericError
from assemblykit.io.assembly import load_assembly
from assemblykit.model.assembly import Assembly, Part
from assemblykit.planning import equilibrium, equilibrium_programs
from assemblykit.planning.planner import plan
from assemblykit.planning.stability import (
    CONE_SIDES,
    FRICTION_STEPS,
    LP_FEASIBILITY,
    EquilibriumMemory,
    EquilibriumModel,
    Gravity,
    equilibrium_model,
    least_residuals,
)
from assemblykit.tolerance import Tolerance
from datasets import dataset, shared_assembly
from stability_blocks import block_on_slope, box, corbels, overhanging_stack

FRICTIONS = (0.0, 0.1, 0.3, 0.5)
RESOLUTION = 0.5 / 2**FRICTION_STEPS


def highs_stands(
    model: EquilibriumModel, present: np.ndarray, fixed: np.ndarray, friction: float
) -> bool:
    """The first program written out from the model's public arrays, on every vertex
    (not only the corners the model keeps), and solved by HiGHS's interior point
    method."""
    free = present & ~fixed
    if not free.any():
        return True
    rows = (6 * np.flatnonzero(free)[:, None] + np.arange(6)).ravel()
    points = present[model.point_parts[:, 0]] & present[model.point_parts[:, 1]]
    selected = np.flatnonzero(points)
    if not len(selected):
        return False
    columns = (CONE_SIDES * selected[:, None] + np.arange(CONE_SIDES)).ravel()
    matrix = model.normal_part[rows][:, columns] + friction * model.tangent_part[rows][:, columns]
    found = linprog(
        np.zeros(len(columns)),
        A_eq=matrix.tocsc(),
        b_eq=-model.load[rows],
        bounds=(0, None),
        method="highs-ipm",
        options={"primal_feasibility_tolerance": LP_FEASIBILITY},
    )
    assert found.status in (0, 2), found.message
    return bool(found.status == 0)


def verdicts(
    model: EquilibriumModel, states: list[set[str] | None], frictions: tuple[float, ...]
) -> tuple[list[bool], list[bool]]:
    """Per state and friction: Clarabel's verdict (HiGHS, its fallback, never asked;
    the states asked one after the other, with one memory) and HiGHS's."""
    ours, reference = [], []
    memory = EquilibriumMemory()
    for parts in states:
        present = model.mask(parts)
        fixed = present & model.mask(model.fixed)
        for friction in frictions:
            with pytest.MonkeyPatch.context() as patch:
                patch.setattr(equilibrium_programs, "linprog", None)
                ours.append(model.stands(present, fixed, friction, memory=memory))
            reference.append(highs_stands(model, present, fixed, friction))
    return ours, reference


def without_each(assembly: Assembly) -> list[set[str] | None]:
    """The whole assembly, and without each of its parts in turn."""
    return [None, *(set(assembly.names) - {name} for name in assembly.names)]


@pytest.mark.parametrize(
    "assembly",
    [
        overhanging_stack(0.4),
        overhanging_stack(0.45),
        overhanging_stack(0.55),
        overhanging_stack(0.6),
        corbels(keystone=True),
        block_on_slope(25.0),
    ],
    ids=["stack 0.4", "stack 0.45", "stack 0.55", "stack 0.6", "corbels", "slope 25"],
)
def test_blocks_computed_by_hand_get_highs_verdicts(assembly):
    model = equilibrium_model(assembly)
    ours, reference = verdicts(model, without_each(assembly), (*FRICTIONS, 0.35, 0.36, 0.47))
    assert ours == reference
    assert any(ours) and not all(ours)


def test_the_arch_gets_highs_verdicts_without_each_block():
    assembly = shared_assembly("compas_assembly/arch_assembly.json")
    model = equilibrium_model(assembly)
    ours, reference = verdicts(model, without_each(assembly), FRICTIONS)
    assert ours == reference
    assert any(ours) and not all(ours)


@pytest.mark.slow
def test_the_cross_vault_gets_highs_verdicts():
    # at the tolerance that makes its crown joints contacts (it stands), and without its
    # highest block or one of its crown blocks; at the default tolerance (it falls)
    path = dataset("compas_assembly/crossvault_assembly.json")
    for tol, removed in ((Tolerance.relative(5e-5), ("4", "9")), (None, ())):
        assembly = load_assembly(path)
        model = equilibrium_model(assembly, tol=tol)
        states = [None, *(set(assembly.names) - {name} for name in removed)]
        ours, reference = verdicts(model, states, (0.5,))
        assert ours == reference


@pytest.mark.slow
def test_local_verdicts_are_those_of_the_whole_program_on_a_vault_taken_down():
    """The cross vault taken down from its highest block, one block at a time: at each
    state and two friction coefficients, also with its highest block held, the verdict
    found from the last balance (a balance kept, or a Farkas certificate on a few parts)
    is the whole program's, and both shortcuts decide some of the states."""
    tol = Tolerance.relative(5e-5)
    assembly = load_assembly(dataset("compas_assembly/crossvault_assembly.json"))
    model = equilibrium_model(assembly, tol=tol)
    decided: list[bool | None] = []
    original = EquilibriumModel._local_verdict

    def recorded(self, *args):
        decided.append(original(self, *args))
        return decided[-1]

    order = sorted(assembly.names, key=lambda n: -float(model.heights[model.mask([n])][0]))
    ours, whole = [], []
    memory = EquilibriumMemory()
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(EquilibriumModel, "_local_verdict", recorded)
        for removed in range(12):
            present = model.mask(order[removed:])
            fixed = present & model.mask(model.fixed)
            for friction in (0.5, 0.3):
                for held in (fixed, fixed | model.mask(order[removed : removed + 1])):
                    ours.append(model.stands(present, held, friction, memory=memory))
                    whole.append(model.stands(present, held, friction, False, memory=memory))
    assert ours == whole
    assert any(ours) and not all(ours)
    assert True in decided and False in decided


def two_stacks() -> Assembly:
    """On one ground slab, two stacks of two unit cubes 3 apart, the left one's top
    overhanging by 0.4 (its centre over its support: it stands), the right one's by 0.6
    (it falls); and a loose cube touching nothing."""
    return Assembly(
        [
            Part("ground", box((8, 1, 1), (-1, 0, -1))),
            Part("left", box((1, 1, 1), (0, 0, 0))),
            Part("left_top", box((1, 1, 1), (0.4, 0, 1))),
            Part("right", box((1, 1, 1), (3, 0, 0))),
            Part("right_top", box((1, 1, 1), (3.6, 0, 1))),
            Part("loose", box((1, 1, 1), (20, 0, 5))),
        ]
    )


def test_the_slack_program_solved_piece_by_piece_is_the_whole_program():
    model = equilibrium_model(two_stacks(), friction=0.5, fixed=["ground"])
    present, fixed = model.mask(None), model.mask(["ground"])
    pieces = model.pieces(present, fixed)
    assert sorted(sorted(model.names[i] for i in np.flatnonzero(p)) for p in pieces) == [
        ["left", "left_top"],
        ["loose"],
        ["right", "right_top"],
    ]
    memory = EquilibriumMemory()
    residuals = dict(zip(model.names, model.slack(present, fixed, memory=memory), strict=True))
    # the loose cube keeps its whole weight, the right top falls, the left stack stands
    assert residuals["loose"] == pytest.approx(1.0)
    assert residuals["right_top"] > 1e-3 > 10 * model.threshold and residuals["ground"] == 0.0
    assert max(residuals["left"], residuals["left_top"]) < model.threshold
    # the same residuals as the whole program over every free part at once
    free = present & ~fixed
    rows = (6 * np.flatnonzero(free)[:, None] + np.arange(6)).ravel()
    selected = present[model.point_parts[:, 0]] & present[model.point_parts[:, 1]]
    whole = least_residuals(model._matrix(rows, selected & model.corners, 0.5), -model.load[rows])
    falls = np.abs(whole).reshape(-1, 6).max(axis=1) > model.threshold
    named = [n for n, f in zip(np.array(model.names)[free], falls, strict=True) if f]
    assert named == ["right_top", "loose"]
    assert [n for n in model.names if residuals[n] > model.threshold] == named
    # the left top taken away: the right piece's residuals stay (kept, with the loose
    # cube's: only the new left piece is solved), the left one stands
    without = present & ~model.mask(["left_top"])
    again = dict(zip(model.names, model.slack(without, fixed, memory=memory), strict=True))
    assert len(memory.residuals) == 4
    assert again["right_top"] == residuals["right_top"] and again["loose"] == residuals["loose"]
    assert again["left"] < model.threshold


def test_slack_programs_solved_together_are_those_slack_solves_one_by_one(monkeypatch):
    # the states of taking each block of the two stacks away (each falls: the loose
    # cube does): solved together on two threads (however small), then read by slack,
    # as slack alone solves them, with the memory holding the same residuals in the
    # same order
    model = equilibrium_model(two_stacks(), friction=0.5, fixed=["ground"])
    present, fixed = model.mask(None), model.mask(["ground"])
    states = [(present & ~model.mask([name]), fixed) for name in ("left_top", "right", "left")]
    alone = EquilibriumMemory()
    expected = [model.slack(p, f, memory=alone) for p, f in states]
    monkeypatch.setattr(equilibrium_programs, "program_threads", lambda: 2)
    monkeypatch.setattr(equilibrium, "THREADED_PARTS", 1)
    together = EquilibriumMemory()
    model.solve_slack(states, memory=together)
    assert [key for key, _ in together.residuals.items()] == [
        key for key, _ in alone.residuals.items()
    ]
    kept = len(together.residuals)
    for (p, f), residuals in zip(states, expected, strict=True):
        assert np.array_equal(model.slack(p, f, memory=together), residuals)
    assert len(together.residuals) == kept
    # what is kept already is not solved again
    model.solve_slack(states, memory=together)
    assert len(together.residuals) == kept


def test_a_plan_under_gravity_is_the_same_with_its_slack_programs_solved_together(monkeypatch):
    # the arch with one hold: from its first steps no removal stands, and each step
    # takes the one that leaves the fewest blocks falling, whose slack programs are
    # solved together (on threads, however few its blocks)
    arch = load_assembly(dataset("compas_assembly/arch_assembly.json"))
    solved: list[int] = []
    solve_slack = EquilibriumModel.solve_slack

    def counted(self, states, friction=None, *, memory):
        states = list(states)
        solved.append(len(states))
        return solve_slack(self, states, friction, memory=memory)

    monkeypatch.setattr(EquilibriumModel, "solve_slack", counted)
    monkeypatch.setattr(equilibrium_programs, "program_threads", lambda: 1)
    one = plan(arch, gravity=Gravity()).to_dict()
    assert max(solved) >= 2
    monkeypatch.setattr(equilibrium_programs, "program_threads", lambda: 2)
    monkeypatch.setattr(equilibrium, "THREADED_PARTS", 1)
    assert plan(arch, gravity=Gravity()).to_dict() == one


def bisected(model: EquilibriumModel, present: np.ndarray, fixed: np.ndarray) -> float | None:
    """The least friction coefficient by plain bisection, each state solved whole."""
    if not model.stands(present, fixed, local=False):
        return None
    if model.stands(present, fixed, 0.0, local=False):
        return 0.0
    low, high = 0.0, model.friction
    for _ in range(FRICTION_STEPS):
        middle = (low + high) / 2
        if model.stands(present, fixed, middle, local=False):
            high = middle
        else:
            low = middle
    return high


def test_the_least_friction_searched_from_the_last_answer_is_the_bisections():
    # the states the arch's plan with three holds leaves standing, one after the other:
    # the search that starts from the last answer finds what bisection finds (the
    # programs it saves are a figure of benchmarks/bench_stability.py)
    assembly = shared_assembly("compas_assembly/arch_assembly.json")
    result = plan(assembly, gravity=Gravity(holds=3))
    model, memory = equilibrium_model(assembly), EquilibriumMemory()
    states = []
    for step in result.steps:
        present = model.mask(step.rest)
        held = model.mask(model.fixed) | model.mask(step.stability.held)
        states.append((present, present & held))
    expected = [bisected(model, present, fixed) for present, fixed in states]
    found = [model.friction_needed(present, fixed, memory=memory) for present, fixed in states]
    # what a balance needs: never above the multiple bisection finds, less than a step
    # below it (the least one is above the step below), 0 where bisection finds 0
    assert None not in found and None not in expected
    for need, multiple in zip(found, expected, strict=True):
        assert multiple - RESOLUTION < need <= multiple + 1e-12
        assert (need == 0) is (multiple == 0)
    assert len(set(expected)) > 4


def standing_vault() -> tuple[EquilibriumModel, np.ndarray, np.ndarray]:
    """A new model of the cross vault with its crown joints as contacts (it stands), the
    mask of all its parts and that of its fixed ones."""
    model = equilibrium_model(
        shared_assembly("compas_assembly/crossvault_assembly.json"), tol=Tolerance.relative(5e-5)
    )
    present = model.mask(None)
    return model, present, present & model.mask(model.fixed)


def test_verdicts_from_kept_balances_and_certificates_are_the_whole_programs():
    # a balance found at 0.45 answers the larger frictions, a certificate of a fall at
    # 0.3 the smaller ones; each verdict is the one the whole program gives, nothing kept
    model, present, fixed = standing_vault()
    memory = EquilibriumMemory()
    for friction, stands in ((0.45, True), (0.9, True), (0.3, False), (0.0, False)):
        assert model.stands(present, fixed, friction, memory=memory) is stands
        assert model.stands(present, fixed, friction, local=False) is stands
    assert len(memory.balances) and len(memory.certificates)
    # holding the highest block changes the state: the kept certificate does not decide it
    held = fixed | model.mask([model.names[int(np.argmin(model.heights))]])
    whole = model.stands(present, held, 0.3, local=False)
    assert model.stands(present, held, 0.3, memory=memory) == whole


def test_a_region_no_solver_decides_is_left_to_the_whole_program(monkeypatch):
    # the arch taken down from its highest block, with what answered the states before
    # kept: every program on fewer equations than the state's (a region's) fails, as if
    # no solver decided it, and every verdict is still the whole program's
    assembly = load_assembly(dataset("compas_assembly/arch_assembly.json"))
    model = equilibrium_model(assembly)
    order = sorted(assembly.names, key=lambda n: -float(model.heights[model.mask([n])][0]))
    states = []
    for removed in range(len(order) - len(model.fixed)):
        present = model.mask(order[removed:])
        states.append((present, present & model.mask(model.fixed)))
    equations = [0]
    failed = []

    def undecided(matrix, rhs):
        if matrix.shape[0] < equations[0]:
            failed.append(matrix.shape[0])
            raise NumericError("equilibrium program failed: undecided")
        return equilibrium_programs.balance(matrix, rhs)

    memory = EquilibriumMemory()
    ours = []
    with monkeypatch.context() as patch:
        patch.setattr(equilibrium, "balance", undecided)
        for present, fixed in states:
            equations[0] = 6 * int((present & ~fixed).sum())
            for friction in (0.5, 0.2):
                ours.append(model.stands(present, fixed, friction, memory=memory))
    whole = [
        model.stands(present, fixed, friction, local=False)
        for present, fixed in states
        for friction in (0.5, 0.2)
    ]
    assert failed and ours == whole
    assert any(ours) and not all(ours)
