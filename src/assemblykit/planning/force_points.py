"""The points where the contacts of an assembly transmit force, for its equilibrium under
gravity (Whiting, Ochsendorf and Durand 2009, "Procedural modeling of
structurally-sound masonry buildings"; docs/planning.md, "Under gravity"), on the
contacts the project already finds (:mod:`assemblykit.geometry.contacts`).

A planar contact transmits forces only at the vertices of its contact polygon; a curved
contact at its sample points (:meth:`CurvedPatch.samples`). A pressure distribution over
a polygon has its resultant inside the polygon's convex hull, which the vertex forces
span, so nothing is lost in the normal direction; friction at the vertices resists
twisting about the normal somewhat more than distributed friction would (the usual
approximation of the method). Each point has a tangent frame whose ``u`` is the downhill
direction of the contact plane, so that a block sliding down a slope meets the exact
friction cone. A vertex on the straight segment between its two neighbours adds nothing
(every force it could carry is a combination of the same force at its neighbours, the
contact's normal and friction directions being the same at all its vertices), so the
first program is solved on the corners only; a vertex repeated counts once
(:func:`_corners`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.ragged import group_of, group_starts
from assemblykit.tolerance import MIN_REL_LENGTH, ModelTolerance, Tolerance

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly


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
    ring = group_of(sizes)
    start = group_starts(sizes)[ring]
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
    normals: NDArray[np.float64], down: NDArray[np.float64], tol: ModelTolerance
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
