"""Where a curved contact really touches: the normals of its patch.

Wilson & Latombe 1992 ("Infinitesimal translations") builds the blocking constraints of a contact
from the normals of its *contact surface*, and Liu 1997 §2 reads a shaft in a hole or a
ball in a socket as a fit of the whole surfaces. A rod lying in a half-round groove, or a
ball in a cup shallower than a hemisphere, touches only part of the surface of
revolution, and the directions it can leave along depend on that part alone: the rod is
blocked along ``d`` iff ``n . d > 0`` for some normal ``n`` of the patch, i.e. iff
``d`` leaves the polar of the *normal cone* (the non-negative combinations of the patch
normals).

A patch is therefore described by a few unit normals of its inner part (the shaft, the
ball, the male cone) that generate that cone:

* coaxial cylinders and cones: the azimuths about the axis that both surfaces cover, as
  arcs (:func:`covered_arcs`, :func:`intersect_arcs`); an arc's normals are its ends and
  points at most a quarter turn apart, whose non-negative combinations are every normal
  of the arc (:func:`arc_angles`); a cylinder's arcs, all in one plane, are first
  replaced by the one arc that generates their cone (:func:`generating_arc`). For a
  cylinder this is exact, and since the constraint ``n . (v + omega x p)`` at a point
  ``p`` of one end circle is linear in ``n`` (``n . (omega x n) = 0``), the same
  normals at both ends also make the rigid (twist) constraints exact. A cone's normals
  are not coplanar: it is sampled every ``1 / CONE_AZIMUTHS`` of a turn, which can only
  leave out blocked directions;
* concentric spheres: the directions from the centre that lie on both surfaces
  (:func:`sphere_region`: a vertex of one surface lies on the other iff its direction
  lies in one of the other's spherical triangles), reduced to the extreme rays of their
  cone (:func:`cone_generators`). Here too ``n . (v + omega x (c + r n))`` is linear in
  ``n``, so the extreme rays are exact for every use.

Membership of a unit direction d in the spherical triangle (a, b, c): d is on the
inner side of the three great circles through its edges, det(a, b, d), det(b, c, d),
det(c, a, d) having the sign of det(a, b, c), and d . (a + b + c) > 0 (the triangle's
hemisphere, which rules out the antipodal triangle).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linprog
from scipy.spatial import ConvexHull, QhullError

from assemblykit.algebra.se3 import axis_basis
from assemblykit.tolerance import Tolerance

# a cone's normals are sampled every eighth of a turn (module docstring)
CONE_AZIMUTHS = 8
# normals of an arc at most a quarter turn apart: any two closer than a half turn
# generate the arc between them, and a whole circle gets the four directions ±e1, ±e2
ARC_STEP = math.pi / 2
# directions tested against all triangles at once; bounds the temporary arrays
CHUNK = 256
TURN = 2.0 * math.pi
_AXES = np.eye(3)


def axis_frame(axis: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Unit ``e1, e2`` completing the unit ``axis`` to a right-handed frame; azimuths
    about the axis are measured from ``e1`` towards ``e2``."""
    u, v = axis_basis(axis / np.linalg.norm(axis))
    return -u, -v


def _merge(intervals: NDArray[np.float64], gap: float) -> NDArray[np.float64]:
    """Union of intervals inside ``[0, 2 pi]``, closing gaps up to ``gap``, as sorted arcs
    ``(start, end)`` with ``start`` in ``[0, 2 pi)``; an arc across azimuth 0 ends beyond
    ``2 pi``, and the whole circle is the single arc ``(0, 2 pi)``."""
    if len(intervals) == 0:
        return np.zeros((0, 2))
    intervals = intervals[np.argsort(intervals[:, 0], kind="stable")]
    merged = [list(intervals[0])]
    for lo, hi in intervals[1:]:
        if lo <= merged[-1][1] + gap:
            merged[-1][1] = max(merged[-1][1], hi)
        else:
            merged.append([lo, hi])
    first, last = merged[0], merged[-1]
    if first[0] <= gap and last[1] >= TURN - gap:
        if len(merged) == 1:
            return np.array([[0.0, TURN]])
        # the arc across azimuth 0 is one arc
        last[1] = first[1] + TURN
        merged.pop(0)
    return np.array(merged, dtype=np.float64)


def _pieces(arcs: NDArray[np.float64]) -> NDArray[np.float64]:
    """The arcs cut at azimuth ``2 pi`` into intervals inside ``[0, 2 pi]``."""
    inside = np.column_stack([arcs[:, 0], np.minimum(arcs[:, 1], TURN)])
    over = arcs[arcs[:, 1] > TURN] - TURN
    return np.vstack([inside, np.column_stack([np.zeros(len(over)), over[:, 1]])])


def covered_arcs(
    triangles: NDArray[np.float64],
    center: NDArray[np.float64],
    axis: NDArray[np.float64],
    gap: float,
) -> NDArray[np.float64]:
    """The azimuths about the axis line (``center``, unit ``axis``) that triangles
    (t x 3 x 3, world) of a surface of revolution cover, as arcs (:func:`_merge`); gaps up
    to ``gap`` radians are closed. A triangle of a tessellated surface of revolution
    spans less than a half turn, so its arc runs between its extreme vertex azimuths."""
    e1, e2 = axis_frame(axis)
    rel = triangles - center
    theta = np.arctan2(rel @ e2, rel @ e1)
    turned = (theta - theta[:, :1] + math.pi) % TURN - math.pi
    lo = theta[:, 0] + turned.min(axis=1)
    hi = theta[:, 0] + turned.max(axis=1)
    start = lo % TURN
    return _merge(_pieces(np.column_stack([start, hi + (start - lo)])), gap)


def intersect_arcs(
    first: NDArray[np.float64], second: NDArray[np.float64], gap: float
) -> NDArray[np.float64]:
    """The azimuths in both sets of arcs, as arcs; overlaps of ``gap`` radians or less
    (a touch along a line) are dropped."""
    a, b = _pieces(first), _pieces(second)
    lo = np.maximum(a[:, None, 0], b[None, :, 0]).ravel()
    hi = np.minimum(a[:, None, 1], b[None, :, 1]).ravel()
    kept = hi - lo > gap
    return _merge(np.column_stack([lo[kept], hi[kept]]), gap)


def generating_arc(arcs: NDArray[np.float64], gap: float) -> NDArray[np.float64]:
    """One arc whose normals generate the same cone as the normals of ``arcs`` (sorted,
    as :func:`_merge` gives them): the normals of a cylinder lie in one plane, so their
    non-negative combinations are the whole plane when no gap between the arcs reaches a
    half turn (``gap`` radians short of it, the tolerance), and otherwise the arc from
    the end of the largest gap round to its start. A tessellated surface covered in many
    pieces thus has the few normals of :func:`arc_angles` on that one arc, and every
    constraint linear in the normal (blocking, twists, contact forces) is the same."""
    if len(arcs) == 0 or arcs[0, 1] - arcs[0, 0] >= TURN:
        return arcs
    ends = np.r_[arcs[1:, 0], arcs[0, 0] + TURN]
    gaps = ends - arcs[:, 1]
    widest = int(np.argmax(gaps))
    if gaps[widest] < math.pi - gap:
        return np.array([[0.0, TURN]])
    start = ends[widest] % TURN
    return np.array([[start, start + TURN - gaps[widest]]])


def arc_angles(arcs: NDArray[np.float64], step: float) -> NDArray[np.float64]:
    """Azimuths sampling the arcs: each arc's ends and points evenly between them at most
    ``step`` apart; the whole circle at multiples of the largest step dividing it."""
    angles: list[NDArray[np.float64]] = []
    for lo, hi in arcs:
        if hi - lo >= TURN:
            count = math.ceil(TURN / step)
            angles.append(np.arange(count, dtype=np.float64) * (TURN / count))
        else:
            count = max(1, math.ceil((hi - lo) / step))
            angles.append(np.linspace(lo, hi, count + 1))
    return np.concatenate(angles) if angles else np.zeros(0)


def revolution_normals(
    axis: NDArray[np.float64], angles: NDArray[np.float64], half_angle: float = 0.0
) -> NDArray[np.float64]:
    """Outward unit normals of a shaft (``half_angle`` 0) or a male cone opening along
    ``axis`` at the azimuths ``angles``."""
    e1, e2 = axis_frame(axis)
    a = axis / np.linalg.norm(axis)
    radial = np.outer(np.cos(angles), e1) + np.outer(np.sin(angles), e2)
    return np.asarray(math.cos(half_angle) * radial - math.sin(half_angle) * a, dtype=np.float64)


def _unit(vectors: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.asarray(vectors / np.linalg.norm(vectors, axis=-1, keepdims=True), dtype=np.float64)


def in_region(
    directions: NDArray[np.float64], corners: NDArray[np.float64], tol: Tolerance
) -> NDArray[np.bool_]:
    """For each unit direction (n x 3), whether it lies in one of the spherical triangles
    with unit ``corners`` (t x 3 x 3), boundaries included within the angle tolerance
    (module docstring). Triangles of zero spherical area cover nothing and are dropped."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    orientation = np.einsum("ij,ij->i", np.cross(a, b), c)
    kept = np.abs(orientation) > tol.angle**2
    a, b, c, sign = a[kept], b[kept], c[kept], np.sign(orientation[kept])
    planes = np.stack([np.cross(a, b), np.cross(b, c), np.cross(c, a)]) * sign[None, :, None]
    middle = a + b + c
    inside = np.zeros(len(directions), dtype=bool)
    for start in range(0, len(directions), CHUNK):
        d = directions[start : start + CHUNK]
        sides = np.einsum("ktj,nj->knt", planes, d)
        ahead = d @ middle.T > 0
        inside[start : start + CHUNK] = np.any(np.all(sides >= -tol.angle, axis=0) & ahead, axis=1)
    return inside


def sphere_region(
    triangles: tuple[NDArray[np.float64], NDArray[np.float64]],
    center: NDArray[np.float64],
    tol: Tolerance,
) -> NDArray[np.float64]:
    """The vertices (world) of two concentric spherical surfaces of equal radius, given
    by their triangles, that lie on both: each surface's vertices whose direction from
    ``center`` falls in the other's triangles (module docstring)."""
    found = []
    for mine, other in (triangles, triangles[::-1]):
        points = np.unique(mine.reshape(-1, 3), axis=0)
        inside = in_region(_unit(points - center), _unit(other - center), tol)
        found.append(points[inside])
    return np.vstack(found)


def _pointing(directions: NDArray[np.float64]) -> tuple[NDArray[np.float64], float]:
    """A direction ``c`` (max-norm at most 1) maximising ``t = min d . c`` over the
    directions, and that ``t``: the cone they span is pointed iff ``t > 0``."""
    count = len(directions)
    result = linprog(
        np.array([0.0, 0.0, 0.0, -1.0]),
        A_ub=np.column_stack([-directions, np.ones(count)]),
        b_ub=np.zeros(count),
        bounds=[(-1.0, 1.0)] * 3 + [(None, 1.0)],
        method="highs",
    )
    return np.asarray(result.x[:3], dtype=np.float64), float(-result.fun)


def _has_free_direction(directions: NDArray[np.float64], tol: Tolerance) -> bool:
    """Whether some direction ``d`` has ``n . d <= 0`` for every given ``n`` (within the
    angle tolerance). Such a ``d`` scaled to max-norm 1 reaches 1 along one signed axis;
    when the directions positively span space only ``d`` of the tolerance's size remain,
    hence the threshold one half."""
    for axis in np.vstack([_AXES, -_AXES]):
        result = linprog(
            -axis,
            A_ub=directions,
            b_ub=np.full(len(directions), tol.angle),
            bounds=[(-1.0, 1.0)] * 3,
            method="highs",
        )
        if result.status == 0 and -result.fun > 0.5:
            return True
    return False


def cone_generators(directions: NDArray[np.float64], tol: Tolerance) -> NDArray[np.float64]:
    """A few of the unit ``directions`` whose non-negative combinations are all of them.

    A pointed cone (the directions lie in an open hemisphere about ``c``) is generated
    by its extreme rays: the vertices of the convex hull of the directions' central
    projection ``d / (d . c)`` on the plane ``x . c = 1``. A cone that spans space is
    generated by the six signed axes. Otherwise (the directions fill a closed hemisphere,
    as in a socket exactly as deep as a hemisphere) every distinct direction is kept."""
    unique = np.unique(np.round(_unit(directions) / tol.angle), axis=0, return_index=True)[1]
    directions = _unit(directions[np.sort(unique)])
    if len(directions) <= 2:
        return directions
    c, margin = _pointing(directions)
    if margin > tol.angle:
        c = c / np.linalg.norm(c)
        e1, e2 = axis_frame(c)
        projected = directions / (directions @ c)[:, None]
        plane = np.column_stack([projected @ e1, projected @ e2])
        try:
            return directions[np.sort(ConvexHull(plane).vertices)]
        except QhullError:
            # collinear projections: the cone is a flat wedge between the two extremes
            spread = plane - plane.mean(axis=0)
            along = spread @ np.linalg.svd(spread, full_matrices=False)[2][0]
            return directions[[int(np.argmin(along)), int(np.argmax(along))]]
    if not _has_free_direction(directions, tol):
        return np.vstack([_AXES, -_AXES])
    return directions


def spread(normals: NDArray[np.float64], count: int) -> NDArray[np.float64]:
    """At most ``count`` of the unit ``normals``, chosen far apart: the first, then
    repeatedly the one farthest in angle from those already chosen. Their cone lies
    inside the cone of all of them, so it blocks fewer directions."""
    if len(normals) <= count:
        return normals
    chosen = [0]
    nearest = normals @ normals[0]
    for _ in range(count - 1):
        k = int(np.argmin(nearest))
        chosen.append(k)
        nearest = np.maximum(nearest, normals @ normals[k])
    return normals[sorted(chosen)]
