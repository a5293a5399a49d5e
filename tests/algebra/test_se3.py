"""Rigid transforms and twists (src/assemblykit/algebra/se3.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from assemblykit.algebra import se3
from assemblykit.tolerance import Tolerance

seeds = st.integers(min_value=0, max_value=2**32 - 1)


def test_rot_z_quarter_turn_maps_x_to_y():
    np.testing.assert_allclose(
        se3.apply(se3.rot_z(math.pi / 2), (1.0, 0.0, 0.0)), (0, 1, 0), atol=1e-15
    )


def test_rotation_about_offset_line_keeps_the_line_fixed():
    t = se3.rotation((0, 0, 1), math.pi, point=(1.0, 0.0, 0.0))
    np.testing.assert_allclose(se3.apply(t, (1.0, 0.0, 5.0)), (1, 0, 5), atol=1e-15)
    np.testing.assert_allclose(se3.apply(t, (0.0, 0.0, 0.0)), (2, 0, 0), atol=1e-15)


def test_screw_one_turn_is_a_translation_by_the_lead():
    # docs/algebra.md §6, W16: with p = 1/(2 pi), Scr(2 pi k; p) = Tr(0, 0, k).
    for k in (-2, 1, 3):
        t = se3.screw((0, 0, 0), (0, 0, 1), 1 / (2 * math.pi), 2 * math.pi * k)
        np.testing.assert_allclose(t, se3.translation((0, 0, k)), atol=1e-12)


def test_frame_is_right_handed_with_requested_z_and_hint():
    f = se3.frame((1, 2, 3), (0, 0, 2), x_hint=(0, 1, 0))
    np.testing.assert_allclose(f[:3, :3], [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-15)
    np.testing.assert_allclose(f[:3, 3], (1, 2, 3))
    g = se3.frame((0, 0, 0), (1, 1, 0))
    assert np.isclose(np.linalg.det(g[:3, :3]), 1.0)
    np.testing.assert_allclose(g[:3, 2], np.array([1, 1, 0]) / math.sqrt(2))


def test_hat_vee_and_adjoint_formula():
    xi = np.array([0.1, -0.2, 0.3, 1.0, 2.0, 3.0])
    np.testing.assert_allclose(se3.vee(se3.hat(xi)), xi)
    t = se3.translation((1, 0, 0)) @ se3.rot_z(math.pi / 2)
    # Ad_g (omega; v) = (R omega; R v + t x R omega)
    out = se3.adjoint(t) @ np.array([0, 0, 1, 0, 0, 0.0])
    np.testing.assert_allclose(out, [0, 0, 1, 0, -1, 0], atol=1e-15)


def test_exp_of_rotation_twist_about_offset_line():
    # (u; N x u) with N = (1, 0, 0), u = z, N x u = (0, -1, 0): rotation about that line.
    xi = np.array([0.0, 0.0, math.pi, 0.0, -math.pi, 0.0])
    np.testing.assert_allclose(se3.exp(xi), se3.rotation((0, 0, 1), math.pi, (1, 0, 0)), atol=1e-12)


def test_is_rigid_rejects_scaling_and_reflection():
    assert se3.is_rigid(se3.rot_x(0.3))
    assert not se3.is_rigid(np.diag([1.0, 1.0, -1.0, 1.0]))
    assert not se3.is_rigid(np.diag([2.0, 1.0, 1.0, 1.0]), Tolerance())


def test_rotation_angle_near_pi():
    assert se3.rotation_angle(se3.rot_x(math.pi)) == pytest.approx(math.pi)
    assert se3.rotation_angle(se3.rot_y(-0.25)) == pytest.approx(0.25)


@settings(max_examples=50, deadline=None)
@given(seeds)
def test_exp_log_round_trip_and_inverse(seed):
    rng = np.random.default_rng(seed)
    t = se3.random_transform(rng)
    np.testing.assert_allclose(se3.exp(se3.log(t)), t, atol=1e-9)
    np.testing.assert_allclose(t @ se3.inverse(t), np.eye(4), atol=1e-12)


@settings(max_examples=50, deadline=None)
@given(seeds)
def test_adjoint_is_conjugation_of_twists(seed):
    rng = np.random.default_rng(seed)
    t = se3.random_transform(rng)
    xi = rng.normal(size=6)
    np.testing.assert_allclose(
        se3.hat(se3.adjoint(t) @ xi), t @ se3.hat(xi) @ se3.inverse(t), atol=1e-9
    )


def test_frame_default_x_is_the_least_aligned_coordinate_axis():
    # z = (0.3, 0.4, 0.5): x comes from e1 made perpendicular; ties pick the first axis.
    f = se3.frame((1, 2, 3), (0.3, 0.4, 0.5))
    z = np.array((0.3, 0.4, 0.5)) / math.sqrt(0.5)
    e1 = np.array((1.0, 0.0, 0.0))
    x = e1 - (e1 @ z) * z
    np.testing.assert_allclose(f[:3, 0], x / np.linalg.norm(x), atol=1e-15)
    np.testing.assert_allclose(f[:3, 2], z, atol=1e-15)
    np.testing.assert_allclose(f[:3, 3], (1, 2, 3))
    np.testing.assert_array_equal(se3.frame((0, 0, 0), (0, 0, 2.0)), np.eye(4))
    np.testing.assert_array_equal(se3.frame((0, 0, 0), (1.0, 0, 0))[:3, 0], (0, 1, 0))


def test_frame_from_floats_gives_the_columns_of_frame():
    x, y, z, o = se3.frame_from_floats((1.0, 2.0, 3.0), (0.0, 0.0, 1.0), (1.0, 1.0, 5.0))
    s = 1 / math.sqrt(2)
    assert x == pytest.approx((s, s, 0.0)) and y == pytest.approx((-s, s, 0.0))
    assert z == (0.0, 0.0, 1.0) and o == (1.0, 2.0, 3.0)
    np.testing.assert_array_equal(
        se3.matrix_from_columns((x, y, z, o)), se3.frame((1, 2, 3), (0, 0, 1), (1, 1, 5))
    )
    assert se3.as_floats(np.array([1, 2, 3])) == (1.0, 2.0, 3.0)


@settings(max_examples=50, deadline=None)
@given(seeds)
def test_inverse_is_exact_on_rigid_transforms(seed):
    t = se3.random_transform(np.random.default_rng(seed))
    np.testing.assert_allclose(se3.inverse(t) @ t, np.eye(4), atol=1e-13)
    np.testing.assert_allclose(se3.inverse(t), np.linalg.inv(t), atol=1e-12)
    assert se3.inverse(t)[3].tolist() == [0.0, 0.0, 0.0, 1.0]


def test_line_classes_group_parallel_and_antiparallel_vectors():
    vectors = np.array([[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, 1e-7, 1.0], [1, 1e-6, 0]])
    leaders, index, orient = se3.line_classes(vectors, 1e-5)
    np.testing.assert_array_equal(leaders, [[1, 0, 0], [0, 1, 0], [0, 1e-7, 1.0]])
    assert index.tolist() == [0, 1, 0, 2, 0]
    assert orient.tolist() == [1, 1, -1, 1, 1]


def test_line_classes_join_the_nearest_earlier_leader():
    """A vector within reach of two leaders joins the nearer one, not the first; a
    leader found after a vector never takes it."""
    turned = [np.array([np.cos(t), np.sin(t), 0.0]) for t in (0.0, 0.16, 0.3)]
    a, v, b = turned
    leaders, index, orient = se3.line_classes(np.array([a, v, b, -v]), 0.2)
    np.testing.assert_array_equal(leaders, [a, b])
    assert index.tolist() == [0, 0, 1, 1]  # sin 0.16 to a, sin 0.14 to b
    assert orient.tolist() == [1, 1, 1, -1]


@given(st.lists(st.tuples(*[st.floats(-1, 1) for _ in range(3)]), max_size=40), st.floats(0, 1))
@settings(max_examples=200, deadline=None)
def test_line_classes_match_one_vector_at_a_time(rows, max_sine):
    """The classes equal those of taking the vectors one by one, each joining the first
    nearest earlier leader within ``max_sine`` or leading a new class."""
    vectors = np.array([r for r in rows if np.linalg.norm(r) > 1e-3]).reshape(-1, 3)
    vectors /= np.maximum(np.linalg.norm(vectors, axis=1, keepdims=True), 1e-300)
    leaders: list[np.ndarray] = []
    expected = []
    for v in vectors:
        sines = [np.linalg.norm(np.cross(u, v)) for u in leaders]
        if sines and min(sines) <= max_sine:
            k = int(np.argmin(sines))
            expected.append((k, 1 if leaders[k] @ v > 0 else -1))
        else:
            leaders.append(v)
            expected.append((len(leaders) - 1, 1))
    found, index, orient = se3.line_classes(vectors, max_sine)
    np.testing.assert_array_equal(found, np.array(leaders).reshape(-1, 3))
    assert list(zip(index.tolist(), orient.tolist(), strict=True)) == expected


rotation_vectors = st.builds(
    lambda axis, angle: angle * np.asarray(axis) / np.linalg.norm(axis),
    st.tuples(*[st.floats(-1, 1) for _ in range(3)]).filter(lambda a: np.linalg.norm(a) > 1e-3),
    st.one_of(
        st.floats(0.0, math.pi),
        st.floats(0.0, 1e-7),
        st.floats(math.pi - 1e-7, math.pi),
    ),
)


@given(rotation_vectors)
@settings(max_examples=300, deadline=None)
def test_rotation_matrix_and_vector_agree_with_scipy(w):
    """Rodrigues' formula and the quaternion logarithm against scipy's Rotation, also
    within 1e-7 of angle 0 and of angle pi (where the axis sign is ambiguous)."""
    from scipy.spatial.transform import Rotation

    r = se3.rotation_matrix(w)
    np.testing.assert_allclose(r, Rotation.from_rotvec(w).as_matrix(), atol=1e-12)
    back = se3.rotation_vector(r)
    np.testing.assert_allclose(se3.rotation_matrix(back), r, atol=1e-12)
    assert np.linalg.norm(back) == pytest.approx(np.linalg.norm(w), abs=1e-9)
    if np.linalg.norm(w) < math.pi - 1e-6:
        np.testing.assert_allclose(back, w, atol=1e-9)


def test_rotation_vector_of_half_turns_and_identity():
    assert se3.rotation_vector(np.eye(3)).tolist() == [0.0, 0.0, 0.0]
    half_x = np.diag([1.0, -1.0, -1.0])
    assert np.abs(se3.rotation_vector(half_x)).tolist() == pytest.approx([math.pi, 0.0, 0.0])
    quarter_z = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    assert se3.rotation_vector(quarter_z) == pytest.approx([0.0, 0.0, math.pi / 2])


unit_axes = st.tuples(*(st.floats(-1.0, 1.0) for _ in range(3))).filter(
    lambda v: math.sqrt(sum(c * c for c in v)) > 1e-3
)


@given(unit_axes, st.booleans())
@settings(max_examples=200, deadline=None)
def test_axis_basis_is_orthonormal_and_right_handed(v, turned):
    n = se3.unit(np.array(v))
    u, w = se3.axis_basis(n, turned=turned)
    frame = np.column_stack([u, w, n])
    np.testing.assert_allclose(frame.T @ frame, np.eye(3), atol=1e-12)
    assert np.linalg.det(frame) == pytest.approx(1.0)


@given(seeds, st.booleans())
@settings(max_examples=50, deadline=None)
def test_axis_basis_of_rows_is_the_basis_of_each_row(seed, turned):
    rows = np.random.default_rng(seed).normal(size=(5, 3))
    rows /= np.linalg.norm(rows, axis=1, keepdims=True)
    u, w = se3.axis_basis(rows, turned=turned)
    for i, n in enumerate(rows):
        one_u, one_w = se3.axis_basis(n, turned=turned)
        np.testing.assert_allclose(u[i], one_u, atol=1e-15)
        np.testing.assert_allclose(w[i], one_w, atol=1e-15)


@given(unit_axes)
@settings(max_examples=200, deadline=None)
def test_turned_axis_basis_is_the_frame_turned_half_a_turn_about_the_axis(v):
    n = se3.unit(np.array(v))
    u, w = se3.axis_basis(n, turned=True)
    plain_u, plain_w = se3.axis_basis(n)
    np.testing.assert_array_equal(u, -plain_u)
    np.testing.assert_array_equal(w, -plain_w)


def test_turned_axis_basis_keeps_the_signs_of_zero_of_the_cross_products():
    # along a coordinate axis the plain frame negated has -0.0 where n x e has 0.0
    for n in np.vstack([np.eye(3), -np.eye(3)]):
        least = np.eye(3)[int(np.argmin(np.abs(n)))]
        u, w = se3.axis_basis(n, turned=True)
        expected_u = np.cross(n, least)
        expected_u /= np.linalg.norm(expected_u)
        np.testing.assert_array_equal(np.signbit(u), np.signbit(expected_u))
        np.testing.assert_array_equal(np.signbit(w), np.signbit(np.cross(n, expected_u)))


@given(seeds)
@settings(max_examples=100, deadline=None)
def test_poses_equal_is_symmetric_and_scales_with_the_tolerance(seed):
    rng = np.random.default_rng(seed)
    a = se3.random_transform(rng)
    tol = Tolerance(scale=10.0)
    near = se3.translation((0.5 * tol.length, 0.0, 0.0)) @ a
    far = se3.translation((2.0 * tol.length, 0.0, 0.0)) @ a
    assert se3.poses_equal(a, a, tol)
    assert se3.poses_equal(a, near, tol) and se3.poses_equal(near, a, tol)
    assert not se3.poses_equal(a, far, tol) and not se3.poses_equal(far, a, tol)
    # the same offsets measured on a model ten times larger are within tolerance
    assert se3.poses_equal(a, far, Tolerance(scale=100.0))
    turned = se3.rotation((0.0, 0.0, 1.0), 10.0 * tol.angle) @ a
    assert not se3.poses_equal(a, turned, tol) and not se3.poses_equal(turned, a, tol)


def test_poses_equal_from_numeric_solvers_takes_the_looser_mesh_tolerance():
    tol = Tolerance(rel_length=1e-9, angle=1e-9)
    a = np.eye(4)
    b = se3.translation((0.5 * (tol.length + tol.mesh_length), 0.0, 0.0))
    assert tol.mesh_length > tol.length
    assert not se3.poses_equal(a, b, tol)
    assert se3.poses_equal(a, b, tol, numeric=True)


def test_random_starts_are_deterministic_and_scaled():
    angles = np.array([True, False, True])
    first = list(se3.random_starts(angles, 5.0, 6))
    again = list(se3.random_starts(angles, 5.0, 6))
    assert len(first) == 6 and np.array_equal(first[0], np.zeros(3))
    assert all(np.array_equal(x, y) for x, y in zip(first, again, strict=True))
    stacked = np.array(first[1:])
    assert np.all(np.abs(stacked[:, [0, 2]]) <= math.pi)
    assert np.all(np.abs(stacked[:, 1]) <= 5.0)


def test_multistart_least_squares_finds_both_roots_of_a_two_root_system():
    # (x - 1)(x + 2) = 0 with y = x: the roots (1, 1) and (-2, -2)
    def residual(p: np.ndarray) -> np.ndarray:
        return np.array([(p[0] - 1.0) * (p[0] + 2.0), p[1] - p[0]])

    starts = [np.array([3.0, 0.0]), np.array([-4.0, 0.0])]
    roots = [fit.x for fit in se3.multistart_least_squares(residual, starts, method="lm")]
    np.testing.assert_allclose(roots[0], (1.0, 1.0), atol=1e-9)
    np.testing.assert_allclose(roots[1], (-2.0, -2.0), atol=1e-9)
