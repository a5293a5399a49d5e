"""Configuration obstacles of translating convex pieces (Wilson & Latombe 1992, extended
translations)."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from assemblykit.geometry.minkowski import (
    blocking_cone,
    blocks_along,
    convex_bodies,
    overlap_depth,
)
from assemblykit.tolerance import DEFAULT, Tolerance

TOL = Tolerance()


def corners(lo, hi) -> np.ndarray:
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    return np.array(
        [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    )


def as_set(normals) -> set[tuple[float, ...]]:
    return {tuple(np.round(n, 9)) for n in normals}


def test_touching_cube_blocks_the_open_half_space():
    below, above = corners([0, 0, 0], [1, 1, 1]), corners([0, 0, 1], [1, 1, 2])
    cone = blocking_cone(above, below, TOL)  # 'above' blocks 'below'
    assert as_set(cone) == {(0.0, 0.0, 1.0)}
    assert blocks_along(cone, np.array([[0.1, 0, 1], [1, 0, 0], [0, 0, -1]])).tolist() == [
        True,
        False,
        False,
    ]


def test_distant_cube_blocks_a_pyramid_of_directions():
    moving, obstacle = (
        corners([-0.5, -0.5, -0.5], [0.5, 0.5, 0.5]),
        corners([2.5, -0.5, -0.5], [3.5, 0.5, 0.5]),
    )
    # grown obstacle [2, 4] x [-1, 1]^2: rays enter it iff |d_y|, |d_z| < d_x / 2
    cone = blocking_cone(obstacle, moving, TOL)
    expected = {
        tuple(np.round(np.array(v) / np.sqrt(5), 9))
        for v in ([1, 2, 0], [1, -2, 0], [1, 0, 2], [1, 0, -2])
    }
    assert as_set(cone) == expected
    assert blocks_along(cone, np.array([1.0, 0.49, 0.0]))[0]
    assert not blocks_along(cone, np.array([1.0, 0.51, 0.0]))[0]
    assert not blocks_along(cone, np.array([-1.0, 0.0, 0.0]))[0]


def test_overlapping_pieces_block_everything():
    cone = blocking_cone(corners([0, 0, 0], [2, 2, 2]), corners([1, 1, 1], [3, 3, 3]), TOL)
    assert cone.shape == (0, 3)
    assert blocks_along(cone, np.array([[1.0, 0, 0], [0, 0, -1.0]])).all()


def test_convex_pieces_split_bodies():
    a = trimesh.creation.box(extents=(1, 1, 1))
    b = trimesh.creation.box(
        extents=(1, 1, 1), transform=trimesh.transformations.translation_matrix([3, 0, 0])
    )
    pieces = convex_bodies(trimesh.util.concatenate([a, b]), tol=DEFAULT)
    assert pieces is not None and len(pieces) == 2
    assert sorted(round(float(p[:, 0].mean()), 9) for p in pieces) == [0.0, 3.0]


def test_a_hollow_box_is_not_two_convex_solids():
    """A box with a sealed cavity is two shells, the inner one facing inwards: the part is
    not convex (its cavity is empty space, not a second solid)."""
    outer = trimesh.creation.box(extents=(5, 3, 3))
    cavity = trimesh.creation.box(extents=(3, 1, 1))
    cavity.invert()
    hollow = trimesh.util.concatenate([outer, cavity])
    assert hollow.body_count == 2 and hollow.volume == pytest.approx(45 - 3)
    assert convex_bodies(hollow, tol=DEFAULT) is None


def test_a_non_convex_body_has_no_convex_decomposition():
    notch = trimesh.creation.box(extents=(2, 2, 2)).difference(
        trimesh.creation.box(
            extents=(1, 1, 1), transform=trimesh.transformations.translation_matrix([0.5, 0.5, 0.5])
        )
    )
    assert convex_bodies(notch, tol=DEFAULT) is None


def test_a_ring_is_no_convex_body_and_a_cube_beside_it_does_not_change_that():
    # a square ring (a plate with a square hole) has a handle: the hull test finds the
    # hole's points deep inside the hull, and the Euler characteristic says so at once
    ring = trimesh.creation.box(extents=(4, 4, 1)).difference(
        trimesh.creation.box(extents=(2, 2, 2))
    )
    assert ring.is_watertight and ring.euler_number == 0
    assert convex_bodies(ring, tol=DEFAULT) is None
    beside = trimesh.creation.box(
        extents=(1, 1, 1), transform=trimesh.transformations.translation_matrix([6, 0, 0])
    )
    assert convex_bodies(trimesh.util.concatenate([ring, beside]), tol=DEFAULT) is None
    # two cubes apart are two convex bodies (Euler characteristic 4, two bodies)
    apart = trimesh.util.concatenate([beside, trimesh.creation.box(extents=(1, 1, 1))])
    assert apart.euler_number == 4 and len(convex_bodies(apart, tol=DEFAULT) or []) == 2


def test_overlap_depth_is_the_largest_ball_inside_both_hulls():
    # unit cubes sharing a 0.2-thick slab: a ball of radius 0.1 fits in both
    assert overlap_depth(corners([0, 0, 0], [1, 1, 1]), corners([0.8, 0, 0], [1.8, 1, 1])) == (
        pytest.approx(0.1)
    )
    # 0.5 apart: negative, half the gap
    assert overlap_depth(corners([0, 0, 0], [1, 1, 1]), corners([1.5, 0, 0], [2.5, 1, 1])) == (
        pytest.approx(-0.25)
    )


def test_pieces_with_many_vertices_that_overlap_block_every_direction():
    # two spheres of 642 vertices each, interpenetrating: the linear program answers
    # before the hull of 412,164 differences is built
    a = np.asarray(trimesh.creation.icosphere(subdivisions=3).vertices)
    b = a + np.array([1.5, 0.0, 0.0])
    assert len(a) * len(b) > 20_000
    cone = blocking_cone(b, a, TOL)
    assert cone.shape == (0, 3)
    assert blocks_along(cone, np.array([[-1.0, 0.0, 0.0]]))[0]
