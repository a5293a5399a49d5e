"""The residue solver: what network reduction leaves, solved numerically (Corner et al. 1983 §III
G).

Corner et al. 1983 hands "the residue" of the cycle finder to "a more powerful inference system".
Here that system is a least-squares solve over the world poses of the remaining body
instances (docs/algebra.md §2.5, "numeric fallback"):

* every unknown pose is parameterised locally by a twist: ``L = [exp(ω) R0 | t0 + v]``;
* every constraint is a residual vector over the poses of the instances it links;
* a deterministic (seeded) multi-start of ``scipy.optimize.least_squares`` collects all
  isolated solutions, deduplicated by pose distance;
* continuous freedom is measured by the rank of the constraint Jacobian at a solution:
  the per-instance dof is the rank of that instance's block of the Jacobian's null space;
* the solver never claims emptiness: it reports "no solution found" with the best residual.

The coupled relations (gear, rack, mirror) enter as constraints over three instances;
their residuals are defined with their kinds (:mod:`assemblykit.model.relations`).
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from assemblykit.algebra import se3
from assemblykit.tolerance import Tolerance

Residual = Callable[[Sequence[np.ndarray]], np.ndarray]
Node = tuple[str, str]
"""A body instance ``(body, situation)``: a node of the network (Corner et al. 1983 §III)."""

STATIONARY = float(np.finfo(np.float64).eps)
"""The gradient norm ``|Jᵀr|`` below which the residue solver stops: only a point that is
stationary to rounding (a start already at a solution, where the gradient vanishes).
Convergence is otherwise decided by the relative step and cost change
(:attr:`Tolerance.precision`). A gradient test at the precision would stop short: the
gradient is the residual times the Jacobian's singular values, and along a long chain of
bodies the smallest of those falls like 1/N² (a stack of N cubes: 0.07 at N = 10, 0.0009 at
N = 100), so the gradient is within the precision while the residual is still far above
the acceptance threshold ``tol.length``."""


@dataclass(frozen=True)
class Constraint:
    """A residual over the world poses of ``nodes`` (zero exactly when it holds).

    ``labels`` name the relations or actions it comes from (for conflict reports);
    ``geometry`` describes the relation when the reduction has a closed form for it.
    """

    nodes: tuple[Node, ...]
    residual: Residual
    labels: tuple[str, ...] = ()
    geometry: Any = None


@dataclass(frozen=True)
class ResidueProblem:
    """Unknown instances with start poses, known instances with poses, and constraints."""

    unknowns: tuple[Hashable, ...]
    start: Mapping[Hashable, np.ndarray]
    known: Mapping[Hashable, np.ndarray]
    constraints: tuple[Constraint, ...]


@dataclass(frozen=True)
class NumericSolution:
    """One solution: world poses, per-instance dof and the total dof of the residue."""

    poses: Mapping[Hashable, np.ndarray]
    dof: Mapping[Hashable, int]
    total_dof: int
    residual: float


@dataclass(frozen=True)
class ResidueResult:
    """All solutions found (isolated ones first), or none with the best residual reached."""

    solutions: tuple[NumericSolution, ...]
    best_residual: float
    starts: int = field(default=0)

    @property
    def found(self) -> bool:
        """Whether at least one solution was found (never a proof of emptiness otherwise)."""
        return bool(self.solutions)


def pose_from_twist(start: np.ndarray, twist: np.ndarray) -> np.ndarray:
    """The pose ``[exp(ω) R0 | t0 + v]`` for the local coordinates ``twist = (ω; v)``."""
    pose = np.eye(4)
    pose[:3, :3] = se3.rotation_matrix(twist[:3]) @ start[:3, :3]
    pose[:3, 3] = start[:3, 3] + twist[3:]
    return pose


def _scaled(constraint: Constraint, poses: Mapping[Hashable, np.ndarray]) -> np.ndarray:
    return np.atleast_1d(
        np.asarray(constraint.residual([poses[n] for n in constraint.nodes]), dtype=np.float64)
    )


def _residual_vector(
    problem: ResidueProblem, starts: Mapping[Hashable, np.ndarray], x: np.ndarray
) -> tuple[np.ndarray, dict[Hashable, np.ndarray]]:
    poses = dict(problem.known)
    for i, node in enumerate(problem.unknowns):
        poses[node] = pose_from_twist(starts[node], x[6 * i : 6 * i + 6])
    parts = [_scaled(c, poses) for c in problem.constraints]
    return (np.concatenate(parts) if parts else np.zeros(0)), poses


def _local_dof(
    problem: ResidueProblem, jac: Any, tol: Tolerance, residual: float = 0.0
) -> tuple[dict[Hashable, int], int]:
    """Per-instance and total dof from the null space of the constraint Jacobian at a
    solution whose worst residual is ``residual`` (docs/algebra.md §2.5 step 5), with the rank
    threshold :meth:`Tolerance.rank`. The local coordinates of each instance differ
    from twists at the solution by an invertible map, which keeps every rank."""
    threshold = tol.rank(residual)
    n = 6 * len(problem.unknowns)
    dense = jac.toarray() if hasattr(jac, "toarray") else np.asarray(jac, dtype=np.float64)
    dense = dense * np.tile(np.concatenate([np.ones(3), np.full(3, tol.scale)]), n // 6)
    if dense.shape[0] == 0:
        null = np.eye(n)
    else:
        _, sv, vt = np.linalg.svd(dense, full_matrices=True)
        rank = int(np.sum(sv > threshold * max(sv[0], 1.0))) if sv.size else 0
        null = vt[rank:].T
    dof = {}
    for i, node in enumerate(problem.unknowns):
        block = null[6 * i : 6 * i + 6]
        sv = np.linalg.svd(block, compute_uv=False) if block.size else np.zeros(0)
        dof[node] = int(np.sum(sv > threshold))
    return dof, null.shape[1]


def _distance(
    a: Mapping[Hashable, np.ndarray], b: Mapping[Hashable, np.ndarray], scale: float
) -> float:
    """Largest pose difference over instances: rotation entries plus translation / scale."""
    return max(
        float(np.abs(a[k][:3, :3] - b[k][:3, :3]).max())
        + float(np.abs(a[k][:3, 3] - b[k][:3, 3]).max()) / scale
        for k in a
    )


def _midpoint(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The pose halfway from ``a`` to ``b`` in the local coordinates of :func:`pose_from_twist`."""
    rotvec = se3.rotation_vector(b[:3, :3] @ a[:3, :3].T)
    return pose_from_twist(a, 0.5 * np.concatenate([rotvec, b[:3, 3] - a[:3, 3]]))


def _same_solution(
    problem: ResidueProblem,
    a: Mapping[Hashable, np.ndarray],
    b: Mapping[Hashable, np.ndarray],
    tol: Tolerance,
) -> bool:
    """Whether two accepted solutions are one: they are within ``tol.mesh_angle`` (an
    angle θ weighs like the arc θ·scale), or the poses halfway between them also satisfy every
    constraint (within the acceptance threshold, or the mesh length when looser: a
    midpoint of two stops on a curved continuum leaves it by a second-order amount).
    Distinct isolated solutions (assembly modes) are separated by violated constraints;
    two stops of the solver on the same solution are not, however far apart a long,
    badly conditioned chain lets them be."""
    if _distance(a, b, tol.scale) <= tol.mesh_angle:
        return True
    poses = {**problem.known, **{n: _midpoint(a[n], b[n]) for n in problem.unknowns}}
    parts = [_scaled(c, poses) for c in problem.constraints]
    limit = max(tol.length, tol.mesh_length)
    return bool(parts) and float(np.abs(np.concatenate(parts)).max()) <= limit


def _sparsity(problem: ResidueProblem, start: Mapping[Hashable, np.ndarray]) -> np.ndarray:
    """Which residual rows depend on which unknowns (6 columns per unknown instance), so
    that finite differences are grouped (a network of N bodies costs O(1) residuals per
    Jacobian, not O(N))."""
    column = {node: 6 * i for i, node in enumerate(problem.unknowns)}
    poses = {**problem.known, **start}
    rows = []
    for constraint in problem.constraints:
        block = np.zeros((_scaled(constraint, poses).size, 6 * len(problem.unknowns)), bool)
        for node in constraint.nodes:
            if node in column:
                block[:, column[node] : column[node] + 6] = True
        rows.append(block)
    return np.vstack(rows) if rows else np.zeros((0, 6 * len(problem.unknowns)), bool)


def _start_points(problem: ResidueProblem, count: int, seed: int, scale: float) -> list[np.ndarray]:
    """The deterministic multi-start: the given start, then seeded random twists."""
    from scipy.spatial.transform import Rotation  # imported here: only residues need it

    n = 6 * len(problem.unknowns)
    rng = np.random.default_rng(seed)
    points = [np.zeros(n)]
    for _ in range(count - 1):
        twist = np.empty(n)
        for i in range(len(problem.unknowns)):
            twist[6 * i : 6 * i + 3] = Rotation.random(random_state=rng).as_rotvec()
            twist[6 * i + 3 : 6 * i + 6] = rng.uniform(-scale, scale, 3)
        points.append(twist)
    return points


def solve_residue(
    problem: ResidueProblem,
    tol: Tolerance,
    *,
    starts: int = 8,
    seed: int = 0,
) -> ResidueResult:
    """Solve the residue numerically (docs/algebra.md §2.5 numeric fallback, steps 1-6).

    Solutions are accepted when every residual entry is within ``tol.length``, the
    tolerance in force (residuals weigh angles by ``tol.arm``, so angles are held to
    ``tol.angle``); the solver stops when its relative step or cost change falls below
    ``tol.precision``, which a looser tolerance never loosens (or at a point stationary
    to rounding, :data:`STATIONARY`, never on a merely small gradient), so a solution
    accepted at one tolerance is accepted at every looser one (monotone answers,
    :mod:`assemblykit.tolerance`). Isolated solutions from different starts are
    deduplicated by pose distance; the first solution on a continuum (total dof > 0)
    ends the search and is its representative. Two solutions are one when the poses
    halfway between them satisfy the constraints too. ``tol.scale`` is the length scale
    of the start spread.
    """
    if not problem.unknowns:
        r, poses = _residual_vector(problem, {}, np.zeros(0))
        worst = float(np.abs(r).max()) if r.size else 0.0
        sols = (NumericSolution(dict(poses), {}, 0, worst),) if worst <= tol.length else ()
        return ResidueResult(sols, worst, 1)
    # imported here: a residue with nothing unknown (a check) and every other command
    # start faster without scipy.optimize
    from scipy.optimize import least_squares

    origin = {node: np.asarray(problem.start[node], dtype=np.float64) for node in problem.unknowns}
    found: list[NumericSolution] = []
    best = np.inf
    points = _start_points(problem, starts, seed, tol.scale)
    # a radian per rotation entry and the model's size per translation entry: with the
    # Jacobian's own scaling a free direction (a zero column) would take unbounded steps
    spread = np.tile(np.concatenate([np.ones(3), np.full(3, tol.scale)]), len(problem.unknowns))
    sparsity = _sparsity(problem, origin)
    for x0 in points:
        moved = {
            node: pose_from_twist(origin[node], x0[6 * i : 6 * i + 6])
            for i, node in enumerate(problem.unknowns)
        }
        fit = least_squares(
            lambda x, moved=moved: _residual_vector(problem, moved, x)[0],
            np.zeros(x0.size),
            method="trf",
            jac_sparsity=sparsity,
            x_scale=spread,
            xtol=tol.precision,
            ftol=tol.precision,
            gtol=STATIONARY,
        )
        r, poses = _residual_vector(problem, moved, fit.x)
        worst = float(np.abs(r).max()) if r.size else 0.0
        best = min(best, worst)
        if worst > tol.length:
            continue
        poses = {node: poses[node] for node in problem.unknowns}
        if any(_same_solution(problem, poses, s.poses, tol) for s in found):
            continue
        dof, total = _local_dof(problem, fit.jac, tol, worst)
        found.append(NumericSolution(poses, dof, total, worst))
        if total > 0:  # a continuum: one representative answers for it
            break
    continua = [s for s in found if s.total_dof > 0]
    isolated = [s for s in found if s.total_dof == 0]
    return ResidueResult(tuple(isolated or continua[:1]), float(best), len(points))
