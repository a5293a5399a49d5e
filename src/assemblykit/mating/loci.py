"""Global positions of bodies joined by non-rigid relations (Liu & Popplestone 1990 step three,
Figs 4-5, and its Discussion).

* **Representative-point loci**: a goal whose two bodies each keep a revolute world
  coset relates a point carried by both (a point of the relation's axis, fixed by the
  relation's group); its orbits under the two bodies' groups (circles) must meet. Two
  circles meet in 0, 1 or 2 points: coplanar circles by the classical construction;
  circles in other planes by intersecting one circle with the other's sphere (the
  radical plane) and keeping the points on the other's plane. Each meeting point fixes
  one body's turn: a branch.
* **Numeric closure** (when no closed form applies: coincident circles, helices,
  cylindrical or spherical freedoms): least squares over the remaining group
  parameters of both bodies and of the relation, X(t) = h(s)·x₀, from a deterministic
  grid of starts (scipy ``least_squares``). Only solutions are reported: finding none
  proves nothing, so the caller keeps the unresolved cosets instead of claiming the
  loop cannot close (Liu & Popplestone 1990 Discussion: geometric methods are incomplete).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Mapping

import numpy as np

from assemblykit.algebra import Coset, Kind, Locus, SymmetryGroup, se3
from assemblykit.tolerance import ModelTolerance

World = dict[str, Coset]
"""The set of possible world poses of each placed body (a right coset)."""

#: Start values per parameter of the numeric closure (radians or model units).
START_VALUES = (-2.0, 0.0, 2.0)
#: Most starting points tried by the numeric closure (the grid is truncated beyond).
MAX_STARTS = 81
#: Convergence thresholds of the solver: float precision; the tolerance policy then
#: decides whether a converged point closes the loop.
SOLVER_PRECISION = 1e-15


def circle_plane(
    circle: Locus, point: np.ndarray, normal: np.ndarray, tol: ModelTolerance
) -> list[np.ndarray] | None:
    """The points of ``circle`` on the plane (``point``, unit ``normal``): 0, 1 or 2
    points; ``None`` when the circle lies in the plane (infinitely many)."""
    assert circle.point is not None and circle.direction is not None
    c, n, r = circle.point, circle.direction, circle.radius
    line = se3.cross(n, normal)
    sine = se3.norm(line)
    offset = float((point - c) @ normal)
    if sine <= tol.angle:
        return None if abs(offset) <= tol.length else []
    line = line / sine
    # The common line of the two planes: c + foot + s·line, foot in the circle's plane.
    across = se3.cross(line, n)
    foot = across * (offset / float(across @ normal))
    distance = se3.norm(foot)
    if distance > r + tol.length:
        return []
    half = math.sqrt(max(r * r - distance * distance, 0.0))
    if half <= tol.length:
        return [c + foot]
    return [c + foot + half * line, c + foot - half * line]


def circle_sphere(
    circle: Locus, center: np.ndarray, radius: float, tol: ModelTolerance
) -> list[np.ndarray] | None:
    """The points of ``circle`` on the sphere (``center``, ``radius``): the circle meets
    the radical plane |p − center|² − |p − c|² = radius² − r² (``None`` when the
    sphere holds the whole circle)."""
    assert circle.point is not None and circle.direction is not None
    c, r = circle.point, circle.radius
    gap = center - c
    length = se3.norm(gap)
    if length <= tol.length:
        return None if abs(radius - r) <= tol.length else []
    normal = gap / length
    # |p-c|² = r² on the circle, so 2 (p - c)·gap = r² - radius² + |gap|².
    along = (r * r - radius * radius + length * length) / (2 * length)
    found = circle_plane(circle, c + along * normal, normal, tol)
    if found is None:
        return None
    return [p for p in found if abs(se3.norm(p - center) - radius) <= tol.length]


def locus_meet(a: Locus, b: Locus, tol: ModelTolerance) -> list[np.ndarray] | None:
    """The common points of two loci that are points or circles (docs/algebra.md §2.3 orbit
    table): circles in one plane meet in 0, 1 or 2 points, circles in other planes too
    (:func:`circle_sphere` then the other's plane). ``None`` when there is no closed form
    here (coincident circles, other kinds of loci)."""
    if a.kind == "point":
        assert a.point is not None
        return [a.point] if b.contains(a.point, tol) else []
    if b.kind == "point":
        assert b.point is not None
        return [b.point] if a.contains(b.point, tol) else []
    if a.kind != "circle" or b.kind != "circle":
        return None
    assert b.point is not None and b.direction is not None
    on_sphere = circle_sphere(a, b.point, b.radius, tol)
    if on_sphere is None:
        # ``a`` lies on b's sphere: b's points of it are the ones on b's plane.
        return circle_plane(a, b.point, b.direction, tol)
    return [p for p in on_sphere if abs(float((p - b.point) @ b.direction)) <= tol.length]


def turn_to(coset: Coset, start: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The member of a revolute coset g·x₀ whose g carries ``start`` to ``target``."""
    frame_inv = coset.group.frame_inverse
    a, b = se3.apply(frame_inv, start), se3.apply(frame_inv, target)
    angle = math.atan2(b[1], b[0]) - math.atan2(a[1], a[0])
    return coset.group.element([angle]) @ coset.rep


def loci_branches(
    world: Mapping[str, Coset], second: str, first: str, relative: Coset, tol: ModelTolerance
) -> list[World] | None:
    """Representative-point loci (Liu & Popplestone 1990 Figs 4-5) for a goal X =
    L_second⁻¹·L_first ∈ ``relative`` whose two bodies each have a revolute world coset and whose
    relation is revolute or spherical: the relation's fixed point p is carried by both bodies, and
    its two orbits meet in the possible positions of p; each fixes ``second``'s turn.
    ``None`` when the case is not of this form or the loci have no closed form."""
    wu, wv = world[second], world[first]
    if wu.kind is not Kind.REVOLUTE or wv.kind is not Kind.REVOLUTE:
        return None
    if relative.kind not in (Kind.REVOLUTE, Kind.SPHERICAL):
        return None
    p = relative.group.origin
    q = se3.apply(se3.inverse(relative.rep), p)
    start = se3.apply(wu.rep, p)
    met = locus_meet(wu.group.orbit(start, tol), wv.group.orbit(se3.apply(wv.rep, q), tol), tol)
    if met is None:
        return None
    branches = []
    for point in met:
        turned = dict(world)
        turned[second] = Coset(SymmetryGroup.identity(), turn_to(wu, start, point))
        branches.append(turned)
    return branches


def _pose_residual(x: np.ndarray, y: np.ndarray, scale: float) -> np.ndarray:
    """Rotation-matrix and translation (over the model size) differences."""
    return np.concatenate([(x[:3, :3] - y[:3, :3]).ravel(), (x[:3, 3] - y[:3, 3]) / scale])


def _starts(dof: int) -> list[np.ndarray]:
    """The deterministic grid of starting parameters, truncated to :data:`MAX_STARTS`."""
    grid = itertools.product(START_VALUES, repeat=dof)
    return [np.asarray(s, dtype=np.float64) for s in itertools.islice(grid, MAX_STARTS)]


def _isolated(
    residual: Callable[[np.ndarray], np.ndarray], x: np.ndarray, tol: ModelTolerance
) -> bool:
    """Whether the solution ``x`` is isolated: the Jacobian (central differences with the
    step that balances truncation and rounding, eps^(1/3)) has full column rank."""
    if x.size == 0:
        return True
    step = np.finfo(np.float64).eps ** (1 / 3)
    columns = [
        (residual(x + step * e) - residual(x - step * e)) / (2 * step) for e in np.eye(x.size)
    ]
    singular = np.linalg.svd(np.stack(columns, axis=1), compute_uv=False)
    return singular.size == x.size and singular[-1] > tol.angle * singular[0]


def numeric_closure(
    world: Mapping[str, Coset], second: str, first: str, relative: Coset, tol: ModelTolerance
) -> list[World] | None:
    """Numeric closure of a loop (module docstring): the distinct solutions of
    L_second(t)⁻¹·L_first(t') = h(s)·x₀ over the parameters of both world cosets (a
    point coset has none) and of the relation's group; each solution fixes both bodies.
    ``None`` when a solution is not isolated (the Jacobian is rank deficient: the loop
    leaves a freedom); an empty list only says that no start converged."""
    cosets = (world[second], world[first], relative)
    dofs = [c.group.dof for c in cosets]

    def members(params: np.ndarray) -> list[np.ndarray]:
        out, k = [], 0
        for coset, dof in zip(cosets, dofs, strict=True):
            out.append(coset.group.element(params[k : k + dof]) @ coset.rep if dof else coset.rep)
            k += dof
        return out

    def residual(params: np.ndarray) -> np.ndarray:
        lu, lv, x = members(params)
        return _pose_residual(se3.inverse(lu) @ lv, x, tol.scale)

    found: list[tuple[np.ndarray, np.ndarray]] = []
    fits = se3.multistart_least_squares(
        residual,
        _starts(sum(dofs)),
        method="lm",
        xtol=SOLVER_PRECISION,
        ftol=SOLVER_PRECISION,
        gtol=SOLVER_PRECISION,
    )
    for fit in fits:
        lu, lv, x = members(fit.x)
        if not se3.poses_equal(se3.inverse(lu) @ lv, x, tol):
            continue
        if not _isolated(residual, fit.x, tol):
            return None
        if not any(se3.poses_equal(lu, u, tol) and se3.poses_equal(lv, v, tol) for u, v in found):
            found.append((lu, lv))
    branches = []
    for lu, lv in found:
        closed = dict(world)
        closed[second] = Coset(SymmetryGroup.identity(), lu)
        closed[first] = Coset(SymmetryGroup.identity(), lv)
        branches.append(closed)
    return branches
