"""Configuration obstacles of translating parts (Wilson & Latombe 1992, "Extended translations").

Part ``j`` blocks the extended translation of part ``i`` along ``d`` iff the volume that
``i`` sweeps meets the interior of ``j``, i.e. iff the ray ``{t d, t > 0}`` enters the
interior of the grown obstacle ``P_j ⊕ (−P_i) = {a − b | a ∈ P_j, b ∈ P_i}`` (the
"Minkowski difference P_j ⊖ P_i" of Wilson & Latombe 1992, "Extended translations",
after Lozano-Pérez 1983). For convex pieces the
obstacle is the convex hull of the vertex differences (scipy ``ConvexHull``) and the
blocked directions form an open polyhedral cone, bounded by the obstacle's facets
through the origin once the origin is added to the hull.

A part made of several convex bodies (one mesh, disjoint shells) has one obstacle per
pair of bodies; a part with a non-convex body has no such exact decomposition here
(:func:`convex_bodies` says so) and goes through the projection test of
:mod:`assemblykit.geometry.occlusion` instead. (manifold3d's ``minkowski_sum`` of two
non-convex meshes took minutes on a 576-triangle torus, too slow to use here.)
Where exact obstacles of non-convex parts are needed (multi-move planning,
:mod:`assemblykit.planning.multimove_mesh`), :func:`convex_pieces` cuts a part into
convex pieces along the planes of its own faces.
"""

from __future__ import annotations

import numpy as np
import trimesh
from numpy.typing import NDArray
from scipy.optimize import linprog
from scipy.spatial import ConvexHull, QhullError

from assemblykit.errors import GeometryError
from assemblykit.geometry.booleans import manifold3d
from assemblykit.geometry.interference import solid
from assemblykit.tolerance import Tolerance, current

MAX_CONVEX_PIECES = 64
"""Most convex pieces :func:`convex_pieces` cuts one part into before giving up (a
finely tessellated curved part would need hundreds)."""

LP_FIRST = 20_000
"""Vertex pairs beyond which :func:`blocking_cone` first asks :func:`overlap_depth`
whether the pieces overlap (then the hull of their differences is not needed)."""


def convex_bodies(mesh: trimesh.Trimesh, tol: Tolerance) -> list[NDArray[np.float64]] | None:
    """Vertex sets of the connected bodies of the mesh when each is a convex solid within
    the length tolerance, else ``None`` (also for a hollow part, whose cavity is a shell
    facing inwards).

    A body counts as convex when none of its vertices or face centres lies deeper than
    ``tol.length`` inside its convex hull: blocks whose polygon faces are not quite
    planar (COMPAS vaults) stay on the exact cone route, and treating them as their hull
    moves their surface by at most the tolerance."""
    # a convex body's closed surface is a sphere (Euler characteristic 2): a closed mesh
    # whose bodies have handles (a plate with holes) is no union of convex bodies, and
    # neither split nor hull is needed to say so
    if mesh.is_watertight and mesh.euler_number < 2 * mesh.body_count:
        return None
    bodies = [mesh] if mesh.body_count < 2 else mesh.split(only_watertight=False)
    # a shell facing inwards bounds a cavity, not a solid: the part is not convex (a
    # body of no volume, a sheet a boolean left, has no centre of mass: not an error)
    with np.errstate(divide="ignore", invalid="ignore"):
        if any(body.is_watertight and body.volume < 0 for body in bodies):
            return None
    if not all(_convex_within(body, tol) for body in bodies):
        return None
    return [np.asarray(body.vertices, dtype=np.float64) for body in bodies]


def _convex_within(body: trimesh.Trimesh, tol: Tolerance) -> bool:
    """Whether no vertex or face centre of ``body`` is deeper than ``tol.length`` inside
    its convex hull (hull facets ``a . x + b <= 0`` inside, ``a`` unit)."""
    points = np.vstack([body.vertices, body.triangles_center])
    try:
        hull = ConvexHull(points)
    except QhullError:
        return False
    # what the body misses of its hull lies in a shell of that depth under the hull's
    # surface: a larger missing volume settles it without testing every point
    if body.is_volume and hull.volume - abs(body.volume) > tol.length * hull.area:
        return False
    facets = hull.equations
    depth = -(points @ facets[:, :3].T + facets[:, 3]).max(axis=1)
    return bool(depth.max() <= tol.length)


def convex_pieces(
    mesh: trimesh.Trimesh,
    tol: Tolerance | None = None,
    limit: int = MAX_CONVEX_PIECES,
    name: str | None = None,
) -> list[NDArray[np.float64]]:
    """Vertex sets of convex pieces whose union is the closed mesh's solid, interiors
    disjoint: each connected body that is not convex (:func:`_convex_within`; a body
    with a cavity never is) is split by the plane of one of its own faces that has
    vertices more than ``tol.length`` on both sides, the plane carrying the most face
    area first, until every piece is convex. A solid lying on one side of every face
    plane is convex, and the cuts only use the finitely many planes of the input's
    faces, so the splitting ends; slivers thinner than the tolerance are dropped.
    Raises :class:`GeometryError` (about part ``name``) beyond ``limit`` pieces."""
    tol = tol or current()
    todo = _bodies(solid(mesh, name), tol)
    pieces: list[NDArray[np.float64]] = []
    while todo:
        body = todo.pop()
        out = body.to_mesh64()
        piece = trimesh.Trimesh(
            np.asarray(out.vert_properties, dtype=np.float64)[:, :3],
            np.asarray(out.tri_verts, dtype=np.int64),
        )
        if _convex_within(piece, tol):
            pieces.append(np.asarray(piece.vertices, dtype=np.float64))
            continue
        normal, offset = _cutting_plane(piece, tol, name)
        for half in body.split_by_plane(tuple(normal), offset):
            todo.extend(_bodies(half, tol))
        if len(pieces) + len(todo) > limit:
            raise GeometryError(f"more than {limit} convex pieces needed", where=name)
    return pieces


def _bodies(body: manifold3d.Manifold, tol: Tolerance) -> list[manifold3d.Manifold]:
    """The connected bodies of a solid thicker than the tolerance. manifold3d's
    ``decompose`` also returns a cavity's surface as a shell of its own (of negative
    volume), so a solid with a cavity stays whole."""
    shells = body.decompose()
    if any(s.volume() <= 0 for s in shells):
        shells = [body]
    return [s for s in shells if s.volume() > tol.length * s.surface_area()]


def _cutting_plane(
    body: trimesh.Trimesh, tol: Tolerance, name: str | None
) -> tuple[NDArray[np.float64], float]:
    """The plane ``(normal, offset)`` of a face of the non-convex ``body`` that has
    vertices beyond ``tol.length`` on both sides, the one carrying the most face area."""
    normals = np.asarray(body.face_normals, dtype=np.float64)
    offsets = np.einsum("ij,ij->i", normals, body.triangles_center)
    keys = np.round(np.column_stack([normals / tol.angle, offsets / tol.length]))
    planes, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    area = np.bincount(inverse.ravel(), weights=body.area_faces, minlength=len(planes))
    for k in np.argsort(-area, kind="stable"):
        n, c = normals[first[k]], offsets[first[k]]
        side = body.vertices @ n - c
        if side.max() > tol.length and side.min() < -tol.length:
            return n, float(c)
    raise GeometryError("a non-convex body has no face plane that cuts it", where=name)


def obstacle_hull(obstacle: NDArray[np.float64], moving: NDArray[np.float64]) -> ConvexHull:
    """Hull of ``{a − b}`` for the vertices ``a`` of the obstacle and ``b`` of the moving
    piece, with the origin added (module docstring)."""
    diffs = (obstacle[:, None, :] - moving[None, :, :]).reshape(-1, 3)
    try:
        return ConvexHull(np.vstack([diffs, np.zeros(3)]))
    except QhullError as bad:
        raise GeometryError(
            f"degenerate convex piece ({len(obstacle)} and {len(moving)} vertices): {bad}"
        ) from None


def blocking_cone(
    obstacle: NDArray[np.float64], moving: NDArray[np.float64], tol: Tolerance
) -> NDArray[np.float64]:
    """Normals ``n`` (m x 3) such that translating the convex piece ``moving`` along ``d``
    to infinity enters the interior of the convex piece ``obstacle`` iff ``n . d > 0`` for
    all of them. An empty array means every direction (the pieces overlap)."""
    obstacle = np.asarray(obstacle, dtype=np.float64)
    moving = np.asarray(moving, dtype=np.float64)
    if len(obstacle) * len(moving) > LP_FIRST and overlap_depth(obstacle, moving) > tol.length:
        return np.zeros((0, 3))
    hull = obstacle_hull(obstacle, moving)
    through = np.abs(hull.equations[:, 3]) <= tol.length
    normals = -hull.equations[through, :3]
    # qhull triangulates facets: keep one normal per plane (first of each repeat)
    same = normals @ normals.T >= np.cos(tol.angle)
    first = ~np.any(np.triu(same, 1), axis=0)
    return np.ascontiguousarray(normals[first], dtype=np.float64).reshape(-1, 3)


def overlap_depth(first: NDArray[np.float64], second: NDArray[np.float64]) -> float:
    """How deep a ball fits inside both convex hulls of the point sets (a linear
    program, scipy ``linprog``): positive when their interiors overlap, so that the
    grown obstacle holds the origin and every direction is blocked. Much cheaper than
    the hull of all vertex differences for pieces with many vertices."""
    try:
        facets = np.vstack([ConvexHull(first).equations, ConvexHull(second).equations])
    except QhullError:
        return 0.0
    # maximise r with a . x + b + r <= 0 for every facet (a unit): x is r inside both
    bounds = [(None, None)] * 3 + [(None, None)]
    found = linprog(
        c=[0.0, 0.0, 0.0, -1.0],
        A_ub=np.column_stack([facets[:, :3], np.ones(len(facets))]),
        b_ub=-facets[:, 3],
        bounds=bounds,
        method="highs",
    )
    return float(found.x[3]) if found.status == 0 else 0.0


def blocks_along(
    cone: NDArray[np.float64], directions: NDArray[np.float64], margin: float = 0.0
) -> NDArray[np.bool_]:
    """Whether each direction (rows, unit) lies in the open blocking cone (rows: its
    facets' unit inner normals), inside each facet by more than the angle ``margin``: a
    direction within the angle tolerance of a facet grazes it (a drawer sliding along
    the plane it rests on, in coordinates rounded by a rotation)."""
    return np.all(np.atleast_2d(directions) @ cone.T > margin, axis=1)


def triangle_cones(
    moving: NDArray[np.float64],
    obstacle: NDArray[np.float64],
    moving_normals: NDArray[np.float64] | None,
    obstacle_normals: NDArray[np.float64] | None,
    tol: Tolerance,
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Open cones of the directions along which each triangle of ``moving`` (m x 3 x 3),
    swept to infinity, crosses each triangle of ``obstacle`` (k x 3 x 3): for the pair,
    the rays entering ``T_o ⊕ (−T_m)``, whose nine vertex differences generate the cone.

    Returns ``normals`` (m k x 12 x 3) and ``valid`` (m k): the cone of a valid pair is
    ``{d : n . d > 0 for its twelve rows}`` (rows of zeros hold always-true padding with
    normal ``0``: callers treat a zero row as no constraint). A facet of a pointed cone
    through the origin is spanned by two generators, so the supporting planes spanned by
    pairs of generators give its H-representation (Wilson & Latombe 1992 §5, the Minkowski
    difference's projection). With outward triangle normals (a mesh bounding a volume)
    two more rows keep only a front face of the moving part (``n_m . d > 0``) meeting a
    back face of the obstacle (``n_o . d < 0``): the first contact of a blocked sweep is
    between such faces, so the union over pairs still covers every blocked direction up
    to its boundary. Pairs whose generators span no volume (coplanar faces in contact)
    or surround the origin (the triangles cross at rest) are not valid; the second kind
    is reported by the caller's interference test instead."""
    mt = np.asarray(moving, dtype=np.float64).reshape(-1, 3, 3)
    ot = np.asarray(obstacle, dtype=np.float64).reshape(-1, 3, 3)
    gens = (ot[None, :, :, None, :] - mt[:, None, None, :, :]).reshape(len(mt) * len(ot), 9, 3)
    p, q = np.triu_indices(9, 1)
    planes = np.cross(gens[:, p], gens[:, q])
    norm = np.linalg.norm(planes, axis=2)
    scale = np.linalg.norm(gens, axis=2).max(axis=1)[:, None]
    # a plane through two generators at an angle below the tolerance is not determined
    usable = norm > tol.angle * scale**2
    planes = np.where(usable[..., None], planes / np.where(usable, norm, 1.0)[..., None], 0.0)
    sides = np.einsum("npk,ngk->npg", planes, gens)
    low, high = sides.min(axis=2), sides.max(axis=2)
    slack = tol.length
    upward = usable & (low >= -slack)
    downward = usable & (high <= slack) & ~upward
    rows = np.where(upward[..., None], planes, np.where(downward[..., None], -planes, 0.0))
    # generators in one plane (coplanar faces): the cone has no interior
    flat = np.all(np.abs(sides) <= slack, axis=2) & usable
    valid = np.any(upward | downward, axis=1) & ~np.any(flat, axis=1)
    # one row per distinct plane (up to 12 kept: a cone generated by nine vectors has
    # at most nine facets)
    rows = _distinct_rows(rows, tol)
    extra = []
    if moving_normals is not None and obstacle_normals is not None:
        mn = np.repeat(np.asarray(moving_normals, dtype=np.float64), len(ot), axis=0)
        on = np.tile(np.asarray(obstacle_normals, dtype=np.float64), (len(mt), 1))
        extra = [mn[:, None, :], -on[:, None, :]]
    else:
        pad = np.zeros((len(gens), 1, 3))
        extra = [pad, pad]
    return np.concatenate([rows, *extra], axis=1), valid


def _distinct_rows(rows: NDArray[np.float64], tol: Tolerance) -> NDArray[np.float64]:
    """The nonzero rows of each cone, repeats (within the angle tolerance) dropped, padded
    with zero rows to ten per cone."""
    same = np.einsum("npk,nqk->npq", rows, rows) >= np.cos(tol.angle)
    repeat = np.any(np.triu(same, 1), axis=1)
    keep = np.linalg.norm(rows, axis=2) > 0.5
    keep &= ~repeat
    order = np.argsort(~keep, axis=1, kind="stable")[:, :10]
    picked = np.take_along_axis(rows, order[..., None], axis=1)
    kept = np.take_along_axis(keep, order, axis=1)
    return np.where(kept[..., None], picked, 0.0)
