"""Synthetic assemblies of known structure, for tests, benchmarks and scaling studies.

A *guillotine packing* cuts a cube by planes through whole cells, largest cell first.
Every such packing comes apart by translations alone (undo the cuts in reverse), so a
planner must always find a plan for it; the number of parts and the seed fix it exactly.
"""

from __future__ import annotations

import numpy as np
import trimesh
from numpy.typing import ArrayLike

from assemblykit.model.assembly import Assembly, Part


def box_mesh(lo: ArrayLike, hi: ArrayLike) -> trimesh.Trimesh:
    """The axis-aligned box with opposite corners ``lo`` and ``hi``, as a closed mesh."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    return trimesh.creation.box(
        extents=hi - lo, transform=trimesh.transformations.translation_matrix((lo + hi) / 2)
    )


def guillotine_cells(n: int, seed: int, size: float = 10.0) -> list[tuple[np.ndarray, np.ndarray]]:
    """``n`` boxes ``(lo, hi)`` tiling the cube ``[0, size]^3``: the largest cell is cut
    across a long axis at 30-70 % of its length until there are ``n`` cells."""
    rng = np.random.default_rng(seed)
    cells = [(np.zeros(3), np.full(3, float(size)))]
    while len(cells) < n:
        lo, hi = cells.pop(int(np.argmax([np.prod(h - low) for low, h in cells])))
        axis = int(np.argmax((hi - lo) * rng.uniform(0.5, 1.0, 3)))
        cut = lo[axis] + (hi[axis] - lo[axis]) * rng.uniform(0.3, 0.7)
        upper, lower = hi.copy(), lo.copy()
        upper[axis], lower[axis] = cut, cut
        cells += [(lo, upper), (lower, hi)]
    return cells


def guillotine_packing(n: int, seed: int, size: float = 10.0) -> Assembly:
    """The :func:`guillotine_cells` as an assembly of parts ``b0 .. b{n-1}``."""
    return Assembly(
        [
            Part(f"b{k}", box_mesh(lo, hi))
            for k, (lo, hi) in enumerate(guillotine_cells(n, seed, size))
        ]
    )
