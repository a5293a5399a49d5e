"""Surface features of a part: planar faces, cylinders, cones and spheres (Liu 1997 §2,
oriented primitive features), recognised on triangle meshes or read exactly from CAD.

Method on meshes (all thresholds from the tolerance policy):

1. **Coplanar groups.** Two adjacent triangles are coplanar when the unshared vertex
   of one lies within the length tolerance of the plane of the other, the one with the
   larger smallest altitude, and their normals point the same way (or one is thinner
   than the tolerance); groups are the connected components of that relation. Vertex
   noise ``e`` tilts a triangle's normal by about ``e / altitude``: a long thin
   triangle's plane swings far at its neighbour's vertex, while the neighbour's plane
   is sure, so noisy slivers still merge into their face. A group's plane is the
   least-squares plane of its vertices (it rests on the whole face, not on the tilts of
   its triangles), and the group is *flat* when all its vertices lie within the length
   tolerance of it. A group that is not flat (a sliver thinner than the tolerance lies
   in both faces of an edge and joins them) falls back to the *strict* groups, where
   each unshared vertex must lie within the tolerance of the other triangle's plane.
   Curved surfaces are recognised on the strict groups (the strips of a finely
   tessellated surface stay apart), planes on the others.
2. **Smooth regions.** Adjacent triangles whose normals differ by at most
   ``smooth_angle`` (30° by default: tessellators keep the angular deflection of curved
   faces below this, and mechanical edges are sharper) are joined; a region containing
   a smooth edge that is not coplanar is a candidate curved surface.
3. **Fits** on each candidate region, accepted when every vertex lies within the length
   tolerance of the fitted surface:

   * cylinder: faceted normals are perpendicular to the axis, so the axis is the
     eigenvector of the smallest eigenvalue of ``Σ w n nᵀ``; centre and radius by the
     linear least-squares circle fit ``x² + y² = 2 c·(x, y) + k`` of the vertices
     projected on the plane normal to the axis;
   * cone: normals make a constant angle with the axis, so they lie on a plane whose
     normal (smallest eigenvector of their centred covariance) is the axis; apex and
     half-angle by least squares of radial distance against height
     (``scipy.optimize.least_squares``);
   * sphere: linear least squares ``|p|² = 2 c·p + k``.

   A surface is convex (shaft, ball, male cone) when the outward normals point away
   from the axis or centre, concave (hole, socket, female cone) otherwise.
4. **Split** smooth regions that fit no surface as a whole (rounded edges join every
   face of a part, as on the ASAP beam): their smooth edges that are not coplanar turn
   the normal about an axis ``n₀ × n₁``; edges with one axis (within ``AXIS_ANGLE``)
   that share coplanar groups form one candidate cylinder, through the edges' vertices (the
   tessellation's rulings lie on it). Each candidate claims the adjacent triangles whose
   vertices all lie on it and is fitted again by step 3; larger ones first, a triangle
   goes to one surface at most. The rest, joined by the remaining smooth edges, is
   fitted with a sphere (the rounded corners). Pieces of one sphere or one cylinder are
   fitted again as one surface. The candidate circles and the spheres of the pieces are
   tested all at once, by the normal equations of the least squares on vertices centred
   per piece; the surfaces that remain are fitted by step 3.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, NamedTuple

import numpy as np
import trimesh
from numpy.typing import NDArray
from scipy.optimize import least_squares

from assemblykit.algebra.se3 import axis_basis, line_classes
from assemblykit.graphs import component_labels
from assemblykit.model.surfaces import Surface, SurfaceKind
from assemblykit.ragged import group_of, group_starts, ranges
from assemblykit.tolerance import Tolerance, current

SMOOTH_ANGLE = np.radians(30.0)
MIN_CURVED_FACES = 3
STRIP_WIDTHS = 2.0
"""A group joined to a rounded edge counts as one of its strips when it is at most this
many times as wide across the axis as the median group of its set (step 4)."""
CIRCLE_EDGES = 3
"""Smooth edges of one axis (rulings of a cylinder) that determine its circle (step 4)."""
AXIS_ANGLE = np.radians(1.0)
"""Edge axes within this angle count as one axis when a smooth region is split (step 4):
the edges of one tessellated cylinder turn about parallel axes, up to the noise of the
normals of small triangles."""


@dataclass(frozen=True, eq=False)
class Segmentation:
    """Coplanar groups and smooth regions of a triangle mesh (method steps 1 and 2).

    Per face: ``group`` and ``region`` labels, unit ``normals`` and ``areas``. Per group:
    area-weighted ``normal`` and ``point``, ``area``, bounds ``lo``/``hi`` and ``flat``.
    ``order``/``start``: faces sorted by group, group ``g`` owning
    ``order[start[g]:start[g + 1]]``. ``curved``: per region, whether it is a candidate
    curved surface.
    """

    group: NDArray[np.int64]
    region: NDArray[np.int64]
    normals: NDArray[np.float64]
    areas: NDArray[np.float64]
    normal: NDArray[np.float64]
    point: NDArray[np.float64]
    area: NDArray[np.float64]
    lo: NDArray[np.float64]
    hi: NDArray[np.float64]
    flat: NDArray[np.bool_]
    order: NDArray[np.int64]
    start: NDArray[np.int64]
    curved: NDArray[np.bool_]
    deviation: NDArray[np.float64] | None = None
    """Per group, the largest distance of its vertices from its plane (``None``: not
    measured): how far noise scatters a face about its plane."""

    def faces_of(self, g: int) -> NDArray[np.int64]:
        """The faces of group ``g``."""
        return self.order[self.start[g] : self.start[g + 1]]


def segment(
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    tol: Tolerance,
    smooth_angle: float = SMOOTH_ANGLE,
    *,
    strict: bool = False,
) -> Segmentation:
    """Coplanar groups and smooth regions of the mesh ``(vertices, faces)`` (steps 1-2).
    ``strict``: each unshared vertex must lie within the tolerance of the other
    triangle's plane, however thin that one is (the strips of a finely tessellated
    curved surface stay apart; curved surfaces are recognised on these groups).

    Works on several parts stacked into one array: parts sharing no vertex index never
    share a group or region."""
    corners = vertices[faces]
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    double_area = np.linalg.norm(cross, axis=1)
    normals = cross / np.where(double_area > 0, double_area, 1.0)[:, None]
    areas = double_area / 2
    adjacency, edges = trimesh.graph.face_adjacency(faces=faces, return_edges=True)
    adjacency = np.asarray(adjacency, dtype=np.int64).reshape(-1, 2)
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    f0, f1 = adjacency[:, 0], adjacency[:, 1]
    unshared0 = faces[f0].sum(axis=1) - edges.sum(axis=1)
    unshared1 = faces[f1].sum(axis=1) - edges.sum(axis=1)
    # each triangle's smallest altitude: vertex noise tilts its normal by about
    # noise / altitude, so of two neighbours the one with the larger altitude has the
    # surer plane, and the other's unshared vertex is measured against it (unless strict)
    longest = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2).max(axis=1)
    altitude = double_area / np.where(longest > 0, longest, 1.0)
    on_edge = vertices[edges[:, 0]]
    dist1 = np.abs(np.einsum("ij,ij->i", normals[f0], vertices[unshared1] - on_edge))
    dist0 = np.abs(np.einsum("ij,ij->i", normals[f1], vertices[unshared0] - on_edge))
    surer = np.where(altitude[f0] >= altitude[f1], dist1, dist0)
    cosine = np.einsum("ij,ij->i", normals[f0], normals[f1])
    # a triangle thinner than the tolerance has no direction of its own
    thin = np.minimum(altitude[f0], altitude[f1]) <= tol.length
    both = (np.maximum(dist0, dist1) <= tol.length) & (cosine > 0)
    coplanar = both if strict else (surer <= tol.length) & ((cosine > 0) | thin)
    smooth = coplanar | (cosine >= np.cos(smooth_angle))
    n_faces = len(faces)
    group = component_labels(n_faces, adjacency[coplanar])
    region = component_labels(n_faces, adjacency[smooth])
    n_regions = int(region.max()) + 1 if n_faces else 0
    curved = np.zeros(n_regions, dtype=bool)
    curved[region[f0[smooth & ~coplanar]]] = True
    planes = _group_planes(corners, normals, areas, group)
    if not strict and not (planes.deviation <= tol.length).all():
        # a sliver thinner than the tolerance lies in both faces of an edge and would
        # join them: where a group is not flat, its faces keep their strict groups
        bent = planes.deviation[group] > tol.length
        strict_group = component_labels(n_faces, adjacency[both])
        kept = np.unique(group[~bent])
        group = np.unique(np.where(bent, strict_group + n_faces, group), return_inverse=True)[1]
        planes = _regrouped(planes, kept, corners, normals, areas, group.astype(np.int64), bent)
    return Segmentation(
        group=group,
        region=region,
        normals=normals,
        areas=areas,
        normal=planes.normal,
        point=planes.point,
        area=planes.area,
        lo=planes.lo,
        hi=planes.hi,
        flat=planes.deviation <= tol.length,
        order=planes.order,
        start=planes.start,
        curved=curved,
        deviation=planes.deviation,
    )


class GroupPlanes(NamedTuple):
    """Per group of coplanar triangles: its unit ``normal``, area-weighted ``point``,
    ``area`` and bounds ``lo``, ``hi``; the triangles sorted by group (``order``) with
    each group's ``start`` (and the total after the last); and the ``deviation``, the
    largest distance of its vertices from its plane."""

    normal: NDArray[np.float64]
    point: NDArray[np.float64]
    area: NDArray[np.float64]
    lo: NDArray[np.float64]
    hi: NDArray[np.float64]
    order: NDArray[np.int64]
    start: NDArray[np.int64]
    deviation: NDArray[np.float64]


def _group_planes(
    corners: NDArray[np.float64],
    normals: NDArray[np.float64],
    areas: NDArray[np.float64],
    group: NDArray[np.int64],
) -> GroupPlanes:
    """Per group of triangles (``corners``, unit ``normals``, ``areas``): its normal,
    area-weighted point, area, bounds, the faces sorted by group with each group's start,
    and the largest distance of its vertices from its plane (flat when within the length
    tolerance, method step 1)."""
    n_groups = int(group.max()) + 1 if len(group) else 0
    weighted = _group_sums(group, normals * areas[:, None], n_groups)
    area = np.asarray(np.bincount(group, weights=areas, minlength=n_groups), dtype=np.float64)
    first, second, third = corners.transpose(1, 0, 2)
    moment = _group_sums(group, (first + second + third) / 3 * areas[:, None], n_groups)
    point = moment / np.where(area > 0, area, 1.0)[:, None]
    normal = _group_normals(corners - point[group][:, None], group, areas, weighted)
    order = np.argsort(group, kind="stable")
    start = np.searchsorted(group[order], np.arange(n_groups + 1))
    heads = start[:-1]
    low = np.minimum(np.minimum(first, second), third)[order]
    high = np.maximum(np.maximum(first, second), third)[order]
    lo = np.minimum.reduceat(low, heads) if n_groups else np.zeros((0, 3))
    hi = np.maximum.reduceat(high, heads) if n_groups else np.zeros((0, 3))
    offsets = np.abs(np.einsum("fkj,fj->fk", corners - point[group][:, None], normal[group]))
    deviation = np.asarray(
        np.maximum.reduceat(offsets.max(axis=1)[order], heads) if n_groups else area,
        dtype=np.float64,
    )
    return GroupPlanes(normal, point, area, lo, hi, order, start, deviation)


def _regrouped(
    planes: GroupPlanes,
    kept: NDArray[np.int64],
    corners: NDArray[np.float64],
    normals: NDArray[np.float64],
    areas: NDArray[np.float64],
    group: NDArray[np.int64],
    bent: NDArray[np.bool_],
) -> GroupPlanes:
    """:func:`_group_planes` of the triangles regrouped as ``group``: the groups ``kept``
    of ``planes`` (numbered first, in their order) are the same, and only the ``bent``
    triangles' new groups are measured (each group's sums run over its own triangles in
    row order, so the values are those of measuring every group again)."""
    new = _group_planes(corners[bent], normals[bent], areas[bent], group[bent] - len(kept))
    per_group = [np.concatenate([old[kept], fresh]) for old, fresh in zip(planes, new, strict=True)]
    normal, point, area, lo, hi, _, _, deviation = per_group
    order = np.argsort(group, kind="stable")
    start = np.searchsorted(group[order], np.arange(len(area) + 1))
    return GroupPlanes(normal, point, area, lo, hi, order, start, deviation)


def _group_sums(
    group: NDArray[np.int64], values: NDArray[np.float64], n_groups: int
) -> NDArray[np.float64]:
    """Per group, the sum of the rows of ``values`` (n x k) of its members, added in
    row order."""
    sums = np.empty((n_groups, values.shape[1]))
    for k, column in enumerate(values.T):
        sums[:, k] = np.bincount(group, weights=column, minlength=n_groups)
    return sums


def plane_deviation(points: NDArray[np.float64]) -> float:
    """The largest distance of ``points`` (k x 3) from their least-squares plane."""
    centred = points - points.mean(axis=0)
    normal = np.linalg.eigh(centred.T @ centred)[1][:, 0]
    return float(np.abs(centred @ normal).max())


def _group_normals(
    centred: NDArray[np.float64],
    group: NDArray[np.int64],
    areas: NDArray[np.float64],
    weighted: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Per group, the unit normal of the least-squares plane of its triangles' corners
    (``centred`` on the group's point, weighted by their triangle's area), turned along
    the area-weighted triangle normal ``weighted``: it rests on the whole extent of the
    face, not on the tilts of its triangles. Groups of zero area keep ``weighted``."""
    products = np.einsum("fki,fkj,f->fij", centred, centred, areas).reshape(-1, 9)
    scatter = _group_sums(group, products, len(weighted)).reshape(-1, 3, 3)
    _, vectors = np.linalg.eigh(scatter)
    normal = (
        vectors[:, :, 0]
        * np.where(np.einsum("ij,ij->i", vectors[:, :, 0], weighted) < 0, -1.0, 1.0)[:, None]
    )
    empty = np.bincount(group, weights=areas, minlength=len(weighted)) == 0
    return np.where(empty[:, None], weighted, normal)


def _circle_fit(xy: NDArray[np.float64]) -> tuple[NDArray[np.float64], float]:
    """Centre and radius of the least-squares circle ``x² + y² = 2 c·(x, y) + k``."""
    system = np.column_stack([2 * xy, np.ones(len(xy))])
    solution = np.linalg.lstsq(system, (xy**2).sum(axis=1), rcond=None)[0]
    centre = solution[:2]
    return centre, float(np.sqrt(max(solution[2] + centre @ centre, 0.0)))


def _fit_cylinder(
    points: NDArray[np.float64],
    normals: NDArray[np.float64],
    weights: NDArray[np.float64],
    tol: Tolerance,
) -> dict[str, Any] | None:
    scatter = (normals * weights[:, None]).T @ normals / weights.sum()
    values, vectors = np.linalg.eigh(scatter)
    if values[0] > tol.angle:
        return None
    axis = vectors[:, 0]
    plane = np.array(axis_basis(axis))
    centre2, radius = _circle_fit(points @ plane.T)
    residual = np.abs(np.linalg.norm(points @ plane.T - centre2, axis=1) - radius)
    if residual.max() > tol.length:
        return None
    heights = points @ axis
    foot = centre2 @ plane + heights.min() * axis
    return {
        "kind": "cylinder",
        "point": foot,
        "axis": axis,
        "radius": radius,
        "extent": (0.0, float(np.ptp(heights))),
    }


def _fit_cone(
    points: NDArray[np.float64],
    normals: NDArray[np.float64],
    weights: NDArray[np.float64],
    tol: Tolerance,
) -> dict[str, Any] | None:
    centred = normals - np.average(normals, axis=0, weights=weights)
    values, vectors = np.linalg.eigh((centred * weights[:, None]).T @ centred / weights.sum())
    if values[0] > tol.angle:
        return None
    axis = vectors[:, 0]
    plane = np.array(axis_basis(axis))
    xy, heights = points @ plane.T, points @ axis
    centre2, mean_radius = _circle_fit(xy)

    def misfit(p: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.linalg.norm(xy - p[:2], axis=1) - (p[2] + p[3] * heights)

    slope0 = float(np.polyfit(heights, np.linalg.norm(xy - centre2, axis=1), 1)[0])
    fit = least_squares(misfit, [*centre2, mean_radius - slope0 * heights.mean(), slope0])
    if np.abs(misfit(fit.x)).max() > tol.length or abs(fit.x[3]) <= tol.angle:
        return None
    cx, cy, r0, slope = fit.x
    apex = np.array([cx, cy]) @ plane + (-r0 / slope) * axis
    axis = axis * np.sign(slope)  # from the apex towards the opening
    along = (points - apex) @ axis
    return {
        "kind": "cone",
        "point": apex,
        "axis": axis,
        "half_angle": float(np.arctan(abs(slope))),
        "extent": (float(along.min()), float(along.max())),
    }


def _fit_sphere(
    points: NDArray[np.float64],
    normals: NDArray[np.float64],
    weights: NDArray[np.float64],
    tol: Tolerance,
) -> dict[str, Any] | None:
    system = np.column_stack([2 * points, np.ones(len(points))])
    solution = np.linalg.lstsq(system, (points**2).sum(axis=1), rcond=None)[0]
    centre = solution[:3]
    radius = float(np.sqrt(max(solution[3] + centre @ centre, 0.0)))
    if np.abs(np.linalg.norm(points - centre, axis=1) - radius).max() > tol.length:
        return None
    return {"kind": "sphere", "point": centre, "axis": None, "radius": radius}


def fit_surface(
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    normals: NDArray[np.float64],
    areas: NDArray[np.float64],
    tol: Tolerance,
    ids: NDArray[np.int64],
    kinds: tuple[SurfaceKind, ...] = ("cylinder", "cone", "sphere"),
) -> Surface | None:
    """The first of ``kinds`` (cylinder, cone, sphere) through the triangles ``faces``
    (numbered ``ids`` in their mesh) by method step 3, or ``None`` when none fits within
    the tolerance."""
    found = _fit_params(vertices, faces, normals, areas, tol, kinds)
    return None if found is None else _surface(vertices, faces, areas, ids, found)


def _fit_params(
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    normals: NDArray[np.float64],
    areas: NDArray[np.float64],
    tol: Tolerance,
    kinds: tuple[SurfaceKind, ...],
) -> dict[str, Any] | None:
    """The parameters of :func:`fit_surface` (kind, point, axis, radius, ...), before its
    convexity is measured."""
    used = np.unique(faces)
    points = vertices[used]
    # points within the tolerance of one plane are a plane, whatever else fits them
    if len(points) < 4 or plane_deviation(points) <= tol.length:
        return None
    for fit in (FITS[kind] for kind in kinds):
        found = fit(points, normals, areas, tol)
        if found is not None:
            return found
    return None


def _surface(
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    areas: NDArray[np.float64],
    ids: NDArray[np.int64],
    found: dict[str, Any],
) -> Surface:
    """The surface of the fitted parameters ``found`` through the triangles ``faces``
    (numbered ``ids`` in their mesh, of ``areas``), convex or not by :func:`is_convex`."""
    convex = is_convex(vertices, faces, found["point"], found["axis"])
    return Surface(faces=ids, area=float(areas.sum()), convex=convex, **found)


FITS = {"cylinder": _fit_cylinder, "cone": _fit_cone, "sphere": _fit_sphere}


def _fit_faces(
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    seg: Segmentation,
    tol: Tolerance,
    ids: NDArray[np.int64],
    kinds: tuple[SurfaceKind, ...] = ("cylinder", "cone", "sphere"),
) -> Surface | None:
    """:func:`fit_surface` on the triangles ``ids`` of a segmented mesh."""
    return fit_surface(vertices, faces[ids], seg.normals[ids], seg.areas[ids], tol, ids, kinds)


@dataclass(frozen=True, eq=False)
class Piece:
    """The triangles ``ids`` of a segmented mesh (numbered in the mesh) on one surface of
    parameters ``found``: fitted by :func:`_fit_params` when ``exact``, else by
    :func:`_sphere_fits` (close enough to compare pieces, fitted again when kept)."""

    ids: NDArray[np.int64]
    found: dict[str, Any]
    exact: bool = True


def _fit_piece(
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    seg: Segmentation,
    tol: Tolerance,
    ids: NDArray[np.int64],
    kind: SurfaceKind,
) -> Piece | None:
    """The triangles ``ids`` of a segmented mesh with the parameters of the surface of
    ``kind`` through them (:func:`_fit_params`), or ``None`` when it does not fit."""
    found = _fit_params(vertices, faces[ids], seg.normals[ids], seg.areas[ids], tol, (kind,))
    return None if found is None else Piece(ids, found)


def is_convex(
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    point: NDArray[np.float64],
    axis: NDArray[np.float64] | None,
) -> bool:
    """Whether the outward normals of the triangles ``faces`` point, on average (area
    weighted), away from the axis through ``point`` (or from ``point`` if no axis):
    the material is inside, as in a shaft, a ball or a male cone."""
    corners = vertices[faces]
    (a0, a1, a2), (b0, b1, b2) = (
        (corners[:, 1] - corners[:, 0]).T,
        (corners[:, 2] - corners[:, 0]).T,
    )
    # the cross products written out (as np.cross computes them, without its overhead
    # on the few triangles of a piece)
    weighted = np.column_stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])
    radial = corners.mean(axis=1) - point
    if axis is not None:
        radial -= np.outer(radial @ axis, axis)
    return bool(np.einsum("ij,ij->", radial, weighted) > 0)


def recognise(mesh: trimesh.Trimesh, tol: Tolerance | None = None) -> tuple[Surface, ...]:
    """The surfaces of ``mesh``: its cylinders, cones and spheres, then its flat coplanar
    groups outside them as planes (module docstring)."""
    tol = tol or current()
    curved = recognise_curved(mesh, tol)
    return curved + recognise_planes(mesh, curved, tol)


def recognise_curved(
    mesh: trimesh.Trimesh,
    tol: Tolerance,
    within: NDArray[np.int64] | None = None,
) -> tuple[Surface, ...]:
    """The cylinders, cones and spheres of ``mesh`` (method steps 1-4 on the strict
    groups): all that contacts need, the planes being the coplanar groups they match.
    ``within``: the ids of the only triangles to look at (numbered in the mesh, as the
    surfaces' faces are): the surfaces of that region alone."""
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    if within is not None:
        return tuple(
            replace(s, faces=within[s.faces]) for s in _curved(vertices, faces[within], tol)
        )
    return _curved(vertices, faces, tol)


def _curved(
    vertices: NDArray[np.float64], faces: NDArray[np.int64], tol: Tolerance
) -> tuple[Surface, ...]:
    """The curved surfaces of the triangles ``faces`` (:func:`recognise_curved`)."""
    seg = segment(vertices, faces, tol, strict=True)
    candidates = np.flatnonzero(seg.curved)
    curved = curved_surfaces(vertices, faces, seg, tol, candidates)
    fitted = np.isin(candidates, seg.region[[int(c.faces[0]) for c in curved]])
    unfit = np.isin(seg.region, candidates[~fitted])
    if unfit.any():
        curved += split_surfaces(vertices, faces, seg, tol, unfit)
    return curved


def recognise_planes(
    mesh: trimesh.Trimesh, curved: tuple[Surface, ...], tol: Tolerance
) -> tuple[Surface, ...]:
    """The flat coplanar groups of ``mesh`` with no face on its ``curved`` surfaces
    (:func:`recognise_curved`), as planes."""
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    return planes(segment(vertices, faces, tol), faces_on(curved, len(faces)))


def curved_surfaces(
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    seg: Segmentation,
    tol: Tolerance,
    regions: NDArray[np.int64],
) -> tuple[Surface, ...]:
    """The fitted curved surfaces of the candidate ``regions`` of a segmentation."""
    found = []
    for r in regions:
        ids = np.flatnonzero(seg.region == r)
        if len(ids) < MIN_CURVED_FACES:
            continue
        surface = _fit_faces(vertices, faces, seg, tol, ids)
        if surface is not None:
            found.append(surface)
    return tuple(found)


def split_surfaces(
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    seg: Segmentation,
    tol: Tolerance,
    inside: NDArray[np.bool_],
) -> tuple[Surface, ...]:
    """The surfaces of the triangles ``inside`` (smooth regions that fit no surface as
    a whole) found by splitting them (method step 4)."""
    adjacency, edges = trimesh.graph.face_adjacency(faces=faces, return_edges=True)
    adjacency = np.asarray(adjacency, dtype=np.int64).reshape(-1, 2)
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    n0, n1 = seg.normals[adjacency[:, 0]], seg.normals[adjacency[:, 1]]
    bent = (
        inside[adjacency[:, 0]]
        & inside[adjacency[:, 1]]
        & (seg.group[adjacency[:, 0]] != seg.group[adjacency[:, 1]])
        & (np.einsum("ij,ij->i", n0, n1) >= np.cos(SMOOTH_ANGLE))
    )
    axes = np.cross(n0, n1)
    sines = np.linalg.norm(axes, axis=1)
    bent &= sines > tol.angle
    adjacency, edges = adjacency[bent], edges[bent]
    if not len(adjacency):
        return ()  # no edge turns about an axis: nothing curved to split
    axes = axes[bent] / sines[bent, None]
    cluster = line_classes(axes, np.sin(AXIS_ANGLE))[1]
    # coplanar groups (a cylinder's strips) joined by edges of one axis: one node per
    # (group, axis)
    ends = seg.group[np.concatenate([adjacency[:, 0], adjacency[:, 1]])]
    nodes, node = np.unique(
        np.column_stack([ends, np.tile(cluster, 2)]), axis=0, return_inverse=True
    )
    node = node.ravel()
    pairs = np.column_stack([node[: len(adjacency)], node[len(adjacency) :]])
    # a face between two parallel rounded edges would join them: within each set of
    # joined groups, drop the groups much wider across the axis than the typical strip
    label = component_labels(len(nodes), pairs)
    first = np.unique(cluster, return_index=True)[1]
    width = _widths(vertices, faces, seg, nodes[:, 0], axes[first[nodes[:, 1]]])
    typical = _medians(width, label)
    narrow = width <= STRIP_WIDTHS * typical
    kept = narrow[pairs[:, 0]] & narrow[pairs[:, 1]]
    adjacency, edges, axes, pairs = adjacency[kept], edges[kept], axes[kept], pairs[kept]
    label = component_labels(len(nodes), pairs)[pairs[:, 0]]
    claimed = np.zeros(len(faces), dtype=bool)
    found: list[Piece] = []
    candidates = _strip_candidates(vertices, faces, seg, tol, adjacency, edges, axes, label)
    for ids in sorted(candidates, key=lambda ids: -float(seg.areas[ids].sum())):
        if len(ids) < MIN_CURVED_FACES or claimed[ids].any():
            continue
        piece = _fit_piece(vertices, faces, seg, tol, ids, "cylinder")
        if piece is not None:
            found.append(piece)
            claimed[ids] = True
    rest = ~claimed[adjacency[:, 0]] & ~claimed[adjacency[:, 1]]
    label = component_labels(len(faces), adjacency[rest])
    # the unclaimed faces inside, sorted by patch (each patch's in ascending order)
    free = np.flatnonzero(inside & ~claimed)
    free = free[np.argsort(label[free], kind="stable")]
    patches = np.unique(label[adjacency[rest, 0]])
    lo = np.searchsorted(label[free], patches)
    hi = np.searchsorted(label[free], patches, side="right")
    large = hi - lo >= MIN_CURVED_FACES
    lo, hi = lo[large], hi[large]
    centres, radii, fits = _sphere_fits(vertices, faces[free], lo, hi, tol)
    for k in np.flatnonzero(fits).tolist():
        sphere = {"kind": "sphere", "point": centres[k], "axis": None, "radius": radii[k]}
        found.append(Piece(free[lo[k] : hi[k]], sphere, exact=False))
    return _merged(vertices, faces, seg, tol, found)


def _strip_candidates(
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    seg: Segmentation,
    tol: Tolerance,
    adjacency: NDArray[np.int64],
    edges: NDArray[np.int64],
    axes: NDArray[np.float64],
    label: NDArray[np.int64],
) -> list[NDArray[np.int64]]:
    """Per set of smooth edges of one ``label`` (the faces ``adjacency``, their shared
    ``edges`` and unit ``axes``) in label order, the faces of their coplanar groups on
    the cylinder through the edges' vertices, when these lie on one (method step 4).

    The circles of sets of at least three edges (three rulings determine a circle) are
    fitted all at once, by the normal equations of the least squares on the vertices
    centred per set; those of two edges, or whose normal equations are ill-conditioned,
    one by one (:func:`_circle_fit`, by an orthogonal factorisation)."""
    if not len(label):
        return []
    _, first, cls, size = np.unique(
        label, return_index=True, return_inverse=True, return_counts=True
    )
    cls = cls.ravel()
    # each set's axis: the mean of its edges' axes turned along its first one's
    signs = np.sign(np.einsum("ij,ij->i", axes, axes[first[cls]]))[:, None]
    turns = np.stack([np.bincount(cls, weights=w) for w in (axes * signs).T], axis=1)
    axis: NDArray[np.float64] = turns / np.linalg.norm(turns, axis=1)[:, None]
    u, v = axis_basis(axis)
    pc, used = np.divmod(np.unique(cls[:, None] * len(vertices) + edges), len(vertices))
    xy = np.column_stack([np.einsum("ij,ij->i", vertices[used], b[pc]) for b in (u, v)])
    count = np.bincount(pc, minlength=len(size))
    heads = np.concatenate([[0], np.cumsum(count)[:-1]])
    mean = np.add.reduceat(xy, heads) / count[:, None]
    centred = xy - mean[pc]
    system = np.column_stack([2 * centred, np.ones(len(centred))])
    gram = np.add.reduceat(np.einsum("pi,pj->pij", system, system), heads)
    moment = np.add.reduceat(system * (centred**2).sum(axis=1)[:, None], heads)
    # normal equations keep half the digits of a system with this conditioning
    singular = np.linalg.svd(gram, compute_uv=False)
    determined = (size >= CIRCLE_EDGES) & (
        singular[:, -1] > np.sqrt(np.finfo(np.float64).eps) * singular[:, 0]
    )
    gram = np.where(determined[:, None, None], gram, np.eye(3))
    solution = np.linalg.solve(gram, moment[:, :, None])[:, :, 0]
    centre = mean + solution[:, :2]
    radius = np.sqrt(np.maximum(solution[:, 2] + (solution[:, :2] ** 2).sum(axis=1), 0.0))
    alone = ~determined & (size >= MIN_CURVED_FACES - 1)
    for k in np.flatnonzero(alone).tolist():
        centre[k], radius[k] = _circle_fit(xy[pc == k])
    miss = np.abs(np.linalg.norm(xy - centre[pc], axis=1) - radius[pc])
    fits = (determined | alone) & (np.maximum.reduceat(miss, heads) <= tol.length)
    # the faces of the coplanar groups of each fitting set's edges, ascending per set
    sides = np.concatenate([adjacency[:, 0], adjacency[:, 1]])
    keep = np.tile(fits[cls], 2)
    gc, gg = np.divmod(
        np.unique(np.tile(cls, 2)[keep] * len(seg.flat) + seg.group[sides[keep]]), len(seg.flat)
    )
    sizes = seg.start[gg + 1] - seg.start[gg]
    rows = np.arange(sizes.sum()) + np.repeat(seg.start[gg] - np.cumsum(sizes) + sizes, sizes)
    fc, near = np.divmod(np.sort(np.repeat(gc, sizes) * len(faces) + seg.order[rows]), len(faces))
    corners = vertices[faces[near]]
    planar = np.stack([np.einsum("ikj,ij->ik", corners, b[fc]) for b in (u, v)], axis=2)
    off = np.abs(np.linalg.norm(planar - centre[fc][:, None], axis=2) - radius[fc][:, None])
    on = off.max(axis=1) <= tol.length
    found = np.split(near[on], np.searchsorted(fc[on], np.arange(1, len(size))))
    return [found[k] for k in np.flatnonzero(fits).tolist()]


def _sphere_fits(
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    lo: NDArray[np.int64],
    hi: NDArray[np.int64],
    tol: Tolerance,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
    """Centre, radius and whether it fits (method step 3, as :func:`fit_surface`), of the
    sphere through each piece of triangles ``faces[lo[k]:hi[k]]``, all pieces at once:
    the vertices of each are centred on their mean and the plane and sphere fitted by
    the normal equations of the least squares, solved on the stack of pieces."""
    if not len(lo):
        return np.zeros((0, 3)), np.zeros(0), np.zeros(0, dtype=bool)
    sizes = hi - lo
    piece = group_of(3 * sizes)
    rows = ranges(lo, sizes)
    keys = np.unique(piece * len(vertices) + faces[rows].ravel())
    piece, used = np.divmod(keys, len(vertices))
    count = np.bincount(piece, minlength=len(lo))
    heads = np.concatenate([[0], np.cumsum(count)[:-1]])

    def sums(values: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.add.reduceat(values, heads, axis=0)

    mean = sums(vertices[used]) / count[:, None]
    centred = vertices[used] - mean[piece]
    # the plane: the smallest eigenvector of the scatter of the centred vertices
    normal = np.linalg.eigh(sums(np.einsum("pi,pj->pij", centred, centred)))[1][:, :, 0]
    off_plane = np.maximum.reduceat(np.abs(np.einsum("pi,pi->p", centred, normal[piece])), heads)
    solid = (count >= 4) & (off_plane > tol.length)
    # the sphere |q|² = 2 c·q + k: a piece off every plane has regular normal equations
    system = np.column_stack([2 * centred, np.ones(len(centred))])
    gram = np.where(solid[:, None, None], sums(np.einsum("pi,pj->pij", system, system)), np.eye(4))
    moment = sums(system * (centred**2).sum(axis=1)[:, None])
    solution = np.linalg.solve(gram, moment[:, :, None])[:, :, 0]
    centre = solution[:, :3]
    radius = np.sqrt(np.maximum(solution[:, 3] + (centre**2).sum(axis=1), 0.0))
    miss = np.abs(np.linalg.norm(centred - centre[piece], axis=1) - radius[piece])
    return mean + centre, radius, solid & (np.maximum.reduceat(miss, heads) <= tol.length)


def _merged(
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    seg: Segmentation,
    tol: Tolerance,
    pieces: list[Piece],
) -> tuple[Surface, ...]:
    """The surfaces of ``pieces`` with the pieces of one sphere (same centre and radius)
    or one cylinder (same axis line and radius) fitted again as one surface: each joins
    the first earlier one it lies on whose union with it still fits. Only the surfaces
    that remain are measured for convexity, and fitted by :func:`_fit_params` if they
    were not."""
    merged: list[Piece] = []
    kinds = np.empty(len(pieces), dtype=object)
    radii = np.empty(len(pieces))
    points = np.empty((len(pieces), 3))
    axes = np.zeros((len(pieces), 3))

    def keep(k: int, found: dict[str, Any]) -> None:
        kinds[k], radii[k], points[k] = found["kind"], found.get("radius", 0.0), found["point"]
        if found["axis"] is not None:
            axes[k] = found["axis"]

    for piece in pieces:
        n = len(merged)
        same = _same_surfaces(piece.found, kinds[:n], radii[:n], points[:n], axes[:n], tol)
        for k in np.flatnonzero(same).tolist():
            ids = np.concatenate([merged[k].ids, piece.ids])
            union = _fit_piece(vertices, faces, seg, tol, ids, piece.found["kind"])
            if union is not None:
                merged[k] = union
                keep(k, union.found)
                break
        else:
            merged.append(piece)
            keep(n, piece.found)
    exact = [
        m if m.exact else _fit_piece(vertices, faces, seg, tol, m.ids, m.found["kind"])
        for m in merged
    ]
    return tuple(
        _surface(vertices, faces[m.ids], seg.areas[m.ids], m.ids, m.found)
        for m in exact
        if m is not None
    )


def _same_surfaces(
    a: dict[str, Any],
    kinds: NDArray[np.object_],
    radii: NDArray[np.float64],
    points: NDArray[np.float64],
    axes: NDArray[np.float64],
    tol: Tolerance,
) -> NDArray[np.bool_]:
    """Per surface given by its kind, radius, point and axis (rows), whether it and the
    sphere or cylinder of parameters ``a`` (:func:`_fit_params`) lie on one sphere, or
    one cylinder, within the tolerance."""
    if a["kind"] not in ("sphere", "cylinder"):
        return np.zeros(len(kinds), dtype=bool)
    same = (kinds == a["kind"]) & (np.abs(a["radius"] - radii) <= tol.length)
    offset = points - a["point"]
    if a["kind"] == "sphere":
        return same & (np.linalg.norm(offset, axis=1) <= tol.length)
    return (
        same
        & (_cross_norms(a["axis"], axes) <= tol.angle)
        & (_cross_norms(a["axis"], offset) <= tol.length)
    )


def _cross_norms(u: NDArray[np.float64], rows: NDArray[np.float64]) -> NDArray[np.float64]:
    """``|u × r|`` per row ``r`` of ``rows``, the cross products written out (as np.cross
    computes them, without its overhead on a few rows)."""
    (a, b, c), (x, y, z) = u, rows.T
    return np.sqrt((b * z - c * y) ** 2 + (c * x - a * z) ** 2 + (a * y - b * x) ** 2)


def _widths(
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    seg: Segmentation,
    groups: NDArray[np.int64],
    axes: NDArray[np.float64],
) -> NDArray[np.float64]:
    """How wide each coplanar group ``groups[i]`` is across ``axes[i]``, within its plane."""
    across = np.cross(seg.normal[groups], axes)
    sizes = seg.start[groups + 1] - seg.start[groups]
    row = group_of(sizes)
    corners = vertices[faces[seg.order[ranges(seg.start[groups], sizes)]]]
    spread = np.einsum("ijk,ik->ij", corners, across[row]).ravel()
    bounds = 3 * group_starts(sizes)
    return np.maximum.reduceat(spread, bounds) - np.minimum.reduceat(spread, bounds)


def _medians(values: NDArray[np.float64], label: NDArray[np.int64]) -> NDArray[np.float64]:
    """Per entry, the median of ``values`` over the entries of its label."""
    order = np.lexsort((values, label))
    ends = np.flatnonzero(np.diff(label[order])) + 1
    starts = np.concatenate([[0], ends])
    sizes = np.diff(np.concatenate([starts, [len(order)]]))
    middle = 0.5 * (values[order[starts + (sizes - 1) // 2]] + values[order[starts + sizes // 2]])
    return middle[group_of(sizes)][np.argsort(order)]


def faces_on(surfaces: tuple[Surface, ...], n_faces: int) -> NDArray[np.bool_]:
    """Per face of a mesh with ``n_faces`` triangles, whether it lies on one of ``surfaces``."""
    mask = np.zeros(n_faces, dtype=bool)
    for surface in surfaces:
        mask[surface.faces] = True
    return mask


def planes(seg: Segmentation, excluded: NDArray[np.bool_]) -> tuple[Surface, ...]:
    """The flat coplanar groups (planar faces) not on ``excluded`` faces, as planes."""
    found = []
    for g in np.flatnonzero(seg.flat).tolist():
        ids = seg.faces_of(g)
        if excluded[ids].any():
            continue
        found.append(
            Surface(
                kind="plane",
                point=seg.point[g],
                axis=seg.normal[g],
                faces=ids,
                area=float(seg.area[g]),
            )
        )
    return tuple(found)
