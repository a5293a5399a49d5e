from __future__ import annotations

import itertools

import numpy as np
import pytest

from assemblykit.model.packings import box_mesh, guillotine_cells, guillotine_packing


def test_box_mesh_spans_its_corners():
    mesh = box_mesh([1, 2, 3], [2, 4, 7])
    np.testing.assert_allclose(mesh.bounds, [[1, 2, 3], [2, 4, 7]])
    assert mesh.is_watertight and mesh.volume == pytest.approx(8.0)


@pytest.mark.parametrize("n", [1, 2, 17, 40])
def test_guillotine_cells_tile_the_cube_without_overlap(n):
    cells = guillotine_cells(n, seed=3, size=10.0)
    assert len(cells) == n
    assert sum(np.prod(hi - lo) for lo, hi in cells) == pytest.approx(1000.0)
    for (lo1, hi1), (lo2, hi2) in itertools.combinations(cells, 2):
        overlap = np.clip(np.minimum(hi1, hi2) - np.maximum(lo1, lo2), 0, None)
        assert np.prod(overlap) == 0.0


def test_guillotine_packing_is_fixed_by_its_seed():
    a, b, c = guillotine_packing(12, 5), guillotine_packing(12, 5), guillotine_packing(12, 6)
    assert list(a.names) == [f"b{k}" for k in range(12)]
    bounds = [np.asarray(asm.parts[name].mesh.bounds) for asm in (a, b) for name in ("b3",)]
    np.testing.assert_array_equal(*bounds)
    assert not np.array_equal(a.parts["b3"].mesh.bounds, c.parts["b3"].mesh.bounds)
