"""Parts made of unit cells (BurrTools pieces, voxel models): the cells of a mesh, and
the extended-translation blocking of such parts along lattice directions decided on the
cells alone (docs/blocking.md, "Three kinds of motion").

Cell ``a`` of a moving part sweeps into cell ``b`` of a still one along ``d`` iff the
ray ``t d`` (``t > 0``) enters the open box ``(b - a - 1, b - a + 1)^3`` (Wilson &
Latombe 1992 §5: the grown obstacle of two cubes). Along a lattice direction ``e`` (each
component -1, 0 or 1), with ``Δ = b - a`` and ``s_k = e_k Δ_k`` on the axes where
``e_k ≠ 0``, the ray is in the box for ``t`` in every interval ``(s_k - 1, s_k + 1)``
and needs ``Δ_k = 0`` on the others: it enters iff ``min s >= 0`` and
``max s - min s <= 1``, integers all. A part blocks another iff one of its cells is so
placed from one of the other's: an exact test in integers, where meshes need their
faces projected.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from assemblykit.tolerance import ModelTolerance

_SPREAD = np.array([0.5 + 1e-3 * np.pi, 0.5 + 1e-3 * np.exp(1.0)])
"""Where in its cell's cross-section a cell is probed (:func:`lattice_cells`): off every
line through two lattice points of a small model, so no probe lies on an edge."""


MAX_CELLS = 4096
"""The most unit cells a part's bounding box may hold for :func:`lattice_cells` to read
its cells (a six-piece burr's pieces hold 32): a large part drawn on whole numbers (a
plate 200 x 100 x 3 in millimetres) is left to its mesh, whose faces are few."""


def lattice_cells(mesh: Any) -> NDArray[np.int64] | None:
    """The unit cells ``[c, c + 1]`` a closed mesh is the union of, when it is one: every
    vertex on the integer lattice and every face square to an axis (a BurrTools piece, a
    part made of voxels), at most :data:`MAX_CELLS` in its bounding box; ``None``
    otherwise. A cell is inside when a ray from a point of it along ``+z`` crosses the
    mesh's faces an odd number of times; the cells must make up the mesh's whole
    volume."""
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    if not len(vertices) or np.prod(np.ptp(vertices, axis=0)) > MAX_CELLS:
        return None
    if not bool(mesh.is_volume):
        return None
    lattice = np.round(vertices)
    normals = np.abs(np.asarray(mesh.face_normals, dtype=np.float64))
    if np.abs(vertices - lattice).max() > 1e-9 or np.abs(normals.max(axis=1) - 1.0).max() > 1e-9:
        return None
    tris = lattice[np.asarray(mesh.faces)]
    flat = tris[normals[:, 2] > 0.5]  # faces square to z
    low, high = lattice.min(axis=0).astype(np.int64), lattice.max(axis=0).astype(np.int64)
    grid = np.stack(
        np.meshgrid(*(np.arange(a, b) for a, b in zip(low, high, strict=True)), indexing="ij"),
        axis=-1,
    ).reshape(-1, 3)
    probe = grid[:, :2] + _SPREAD
    a, b, c = flat[:, 0, :2], flat[:, 1, :2], flat[:, 2, :2]

    def side(p: NDArray[np.float64], q: NDArray[np.float64]) -> NDArray[np.float64]:
        e = (q - p)[None]
        r = probe[:, None, :] - p[None]
        out: NDArray[np.float64] = e[..., 0] * r[..., 1] - e[..., 1] * r[..., 0]
        return out

    s1, s2, s3 = side(a, b), side(b, c), side(c, a)
    within = ((s1 > 0) & (s2 > 0) & (s3 > 0)) | ((s1 < 0) & (s2 < 0) & (s3 < 0))
    above = flat[None, :, 0, 2] > grid[:, None, 2] + 0.5
    cells: NDArray[np.int64] = grid[np.count_nonzero(within & above, axis=1) % 2 == 1]
    if abs(len(cells) - float(mesh.volume)) > 1e-6:
        return None
    return cells


def lattice_direction(
    direction: NDArray[np.float64], tol: ModelTolerance
) -> NDArray[np.int64] | None:
    """The lattice direction ``e`` (components -1, 0 or 1) within the angle tolerance of
    ``direction``, or ``None``."""
    d = np.asarray(direction, dtype=np.float64)
    largest = float(np.abs(d).max(initial=0.0))
    if not largest > 0:
        return None
    e = np.round(d / largest)
    turn = np.linalg.norm(np.cross(d / np.linalg.norm(d), e / np.linalg.norm(e)))
    return e.astype(np.int64) if turn <= tol.angle and float(d @ e) > 0 else None


def cells_block(
    moving: NDArray[np.int64], still: NDArray[np.int64], direction: NDArray[np.int64]
) -> bool:
    """Whether the part of cells ``still`` blocks the extended translation of the part of
    cells ``moving`` along the lattice direction ``direction`` (module docstring)."""
    offsets = (still[None, :, :] - moving[:, None, :]).reshape(-1, 3)
    along = direction != 0
    level = np.all(offsets[:, ~along] == 0, axis=1)
    s = offsets[:, along] * direction[along]
    return bool(np.any(level & (s.min(axis=1) >= 0) & (s.max(axis=1) - s.min(axis=1) <= 1)))
