"""Force points on a straight stretch of a contact polygon's boundary are left out of
the first equilibrium program (whether the equations alone have a solution): the answers
must be those of the programs with every vertex, and vertices off the stretch must
stay (which vertices are corners: test_force_points.py)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.optimize import linprog

from assemblykit.errors import NumericError
from assemblykit.planning import force_points
from assemblykit.planning.stability import (
    CONE_SIDES,
    FRICTION_STEPS,
    EquilibriumMemory,
    EquilibriumModel,
    contact_points,
    equilibrium_model,
    least_residuals,
)
from datasets import shared_assembly
from stability_blocks import corbels, overhanging_stack

MU = 0.5


def with_midpoints(monkeypatch: pytest.MonkeyPatch, bulge: float) -> None:
    """Give every contact polygon a vertex in the middle of each side, moved outwards
    (across the side, in the contact plane) by ``bulge``."""
    original = force_points.assembly_contacts

    def patched(assembly, tol=None):
        found = []
        for contact in original(assembly, tol):
            planar = []
            for patch in contact.planar:
                polygon = np.asarray(patch.polygon, dtype=np.float64)
                middle = (polygon + np.roll(polygon, -1, axis=0)) / 2
                outward = middle - polygon.mean(axis=0)
                outward -= (outward @ patch.normal)[:, None] * patch.normal
                middle += bulge * outward / np.linalg.norm(outward, axis=1, keepdims=True)
                ring = np.stack([polygon, middle], axis=1).reshape(-1, 3)
                planar.append(dataclasses.replace(patch, polygon=ring))
            found.append(dataclasses.replace(contact, planar=tuple(planar)))
        return found

    monkeypatch.setattr(force_points, "assembly_contacts", patched)


def answers(model: EquilibriumModel, states: list[set[str]]) -> list[tuple]:
    """Per state (asked in turn, with one memory): the parts that would fall and the
    least friction it needs."""
    out = []
    memory = EquilibriumMemory()
    for parts in states:
        present = model.mask(parts)
        fixed = present & model.mask(model.fixed)
        found = model.check(parts, memory=memory)
        out.append((found.would_fall, model.friction_needed(present, fixed, memory=memory)))
    return out


def assert_same(found: list[tuple], expected: list[tuple]) -> None:
    """The same parts fall, and the friction needed is the same within the resolution
    of the search (what a balance needs depends on the points it has: with more, a
    balance may need less)."""
    assert [falls for falls, _ in found] == [falls for falls, _ in expected]
    for (_, need), (_, other) in zip(found, expected, strict=True):
        assert (need is None) is (other is None)
        if need is not None:
            assert abs(need - other) < MU / 2**FRICTION_STEPS


CASES = [
    (overhanging_stack(0.4), [{"bottom", "middle", "top"}]),
    (overhanging_stack(0.6), [{"bottom", "middle", "top"}, {"bottom", "middle"}]),
    (
        corbels(keystone=True),
        [
            {"ground", "pillar_l", "pillar_r", "corbel_l", "corbel_r", "keystone"},
            {"ground", "pillar_l", "pillar_r", "corbel_l", "corbel_r"},
            {"ground", "pillar_l", "corbel_l"},
        ],
    ),
]


@pytest.mark.parametrize(("assembly", "states"), CASES)
def test_vertices_between_their_neighbours_are_left_out_with_the_same_answers(
    monkeypatch, assembly, states
):
    plain = contact_points(assembly, [0, 0, -1])
    expected = answers(equilibrium_model(assembly, friction=MU), states)
    assert plain.corners.all()
    with monkeypatch.context() as patch:
        with_midpoints(patch, 0.0)
        # the midpoints are on the sides: no corners, the same answers
        found = contact_points(assembly, [0, 0, -1])
        assert len(found.points) == 2 * len(plain.points)
        assert np.array_equal(found.points[found.corners], plain.points)
        model = equilibrium_model(assembly, friction=MU)
        assert model.normal_part.shape[1] == len(found.points) * CONE_SIDES
        assert_same(answers(model, states), expected)
        # and the programs with every midpoint agree
        patch.setattr(
            force_points,
            "_corners",
            lambda polygons, resolution: np.ones(sum(map(len, polygons)), dtype=bool),
        )
        full = equilibrium_model(assembly, friction=MU)
        assert full.corners.all() and not model.corners.all()
        assert_same(answers(full, states), expected)


@pytest.mark.slow
def test_the_cross_vault_has_the_same_least_residuals_on_its_corners():
    """At the default tolerance the cross vault does not stand; the least residuals of
    its equations over the corners of its contact polygons are those over every vertex
    (6.3125 by HiGHS on every vertex; 6.3331 when repeated corners were lost). The
    optimum is checked against HiGHS's dual simplex on the program written out here,
    to the interior point method's accuracy (relative 1e-4), not against one release's
    digits."""
    model = equilibrium_model(shared_assembly("compas_assembly/crossvault_assembly.json"))
    present = model.mask(None)
    free = present & ~model.mask(model.fixed)
    rows = (6 * np.flatnonzero(free)[:, None] + np.arange(6)).ravel()
    optimum = []
    for points in (np.ones_like(model.corners), model.corners):
        columns = (CONE_SIDES * np.flatnonzero(points)[:, None] + np.arange(CONE_SIDES)).ravel()
        matrix = (model.normal_part + MU * model.tangent_part)[rows][:, columns].tocsc()
        optimum.append(np.abs(least_residuals(matrix, -model.load[rows])).sum())
    columns = (CONE_SIDES * np.arange(len(model.corners))[:, None] + np.arange(CONE_SIDES)).ravel()
    matrix = (model.normal_part + MU * model.tangent_part)[rows][:, columns].tocsc()
    eye = sp.identity(len(rows), format="csc")
    independent = linprog(
        np.r_[np.zeros(matrix.shape[1]), np.ones(2 * len(rows))],
        A_eq=sp.hstack([matrix, eye, -eye], format="csc"),
        b_eq=-model.load[rows],
        bounds=(0, None),
        method="highs-ds",
    )
    assert independent.status == 0
    assert 6.3 < independent.fun < 6.33
    assert optimum[0] == pytest.approx(independent.fun, rel=1e-4)
    assert optimum[1] == pytest.approx(optimum[0], rel=1e-6)


def test_points_off_the_sides_are_kept_and_change_what_stands(monkeypatch):
    # the top block overhangs 0.55: its centre at x = 1.05 is beyond the middle block
    # (x <= 1); a contact polygon bulged 0.1 outwards across each side reaches x = 1.1,
    # so those points are kept and the top stands on them
    assembly = overhanging_stack(0.55)
    assert equilibrium_model(assembly).check().would_fall == ("top",)
    with_midpoints(monkeypatch, 0.1)
    found = contact_points(assembly, [0, 0, -1])
    assert len(found.points) == 16 and found.corners.all()
    assert equilibrium_model(assembly).check().stands


def test_the_whole_arch_balance_proves_a_voussoir_removal_falls_from_the_gap_alone():
    # the memory holds only the whole arch's balance as its reference: a state taken
    # from the arch is proved to fall from the equations of the blocks around the gap,
    # and the reference never shows a state to stand (no balance is kept)
    model = equilibrium_model(shared_assembly("compas_assembly/arch_assembly.json"))
    present = model.mask(None)
    fixed = present & model.mask(model.fixed)
    reference = model.reference(present, fixed)
    assert reference is not None
    for taken in ("9", "14", "20"):
        state = present & ~model.mask([taken])
        memory = EquilibriumMemory()
        memory.reference = reference
        assert not model.stands(state, fixed, memory=memory)
        assert len(memory.balances) == 0
        (y,) = memory.certificates.values()
        # a few blocks' equations around the gap, not the arch's
        assert np.count_nonzero(y) <= 6 * 4 < 6 * int((state & ~fixed).sum())
        # an independent check of Farkas' lemma on the whole state's first program:
        # no generator gains from y while the loads do, so no balance exists
        free = state & ~fixed
        rows = model._rows(free)
        matrix = model._matrix(rows, model._touching(state) & model.corners, model.friction)
        rhs = -model.load[rows]
        assert rhs @ y[rows] < 0
        assert (matrix.T @ y[rows]).min() >= 1e-7 * (rhs @ y[rows])
        assert not linprog(
            np.zeros(matrix.shape[1]), A_eq=matrix, b_eq=rhs, bounds=(0, None), method="highs"
        ).success
    # a state that stands is not decided by the reference: its own program says so
    memory = EquilibriumMemory()
    memory.reference = reference
    assert model.stands(present, fixed, memory=memory)
    # the whole state of an arch missing its keystone falls: no reference for it
    keystone = present & ~model.mask(["14"])
    assert model.reference(keystone, fixed & keystone) is None


def test_a_reference_no_solver_decides_is_none(monkeypatch):
    model = equilibrium_model(shared_assembly("compas_assembly/arch_assembly.json"))
    present = model.mask(None)

    def undecided(matrix, rhs):
        raise NumericError("equilibrium program failed: no answer")

    monkeypatch.setattr("assemblykit.planning.equilibrium.balance", undecided)
    assert model.reference(present, present & model.mask(model.fixed)) is None
