"""The linear programs of rigid-block equilibrium (Whiting, Ochsendorf and Durand 2009,
"Procedural modeling of structurally-sound masonry buildings"; docs/planning.md, "Under
gravity"), over the equations a model assembles (:mod:`assemblykit.planning.equilibrium`).

A force at a contact point is compressive along the contact normal, with friction inside
a Coulomb cone of coefficient ``mu`` linearised as a pyramid of :data:`CONE_SIDES`
generators ``n + mu (cos t u + sin t v)`` inscribed in the cone (conservative: never
stands where the true cone would not). A set of parts stands when non-negative generator
weights balance every free part's weight (six equations per part). The first program asks
whether the equations alone have such a solution; it is solved in its Farkas form by
Clarabel, and answers a balance or a certificate that there is none (:func:`balance`).
When there is none, a second one minimises the absolute residuals (slacks) of those
equations: it is always feasible, and the parts left with a residual beyond the tolerance
are those that cannot be in equilibrium (they would fall). Its optimum is not unique on a
state that falls; the parts named are those left unbalanced by *some* least-residual
balance, the support of the interior of its optimal face, to which Clarabel's interior
point method converges (:func:`least_residuals`), so the set does not depend on a
solver's pivots. It converges to :data:`SLACK_ACCURACY`, well past the least residual
itself: before that, which parts keep a residual depends on how the program is written.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import TypeVar

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.optimize import linprog

from assemblykit.errors import InputError, NumericError

T = TypeVar("T")

CONE_SIDES = 8
"""Generators of the linearised friction cone (an inscribed 8-sided pyramid)."""

LP_FEASIBILITY = 1e-7
"""HiGHS's primal feasibility tolerance (its default, passed explicitly): residuals below
it are the solver's rounding, not a fall. A part that a known balance leaves with
residuals below it is balanced
(:meth:`~assemblykit.planning.equilibrium.EquilibriumModel.stands`)."""

LP_TIME_LIMIT = 120.0
"""Seconds one equilibrium program may take before :class:`NumericError`: a bound two
orders of magnitude above the largest programs measured, about a second each
(benchmarks/bench_stability.py)."""

RETRY_REGULARIZATION = 1e-6
"""Clarabel's static regularisation (its default is 1e-8) when :func:`balance` asks it
again about a program it stopped short on: on a late state of the cross vault (61
blocks, 2,100 generators) it stops with insufficient progress at the default and proves
the state falls at 1e-6, where the HiGHS of scipy 1.13 returns an unknown status."""

SLACK_ACCURACY = 1e-10
"""Clarabel's gap and feasibility tolerances in the slack program (its defaults are 1e-8,
which an answer that stops short of these must still meet): the residuals settle on the
parts well after the least residual is reached, and only settled ones name the same
parts however the program is written (docs/planning.md, "Under gravity": its known
limits)."""


@dataclass(frozen=True, eq=False)
class Balance:
    """The first program's answer: ``forces``, a solution ``x >= 0`` of ``matrix @ x =
    rhs``, or when there is none ``certificate``, a ``y`` with ``matrix.T @ y >= 0`` and
    ``rhs @ y < 0`` (Farkas' lemma; ``None`` when the solver that answered gave none)."""

    forces: NDArray[np.float64] | None
    certificate: NDArray[np.float64] | None = None

    @property
    def found(self) -> bool:
        """Whether there is a balance."""
        return self.forces is not None


def balance(matrix: sp.csc_matrix, rhs: NDArray[np.float64]) -> Balance:
    """Whether some ``x >= 0`` solves ``matrix @ x = rhs``. By Farkas' lemma there is none
    exactly when some ``y`` has ``matrix.T @ y >= 0`` and ``rhs @ y < 0``, so the program
    "minimise ``rhs @ y`` subject to ``matrix.T @ y >= 0``" has the optimum 0 when there
    is a solution and is unbounded otherwise; its multipliers are then a solution, and
    its ray of unboundedness the certificate ``y``. It is solved by Clarabel's interior
    point method (Goulart and Chen 2024, "Clarabel: an interior-point solver for conic
    programs with quadratic objectives": a sparse direct factorisation per iteration;
    0.6 s on the 527-block dome where HiGHS's interior point method needs 25 s), which
    proves unboundedness by that ray; its unknowns are the equations (6 per part), not
    the generators. An answer it calls *almost* solved, or a ray it calls almost one of
    unboundedness, is taken once checked (:func:`_balances`, :func:`_proves_none`: on
    the cross vault a state nearly in balance gives a ray of length 1e11 after 187
    iterations that certifies it by a wide margin). Should it stop short of either
    answer (iterations, numerical trouble, :data:`LP_TIME_LIMIT`), it is asked again
    with :data:`RETRY_REGULARIZATION`, and then HiGHS's interior point method decides,
    within :data:`LP_FEASIBILITY` (with no certificate)."""
    for regularization in (None, RETRY_REGULARIZATION):
        found = _clarabel_balance(matrix, rhs, regularization)
        if found is not None:
            return found
    _, columns = matrix.shape
    result = linprog(
        np.zeros(columns),
        A_eq=matrix,
        b_eq=rhs,
        bounds=(0, None),
        method="highs-ipm",
        options={"primal_feasibility_tolerance": LP_FEASIBILITY, "time_limit": LP_TIME_LIMIT},
    )
    if result.status not in (0, 2):
        raise NumericError(f"equilibrium program failed: {result.message}")
    return Balance(np.asarray(result.x) if result.status == 0 else None)


def _clarabel_balance(
    matrix: sp.csc_matrix, rhs: NDArray[np.float64], regularization: float | None
) -> Balance | None:
    """:func:`balance` by Clarabel, with its default static regularisation or
    ``regularization``; ``None`` when it stops short of both answers."""
    import clarabel

    rows, columns = matrix.shape
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.time_limit = LP_TIME_LIMIT
    if regularization is not None:
        settings.static_regularization_constant = regularization
    found = clarabel.DefaultSolver(
        sp.csc_matrix((rows, rows)),
        np.asarray(rhs, dtype=np.float64),
        sp.csc_matrix(-matrix.T),
        np.zeros(columns),
        [clarabel.NonnegativeConeT(columns)],
        settings,
    ).solve()
    status, done = found.status, clarabel.SolverStatus
    forces = np.maximum(np.asarray(found.z, dtype=np.float64), 0.0)
    ray = np.asarray(found.x, dtype=np.float64)
    if status == done.Solved or (status == done.AlmostSolved and _balances(matrix, rhs, forces)):
        return Balance(forces)
    if status == done.DualInfeasible or (
        status == done.AlmostDualInfeasible and _proves_none(matrix, rhs, ray)
    ):
        return Balance(None, ray)
    return None


def _balances(matrix: sp.csc_matrix, rhs: NDArray[np.float64], forces: NDArray[np.float64]) -> bool:
    """Whether ``forces`` solve ``matrix @ x = rhs`` to :data:`LP_FEASIBILITY` of the
    largest load: an answer the solver calls almost solved, checked."""
    error = np.abs(matrix @ forces - rhs).max(initial=0.0)
    return bool(error <= LP_FEASIBILITY * max(1.0, float(np.abs(rhs).max(initial=0.0))))


def _proves_none(matrix: sp.csc_matrix, rhs: NDArray[np.float64], ray: NDArray[np.float64]) -> bool:
    """Whether ``ray`` is a Farkas certificate that ``matrix @ x = rhs`` has no
    ``x >= 0``: ``rhs @ ray < 0`` while no column loses by it (``matrix.T @ ray >= 0``, to
    :data:`LP_FEASIBILITY` of ``rhs @ ray``), as
    :meth:`~assemblykit.planning.equilibrium.EquilibriumModel._first_certifying` reads a
    kept one: an answer the solver calls almost infeasible, checked."""
    share = float(rhs @ ray)
    return share < 0 and bool((matrix.T @ ray).min(initial=0.0) >= LP_FEASIBILITY * share)


def least_residuals(matrix: sp.csc_matrix, rhs: NDArray[np.float64]) -> NDArray[np.float64]:
    """The residual ``rhs - matrix @ x`` of the least-residual balance: the program
    "minimise ``|r|_1`` with ``matrix @ x + r = rhs``, ``x >= 0``", at the point of its
    optimal face that an interior point method converges to (the central path's limit,
    in the relative interior of that face). Its support is therefore the same at every
    such point: the equations left unbalanced by *some* least-residual balance, a set
    defined by the program alone, where a vertex optimum names a subset that depends on
    the solver's pivots. Solved by Clarabel in dual form ("maximise ``rhs @ y`` with
    ``matrix.T @ y <= 0`` and ``-1 <= y <= 1``", the unknowns being the equations), whose
    multipliers are ``x`` and the two signs of ``r``, to :data:`SLACK_ACCURACY` (an
    answer that stops short of it is taken when it meets Clarabel's default tolerances,
    1e-8). Should it stop short of those,
    HiGHS's interior point method with crossover answers (a vertex of that face), and
    :class:`NumericError` if it fails too."""
    import clarabel

    rows, columns = matrix.shape
    eye = sp.identity(rows, format="csc")
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.time_limit = LP_TIME_LIMIT
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = SLACK_ACCURACY
    settings.reduced_tol_gap_abs = settings.reduced_tol_gap_rel = 1e-8
    settings.reduced_tol_feas = 1e-8
    found = clarabel.DefaultSolver(
        sp.csc_matrix((rows, rows)),
        -np.asarray(rhs, dtype=np.float64),
        sp.vstack([matrix.T, eye, -eye], format="csc"),
        np.r_[np.zeros(columns), np.ones(2 * rows)],
        [clarabel.NonnegativeConeT(columns + 2 * rows)],
        settings,
    ).solve()
    if found.status in (clarabel.SolverStatus.Solved, clarabel.SolverStatus.AlmostSolved):
        multipliers = np.asarray(found.z, dtype=np.float64)
        return multipliers[columns : columns + rows] - multipliers[columns + rows :]
    result = linprog(
        np.r_[np.zeros(columns), np.ones(2 * rows)],
        A_eq=sp.hstack([matrix, eye, -eye], format="csc"),
        b_eq=rhs,
        bounds=(0, None),
        method="highs-ipm",
        options={"primal_feasibility_tolerance": LP_FEASIBILITY, "time_limit": LP_TIME_LIMIT},
    )
    if result.status != 0:
        raise NumericError(f"equilibrium slack program failed: {result.message}")
    return np.asarray(result.x[columns : columns + rows] - result.x[columns + rows :])


def cone_directions(turn: float = 0.0) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The cosines and sines of the friction pyramid's generator angles (turned by
    ``turn``: by half a side, its sides' outward normals)."""
    angles = 2 * np.pi * np.arange(CONE_SIDES) / CONE_SIDES + turn
    return np.cos(angles), np.sin(angles)


def point_sums(weights: NDArray[np.float64], points: int) -> sp.csr_matrix:
    """The matrix (``points * CONE_SIDES`` x ``points``) that sums each point's
    generator columns with ``weights``, one per generator."""
    rows = np.arange(points * CONE_SIDES)
    return sp.csr_matrix(
        (np.tile(weights, points), (rows, rows // CONE_SIDES)),
        shape=(points * CONE_SIDES, points),
    )


def pyramid_gauge(tangent: NDArray[np.float64]) -> NDArray[np.float64]:
    """Per point, the least multiple of the unit pyramid's section (the polygon of the
    generators' tangent directions) that holds the tangential force ``tangent`` (P x 2,
    in ``u`` and ``v``): its largest projection on a side's outward normal over that
    side's distance ``cos(pi / CONE_SIDES)`` from the axis. A force whose normal part is
    ``N`` is inside the pyramid of ``mu`` when its gauge is at most ``mu N``."""
    half = np.pi / CONE_SIDES
    largest: NDArray[np.float64] = (tangent @ np.stack(cone_directions(half))).max(axis=1)
    return largest / math.cos(half)


PROGRAM_THREADS_VARIABLE = "ASSEMBLYKIT_PROGRAM_THREADS"
"""The environment variable that caps the programs :func:`solve_all` solves at once (a
positive whole number; 1: one after another). ``assemblykit batch`` sets it to 1 in its
workers, which are its parallelism."""


def program_threads() -> int:
    """How many programs :func:`solve_all` solves at once: the processor cores this
    process may run on, at most :data:`PROGRAM_THREADS_VARIABLE` when it is set
    (:class:`InputError` when it is not a positive whole number)."""
    if hasattr(os, "sched_getaffinity"):
        cores = len(os.sched_getaffinity(0))
    else:
        cores = os.cpu_count() or 1
    value = os.environ.get(PROGRAM_THREADS_VARIABLE, "").strip()
    if not value:
        return cores
    if not value.isdigit() or int(value) < 1:
        raise InputError(
            f"expected a positive whole number of threads, got {value!r}",
            where=PROGRAM_THREADS_VARIABLE,
        )
    return min(cores, int(value))


def solve_all(programs: Sequence[Callable[[], T]]) -> list[T]:
    """The answers of independent ``programs`` (each a call that solves one), in their
    order, solved :func:`program_threads` at a time: Clarabel releases Python's global
    interpreter lock while it iterates, so threads solve side by side (eight slack
    programs of the whole cross vault on two cores: 1.87x one after another), and a
    program's answer does not depend on the thread that solves it."""
    threads = min(program_threads(), len(programs)) if len(programs) > 1 else 1
    if threads < 2:
        return [program() for program in programs]
    with ThreadPoolExecutor(threads) as pool:
        return list(pool.map(lambda program: program(), programs))
