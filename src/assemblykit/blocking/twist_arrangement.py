"""The arrangement of central hyperplanes in twist space R⁶: its full-dimensional cells
(the 5-dimensional regular regions of S⁵ of Wilson & Latombe 1992, "Infinitesimal rigid motions").

Each contact point gives a hyperplane ``a . xi = 0`` through the origin; the cells are
the sign vectors ``sign(A xi)`` with no zero that some twist ``xi`` realises. They are
enumerated by a breadth-first walk: from a cell, crossing hyperplane ``h`` leads to the
sign vector with ``h`` flipped, which is a cell exactly when ``h`` bounds the current
cell by a facet (the two sides of ``h`` inside the convex cone of the other
hyperplanes' signs are then both open and non-empty). Each candidate is decided by a
linear program (scipy ``linprog``, HiGHS) that maximises the smallest margin of a point
inside it; the point found is kept as the cell's representative.
"""

from __future__ import annotations

from collections import deque

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linprog

from assemblykit.errors import NumericError
from assemblykit.tolerance import ModelTolerance


def snap_hyperplanes(
    rows: NDArray[np.float64], tol: ModelTolerance
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int8]]:
    """Group rows (m x d) that define the same central hyperplane (parallel or antiparallel
    within the mesh angle tolerance: contact points come from meshes).

    Returns the distinct unit normals (the first row of each group), the hyperplane of
    each row and its orientation (+1 same, -1 opposite)."""
    units = np.asarray(rows, dtype=np.float64)
    units = units / np.linalg.norm(units, axis=1, keepdims=True)
    planes: list[NDArray[np.float64]] = []
    index = np.empty(len(units), dtype=np.int64)
    orient = np.empty(len(units), dtype=np.int8)
    for i, a in enumerate(units):
        if planes:
            dots = np.asarray(planes) @ a
            k = int(np.argmax(np.abs(dots)))
            # sine of the angle between the two lines, stable near 0
            if np.sqrt(max(0.0, 1.0 - dots[k] ** 2)) <= tol.mesh_angle:
                index[i], orient[i] = k, 1 if dots[k] > 0 else -1
                continue
        planes.append(a)
        index[i], orient[i] = len(planes) - 1, 1
    return np.asarray(planes, dtype=np.float64).reshape(-1, units.shape[1]), index, orient


def cell_point(
    normals: NDArray[np.float64], signs: NDArray[np.int8], tol: ModelTolerance
) -> NDArray[np.float64] | None:
    """A point ``x`` in the box ``|x_i| <= 1`` with ``signs * (normals @ x)`` at least a
    common margin as large as possible (linear program), or ``None`` when that margin
    does not exceed the mesh angle tolerance (HiGHS solves to about 1e-7): the sign
    vector is then no full-dimensional cell."""
    m, d = normals.shape
    result = linprog(
        c=np.r_[np.zeros(d), -1.0],
        A_ub=np.column_stack([-signs[:, None] * normals, np.ones(m)]),
        b_ub=np.zeros(m),
        bounds=[(-1.0, 1.0)] * d + [(None, 1.0)],
        method="highs",
    )
    if result.status != 0 or -result.fun <= tol.mesh_angle:
        return None
    return np.asarray(result.x[:d], dtype=np.float64)


def arrangement_cells(
    normals: NDArray[np.float64], tol: ModelTolerance
) -> tuple[NDArray[np.int8], NDArray[np.float64]]:
    """Every full-dimensional cell of the arrangement of the central hyperplanes with
    the given unit ``normals`` (m x d): their sign vectors (R x m, entries ±1) and one
    interior point of each (R x d), in the span of the normals, in breadth-first order
    (module docstring). With no hyperplane the whole space is one cell."""
    m, d = normals.shape
    if m == 0:
        return np.ones((1, 0), dtype=np.int8), np.eye(d)[:1]
    # the first cell: the one containing the direction of least alignment with any
    # hyperplane among a few fixed generic directions
    generic = np.random.default_rng(0).normal(size=(16, d))
    start = generic[int(np.argmax(np.min(np.abs(generic @ normals.T), axis=1)))]
    first = np.where(normals @ start > 0, 1, -1).astype(np.int8)
    point = cell_point(normals, first, tol)
    if point is None:
        raise NumericError("twist arrangement: no cell found around a generic twist")
    cells: dict[bytes, int] = {first.tobytes(): 0}
    signs, points = [first], [point]
    empty: set[bytes] = set()
    queue = deque([0])
    while queue:
        current_signs = signs[queue.popleft()]
        for h in range(m):
            flipped = current_signs.copy()
            flipped[h] = -flipped[h]
            key = flipped.tobytes()
            if key in cells or key in empty:
                continue
            found = cell_point(normals, flipped, tol)
            if found is None:
                empty.add(key)
                continue
            cells[key] = len(signs)
            queue.append(len(signs))
            signs.append(flipped)
            points.append(found)
    # drop the part along the common null space of the normals, where every constraint
    # slides: it does not change the signs and would only blur the representatives
    on_span = np.linalg.pinv(normals) @ normals
    return np.asarray(signs, dtype=np.int8), np.asarray(points, dtype=np.float64) @ on_span.T
