"""The unilateral (push-only) reading of contacts: free-twist cone by linear programming."""

from __future__ import annotations

import numpy as np
import pytest

from assemblykit.motion.unilateral import (
    constraint_rows,
    lift_off_witnesses,
    translation_cone,
    unilateral_reading,
)
from assemblykit.tolerance import Tolerance

TOL = Tolerance()
SQUARE = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
DOWN = np.tile([0.0, 0.0, -1.0], (4, 1))


def _span(vectors: tuple[np.ndarray, ...]) -> np.ndarray:
    """Orthogonal projector onto the span of ``vectors``."""
    basis = np.array(vectors).reshape(-1, 3)
    return basis.T @ np.linalg.pinv(basis.T) if len(basis) else np.zeros((3, 3))


def test_rows_are_moment_and_normal() -> None:
    rows = constraint_rows(np.array([[1.0, 2.0, 3.0]]), np.array([[0.0, 0.0, 1.0]]))
    # p x n = (2, -1, 0); a . (omega; v) = n . (v + omega x p)
    assert rows.tolist() == [[2.0, -1.0, 0.0, 0.0, 0.0, 1.0]]


def test_block_on_table_lifts_off_into_the_upper_hemisphere() -> None:
    reading = unilateral_reading(SQUARE, DOWN, scale=2.0, tol=TOL)
    assert reading.free
    assert len(reading.lift_off) == 1
    np.testing.assert_allclose(reading.lift_off[0], [0.0, 0.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(_span(reading.sliding), np.diag([1.0, 1.0, 0.0]), atol=1e-12)
    np.testing.assert_allclose(reading.witness, [0.0, 0.0, 0.0, 0.0, 0.0, 1.0], atol=1e-12)


def test_block_in_a_corner_has_two_lift_off_rays_and_slides_along_the_edge() -> None:
    wall_points = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 1.0, 1.0], [0.0, 0.0, 1.0]])
    points = np.vstack([SQUARE, wall_points])
    normals = np.vstack([DOWN, np.tile([-1.0, 0.0, 0.0], (4, 1))])
    sliding, rays = translation_cone(normals, TOL)
    np.testing.assert_allclose(np.abs(np.array(sliding)), [[0.0, 1.0, 0.0]], atol=1e-12)
    assert sorted(np.round(r, 12).tolist() for r in rays) == [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]
    assert unilateral_reading(points, normals, 2.0, TOL).free


def test_pointed_cone_has_edge_rays() -> None:
    # three walls of an inside corner: the free translations are the octant x, y, z >= 0
    normals = -np.eye(3)
    sliding, rays = translation_cone(normals, TOL)
    assert sliding == ()
    assert sorted(np.round(r, 12).tolist() for r in rays) == np.eye(3)[::-1].tolist()


def test_enclosed_block_is_held() -> None:
    normals = np.vstack([np.eye(3), -np.eye(3)])
    sliding, rays = translation_cone(normals, TOL)
    assert sliding == () and rays == ()
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    cube_points = np.vstack([corners[np.isclose(corners @ n, 1.0)] for n in normals])
    cube_normals = np.repeat(normals, 4, axis=0)
    assert lift_off_witnesses([(cube_points, cube_normals)], 3.0, TOL) == [None]
    reading = unilateral_reading(cube_points, cube_normals, 3.0, TOL)
    assert not reading.free and reading.witness is None


def test_witness_tips_a_block_when_no_translation_lifts_it() -> None:
    # a floor under the end x = 0 and a ceiling over the end x = 1: no translation
    # leaves them, but turning about y lifts the block off both
    points = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 1.0], [1.0, 1.0, 1.0]])
    normals = np.array([[0.0, 0.0, -1.0], [0.0, 0.0, -1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    reading = unilateral_reading(points, normals, 2.0, TOL)
    assert reading.lift_off == ()
    witness = reading.witness
    assert witness is not None
    slack = constraint_rows(points, normals) @ witness
    assert np.all(slack <= 1e-12)
    assert np.min(slack) < -1e-6
    # no translation breaks a contact, so the witness turns
    assert np.linalg.norm(witness[:3]) > 1e-6


@pytest.mark.parametrize("scale", [1.0, 1000.0])
def test_witness_is_scale_invariant_in_kind(scale: float) -> None:
    witness = lift_off_witnesses([(scale * SQUARE, DOWN)], scale, TOL)[0]
    assert witness is not None
    assert np.all(constraint_rows(scale * SQUARE, DOWN) @ witness <= 1e-9 * scale)


def test_batched_witnesses_match_one_by_one() -> None:
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    normals = np.vstack([np.eye(3), -np.eye(3)])
    cube = (
        np.vstack([corners[np.isclose(corners @ n, 1.0)] for n in normals]),
        np.repeat(normals, 4, axis=0),
    )
    table = (SQUARE, DOWN)
    empty = (np.zeros((0, 3)), np.zeros((0, 3)))
    held, lifted, nothing = lift_off_witnesses([cube, table, empty], 2.0, TOL)
    assert held is None and nothing is None
    assert lifted is not None
    slack = constraint_rows(*table) @ lifted
    assert np.all(slack <= 1e-12) and np.min(slack) < -1e-6
