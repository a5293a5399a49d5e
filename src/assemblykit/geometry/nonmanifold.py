"""Closed meshes made 2-manifold where a solid touches itself or another along an edge
(docs/geometry.md, "STEP tessellation").

A solid whose boundary meets itself along a line (a ring whose slit closes to nothing,
two lobes drawn tangent, voxel cubes that share an edge only) tessellates into a closed,
consistently wound mesh in which that edge is shared by four triangles (or six, ...).
The mesh bounds the right volume, but it is no 2-manifold: manifold3d refuses it, and
trimesh does not call it watertight. :func:`split_touching` separates the sheets that
meet there, as the solid's own faces do: around such an edge the triangles are sorted by
the angle at which they leave it, and each triangle is paired with its neighbour across
the wedge of material between them (the side its outward normal turns away from). Each
vertex is then copied once per fan of triangles that these pairs (and the edges shared
by exactly two triangles) join around it, so that the copies lie at the same point and
every edge is shared by two triangles.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import trimesh
from numpy.typing import NDArray
from scipy.sparse.csgraph import connected_components


def split_touching(mesh: trimesh.Trimesh) -> trimesh.Trimesh | None:
    """``mesh`` (closed and consistently wound, some edges shared by more than two
    triangles) with its sheets separated along those edges (module docstring): the
    same triangles in the same order, their vertices copied where sheets meet; ``None``
    when the copies do not make a closed 2-manifold (the mesh has holes, or the
    triangles at an edge do not alternate between its two directions)."""
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    count = len(faces)
    starts = faces.ravel()
    ends = faces[:, [1, 2, 0]].ravel()
    keys = np.sort(np.stack([starts, ends], axis=1), axis=1)
    order = np.lexsort((keys[:, 1], keys[:, 0]))
    first = np.r_[True, np.any(keys[order][1:] != keys[order][:-1], axis=1)]
    bounds = np.r_[np.flatnonzero(first), len(order)]
    sizes = np.diff(bounds)
    if np.any(sizes % 2):
        return None
    pairs = [order[bounds[:-1][sizes == 2]], order[bounds[:-1][sizes == 2] + 1]]
    for start, size in zip(bounds[:-1][sizes > 2], sizes[sizes > 2], strict=True):
        around = _material_pairs(vertices, faces, mesh.face_normals, order[start : start + size])
        if around is None:
            return None
        pairs[0] = np.r_[pairs[0], around[0]]
        pairs[1] = np.r_[pairs[1], around[1]]
    one, other = pairs
    if np.any(starts[one] != ends[other]) or np.any(ends[one] != starts[other]):
        return None
    # half-edge h is the corner h (its start) to the corner after it in its triangle
    after = (np.arange(3 * count) // 3) * 3 + (np.arange(3 * count) + 1) % 3
    joined = sp.coo_matrix(
        (
            np.ones(2 * len(one)),
            (np.r_[one, after[one]], np.r_[after[other], other]),
        ),
        shape=(3 * count, 3 * count),
    )
    _, labels = connected_components(joined, directed=False)
    corner = np.zeros(labels.max() + 1, dtype=np.int64)
    corner[labels] = np.arange(3 * count)
    split = trimesh.Trimesh(vertices[starts[corner]], labels.reshape(-1, 3), process=False)
    return split if split.is_watertight and split.is_winding_consistent else None


def _material_pairs(
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    normals: NDArray[np.float64],
    halves: NDArray[np.int64],
) -> tuple[NDArray[np.int64], NDArray[np.int64]] | None:
    """The half-edges ``halves`` of one edge (indices into the faces' corners) paired
    across the wedges of material about the edge: sorted by the angle at which their
    triangles leave it, each triangle whose material lies towards the larger angle
    with the next one; ``None`` when that does not pair every half-edge once."""
    owner = halves // 3
    start = faces[owner[0], halves[0] % 3]
    end = faces[owner[0], (halves[0] + 1) % 3]
    axis = vertices[end] - vertices[start]
    axis /= np.linalg.norm(axis)
    third = faces[owner, (halves + 2) % 3]
    wings = vertices[third] - vertices[start]
    wings -= np.outer(wings @ axis, axis)
    wings /= np.linalg.norm(wings, axis=1)[:, None]
    across = np.cross(axis, wings[0])
    angles = np.arctan2(wings @ across, wings @ wings[0])
    turning = np.cross(axis, wings)
    ahead = np.einsum("ij,ij->i", -normals[owner], turning) > 0
    ranked = np.argsort(angles, kind="stable")
    leads = np.flatnonzero(ahead[ranked])
    if 2 * len(leads) != len(halves):
        return None
    one, other = ranked[leads], ranked[(leads + 1) % len(halves)]
    if len(np.unique(np.r_[one, other])) != len(halves):
        return None
    return halves[one], halves[other]
