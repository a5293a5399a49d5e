"""The narrow phase of finding contacts: where the surfaces of two parts coincide.

Vectorised over all candidate pairs of the broad phase
(:mod:`assemblykit.geometry.broad_phase`) at once, the coplanar groups of facets
(:func:`~assemblykit.geometry.recognition.segment`) of one part are matched with the
groups of the other that lie in the same plane with the opposite normal
(:func:`planar_matches`), and their overlap is measured by shapely in that plane
(:func:`group_overlaps`, :func:`planar_patches`), with the cracks that vertex noise
leaves between the pieces of one face closed (:func:`cracks_closed`; docs/geometry.md,
"Noisy meshes"). Curved contacts are coaxial cylinders and cones and concentric spheres
of equal size, one convex and one concave (:func:`may_fit`, :func:`curved_contact`);
each keeps only the part of the surface of revolution both parts cover, as the normals
there (:mod:`assemblykit.geometry.curved`). What they make are the patches of
:mod:`assemblykit.geometry.contact_values` (docs/geometry.md, "The contact model").
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray

from assemblykit.algebra.se3 import axis_basis
from assemblykit.geometry.broad_phase import PartStack, facing_groups
from assemblykit.geometry.contact_values import CurvedKind, CurvedPatch, PlanarPatch
from assemblykit.geometry.curved import (
    ARC_STEP,
    CONE_AZIMUTHS,
    TURN,
    arc_angles,
    cone_generators,
    covered_arcs,
    generating_arc,
    intersect_arcs,
    revolution_normals,
    sphere_region,
)
from assemblykit.geometry.recognition import Segmentation
from assemblykit.model.surfaces import Surface
from assemblykit.ragged import group_of, group_starts, ranges
from assemblykit.tolerance import Tolerance


def _cross_join(
    left_owner: NDArray[np.int64], right_owner: NDArray[np.int64], n_owners: int
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """All pairs ``(i, j)`` of entries with the same owner; owners must be sorted."""
    right_count = np.bincount(right_owner, minlength=n_owners)
    right_start = group_starts(right_count)
    per_left = right_count[left_owner]
    left = group_of(per_left)
    right = ranges(right_start[left_owner], per_left)
    return left, right


def planar_matches(
    stack: PartStack,
    seg: Segmentation,
    group_part: NDArray[np.int64],
    usable: NDArray[np.bool_],
    part_lo: NDArray[np.float64],
    part_hi: NDArray[np.float64],
    pairs: NDArray[np.int64],
    tol: Tolerance,
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Facing group pairs (:func:`~assemblykit.geometry.broad_phase.facing_groups`) that
    are flat, have opposite normals and are coplanar: all vertices of one of them lie
    within the length tolerance of the other's plane (so the contact region, inside both,
    is within the tolerance)."""
    margin = tol.length
    g, h = facing_groups(seg, group_part, usable, part_lo, part_hi, pairs, margin)
    n_g, n_h = seg.normal[g], seg.normal[h]
    gap = seg.point[h] - seg.point[g]
    # a centroid is within the largest vertex distance, so this keeps every true match
    near_plane = np.minimum(
        np.abs(np.einsum("ij,ij->i", n_g, gap)), np.abs(np.einsum("ij,ij->i", n_h, gap))
    )
    ok = (np.einsum("ij,ij->i", n_g, n_h) < 0) & (near_plane <= margin)
    g, h = g[ok], h[ok]
    close = (
        np.minimum(group_deviation(stack, seg, h, g), group_deviation(stack, seg, g, h)) <= margin
    )
    return g[close], h[close]


def group_deviation(
    stack: PartStack, seg: Segmentation, g: NDArray[np.int64], h: NDArray[np.int64]
) -> NDArray[np.float64]:
    """Per pair, the largest distance of a vertex of group ``g[k]`` from the plane of
    group ``h[k]``."""
    size = seg.start[g + 1] - seg.start[g]
    owner = group_of(size)
    corners = stack.vertices[stack.faces[seg.order[ranges(seg.start[g], size)]]]
    offsets = np.einsum("fkj,fj->fk", corners - seg.point[h][owner, None], seg.normal[h][owner])
    deviation = np.zeros(len(g))
    np.maximum.at(deviation, owner, np.abs(offsets).max(axis=1))
    return deviation


def _triangles_2d(
    corners: NDArray[np.float64], u: NDArray[np.float64], v: NDArray[np.float64]
) -> NDArray[np.float64]:
    return np.stack([np.einsum("tkj,tj->tk", corners, u), np.einsum("tkj,tj->tk", corners, v)], -1)


OVERLAP_CHUNK = 1 << 20
"""How many triangle pairs :func:`group_overlaps` projects and intersects at once: the
pairs of large coplanar groups (a plate on a plate) run to millions, and their 2D
triangles, boxes and polygons are made chunk by chunk to bound the memory they take."""


OUTLINE_PAIRS = 4096
"""Group pairs of more triangle pairs than this are intersected outline to outline (the
union of each group's triangles, which tile it), at a cost that follows the triangles'
count rather than its product: two plates' faces of thousands of triangles each."""


def group_overlaps(
    stack: PartStack, seg: Segmentation, g: NDArray[np.int64], h: NDArray[np.int64], margin: float
) -> tuple[NDArray[np.int64], NDArray[Any], NDArray[np.float64], NDArray[np.float64]]:
    """Where the triangles of groups ``g[k]`` and ``h[k]`` overlap, projected on the plane
    of ``g[k]`` with the frame ``(u[k], v[k])``: the non-empty intersections of triangle
    pairs whose 2D boxes overlap by more than ``margin`` (shapely, vectorised, over
    chunks of about ``OVERLAP_CHUNK`` triangle pairs), each with its ``owner`` ``k``
    (in order); for a pair of more than ``OUTLINE_PAIRS`` triangle pairs, the one
    intersection of the two groups' outlines. Returns ``owner, pieces, u, v``."""
    u, v = axis_basis(seg.normal[g]) if len(g) else (np.zeros((0, 3)), np.zeros((0, 3)))
    work = (seg.start[g + 1] - seg.start[g]) * (seg.start[h + 1] - seg.start[h])
    small, large = np.flatnonzero(work <= OUTLINE_PAIRS), np.flatnonzero(work > OUTLINE_PAIRS)
    by_triangle = _triangle_pieces(stack, seg, g[small], h[small], u[small], v[small], margin)
    by_outline = _outline_pieces(stack, seg, g[large], h[large], u[large], v[large])
    owner = np.concatenate([small[by_triangle[0]], large[by_outline[0]]])
    order = np.argsort(owner, kind="stable")
    return owner[order], np.concatenate([by_triangle[1], by_outline[1]])[order], u, v


def _triangle_pieces(
    stack: PartStack,
    seg: Segmentation,
    g: NDArray[np.int64],
    h: NDArray[np.int64],
    u: NDArray[np.float64],
    v: NDArray[np.float64],
    margin: float,
) -> tuple[NDArray[np.int64], NDArray[Any]]:
    """:func:`group_overlaps` triangle by triangle, chunk by chunk."""
    work = np.cumsum((seg.start[g + 1] - seg.start[g]) * (seg.start[h + 1] - seg.start[h]))
    cuts = np.searchsorted(
        work, np.arange(OVERLAP_CHUNK, int(work[-1]) if len(g) else 0, OVERLAP_CHUNK)
    )
    owners, pieces = [np.zeros(0, dtype=np.int64)], [np.zeros(0, dtype=object)]
    for chunk in np.split(np.arange(len(g), dtype=np.int64), np.unique(cuts + 1)):
        found = _chunk_overlaps(stack, seg, g, h, chunk, u, v, margin)
        owners.append(found[0])
        pieces.append(found[1])
    return np.concatenate(owners), np.concatenate(pieces)


def _outline_pieces(
    stack: PartStack,
    seg: Segmentation,
    g: NDArray[np.int64],
    h: NDArray[np.int64],
    u: NDArray[np.float64],
    v: NDArray[np.float64],
) -> tuple[NDArray[np.int64], NDArray[Any]]:
    """:func:`group_overlaps` outline to outline: each group's outline made once in
    its frame (``g``'s) and intersected; the pairs whose overlap has an area."""
    if not len(g):
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=object)
    unique, first = np.unique(g, return_index=True)
    outline_g = _outlines(stack, seg, unique, u[first], v[first])
    shared = shapely.intersection(
        outline_g[np.searchsorted(unique, g)], _outlines(stack, seg, h, u, v)
    )
    owner = np.flatnonzero(shapely.area(shared) > 0)
    return owner, shared[owner]


def _outlines(
    stack: PartStack,
    seg: Segmentation,
    groups: NDArray[np.int64],
    u: NDArray[np.float64],
    v: NDArray[np.float64],
) -> NDArray[Any]:
    """Per group, the union of its triangles projected with the frame ``(u, v)``."""
    size = seg.start[groups + 1] - seg.start[groups]
    owner = group_of(size)
    faces = seg.order[ranges(seg.start[groups], size)]
    triangles = shapely.polygons(
        _triangles_2d(stack.vertices[stack.faces[faces]], u[owner], v[owner])
    )
    outlines = np.empty(len(groups), dtype=object)
    outlines[:] = [shapely.union_all(t) for t in np.split(triangles, np.cumsum(size)[:-1])]
    return outlines


def _chunk_overlaps(
    stack: PartStack,
    seg: Segmentation,
    g: NDArray[np.int64],
    h: NDArray[np.int64],
    match: NDArray[np.int64],
    u: NDArray[np.float64],
    v: NDArray[np.float64],
    margin: float,
) -> tuple[NDArray[np.int64], NDArray[Any]]:
    """:func:`group_overlaps` for the group pairs ``match`` (consecutive indices)."""
    if not len(match):
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=object)
    size_g = seg.start[g[match] + 1] - seg.start[g[match]]
    size_h = seg.start[h[match] + 1] - seg.start[h[match]]
    owner_a = np.repeat(match, size_g)
    faces_a = seg.order[ranges(seg.start[g[match]], size_g)]
    owner_b = np.repeat(match, size_h)
    faces_b = seg.order[ranges(seg.start[h[match]], size_h)]
    i, j = _cross_join(owner_a - match[0], owner_b - match[0], len(match))
    owner = owner_a[i]
    tri_a = _triangles_2d(stack.vertices[stack.faces[faces_a[i]]], u[owner], v[owner])
    tri_b = _triangles_2d(stack.vertices[stack.faces[faces_b[j]]], u[owner], v[owner])
    width = np.minimum(tri_a.max(axis=1), tri_b.max(axis=1)) - np.maximum(
        tri_a.min(axis=1), tri_b.min(axis=1)
    )
    keep = np.all(width > margin, axis=1)
    pieces = shapely.intersection(shapely.polygons(tri_a[keep]), shapely.polygons(tri_b[keep]))
    owner = owner[keep]
    solid = shapely.area(pieces) > 0
    return owner[solid], pieces[solid]


def planar_patches(
    stack: PartStack, seg: Segmentation, g: NDArray[np.int64], h: NDArray[np.int64], tol: Tolerance
) -> tuple[NDArray[np.int64], list[PlanarPatch]]:
    """The contact polygons of the matched group pairs ``(g[k], h[k])``: the union of
    their triangles' overlaps in ``g[k]``'s plane (:func:`group_overlaps`), one
    polygon per connected piece wider than the tolerance, at the mean height of the two
    planes, counter-clockwise about ``g[k]``'s normal. Returns each patch's ``k``."""
    owner, pieces, u, v = group_overlaps(stack, seg, g, h, tol.length)
    matched, slot = np.unique(owner, return_inverse=True)
    rank = np.arange(len(owner)) - np.searchsorted(owner, owner)
    table = np.full((len(matched), int(rank.max()) + 1 if len(rank) else 0), None, dtype=object)
    table[slot, rank] = pieces
    merged = shapely.union_all(table, axis=1) if len(matched) else np.array([], dtype=object)
    merged = cracks_closed(merged, tol.length)
    polygons, which = shapely.get_parts(merged, return_index=True)
    polygons = shapely.simplify(polygons, 0.0)
    wide = shapely.is_valid(polygons) & (shapely.get_type_id(polygons) == 3)
    wide &= shapely.area(polygons) > tol.length * shapely.length(polygons) / 2
    polygons, k = polygons[wide], matched[which[wide]]
    rings = shapely.get_exterior_ring(shapely.orient_polygons(polygons))
    coords, ring = shapely.get_coordinates(rings, return_index=True)
    # each ring repeats its first vertex last
    last = np.r_[ring[1:] != ring[:-1], True][: len(ring)]
    coords, ring = coords[~last], ring[~last]
    normal = seg.normal[g]
    height = (
        np.einsum("ij,ij->i", normal, seg.point[g]) + np.einsum("ij,ij->i", normal, seg.point[h])
    ) / 2
    at = k[ring]
    world = coords[:, :1] * u[at] + coords[:, 1:] * v[at] + height[at, None] * normal[at]
    bounds = np.searchsorted(ring, np.arange(len(polygons) + 1))
    areas = shapely.area(polygons)
    scatter = (
        np.zeros(len(g))
        if seg.deviation is None
        else np.maximum(seg.deviation[g], seg.deviation[h])
    )
    patches = [
        PlanarPatch(
            normal=normal[k[n]].copy(),
            polygon=world[bounds[n] : bounds[n + 1]],
            area=float(areas[n]),
            scatter=float(scatter[k[n]]),
        )
        for n in range(len(polygons))
    ]
    return k, patches


def _openings(shapes: NDArray[Any]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Per (multi)polygon, how many pieces and how many holes it has."""
    parts, which = shapely.get_parts(shapes, return_index=True)
    holes = np.bincount(which, weights=shapely.get_num_interior_rings(parts), minlength=len(shapes))
    return shapely.get_num_geometries(shapes), holes.astype(np.int64)


def cracks_closed(shapes: NDArray[Any], width: float) -> NDArray[Any]:
    """``shapes`` (polygons) with cracks and holes narrower than ``width`` closed: vertex
    noise leaves such cracks between the pieces of one face. A morphological closing
    (square corners kept) is used where it joins something; elsewhere the exact shape
    stays."""
    shapes = np.asarray(shapes, dtype=object)
    closed = shapely.buffer(
        shapely.buffer(shapes, width, join_style="mitre"), -width, join_style="mitre"
    )
    (pieces, holes), (closed_pieces, closed_holes) = _openings(shapes), _openings(closed)
    joins = (closed_pieces < pieces) | ((closed_pieces == pieces) & (closed_holes < holes))
    return np.where(joins, closed, shapes)


def _axial_overlap(
    first: Surface, second: Surface, axis: NDArray[np.float64], origin: NDArray[np.float64]
) -> tuple[float, float]:
    """The common interval of two surfaces' extents, measured along ``axis`` from ``origin``."""

    def span(s: Surface) -> tuple[float, float]:
        assert s.axis is not None  # surfaces with an extent along an axis have one
        base = float((s.point - origin) @ axis)
        ends = [base + e * float(s.axis @ axis) for e in s.extent]
        return min(ends), max(ends)

    (lo_a, hi_a), (lo_b, hi_b) = span(first), span(second)
    return max(lo_a, lo_b), min(hi_a, hi_b)


def _boundary(
    points: NDArray[np.float64],
    axis: NDArray[np.float64],
    origin: NDArray[np.float64],
    lo: float,
    hi: float,
    tol: Tolerance,
) -> NDArray[np.float64]:
    along = (points - origin) @ axis
    ends = (np.abs(along - lo) <= tol.length) | (np.abs(along - hi) <= tol.length)
    return np.unique(points[ends], axis=0)


def may_fit(
    first: Sequence[Surface], second: Sequence[Surface], tol: Tolerance
) -> list[tuple[int, int]]:
    """The pairs ``(i, j)`` of surfaces ``first[i]``, ``second[j]`` that :func:`curved_contact`
    may find in contact, in the order of ``i`` then ``j``: the same kind of surface of
    revolution (cylinder, cone, sphere), one convex and one concave, and for cylinders
    and spheres radii equal within the length tolerance. The others it would turn down
    by these tests alone; a hundred curved surfaces of one part near a hundred of
    another are so compared in one array operation."""
    if not first or not second:
        return []

    def columns(
        surfaces: Sequence[Surface],
    ) -> tuple[NDArray[np.str_], NDArray[np.bool_], NDArray[np.float64]]:
        return (
            np.array([s.kind for s in surfaces]),
            np.array([s.convex for s in surfaces], dtype=bool),
            np.array([s.radius for s in surfaces], dtype=np.float64),
        )

    (kind_a, convex_a, radius_a), (kind_b, convex_b, radius_b) = columns(first), columns(second)
    fits = (kind_a[:, None] == kind_b[None, :]) & (convex_a[:, None] != convex_b[None, :])
    fits &= np.isin(kind_a, ("cylinder", "cone", "sphere"))[:, None]
    radial = np.isin(kind_a, ("cylinder", "sphere"))[:, None]
    fits &= ~radial | (np.abs(radius_a[:, None] - radius_b[None, :]) <= tol.length)
    return [(int(i), int(j)) for i, j in np.argwhere(fits)]


def curved_contact(
    first: Surface,
    second: Surface,
    names: tuple[str, str],
    triangles: tuple[NDArray[np.float64], NDArray[np.float64]],
    tol: Tolerance,
) -> CurvedPatch | None:
    """The curved contact of two surfaces of parts ``names``, or ``None``: equal coaxial
    cylinders or cones, or equal concentric spheres, one convex and one concave, whose
    axial extents overlap by more than the length tolerance (Liu 1997 §2: a shaft fits
    a hole, a ball a socket) and that share more than a line. ``triangles``: each
    surface's triangles (t x 3 x 3, world), which tell the part of the surface of
    revolution both cover (:mod:`assemblykit.geometry.curved`; Wilson & Latombe 1992 builds the
    blocking constraints from the normals of that part only)."""
    if first.kind != second.kind or first.convex == second.convex:
        return None
    inner = names[0] if first.convex else names[1]
    if first.kind == "sphere":
        same_centre = np.linalg.norm(first.point - second.point) <= tol.length
        if not (same_centre and abs(first.radius - second.radius) <= tol.length):
            return None
        region = sphere_region(triangles, first.point, tol)
        if len(region) == 0:
            return None
        normals = cone_generators(region - first.point, tol)
        return CurvedPatch(
            "spherical", first.point, None, first.radius, inner, points=region, normals=normals
        )
    if first.kind not in ("cylinder", "cone"):
        return None
    axis = first.axis
    assert axis is not None and second.axis is not None
    aligned = float(axis @ second.axis)
    # a direction fitted on a mesh is as sure as the tolerance over the surface's size:
    # the smaller surface, turned onto the other's axis, moves by at most the tolerance
    reach = direction_reach(tol, min(surface_size(first), surface_size(second)))
    if np.linalg.norm(np.cross(axis, second.axis)) > reach:
        return None
    offset = second.point - first.point
    if first.kind == "cone" and (
        aligned < 0
        or np.linalg.norm(offset) > tol.length
        or abs(first.half_angle - second.half_angle) > reach
    ):
        return None
    if first.kind == "cylinder" and abs(first.radius - second.radius) > tol.length:
        return None
    lo, hi = _axial_overlap(first, second, axis, first.point)
    if hi - lo <= tol.length:
        return None
    # the second axis stays within the tolerance of the first along their common part
    along = (np.array([lo, hi]) - offset @ axis) / aligned
    ends = offset + np.outer(along, second.axis)
    if np.max(np.linalg.norm(ends - np.outer(ends @ axis, axis), axis=1)) > tol.length:
        return None
    every = np.vstack([t.reshape(-1, 3) for t in triangles])
    rel = every - first.point
    widest = float(np.max(np.linalg.norm(rel - np.outer(rel @ axis, axis), axis=1)))
    # the azimuth a length tolerance subtends on the widest circle of the surfaces
    gap = tol.length / widest
    arcs = intersect_arcs(
        covered_arcs(triangles[0], first.point, axis, gap),
        covered_arcs(triangles[1], first.point, axis, gap),
        gap,
    )
    if len(arcs) == 0:
        return None
    kind: CurvedKind = "cylindrical" if first.kind == "cylinder" else "conical"
    if kind == "cylindrical":
        normals = revolution_normals(axis, arc_angles(generating_arc(arcs, gap), ARC_STEP))
    else:
        angles = arc_angles(arcs, TURN / CONE_AZIMUTHS)
        normals = revolution_normals(axis, angles, first.half_angle)
    centre = first.point + lo * axis if kind == "cylindrical" else first.point
    extent = (0.0, hi - lo) if kind == "cylindrical" else (lo, hi)
    return CurvedPatch(
        kind,
        centre,
        axis,
        (first.radius + second.radius) / 2,
        inner,
        extent=extent,
        half_angle=first.half_angle,
        points=_boundary(every, axis, first.point, lo, hi, tol),
        normals=normals,
    )


def direction_reach(tol: Tolerance, size: float) -> float:
    """The largest angle between two directions of a surface of diameter ``size`` that the
    tolerance cannot tell apart: turning it by ``tol.length / size`` moves none of its
    points further than the length tolerance (never below the angle tolerance)."""
    return max(tol.angle, tol.length / max(size, tol.length))


def surface_size(surface: Surface) -> float:
    """The diameter of a curved surface: the diagonal of its axial extent and diameter."""
    return math.hypot(surface.extent[1] - surface.extent[0], 2.0 * surface.radius)
