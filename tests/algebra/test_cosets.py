"""Relation cosets: the worked examples W1-W21 of docs/algebra.md §6 at the algebra level
(src/assemblykit/algebra/cosets.py). Relations are built with ``transporter`` as §5.1
prescribes: 'against' maps the body-2 plane with its normal negated onto the body-1 plane."""

from __future__ import annotations

import math
from unittest import mock

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from assemblykit.algebra import (
    Chain,
    Coset,
    EmptySet,
    Kind,
    LineInvariant,
    PlaneInvariant,
    PointInvariant,
    SymmetryGroup,
    cosets,
    intersect_groups,
    se3,
    transform_invariant,
    transporter,
)
from assemblykit.tolerance import Tolerance

Z = (0.0, 0.0, 1.0)
ORIGIN = (0.0, 0.0, 0.0)
HALF_PI = math.pi / 2
seeds = st.integers(min_value=0, max_value=2**32 - 1)


def tr(x, y, z):
    return se3.translation((x, y, z))


def against(face1, face2):
    """B2's plane (point, outward normal) against B1's plane."""
    return transporter([PlaneInvariant(*face1)], [PlaneInvariant(face2[0], -np.asarray(face2[1]))])


def fits(axis1, axis2, directed=True):
    """B2's shaft axis in B1's hole axis (equal radii assumed)."""
    return transporter(
        [LineInvariant(*axis1, directed=directed)], [LineInvariant(*axis2, directed=directed)]
    )


def ball(socket, ball_center):
    return transporter([PointInvariant(socket)], [PointInvariant(ball_center)])


def meet(*cosets):
    out = cosets[0]
    for c in cosets[1:]:
        out = out.intersect(c)
    return out


FLOOR = ((0, 0, 0), (0, 0, 1))
BOTTOM = ((0, 0, 0), (0, 0, -1))
WALL_X = ((0, 0, 0), (1, 0, 0))
LEFT = ((0, 0, 0), (-1, 0, 0))


def test_w1_single_against_is_planar():
    c = against(FLOOR, BOTTOM)
    assert c.kind is Kind.PLANAR and c.dof == 3 and c.n_components == 1
    assert c.contains(tr(1, 2, 0) @ se3.rot_z(0.3))
    assert not c.contains(tr(0, 0, 0.1)) and not c.contains(se3.rot_x(0.1))


def test_w2_two_perpendicular_against_is_prismatic_along_y():
    c = meet(against(FLOOR, BOTTOM), against(WALL_X, LEFT))
    assert c.kind is Kind.PRISMATIC and c.dof == 1
    np.testing.assert_allclose(abs(c.invariants()["direction"] @ (0, 1, 0)), 1.0)
    assert c.contains(tr(0, -3, 0)) and c.contains(tr(0, 2.5, 0))
    assert not c.contains(tr(0.1, 0, 0)) and not c.contains(se3.rot_z(0.1))
    cube2 = meet(against(FLOOR, ((1, 1, 0), (0, 0, -1))), against(WALL_X, ((0, 1, 1), (-1, 0, 0))))
    assert cube2.kind is Kind.PRISMATIC and cube2.contains(tr(0, 7, 0))


def test_w3_three_against_fix_the_block():
    c = meet(
        against(FLOOR, BOTTOM),
        against(WALL_X, LEFT),
        against((ORIGIN, (0, 1, 0)), (ORIGIN, (0, -1, 0))),
    )
    assert c.is_point
    np.testing.assert_allclose(c.points()[0], np.eye(4), atol=1e-12)
    corner = (1, 2, 3)
    off = meet(
        against((corner, Z), BOTTOM),
        against((corner, (1, 0, 0)), LEFT),
        against((corner, (0, 1, 0)), (ORIGIN, (0, -1, 0))),
    )
    assert off.is_point
    np.testing.assert_allclose(off.rep, tr(1, 2, 3), atol=1e-12)


def test_w3b_angle_mismatch_of_10_degrees():
    s, c = math.sin(math.radians(10)), math.cos(math.radians(10))
    out = meet(against(FLOOR, BOTTOM), against(WALL_X, (ORIGIN, (-c, 0, s))))
    assert isinstance(out, EmptySet) and out.proven
    assert out.mismatch.kind == "angle"
    assert math.degrees(out.mismatch.value) == pytest.approx(10.0)
    assert "angle mismatch 10°" in out.mismatch.message


def test_w4_pin_in_hole_with_shoulder_is_revolute():
    down = (0, 0, -1)
    c = meet(against(FLOOR, BOTTOM), fits((ORIGIN, down), (ORIGIN, down)))
    assert c.kind is Kind.REVOLUTE and c.dof == 1
    np.testing.assert_allclose(c.invariants()["point"][:2], (0, 0), atol=1e-12)
    assert c.contains(se3.rot_z(1.0)) and c.contains(se3.rot_z(-2.0))
    assert not c.contains(tr(0, 0, 1)) and not c.contains(tr(1, 0, 0))


def test_w5_two_parallel_pins_is_prismatic_with_quarter_turn():
    c = meet(fits((ORIGIN, Z), (ORIGIN, Z)), fits(((10, 0, 0), Z), ((0, 10, 0), Z)))
    assert c.kind is Kind.PRISMATIC and c.n_components == 1
    assert c.contains(se3.rot_z(-HALF_PI)) and c.contains(tr(0, 0, 7) @ se3.rot_z(-HALF_PI))
    assert not c.contains(np.eye(4))
    undirected = meet(
        fits((ORIGIN, Z), (ORIGIN, Z), directed=False),
        fits(((10, 0, 0), Z), ((10, 0, 0), Z), False),
    )
    assert undirected.kind is Kind.PRISMATIC and undirected.n_components == 2
    assert undirected.contains(tr(0, 0, 4)) and undirected.contains(
        se3.rot_x(math.pi) @ tr(0, 0, 4)
    )
    assert not undirected.contains(se3.rot_z(math.pi))


def test_w6_unequal_spacing_is_a_distance_mismatch_of_2():
    out = meet(fits((ORIGIN, Z), (ORIGIN, Z)), fits(((10, 0, 0), Z), ((12, 0, 0), Z)))
    assert isinstance(out, EmptySet) and out.mismatch.kind == "distance"
    assert out.mismatch.value == pytest.approx(2.0)


def test_w7_shaft_parallel_to_face():
    x = (1, 0, 0)
    c = meet(against(FLOOR, BOTTOM), fits(((0, 0, 5), x), ((0, 0, 5), x)))
    assert c.kind is Kind.PRISMATIC and c.contains(tr(3, 0, 0)) and not c.contains(tr(0, 3, 0))
    u = meet(against(FLOOR, BOTTOM), fits(((0, 0, 5), x), ((0, 0, 5), x), directed=False))
    assert u.n_components == 2 and u.contains(se3.rot_z(math.pi) @ tr(-2, 0, 0))
    bad = meet(against(FLOOR, BOTTOM), fits(((0, 0, 5), x), ((0, 0, 4), x)))
    assert isinstance(bad, EmptySet) and bad.mismatch.kind == "distance"
    assert bad.mismatch.value == pytest.approx(1.0)


def test_w9_two_balls_is_revolute_about_the_line_of_centres():
    c = meet(ball(ORIGIN, ORIGIN), ball((0, 0, 10), (0, 0, 10)))
    assert c.kind is Kind.REVOLUTE and c.contains(se3.rot_z(0.4))
    v = meet(ball(ORIGIN, ORIGIN), ball((0, 0, 10), (0, 10, 0)))
    assert v.kind is Kind.REVOLUTE and v.contains(se3.rot_z(0.4) @ se3.rot_x(HALF_PI))
    assert not v.contains(np.eye(4))
    bad = meet(ball(ORIGIN, ORIGIN), ball((0, 0, 10), (0, 0, 9)))
    assert isinstance(bad, EmptySet) and bad.mismatch.kind == "distance"
    assert bad.mismatch.value == pytest.approx(1.0)


def test_w10_three_balls_fix_the_body():
    c = meet(ball(ORIGIN, ORIGIN), ball((0, 0, 10), (0, 0, 10)), ball((10, 0, 0), (10, 0, 0)))
    assert c.is_point
    np.testing.assert_allclose(c.rep, np.eye(4), atol=1e-12)


def test_w11_ball_and_sliding_face():
    c = meet(ball((0, 0, 1), (0, 0, 1)), against(FLOOR, BOTTOM))
    assert c.kind is Kind.REVOLUTE
    assert c.group.equals(SymmetryGroup.revolute((0, 0, 1), Z))
    bad = meet(ball((0, 0, 1), (0, 0, 2)), against(FLOOR, BOTTOM))
    assert isinstance(bad, EmptySet) and bad.mismatch.value == pytest.approx(1.0)


@pytest.mark.parametrize(("n", "count"), [(4, 4), (2, 2), (24, 24)])
def test_w14_keyed_peg_with_shoulder_has_finitely_many_positions(n, count):
    turns = tuple(se3.rot_z(2 * math.pi * k / n) for k in range(n))
    peg = Coset(SymmetryGroup.prismatic(Z).with_discrete(reps=turns), np.eye(4))
    c = peg.intersect(against(FLOOR, BOTTOM))
    assert c.dof == 0 and c.n_components == count and not c.is_point
    points = c.points()
    assert len(points) == count
    for k in range(n):
        assert any(np.allclose(p, turns[k], atol=1e-12) for p in points)


def test_w16_thread_and_key_give_a_lattice():
    p = 1.5 / (2 * math.pi)
    thread = Coset(SymmetryGroup.helical(ORIGIN, Z, p), np.eye(4))
    key = Coset(SymmetryGroup.prismatic(Z), np.eye(4))
    c = thread.intersect(key)
    assert c.dof == 0 and c.n_components == math.inf and not c.is_point
    for k in (-2, 1, 3):
        assert c.contains(tr(0, 0, 1.5 * k))
    assert not c.contains(tr(0, 0, 1.0))


def test_w18a_products_that_are_cosets():
    rz = Coset(SymmetryGroup.revolute(ORIGIN, Z), np.eye(4))
    tz = Coset(SymmetryGroup.prismatic(Z), np.eye(4))
    gz = Coset(SymmetryGroup.planar(Z), np.eye(4))
    c = rz.product(tz)
    assert isinstance(c, Coset) and c.group.equals(SymmetryGroup.cylindrical(ORIGIN, Z))
    x = gz.product(tz)
    assert isinstance(x, Coset) and x.group.equals(SymmetryGroup.schoenflies(Z))


def test_w18b_two_revolutes_through_a_point_are_a_chain():
    rz = Coset(SymmetryGroup.revolute(ORIGIN, Z), np.eye(4))
    rx = Coset(SymmetryGroup.revolute(ORIGIN, (1, 0, 0)), np.eye(4))
    ch = rz.product(rx)
    assert isinstance(ch, Chain) and ch.dof == 2
    a, b = se3.rot_z(0.5), se3.rot_x(0.5)
    assert ch.contains(a) and ch.contains(b)
    witness = b @ a
    assert witness[2, 0] == pytest.approx(0.22984884706593015)  # sin^2 0.5
    assert not ch.contains(witness)


def test_w18c_network_products():
    gz = Coset(SymmetryGroup.planar(Z), np.eye(4))
    vertical = gz.product(Coset(SymmetryGroup.cylindrical((2, 0, 0), Z), np.eye(4)))
    assert isinstance(vertical, Coset) and vertical.group.equals(SymmetryGroup.schoenflies(Z))
    pin = (0, 0, 1), (1, 0, 0)
    horizontal = gz.product(Coset(SymmetryGroup.cylindrical(*pin), np.eye(4)))
    assert isinstance(horizontal, Chain) and horizontal.dof == 4
    a, b = se3.rotation(pin[1], 0.5, pin[0]), se3.rot_z(0.5)
    assert horizontal.contains(a) and horizontal.contains(b)
    assert not horizontal.contains(a @ b)


def test_w20_slot_is_redundant_or_inconsistent():
    ceiling = ((0, 0, 10), (0, 0, -1))
    c = meet(against(FLOOR, BOTTOM), against(ceiling, ((0, 0, 10), Z)))
    assert c.kind is Kind.PLANAR and c.dof == 3
    thin = meet(against(FLOOR, BOTTOM), against(ceiling, ((0, 0, 9.9), Z)))
    assert isinstance(thin, EmptySet) and thin.mismatch.kind == "distance"
    assert thin.mismatch.value == pytest.approx(0.1)


def test_inverse_left_right_and_conjugate():
    c = against(FLOOR, BOTTOM).right(tr(1, 0, 0))
    assert c.contains(tr(1, 0, 0)) and c.contains(tr(5, 5, 0) @ se3.rot_z(2))
    inv = c.inverse()
    for x in c.sample(np.random.default_rng(0), 5):
        assert inv.contains(se3.inverse(x))
    h = se3.rot_x(0.3) @ tr(1, 2, 3)
    assert c.left(h).contains(h @ tr(1, 0, 0))
    assert c.conjugate(h).contains(h @ tr(1, 0, 0) @ se3.inverse(h))


# ----------------------------------------------------------------------------- equivariance


def _w4_relations(b1=None, b2=None):
    b1 = np.eye(4) if b1 is None else b1
    b2 = np.eye(4) if b2 is None else b2
    down = np.array([0.0, 0.0, -1.0])

    def face(t, p, n):
        inv = transform_invariant(t, PlaneInvariant(p, n))
        return inv.point, inv.normal

    def axis(t, p, u):
        inv = transform_invariant(t, LineInvariant(p, u))
        return inv.point, inv.direction

    return meet(
        against(face(b1, ORIGIN, Z), face(b2, ORIGIN, down)),
        fits(axis(b1, ORIGIN, down), axis(b2, ORIGIN, down)),
        ball(*(transform_invariant(t, PointInvariant((0, 0, -3))).point for t in (b1, b2))),
    )


@settings(max_examples=30, deadline=None)
@given(seeds)
def test_equivariance_recipe(seed):
    rng = np.random.default_rng(seed)
    base = _w4_relations()
    assert base.kind is Kind.REVOLUTE
    g, h = se3.random_transform(rng), se3.random_transform(rng)
    # B2's features replaced by g^-1(feature): X -> X g, H unchanged.
    moved2 = _w4_relations(b2=se3.inverse(g))
    assert moved2.group.equals(base.group)
    assert moved2.contains(base.rep @ g)
    # B1's features replaced by h(feature): H -> h H h^-1, X -> h X.
    moved1 = _w4_relations(b1=h)
    assert moved1.group.equals(base.group.conjugate(h))
    assert moved1.contains(h @ base.rep)


# ----------------------------------------------------------------------------- properties


def _random_relation(rng: np.random.Generator) -> Coset:
    kind = int(rng.integers(3))
    p, d = rng.integers(-2, 3, 3).astype(float), np.eye(3)[int(rng.integers(3))]
    g = se3.random_transform(rng)
    inv = [PlaneInvariant(p, d), LineInvariant(p, d), PointInvariant(p)][kind]
    out = transporter([inv], [transform_invariant(se3.inverse(g), inv)])
    assert isinstance(out, Coset)
    return out


@settings(max_examples=50, deadline=None)
@given(seeds)
def test_coset_intersection_members_and_equivariance(seed):
    rng = np.random.default_rng(seed)
    a, b = _random_relation(rng), _random_relation(rng)
    m = a.intersect(b)
    h = se3.random_transform(rng)
    moved = a.left(h).intersect(b.left(h))
    if isinstance(m, EmptySet):
        assert isinstance(moved, EmptySet)
        return
    for x in m.sample(rng, 3):
        assert a.contains(x) and b.contains(x)
    assert isinstance(moved, Coset)
    assert moved.group.equals(m.group.conjugate(h)) and moved.contains(h @ m.rep)


@settings(max_examples=50, deadline=None)
@given(seeds)
def test_product_with_inverse_contains_identity(seed):
    rng = np.random.default_rng(seed)
    c = _random_relation(rng)
    prod = c.product(c.inverse())
    assert isinstance(prod, Coset)
    assert prod.contains(np.eye(4))
    np.testing.assert_allclose(prod.rep, np.eye(4), atol=1e-9)


@settings(max_examples=15, deadline=None)
@given(seeds)
def test_helical_coset_intersection_finds_a_common_point(seed):
    rng = np.random.default_rng(seed)
    x = se3.random_transform(rng)
    pitch = float(rng.uniform(0.2, 1.0))
    thread = Coset(SymmetryGroup.helical(ORIGIN, Z, pitch), x)
    other = Coset(
        [SymmetryGroup.planar(Z), SymmetryGroup.cylindrical((1, 0, 0), Z)][int(rng.integers(2))],
        x,
    )
    m = thread.intersect(other)
    assert isinstance(m, Coset)
    assert m.contains(x) and thread.contains(m.rep) and other.contains(m.rep)


def test_w16_lattice_meets_a_third_relation():
    p = 1.5 / (2 * math.pi)
    w16 = Coset(SymmetryGroup.helical(ORIGIN, Z, p), np.eye(4)).intersect(
        Coset(SymmetryGroup.prismatic(Z), np.eye(4))
    )
    seat = transporter([PlaneInvariant((0, 0, 4.5), Z)], [PlaneInvariant(ORIGIN, Z)])
    fixed = w16.intersect(seat)
    assert isinstance(fixed, Coset) and fixed.is_point
    np.testing.assert_allclose(fixed.rep, tr(0, 0, 4.5), atol=1e-12)
    off_lattice = transporter([PlaneInvariant((0, 0, 4.0), Z)], [PlaneInvariant(ORIGIN, Z)])
    missed = w16.intersect(off_lattice)
    # 4.0 lies between the lattice steps 3.0 and 4.5: proven empty, 0.5 from the nearest.
    assert isinstance(missed, EmptySet) and missed.proven
    assert missed.mismatch.kind == "distance"
    assert missed.mismatch.value == pytest.approx(0.5, abs=1e-12)


# ----------------------------------------------------------------------------- helical closed forms
# docs/algebra.md §2.4 table and §2.5: a thread coset meets a TR coset in a one-parameter
# problem in the screw angle, solved exactly (no numeric search).

LEAD = 1.5
PITCH = LEAD / (2 * math.pi)


@pytest.fixture
def no_numeric_search(monkeypatch):
    """Fail if the numeric fallback runs: the closed forms must decide."""

    def refuse(*args, **kwargs):
        raise AssertionError("the numeric search ran")

    monkeypatch.setattr("assemblykit.algebra.cosets._numeric_meet", refuse)


def thread(rep=None):
    return Coset(SymmetryGroup.helical(ORIGIN, Z, PITCH), np.eye(4) if rep is None else rep)


def test_thread_against_a_face_fixes_the_screw_angle(no_numeric_search):
    # The nut seats 0.75 up: half the lead, so half a turn.
    seat = against(((0, 0, 0.75), Z), ((0, 0, 0), (0, 0, -1)))
    c = thread().intersect(seat)
    assert isinstance(c, Coset) and c.is_point
    np.testing.assert_allclose(c.rep, tr(0, 0, 0.75) @ se3.rot_z(math.pi), atol=1e-12)
    # The other order gives the same point.
    d = seat.intersect(thread())
    np.testing.assert_allclose(d.rep, c.rep, atol=1e-12)


def test_thread_and_key_give_the_lead_lattice_through_the_key_angle(no_numeric_search):
    key = Coset(SymmetryGroup.prismatic(Z), se3.rot_z(0.3))
    c = thread().intersect(key)
    assert isinstance(c, Coset) and c.dof == 0 and c.n_components == math.inf
    np.testing.assert_allclose(c.rep, se3.screw(ORIGIN, Z, PITCH, 0.3), atol=1e-12)
    np.testing.assert_allclose(c.group.lattice[0][:3, 3], (0, 0, LEAD), atol=1e-12)
    assert c.contains(tr(0, 0, 2 * LEAD) @ c.rep)


def test_thread_and_revolute_on_the_same_axis_give_one_point(no_numeric_search):
    shoulder = Coset(SymmetryGroup.revolute(ORIGIN, Z), tr(0, 0, 0.375))
    c = thread().intersect(shoulder)
    assert isinstance(c, Coset) and c.is_point
    np.testing.assert_allclose(c.rep, tr(0, 0, 0.375) @ se3.rot_z(math.pi / 2), atol=1e-12)


def test_thread_off_phase_is_proven_empty_with_the_axial_miss(no_numeric_search):
    # Rotations about the parallel axis through (1, 0, 0) meet the helix only at whole
    # turns, i.e. at heights 1.5 k; 0.375 is 0.375 from the nearest.
    other = Coset(SymmetryGroup.revolute((1, 0, 0), Z), tr(0, 0, 0.375))
    e = thread().intersect(other)
    assert isinstance(e, EmptySet) and e.proven
    assert e.mismatch.kind == "distance"
    assert e.mismatch.value == pytest.approx(0.375, abs=1e-12)


def test_thread_in_a_tilted_bore_is_empty_by_the_hull(no_numeric_search):
    tilted = fits(((0, 0, 0), (1, 0, 0)), ((0, 0, 0), (0, 0, 1)))
    bore = fits(((0, 0, 0), Z), ((0, 0, 0), Z))
    assert isinstance(bore, Coset)
    # C(x-axis) . Ry(pi/2)^-1 ∩ H(z): every element of the hull C(z) keeps z, none maps z to x.
    e = thread().intersect(tilted)
    assert isinstance(e, EmptySet) and e.proven and e.mismatch.kind == "angle"


def test_pseudo_planar_meets_a_face_and_a_key(no_numeric_search):
    y = Coset(SymmetryGroup.pseudo_planar(Z, PITCH), tr(1, 2, 3))
    seat = against(((0, 0, 0.75), Z), ((0, 0, 0), (0, 0, -1)))
    c = y.intersect(seat)
    # Y(z) ∩ G(z) = T2(z): the plane at height 0.75 with the angle fixed mod 2 pi.
    assert isinstance(c, Coset) and c.kind is Kind.TRANSLATION2
    assert c.rep[2, 3] == pytest.approx(0.75, abs=1e-12)
    assert y.contains(c.rep) and seat.contains(c.rep)
    assert c.contains(tr(5, -1, 0) @ c.rep)
    key = Coset(SymmetryGroup.prismatic(Z), se3.rot_z(0.3))
    k = y.intersect(key)
    assert isinstance(k, Coset) and k.dof == 0 and k.n_components == math.inf
    # Height 3 + 0.3 p: the screw 0.3 on top of the offset 3 = 2 lead turns (3 = 2 x 1.5).
    np.testing.assert_allclose(k.rep, tr(0, 0, 3 + 0.3 * PITCH) @ se3.rot_z(0.3), atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(seeds)
def test_helical_closed_forms_contain_a_shared_position_and_are_equivariant(seed):
    """A thread (H) or pseudo-planar (Y) relation and a plane, line or point relation
    through one random position x: the answer contains x, lies in both, and moving body
    1 by h moves the answer; the numeric search is never needed."""
    rng = np.random.default_rng(seed)
    x = se3.random_transform(rng)
    pitch = float(rng.uniform(0.05, 1.0)) * (1 if rng.random() < 0.5 else -1)
    group = (
        SymmetryGroup.helical(rng.normal(size=3), rng.normal(size=3), pitch)
        if rng.random() < 0.5
        else SymmetryGroup.pseudo_planar(rng.normal(size=3), pitch)
    )
    helix = Coset(group, x)
    inv = (
        PlaneInvariant(rng.normal(size=3), rng.normal(size=3)),
        LineInvariant(rng.normal(size=3), rng.normal(size=3)),
        PointInvariant(rng.normal(size=3)),
    )[rng.integers(3)]
    other = transporter([inv], [transform_invariant(se3.inverse(x), inv)])
    assert isinstance(other, Coset) and other.contains(x)
    h = se3.random_transform(rng)
    for a, b, point in ((helix, other, x), (helix.left(h), other.left(h), h @ x)):
        with mock.patch.object(cosets, "_numeric_meet", side_effect=AssertionError("numeric")):
            m = a.intersect(b)
        assert isinstance(m, Coset)
        assert m.contains(point) and a.contains(m.rep) and b.contains(m.rep)
        assert m.group.equals(intersect_groups(a.group, b.group))


# ----------------------------------------------------------------------------- lattice cosets


def test_lattice_coset_meets_in_closed_form_far_from_the_origin(no_numeric_search):
    """W16 seated 900 lead steps up: beyond any bounded step search, found exactly."""
    w16 = thread().intersect(Coset(SymmetryGroup.prismatic(Z), np.eye(4)))
    far = against(((0, 0, 900 * LEAD), Z), ((0, 0, 0), (0, 0, -1)))
    c = w16.intersect(far)
    assert isinstance(c, Coset) and c.is_point
    np.testing.assert_allclose(c.rep, tr(0, 0, 1350.0), atol=1e-9)


def test_discrete_screw_coset_meets_a_key_every_other_step(no_numeric_search):
    """H(1) ∩ H(3) = <Scr(-3 pi; 1)>: rotation pi per step, so a key (no rotation)
    meets the coset through Tr(0, 0, 4 pi) only at even steps, the nearest being
    Tr(0, 0, 4 pi - 6 pi . 0) ... i.e. heights 4 pi + 6 pi Z."""
    screws = intersect_groups(
        SymmetryGroup.helical(ORIGIN, Z, 1.0), SymmetryGroup.helical(ORIGIN, Z, 3.0)
    )
    lattice = Coset(screws, tr(0, 0, 4 * math.pi))
    key = Coset(SymmetryGroup.prismatic(Z), np.eye(4))
    c = lattice.intersect(key)
    assert isinstance(c, Coset) and c.dof == 0 and c.n_components == math.inf
    assert np.allclose(c.rep[:3, :3], np.eye(3), atol=1e-12)
    height = c.rep[2, 3]
    assert ((height - 4 * math.pi) / (6 * math.pi)) == pytest.approx(
        round((height - 4 * math.pi) / (6 * math.pi)), abs=1e-12
    )
    np.testing.assert_allclose(c.group.lattice[0][:3, 3], (0, 0, -6 * math.pi), atol=1e-9)
    # A half-turn key only meets the odd steps.
    flipped = Coset(SymmetryGroup.prismatic(Z), se3.rot_z(math.pi))
    d = lattice.intersect(flipped)
    assert isinstance(d, Coset)
    np.testing.assert_allclose(d.rep[:3, :3], se3.rot_z(math.pi)[:3, :3], atol=1e-12)
    # A quarter-turn key meets none: proven.
    quarter = Coset(SymmetryGroup.prismatic(Z), se3.rot_z(math.pi / 2))
    e = lattice.intersect(quarter)
    assert isinstance(e, EmptySet) and e.proven


# ----------------------------------------------------------------------------- many components
# docs/algebra.md §2.4 "Finite parts", §2.5: cosets with discrete parts meet only the pairs of
# components that can meet, with the result of meeting every pair.


def prism_coset(
    n: int,
    axis_point: tuple[float, float, float] = ORIGIN,
    axis: tuple[float, float, float] = Z,
    phase: float = 0.0,
    rep: np.ndarray | None = None,
) -> Coset:
    """A prism fit: the coset (T(u) ⋊ Cₙ) . x0 of an n-sided prism about the line
    (``axis_point``, ``axis``), one vertex at ``phase`` (the relation's representative
    ``rep``, default I)."""
    frame = se3.frame(axis_point, axis) @ se3.rot_z(phase)
    turns = tuple(frame @ se3.rot_z(math.tau * k / n) @ se3.inverse(frame) for k in range(1, n))
    group = SymmetryGroup(Kind.PRISMATIC, frame, 0.0, (np.eye(4), *turns))
    return Coset(group, np.eye(4) if rep is None else rep)


def all_pairs_intersect(p: Coset, q: Coset, tol: Tolerance | None = None) -> Coset | EmptySet:
    """P ∩ Q from the meets A0 alpha a ∩ B0 beta b of every pair of components (§2.5, the
    definition): the first common coset with the others as extra components, or the
    first unproven empty answer, else the first empty one."""
    a0, b0 = p.group.connected_part, q.group.connected_part
    pieces = [
        Coset(a0, alpha @ p.rep).intersect(Coset(b0, beta @ q.rep), tol)
        for alpha in p.group.reps
        for beta in q.group.reps
    ]
    found = [piece for piece in pieces if isinstance(piece, Coset)]
    if not found:
        empties = [piece for piece in pieces if isinstance(piece, EmptySet)]
        return next((e for e in empties if not e.proven), empties[0])
    extra = tuple(c.rep @ se3.inverse(found[0].rep) for c in found[1:])
    return Coset(found[0].group.with_known_discrete(reps=extra, tol=tol), found[0].rep)


def assert_same_meet(met: Coset | EmptySet, expected: Coset | EmptySet) -> None:
    """The same set, built the same way: the same representative, connected part and
    components in the same order, or the same empty answer."""
    assert type(met) is type(expected)
    if isinstance(met, EmptySet):
        assert isinstance(expected, EmptySet)
        assert met.mismatch == expected.mismatch and met.proven == expected.proven
        return
    assert isinstance(expected, Coset)
    assert np.array_equal(met.rep, expected.rep)
    assert met.kind is expected.kind and np.array_equal(met.group.frame, expected.group.frame)
    assert len(met.group.reps) == len(expected.group.reps)
    assert all(
        np.array_equal(x, y) for x, y in zip(met.group.reps, expected.group.reps, strict=True)
    )


SIDES = 360
"""Sides of the large prisms (each turn a component); ``benchmarks/bench_algebra.py``
times the same meets with 1000 sides against their targets."""


def test_two_coaxial_prism_fits_of_many_sides_slide_with_every_turn():
    """Two fits of 360-sided prisms on one axis between the same bodies, the second
    fit's representative another of its components: T(z) ⋊ C₃₆₀ through the body's
    pose (not a meet of every pair of components, which takes minutes at 1000 sides);
    with 540 sides on the second prism, T(z) ⋊ C₁₈₀."""
    pose = tr(0.3, -0.2, 4.0) @ se3.rot_z(0.1)
    second_axis = (0.0, 0.0, -20.0)
    first = prism_coset(SIDES, rep=pose)
    second = prism_coset(SIDES, second_axis, rep=se3.rot_z(math.tau * 7 / SIDES) @ pose)
    met = first.intersect(second)
    assert isinstance(met, Coset)
    assert (met.kind, met.dof, met.n_components) == (Kind.PRISMATIC, 1, SIDES)
    assert met.group.equals(prism_coset(SIDES).group) and met.contains(pose)
    assert met.contains(se3.rot_z(math.tau * 217 / SIDES) @ tr(0, 0, -3) @ pose)
    assert not met.contains(se3.rot_z(math.tau * 217.5 / SIDES) @ pose)
    coarse = first.intersect(prism_coset(3 * SIDES // 2, second_axis, rep=pose))
    assert isinstance(coarse, Coset) and coarse.n_components == SIDES // 2
    assert coarse.contains(se3.rot_z(math.tau * 3 / (SIDES // 2)) @ pose)
    assert not coarse.contains(se3.rot_z(math.tau / SIDES) @ pose)


def test_two_prism_fits_of_many_sides_out_of_phase_are_empty():
    """A second 360-sided fit a third of a step out of phase: no component meets, and the
    answer is the first pair's proven empty set."""
    met = prism_coset(SIDES).intersect(prism_coset(SIDES, rep=se3.rot_z(math.tau / (3 * SIDES))))
    assert isinstance(met, EmptySet) and met.proven


PAIR_CASES = {
    "coaxial prisms": (prism_coset(12), prism_coset(18, (0, 0, -5), rep=se3.rot_z(math.pi / 3))),
    "prisms on parallel axes": (prism_coset(4), prism_coset(6, (1, 0, 0))),
    "prism and a set of turns": (
        prism_coset(12),
        Coset(SymmetryGroup.cyclic(ORIGIN, Z, 8), tr(0, 0, 2)),
    ),
    "turns and a prism": (
        Coset(SymmetryGroup.cyclic(ORIGIN, Z, 8), np.eye(4)),
        prism_coset(12, phase=math.pi / 12),
    ),
    "crossed prisms": (prism_coset(4), prism_coset(6, (0, 0, 1), (1, 0, 0))),
    "dihedral prisms": (
        Coset(prism_coset(4).group.extended_by([se3.rot_x(math.pi)]), np.eye(4)),
        Coset(prism_coset(6).group.extended_by([se3.rot_x(math.pi)]), tr(0, 0, 1)),
    ),
    "flipped cylinder and a prism": (
        Coset(SymmetryGroup.cylindrical(ORIGIN, Z).extended_by([se3.rot_x(math.pi)]), np.eye(4)),
        prism_coset(6, rep=se3.rot_y(math.pi)),
    ),
    "prisms out of phase": (prism_coset(6), prism_coset(6, phase=0.1, rep=se3.rot_z(0.1))),
    "prisms on skew axes": (prism_coset(4), prism_coset(6, (0, 1, 1), (1, 0, 0))),
    "flipped thread and flipped cylinder": (
        Coset(SymmetryGroup.helical(ORIGIN, Z, PITCH).extended_by([se3.rot_x(math.pi)]), np.eye(4)),
        Coset(SymmetryGroup.cylindrical(ORIGIN, Z).extended_by([se3.rot_x(math.pi)]), tr(0, 0, 1)),
    ),
    "flipped thread and turns": (
        Coset(SymmetryGroup.helical(ORIGIN, Z, PITCH).extended_by([se3.rot_x(math.pi)]), np.eye(4)),
        Coset(SymmetryGroup.cyclic(ORIGIN, Z, 4), tr(0, 0, LEAD / 4)),
    ),
}


@pytest.mark.parametrize("case", PAIR_CASES)
def test_coset_meets_pair_only_the_components_that_can_meet(case):
    """Coaxial, parallel, crossed and skew prisms, turns, flips and threads (these meet
    every pair): the same coset (components in the same order) or the same empty answer
    as meeting every pair."""
    p, q = PAIR_CASES[case]
    assert_same_meet(p.intersect(q), all_pairs_intersect(p, q))
    assert_same_meet(q.intersect(p), all_pairs_intersect(q, p))


@settings(max_examples=40, deadline=None)
@given(seeds)
def test_prism_fits_meet_as_every_pair_of_components(seed):
    """Random prism fits of 2 to 9 sides on the same, a parallel, a crossed or a random
    axis, placed by random poses and representatives, the second sometimes turned or
    moved off the first (mostly empty then): the pruned intersection equals the
    all-pairs one."""
    rng = np.random.default_rng(seed)
    pose = se3.random_transform(rng)
    n, m = (int(k) for k in rng.integers(2, 10, 2))
    axes = [
        (ORIGIN, Z),
        ((float(rng.uniform(-2, 2)), 0.0, 0.0), Z),
        (ORIGIN, (1.0, 0.0, 0.0)),
        (tuple(rng.uniform(-2, 2, 3)), tuple(se3.unit(rng.normal(size=3)))),
    ]
    point, axis = axes[int(rng.integers(len(axes)))]
    phase = [0.0, math.pi / m, float(rng.uniform(0, math.tau))][int(rng.integers(3))]
    moves = [
        np.eye(4),
        se3.rot_z(math.tau / int(rng.integers(1, 10))),
        se3.rot_z(float(rng.uniform(0, math.tau))),
        se3.translation(rng.uniform(-1, 1, 3)),
    ]
    move = moves[int(rng.integers(len(moves)))]
    first = prism_coset(n, rep=pose)
    turn = first.group.reps[int(rng.integers(n))]
    second = prism_coset(m, point, axis, phase, rep=move @ turn @ pose)
    assert_same_meet(first.intersect(second), all_pairs_intersect(first, second))
    assert_same_meet(second.intersect(first), all_pairs_intersect(second, first))


def coaxial_prism_fits_meet_as_every_pair(seed: int) -> None:
    """Coaxial prism fits of 2 to 12 and up to twice as many sides, the second placed
    along the axis up to the model's size away and nudged by 0 to 4 tolerances (from
    1e-9 to 1e-2 of models of size 1 to 1000): the components whose keys fall near each
    other's are the ones the all-pairs intersection finds, in the same order."""
    rng = np.random.default_rng(seed)
    rel = float(rng.choice([1e-9, 1e-6, 1e-3, 1e-2]))
    tol = Tolerance(scale=float(rng.choice([1.0, 50.0, 1000.0])), rel_length=rel, angle=rel)
    n = int(rng.integers(2, 13))
    pose = se3.random_transform(rng)
    size = float(rng.choice([0.0, 0.3, 0.8, 1.5, 4.0]))
    pivot = rng.uniform(-1.0, 1.0, 3) * tol.scale
    nudge = se3.rotation(se3.unit(rng.normal(size=3)), size * tol.angle, pivot)
    nudge = nudge @ se3.translation(size * tol.length * se3.unit(rng.normal(size=3)))
    along = float(rng.uniform(-1.0, 1.0)) * tol.scale
    first = prism_coset(n, rep=pose)
    turn = first.group.reps[int(rng.integers(n))]
    rep = nudge @ tr(0, 0, along) @ turn @ pose
    second = prism_coset(n * int(rng.integers(1, 3)), (0.0, 0.0, along), rep=rep)
    assert_same_meet(first.intersect(second, tol), all_pairs_intersect(first, second, tol))
    assert_same_meet(second.intersect(first, tol), all_pairs_intersect(second, first, tol))


@settings(max_examples=20, deadline=None)
@given(seeds)
def test_coaxial_prism_fits_near_the_tolerance_meet_as_every_pair(seed):
    coaxial_prism_fits_meet_as_every_pair(seed)


@pytest.mark.slow
@settings(max_examples=200, deadline=None)
@given(seeds)
def test_many_coaxial_prism_fits_near_the_tolerance_meet_as_every_pair(seed):
    coaxial_prism_fits_meet_as_every_pair(seed)
