"""Cells of central hyperplane arrangements in twist space R⁶ (Wilson & Latombe 1992, S⁵)."""

from __future__ import annotations

from math import comb

import numpy as np
import pytest

from assemblykit.blocking.twist_arrangement import arrangement_cells, snap_hyperplanes
from assemblykit.tolerance import DEFAULT


def general_position_count(m: int, d: int) -> int:
    """Regions of m central hyperplanes in general position in R^d."""
    return 2 * sum(comb(m - 1, k) for k in range(d))


def unit_rows(rng: np.random.Generator, m: int, d: int = 6) -> np.ndarray:
    rows = rng.normal(size=(m, d))
    return rows / np.linalg.norm(rows, axis=1, keepdims=True)


def test_region_formula_by_hand():
    # m <= 6 independent hyperplanes in R^6 are coordinate hyperplanes up to a linear map
    assert [general_position_count(m, 6) for m in range(1, 7)] == [2, 4, 8, 16, 32, 64]
    # m = 7: every sign vector but the two forbidden by the one relation among 7 rows
    assert general_position_count(7, 6) == 2**7 - 2 == 126
    assert general_position_count(8, 6) == 240
    assert general_position_count(4, 3) == 14


@pytest.mark.parametrize(("m", "seed"), [(1, 0), (3, 1), (6, 2), (7, 3), (8, 4)])
def test_random_hyperplanes_give_the_general_position_count(m, seed):
    normals = unit_rows(np.random.default_rng(seed), m)
    signs, points = arrangement_cells(normals, tol=DEFAULT)
    assert len(signs) == general_position_count(m, 6)
    assert len({s.tobytes() for s in signs}) == len(signs)
    # each representative lies strictly inside its cell
    assert np.array_equal(np.sign(points @ normals.T), signs)
    assert np.all(np.abs(points @ normals.T) > 1e-6)


def test_rank_deficient_arrangement_counts_in_the_span():
    # four generic hyperplanes whose normals span a 3-space of R^6: 14 cells as in R^3
    rng = np.random.default_rng(5)
    normals = np.hstack([unit_rows(rng, 4, 3), np.zeros((4, 3))])
    signs, points = arrangement_cells(normals, tol=DEFAULT)
    assert len(signs) == 14
    # the representatives drop the sliding part (last three coordinates)
    assert np.allclose(points[:, 3:], 0.0)


def test_no_hyperplane_is_one_cell():
    signs, points = arrangement_cells(np.zeros((0, 6)), tol=DEFAULT)
    assert signs.shape == (1, 0) and points.shape == (1, 6)


def test_snapping_merges_parallel_and_antiparallel_rows():
    a = np.array([1.0, 2.0, 0.0, 0.0, 0.0, 2.0])
    b = np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    planes, index, orient = snap_hyperplanes(np.array([a, -3 * a, b, 2 * a + 1e-12]), tol=DEFAULT)
    assert np.allclose(planes, [a / 3, b])
    assert index.tolist() == [0, 0, 1, 0]
    assert orient.tolist() == [1, -1, 1, 1]
