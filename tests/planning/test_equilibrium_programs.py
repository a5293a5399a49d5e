"""The linear programs of equilibrium on matrices written by hand
(:mod:`assemblykit.planning.equilibrium_programs`): the least-residual balance names
every equation some optimum leaves unbalanced, the slack program falls back to HiGHS
when Clarabel stops short, an answer Clarabel calls *almost* found is taken only once
checked, the pyramid's gauge is that of its sides, and programs solved together on
threads answer as one after another."""

from __future__ import annotations

import math
import os

import clarabel
import numpy as np
import pytest
import scipy.sparse as sp

from assemblykit.errors import InputError
from assemblykit.planning import equilibrium_programs
from assemblykit.planning.equilibrium_programs import (
    CONE_SIDES,
    LP_FEASIBILITY,
    PROGRAM_THREADS_VARIABLE,
    RETRY_REGULARIZATION,
    _balances,
    _proves_none,
    balance,
    cone_directions,
    least_residuals,
    program_threads,
    pyramid_gauge,
    solve_all,
)


def test_the_least_residual_balance_names_every_equation_some_optimum_leaves_unbalanced():
    # minimise |1 - x| + |-1 - x| over x >= 0: the optimum 2 is reached by every x in
    # [0, 1]; the vertex x = 1 leaves only the second equation unbalanced, x = 0 both,
    # and the interior point (0 < x < 1) both: the set every optimum's support lies in
    residual = least_residuals(sp.csc_matrix([[1.0], [1.0]]), np.array([1.0, -1.0]))
    assert np.abs(residual).sum() == pytest.approx(2.0, abs=1e-7)
    assert np.all(np.abs(residual) > 1e-3)
    assert residual[0] > 0 > residual[1]
    # a unique optimum: x = 1 balances both
    unique = least_residuals(sp.csc_matrix([[1.0], [2.0]]), np.array([1.0, 2.0]))
    assert np.abs(unique).max() < LP_FEASIBILITY


def test_the_slack_program_falls_back_to_highs_when_clarabel_stops_short(monkeypatch):
    matrix, rhs = sp.csc_matrix([[1.0], [2.0]]), np.array([1.0, 1.0])
    interior = least_residuals(matrix, rhs)
    settings = clarabel.DefaultSettings

    def one_iteration():
        found = settings()
        found.max_iter = 1
        return found

    monkeypatch.setattr(clarabel, "DefaultSettings", one_iteration)
    vertex = least_residuals(matrix, rhs)
    # by hand: |1 - x| + |1 - 2x| is least, 0.5, at x = 0.5: residuals (0.5, 0)
    np.testing.assert_allclose(vertex, [0.5, 0.0], atol=1e-7)
    np.testing.assert_allclose(interior, vertex, atol=1e-7)


def test_clarabel_stopping_short_is_asked_again_more_regularised(monkeypatch):
    # Clarabel given one iteration at its default regularisation stops short; asked
    # again at RETRY_REGULARIZATION it answers, and HiGHS is never asked: x1 + x2 = -1
    # has no x >= 0 (a certificate proves it), x1 + 2 x2 = 3 has one
    solver = clarabel.DefaultSolver

    def short_unless_regularised(*program):
        settings = program[-1]
        if settings.static_regularization_constant < RETRY_REGULARIZATION:
            settings.max_iter = 1
        return solver(*program)

    monkeypatch.setattr(clarabel, "DefaultSolver", short_unless_regularised)
    monkeypatch.setattr(equilibrium_programs, "linprog", None)
    none, rhs = sp.csc_matrix(np.array([[1.0, 1.0]])), np.array([-1.0])
    found = balance(none, rhs)
    assert not found.found and found.certificate is not None
    assert _proves_none(none, rhs, found.certificate)
    some, rhs = sp.csc_matrix(np.array([[1.0, 2.0]])), np.array([3.0])
    found = balance(some, rhs)
    assert found.forces is not None and _balances(some, rhs, found.forces)


def test_an_almost_answer_is_taken_only_when_it_checks_out():
    # x1 + x2 = -1 has no x >= 0: y = 1 proves it (rhs . y = -1 < 0, both columns gain
    # 1), however long y is; y = -1 proves nothing. x1 + 2 x2 = 3 is balanced by (1, 1)
    # and not by (1, 0.9) beyond the feasibility tolerance
    none = sp.csc_matrix(np.array([[1.0, 1.0]]))
    assert _proves_none(none, np.array([-1.0]), np.array([1.0]))
    assert _proves_none(none, np.array([-1.0]), np.array([8.5e10]))
    assert not _proves_none(none, np.array([-1.0]), np.array([-1.0]))
    # a column that loses by more than the tolerance spoils it
    mixed = sp.csc_matrix(np.array([[1.0, -1.0]]))
    assert not _proves_none(mixed, np.array([-1.0]), np.array([1.0]))
    some = sp.csc_matrix(np.array([[1.0, 2.0]]))
    assert _balances(some, np.array([3.0]), np.array([1.0, 1.0]))
    assert _balances(some, np.array([3.0]), np.array([1.0, 1.0 + LP_FEASIBILITY / 4]))
    assert not _balances(some, np.array([3.0]), np.array([1.0, 0.9]))


def test_a_force_along_a_generator_is_on_the_pyramid_and_one_between_two_is_beyond():
    # a unit tangential force along a generator is held by the pyramid of mu = 1 (its
    # gauge is 1); halfway between two generators it needs 1 / cos(pi / CONE_SIDES)
    cos, sin = cone_directions()
    along = np.stack([cos, sin], axis=1)
    np.testing.assert_allclose(pyramid_gauge(along), 1.0)
    cos, sin = cone_directions(math.pi / CONE_SIDES)
    between = np.stack([cos, sin], axis=1)
    np.testing.assert_allclose(pyramid_gauge(between), 1 / math.cos(math.pi / CONE_SIDES))


def test_programs_solved_together_answer_in_order_as_one_after_another(monkeypatch):
    # slack programs of random stacked systems: each answer is that of the program
    # solved alone, in the order given, on two threads as on one
    rng = np.random.default_rng(7)
    programs = []
    for rows in (6, 12, 18, 24, 30):
        matrix = sp.csc_matrix(
            rng.normal(size=(rows, 3 * rows)) * (rng.random((rows, 3 * rows)) < 0.3)
        )
        rhs = rng.normal(size=rows)
        programs.append((matrix, rhs))
    alone = [least_residuals(m, r) for m, r in programs]
    monkeypatch.setattr(equilibrium_programs, "program_threads", lambda: 2)
    together = solve_all([lambda m=m, r=r: least_residuals(m, r) for m, r in programs])
    assert len(together) == len(alone)
    for one, other in zip(alone, together, strict=True):
        assert np.array_equal(one, other)


def test_a_program_that_fails_among_others_fails_them_all(monkeypatch):
    monkeypatch.setattr(equilibrium_programs, "program_threads", lambda: 2)

    def fails() -> float:
        raise ValueError("no answer")

    with pytest.raises(ValueError, match="no answer"):
        solve_all([lambda: 1.0, fails, lambda: 2.0])
    assert solve_all([lambda: 1.0, lambda: 2.0, lambda: 3.0]) == [1.0, 2.0, 3.0]
    monkeypatch.setattr(equilibrium_programs, "program_threads", lambda: 1)
    assert solve_all([lambda: 1.0, lambda: 2.0]) == [1.0, 2.0]


def test_the_threads_are_the_cores_capped_by_the_variable(monkeypatch):
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    monkeypatch.delenv(PROGRAM_THREADS_VARIABLE, raising=False)
    assert program_threads() == cores
    monkeypatch.setenv(PROGRAM_THREADS_VARIABLE, "1")
    assert program_threads() == 1
    monkeypatch.setenv(PROGRAM_THREADS_VARIABLE, " 64 ")
    assert program_threads() == cores
    for bad in ("0", "two", "-1", "1.5"):
        monkeypatch.setenv(PROGRAM_THREADS_VARIABLE, bad)
        with pytest.raises(InputError, match=PROGRAM_THREADS_VARIABLE):
            program_threads()
