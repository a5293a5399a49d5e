"""Snapping the directions of contacts: noisy normals of one direction made one.

Meshes that went through other tools carry vertex noise, so the patches of one face, or
of faces that share a direction, come with normals and axes a little apart. Once the
contacts are found (:mod:`assemblykit.geometry.contacts`), every planar normal and
curved axis that is parallel, within the tolerance, to that of a wider patch is
replaced by it (:func:`snap_classes`, :func:`snapped`) when turning the patch there
moves none of its points further than twice the scatter of the faces' vertices about
their planes (a fitted axis counts as scattered by the tolerance), never further than
the tolerance. Exact faces have no scatter and keep their directions. The planar
patches of one face, split by the noise, are then joined (their cracks, narrower than
the tolerance, closed), so that what compares directions afterwards (motion groups,
blocking arrangements) sees one direction where the geometry has one (docs/geometry.md,
"Noisy meshes").
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray

from assemblykit.algebra.se3 import axis_basis
from assemblykit.geometry.contact_values import Contact, CurvedPatch, PlanarPatch
from assemblykit.geometry.curved import axis_frame
from assemblykit.geometry.narrow_phase import cracks_closed
from assemblykit.tolerance import Tolerance


def _spread(patch: PlanarPatch | CurvedPatch) -> NDArray[np.float64]:
    """Points of a patch relative to its middle that bound where turning its direction
    moves it: a planar polygon's vertices; a cylinder's or cone's end circles, sampled
    at four azimuths each."""
    if isinstance(patch, PlanarPatch):
        return patch.polygon - patch.polygon.mean(axis=0)
    assert patch.axis is not None
    axis = patch.axis / np.linalg.norm(patch.axis)
    e1, e2 = axis_frame(axis)
    lo, hi = patch.extent if patch.extent is not None else (0.0, 0.0)
    ends = []
    for t in (lo, hi):
        r = patch.radius if patch.kind == "cylindrical" else abs(t) * math.tan(patch.half_angle)
        ends += [t * axis + r * e for e in (e1, -e1, e2, -e2)]
    ends_array = np.array(ends)
    return ends_array - ends_array.mean(axis=0)


def snap_classes(
    directions: NDArray[np.float64],
    spreads: list[NDArray[np.float64]],
    scatter: NDArray[np.float64],
    tol: Tolerance,
) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Per unit direction (rows) of a patch whose points relative to its middle are
    ``spreads[i]`` and whose faces' vertices lie up to ``scatter[i]`` from their planes,
    the index of the direction it is snapped to and the sign (+1, -1) that turns that
    one into it. Each direction, widest patch first (by the second largest extent of its
    points: a long thin strip's normal is unsure), joins the leader nearest to it if
    turning the patch onto it (about their common perpendicular, through the patch's
    middle) moves no point further than the two patches' scatter, and never further
    than the length tolerance; else it leads. Exact faces (no scatter) keep their
    directions: their differences are the geometry's, not noise. Snapping moves each
    patch within the tolerance, whatever the others' sizes."""
    width = np.array(
        [
            np.linalg.svd(p, compute_uv=False)[1] / math.sqrt(len(p)) if len(p) > 1 else 0.0
            for p in spreads
        ]
    )
    order = np.argsort(-width, kind="stable")
    leader = np.arange(len(directions), dtype=np.int64)
    sign = np.ones(len(directions))
    # leaders along one line (the same direction up to its sign) turn a patch alike: a
    # patch is compared with each line once, then with the leaders of the lines it may
    # join (only their scatter differs). Exact faces that share a direction do not join
    # (they turn by nothing), so a box packing has thousands of leaders on three lines.
    lines = np.zeros((0, 3))
    members: list[list[int]] = []
    loosest: list[float] = []
    line_of: dict[tuple[float, ...], int] = {}
    position: dict[int, int] = {}
    for i in order.tolist():
        d = directions[i]
        if len(lines):
            facing = np.where(lines @ d < 0, -1.0, 1.0)
            turn = np.cross(d, lines * facing[:, None])
            sines = np.linalg.norm(turn, axis=1)
            hinge = turn / np.maximum(sines, np.finfo(float).tiny)[:, None]
            # how far each point is from each turning axis through the middle
            lever = np.linalg.norm(np.cross(hinge[:, None, :], spreads[i][None]), axis=2)
            moved = sines * (lever.max(axis=1) if lever.size else 0.0)
            near = (moved <= np.minimum(2.0 * (scatter[i] + np.array(loosest)), tol.length)) & (
                sines > 0
            )
            best: tuple[float, int, int] | None = None
            for u in np.flatnonzero(near).tolist():
                group = members[u]
                allowed = np.minimum(2.0 * (scatter[i] + scatter[group]), tol.length)
                first = group[int(np.argmax(moved[u] <= allowed))]
                if best is None or (sines[u], position[first]) < best[:2]:
                    best = (float(sines[u]), position[first], first)
            if best is not None:
                leader[i] = best[2]
                sign[i] = -1.0 if directions[best[2]] @ d < 0 else 1.0
                continue
        position[i] = len(position)
        key = _line_key(d)
        if key not in line_of:
            line_of[key] = len(members)
            lines = np.vstack([lines, d])
            members.append([])
            loosest.append(-np.inf)
        u = line_of[key]
        members[u].append(i)
        loosest[u] = max(loosest[u], float(scatter[i]))
    return leader, sign


def _line_key(d: NDArray[np.float64]) -> tuple[float, ...]:
    """The line of direction ``d``: ``d`` or ``-d``, whichever has its first nonzero
    coordinate positive (zeros unsigned)."""
    nonzero = np.flatnonzero(d)
    line = -d if len(nonzero) and d[nonzero[0]] < 0 else d
    return tuple(np.where(line == 0, 0.0, line).tolist())


def snapped(contacts: list[Contact], tol: Tolerance) -> list[Contact]:
    """``contacts`` with every planar normal and curved axis that is parallel, within the
    tolerance, to that of a larger patch replaced by it (:func:`snap_classes`), then
    the planar patches of one face joined (:func:`_joined`): noisy normals of one
    direction become one direction, and what compares them afterwards (motion groups,
    blocking arrangements) sees it exactly."""
    patches: list[PlanarPatch | CurvedPatch] = [p for c in contacts for p in c.planar]
    patches += [p for c in contacts for p in c.curved if p.axis is not None]
    if not patches:
        return contacts
    directions = np.array(
        [p.normal if isinstance(p, PlanarPatch) else p.axis for p in patches], dtype=np.float64
    )
    # a fitted axis is as sure as the tolerance its surface was fitted to
    scatter = np.array([p.scatter if isinstance(p, PlanarPatch) else tol.length for p in patches])
    leader, sign = snap_classes(directions, [_spread(p) for p in patches], scatter, tol)
    new = directions[leader] * sign[:, None]
    turned: dict[int, Any] = {
        id(p): _turned(p, new[k]) if isinstance(p, PlanarPatch) else replace(p, axis=new[k].copy())
        for k, p in enumerate(patches)
    }
    return [
        replace(
            c,
            planar=_joined([turned[id(p)] for p in c.planar], tol),
            curved=tuple(turned.get(id(p), p) for p in c.curved),
        )
        for c in contacts
    ]


def _turned(patch: PlanarPatch, normal: NDArray[np.float64]) -> PlanarPatch:
    """``patch`` turned about its middle onto the plane of normal ``normal``."""
    middle = patch.centroid
    polygon = patch.polygon - np.outer((patch.polygon - middle) @ normal, normal)
    return replace(patch, normal=normal.copy(), polygon=polygon)


def _joined(patches: list[PlanarPatch], tol: Tolerance) -> tuple[PlanarPatch, ...]:
    """Planar ``patches`` of one contact with one (snapped) normal and heights within the
    tolerance joined where they touch or overlap
    (:func:`~assemblykit.geometry.narrow_phase.cracks_closed`): the pieces of one face
    that vertex noise split into several coplanar groups."""
    joined: list[PlanarPatch] = []
    by_normal: dict[tuple[float, ...], list[PlanarPatch]] = {}
    for patch in patches:
        by_normal.setdefault(tuple(patch.normal.tolist()), []).append(patch)
    for same in by_normal.values():
        normal = same[0].normal
        heights = np.array([float(normal @ p.centroid) for p in same])
        order = np.argsort(heights, kind="stable")
        layers = np.split(order, np.flatnonzero(np.diff(heights[order]) > tol.length) + 1)
        for layer in layers:
            if len(layer) == 1:
                joined.append(same[int(layer[0])])
                continue
            joined.extend(_layer_patches([same[int(k)] for k in layer], normal, tol))
    return tuple(joined)


def _layer_patches(
    patches: list[PlanarPatch], normal: NDArray[np.float64], tol: Tolerance
) -> list[PlanarPatch]:
    """The union of coplanar ``patches`` (normal ``normal``) as patches, one per piece."""
    u, v = (w[0] for w in axis_basis(normal[None]))
    height = float(np.mean([normal @ p.centroid for p in patches]))
    flat = [shapely.Polygon(np.column_stack([p.polygon @ u, p.polygon @ v])) for p in patches]
    union = cracks_closed(np.array([shapely.union_all(flat)], dtype=object), tol.length)[0]
    pieces = shapely.get_parts(shapely.orient_polygons(union))
    found = []
    for piece in pieces[~shapely.is_empty(pieces)]:
        ring = shapely.get_coordinates(piece.exterior)[:-1]
        polygon = ring[:, :1] * u + ring[:, 1:] * v + height * normal
        found.append(
            PlanarPatch(normal.copy(), polygon, float(piece.area), max(p.scatter for p in patches))
        )
    return found
