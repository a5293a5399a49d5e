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
shapely's STRtree over the triangles' bounding boxes with an affine depth bound, the
overlaps every pair's triangles clipped by one another at once (Sutherland & Hodgman
1974, in numpy); overlaps thinner than the length tolerance (shared edges) have no area
and are left out. Triangles within the angle tolerance of parallel to ``d`` project to
nothing and are skipped, and so are those whose projection is thinner than the length
tolerance (a side face tilted by vertex noise): every overlap with them would be too
thin to count. Meshes that do not bound a volume (open or inconsistently wound) use
all their triangles on both sides, which is still exact, only slower.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely
import trimesh
from numpy.typing import ArrayLike, NDArray

from assemblykit.tolerance import Tolerance, current

_FIRST_CHUNK = 1024


def view_frame(direction: ArrayLike) -> NDArray[np.float64]:
    """Rows ``e1, e2, d``: an orthonormal frame whose third axis is the unit ``direction``."""
    d = np.asarray(direction, dtype=np.float64).ravel()
    d = d / np.linalg.norm(d)
    e1 = np.cross(d, np.eye(3)[int(np.argmin(np.abs(d)))])
    e1 /= np.linalg.norm(e1)
    return np.array([e1, np.cross(d, e1), d])


@dataclass(frozen=True, eq=False)
class Shadows:
    """The non-vertical triangles of several meshes seen along a direction.

    ``owner`` is the mesh of each triangle; ``facing`` +1 forwards, -1 backwards, 0 both
    (a mesh that bounds no volume); ``flat`` the projected triangles (t x 3 x 2);
    ``plane`` rows ``(a, b, c)`` with depth ``a u + b v + c`` at ``(u, v)``; ``low`` and
    ``high`` each triangle's depth range and ``box`` its ``(umin, vmin, umax, vmax)``."""

    owner: NDArray[np.int64]
    facing: NDArray[np.int8]
    flat: NDArray[np.float64]
    plane: NDArray[np.float64]
    low: NDArray[np.float64]
    high: NDArray[np.float64]
    box: NDArray[np.float64]

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


def _shadow_width(flat: NDArray[np.float64]) -> NDArray[np.float64]:
    """The smallest altitude of each projected triangle (t x 3 x 2)."""
    edges = np.roll(flat, -1, axis=1) - flat
    double_area = np.abs(edges[:, 0, 0] * edges[:, 1, 1] - edges[:, 0, 1] * edges[:, 1, 0])
    longest = np.linalg.norm(edges, axis=2).max(axis=1)
    return double_area / np.where(longest > 0, longest, 1.0)


def shadows(
    meshes: Sequence[trimesh.Trimesh], direction: ArrayLike, tol: Tolerance | None = None
) -> Shadows:
    """Project the meshes' triangles on the plane ``⟂ direction`` (module docstring)."""
    tol = tol or current()
    frame = view_frame(direction)
    owner, facing, corners, normals = [], [], [], []
    for k, mesh in enumerate(meshes):
        cos = mesh.face_normals @ frame[2]
        flat = np.asarray(mesh.triangles, dtype=np.float64) @ frame[:2].T
        keep = (np.abs(cos) > tol.mesh_angle) & (_shadow_width(flat) > tol.length)
        owner.append(np.full(int(keep.sum()), k, dtype=np.int64))
        # without a consistent outside every triangle may bound the part on either side
        facing.append(np.sign(cos[keep]).astype(np.int8) * np.int8(mesh.is_volume))
        corners.append(np.asarray(mesh.triangles[keep], dtype=np.float64) @ frame.T)
        normals.append(mesh.face_normals[keep] @ frame.T)
    tri = np.concatenate(corners) if corners else np.zeros((0, 3, 3))
    n = np.concatenate(normals) if normals else np.zeros((0, 3))
    # plane n . x = n . p0 solved for the depth coordinate
    plane = np.column_stack(
        [-n[:, 0] / n[:, 2], -n[:, 1] / n[:, 2], np.einsum("ij,ij->i", n, tri[:, 0]) / n[:, 2]]
    )
    return Shadows(
        np.concatenate(owner) if owner else np.zeros(0, np.int64),
        np.concatenate(facing) if facing else np.zeros(0, np.int8),
        tri[:, :, :2],
        plane,
        tri[:, :, 2].min(axis=1),
        tri[:, :, 2].max(axis=1),
        np.column_stack([tri[:, :, :2].min(axis=1), tri[:, :, :2].max(axis=1)]),
    )


def triangle_overlaps(
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
    for e in range(3):
        a, edge = clip[:, e, None], (clip[:, (e + 1) % 3] - clip[:, e])[:, None]
        after = _following(corner)
        side = edge[..., 0] * (points[..., 1] - a[..., 1]) - edge[..., 1] * (
            points[..., 0] - a[..., 0]
        )
        side_after = np.take_along_axis(side, after, axis=1)
        inside = corner & (side >= 0)
        crossing = corner & ((side >= 0) != (side_after >= 0))
        t = side / np.where(crossing, side - side_after, 1.0)
        ahead = np.take_along_axis(points, after[..., None], axis=1)
        candidates = np.stack([points, points + t[..., None] * (ahead - points)], axis=2)
        kept = np.stack([inside, crossing], axis=2).reshape(len(points), -1)
        # the kept points first, in their order around the overlap
        order = np.argsort(~kept, axis=1, kind="stable")[:, : max(int(kept.sum(1).max()), 1)]
        points = np.take_along_axis(candidates.reshape(len(points), -1, 2), order[..., None], 1)
        corner = np.take_along_axis(kept, order, axis=1)
    step = np.take_along_axis(points, _following(corner)[..., None], axis=1) - points
    step[~corner] = 0.0
    twice = points[..., 0] * step[..., 1] - points[..., 1] * step[..., 0]
    area = np.abs(np.where(corner, twice, 0.0).sum(axis=1)) / 2
    return points, corner, area, np.linalg.norm(step, axis=2).sum(axis=1)


def _following(corner: NDArray[np.bool_]) -> NDArray[np.int64]:
    """Per row, the index of the next vertex around the polygon of the first
    ``corner.sum(1)`` points (the last one's is the first)."""
    index = np.arange(corner.shape[1])
    return np.where(index + 1 < corner.sum(axis=1)[:, None], index + 1, 0)


def occluded_pairs(
    view: Shadows, allowed: NDArray[np.bool_], tol: Tolerance | None = None
) -> set[tuple[int, int]]:
    """The pairs ``(i, j)`` of meshes such that ``j`` blocks the extended translation of
    ``i`` along the view direction, among those with ``allowed[i, j]`` (module
    docstring). Triangle pairs are examined by decreasing :meth:`Shadows.bound`, and a
    pair of meshes stops being examined once it blocks."""
    tol = tol or current()
    backward = np.flatnonzero((view.facing <= 0) & np.any(allowed, axis=1)[view.owner])
    forward = np.flatnonzero((view.facing >= 0) & np.any(allowed, axis=0)[view.owner])
    if not len(backward) or not len(forward):
        return set()
    # the tree only compares bounding boxes: each box's diagonal has the same and is
    # cheaper to make than the triangle
    diagonals = shapely.linestrings(np.stack([view.box[:, :2], view.box[:, 2:]], axis=1))
    hits = shapely.STRtree(diagonals[forward]).query(diagonals[backward])
    back, front = backward[hits[0]], forward[hits[1]]
    keep = allowed[view.owner[back], view.owner[front]]
    back, front = back[keep], front[keep]
    bound = view.bound(back, front) * np.maximum(view.cos[front], view.cos[back])
    keep = bound > tol.length
    order = np.argsort(-bound[keep], kind="stable")
    back, front = back[keep][order], front[keep][order]
    found: set[tuple[int, int]] = set()
    size = len(allowed)
    lo, chunk = 0, _FIRST_CHUNK
    while lo < len(back):
        b, f = back[lo : lo + chunk], front[lo : lo + chunk]
        # growing chunks: blocking pairs are usually found in the first, deepest ones
        lo, chunk = lo + chunk, 2 * chunk
        pair = view.owner[b] * size + view.owner[f]
        fresh = ~np.isin(pair, [i * size + j for i, j in found])
        b, f, pair = b[fresh], f[fresh], pair[fresh]
        points, corner, area, perimeter = triangle_overlaps(view.flat[b], view.flat[f])
        which, at = np.nonzero(corner & (area > tol.length * perimeter)[:, None])
        uv = points[which, at]
        b, f, pair = b[which], f[which], pair[which]
        excess = (view.depth(f, uv) - view.depth(b, uv)) * np.maximum(view.cos[f], view.cos[b])
        found |= {(int(p // size), int(p % size)) for p in np.unique(pair[excess > tol.length])}
    return found
