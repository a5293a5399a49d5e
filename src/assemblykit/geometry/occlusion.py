"""Which meshes a translating mesh runs into: exact extended blocking on triangle meshes
(Wilson & Latombe 1992, "Extended translations").

Part ``j`` blocks the extended translation of part ``i`` along ``d`` iff the volume
``i`` sweeps to infinity meets the interior of ``j``. On a line parallel to ``d`` the
sweep of ``i`` starts at the lowest depth ``x . d`` of ``i`` on that line, reached on a
triangle of ``i`` facing backwards (``n . d < 0``), and ``j`` reaches farthest on a
triangle facing forwards; so ``j`` blocks ``i`` iff, over a set of lines of positive
area, some forward triangle of ``j`` lies deeper than some backward triangle of ``i``.
Projected on the plane ``⟂ d`` each triangle's depth is affine, hence so is the
difference of two depths over the convex overlap of their projections, and its
maximum is reached at a vertex of that overlap: ``j`` blocks ``i`` iff at a vertex of
some overlap the depth of ``j`` exceeds that of ``i`` by more than the length tolerance
(faces in contact give 0). The excess is measured across the faces (times the larger
``|n . d|`` of the two): coincident faces nearly parallel to ``d`` differ along ``d`` by
their rounding error divided by that cosine, not by an overlap. The broad phase is
shapely's STRtree over the triangles' bounding boxes, one per blocking mesh, with an
affine depth bound, the overlaps every pair's triangles clipped by one another at once
(Sutherland & Hodgman 1974, in numpy). Any pair of triangles that blocks shows that its
meshes block, so the largest projected triangles of each mesh are compared first and
only the pairs of meshes not yet blocking are compared over all triangles. Overlaps
thinner than the length tolerance (shared edges) have no area and are left out.
Triangles within the angle tolerance of parallel to ``d`` project to nothing and are
skipped, and so are those whose projection is thinner than the length tolerance (a side
face tilted by vertex noise): every overlap with them would be too thin to count.
Meshes that do not bound a volume (open or inconsistently wound) use all their triangles
on both sides, which is still exact, only slower.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely
import trimesh
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import ConvexHull, HalfspaceIntersection

from assemblykit.algebra import se3
from assemblykit.deprecation import moved
from assemblykit.ragged import group_of
from assemblykit.tolerance import Tolerance, current

_FIRST_CHUNK = 1024
_FIRST_TRIANGLES = 256
"""How many of each mesh's largest projected triangles :func:`occluded_pairs` compares
first (where most blocking pairs show)."""


def view_frame(direction: ArrayLike) -> NDArray[np.float64]:
    """Rows ``e1, e2, d``: an orthonormal frame whose third axis is the unit ``direction``."""
    d = np.asarray(direction, dtype=np.float64).ravel()
    d = d / np.linalg.norm(d)
    # the frame is returned: shadows' coordinates, boxes and depths are kept in it
    e1, e2 = se3.axis_basis(d, turned=True)
    return np.array([e1, e2, d])


@dataclass(frozen=True, eq=False)
class Shadows:
    """The non-vertical triangles of several meshes seen along a direction.

    ``owner`` is the mesh of each triangle; ``facing`` +1 forwards, -1 backwards, 0 both
    (a mesh that bounds no volume); ``flat`` the projected triangles (t x 3 x 2);
    ``plane`` rows ``(a, b, c)`` with depth ``a u + b v + c`` at ``(u, v)``; ``low`` and
    ``high`` each triangle's depth range, ``box`` its ``(umin, vmin, umax, vmax)`` and
    ``face`` its index among its mesh's faces."""

    owner: NDArray[np.int64]
    facing: NDArray[np.int8]
    flat: NDArray[np.float64]
    plane: NDArray[np.float64]
    low: NDArray[np.float64]
    high: NDArray[np.float64]
    box: NDArray[np.float64]
    face: NDArray[np.int64]

    @property
    def cos(self) -> NDArray[np.float64]:
        """``|n . d|`` of each triangle (from its depth gradient)."""
        return 1.0 / np.sqrt(1.0 + self.plane[:, 0] ** 2 + self.plane[:, 1] ** 2)

    def bound(self, back: NDArray[np.int64], front: NDArray[np.int64]) -> NDArray[np.float64]:
        """An upper bound of how much deeper triangle ``front`` lies than ``back`` over
        their overlap: the depth difference at the corners of the overlap of their
        bounding boxes (an affine function peaks at a corner of a box), capped by
        their depth ranges."""
        lo = np.maximum(self.box[back, :2], self.box[front, :2])
        hi = np.minimum(self.box[back, 2:], self.box[front, 2:])
        diff = self.plane[front] - self.plane[back]
        corner = (
            np.where(diff[:, 0] > 0, hi[:, 0], lo[:, 0]) * diff[:, 0]
            + np.where(diff[:, 1] > 0, hi[:, 1], lo[:, 1]) * diff[:, 1]
            + diff[:, 2]
        )
        return np.minimum(corner, self.high[front] - self.low[back])

    def depth(self, triangles: NDArray[np.int64], uv: NDArray[np.float64]) -> NDArray[np.float64]:
        """Depth of each triangle's plane at the points ``uv``, clamped to its range
        (the points lie on the triangle up to rounding)."""
        p = self.plane[triangles]
        z = p[:, 0] * uv[:, 0] + p[:, 1] * uv[:, 1] + p[:, 2]
        return np.clip(z, self.low[triangles], self.high[triangles])


_CUBE_DIRECTIONS = np.array(
    [(x, y, z) for x in (-1, 0, 1) for y in (-1, 0, 1) for z in (-1, 0, 1) if x or y or z],
    dtype=np.float64,
)
_DOP_AXES = _CUBE_DIRECTIONS / np.linalg.norm(_CUBE_DIRECTIONS, axis=1)[:, None]
"""The 26 outward normals of a discrete-orientation polytope (the axes, the face and
the corner diagonals of a cube)."""

_LARGEST_FACES = 8
"""How many of a hull's largest faces bound its outer polytope besides those normals."""


def hull_vertices(mesh: trimesh.Trimesh) -> NDArray[np.float64]:
    """The corners of a polytope holding ``mesh``: its convex hull (scipy's qhull, whose
    facets come with their outward planes) cut down to the planes of the 26
    :data:`_DOP_AXES` touching it and of its :data:`_LARGEST_FACES` largest faces
    (scipy's half-space intersection), a few dozen corners where a tessellated
    cylinder's hull has hundreds; all the mesh's vertices
    where the hull is degenerate (a flat part). Projected along any direction, the
    polytope's outline holds the mesh's: where two outlines do not overlap, neither do
    the meshes (:func:`hulls_may_block`)."""
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    try:
        hull = ConvexHull(vertices, qhull_options="QbB Pp Qt")
        corners = vertices[hull.vertices]
        if len(corners) <= len(_DOP_AXES) + _LARGEST_FACES:
            return corners
        triangles = vertices[hull.simplices]
        areas = np.linalg.norm(
            np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0]), axis=1
        )
        largest = np.argsort(-areas, kind="stable")[:_LARGEST_FACES]
        normals = np.vstack([_DOP_AXES, hull.equations[largest, :3]])
        offsets = (corners @ normals.T).max(axis=0)
        planes = np.column_stack([normals, -offsets])
        cut = HalfspaceIntersection(planes, corners.mean(axis=0)).intersections
    except Exception:  # qhull refuses flat and degenerate point sets
        return vertices
    return np.asarray(cut, dtype=np.float64) if np.all(np.isfinite(cut)) else corners


def triangle_spheres(mesh: trimesh.Trimesh) -> NDArray[np.float64]:
    """Per triangle of ``mesh``, its centroid and the distance from it to its farthest
    corner (rows ``x, y, z, r``): a ball holding the triangle."""
    corners = np.asarray(mesh.triangles, dtype=np.float64)
    centre = corners.mean(axis=1)
    radius = np.linalg.norm(corners - centre[:, None, :], axis=2).max(axis=1)
    return np.column_stack([centre, radius])


def faces_near_outlines(
    spheres: Sequence[NDArray[np.float64]],
    hulls: Sequence[NDArray[np.float64]],
    pairs: NDArray[np.int64],
    direction: ArrayLike,
    tol: Tolerance,
) -> list[NDArray[np.int64]]:
    """Per mesh (its :func:`triangle_spheres` and the points of its convex hull), the
    faces that may take part in a block between the pairs ``(i, j)`` of ``pairs`` along
    ``direction``: those whose projection on the plane ``⟂ d`` may meet the box around
    the projection of the other mesh's hull (with the length tolerance). A pair of
    triangles shows a block only where their projections overlap (module docstring),
    inside both meshes' outlines, so a face whose ball projects clear of the other
    outline's box takes part in none."""
    frame = view_frame(direction)[:2]
    boxes = []
    for points in hulls:
        flat = np.asarray(points, dtype=np.float64) @ frame.T
        boxes.append((flat.min(axis=0), flat.max(axis=0)))
    partners: dict[int, set[int]] = {}
    for i, j in np.asarray(pairs).tolist():
        partners.setdefault(i, set()).add(j)
        partners.setdefault(j, set()).add(i)
    chosen = [np.zeros(0, dtype=np.int64) for _ in spheres]
    for mine, others in partners.items():
        centre = spheres[mine][:, :3] @ frame.T
        reach = spheres[mine][:, 3:] + tol.length
        low, high = centre - reach, centre + reach
        near = np.zeros(len(centre), dtype=bool)
        for other in others:
            lo, hi = boxes[other]
            near |= (
                (high[:, 0] >= lo[0])
                & (low[:, 0] <= hi[0])
                & (high[:, 1] >= lo[1])
                & (low[:, 1] <= hi[1])
            )
        chosen[mine] = np.flatnonzero(near)
    return chosen


def hulls_may_block(
    hulls: Sequence[NDArray[np.float64]],
    pairs: NDArray[np.int64],
    direction: ArrayLike,
    tol: Tolerance,
) -> NDArray[np.bool_]:
    """Per pair ``(i, j)`` of ``pairs`` (rows of indices into ``hulls``, each the points
    of a part's convex hull), whether ``j`` may block the extended translation of ``i``
    along ``direction``: the projections of their hulls on the plane ``⟂ d`` meet over
    an area and some point of ``j`` lies deeper than every point of ``i`` by more than
    the length tolerance. Where either fails, no two triangles of the parts can show a
    block (module docstring): the overlaps of their projections lie in the hulls'
    overlap, so their inradius is at most that of the hulls' overlap, and an overlap of
    area ``A`` and perimeter ``P`` has an inradius of at most ``2 A / P``; so an overlap
    of the hulls with ``A <= P tol / 2`` holds no triangle overlap that counts
    (``A > P tol``, as :func:`occluded_pairs` counts them). All pairs at once (shapely's
    vectorised hulls and intersections)."""
    if not len(pairs):
        return np.zeros(0, dtype=bool)
    frame = view_frame(direction)
    used = np.unique(pairs)
    seen = [np.asarray(hulls[k], dtype=np.float64) @ frame.T for k in used]
    owner = group_of([len(s) for s in seen])
    points = np.concatenate(seen)
    outlines = shapely.convex_hull(shapely.multipoints(points[:, :2], indices=owner))
    deepest = np.full(len(used), -np.inf)
    lowest = np.full(len(used), np.inf)
    np.maximum.at(deepest, owner, points[:, 2])
    np.minimum.at(lowest, owner, points[:, 2])
    place = np.searchsorted(used, pairs)
    moving, blocker = place[:, 0], place[:, 1]
    ahead = deepest[blocker] - lowest[moving] > tol.length
    shared = shapely.intersection(outlines[moving], outlines[blocker])
    wide = shapely.area(shared) > 0.5 * tol.length * shapely.length(shared)
    return np.asarray(ahead & wide, dtype=bool)


def _shadow_width(flat: NDArray[np.float64]) -> NDArray[np.float64]:
    """The smallest altitude of each projected triangle (``... x 3 x 2``)."""
    # the edges from each corner to the next, as views of the corners (no gathering)
    first = flat[..., 1, :] - flat[..., 0, :]
    second = flat[..., 2, :] - flat[..., 1, :]
    third = flat[..., 0, :] - flat[..., 2, :]
    double_area = np.abs(first[..., 0] * second[..., 1] - first[..., 1] * second[..., 0])
    longest = np.sqrt(
        np.maximum(
            np.maximum(
                np.einsum("...j,...j->...", first, first),
                np.einsum("...j,...j->...", second, second),
            ),
            np.einsum("...j,...j->...", third, third),
        )
    )
    return double_area / np.where(longest > 0, longest, 1.0)


def shadows(
    meshes: Sequence[trimesh.Trimesh],
    direction: ArrayLike,
    tol: Tolerance,
    faces: Sequence[NDArray[np.int64]] | None = None,
) -> Shadows:
    """Project the meshes' triangles on the plane ``⟂ direction`` (module docstring):
    all of them, or those listed per mesh in ``faces``."""
    frame = view_frame(direction)
    owner, facing, corners, normals, kept = [], [], [], [], []
    for k, mesh in enumerate(meshes):
        chosen = np.arange(len(mesh.faces)) if faces is None else np.asarray(faces[k])
        face_normals = mesh.face_normals if faces is None else mesh.face_normals[chosen]
        triangles = mesh.triangles if faces is None else mesh.triangles[chosen]
        # without a consistent outside every triangle may bound the part on either side
        shown, sides, seen, turned = _seen(
            np.asarray(triangles, dtype=np.float64),
            face_normals,
            np.int8(mesh.is_volume),
            frame[None],
            tol,
        )
        keep = shown[0]
        owner.append(np.full(len(sides), k, dtype=np.int64))
        facing.append(sides)
        corners.append(seen)
        normals.append(turned)
        kept.append(chosen[keep])
    return _shadows_of(
        np.concatenate(owner) if owner else np.zeros(0, np.int64),
        np.concatenate(facing) if facing else np.zeros(0, np.int8),
        np.concatenate(corners) if corners else np.zeros((0, 3, 3)),
        np.concatenate(normals) if normals else np.zeros((0, 3)),
        np.concatenate(kept) if kept else np.zeros(0, np.int64),
    )


def _seen(
    triangles: NDArray[np.float64],
    normals: NDArray[np.float64],
    volume: np.int8 | NDArray[np.int8],
    frames: NDArray[np.float64],
    tol: Tolerance,
) -> tuple[NDArray[np.bool_], NDArray[np.int8], NDArray[np.float64], NDArray[np.float64]]:
    """The triangles (``t x 3 x 3``, unit ``normals``) seen in each view frame of
    ``frames`` (``f x 3 x 3``, :func:`view_frame`): which are kept (``f x t``: neither
    within the angle tolerance of parallel to the view nor thinner than the length
    tolerance once projected), and of those, in the order of ``np.nonzero(keep)``, the
    side each faces (times ``volume``, 0 for a mesh that bounds no volume), and the
    corners and normals in the frame."""
    cos = np.matmul(normals, frames[:, 2, :, None])[..., 0]
    # every corner in the view frame once: its first two coordinates on the plane
    seen = np.matmul(triangles, frames.transpose(0, 2, 1)[:, None])
    keep = (np.abs(cos) > tol.mesh_angle) & (_shadow_width(seen[..., :2]) > tol.length)
    view, face = np.nonzero(keep)
    facing = np.sign(cos[keep]).astype(np.int8)
    facing *= volume[face] if isinstance(volume, np.ndarray) else volume
    if len(frames) == 1:
        turned = normals[face] @ frames[0].T
    else:
        turned = np.matmul(normals[face, None, :], frames[view].transpose(0, 2, 1))[:, 0]
    return keep, facing, seen[keep], turned


def _shadows_of(
    owner: NDArray[np.int64],
    facing: NDArray[np.int8],
    tri: NDArray[np.float64],
    n: NDArray[np.float64],
    face: NDArray[np.int64],
) -> Shadows:
    """The :class:`Shadows` of triangles kept by :func:`_seen` (corners ``tri`` and
    normals ``n`` in the view frame)."""
    # plane n . x = n . p0 solved for the depth coordinate
    plane = np.column_stack(
        [-n[:, 0] / n[:, 2], -n[:, 1] / n[:, 2], np.einsum("ij,ij->i", n, tri[:, 0]) / n[:, 2]]
    )
    # minima and maxima of the three corners pairwise: reductions over an axis of
    # length 3 cost more than the comparisons
    lowest = np.minimum(np.minimum(tri[:, 0], tri[:, 1]), tri[:, 2])
    highest = np.maximum(np.maximum(tri[:, 0], tri[:, 1]), tri[:, 2])
    return Shadows(
        owner,
        facing,
        tri[:, :, :2],
        plane,
        lowest[:, 2],
        highest[:, 2],
        np.column_stack([lowest[:, :2], highest[:, :2]]),
        face,
    )


def clip_triangles(
    subject: NDArray[np.float64], clip: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.float64], NDArray[np.float64]]:
    """The overlaps of pairs of plane triangles (``n x 3 x 2`` each), all pairs at once:
    ``subject`` clipped by the three edges of ``clip`` (Sutherland & Hodgman 1974).

    Returns ``points`` (``n x m x 2``) with ``corner[k, i]`` telling which are vertices
    of overlap ``k`` (the first ones, in order around it), and each overlap's area and
    perimeter (both 0 when the triangles do not overlap)."""
    if not len(subject):
        return subject, np.zeros((0, 3), dtype=bool), np.zeros(0), np.zeros(0)
    # counter-clockwise clip triangles: the inside of an edge a -> b is on its left
    edges = clip[:, 1] - clip[:, 0], clip[:, 2] - clip[:, 0]
    turned = edges[0][:, 0] * edges[1][:, 1] - edges[0][:, 1] * edges[1][:, 0] < 0
    clip = np.where(turned[:, None, None], clip[:, ::-1], clip)
    points, corner = subject, np.ones(subject.shape[:2], dtype=bool)
    # each row's entries picked by an index array per row (``a[rows, index]``)
    rows = np.arange(len(subject))[:, None]
    for e in range(3):
        a, edge = clip[:, e, None], (clip[:, (e + 1) % 3] - clip[:, e])[:, None]
        after = _following(corner)
        side = edge[..., 0] * (points[..., 1] - a[..., 1]) - edge[..., 1] * (
            points[..., 0] - a[..., 0]
        )
        side_after = side[rows, after]
        inside = corner & (side >= 0)
        crossing = corner & ((side >= 0) != (side_after >= 0))
        t = side / np.where(crossing, side - side_after, 1.0)
        ahead = points[rows, after]
        candidates = np.stack([points, points + t[..., None] * (ahead - points)], axis=2)
        kept = np.stack([inside, crossing], axis=2).reshape(len(points), -1)
        # the kept points first, in their order around the overlap
        order = np.argsort(~kept, axis=1, kind="stable")[:, : max(int(kept.sum(1).max()), 1)]
        points = candidates.reshape(len(points), -1, 2)[rows, order]
        corner = kept[rows, order]
    step = points[rows, _following(corner)] - points
    step[~corner] = 0.0
    twice = points[..., 0] * step[..., 1] - points[..., 1] * step[..., 0]
    area = np.abs(np.where(corner, twice, 0.0).sum(axis=1)) / 2
    return points, corner, area, np.linalg.norm(step, axis=2).sum(axis=1)


def _following(corner: NDArray[np.bool_]) -> NDArray[np.int64]:
    """Per row, the index of the next vertex around the polygon of the first
    ``corner.sum(1)`` points (the last one's is the first)."""
    index = np.arange(corner.shape[1])
    return np.where(index + 1 < corner.sum(axis=1)[:, None], index + 1, 0)


def _box_hits(
    view: Shadows,
    backward: NDArray[np.int64],
    forward: NDArray[np.int64],
    allowed: NDArray[np.bool_],
    tol: Tolerance,
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The pairs of a ``backward`` and a ``forward`` triangle of meshes ``(i, j)`` with
    ``allowed[i, j]`` whose bounding boxes meet and whose depth ranges let the forward
    one lie deeper by more than the length tolerance (else :meth:`Shadows.bound` rules
    them out): per blocking mesh, its forward triangles and the backward triangles of the
    meshes it may block, each kept only where it meets the other side's overall box and
    depth range, then one STRtree (a mesh's own triangles, overlapping everywhere, are
    never compared)."""
    sides: list[tuple[NDArray[np.int64], NDArray[np.int64]]] = []
    for j in np.flatnonzero(np.any(allowed, axis=0)):
        front = forward[view.owner[forward] == j]
        back = backward[allowed[view.owner[backward], j]]
        if len(front) and len(back):
            back = back[_meets(view, back, front, tol, behind=True)]
        if len(back):
            front = front[_meets(view, front, back, tol, behind=False)]
        if len(front) and len(back):
            sides.append((back, front))
    # the trees only compare bounding boxes: each box's diagonal has the same and is
    # cheaper to make than the triangle (made once for a triangle on several sides)
    used = np.unique(
        np.concatenate([np.zeros(0, dtype=np.int64), *(np.concatenate(s) for s in sides)])
    )
    diagonals = np.empty(len(view.owner), dtype=object)
    diagonals[used] = shapely.linestrings(
        np.stack([view.box[used, :2], view.box[used, 2:]], axis=1)
    )
    backs, fronts = [np.zeros(0, dtype=np.int64)], [np.zeros(0, dtype=np.int64)]
    for back, front in sides:
        hits = shapely.STRtree(diagonals[front]).query(diagonals[back])
        backs.append(back[hits[0]])
        fronts.append(front[hits[1]])
    return np.concatenate(backs), np.concatenate(fronts)


def _meets(
    view: Shadows,
    these: NDArray[np.int64],
    others: NDArray[np.int64],
    tol: Tolerance,
    *,
    behind: bool,
) -> NDArray[np.bool_]:
    """Per triangle of ``these``, whether its box meets the box around all of ``others``
    and whether a forward triangle can lie deeper than a backward one by more than the
    length tolerance: ``behind``, these are backward (the deepest of ``others`` beyond
    their lowest depth by more), else forward (their deepest beyond the lowest of
    ``others`` by more), the differences taken as :meth:`Shadows.bound` takes them."""
    lo, hi = view.box[others, :2].min(axis=0), view.box[others, 2:].max(axis=0)
    box = view.box[these]
    near = np.all((box[:, :2] <= hi) & (box[:, 2:] >= lo), axis=1)
    if behind:
        return near & (view.high[others].max() - view.low[these] > tol.length)
    return near & (view.high[these] - view.low[others].min() > tol.length)


def occluded_pairs(
    view: Shadows,
    allowed: NDArray[np.bool_],
    tol: Tolerance | None = None,
    *,
    first_only: bool = False,
) -> set[tuple[int, int]]:
    """The pairs ``(i, j)`` of meshes such that ``j`` blocks the extended translation of
    ``i`` along the view direction, among those with ``allowed[i, j]`` (module
    docstring; :func:`blocking_witnesses` without the witnesses)."""
    return set(blocking_witnesses(view, allowed, tol or current(), first_only=first_only))


def blocking_witnesses(
    view: Shadows,
    allowed: NDArray[np.bool_],
    tol: Tolerance,
    *,
    first_only: bool = False,
) -> dict[tuple[int, int], tuple[int, int]]:
    """Per pair ``(i, j)`` of meshes such that ``j`` blocks the extended translation of
    ``i`` along the view direction, among those with ``allowed[i, j]`` (module
    docstring), a witness: a backward face of ``i`` and a forward face of ``j`` (their
    indices among their meshes' faces) whose projections overlap where ``j`` lies deeper.
    First among the largest projected triangles of each mesh (``_FIRST_TRIANGLES``):
    most blocking pairs have a pair of triangles that shows it there, and only the
    others are then examined over all their triangles. With ``first_only``, a mesh
    found blocked by one is not examined further: each blocked mesh has at least one
    pair, the others may be missing (whether a part can leave, not all that holds it)."""
    found = _occluded_among(view, allowed, _largest(view, _FIRST_TRIANGLES), tol, first_only)
    rest = allowed.copy()
    for i, j in found:
        rest[i, j] = False
        if first_only:
            rest[i] = False
    every = np.ones(len(view.owner), dtype=bool)
    found |= _occluded_among(view, rest, every, tol, first_only)
    return {pair: (int(view.face[b]), int(view.face[f])) for pair, (b, f) in found.items()}


def witnesses_hold(
    meshes: Sequence[trimesh.Trimesh],
    witnesses: Sequence[tuple[int, int, int, int]],
    direction: ArrayLike,
    tol: Tolerance | None = None,
) -> NDArray[np.bool_]:
    """Per witness ``(i, j, face_i, face_j)`` (meshes ``i``, ``j`` of ``meshes`` and a
    face of each, as :func:`blocking_witnesses` gives them), whether those two faces
    show that ``j`` blocks ``i`` along ``direction`` too: the test of the module
    docstring on these two triangles alone. A witness that holds shows the block (a
    pair of triangles is enough); one that fails shows nothing."""
    return witnesses_hold_along(meshes, witnesses, view_frame(direction)[None], tol or current())[
        :, 0
    ]


def witnesses_hold_along(
    meshes: Sequence[trimesh.Trimesh],
    witnesses: Sequence[tuple[int, int, int, int]],
    frames: NDArray[np.float64],
    tol: Tolerance,
) -> NDArray[np.bool_]:
    """:func:`witnesses_hold` along the direction of each of the view ``frames``
    (``f x 3 x 3``, :func:`view_frame`), as ``witnesses x f``: the faces are gathered
    once and the overlaps of every direction's pairs clipped at once, so that a search
    over many directions asks once for a pair of parts instead of once per direction."""
    table = np.asarray(witnesses, dtype=np.int64).reshape(-1, 4)
    count = len(table)
    if not count or not len(frames):
        return np.zeros((count, len(frames)), dtype=bool)
    # the backward face of each witness, then the forward one
    owner = np.concatenate([table[:, 0], table[:, 1]])
    face = np.concatenate([table[:, 2], table[:, 3]])
    corners = np.empty((2 * count, 3, 3))
    normals = np.empty((2 * count, 3))
    volume = np.empty(2 * count, dtype=np.int8)
    for k in np.unique(owner).tolist():
        rows = owner == k
        corners[rows] = meshes[k].triangles[face[rows]]
        normals[rows] = meshes[k].face_normals[face[rows]]
        volume[rows] = meshes[k].is_volume
    keep, facing, seen, turned = _seen(corners, normals, volume, frames, tol)
    # where each face lies among the triangles of the view (-1: not projected)
    place = np.full(keep.shape, -1, dtype=np.int64)
    place[keep] = np.arange(int(keep.sum()))
    view = _shadows_of(
        np.zeros(len(facing), dtype=np.int64),
        facing,
        seen,
        turned,
        np.zeros(len(facing), dtype=np.int64),
    )
    back, front = place[:, :count], place[:, count:]
    present = (back >= 0) & (front >= 0)
    b, f = back[present], front[present]
    facing_ok = (view.facing[b] <= 0) & (view.facing[f] >= 0)
    shown = np.zeros(len(b), dtype=bool)
    shown[facing_ok] = _shows_block(view, b[facing_ok], f[facing_ok], tol)
    holds = np.zeros((len(frames), count), dtype=bool)
    holds[present] = shown
    return holds.T


def _largest(view: Shadows, count: int) -> NDArray[np.bool_]:
    """Per triangle, whether it is among the ``count`` largest projected triangles of
    its mesh."""
    edges = view.flat[:, 1:] - view.flat[:, :1]
    area = np.abs(edges[:, 0, 0] * edges[:, 1, 1] - edges[:, 0, 1] * edges[:, 1, 0])
    large = np.zeros(len(area), dtype=bool)
    for k in np.unique(view.owner):
        mine = np.flatnonzero(view.owner == k)
        if len(mine) > count:
            mine = mine[np.argpartition(-area[mine], count)[:count]]
        large[mine] = True
    return large


def _occluded_among(
    view: Shadows,
    allowed: NDArray[np.bool_],
    among: NDArray[np.bool_],
    tol: Tolerance,
    first_only: bool = False,
) -> dict[tuple[int, int], tuple[int, int]]:
    """:func:`blocking_witnesses` over the triangles ``among`` alone (a subset shows only
    pairs that block), each witness as two triangles of ``view``. Triangle pairs are
    examined by decreasing :meth:`Shadows.bound` within each pair of meshes, the pairs of
    meshes in turn, and a pair of meshes stops being examined once it blocks (with
    ``first_only``, every pair of its moving mesh)."""
    backward = np.flatnonzero(among & (view.facing <= 0) & np.any(allowed, axis=1)[view.owner])
    forward = np.flatnonzero(among & (view.facing >= 0) & np.any(allowed, axis=0)[view.owner])
    if not len(backward) or not len(forward):
        return {}
    back, front = _box_hits(view, backward, forward, allowed, tol)
    bound = view.bound(back, front) * np.maximum(view.cos[front], view.cos[back])
    keep = bound > tol.length
    order = np.argsort(-bound[keep], kind="stable")
    back, front = back[keep][order], front[keep][order]
    size = len(allowed)
    # round robin over the pairs of meshes: the k-th deepest candidate of every pair
    # before the (k + 1)-th of any, so that each blocking pair is met early whatever
    # the depths of the others
    pairs = view.owner[back] * size + view.owner[front]
    by_pair = np.argsort(pairs, kind="stable")
    ranked = pairs[by_pair]
    rank = np.empty(len(pairs), dtype=np.int64)
    rank[by_pair] = np.arange(len(pairs)) - np.searchsorted(ranked, ranked)
    order = np.argsort(rank, kind="stable")
    back, front = back[order], front[order]
    found: dict[tuple[int, int], tuple[int, int]] = {}
    lo, chunk = 0, _FIRST_CHUNK
    while lo < len(back):
        b, f = back[lo : lo + chunk], front[lo : lo + chunk]
        # growing chunks: blocking pairs are usually found in the first, deepest ones of
        # each pair of meshes
        lo, chunk = lo + chunk, 2 * chunk
        pair = view.owner[b] * size + view.owner[f]
        fresh = ~np.isin(pair, [i * size + j for i, j in found])
        if first_only:
            fresh &= ~np.isin(view.owner[b], [i for i, _ in found])
        b, f, pair = b[fresh], f[fresh], pair[fresh]
        shown = _shows_block(view, b, f, tol)
        # the first witness of each pair found
        pair, first = np.unique(pair[shown], return_index=True)
        witnesses = zip(b[shown][first].tolist(), f[shown][first].tolist(), strict=True)
        for p, (i, j) in zip(pair.tolist(), witnesses, strict=True):
            found[(p // size, p % size)] = (i, j)
    return found


def _shows_block(
    view: Shadows, back: NDArray[np.int64], front: NDArray[np.int64], tol: Tolerance
) -> NDArray[np.bool_]:
    """Per pair of a backward triangle ``back`` and a forward triangle ``front`` of
    ``view``, whether their projections overlap over an area (more than the length
    tolerance times its perimeter) at a vertex of which ``front`` lies deeper than
    ``back`` by more than the length tolerance, measured across the faces (module
    docstring)."""
    points, corner, area, perimeter = clip_triangles(view.flat[back], view.flat[front])
    which, at = np.nonzero(corner & (area > tol.length * perimeter)[:, None])
    uv = points[which, at]
    b, f = back[which], front[which]
    excess = (view.depth(f, uv) - view.depth(b, uv)) * np.maximum(view.cos[f], view.cos[b])
    shown = np.zeros(len(back), dtype=bool)
    shown[which[excess > tol.length]] = True
    return shown


__getattr__ = moved(
    __name__, {"triangle_overlaps": "assemblykit.geometry.occlusion:clip_triangles"}
)
