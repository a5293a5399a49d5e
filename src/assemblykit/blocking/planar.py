"""Polygons in the plane (Wilson & Latombe 1992, "2D case"), the blocking layer: the
contact segments and the blocking terms of a
:class:`~assemblykit.model.polygons.PolygonAssembly`, the planar variants of what
:mod:`assemblykit.geometry.contacts` and :mod:`assemblykit.blocking.extended` find for
meshes (registered with :func:`~assemblykit.geometry.contacts.assembly_contacts`,
:func:`~assemblykit.blocking.extended.assembly_extended_terms` and
:func:`~assemblykit.blocking.extended.exact_extended`). The package imports this module,
so the registrations are made whenever :mod:`assemblykit.blocking` is used.

Contacts. Two parts are in contact along a segment where an edge of one lies on an edge
of the other with opposite outward normals and the two overlap with positive length.
Each contact segment becomes a :class:`PlanarPatch` with its in-plane normal (from part
``a`` into part ``b``), its two endpoints (z = 0) and its length as area, so that the
NDBG machinery treats the planar case on the circle of directions S¹. The contacts found
are kept per tolerance in the :class:`PolygonContacts` store of the assembly's
:class:`~assemblykit.model.assembly.Memo`. Polygons are cut from 3D meshes by a plane
with :func:`section_polygons`.

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
from collections.abc import Iterable, Set
from dataclasses import dataclass, field

import numpy as np
import shapely
import trimesh
from numpy.typing import NDArray
from shapely.geometry import MultiPoint, Point, Polygon
from shapely.geometry.polygon import orient
from shapely.ops import unary_union

from assemblykit.algebra import se3
from assemblykit.blocking.constraints import BlockingTerm
from assemblykit.blocking.extended import assembly_extended_terms, exact_extended
from assemblykit.errors import GeometryError
from assemblykit.geometry.contact_values import Contact, PlanarPatch
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.model.polygons import PolygonAssembly
from assemblykit.tolerance import Tolerance


def convex_pieces(polygon: NDArray[np.float64], tol: Tolerance) -> list[NDArray[np.float64]]:
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
    moving: NDArray[np.float64], blocker: NDArray[np.float64], tol: Tolerance
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
def planar_extended_terms(model: PolygonAssembly, tol: Tolerance) -> list[BlockingTerm]:
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


def areas(model: PolygonAssembly) -> dict[str, float]:
    """The area of each polygon (the planar planner keeps the largest part as base)."""
    return {name: float(Polygon(poly).area) for name, poly in model.polygons.items()}


@dataclass(eq=False)
class PolygonContacts:
    """The contact segments of a polygon assembly per tolerance (``found``), a store of
    its memo (:func:`polygon_contacts`)."""

    found: dict[Tolerance, list[Contact]] = field(default_factory=dict)

    def restricted(self, names: Set[str]) -> PolygonContacts:
        """The contacts among the polygons ``names`` alone, per tolerance: contacts are
        found pair by pair, so those of the other pairs still hold."""
        return PolygonContacts(
            {
                tol: [c for c in found if c.a in names and c.b in names]
                for tol, found in self.found.items()
            }
        )


@assembly_contacts.register
def polygon_contacts(assembly: PolygonAssembly, tol: Tolerance | None = None) -> list[Contact]:
    """Contact segments between every two polygons of ``assembly`` (computed once per
    tolerance, kept in the :class:`PolygonContacts` of its memo): its
    :func:`~assemblykit.geometry.contacts.assembly_contacts`."""
    tol = assembly.tolerance(tol)
    kept = assembly.memo.of(PolygonContacts).found
    if tol not in kept:
        kept[tol] = edge_contacts(assembly.polygons, tol)
    return kept[tol]


def counter_clockwise(
    points: NDArray[np.float64], name: str, source: str | None = None
) -> NDArray[np.float64]:
    """``points`` (k x 2) as a counter-clockwise polygon without its closing vertex;
    :class:`GeometryError` naming part ``name`` when they are not a simple polygon of
    positive area."""
    poly = Polygon(points)
    if not poly.is_valid or poly.area <= 0:
        raise GeometryError(
            "not a simple polygon of positive area", source=source, where=f"parts.{name}"
        )
    return np.asarray(orient(poly, 1.0).exterior.coords, dtype=np.float64)[:-1]


def section_polygons(
    meshes: dict[str, trimesh.Trimesh],
    origin: NDArray[np.float64],
    normal: NDArray[np.float64],
) -> PolygonAssembly:
    """Cross-sections of meshes by the plane through ``origin`` with ``normal``, as
    polygons in one frame of that plane (the largest region of each part)."""
    n = np.asarray(normal, dtype=np.float64)
    n = n / np.linalg.norm(n)
    # the polygons' coordinates are in the plane's frame: its turn is part of the answer
    e1, e2 = se3.axis_basis(n, turned=True)
    to_2d = np.eye(4)
    to_2d[:3, :3] = np.vstack([e1, e2, n])
    to_2d[:3, 3] = -to_2d[:3, :3] @ np.asarray(origin, dtype=np.float64)
    polygons = {}
    for name, mesh in meshes.items():
        cut = mesh.section(plane_origin=origin, plane_normal=n)
        if cut is None:
            continue
        planar, _ = cut.to_2D(to_2D=to_2d, check=False)
        regions = planar.polygons_full
        if regions:
            # the triangulation leaves collinear vertices on the section's edges
            biggest = max(regions, key=lambda p: p.area).simplify(0)
            polygons[name] = counter_clockwise(np.asarray(biggest.exterior.coords)[:-1], name)
    return PolygonAssembly(polygons)


def _edges(poly: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    return poly, np.roll(poly, -1, axis=0)


def edge_contacts(polygons: dict[str, NDArray[np.float64]], tol: Tolerance) -> list[Contact]:
    """Contact segments between every two counter-clockwise polygons (module docstring)."""
    contacts = []
    boxes = {
        n: (p.min(axis=0) - tol.length, p.max(axis=0) + tol.length) for n, p in polygons.items()
    }
    for a, b in itertools.combinations(polygons, 2):
        (alo, ahi), (blo, bhi) = boxes[a], boxes[b]
        if np.any(alo > bhi) or np.any(blo > ahi):
            continue
        patches = []
        for p, q in zip(*_edges(polygons[a]), strict=True):
            u = (q - p) / np.linalg.norm(q - p)
            normal = np.array([u[1], -u[0]])  # outward for a counter-clockwise polygon
            for r, s in zip(*_edges(polygons[b]), strict=True):
                w = (s - r) / np.linalg.norm(s - r)
                if u @ w > 0 or abs(u[0] * w[1] - u[1] * w[0]) > tol.angle:
                    continue
                if abs(normal @ (r - p)) > tol.length or abs(normal @ (s - p)) > tol.length:
                    continue
                lo = max(0.0, min(u @ (r - p), u @ (s - p)))
                hi = min(float(u @ (q - p)), max(u @ (r - p), u @ (s - p)))
                if hi - lo > tol.length:
                    seg = np.array([[*(p + lo * u), 0.0], [*(p + hi * u), 0.0]])
                    patches.append(PlanarPatch(np.array([*normal, 0.0]), seg, hi - lo))
        if patches:
            contacts.append(Contact(a, b, planar=tuple(patches)))
    return contacts
