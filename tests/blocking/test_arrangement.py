"""Partitions of S¹ and arrangements of great circles on S² (Wilson & Latombe 1992)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from assemblykit.blocking.arrangement import (
    circle_partition,
    side_signs,
    snap_normals,
    sphere_arrangement,
)
from assemblykit.tolerance import Tolerance

TOL = Tolerance()


def unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v)


def test_snap_merges_parallel_and_antiparallel_within_angle():
    tiny = 1e-12
    normals = np.array([[1, 0, 0], [-1, tiny, 0], [0, 1, 0], [1, 1e-5, 0]], dtype=float)
    circles, index, orient = snap_normals(normals, TOL)
    assert len(circles) == 3
    assert index.tolist() == [0, 0, 1, 2]
    assert orient.tolist() == [1, -1, 1, 1]


def test_circle_partition_has_4k_regions():
    normals = np.array([unit([np.cos(a), np.sin(a), 0]) for a in (0.1, 0.7, 2.0)])
    arr = circle_partition(normals, TOL)
    assert arr.counts == {"vertices": 6, "edges": 6, "faces": 0}
    # points are perpendicular to a normal, arcs are not
    dots = np.abs(arr.directions @ normals.T)
    assert np.all(dots[arr.dims == 0].min(axis=1) < 1e-12)
    assert np.all(dots[arr.dims == 1].min(axis=1) > 1e-3)


def test_three_orthogonal_circles_make_an_octahedron():
    arr = sphere_arrangement(np.eye(3))
    assert arr.counts == {"vertices": 6, "edges": 12, "faces": 8}
    faces = arr.directions[arr.dims == 2]
    assert np.allclose(np.abs(faces), 1 / np.sqrt(3))
    assert len({tuple(np.sign(f)) for f in faces}) == 8


def test_concurrent_circles_share_vertices():
    # four circles through the z axis plus the equator: 2 vertices of degree 4 + 8
    normals = [unit([np.cos(a), np.sin(a), 0]) for a in (0.0, 0.5, 1.2, 2.2)] + [[0, 0, 1]]
    arr = sphere_arrangement(np.array(normals))
    assert arr.counts == {"vertices": 10, "edges": 24, "faces": 16}


def test_triple_concurrent_up_to_rounding_is_one_vertex():
    # exactly, these three circles make a triangle of about 1e-19 rad (the last digits of
    # the two tilted normals differ): snapped, they share one vertex pair
    near = np.array(
        [
            [-0.7071067811865476, 0.7071067811865476, 0.0],
            [-0.9999920637125159, 0.0, 0.00398403212634469],
            [0.0, -0.9999920637125158, 0.00398403212634469],
        ]
    )
    assert sphere_arrangement(near).counts == {"vertices": 2, "edges": 6, "faces": 6}
    # 1e-13 rad off is a genuine (small) triangle: general position
    far = np.array([[1, 0, 0], [0, 1, 0], unit([1, 1, 1e-13])])
    assert sphere_arrangement(far).counts == {"vertices": 6, "edges": 12, "faces": 8}


def test_exact_sign_near_zero():
    tight = Tolerance(angle=1e-20)
    n = np.array([[1.0, 1e-17, 0.0]])
    d = np.array([[1e-17, -1.0, 0.0]])  # float dot rounds to 0, exactly it is 0 too
    assert side_signs(n, d, tight)[0, 0] == 0
    d2 = np.array([[3e-17, -1.0, 0.0]])  # exact: 3e-17 - 1e-17 > 0
    assert side_signs(n, d2, tight)[0, 0] == 1


@settings(max_examples=25, deadline=None)
@given(st.integers(min_value=2, max_value=9), st.integers(min_value=0, max_value=10_000))
def test_general_position_counts_and_euler(c, seed):
    rng = np.random.default_rng(seed)
    normals = rng.normal(size=(c, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    arr = sphere_arrangement(normals)
    v, e, f = arr.counts.values()
    assert (v, e, f) == (c * (c - 1), 2 * c * (c - 1), c * (c - 1) + 2)
    # every face representative is strictly off every circle
    faces = arr.directions[arr.dims == 2]
    assert np.all(side_signs(normals, faces, TOL) != 0)
    # the face directions are pairwise in different cells
    signs = side_signs(normals, faces, TOL)
    assert len({tuple(s) for s in signs}) == f
