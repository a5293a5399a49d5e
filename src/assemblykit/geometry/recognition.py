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
   fitted again as one surface.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import trimesh
from numpy.typing import NDArray
from scipy.optimize import least_squares
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from assemblykit.algebra.se3 import axis_basis, line_classes
from assemblykit.model.surfaces import Surface, SurfaceKind
from assemblykit.tolerance import Tolerance, current

SMOOTH_ANGLE = np.radians(30.0)
MIN_CURVED_FACES = 3
STRIP_WIDTHS = 2.0
"""A group joined to a rounded edge counts as one of its strips when it is at most this
many times as wide across the axis as the median group of its set (step 4)."""
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


def _components(n: int, pairs: NDArray[np.int64]) -> NDArray[np.int64]:
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    return connected_components(graph, directed=False)[1].astype(np.int64)


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
    group = _components(n_faces, adjacency[coplanar])
    region = _components(n_faces, adjacency[smooth])
    n_regions = int(region.max()) + 1 if n_faces else 0
    curved = np.zeros(n_regions, dtype=bool)
    curved[region[f0[smooth & ~coplanar]]] = True
    planes = _group_planes(corners, normals, areas, group)
    if not strict and not (planes[-1] <= tol.length).all():
        # a sliver thinner than the tolerance lies in both faces of an edge and would
        # join them: where a group is not flat, its faces keep their strict groups
        bent = planes[-1][group] > tol.length
        strict_group = _components(n_faces, adjacency[both])
        group = np.unique(np.where(bent, strict_group + n_faces, group), return_inverse=True)[1]
        planes = _group_planes(corners, normals, areas, group.astype(np.int64))
    normal, point, area, lo, hi, order, start, deviation = planes
    flat = deviation <= tol.length
    return Segmentation(
        group,
        region,
        normals,
        areas,
        normal,
        point,
        area,
        lo,
        hi,
        flat,
        order,
        start,
        curved,
        deviation,
    )


def _group_planes(
    corners: NDArray[np.float64],
    normals: NDArray[np.float64],
    areas: NDArray[np.float64],
    group: NDArray[np.int64],
) -> tuple[NDArray[Any], ...]:
    """Per group of triangles (``corners``, unit ``normals``, ``areas``): its normal,
    area-weighted point, area, bounds, the faces sorted by group with each group's start,
    and the largest distance of its vertices from its plane (flat when within the length
    tolerance, method step 1)."""
    n_groups = int(group.max()) + 1 if len(group) else 0
    weighted = np.zeros((n_groups, 3))
    np.add.at(weighted, group, normals * areas[:, None])
    area = np.bincount(group, weights=areas, minlength=n_groups)
    moment = np.zeros((n_groups, 3))
    np.add.at(moment, group, corners.mean(axis=1) * areas[:, None])
    point = moment / np.where(area > 0, area, 1.0)[:, None]
    normal = _group_normals(corners - point[group][:, None], group, areas, weighted)
    order = np.argsort(group, kind="stable")
    start = np.searchsorted(group[order], np.arange(n_groups + 1))
    heads = start[:-1]
    lo = np.minimum.reduceat(corners.min(axis=1)[order], heads) if n_groups else np.zeros((0, 3))
    hi = np.maximum.reduceat(corners.max(axis=1)[order], heads) if n_groups else np.zeros((0, 3))
    offsets = np.abs(np.einsum("fkj,fj->fk", corners - point[group][:, None], normal[group]))
    deviation = np.maximum.reduceat(offsets.max(axis=1)[order], heads) if n_groups else area
    return normal, point, area, lo, hi, order, start, deviation


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
    scatter = np.zeros((len(weighted), 3, 3))
    np.add.at(scatter, group, np.einsum("fki,fkj,f->fij", centred, centred, areas))
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
    used = np.unique(faces)
    points = vertices[used]
    # points within the tolerance of one plane are a plane, whatever else fits them
    if len(points) < 4 or plane_deviation(points) <= tol.length:
        return None
    for fit in (FITS[kind] for kind in kinds):
        found = fit(points, normals, areas, tol)
        if found is not None:
            break
    else:
        return None
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
    curved = recognise_curved(mesh, tol)
    return curved + recognise_planes(mesh, curved, tol)


def recognise_curved(mesh: trimesh.Trimesh, tol: Tolerance | None = None) -> tuple[Surface, ...]:
    """The cylinders, cones and spheres of ``mesh`` (method steps 1-4 on the strict
    groups): all that contacts need, the planes being the coplanar groups they match."""
    tol = tol or current()
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    seg = segment(vertices, faces, tol, strict=True)
    candidates = np.flatnonzero(seg.curved)
    curved = curved_surfaces(vertices, faces, seg, tol, candidates)
    fitted = np.isin(candidates, seg.region[[int(c.faces[0]) for c in curved]])
    unfit = np.isin(seg.region, candidates[~fitted])
    if unfit.any():
        curved += split_surfaces(vertices, faces, seg, tol, unfit)
    return curved


def recognise_planes(
    mesh: trimesh.Trimesh, curved: tuple[Surface, ...], tol: Tolerance | None = None
) -> tuple[Surface, ...]:
    """The flat coplanar groups of ``mesh`` with no face on its ``curved`` surfaces
    (:func:`recognise_curved`), as planes."""
    tol = tol or current()
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
    label = _components(len(nodes), pairs)
    first = np.unique(cluster, return_index=True)[1]
    width = _widths(vertices, faces, seg, nodes[:, 0], axes[first[nodes[:, 1]]])
    typical = _medians(width, label)
    narrow = width <= STRIP_WIDTHS * typical
    kept = narrow[pairs[:, 0]] & narrow[pairs[:, 1]]
    adjacency, edges, axes, pairs = adjacency[kept], edges[kept], axes[kept], pairs[kept]
    label = _components(len(nodes), pairs)[pairs[:, 0]]
    claimed = np.zeros(len(faces), dtype=bool)
    found: list[Surface] = []
    candidates: list[NDArray[np.int64]] = []
    for members in _classes(label):
        if len(members) < MIN_CURVED_FACES - 1:
            continue
        turns = axes[members]
        axis = (turns * np.sign(turns @ turns[0])[:, None]).mean(axis=0)
        axis /= np.linalg.norm(axis)
        points = vertices[np.unique(edges[members])]
        plane = np.array(axis_basis(axis))
        centre, radius = _circle_fit(points @ plane.T)
        if np.abs(np.linalg.norm(points @ plane.T - centre, axis=1) - radius).max() > tol.length:
            continue
        near = np.sort(
            np.concatenate([seg.faces_of(g) for g in np.unique(seg.group[adjacency[members]])])
        )
        corners = vertices[faces[near]] @ plane.T - centre
        on = np.abs(np.linalg.norm(corners, axis=2) - radius).max(axis=1) <= tol.length
        candidates.append(near[on])
    for ids in sorted(candidates, key=lambda ids: -float(seg.areas[ids].sum())):
        if len(ids) < MIN_CURVED_FACES or claimed[ids].any():
            continue
        surface = _fit_faces(vertices, faces, seg, tol, ids, ("cylinder",))
        if surface is not None:
            found.append(surface)
            claimed[ids] = True
    rest = ~claimed[adjacency[:, 0]] & ~claimed[adjacency[:, 1]]
    label = _components(len(faces), adjacency[rest])
    # the unclaimed faces inside, sorted by patch (each patch's in ascending order)
    free = np.flatnonzero(inside & ~claimed)
    free = free[np.argsort(label[free], kind="stable")]
    patches = np.unique(label[adjacency[rest, 0]])
    lo = np.searchsorted(label[free], patches)
    hi = np.searchsorted(label[free], patches, side="right")
    for start, stop in zip(lo.tolist(), hi.tolist(), strict=True):
        ids = free[start:stop]
        if len(ids) < MIN_CURVED_FACES:
            continue
        sphere = _fit_faces(vertices, faces, seg, tol, ids, ("sphere",))
        if sphere is not None:
            found.append(sphere)
    return _merged(vertices, faces, seg, tol, found)


def _merged(
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    seg: Segmentation,
    tol: Tolerance,
    surfaces: list[Surface],
) -> tuple[Surface, ...]:
    """``surfaces`` with the pieces of one sphere (same centre and radius) or one
    cylinder (same axis line and radius) fitted again as one surface: each joins the
    first earlier one it lies on whose union with it still fits."""
    merged: list[Surface] = []
    kinds = np.empty(len(surfaces), dtype=object)
    radii = np.empty(len(surfaces))
    points = np.empty((len(surfaces), 3))
    axes = np.zeros((len(surfaces), 3))

    def keep(k: int, surface: Surface) -> None:
        kinds[k], radii[k], points[k] = surface.kind, surface.radius, surface.point
        if surface.axis is not None:
            axes[k] = surface.axis

    for surface in surfaces:
        n = len(merged)
        same = _same_surfaces(surface, kinds[:n], radii[:n], points[:n], axes[:n], tol)
        for k in np.flatnonzero(same).tolist():
            ids = np.concatenate([merged[k].faces, surface.faces])
            union = _fit_faces(vertices, faces, seg, tol, ids, (surface.kind,))
            if union is not None:
                merged[k] = union
                keep(k, union)
                break
        else:
            merged.append(surface)
            keep(n, surface)
    return tuple(merged)


def _same_surfaces(
    a: Surface,
    kinds: NDArray[np.object_],
    radii: NDArray[np.float64],
    points: NDArray[np.float64],
    axes: NDArray[np.float64],
    tol: Tolerance,
) -> NDArray[np.bool_]:
    """Per surface given by its kind, radius, point and axis (rows), whether it and the
    sphere or cylinder ``a`` lie on one sphere, or one cylinder, within the tolerance."""
    if a.kind not in ("sphere", "cylinder"):
        return np.zeros(len(kinds), dtype=bool)
    same = (kinds == a.kind) & (np.abs(a.radius - radii) <= tol.length)
    offset = points - a.point
    if a.kind == "sphere":
        return same & (np.linalg.norm(offset, axis=1) <= tol.length)
    assert a.axis is not None
    parallel = np.linalg.norm(np.cross(a.axis, axes), axis=1) <= tol.angle
    return same & parallel & (np.linalg.norm(np.cross(offset, a.axis), axis=1) <= tol.length)


def _classes(label: NDArray[np.int64]) -> list[NDArray[np.int64]]:
    """The indices of each label, one array per distinct label."""
    order = np.argsort(label, kind="stable")
    return np.split(order, np.flatnonzero(np.diff(label[order])) + 1)


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
    row = np.repeat(np.arange(len(groups)), sizes)
    offset = np.arange(len(row)) - np.repeat(np.cumsum(sizes) - sizes, sizes)
    corners = vertices[faces[seg.order[seg.start[groups][row] + offset]]]
    spread = np.einsum("ijk,ik->ij", corners, across[row]).ravel()
    bounds = 3 * (np.cumsum(sizes) - sizes)
    return np.maximum.reduceat(spread, bounds) - np.minimum.reduceat(spread, bounds)


def _medians(values: NDArray[np.float64], label: NDArray[np.int64]) -> NDArray[np.float64]:
    """Per entry, the median of ``values`` over the entries of its label."""
    order = np.lexsort((values, label))
    ends = np.flatnonzero(np.diff(label[order])) + 1
    starts = np.concatenate([[0], ends])
    sizes = np.diff(np.concatenate([starts, [len(order)]]))
    middle = 0.5 * (values[order[starts + (sizes - 1) // 2]] + values[order[starts + sizes // 2]])
    return middle[np.repeat(np.arange(len(starts)), sizes)][np.argsort(order)]


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
