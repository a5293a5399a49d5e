"""Static equilibrium of rigid parts under gravity, decided by a linear program.

The model is the rigid-block equilibrium analysis of masonry (Whiting, Ochsendorf and
Durand 2009, "Procedural modeling of structurally-sound masonry buildings"; the RBE
of compas_cra), on the contacts the project already finds
(:mod:`assemblykit.geometry.contacts`). Planning assembly as reversed disassembly that
keeps every intermediate state standing, with temporary supports where it cannot, is
the approach of Kao et al. 2017 ("Assembly-aware design of masonry shell structures"),
who judged the states by rigid-body simulation instead.

* every part is rigid; its weight (``density x volume``, uniform density unless given per
  part) acts at its volume centroid along the gravity direction;
* a planar contact transmits forces only at the vertices of its contact polygon; a
  curved contact at its sample points (:meth:`CurvedPatch.samples`). A pressure
  distribution over a polygon has its resultant inside the polygon's convex hull, which
  the vertex forces span, so nothing is lost in the normal direction; friction at the
  vertices resists twisting about the normal somewhat more than distributed friction
  would (the usual approximation of the method);
* each force is compressive along the contact normal, with friction inside a Coulomb
  cone of coefficient ``mu`` linearised as a pyramid of ``CONE_SIDES`` generators
  ``n + mu (cos t u + sin t v)`` inscribed in the cone (conservative: never stands where
  the true cone would not). ``u`` is the downhill direction of the contact plane, so a
  block sliding down a slope meets the exact cone;
* fixed parts (ground, fixture) and held parts take any wrench.

A set of parts stands when non-negative generator weights balance every free part's
weight (six equations per part). A first program asks whether the equations alone have a
solution, on the corners of the contact polygons only: a vertex on the straight segment
between its two neighbours adds nothing (every force it could carry is a combination of
the same force at its neighbours, the contact's normal and friction directions being the
same at all its vertices), so the answer is the same with a quarter fewer columns on the
dome; a vertex repeated counts once (:func:`_corners`). It is solved in its Farkas form
by Clarabel (:func:`balance`). When they have none, a second one, also on the corners,
minimises the absolute residuals (slacks) of those equations, each scaled by the part's
weight and the model's size: it is always feasible, and the parts left with a residual
beyond the tolerance are those that cannot be in equilibrium (they would fall). Its
optimum is not unique on a state that falls; the parts named are those left unbalanced
by *some* least-residual balance, the support of the interior of its optimal face, to
which Clarabel's interior point method converges (:func:`least_residuals`), so the set
does not depend on a solver's pivots. It converges to :data:`SLACK_ACCURACY`, well past
the least residual itself: before that, which parts keep a residual depends on how the
program is written. It is solved for each piece of the state (free parts that no force
point joins: :meth:`EquilibriumModel.pieces`) on its own. A plan
asks about states that differ by a block, a hold or the friction coefficient from one
already decided: the balances and Farkas certificates found before answer many of them
with no program, or from a few parts' equations (:meth:`EquilibriumModel.stands`).
Loads are homogeneous in rigid-block equilibrium (scaling gravity scales every force),
so the margin reported is the friction coefficient a balance of the state needs, less
than ``mu / 32`` above the least one (:meth:`EquilibriumModel.friction_needed`); a state
that falls is told apart by whether it tips over, falling even with unbounded friction
(:meth:`EquilibriumModel.tips`), or slides.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import linprog

from assemblykit import formatting as fmt
from assemblykit.errors import InputError, NumericError
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.graphs import component_labels
from assemblykit.model.assembly import lowest_parts
from assemblykit.tolerance import MIN_REL_LENGTH, Tolerance, order_key

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly

FRICTION = 0.5
"""Default Coulomb friction coefficient."""

CONE_SIDES = 8
"""Generators of the linearised friction cone (an inscribed 8-sided pyramid)."""

FRICTION_STEPS = 5
"""Bisection steps for the least friction coefficient: resolution ``mu / 2**5``."""

LP_FEASIBILITY = 1e-7
"""HiGHS's primal feasibility tolerance (its default, passed explicitly): residuals below
it are the solver's rounding, not a fall. A part that a known balance leaves with
residuals below it is balanced (:meth:`EquilibriumModel.stands`)."""

LP_TIME_LIMIT = 120.0
"""Seconds one equilibrium program may take before :class:`NumericError` (a bound; the
largest programs measured, the 527-block dome's first and the 184-block cross vault's
slack program, take 0.5 to 1.2 s and 0.2 to 0.3 s on two shared cores:
benchmarks/bench_stability.py)."""

LOCAL_HOPS = 1
"""How many contacts :meth:`EquilibriumModel.stands` grows the region of unbalanced
parts by, one at a time, before it leaves the verdict to the whole program. A region
that a contact more does not prove falling rarely falls with two or three more: the
cross vault's first 39 steps solve 359 programs in 40 s with one, 502 in 41 s with two,
639 in 43 s with three, and 372 in 63 s with none (128 certificates kept)."""

SLACK_ACCURACY = 1e-10
"""Clarabel's gap and feasibility tolerances in the slack program (its defaults are 1e-8,
which an answer that stops short of these must still meet). The least residual is
reached well before the residuals settle on the parts: on a state that falls, moving
residual onto a part can raise the sum by very little, so an answer within 1e-8 of the
optimum can leave a part a hundredth of its weight unbalanced where the converged one
leaves 1e-9, and which parts depends on the columns (corners or every vertex) and on
whether the program is solved whole or piece by piece. On the 137 falling states of the
cross vault's plan under gravity, the parts named at 1e-8 differed in 11 states from
those of programs solved to 1e-12; at 1e-10 in none, whole or by pieces, on corners or
on every vertex (elsewhere only in parts within ten times the tolerance, the rounding
band of any threshold), for about a tenth more time in the slack programs."""

KEPT = 8
"""How many balances an :class:`EquilibriumModel` keeps (the most recently useful
first) to decide later states without a program: a balance rarely outlives the state it
was found for (removing a block unbalances its neighbours), but decides the friction
coefficients above the one it was found at."""

KEPT_RESIDUALS = 256
"""How many pieces' residuals an :class:`EquilibriumModel` keeps (:meth:`slack`): a
piece of a state that no removal since has touched has the same ones."""

KEPT_CERTIFICATES = 128
"""How many Farkas certificates an :class:`EquilibriumModel` keeps (the most recently
useful first): a certificate outlives many states (what falls at one step still falls
at the next, unless its parts are taken or held). A plan's step finds a few dozen, one
per candidate that falls, and asks about most of those candidates again at the next
step: with 32 kept, the cross vault's first 39 steps solved 1,114 programs, with 128
(or 512) 639."""

DOWN = (0.0, 0.0, -1.0)

_AXES = {"x": 0, "y": 1, "z": 2}


def gravity_direction(value: str | ArrayLike) -> NDArray[np.float64]:
    """The unit gravity direction from ``-z``, ``+y``, ``x`` or a vector (``0,0,-1``, a
    sequence of three numbers); :class:`InputError` naming ``--gravity`` otherwise."""
    if isinstance(value, str):
        text = value.strip().lower()
        sign = -1.0 if text.startswith("-") else 1.0
        axis = text.lstrip("+-")
        if axis in _AXES:
            vector = np.zeros(3)
            vector[_AXES[axis]] = sign
            return vector
        try:
            numbers = [float(x) for x in text.replace(",", " ").split()]
        except ValueError:
            numbers = []
    else:
        numbers = [float(x) for x in np.asarray(value, dtype=np.float64).ravel()]
    vector = np.asarray(numbers, dtype=np.float64)
    norm = float(np.linalg.norm(vector)) if vector.shape == (3,) else 0.0
    if not (math.isfinite(norm) and norm > 0):
        raise InputError(
            f"expected -z, +y, x or three numbers such as 0,0,-1, got {value!r}", where="--gravity"
        )
    return vector / norm


@dataclass(frozen=True)
class Gravity:
    """The settings of stability-aware planning: unit ``direction`` of gravity,
    ``friction`` coefficient, ``holds`` (hands or fixtures per step, the one holding the
    moved parts included), ``fixed`` parts (``None``: those touching the lowest plane,
    :func:`lowest_parts`) and per-part ``densities`` (others 1)."""

    direction: tuple[float, float, float] = DOWN
    friction: float = FRICTION
    holds: int = 1
    fixed: tuple[str, ...] | None = None
    densities: tuple[tuple[str, float], ...] = ()

    @property
    def extra_holds(self) -> int:
        """The holds beyond the grip of the moved parts: ``holds - 1``."""
        return self.holds - 1

    def to_dict(self) -> dict[str, Any]:
        """JSON form: ``direction``, ``friction``, ``holds`` (the grip included) and
        ``extra_holds`` (beyond it)."""
        return {
            "direction": [float(x) + 0.0 for x in self.direction],
            "friction": self.friction,
            "holds": self.holds,
            "extra_holds": self.extra_holds,
        }


@dataclass(frozen=True)
class Equilibrium:
    """Whether the parts ``parts`` stand with ``fixed`` parts immobile: ``would_fall``
    lists the free parts that cannot be in equilibrium (residual beyond the tolerance),
    ``residuals`` the largest scaled residual per free part."""

    parts: tuple[str, ...]
    fixed: tuple[str, ...]
    would_fall: tuple[str, ...]
    residuals: tuple[float, ...]

    @property
    def stands(self) -> bool:
        """True when every free part is in equilibrium."""
        return not self.would_fall

    def to_dict(self) -> dict[str, Any]:
        """JSON form: ``stands``, ``parts``, ``fixed``, ``would_fall``."""
        return {
            "stands": self.stands,
            "parts": list(self.parts),
            "fixed": list(self.fixed),
            "would_fall": list(self.would_fall),
        }


@dataclass(frozen=True, eq=False)
class ContactPoints:
    """The force points of an assembly's contacts: ``points`` (P x 3) where part
    ``first[p]`` pushes part ``second[p]`` along unit ``normals[p]``, and the contact
    plane's tangents ``u`` (downhill when gravity is not along the normal) and ``v``;
    ``corners`` marks the points that are not on a straight stretch of their polygon's
    boundary (:func:`_corners`; every curved sample point is one)."""

    points: NDArray[np.float64]
    normals: NDArray[np.float64]
    first: NDArray[np.int64]
    second: NDArray[np.int64]
    u: NDArray[np.float64]
    v: NDArray[np.float64]
    corners: NDArray[np.bool_]


def contact_points(
    assembly: Assembly, direction: ArrayLike, tol: Tolerance | None = None
) -> ContactPoints:
    """Polygon vertices of the planar contacts and sample points of the curved ones, with
    normals from the pushing part into the pushed one (contacts.py's convention: from
    ``a`` into ``b``; curved: from the inner part outward), tangent frames and corners."""
    index = {name: i for i, name in enumerate(assembly.names)}
    resolution = MIN_REL_LENGTH * assembly.scale
    points, normals, first, second, planar = [], [], [], [], []
    polygons: list[NDArray[np.float64]] = []
    for contact in assembly_contacts(assembly, tol):
        a, b = index[contact.a], index[contact.b]
        for patch in contact.planar:
            polygon = np.asarray(patch.polygon, dtype=np.float64)
            count = len(polygon)
            points.append(polygon)
            normals.append(np.tile(patch.normal, (count, 1)))
            first.append(np.full(count, a))
            second.append(np.full(count, b))
            planar.append(np.ones(count, dtype=bool))
            polygons.append(polygon)
        for curved in contact.curved:
            at, outward = curved.samples()
            inner = index[curved.inner]
            points.append(at)
            normals.append(outward)
            first.append(np.full(len(at), inner))
            second.append(np.full(len(at), b if inner == a else a))
            planar.append(np.zeros(len(at), dtype=bool))
    if not points:
        empty = np.zeros((0, 3))
        none = np.zeros(0, dtype=np.int64)
        return ContactPoints(empty, empty, none, none, empty, empty, np.zeros(0, dtype=bool))
    n = np.vstack(normals)
    n = n / np.linalg.norm(n, axis=1, keepdims=True)
    u, v = _tangents(n, np.asarray(direction, dtype=np.float64), assembly.tolerance(tol))
    on_polygon = np.concatenate(planar)
    corners = np.ones(len(on_polygon), dtype=bool)
    corners[on_polygon] = _corners(polygons, resolution)
    return ContactPoints(
        np.vstack(points),
        n,
        np.concatenate(first).astype(np.int64),
        np.concatenate(second).astype(np.int64),
        u,
        v,
        corners,
    )


def _corners(polygons: Sequence[NDArray[np.float64]], resolution: float) -> NDArray[np.bool_]:
    """Which vertices of closed polygons (each in boundary order; their vertices one after
    the other) are corners. A vertex within ``resolution`` (float64's) of the one before
    it in its ring is that vertex again, and no corner (one per ring stays); of the
    others, those strictly between their two neighbours on the segment joining them are
    no corners either. The forces of a vertex that is no corner are combinations of the
    same forces at corners: ``p = t a + (1 - t) b`` moves a force ``f`` to ``t f`` at
    ``a`` and ``(1 - t) f`` at ``b`` with the same resultant and moment, and a run of
    vertices on one line ends at two corners, where the ring turns. Repeats go first:
    two copies of a corner, each between the other and its far neighbour, would
    otherwise both be dropped and the corner lost."""
    sizes = np.array([len(p) for p in polygons], dtype=np.int64)
    if not sizes.sum():
        return np.zeros(0, dtype=bool)
    polygon = np.vstack(polygons)
    ring = np.repeat(np.arange(len(sizes)), sizes)
    start = np.repeat(np.cumsum(sizes) - sizes, sizes)
    local = np.arange(len(polygon)) - start
    previous = polygon[start + (local - 1) % sizes[ring]]
    kept = np.linalg.norm(polygon - previous, axis=1) > resolution
    # a ring that is one point repeated keeps its first vertex
    kept |= (local == 0) & (np.bincount(ring, weights=kept, minlength=len(sizes)) == 0)[ring]
    points, owner = polygon[kept], ring[kept]
    count = np.bincount(owner, minlength=len(sizes))
    first = np.cumsum(count) - count
    size = count[owner]
    order = np.arange(len(points)) - first[owner]
    before = points[first[owner] + (order - 1) % size]
    after = points[first[owner] + (order + 1) % size]
    chord = after - before
    length = np.linalg.norm(chord, axis=1)
    offset = points - before
    with np.errstate(divide="ignore", invalid="ignore"):
        distance = np.linalg.norm(np.cross(offset, chord), axis=1) / length
        along = np.sum(offset * chord, axis=1) / length**2
    between = (length > resolution) & (distance <= resolution) & (along > 0) & (along < 1)
    out = np.zeros(len(polygon), dtype=bool)
    out[kept] = ~between | (size < 3)
    return out


def _tangents(
    normals: NDArray[np.float64], down: NDArray[np.float64], tol: Tolerance
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per normal, ``u`` along gravity's component in the contact plane (a coordinate
    axis across the normal when gravity is along it) and ``v = n x u``."""
    u = down - (normals @ down)[:, None] * normals
    flat = np.linalg.norm(u, axis=1) <= tol.angle
    if flat.any():
        # gravity along the normal: any tangent will do; the axis least along the normal
        axis = np.eye(3)[np.argmin(np.abs(normals[flat]), axis=1)]
        u[flat] = axis - np.sum(axis * normals[flat], axis=1)[:, None] * normals[flat]
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    return u, np.cross(normals, u)


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
    answer (iterations, numerical trouble, :data:`LP_TIME_LIMIT`), HiGHS's interior
    point method decides, within :data:`LP_FEASIBILITY` (with no certificate)."""
    import clarabel

    rows, columns = matrix.shape
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.time_limit = LP_TIME_LIMIT
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


def _balances(matrix: sp.csc_matrix, rhs: NDArray[np.float64], forces: NDArray[np.float64]) -> bool:
    """Whether ``forces`` solve ``matrix @ x = rhs`` to :data:`LP_FEASIBILITY` of the
    largest load: an answer the solver calls almost solved, checked."""
    error = np.abs(matrix @ forces - rhs).max(initial=0.0)
    return bool(error <= LP_FEASIBILITY * max(1.0, float(np.abs(rhs).max(initial=0.0))))


def _proves_none(matrix: sp.csc_matrix, rhs: NDArray[np.float64], ray: NDArray[np.float64]) -> bool:
    """Whether ``ray`` is a Farkas certificate that ``matrix @ x = rhs`` has no
    ``x >= 0``: ``rhs @ ray < 0`` while no column loses by it (``matrix.T @ ray >= 0``, to
    :data:`LP_FEASIBILITY` of ``rhs @ ray``), as :meth:`EquilibriumModel._first_certifying`
    reads a kept one: an answer the solver calls almost infeasible, checked."""
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
        multipliers = np.asarray(found.z)
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


def _cone_directions(turn: float = 0.0) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The cosines and sines of the friction pyramid's generator angles (turned by
    ``turn``: by half a side, its sides' outward normals)."""
    angles = 2 * np.pi * np.arange(CONE_SIDES) / CONE_SIDES + turn
    return np.cos(angles), np.sin(angles)


def _per_point(weights: NDArray[np.float64], points: int) -> sp.csr_matrix:
    """The matrix (``points * CONE_SIDES`` x ``points``) that sums each point's
    generator columns with ``weights``, one per generator."""
    rows = np.arange(points * CONE_SIDES)
    return sp.csr_matrix(
        (np.tile(weights, points), (rows, rows // CONE_SIDES)),
        shape=(points * CONE_SIDES, points),
    )


def _gauge(tangent: NDArray[np.float64]) -> NDArray[np.float64]:
    """Per point, the least multiple of the unit pyramid's section (the polygon of the
    generators' tangent directions) that holds the tangential force ``tangent`` (P x 2,
    in ``u`` and ``v``): its largest projection on a side's outward normal over that
    side's distance ``cos(pi / CONE_SIDES)`` from the axis. A force whose normal part is
    ``N`` is inside the pyramid of ``mu`` when its gauge is at most ``mu N``."""
    half = np.pi / CONE_SIDES
    return (tangent @ np.stack(_cone_directions(half))).max(axis=1) / math.cos(half)


@dataclass(frozen=True, eq=False)
class EquilibriumModel:
    """The equilibrium equations of every part of an assembly, assembled once.

    Column ``p * CONE_SIDES + s`` is generator ``s`` of force point ``p``; its force on
    the pushed part is ``normal_part + mu * tangent_part`` (the two sparse matrices,
    6 rows per part: force, then moment about ``origin`` divided by ``scale``, each row
    divided by the part's weight), and the opposite on the pushing part. ``load`` holds
    the scaled weights. A state (a subset of the parts, some of them fixed) keeps the
    rows of its free parts and the columns of the points between its parts (of the
    ``corners`` among them in the first program).
    """

    names: tuple[str, ...]
    normal_part: sp.csr_matrix
    tangent_part: sp.csr_matrix
    load: NDArray[np.float64]
    point_parts: NDArray[np.int64]
    corners: NDArray[np.bool_]
    heights: NDArray[np.float64]
    offsets: NDArray[np.float64]
    """Each centre's distance from the vertical through the middle of the assembly's
    bounds (what orders parts of equal height: :attr:`levels`)."""
    fixed: tuple[str, ...]
    friction: float
    threshold: float
    _index: dict[str, int] = field(default_factory=dict, repr=False, init=False)
    _balances: list[tuple[NDArray[np.float64], NDArray[np.float64]]] = field(
        default_factory=list, repr=False, init=False
    )
    """Balances found (at most :data:`KEPT`, the most recently useful first), each as the
    force at every point (normal, ``u`` and ``v`` parts: P x 3) with the pyramid gauge of
    its tangential part (P: ``mu`` times the normal part must reach it), so that one
    balance serves every friction coefficient it fits (:meth:`stands`)."""
    _certificates: list[NDArray[np.float64]] = field(default_factory=list, repr=False, init=False)
    """Farkas certificates found (at most :data:`KEPT_CERTIFICATES`, the most recently
    useful first), each as its ``y`` over every equation, zero on those it does not
    weigh (:meth:`stands`)."""
    _residuals: dict[tuple[bytes, bytes, float], NDArray[np.float64]] = field(
        default_factory=dict, repr=False, init=False
    )
    """The residuals of pieces of states (:meth:`slack`), per piece, the state's immobile
    parts and the friction coefficient (at most :data:`KEPT_RESIDUALS`, the oldest
    forgotten first)."""
    _needed: list[int] = field(default_factory=list, repr=False, init=False)
    """The upper end of :meth:`friction_needed`'s last bracket, in steps of its
    resolution, where its next search starts (none yet: at ``friction``)."""

    def __post_init__(self) -> None:
        self._index.update({name: i for i, name in enumerate(self.names)})

    @cached_property
    def levels(self) -> NDArray[np.int64]:
        """The parts in the order in which they are taken down (a rank each): the highest
        first, and of equal heights the nearest the middle (a keystone before its
        corbels), both compared by :func:`order_key` at the scale of the assembly, so
        that mirror images are equal whatever the rounding (then by index)."""
        if not len(self.heights):
            return np.zeros(0, dtype=np.int64)
        scale = float(np.ptp(self.heights) + self.offsets.max())
        keys = [
            (order_key(float(h), scale), order_key(float(r), scale), i)
            for i, (h, r) in enumerate(zip(self.heights, self.offsets, strict=True))
        ]
        ranks = np.empty(len(keys), dtype=np.int64)
        ranks[[i for *_, i in sorted(keys)]] = np.arange(len(keys))
        return ranks

    @property
    def resolution(self) -> float:
        """The width of :meth:`friction_needed`'s last bracket:
        ``friction / 2**FRICTION_STEPS``."""
        return self.friction / 2**FRICTION_STEPS

    def mask(self, names: Iterable[str] | None) -> NDArray[np.bool_]:
        """``names`` (default: all parts) as a boolean vector over :attr:`names`."""
        out = np.zeros(len(self.names), dtype=bool)
        if names is None:
            out[:] = True
        else:
            out[[self._index[n] for n in names]] = True
        return out

    def _rows(self, free: NDArray[np.bool_]) -> NDArray[np.int64]:
        """The equations (rows) of the ``free`` parts."""
        return (6 * np.flatnonzero(free)[:, None] + np.arange(6)).ravel()

    def _touching(self, present: NDArray[np.bool_]) -> NDArray[np.bool_]:
        """The force points between two parts of ``present``."""
        return present[self.point_parts[:, 0]] & present[self.point_parts[:, 1]]

    def _acting_on(self, parts: NDArray[np.bool_]) -> NDArray[np.bool_]:
        """The force points with a part of ``parts`` on one side or the other."""
        return parts[self.point_parts[:, 0]] | parts[self.point_parts[:, 1]]

    def _columns(self, selected: NDArray[np.bool_]) -> NDArray[np.int64]:
        """The generator columns of the ``selected`` points."""
        return (CONE_SIDES * np.flatnonzero(selected)[:, None] + np.arange(CONE_SIDES)).ravel()

    def _matrix(
        self, rows: NDArray[np.int64], selected: NDArray[np.bool_], mu: float
    ) -> sp.csc_matrix:
        """The equations ``rows`` over the generators of the ``selected`` points."""
        columns = self._columns(selected)
        part = self.normal_part[rows][:, columns] + mu * self.tangent_part[rows][:, columns]
        return sp.csc_matrix(part)

    @cached_property
    def _point_wrenches(self) -> tuple[sp.csr_matrix, sp.csr_matrix, sp.csr_matrix]:
        """The scaled wrenches (6 rows per part) of a unit force at each point along its
        normal, ``u`` and ``v`` (three P-column matrices): generator ``s`` is the normal
        one plus ``mu (cos t u + sin t v)``, and the ``CONE_SIDES`` angles ``t`` are
        spread evenly, so the tangent columns are recovered as their weighted means."""
        cos, sin = _cone_directions()
        spread = 2.0 / CONE_SIDES
        points = self.normal_part.shape[1] // CONE_SIDES
        return (
            sp.csr_matrix(self.normal_part[:, ::CONE_SIDES]),
            sp.csr_matrix(self.tangent_part @ _per_point(spread * cos, points)),
            sp.csr_matrix(self.tangent_part @ _per_point(spread * sin, points)),
        )

    def _keep_balance(self, weights: NDArray[np.float64], mu: float) -> None:
        """Keep the balance of generator weights ``weights`` at ``mu`` as forces."""
        cos, sin = _cone_directions()
        per_point = weights.reshape(-1, CONE_SIDES)
        forces = np.stack([per_point.sum(axis=1), mu * per_point @ cos, mu * per_point @ sin], 1)
        self._balances.insert(0, (forces, _gauge(forces[:, 1:])))
        del self._balances[KEPT:]

    def _keep_certificate(self, rows: NDArray[np.int64], certificate: NDArray[np.float64]) -> None:
        """Keep a Farkas certificate over the equations ``rows`` (zero on the others)."""
        y = np.zeros(len(self.load))
        y[rows] = certificate
        self._certificates.insert(0, y)
        del self._certificates[KEPT_CERTIFICATES:]

    @cached_property
    def _transposed(self) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """The normal and tangent parts transposed (a row per generator): a certificate's
        gain per generator is one product with each."""
        return sp.csr_matrix(self.normal_part.T), sp.csr_matrix(self.tangent_part.T)

    def stands(
        self,
        present: NDArray[np.bool_],
        fixed: NDArray[np.bool_],
        friction: float | None = None,
        local: bool = True,
    ) -> bool:
        """Whether the equations of ``present`` alone have a solution with ``fixed``
        immobile: the first program, on the corners (:func:`balance`). With ``local``,
        the balances and certificates found before decide first where they can
        (:meth:`_local_verdict`); its verdicts are the whole program's."""
        free = present & ~fixed
        if not free.any():
            return True
        points = self._touching(present)
        if not points.any():
            return False
        mu = self.friction if friction is None else friction
        selected = points & self.corners
        if local:
            verdict = self._local_verdict(present, free, selected, mu)
            if verdict is not None:
                return verdict
            # the states of a plan mostly need the friction the last one needed, and a
            # balance found there is one here too, of use to the friction's search
            hint = self._needed[0] * self.resolution if self._needed else mu
            if hint < mu and self.stands(present, fixed, hint):
                return True
        rows = self._rows(free)
        found = balance(self._matrix(rows, selected, mu), -self.load[rows])
        if found.forces is None:
            if found.certificate is not None:
                self._keep_certificate(rows, found.certificate)
            return False
        weights = np.zeros(self.normal_part.shape[1])
        weights[self._columns(selected)] = found.forces
        self._keep_balance(weights, mu)
        return True

    def _unbalanced(
        self, forces: NDArray[np.float64], free: NDArray[np.bool_]
    ) -> NDArray[np.bool_]:
        """The ``free`` parts whose equations the point ``forces`` (P x 3) leave with a
        residual beyond :data:`LP_FEASIBILITY`."""
        normal, along_u, along_v = self._point_wrenches
        wrench = normal @ forces[:, 0] + along_u @ forces[:, 1] + along_v @ forces[:, 2]
        error = np.abs(-self.load - wrench).reshape(-1, 6).max(axis=1)
        return free & (error > LP_FEASIBILITY)

    def _first_certifying(
        self, free: NDArray[np.bool_], selected: NDArray[np.bool_], mu: float
    ) -> int | None:
        """The index of the first certificate kept (its ``y``) that, restricted to the
        equations of the ``free`` parts, proves that they have no balance over the
        ``selected`` points at ``mu`` (``None`` when none does): no generator gains
        from it (``matrix.T @ y >= 0``, to :data:`LP_FEASIBILITY` of the loads' share)
        while the loads do (``rhs @ y < 0``). A part removed takes its generators away
        and a part held its equations: either can spoil one, which the test sees. Every
        certificate is tested in one product with each matrix."""
        if not self._certificates:
            return None
        kept = np.stack(self._certificates, axis=1) * np.repeat(free, 6)[:, None]
        shares = -self.load @ kept
        generators = np.repeat(selected, CONE_SIDES)
        normal, tangent = self._transposed
        gains = normal[generators] @ kept + mu * (tangent[generators] @ kept)
        worst = gains.min(axis=0, initial=0.0)
        proven = (shares < 0) & (worst >= LP_FEASIBILITY * shares)
        return int(np.argmax(proven)) if proven.any() else None

    def _local_verdict(
        self,
        present: NDArray[np.bool_],
        free: NDArray[np.bool_],
        selected: NDArray[np.bool_],
        mu: float,
    ) -> bool | None:
        """The verdict of :meth:`stands` where what was found before decides it (``None``
        where it does not):

        * *stands* when a balance kept, without the forces on parts absent from this
          state, still balances every free part with forces that ``mu``'s pyramids
          hold (a balance at one friction coefficient is one at every larger one);
        * *falls* when a certificate kept still proves it (:meth:`_first_certifying`), or when
          the parts the last balance leaves unbalanced, or pushes on with more friction
          than ``mu`` allows, grown by contacts (:data:`LOCAL_HOPS`), cannot balance
          even with every part around them immobile (pushing on them however it must):
          a Farkas certificate on their equations alone is one for the whole state,
          and is kept.

        Removing a block leaves its neighbours to be proved, a dozen parts, where the
        whole program has all of them; a region holding more than half the free parts
        is left to the whole program."""
        for index, (forces, gauge) in enumerate(self._balances):
            if np.any((gauge - mu * forces[:, 0])[selected] > LP_FEASIBILITY):
                continue
            kept = forces * selected[:, None]
            if not self._unbalanced(kept, free).any():
                del self._balances[index]
                self._balances.insert(0, (kept, gauge * selected))
                return True
        proof = self._first_certifying(free, selected, mu)
        if proof is not None:
            self._certificates.insert(0, self._certificates.pop(proof))
            return False
        if not self._balances:
            return None
        forces, gauge = self._balances[0]
        forces = forces * selected[:, None]
        region = self._unbalanced(forces, free)
        ends = self.point_parts
        # and the parts on both sides of the points whose forces mu's pyramids do not hold
        slipping = selected & (gauge - mu * forces[:, 0] > LP_FEASIBILITY)
        region[ends[slipping].ravel()] = True
        region &= free
        if not region.any():
            return None
        for _ in range(LOCAL_HOPS):
            near = np.zeros_like(region)
            near[ends[selected & region[ends[:, 0]], 1]] = True
            near[ends[selected & region[ends[:, 1]], 0]] = True
            region |= near & free
            if 2 * int(region.sum()) > int(free.sum()):
                return None
            rows = self._rows(region)
            touching = selected & self._acting_on(region)
            found = balance(self._matrix(rows, touching, mu), -self.load[rows])
            if not found.found:
                if found.certificate is not None:
                    self._keep_certificate(rows, found.certificate)
                return False
        return None

    def residuals(
        self,
        present: NDArray[np.bool_],
        fixed: NDArray[np.bool_],
        friction: float | None = None,
    ) -> NDArray[np.float64]:
        """Per part, the largest scaled residual of its six equations at the optimum of
        the slack program (0 for fixed and absent parts). A state that stands is told by
        the equations alone first, on the corners (:meth:`stands`): that program is
        smaller, and its answer is all zeros. The slack program is on the corners too
        (:func:`least_residuals`: the residuals of the interior of its optimal face)."""
        if self.stands(present, fixed, friction):
            return np.zeros(len(self.names))
        return self.slack(present, fixed, friction)

    def pieces(
        self, present: NDArray[np.bool_], fixed: NDArray[np.bool_]
    ) -> list[NDArray[np.bool_]]:
        """The free parts of a state in pieces that no force point joins (connected
        components of the contacts between free parts; immobile parts join nothing, as
        they take any wrench). The programs of a state are those of its pieces side by
        side: no generator acts on the equations of two pieces."""
        free = present & ~fixed
        ends = self.point_parts
        joined = free[ends[:, 0]] & free[ends[:, 1]]
        label = component_labels(len(self.names), ends[joined])
        return [free & (label == piece) for piece in np.unique(label[free])]

    def slack(
        self,
        present: NDArray[np.bool_],
        fixed: NDArray[np.bool_],
        friction: float | None = None,
    ) -> NDArray[np.float64]:
        """The slack program of :meth:`residuals` alone, for a state known not to stand:
        per part, the largest scaled residual of its equations at its optimum. It is
        solved piece by piece (:meth:`pieces`), and a piece's residuals are kept: a
        removal elsewhere leaves them as they were."""
        mu = self.friction if friction is None else friction
        out = np.zeros(len(self.names))
        immobile = (present & fixed).tobytes()
        for piece in self.pieces(present, fixed):
            key = (piece.tobytes(), immobile, mu)
            if key not in self._residuals:
                self._residuals[key] = self._piece_residuals(present, piece, mu)
                if len(self._residuals) > KEPT_RESIDUALS:
                    del self._residuals[next(iter(self._residuals))]
            out[piece] = self._residuals[key]
        return out

    def _piece_residuals(
        self, present: NDArray[np.bool_], piece: NDArray[np.bool_], mu: float
    ) -> NDArray[np.float64]:
        """The residuals of one piece's parts at the slack program's optimum, on the
        corners of its points (they span the same wrenches as every point: the same least
        residual and the same parts left unbalanced, :data:`SLACK_ACCURACY`); a piece
        that touches nothing keeps its whole weight as residual."""
        rows = self._rows(piece)
        points = self._touching(present) & self._acting_on(piece)
        if not points.any():
            return np.abs(self.load[rows]).reshape(-1, 6).max(axis=1)
        corners = self._matrix(rows, points & self.corners, mu)
        return np.abs(least_residuals(corners, -self.load[rows])).reshape(-1, 6).max(axis=1)

    def falling(
        self, present: NDArray[np.bool_], fixed: NDArray[np.bool_], friction: float | None = None
    ) -> NDArray[np.bool_]:
        """The parts of ``present`` that cannot be in equilibrium with ``fixed`` immobile."""
        return self.residuals(present, fixed, friction) > self.threshold

    def check(self, parts: Iterable[str] | None = None, held: Iterable[str] = ()) -> Equilibrium:
        """Whether ``parts`` (default: all) stand, with the model's fixed parts among them
        and ``held`` immobile."""
        present = self.mask(parts)
        fixed = present & (self.mask(self.fixed) | self.mask(held))
        residual = self.residuals(present, fixed)
        free = np.flatnonzero(present & ~fixed)
        return Equilibrium(
            parts=tuple(self.names[i] for i in np.flatnonzero(present)),
            fixed=tuple(self.names[i] for i in np.flatnonzero(fixed)),
            would_fall=tuple(self.names[i] for i in free if residual[i] > self.threshold),
            residuals=tuple(float(residual[i]) for i in free),
        )

    def friction_needed(
        self,
        present: NDArray[np.bool_],
        fixed: NDArray[np.bool_],
        falls: NDArray[np.bool_] | None = None,
    ) -> float | None:
        """A friction coefficient with which ``present`` is shown to stand, less than
        ``friction / 2**FRICTION_STEPS`` (:attr:`resolution`) above the least one and
        never above the least multiple of the resolution with which it stands; ``None``
        when ``friction`` itself does not suffice. ``falls``: :meth:`falling` at
        ``friction``, when already known.

        Standing is monotone in the friction coefficient (a larger pyramid holds every
        force a smaller one does), so a bracket of multiples of the resolution holds the
        least one: a probe that falls raises its lower end; one that stands lowers its
        upper end to the multiple just above what the balance that showed it needs
        (:meth:`_carrying`), and keeps that need. The search ends when the bracket is
        one step wide, and answers what the last balance found needs once its
        tangential forces are spread (:meth:`_spread_friction`, one more program): a
        balance stands with it, and the least one is above the lower end; 0 when the
        state stands without friction. It starts at the upper end of the last bracket:
        consecutive states of a plan mostly need the same friction, which two programs
        then confirm (a probe there, mostly decided by the balance the state's own
        verdict found there, :meth:`stands`, and one a step below what its balance
        needs); else it gallops away from it, then bisects (docs/planning.md, "Under
        gravity")."""
        if (self.falling(present, fixed) if falls is None else falls).any():
            return None
        free = present & ~fixed
        if not free.any() or self.friction == 0:
            return 0.0
        grid, step = 2**FRICTION_STEPS, self.resolution
        low, high = -1, grid
        shown: list[float] = []

        def stands(k: int) -> bool:
            """Probe ``k`` steps: narrow the bracket, keep what a balance needs, and say
            whether the state stands. With ``friction`` it stands (``falls`` names no
            part there) even should the first program find no balance within its
            tolerance."""
            nonlocal low, high
            mu = k * step
            if self.stands(present, fixed, mu):
                shown[:] = [min(mu, self._carrying(free)[1])]
                # the least multiple not below what the balance needs
                above = math.ceil(shown[0] / step)
                high = min(high, above + (above * step < shown[0]))
                return True
            if k < grid:
                low = k
                return False
            return True

        reach = 1
        if stands(self._needed[0] if self._needed else grid):
            while high - low > 1 and stands(max(high - reach, 0)):
                reach *= 2
        else:
            while high - low > 1 and not stands(min(low + reach, grid)):
                reach *= 2
        while high - low > 1:
            stands((low + high) // 2)
        self._needed[:] = [high]
        if not shown:
            return self.friction
        return min(shown[0], self._spread_friction(free)) if shown[0] > 0 else 0.0

    def _carrying(self, free: NDArray[np.bool_]) -> tuple[NDArray[np.bool_], float]:
        """The points of the balance :meth:`stands` found last (the first kept, after it
        answers that the state stands) that carry force on a ``free`` part (normal
        force beyond :data:`LP_FEASIBILITY` of the largest), and the friction
        coefficient that balance needs: the largest ratio of their pyramid gauge to
        their normal force."""
        forces, gauge = self._balances[0]
        normal = forces[:, 0]
        carrying = self._acting_on(free) & (normal > LP_FEASIBILITY * normal.max(initial=0.0))
        return carrying, float(np.max(gauge[carrying] / normal[carrying], initial=0.0))

    def _spread_friction(self, free: NDArray[np.bool_]) -> float:
        """The least friction coefficient of a balance of the ``free`` parts with the
        normal forces of the one :meth:`stands` found last (:meth:`_carrying`), its
        tangential forces spread over the points carrying force so that the largest
        ratio of gauge to normal force is least: with the normal forces fixed, the
        linear program "minimise ``s`` with every gauge at most ``s N``, the equations
        of the free parts balanced", solved by Clarabel. Its balance, checked
        (residuals within :data:`LP_FEASIBILITY`, the ratio read again from its
        forces), is kept first in place of the one it improves (it fits every
        coefficient that one fits, and more); should it not check out, what the balance
        found needs is the answer. A block on a slope of ``tan 20° = 0.364`` balanced
        with ``mu = 0.5`` needs 0.41 at its lower corners, where the weight presses
        most; spread evenly, every corner needs 0.364."""
        import clarabel

        carrying, found = self._carrying(free)
        if found == 0.0:
            return found
        forces = self._balances[0][0]
        normal = forces[:, 0]
        rows = self._rows(free)
        wrench_n, wrench_u, wrench_v = (m[rows] for m in self._point_wrenches)
        rest = forces * ~carrying[:, None]
        rhs = -self.load[rows] - wrench_n @ normal - wrench_u @ rest[:, 1] - wrench_v @ rest[:, 2]
        count = int(carrying.sum())
        half = np.pi / CONE_SIDES
        cos, sin = _cone_directions(half)
        # unknowns: u and v of each carrying point's tangential force, then s; per point
        # and pyramid side, (side normal . tangent) / cos(pi / S) - s N <= 0
        constraints = sp.bmat(
            [
                [wrench_u[:, carrying], wrench_v[:, carrying], None],
                [
                    sp.kron(sp.identity(count), cos[:, None] / math.cos(half)),
                    sp.kron(sp.identity(count), sin[:, None] / math.cos(half)),
                    -np.repeat(normal[carrying], CONE_SIDES)[:, None],
                ],
            ],
            format="csc",
        )
        settings = clarabel.DefaultSettings()
        settings.verbose = False
        settings.time_limit = LP_TIME_LIMIT
        solved = clarabel.DefaultSolver(
            sp.csc_matrix((2 * count + 1, 2 * count + 1)),
            np.r_[np.zeros(2 * count), 1.0],
            constraints,
            np.r_[rhs, np.zeros(count * CONE_SIDES)],
            [clarabel.ZeroConeT(len(rows)), clarabel.NonnegativeConeT(count * CONE_SIDES)],
            settings,
        ).solve()
        spread = forces.copy()
        spread[carrying, 1:] = np.asarray(solved.x[: 2 * count]).reshape(2, count).T
        spread_gauge = _gauge(spread[:, 1:])
        least = float(np.max(spread_gauge[carrying] / normal[carrying], initial=0.0))
        # NaN where the solver gave up: not less
        if not least < found or self._unbalanced(spread, free).any():
            return found
        self._balances[0] = (spread, spread_gauge)
        return least

    def tips(self, present: NDArray[np.bool_], fixed: NDArray[np.bool_]) -> bool:
        """Whether ``present`` falls with ``fixed`` immobile even with unbounded friction:
        whether no compressive normal forces (``N >= 0``) with free tangential forces,
        at the corners of its points (:meth:`stands`), balance every free part (one
        program, :func:`balance`: columns the normal wrench of each point and its ``u``
        and ``v`` wrenches of both signs). A state that falls but not then needs more
        friction than it has (it slides); one that falls even then tips over, as does
        one with free parts and no contact (docs/planning.md, "Under gravity")."""
        free = present & ~fixed
        if not free.any():
            return False
        selected = self._touching(present) & self.corners
        if not selected.any():
            return True
        rows = self._rows(free)
        normal, along_u, along_v = (m[rows][:, selected] for m in self._point_wrenches)
        matrix = sp.hstack([normal, along_u, -along_u, along_v, -along_v], format="csc")
        return not balance(matrix, -self.load[rows]).found


def equilibrium_model(
    assembly: Assembly,
    direction: ArrayLike = DOWN,
    friction: float = FRICTION,
    fixed: Sequence[str] | None = None,
    densities: Mapping[str, float] | None = None,
    tol: Tolerance | None = None,
) -> EquilibriumModel:
    """The equilibrium equations of ``assembly`` under gravity along ``direction``
    (module docstring), assembled with numpy into sparse matrices. ``fixed`` defaults to
    :func:`lowest_parts`; ``densities`` (default 1) scale each part's weight."""
    tol = assembly.tolerance(tol)
    down = gravity_direction(direction)
    names = tuple(assembly.names)
    for name in (*(fixed or ()), *(densities or {})):
        assembly.part(name)
    if not math.isfinite(friction) or friction < 0:
        raise InputError(
            f"expected a friction coefficient >= 0, got {friction}", where="--friction"
        )
    density = np.array([(densities or {}).get(n, 1.0) for n in names], dtype=np.float64)
    weight = density * np.array([assembly.parts[n].volume for n in names])
    centres = np.array([assembly.parts[n].mesh.center_mass for n in names], dtype=np.float64)
    origin = assembly.bounds.mean(axis=0)
    scale = assembly.scale
    found = contact_points(assembly, down, tol)

    cos, sin = _cone_directions()
    # per point and generator: the force's normal and tangential parts (P x S x 3)
    normal_force = np.repeat(found.normals[:, None, :], CONE_SIDES, axis=1)
    tangent_force = (
        cos[None, :, None] * found.u[:, None, :] + sin[None, :, None] * found.v[:, None, :]
    )
    arm = (found.points - origin) / scale
    ends = np.stack([found.second, found.first], axis=1)
    signs = np.array([1.0, -1.0])
    total_columns = len(found.points) * CONE_SIDES
    columns = np.arange(total_columns).reshape(-1, CONE_SIDES)

    def matrix(force: NDArray[np.float64]) -> sp.csr_matrix:
        moment = np.cross(arm[:, None, :], force)
        wrench = np.concatenate([force, moment], axis=2)  # P x S x 6
        # P x 2 (pushed, pushing) x S x 6, each row divided by its part's weight
        data = signs[None, :, None, None] * wrench[:, None] / weight[ends][:, :, None, None]
        rows = 6 * ends[:, :, None, None] + np.arange(6)[None, None, None, :]
        cols = np.broadcast_to(columns[:, None, :, None], data.shape)
        return sp.csr_matrix(
            (data.ravel(), (np.broadcast_to(rows, data.shape).ravel(), cols.ravel())),
            shape=(6 * len(names), total_columns),
        )

    load = np.concatenate(
        [np.tile(down, (len(names), 1)), np.cross((centres - origin) / scale, down)], axis=1
    )
    return EquilibriumModel(
        names=names,
        normal_part=matrix(normal_force),
        tangent_part=matrix(tangent_force),
        load=load.ravel(),
        point_parts=ends,
        corners=found.corners,
        heights=centres @ down,
        offsets=np.linalg.norm(np.cross(centres - origin, down), axis=1),
        fixed=tuple(fixed) if fixed is not None else lowest_parts(assembly, down, tol),
        friction=float(friction),
        threshold=max(tol.rel_length, LP_FEASIBILITY),
    )


def equilibrium(
    assembly: Assembly,
    direction: ArrayLike = DOWN,
    friction: float = FRICTION,
    fixed: Sequence[str] | None = None,
    held: Iterable[str] = (),
    densities: Mapping[str, float] | None = None,
    tol: Tolerance | None = None,
) -> Equilibrium:
    """Whether every part of ``assembly`` stands under gravity along ``direction``, with
    ``fixed`` (default: :func:`lowest_parts`) and ``held`` parts immobile."""
    model = equilibrium_model(assembly, direction, friction, fixed, densities, tol)
    return model.check(held=held)


def _friction_cell(needed: float | None, tips: bool) -> str:
    """The friction needed as a table cell: the coefficient, or when ``friction`` does
    not suffice "tips" (no friction would hold it) or "more than μ" (more would)."""
    if needed is not None:
        return f"{needed:.3f}"
    return "tips" if tips else "more than μ"


@dataclass(frozen=True)
class StepStability:
    """A disassembly step under gravity: ``held`` are the parts held during it (one grip
    on the moved parts, the grip of a subassembly being taken apart in the air, and the
    parts held so that the rest stands), ``would_fall`` the parts that would fall without
    the holds beyond the grip(s), ``stands`` whether every state stands with the holds
    (within the ``holds`` allowed), ``friction_needed`` the least friction coefficient
    with which they stand (``None`` when ``friction`` does not suffice)."""

    held: tuple[str, ...]
    would_fall: tuple[str, ...]
    stands: bool
    friction_needed: float | None
    friction: float
    unbalanced: float | None = None
    """When the step does not stand: the largest share of a part's weight that no
    balance of the contact forces carries (the slack program's residual, without the
    holds beyond the grips): how far beyond :attr:`threshold` the fall is."""
    threshold: float = 0.0
    """The residual beyond which a part falls (the model's tolerance)."""
    tips: bool = False
    """When ``friction`` does not suffice: whether a state of the step falls even with
    unbounded friction (it tips over; otherwise it slides: more friction would hold it,
    :meth:`EquilibriumModel.tips`)."""

    @property
    def margin(self) -> float | None:
        """``friction - friction_needed``: how much friction may be lost before the states
        of the step no longer stand (``None`` when they do not)."""
        return None if self.friction_needed is None else self.friction - self.friction_needed

    def to_dict(self) -> dict[str, Any]:
        """JSON keys added to a step: ``held``, ``would_fall``, ``stands``,
        ``friction_needed``, ``stability_margin`` (the friction that may be lost), for
        a step that does not stand ``unbalanced`` with the ``fall_threshold`` it is
        compared to (how far the verdict is from the solver's tolerance), and ``tips``
        (:attr:`tips`)."""
        return {
            "held": list(self.held),
            "would_fall": list(self.would_fall),
            "stands": self.stands,
            "friction_needed": self.friction_needed,
            "stability_margin": self.margin,
            "unbalanced": self.unbalanced,
            "fall_threshold": self.threshold,
            "tips": self.tips,
        }

    def cells(self) -> list[str]:
        """Table cells: held, would fall, friction needed ("tips" when no friction
        holds a state, "more than μ" when more would); long lists of parts cut to their
        first names and how many more, as the plan's "away from" cells are
        (docs/planning.md, "Under gravity")."""
        needed = _friction_cell(self.friction_needed, self.tips)
        return [fmt.name_list(self.held), fmt.name_list(self.would_fall) or "-", needed]


@dataclass(frozen=True)
class GravityReport:
    """A plan's stability: its ``settings``, the ``fixed`` parts, whether the ``whole``
    assembly stands, the least friction it needs, and ``stable``: every state of the plan
    stands with the holds listed."""

    settings: Gravity
    fixed: tuple[str, ...]
    whole: Equilibrium
    friction_needed: float | None
    stable: bool
    tips: bool = False
    """When ``friction`` does not suffice for the whole assembly: whether it falls even
    with unbounded friction (:meth:`EquilibriumModel.tips`)."""

    def to_dict(self) -> dict[str, Any]:
        """JSON form: the settings, ``fixed``, ``stable``, ``stands``, ``would_fall``
        and ``tips`` (of the whole assembly) and its ``friction_needed``."""
        return {
            **self.settings.to_dict(),
            "fixed": list(self.fixed),
            "stable": self.stable,
            "stands": self.whole.stands,
            "would_fall": list(self.whole.would_fall),
            "tips": self.tips,
            "friction_needed": self.friction_needed,
        }

    def cells(self) -> list[str]:
        """Table cells of the whole assembly as given, as :meth:`StepStability.cells`
        has them: nothing held, the parts that would fall, the friction needed."""
        needed = _friction_cell(self.friction_needed, self.tips)
        return ["-", fmt.name_list(self.whole.would_fall) or "-", needed]

    def summary(self) -> str:
        """One phrase for a table title."""
        extra = self.settings.extra_holds
        holds = "no extra hold" if extra == 0 else fmt.count(extra, "extra hold")
        verdict = "every state stands" if self.stable else "some states fall"
        return f"gravity, μ = {self.settings.friction:g}, {holds}: {verdict}"


@dataclass(frozen=True)
class _Assessment:
    """A candidate step judged: its holds, its verdict, its two states (what remains and
    what is taken, each with its immobile parts) and, asked for only when needed (a
    slack program each), the parts that would fall without the holds."""

    held: NDArray[np.bool_]
    stands: bool
    states: tuple[tuple[NDArray[np.bool_], NDArray[np.bool_]], ...]
    residual: Callable[[], NDArray[np.float64]]
    """Per part, its residual without the holds (a slack program per state that falls)."""
    threshold: float

    @cached_property
    def residuals(self) -> NDArray[np.float64]:
        """Per part, the share of its weight left unbalanced without the holds."""
        return self.residual()

    @cached_property
    def falls(self) -> NDArray[np.bool_]:
        """The parts that would fall without the holds."""
        return self.residuals > self.threshold


class StateJudge:
    """Stability of the planner's candidate steps (sets of parts as bit masks).

    A step moves ``moved`` out of ``members``. The set on the ground (it holds the
    planner's base, ``ground_base``) keeps the model's fixed parts immobile; a
    subassembly taken away earlier is held by its grip (its base), which costs a hold.
    The moved parts are gripped at their base (one hold) and must stand on it when they
    are several; what remains must stand. Parts that would fall are held greedily,
    highest first, while holds remain (``holds`` in all). ``vector`` turns a mask into a
    boolean vector over the model's parts; ``base`` names a set's base.
    """

    def __init__(
        self,
        model: EquilibriumModel,
        holds: int,
        vector: Callable[[int], NDArray[np.bool_]],
        base: Callable[[int], int],
        ground_base: int,
    ) -> None:
        self.model = model
        self.holds = holds
        self.vector = vector
        self.base = base
        self.ground_base = ground_base
        self.fixed = model.mask(model.fixed)
        self._stands: dict[tuple[bytes, bytes], bool] = {}
        self._falling: dict[tuple[bytes, bytes], NDArray[np.float64]] = {}
        self._assessed: dict[tuple[int, int], _Assessment] = {}
        self._single_falls: dict[int, int] = {}

    def stands(self, present: NDArray[np.bool_], fixed: NDArray[np.bool_]) -> bool:
        """:meth:`EquilibriumModel.stands`, once per state."""
        key = (present.tobytes(), fixed.tobytes())
        if key not in self._stands:
            self._stands[key] = self.model.stands(present, fixed)
        return self._stands[key]

    def residual(self, present: NDArray[np.bool_], fixed: NDArray[np.bool_]) -> NDArray[np.float64]:
        """:meth:`EquilibriumModel.residuals`, once per state: the slack program only when
        :meth:`stands` says it does not."""
        key = (present.tobytes(), fixed.tobytes())
        if key not in self._falling:
            self._falling[key] = (
                np.zeros(len(present))
                if self.stands(present, fixed)
                else self.model.slack(present, fixed)
            )
        return self._falling[key]

    def falling(self, present: NDArray[np.bool_], fixed: NDArray[np.bool_]) -> NDArray[np.bool_]:
        """:meth:`EquilibriumModel.falling`, once per state (:meth:`residual`)."""
        return self.residual(present, fixed) > self.model.threshold

    def _hold(
        self, present: NDArray[np.bool_], fixed: NDArray[np.bool_], budget: int
    ) -> tuple[NDArray[np.bool_], bool]:
        """Hold the highest falling part of ``present`` while ``budget`` allows: the
        holds and whether the state then stands (once the last hold is taken, or when
        none may be, which parts still fall no longer matters: the first program alone
        tells)."""
        held = np.zeros_like(present)
        if budget <= 0:
            return held, self.stands(present, fixed)
        now = self.falling(present, fixed)
        while now.any() and int(held.sum()) < budget:
            top = min(np.flatnonzero(now), key=lambda i: (int(self.model.levels[i]), i))
            held[top] = True
            if int(held.sum()) == budget:
                return held, self.stands(present, fixed | held)
            now = self.falling(present, fixed | held)
        return held, not now.any()

    def _one(self, index: int) -> NDArray[np.bool_]:
        out = np.zeros(len(self.model.names), dtype=bool)
        out[index] = True
        return out

    def assess(self, members: int, moved: int) -> _Assessment:
        """The holds, falling parts and verdict of moving ``moved`` out of ``members``."""
        key = (members, moved)
        if key in self._assessed:
            return self._assessed[key]
        inside, taken = self.vector(members), self.vector(moved)
        rest = inside & ~taken
        grounded = bool(members >> self.ground_base & 1)
        ground = self.fixed if grounded else self._one(self.base(members))
        grip = self._one(self.base(moved))
        base_held = rest & ground if not grounded else np.zeros_like(rest)
        budget = self.holds - 1 - int(base_held.sum())
        several = int(taken.sum()) > 1
        held_rest, rest_ok = self._hold(rest, rest & ground, budget)
        held_moved, moved_ok = np.zeros_like(rest), True
        if several:
            held_moved, moved_ok = self._hold(taken, grip, budget - int(held_rest.sum()))
        held = grip | base_held | held_rest | held_moved

        def residual() -> NDArray[np.float64]:
            left = self.residual(rest, rest & ground)
            return np.maximum(left, self.residual(taken, grip)) if several else left

        found = _Assessment(
            held=held,
            stands=rest_ok and moved_ok and int(held.sum()) <= self.holds,
            states=((rest, (rest & ground) | held_rest), (taken, grip | held_moved)),
            residual=residual,
            threshold=self.model.threshold,
        )
        self._assessed[key] = found
        if not found.stands and moved & (moved - 1) == 0:
            self._single_falls[members] = self._single_falls.get(members, 0) | moved
        return found

    def ordered(self, sets: list[int]) -> list[int]:
        """Fewest parts first, then the highest (a set's highest centre, to
        :data:`~assemblykit.tolerance.ORDER_RESOLUTION`), then index."""

        def key(mask: int) -> tuple[int, int, int]:
            inside = self.vector(mask)
            return (int(inside.sum()), int(self.model.levels[inside].min()), mask)

        return sorted(sets, key=key)

    def stands_without(self, members: int, moved: int) -> bool:
        """Whether moving ``moved`` out of ``members`` stands with the holds allowed (the
        planner moves the first such set, in :meth:`ordered`, alone)."""
        return self.assess(members, moved).stands

    def known_to_fall(self, members: int) -> int:
        """The parts of ``members`` (a mask) whose removal alone was judged already and
        does not stand (nothing is computed)."""
        return self._single_falls.get(members, 0)

    def fewest_falling(self, members: int, k: int, sets: list[int]) -> list[int]:
        """The set whose removal leaves the fewest parts falling (a step that does not
        stand, reported as such)."""
        return [min(self.ordered(sets), key=lambda m: int(self.assess(members, m).falls.sum()))]

    def judge(self, members: int, moved: int) -> StepStability:
        """The step's stability, with the least friction its states need and, when
        ``friction`` does not suffice, whether one of them tips over (one program per
        state that falls: :meth:`EquilibriumModel.tips`)."""
        found = self.assess(members, moved)
        names = self.model.names
        states = [(present, fixed) for present, fixed in found.states if (present & ~fixed).any()]
        needed = [
            self.model.friction_needed(present, fixed, self.falling(present, fixed))
            for present, fixed in states
        ]
        tips = any(
            self.model.tips(present, fixed)
            for (present, fixed), need in zip(states, needed, strict=True)
            if need is None
        )
        return StepStability(
            held=tuple(names[i] for i in np.flatnonzero(found.held)),
            would_fall=tuple(names[i] for i in np.flatnonzero(found.falls)),
            stands=found.stands,
            friction_needed=None if None in needed else max(needed, default=0.0),  # type: ignore[type-var]
            friction=self.model.friction,
            unbalanced=None if found.stands else float(found.residuals.max()),
            threshold=self.model.threshold,
            tips=tips,
        )
