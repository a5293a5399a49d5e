"""Closed-form chain solvers for short loops (docs/algebra.md §5.2 rule 4, §5.4).

A loop i→j→k closing on i→k, whose first link is a revolute and whose second link fixes
a point ``Q`` (a revolute or spherical joint), is solved by intersecting two orbits of
``Q`` in i's frame (docs/algebra.md §2.3 orbit table; Kramer's locus-intersection plan
fragments, §5.4): the circle ``Q`` sweeps under the first revolute and the orbit of ``Q``
under the closing coset (a point, circle, line, plane or sphere). Each common point fixes
the first joint's angle; what remains of the loop is then a coset intersection (rule 1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from assemblykit.algebra import Kind, Locus, LocusKind, se3
from assemblykit.model.relations import signed_angle
from assemblykit.tolerance import ModelTolerance


@dataclass(frozen=True)
class Circle:
    """A circle in space: centre, unit normal and radius."""

    center: np.ndarray
    normal: np.ndarray
    radius: float


@dataclass(frozen=True)
class LoopPoses:
    """The answer of a point-orbit loop solver: the pattern solved (``"circle-sphere"``,
    ``"circle-plane"``, ``"circle-line"``, ...), the poses of the first link (0, 1, 2)
    and, when there is none, the ``gap``: how far the loop is from closing."""

    pattern: str
    poses: tuple[np.ndarray, ...]
    gap: float = 0.0


GAP_SAMPLES = 720
"""Points of a circle sampled before the nearest one is refined (:func:`circle_gap`); a
distance along a circle has at most a few local minima, each far wider than 1/720 turn."""


def circle_gap(circle: Circle, locus: Locus) -> float:
    """The least distance between a circle and a locus (point, circle, line, cylinder,
    plane, sphere): how far a loop whose joint point sweeps ``circle`` is from closing on
    ``locus``. The circle is sampled, then the best sample refined by golden sections
    within its neighbours (the distance is smooth and unimodal there)."""
    c, r = circle.center, circle.radius
    axes = se3.frame(np.zeros(3), circle.normal)
    e1, e2 = axes[:3, 0], axes[:3, 1]

    def at(phi: np.ndarray) -> np.ndarray:
        points: np.ndarray = c + r * (np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2)
        return points

    step = 2 * math.pi / GAP_SAMPLES
    phis = np.arange(GAP_SAMPLES) * step
    best = float(phis[int(np.argmin(locus.distance(at(phis))))])
    low, high = best - step, best + step
    ratio = (math.sqrt(5) - 1) / 2
    for _ in range(60):  # (0.618)^60 of a 1/360 turn: below float64's resolution
        a, b = high - ratio * (high - low), low + ratio * (high - low)
        da, db = locus.distance(at(np.array([a, b])))
        if da < db:
            high = b
        else:
            low = a
    return float(locus.distance(at(np.array([(low + high) / 2])))[0])


def foot(point: np.ndarray, origin: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """The foot of ``point`` on the line through ``origin`` with unit ``direction``."""
    along = float(np.dot(point - origin, direction))
    return origin + along * direction


def rotation_about(point: np.ndarray, direction: np.ndarray, angle: float) -> np.ndarray:
    """The rotation by ``angle`` about the line through ``point`` with unit ``direction``."""
    return se3.translation(point) @ se3.rotation(direction, angle) @ se3.translation(-point)


def circle_circle(first: Circle, second: Circle, tol: ModelTolerance) -> list[np.ndarray] | None:
    """Common points of two coplanar circles (0, 1 or 2); None if they coincide (a
    continuum) or are not parallel (use :func:`circle_meets` with a circle locus)."""
    c1, n1, r1 = first.center, first.normal, first.radius
    c2, r2 = second.center, second.radius
    if np.linalg.norm(np.cross(n1, second.normal)) > tol.angle:
        return None
    if abs(np.dot(n1, c2 - c1)) > tol.length:
        return []
    d = c2 - c1
    dist = float(np.linalg.norm(d))
    if dist <= tol.length:
        return None if abs(r1 - r2) <= tol.length else []
    along = (dist**2 + r1**2 - r2**2) / (2 * dist)
    h2 = r1**2 - along**2
    if h2 < -2 * r1 * tol.length:
        return []
    u = d / dist
    base = c1 + along * u
    if h2 <= 2 * r1 * tol.length:
        return [base]
    side = np.cross(n1, u)
    h = math.sqrt(h2)
    return [base + h * side, base - h * side]


def _on_circle(circle: Circle, point: np.ndarray, tol: ModelTolerance) -> bool:
    d = point - circle.center
    along = float(np.dot(d, circle.normal))
    radial = float(np.linalg.norm(d - along * circle.normal))
    return abs(along) <= tol.length and abs(radial - circle.radius) <= tol.length


def circle_plane(
    circle: Circle, point: np.ndarray, normal: np.ndarray, tol: ModelTolerance
) -> list[np.ndarray] | None:
    """Points of a circle on the plane through ``point`` with unit ``normal``: 0, 1 or 2,
    None when the circle lies in the plane. With ``e1`` the in-plane direction of the
    normal (|m⊥| = s), a circle point ``c + r(cos φ e1 + sin φ e2)`` is on the plane iff
    ``cos φ = −m·(c − p) / (r s)``."""
    c, n, r = circle.center, circle.normal, circle.radius
    offset = float(np.dot(normal, c - point))
    tangential = normal - np.dot(normal, n) * n
    s = float(np.linalg.norm(tangential))
    if s <= tol.angle:
        return None if abs(offset) <= tol.length else []
    e1 = tangential / s
    e2 = np.cross(n, e1)
    # the plane's distance from the circle's nearest and farthest points, in lengths
    reach = r * s
    if abs(offset) > reach + tol.length:
        return []
    cos_phi = max(-1.0, min(1.0, -offset / reach))
    base = c + r * cos_phi * e1
    half = r * math.sqrt(max(0.0, 1.0 - cos_phi**2))
    if half <= tol.length:
        return [base]
    return [base + half * e2, base - half * e2]


def circle_line(
    circle: Circle, point: np.ndarray, direction: np.ndarray, tol: ModelTolerance
) -> list[np.ndarray] | None:
    """Points of a circle on the line through ``point`` with unit ``direction``: 0, 1
    or 2. A line across the circle's plane meets it once at most; a line in the plane
    meets it where its foot from the centre is within the radius."""
    c, n, r = circle.center, circle.normal, circle.radius
    slope = float(np.dot(direction, n))
    if abs(slope) > tol.angle:
        hit = point + (float(np.dot(n, c - point)) / slope) * direction
        return [hit] if _on_circle(circle, hit, tol) else []
    if abs(float(np.dot(n, point - c))) > tol.length:
        return []
    base = foot(c, point, direction)
    h2 = r**2 - float(np.dot(base - c, base - c))
    if h2 < -2 * r * tol.length:
        return []
    if h2 <= 2 * r * tol.length:
        return [base]
    h = math.sqrt(h2)
    return [base + h * direction, base - h * direction]


def circle_sphere(
    circle: Circle, center: np.ndarray, radius: float, tol: ModelTolerance
) -> list[np.ndarray] | None:
    """Points of a circle on a sphere: the sphere cuts the circle's plane in a circle
    (radius² = R² − h², h the centre's height over the plane), then circle-circle."""
    height = float(np.dot(circle.normal, center - circle.center))
    r2 = radius**2 - height**2
    if r2 < -2 * radius * tol.length:
        return []
    cut = Circle(center - height * circle.normal, circle.normal, math.sqrt(max(0.0, r2)))
    return circle_circle(circle, cut, tol)


def circle_meets(circle: Circle, locus: Locus, tol: ModelTolerance) -> list[np.ndarray] | None:
    """Common points of a circle and an orbit (docs/algebra.md §2.3): a point, circle, line,
    plane or sphere. None for a continuum or a locus without a closed form here."""
    if locus.kind == LocusKind.POINT:
        assert locus.point is not None
        return [locus.point] if _on_circle(circle, locus.point, tol) else []
    if locus.kind == LocusKind.SPHERE:
        assert locus.point is not None
        return circle_sphere(circle, locus.point, locus.radius, tol)
    if locus.kind == LocusKind.LINE:
        assert locus.point is not None and locus.direction is not None
        return circle_line(circle, locus.point, locus.direction, tol)
    if locus.kind == LocusKind.PLANE:
        assert locus.point is not None and locus.direction is not None
        return circle_plane(circle, locus.point, locus.direction, tol)
    if locus.kind == LocusKind.CIRCLE:
        assert locus.point is not None and locus.direction is not None
        other = Circle(locus.point, locus.direction, locus.radius)
        met = circle_plane(circle, locus.point, locus.direction, tol)
        if met is None:
            return circle_circle(circle, other, tol)
        return [p for p in met if _on_circle(other, p, tol)]
    return None


def _single(value: Any, kinds: tuple[Kind, ...]) -> bool:
    """Whether a coset is connected (one component) with a group of one of ``kinds``."""
    return value.group.kind in kinds and value.n_components == 1


def point_loop(first: Any, second: Any, closing: Any, tol: ModelTolerance) -> LoopPoses | None:
    """Closed-form R·(R or S) ∩ coset (docs/algebra.md §5.2 rule 4): circle against the
    closing orbit.

    ``first`` (i→j) is a revolute coset, ``second`` (j→k) fixes a point ``Q`` of j (on
    its axis or its centre), ``closing`` (i→k) any coset. In i's frame ``Q`` sweeps a
    circle under ``first`` and the orbit of ``Q``'s point of k under ``closing``; each
    common point fixes ``X_ij``. Both axis points of a revolute second link are tried
    (a point whose circle lies inside the orbit says nothing). Returns the poses
    ``X_ij`` (possibly none: the loop cannot close), or None when the pattern does not
    apply (other kinds, a point on the first axis, a continuum, an orbit without a
    closed form)."""
    if not _single(first, (Kind.REVOLUTE,)):
        return None
    if not _single(second, (Kind.REVOLUTE, Kind.SPHERICAL)) or closing.group.lattice:
        return None
    p1, u1 = first.group.origin, first.group.axis
    origin = second.group.origin
    points = [origin]
    if second.group.kind is Kind.REVOLUTE:
        points.append(origin + second.group.axis * tol.scale)
    for q_j in points:
        q0 = se3.apply(first.rep, q_j)
        center = foot(q0, p1, u1)
        radius = float(np.linalg.norm(q0 - center))
        if radius <= tol.length:
            continue
        q_k = se3.apply(se3.inverse(second.rep), q_j)
        locus = closing.group.orbit(se3.apply(closing.rep, q_k), tol)
        circle = Circle(center, u1, radius)
        meets = circle_meets(circle, locus, tol)
        if meets is None:
            continue
        poses = tuple(
            rotation_about(p1, u1, signed_angle(q0 - center, p - center, u1)) @ first.rep
            for p in meets
        )
        gap = 0.0 if poses else circle_gap(circle, locus)
        return LoopPoses(f"circle-{locus.kind}", poses, gap)
    return None


_AXIAL = (Kind.REVOLUTE, Kind.CYLINDRICAL, Kind.HELICAL)
"""Joints that keep a line of both bodies in place (their axis) and turn about it."""


@dataclass(frozen=True)
class Reach:
    """The reach bound of a loop of joints with parallel axes: the span of each body of
    the loop between its two joint axes, in loop order."""

    spans: tuple[float, ...]

    @property
    def longest(self) -> int:
        """The position in the loop of the body with the longest span."""
        return int(np.argmax(self.spans))

    @property
    def gap(self) -> float:
        """How far the loop stays open at best: the longest span less the sum of the others
        (zero or negative when the loop can close). With the other bodies stretched in one
        line, the ends of the longest span are this far from theirs."""
        return 2 * max(self.spans) - sum(self.spans)


def _axis_ends(link: Any) -> tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """A point and the unit direction of a joint's axis (the group origin and ``+z``) in
    the frame of the link's source and in that of its target. Every pose ``h·x0`` of the
    coset carries the target's copy of the axis onto the source's (``h`` keeps the axis
    line), so the target's copy is the source's moved by ``x0⁻¹``."""
    point, axis = link.group.origin, link.group.axis
    back = se3.inverse(link.rep)
    return (point, axis), (se3.apply(back, point), back[:3, :3] @ axis)


def loop_reach(links: list[Any], tol: ModelTolerance) -> Reach | None:
    """The reach bound of a loop of revolute, cylindrical or helical joints with parallel
    axes (docs/algebra.md §5.2 rule 4, "R·R vs R·R with all four axes parallel (planar 4-bar
    loop)"), a necessary condition for the loop to close.

    ``links[i]`` is the coset of body ``i + 1`` relative to body ``i`` (indices modulo
    the loop's length, the last link closing on body 0). When each body's two joint axes
    are parallel, every turn in the loop is about that one direction, and the loop
    projects onto the plane normal to it as a closed polygon whose sides are the
    distances between each body's two axes (a planar four-bar: crank, coupler, rocker
    and the ground between its pivots). A closed polygon has no side longer than the
    others together, so a positive :attr:`Reach.gap` proves the loop cannot close.
    Returns None when the pattern does not apply (another joint, a discrete or lattice
    part, axes that are not parallel)."""
    if not all(_single(link, _AXIAL) for link in links):
        return None
    ends = [_axis_ends(link) for link in links]
    spans = []
    for (p, u), (q, w) in ((ends[i - 1][1], ends[i][0]) for i in range(len(links))):
        if np.linalg.norm(np.cross(u, w)) > tol.angle:
            return None
        d = q - p
        spans.append(float(np.linalg.norm(d - np.dot(d, w) * w)))
    return Reach(tuple(spans))
