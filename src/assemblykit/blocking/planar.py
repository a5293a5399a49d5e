"""Polygons in the plane (Wilson & Latombe 1992, "2D case"), the blocking layer: the
blocking terms of a :class:`~assemblykit.model.polygons.PolygonAssembly`, the planar
variants of what :mod:`assemblykit.blocking.extended` finds for meshes (registered with
:func:`~assemblykit.blocking.extended.assembly_extended_terms` and
:func:`~assemblykit.blocking.extended.exact_extended`). The package imports this module,
so the registrations are made whenever :mod:`assemblykit.blocking` is used. The contact
segments of polygons are found by :mod:`assemblykit.geometry.polygons`.

Extended translations (Γ_e in the plane). Part ``j`` blocks part ``i`` along ``d`` (a
direction of the circle S¹) iff the area ``i`` sweeps out when it translates along ``d``
to infinity meets the interior of ``j``. Each polygon is cut into convex pieces (a
constrained triangulation whose triangles are merged while their union stays convex).
For a convex piece ``p`` of ``i`` and ``q`` of ``j`` the sweep of ``p`` meets the
interior of ``q`` iff the ray from the origin along ``d`` enters the interior of the
grown obstacle ``M = q ⊕ (−p)`` (the convex hull of the vertex differences; Wilson &
Latombe 1992 with [Lozano-Pérez, 1983]). So the blocked directions of a pair of pieces
are read off ``M`` seen from the origin, exactly, from the vertices:

* origin outside ``M``: the open arc between the two extreme directions of the vertices
  of ``M`` (an open cone of angle below π: two half-planes ``n . d > 0``);
* origin on the boundary of ``M`` (the pieces touch): the open half-circle of the inward
  normal of the edge it lies on, or the open cone of the two edges at a vertex;
* origin inside ``M`` (the pieces overlap): every direction.

A part blocks another along ``d`` iff one pair of their pieces does (a sweep that meets
the interior of a part meets the interior of one of its pieces: the cuts have no area).
The terms become the columns of the NDBG (:mod:`assemblykit.blocking.ndbg`); the
diameters perpendicular to their normals cut S¹ into the regular regions, so the NDBG of
polygons for extended translations is exact: its regions are points and open arcs, the
DBG is constant over each, and ``dbg(d)`` holds for any ``d``.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable

import numpy as np
import shapely
from numpy.typing import NDArray
from shapely.geometry import MultiPoint, Point, Polygon
from shapely.ops import unary_union

from assemblykit.blocking.constraints import BlockingTerm
from assemblykit.blocking.extended import assembly_extended_terms, exact_extended
from assemblykit.model.polygons import PolygonAssembly
from assemblykit.tolerance import ModelTolerance


def convex_pieces(polygon: NDArray[np.float64], tol: ModelTolerance) -> list[NDArray[np.float64]]:
    """Convex pieces (counter-clockwise vertex arrays) whose union is the simple polygon:
    the triangles of a constrained Delaunay triangulation, two pieces sharing an edge
    merged while their union is convex (its area is its hull's, within the length
    tolerance times the perimeter). A convex polygon is its own single piece."""
    shape = Polygon(polygon)
    if shape.convex_hull.area - shape.area <= tol.length * shape.length:
        return [np.asarray(polygon, dtype=np.float64)]
    pieces: list[Polygon] = list(shapely.constrained_delaunay_triangles(shape).geoms)
    merged = True
    while merged:
        merged = False
        for a, b in itertools.combinations(range(len(pieces)), 2):
            shared = pieces[a].boundary.intersection(pieces[b].boundary)
            if shared.length <= tol.length:
                continue
            union = unary_union([pieces[a], pieces[b]])
            if (
                isinstance(union, Polygon)
                and union.convex_hull.area - union.area <= tol.length * union.length
            ):
                pieces[a] = union.convex_hull
                del pieces[b]
                merged = True
                break
    return [_ccw_vertices(piece) for piece in pieces]


def _ccw_vertices(piece: Polygon) -> NDArray[np.float64]:
    ring = shapely.geometry.polygon.orient(piece, 1.0).exterior.coords
    return np.asarray(ring, dtype=np.float64)[:-1]


def _left(v: NDArray[np.float64]) -> NDArray[np.float64]:
    """``v`` turned a quarter turn counter-clockwise, as a unit 3-vector (z = 0)."""
    n = np.array([-v[1], v[0], 0.0], dtype=np.float64)
    return n / float(np.linalg.norm(n))


def blocked_normals(
    moving: NDArray[np.float64], blocker: NDArray[np.float64], tol: ModelTolerance
) -> NDArray[np.float64]:
    """The half-planes ``n . d > 0`` (rows ``n``, unit, z = 0) whose intersection is the
    set of directions along which the convex piece ``blocker`` blocks the convex piece
    ``moving`` (module docstring); no rows when they overlap (every direction)."""
    diffs = (blocker[:, None, :] - moving[None, :, :]).reshape(-1, 2)
    grown = MultiPoint(diffs).convex_hull
    origin = Point(0.0, 0.0)
    gap = grown.exterior.distance(origin)
    if gap <= tol.length:
        # touching: the edges of the grown obstacle through the origin bound the cone
        ring = _ccw_vertices(grown)
        normals = [
            _left(b - a)
            for a, b in zip(ring, np.roll(ring, -1, axis=0), strict=True)
            if shapely.geometry.LineString([a, b]).distance(origin) <= tol.length
        ]
        return np.array(normals).reshape(-1, 3)
    if grown.contains(origin):
        return np.zeros((0, 3))
    nearest = np.asarray(shapely.ops.nearest_points(grown, origin)[0].coords[0])
    r = nearest / np.linalg.norm(nearest)
    angles = np.arctan2(r[0] * diffs[:, 1] - r[1] * diffs[:, 0], diffs @ r)
    first, last = diffs[int(np.argmin(angles))], diffs[int(np.argmax(angles))]
    # counter-clockwise of the first extreme ray and clockwise of the last one
    return np.array([_left(first), -_left(last)])


@assembly_extended_terms.register(PolygonAssembly)
def planar_extended_terms(model: PolygonAssembly, tol: ModelTolerance) -> list[BlockingTerm]:
    """The Γ_e terms of a polygon assembly (:class:`assemblykit.model.polygons.
    PolygonAssembly`): one per pair of convex pieces of every two parts, both ways."""
    pieces = {name: convex_pieces(poly, tol) for name, poly in model.polygons.items()}
    terms: list[BlockingTerm] = []
    # no pruning by distance: two disjoint pieces block each other along some arc
    for a, b in itertools.combinations(model.polygons, 2):
        for p, q in itertools.product(pieces[a], pieces[b]):
            normals = blocked_normals(p, q, tol)
            terms.append(BlockingTerm(a, b, normals))
            terms.append(BlockingTerm(b, a, -normals))
    return terms


@exact_extended.register(PolygonAssembly)
def _exact_for_polygons(assembly: PolygonAssembly, parts: Iterable[str]) -> bool:
    """Γ_e of polygons is exact whatever their shape (module docstring)."""
    return True
