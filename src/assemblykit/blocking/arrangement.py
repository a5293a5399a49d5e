"""Partitions of the direction sphere into regular regions (Wilson & Latombe 1992, "Non-Directional
Blocking Graph" and "Computation of Blocking Graph").

Every blocking constraint "``n . d > 0``" has its boundary on the great circle
``n . d = 0``. The regular regions are the cells of the arrangement of these circles:

* **2D** (directions in the plane z = 0, the circle S¹): the endpoints of the
  diameters perpendicular to the contact normals (points) and the open arcs between
  them; ``k`` distinct diameters give ``2k`` points and ``2k`` arcs.
* **3D** (the sphere S²): vertices where two or more great circles meet, the open
  arcs between them (edges) and the open cells between those (faces), traced as the
  cycles of a doubly connected edge list.

A region is described by a representative unit direction and, for the crossing rule,
by its *links*: ``(low, high, circle, sign)`` says that region ``low`` lies in the
boundary of region ``high`` and that ``high`` is on side ``sign`` of ``circle`` where
``low`` is on it (Wilson & Latombe 1992, crossing rule).

Robustness (the tolerance policy of docs/architecture.md, "Tolerances"): normals parallel
within the angle tolerance are first snapped to one circle; three circles whose
determinant is within rounding error of zero are snapped to one vertex, and the vertices
are closed so that two circles share exactly one pair of antipodal vertices (the
incidences stay consistent for nearly parallel circles, where float signs alone would be
wrong). The side of a direction with respect to a circle uses the angle tolerance, and
rationals when that tolerance is below rounding.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np
from numpy.typing import NDArray
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from assemblykit.algebra.se3 import line_classes
from assemblykit.ragged import group_of, ranges
from assemblykit.tolerance import ModelTolerance

# Rounding error of a 3-term dot product of unit vectors, in units of its magnitude.
_DOT_ROUNDING = 4 * float(np.finfo(np.float64).eps)
_CHUNK = 4096


@dataclass(frozen=True, eq=False)
class Arrangement:
    """The regular regions of the direction circle (``dimension`` 2) or sphere (3).

    ``normals`` (c x 3) are the distinct circle normals; ``directions`` (R x 3) one unit
    direction inside each region and ``dims`` its dimension (0 vertex/point, 1 edge/arc,
    2 face); ``links_*`` the boundary relation with the circle crossed (module docstring).
    ``root`` is the region whose DBG is computed directly and ``root_signs`` its side of
    every circle.
    """

    dimension: int
    normals: NDArray[np.float64]
    directions: NDArray[np.float64]
    dims: NDArray[np.int8]
    links_low: NDArray[np.int64]
    links_high: NDArray[np.int64]
    links_circle: NDArray[np.int64]
    links_sign: NDArray[np.int64]
    root: int
    root_signs: NDArray[np.int8]

    @property
    def counts(self) -> dict[str, int]:
        """Number of regions by kind: ``vertices``, ``edges``, ``faces``."""
        return {
            "vertices": int(np.sum(self.dims == 0)),
            "edges": int(np.sum(self.dims == 1)),
            "faces": int(np.sum(self.dims == 2)),
        }

    def __len__(self) -> int:
        return len(self.dims)


def _exact_sign(a: NDArray[np.float64], b: NDArray[np.float64]) -> int:
    total = sum(
        (Fraction(float(x)) * Fraction(float(y)) for x, y in zip(a, b, strict=True)), Fraction(0)
    )
    return (total > 0) - (total < 0)


def side_signs(
    normals: NDArray[np.float64], directions: NDArray[np.float64], tol: ModelTolerance
) -> NDArray[np.int8]:
    """Side of every direction (rows) with respect to every circle (columns): ``+1``,
    ``-1``, or ``0`` when the direction is within the angle tolerance of the circle.

    Signs whose magnitude is within rounding error (only possible when the angle
    tolerance is below it) are decided exactly (module docstring, robustness)."""
    dots = np.atleast_2d(directions) @ np.asarray(normals, dtype=np.float64).T
    signs = np.sign(dots).astype(np.int8)
    signs[np.abs(dots) <= tol.angle] = 0
    if tol.angle < _DOT_ROUNDING:
        dirs = np.atleast_2d(directions)
        for r, k in zip(*np.nonzero(np.abs(dots) <= _DOT_ROUNDING), strict=True):
            signs[r, k] = _exact_sign(dirs[r], normals[k])
    return signs


def snap_normals(
    normals: NDArray[np.float64], tol: ModelTolerance
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int8]]:
    """Group normals that are parallel or antiparallel within the angle tolerance.

    Returns the distinct circle normals (the first unit normal of each group), the
    circle of each input normal and its orientation (+1 same, -1 opposite)."""
    units = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    return line_classes(units / np.linalg.norm(units, axis=1, keepdims=True), tol.angle)


def _links(
    rows: list[tuple[int, int, int, int]],
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    arr = np.asarray(rows, dtype=np.int64).reshape(-1, 4)
    return arr[:, 0], arr[:, 1], arr[:, 2], arr[:, 3]


def _whole(
    dimension: int, normals: NDArray[np.float64], direction: tuple[float, float, float]
) -> Arrangement:
    """The arrangement of no circle (Wilson & Latombe 1992): the whole direction circle
    (``dimension`` 2) or sphere (3) as one region, represented by ``direction``."""
    return Arrangement(
        dimension,
        normals,
        np.array([direction]),
        np.array([dimension - 1], np.int8),
        *_links([]),
        0,
        np.zeros(0, np.int8),
    )


def circle_partition(normals: NDArray[np.float64], tol: ModelTolerance) -> Arrangement:
    """The partition of S¹ (Wilson & Latombe 1992, 2D case) by the diameters perpendicular to the
    given in-plane circle normals (distinct, z = 0): points and open arcs, in angular
    order, each arc linked to its two endpoints. O(c log c)."""
    normals = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    c = len(normals)
    if c == 0:
        return _whole(2, normals, (1.0, 0.0, 0.0))
    z = np.array([0.0, 0.0, 1.0])
    perp = np.cross(z, normals)
    points = np.concatenate([perp, -perp])
    circle_of = np.concatenate([np.arange(c), np.arange(c)])
    order = np.argsort(np.arctan2(points[:, 1], points[:, 0]))
    points, circle_of = points[order], circle_of[order]
    angles = np.arctan2(points[:, 1], points[:, 0])
    gaps = np.diff(np.append(angles, angles[0] + 2 * np.pi))
    mids = angles + gaps / 2
    arcs = np.column_stack([np.cos(mids), np.sin(mids), np.zeros(2 * c)])
    npts = 2 * c
    rows: list[tuple[int, int, int, int]] = []
    for p in range(npts):
        k = int(circle_of[p])
        ahead = np.cross(z, points[p])  # direction of increasing angle at the point
        s = 1 if normals[k] @ ahead > 0 else -1
        rows.append((p, npts + p, k, s))
        rows.append((p, npts + (p - 1) % npts, k, -s))
    root_signs = side_signs(normals, points[0], tol)[0]
    root_signs[circle_of[0]] = 0
    return Arrangement(
        2,
        normals,
        np.concatenate([points, arcs]),
        np.concatenate([np.zeros(npts, np.int8), np.ones(npts, np.int8)]),
        *_links(rows),
        0,
        root_signs,
    )


def _basis(normals: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Unit vectors e1, e2 with e1 x e2 = n, for each row n."""
    helper = np.where(np.abs(normals[:, [0]]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    e1 = np.cross(normals, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    return e1, np.cross(normals, e1)


def triple_signs(
    normals: NDArray[np.float64], i: NDArray[np.int64], j: NDArray[np.int64]
) -> NDArray[np.int8]:
    """Signs of ``det(n_i, n_j, n_m)`` for every row (i, j) and circle m: on which side
    of circle m the vertex ``n_i x n_j`` lies. Values within rounding error of zero are
    snapped to 0 (circle m passes through the vertex): deciding them exactly would make
    triangles of 1e-16 rad that float angles cannot order (module docstring, robustness)."""
    cross = np.cross(normals[i], normals[j])
    det = cross @ normals.T
    signs = np.sign(det).astype(np.int8)
    bound = _DOT_ROUNDING * (np.linalg.norm(cross, axis=1, keepdims=True) + 1)
    signs[np.abs(det) <= bound] = 0
    rows = np.arange(len(i))
    signs[rows, i] = signs[rows, j] = 0
    return signs


def _incidences(
    vertex: NDArray[np.int64], circle: NDArray[np.int64], circles: int
) -> NDArray[np.int64]:
    """The distinct rows ``(vertex, circle)``, sorted, by one sort of one key per row
    (where many circles meet at a point, as the holes of a plate all do at its normal,
    there are millions of rows)."""
    keys = np.unique(vertex.astype(np.int64) * circles + circle)
    return np.column_stack([keys // circles, keys % circles])


def _vertices(
    normals: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64], NDArray[np.int8]]:
    """The vertices ±v of the arrangement, their (vertex, circle) incidences and the
    side of every circle at vertex 0.

    Circle m passes through the intersection of circles i and j iff
    ``det(n_i, n_j, n_m)`` is zero (:func:`triple_signs`). Pairs of circles meeting at
    one point are merged by connected components, closed so that two circles share one
    vertex pair only (the incidences are then consistent even where snapping is not
    transitive); a vertex is placed at its best-conditioned pair's intersection."""
    c = len(normals)
    ii, jj = np.triu_indices(c, 1)

    def pair_id(a: NDArray[np.int64], b: NDArray[np.int64]) -> NDArray[np.int64]:
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        ids: NDArray[np.int64] = lo * c - lo * (lo + 1) // 2 + (hi - lo - 1)
        return ids

    found = [
        np.nonzero(triple_signs(normals, ii[lo : lo + _CHUNK], jj[lo : lo + _CHUNK]) == 0)
        for lo in range(0, len(ii), _CHUNK)
    ]
    pairs_of = np.concatenate([r + k * _CHUNK for k, (r, _) in enumerate(found)])
    circles_of = np.concatenate([m for _, m in found])
    third = (circles_of != ii[pairs_of]) & (circles_of != jj[pairs_of])
    src = np.repeat(pairs_of[third], 2)
    linked = np.column_stack(
        [
            pair_id(ii[pairs_of[third]], circles_of[third]),
            pair_id(jj[pairs_of[third]], circles_of[third]),
        ]
    ).ravel()
    nv, label = -1, np.zeros(0, np.int64)
    while True:
        graph = coo_matrix((np.ones(len(src)), (src, linked)), shape=(len(ii),) * 2)
        count, label = connected_components(graph, directed=True, connection="weak")
        if count == nv:
            break
        nv = count
        vertex_circle = _incidences(label[pairs_of], circles_of, c)
        cuts = np.flatnonzero(np.diff(vertex_circle[:, 0])) + 1
        for group in np.split(vertex_circle[:, 1], cuts):
            if len(group) > 2:
                a, b = np.triu_indices(len(group), 1)
                ids = pair_id(group[a], group[b])
                src, linked = np.r_[src, ids], np.r_[linked, np.full(len(ids), ids[0])]
    vertex_circle = _incidences(label[pairs_of], circles_of, c)
    cross = np.cross(normals[ii], normals[jj])
    strength = np.linalg.norm(cross, axis=1)
    best = np.empty(nv, dtype=np.int64)
    order = np.argsort(strength)
    best[label[order]] = order  # the strongest pair of each vertex is written last
    v = cross[best] / strength[best, None]
    root_signs = triple_signs(normals, ii[best[:1]], jj[best[:1]])[0]
    root_signs[vertex_circle[vertex_circle[:, 0] == 0, 1]] = 0
    vi, ci = vertex_circle[:, 0], vertex_circle[:, 1]
    both = np.empty((2 * nv, 3))
    both[0::2], both[1::2] = v, -v
    return both, np.concatenate([2 * vi, 2 * vi + 1]), np.concatenate([ci, ci]), root_signs


def sphere_arrangement(normals: NDArray[np.float64]) -> Arrangement:
    """The arrangement of great circles on S² (Wilson & Latombe 1992, 3D case) for distinct
    (snapped) circle normals: vertices, edges and faces with their boundary links. O(c² log c)."""
    normals = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    c = len(normals)
    if c == 0:
        return _whole(3, normals, (0.0, 0.0, 1.0))
    if c == 1:
        e1, _ = _basis(normals)
        return Arrangement(
            3,
            normals,
            np.concatenate([e1, normals, -normals]),
            np.array([1, 2, 2], np.int8),
            *_links([(0, 1, 0, 1), (0, 2, 0, -1)]),
            0,
            np.zeros(1, np.int8),
        )
    verts, inc_v, inc_c, root_signs = _vertices(normals)
    nv = len(verts)
    # edges: consecutive vertices along each circle, by angle
    e1, e2 = _basis(normals)
    p = verts[inc_v]
    theta = np.arctan2(np.einsum("ij,ij->i", p, e2[inc_c]), np.einsum("ij,ij->i", p, e1[inc_c]))
    order = np.lexsort((theta, inc_c))
    vs, cs, th = inc_v[order], inc_c[order], theta[order]
    starts = np.flatnonzero(np.r_[True, cs[1:] != cs[:-1]])
    group_start = np.repeat(starts, np.diff(np.r_[starts, len(cs)]))
    group_end = np.repeat(np.r_[starts[1:], len(cs)], np.diff(np.r_[starts, len(cs)]))
    nxt = np.arange(len(cs)) + 1
    nxt[nxt == group_end] = group_start[nxt == group_end]
    va, vb, circ = vs, vs[nxt], cs
    span = np.mod(th[nxt] - th, 2 * np.pi)
    mid = th + span / 2
    edge_dirs = np.cos(mid)[:, None] * e1[circ] + np.sin(mid)[:, None] * e2[circ]
    ne = len(circ)
    t_start = np.cross(normals[circ], verts[va])  # leaving va along the edge
    t_end = -np.cross(normals[circ], verts[vb])  # leaving vb along the edge
    # vertex -> edge links: the other circles through the vertex, side of the tangent
    inc_order = np.argsort(inc_v, kind="stable")
    z_ptr = np.searchsorted(inc_v[inc_order], np.arange(nv + 1))
    z_idx = inc_c[inc_order]
    rows_low, rows_high, rows_c, rows_s = [], [], [], []
    for vert_of, tang in ((va, t_start), (vb, t_end)):
        size = z_ptr[vert_of + 1] - z_ptr[vert_of]
        edge_rep = group_of(size)
        pos = ranges(z_ptr[vert_of], size)
        others = z_idx[pos]
        keep = others != circ[edge_rep]
        edge_rep, others = edge_rep[keep], others[keep]
        s = np.sign(np.einsum("ij,ij->i", normals[others], tang[edge_rep])).astype(np.int64)
        rows_low.append(vert_of[edge_rep])
        rows_high.append(nv + edge_rep)
        rows_c.append(others)
        rows_s.append(s)
    faces, nf = _faces(verts, va, vb, t_start, t_end)
    face_dirs = np.zeros((nf, 3))
    np.add.at(face_dirs, faces[0::2], edge_dirs)
    np.add.at(face_dirs, faces[1::2], edge_dirs)
    face_dirs /= np.linalg.norm(face_dirs, axis=1, keepdims=True)
    for side in (1, -1):
        rows_low.append(nv + np.arange(ne))
        rows_high.append(nv + ne + faces[(1 - side) // 2 :: 2])
        rows_c.append(circ)
        rows_s.append(np.full(ne, side))
    return Arrangement(
        3,
        normals,
        np.concatenate([verts, edge_dirs, face_dirs]),
        np.concatenate([np.zeros(nv, np.int8), np.ones(ne, np.int8), np.full(nf, 2, np.int8)]),
        np.concatenate(rows_low),
        np.concatenate(rows_high),
        np.concatenate(rows_c),
        np.concatenate(rows_s).astype(np.int8),
        0,
        root_signs,
    )


def _faces(
    verts: NDArray[np.float64],
    va: NDArray[np.int64],
    vb: NDArray[np.int64],
    t_start: NDArray[np.float64],
    t_end: NDArray[np.float64],
) -> tuple[NDArray[np.int64], int]:
    """Face of each half-edge (2e: edge e from va to vb, face on its left = + side of
    the circle; 2e + 1: from vb to va, the - side), by tracing the cycles of a doubly
    connected edge list: the successor of a half-edge arriving at w is the outgoing
    half-edge at w next clockwise from its twin."""
    ne = len(va)
    tail = np.empty(2 * ne, np.int64)
    tail[0::2], tail[1::2] = va, vb
    tangent = np.empty((2 * ne, 3))
    tangent[0::2], tangent[1::2] = t_start, t_end
    f1, f2 = _basis(verts[tail])
    angle = np.arctan2(np.einsum("ij,ij->i", tangent, f2), np.einsum("ij,ij->i", tangent, f1))
    order = np.lexsort((angle, tail))
    sorted_tail = tail[order]
    starts = np.flatnonzero(np.r_[True, sorted_tail[1:] != sorted_tail[:-1]])
    sizes = np.diff(np.r_[starts, len(order)])
    gstart = np.repeat(starts, sizes)
    prev = np.arange(len(order)) - 1
    wrap = prev < gstart
    prev[wrap] = (gstart + sizes.repeat(sizes) - 1)[wrap]
    position = np.empty(2 * ne, np.int64)
    position[order] = np.arange(2 * ne)
    twin = np.arange(2 * ne) ^ 1
    successor = order[prev[position[twin]]]
    graph = coo_matrix((np.ones(2 * ne), (np.arange(2 * ne), successor)), shape=(2 * ne,) * 2)
    nf, labels = connected_components(graph, directed=True, connection="weak")
    return labels.astype(np.int64), int(nf)
