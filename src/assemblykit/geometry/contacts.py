"""Contacts between the parts of an assembly: how they are found, and kept with it.

The functions below find them (:func:`find_contacts`): after the broad phase
(:mod:`~assemblykit.geometry.broad_phase`: the pairs of parts whose bounding boxes meet,
inflated by the length tolerance), vectorised over all candidate pairs at once, the
coplanar groups of facets (:func:`~assemblykit.geometry.recognition.segment`) of one
part are matched with the groups of the other that lie in the same plane with the
opposite normal, and their overlap is measured by shapely in that plane. Curved contacts
are coaxial cylinders and cones and concentric spheres of equal size, one convex and one
concave, read from the parts' exact surfaces, or recognised on each part's triangles
within reach of the other's box (:func:`near_curved_surfaces`: per pair, so a pair's
contacts depend on its two parts alone); each keeps only the part of the surface of
revolution both parts cover, as the normals there (:mod:`assemblykit.geometry.curved`).
A coplanar group with a face on such a surface is a facet of it, not a planar face, and
makes no planar patch.

What is found is kept with the assembly: :func:`assembly_contacts` (contacts per
tolerance) and :func:`assembly_surfaces` (surfaces per part and tolerance) fill a
:class:`GeometryMemo`, an explicit object held in the assembly's ``memo`` slot rather than
a module global keyed by assembly. The model owns the slot and knows only its protocol
(``model.assembly.Derived``); this layer fills it. So the memo lives and dies with the
assembly, two assemblies never share one, and a sub-assembly keeps what concerns its own
parts (:meth:`GeometryMemo.restricted`, called by ``Assembly.subset`` and ``with_part``):
taking parts away costs nothing, and adding one costs only that part's contacts.

The contacts found are the values of :mod:`~assemblykit.geometry.contact_values`
(:class:`Contact`, :class:`Contacts`, :class:`PlanarPatch`, :class:`CurvedPatch`), which
this module names too.
"""

from __future__ import annotations

import math
from collections.abc import Sequence, Set
from dataclasses import dataclass, field, replace
from functools import singledispatch
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray

from assemblykit.algebra.se3 import axis_basis
from assemblykit.deprecation import moved
from assemblykit.geometry.broad_phase import (
    PartStack,
    boxes_overlap,
    candidate_pairs,
    facing_groups,
    stack_parts,
)
from assemblykit.geometry.contact_values import (
    Contact,
    Contacts,
    CurvedKind,
    CurvedPatch,
    PlanarPatch,
)
from assemblykit.geometry.curved import (
    ARC_STEP,
    CONE_AZIMUTHS,
    TURN,
    arc_angles,
    axis_frame,
    cone_generators,
    covered_arcs,
    generating_arc,
    intersect_arcs,
    revolution_normals,
    sphere_region,
)
from assemblykit.geometry.recognition import (
    Segmentation,
    recognise_curved,
    recognise_planes,
    segment,
)
from assemblykit.model.assembly import Assembly
from assemblykit.model.surfaces import Surface
from assemblykit.ragged import group_of, group_starts, ranges
from assemblykit.tolerance import Tolerance

__all__ = [
    "OUTLINE_PAIRS",
    "OVERLAP_CHUNK",
    "WHOLE_SHARE",
    "Contact",
    "Contacts",
    "CurvedKind",
    "CurvedPatch",
    "GeometryMemo",
    "PartStack",
    "PlanarPatch",
    "assembly_contacts",
    "assembly_curved_surfaces",
    "assembly_surfaces",
    "candidate_pairs",
    "curved_contact",
    "direction_reach",
    "facing_groups",
    "find_contacts",
    "group_deviation",
    "group_overlaps",
    "memo_of",
    "near_curved_surfaces",
    "snap_classes",
    "snapped",
    "stack_parts",
    "surface_size",
]


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


def _planar_matches(
    stack: PartStack,
    seg: Segmentation,
    group_part: NDArray[np.int64],
    usable: NDArray[np.bool_],
    part_lo: NDArray[np.float64],
    part_hi: NDArray[np.float64],
    pairs: NDArray[np.int64],
    tol: Tolerance,
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Facing group pairs (:func:`facing_groups`) that are flat, have opposite normals
    and are coplanar: all vertices of one of them lie within the length tolerance of
    the other's plane (so the contact region, inside both, is within the tolerance)."""
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


def _planar_patches(
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
    merged = _closed(merged, tol.length)
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


def _closed(shapes: NDArray[Any], width: float) -> NDArray[Any]:
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


def _may_fit(
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


def _surface_triangles(assembly: Assembly, name: str, surface: Surface) -> NDArray[np.float64]:
    mesh = assembly.parts[name].mesh
    faces = np.asarray(mesh.faces, dtype=np.int64)[surface.faces]
    return np.asarray(mesh.vertices, dtype=np.float64)[faces]


def _sorted_member(values: NDArray[np.int64], keys: NDArray[np.int64]) -> NDArray[np.bool_]:
    """Whether each of ``values`` is among the sorted, distinct, non-empty ``keys``
    (``np.isin``, by binary search: the keys are many and already sorted)."""
    at = np.minimum(np.searchsorted(keys, values), len(keys) - 1)
    found: NDArray[np.bool_] = keys[at] == values
    return found


def find_contacts(
    assembly: Assembly, tol: Tolerance | None = None, *, only: str | None = None
) -> list[Contact]:
    """The contacts between the touching parts of ``assembly``, in part order (module
    docstring); with ``only``, just the contacts of that part. ``tol`` is a policy that
    :meth:`Assembly.tolerance` scales to the model. Directions are snapped
    (:func:`snapped`) within the policy alone: a measured joint mismatch says where
    faces may meet, not that their directions are one."""
    policy = assembly.policy_tolerance(tol)
    tol = assembly.tolerance(tol)
    names = list(assembly.parts)
    if len(names) < 2:
        return []
    stack = stack_parts(p.mesh for p in assembly)
    seg = segment(stack.vertices, stack.faces, tol)
    part_lo = np.array([p.mesh.bounds[0] for p in assembly.parts.values()])
    part_hi = np.array([p.mesh.bounds[1] for p in assembly.parts.values()])
    pairs = candidate_pairs(
        np.stack([part_lo, part_hi], axis=1),
        tol.length,
        None if only is None else names.index(only),
    )
    curved_part = np.zeros(len(names), dtype=bool)
    curved_part[stack.part[np.isin(seg.region, np.flatnonzero(seg.curved))]] = True
    # per ordered pair (k, other): the curved surfaces of part k where it may touch other
    surfaces: dict[tuple[int, int], tuple[Surface, ...]] = {}
    for a, b in pairs.tolist():
        for k, other in ((a, b), (b, a)):
            if assembly.parts[names[k]].surfaces or curved_part[k]:
                surfaces[k, other] = near_curved_surfaces(assembly, names[k], names[other], tol)

    group_part = stack.part[seg.order[seg.start[:-1]]]
    g, h = _planar_matches(stack, seg, group_part, seg.flat, part_lo, part_hi, pairs, tol)
    # a coplanar group with a face on a curved surface of its part (where that part may
    # touch the other) is a facet of that surface, not a planar face
    groups_on: dict[Surface, NDArray[np.int64]] = {}
    for (k, _), near in surfaces.items():
        for s in near:
            if s not in groups_on:
                groups_on[s] = np.unique(seg.group[stack.face_start[k] + s.faces])
    on_curved = [
        (k * len(names) + other) * len(seg.flat) + groups_on[s]
        for (k, other), near in surfaces.items()
        for s in near
    ]
    if on_curved:
        keys = np.unique(np.concatenate(on_curved))
        pg, ph = group_part[g], group_part[h]
        facet = _sorted_member((pg * len(names) + ph) * len(seg.flat) + g, keys) | _sorted_member(
            (ph * len(names) + pg) * len(seg.flat) + h, keys
        )
        g, h = g[~facet], h[~facet]
    k, patches = _planar_patches(stack, seg, g, h, tol)
    planar: dict[tuple[int, int], list[PlanarPatch]] = {}
    for m, flat in zip(k, patches, strict=True):
        planar.setdefault((int(group_part[g[m]]), int(group_part[h[m]])), []).append(flat)

    triangles: dict[tuple[int, int, int], NDArray[np.float64]] = {}

    def triangles_of(k: int, other: int, index: int) -> NDArray[np.float64]:
        if (k, other, index) not in triangles:
            triangles[k, other, index] = _surface_triangles(
                assembly, names[k], surfaces[k, other][index]
            )
        return triangles[k, other, index]

    curved: dict[tuple[int, int], list[CurvedPatch]] = {}
    for a, b in pairs.tolist():
        first, second = surfaces.get((a, b), ()), surfaces.get((b, a), ())
        for i, j in _may_fit(first, second, tol):
            both = (triangles_of(a, b, i), triangles_of(b, a, j))
            patch = curved_contact(first[i], second[j], (names[a], names[b]), both, tol)
            if patch is not None:
                curved.setdefault((a, b), []).append(patch)

    found = [
        Contact(names[a], names[b], tuple(planar.get(key, ())), tuple(curved.get(key, ())))
        for key in sorted(set(planar) | set(curved))
        for a, b in [key]
        if planar.get(key) or curved.get(key)
    ]
    return snapped(found, policy)


@dataclass(eq=False)
class GeometryMemo:
    """What the geometry of an assembly's parts gave, kept in its ``memo`` slot (module
    docstring): ``contacts`` per tolerance, with the names of the parts they cover,
    ``surfaces`` per part name and tolerance, the ``curved`` ones among them (recognised
    first, without the planes), and the curved surfaces ``near`` per part, other part
    and tolerance (those contacts ask for: :func:`near_curved_surfaces`)."""

    contacts: dict[Tolerance, tuple[frozenset[str], Contacts]] = field(default_factory=dict)
    surfaces: dict[tuple[str, Tolerance], tuple[Surface, ...]] = field(default_factory=dict)
    curved: dict[tuple[str, Tolerance], tuple[Surface, ...]] = field(default_factory=dict)
    near: dict[tuple[str, str, Tolerance], tuple[Surface, ...]] = field(default_factory=dict)

    def restricted(self, names: Set[str]) -> GeometryMemo:
        """What still holds for the parts ``names`` alone: the contacts among them and
        their surfaces."""
        return GeometryMemo(
            {
                key: (covered & names, Contacts(c for c in found if c.a in names and c.b in names))
                for key, (covered, found) in self.contacts.items()
            },
            {key: found for key, found in self.surfaces.items() if key[0] in names},
            {key: found for key, found in self.curved.items() if key[0] in names},
            {key: found for key, found in self.near.items() if {key[0], key[1]} <= names},
        )


def memo_of(assembly: Assembly) -> GeometryMemo:
    """The :class:`GeometryMemo` in ``assembly.memo``, an empty one on first use."""
    if not isinstance(assembly.memo, GeometryMemo):
        assembly.memo = GeometryMemo()
    return assembly.memo


def assembly_surfaces(
    assembly: Assembly, name: str, tol: Tolerance | None = None
) -> tuple[Surface, ...]:
    """The surfaces of part ``name``: its exact CAD surfaces, else those recognised on
    its mesh (:func:`~assemblykit.geometry.recognition.recognise`: the curved ones of
    :func:`assembly_curved_surfaces`, then the planes), once per tolerance."""
    part = assembly.part(name)
    if part.surfaces:
        return part.surfaces
    key = (name, assembly.tolerance(tol))
    memo = memo_of(assembly).surfaces
    if key not in memo:
        curved = assembly_curved_surfaces(assembly, name, tol)
        memo[key] = curved + recognise_planes(part.mesh, curved, key[1])
    return memo[key]


def assembly_curved_surfaces(
    assembly: Assembly, name: str, tol: Tolerance | None = None
) -> tuple[Surface, ...]:
    """The surfaces of part ``name`` other than planes: of its exact CAD surfaces, else
    those recognised on its mesh
    (:func:`~assemblykit.geometry.recognition.recognise_curved`), once per tolerance."""
    part = assembly.part(name)
    if part.surfaces:
        return tuple(s for s in part.surfaces if s.kind != "plane")
    key = (name, assembly.tolerance(tol))
    memo = memo_of(assembly).curved
    if key not in memo:
        memo[key] = recognise_curved(part.mesh, key[1])
    return memo[key]


WHOLE_SHARE = 0.25
"""The share of a part's triangles within reach of another part beyond which the curved
surfaces of the whole part serve that pair (:func:`near_curved_surfaces`): recognised
once, and kept for all its pairs and its features, they cost less than regions that
large recognised again pair by pair (a housing touching a dozen parts)."""


def near_curved_surfaces(
    assembly: Assembly, name: str, other: str, tol: Tolerance | None = None
) -> tuple[Surface, ...]:
    """The curved surfaces of part ``name`` where it may touch part ``other``: all of its
    exact CAD surfaces other than planes, else those recognised
    (:func:`~assemblykit.geometry.recognition.recognise_curved`) on its triangles whose
    bounding boxes meet ``other``'s, inflated by the length tolerance (every triangle
    within the tolerance of ``other`` is among them), once per pair and tolerance; when
    these are more than :data:`WHOLE_SHARE` of its triangles, those of the whole part
    (:func:`assembly_curved_surfaces`, kept for every pair and for its features).

    So a pair's contacts depend on its two parts alone, and recognition costs what the
    region where they meet holds rather than the whole part: on the ASAP beam, a
    beam's end on its post is 24% of its triangles, a post's top on the beam 6%."""
    part = assembly.part(name)
    if part.surfaces:
        return assembly_curved_surfaces(assembly, name, tol)
    key = (name, other, assembly.tolerance(tol))
    memo = memo_of(assembly).near
    if key not in memo:
        lo, hi = assembly.part(other).mesh.bounds
        first, second, third = np.asarray(part.mesh.triangles, dtype=np.float64).transpose(1, 0, 2)
        low = np.minimum(np.minimum(first, second), third)
        high = np.maximum(np.maximum(first, second), third)
        reach = np.flatnonzero(boxes_overlap(low, high, lo, hi, key[2].length))
        memo[key] = (
            assembly_curved_surfaces(assembly, name, tol)
            if len(reach) > WHOLE_SHARE * len(first)
            else recognise_curved(part.mesh, key[2], reach)
        )
    return memo[key]


@singledispatch
def assembly_contacts(assembly: object, tol: Tolerance | None = None) -> list[Contact]:
    """The contacts between the touching parts of ``assembly``, dispatched on its type:
    an :class:`~assemblykit.model.assembly.Assembly` (:func:`_mesh_contacts`) or another
    kind that registers its own (the planar polygons of ``assemblykit.blocking.polygons``)."""
    raise TypeError(f"no contacts for a {type(assembly).__name__}")


@assembly_contacts.register
def _mesh_contacts(assembly: Assembly, tol: Tolerance | None = None) -> Contacts:
    """The contacts between touching parts, computed once per tolerance
    (:func:`find_contacts`); for parts the memo does not cover yet (one added by
    ``Assembly.with_part``) only their own contacts are found and added."""
    key = assembly.tolerance(tol)
    memo = memo_of(assembly).contacts
    covered, found = memo.get(key, (frozenset(), Contacts()))
    missing = [name for name in assembly.parts if name not in covered]
    if missing:
        if not covered:
            found = Contacts(find_contacts(assembly, tol))
        else:
            found, added = Contacts(found), set[str]()
            for name in missing:
                found += [
                    c
                    for c in find_contacts(assembly, key, only=name)
                    if c.a not in added and c.b not in added
                ]
                added.add(name)
        memo[key] = (frozenset(assembly.parts), found)
    return found


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
    tolerance joined where they touch or overlap (:func:`_closed`): the pieces of one
    face that vertex noise split into several coplanar groups."""
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
    union = _closed(np.array([shapely.union_all(flat)], dtype=object), tol.length)[0]
    pieces = shapely.get_parts(shapely.orient_polygons(union))
    found = []
    for piece in pieces[~shapely.is_empty(pieces)]:
        ring = shapely.get_coordinates(piece.exterior)[:-1]
        polygon = ring[:, :1] * u + ring[:, 1:] * v + height * normal
        found.append(
            PlanarPatch(normal.copy(), polygon, float(piece.area), max(p.scatter for p in patches))
        )
    return found


__getattr__ = moved(__name__, {"triangle_overlaps": "assemblykit.geometry.contacts:group_overlaps"})
