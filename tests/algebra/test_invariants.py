"""Characteristic invariants, stabilisers and transporters
(src/assemblykit/algebra/invariants.py; docs/algebra.md §2.5)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from assemblykit.algebra import (
    Coset,
    DirectionInvariant,
    EmptySet,
    Kind,
    LineInvariant,
    PlaneInvariant,
    PointInvariant,
    SymmetryGroup,
    congruence_mismatch,
    pair_frame,
    se3,
    stabilizer,
    transform_invariant,
    transporter,
)
from assemblykit.errors import FeatureError
from assemblykit.tolerance import Tolerance

Z = (0.0, 0.0, 1.0)
X = (1.0, 0.0, 0.0)
ORIGIN = (0.0, 0.0, 0.0)
seeds = st.integers(min_value=0, max_value=2**32 - 1)


def test_zero_normal_is_a_feature_error():
    with pytest.raises(FeatureError):
        PlaneInvariant(ORIGIN, (0, 0, 0))


def test_transform_invariant_moves_points_and_rotates_directions():
    t = se3.translation((1, 0, 0)) @ se3.rot_z(math.pi / 2)
    line = transform_invariant(t, LineInvariant((1, 0, 0), X, directed=False))
    np.testing.assert_allclose(line.point, (1, 1, 0), atol=1e-15)
    np.testing.assert_allclose(line.direction, (0, 1, 0), atol=1e-15)
    assert line.directed is False
    d = transform_invariant(t, DirectionInvariant(X))
    np.testing.assert_allclose(d.direction, (0, 1, 0), atol=1e-15)


def test_stabilizers_of_single_invariants():
    assert stabilizer([PointInvariant((1, 2, 3))]).equals(SymmetryGroup.spherical((1, 2, 3)))
    assert stabilizer([LineInvariant(ORIGIN, Z)]).equals(SymmetryGroup.cylindrical(ORIGIN, Z))
    assert stabilizer([PlaneInvariant((0, 0, 5), Z)]).equals(SymmetryGroup.planar(Z))
    assert stabilizer([DirectionInvariant(Z)]).equals(SymmetryGroup.schoenflies(Z))
    flip = stabilizer([LineInvariant(ORIGIN, Z, directed=False)])
    assert flip.kind is Kind.CYLINDRICAL and flip.n_components == 2
    assert flip.contains(se3.rot_x(math.pi)) and flip.contains(se3.rot_y(math.pi))


def test_stabilizer_of_pairs_follows_the_table():
    # plane + plane, non-parallel: T(n1 x n2)
    assert stabilizer([PlaneInvariant(ORIGIN, Z), PlaneInvariant(ORIGIN, X)]).equals(
        SymmetryGroup.prismatic((0, 1, 0))
    )
    # line ⊥ plane: R(L); line ∥ plane: T(u)
    assert stabilizer([LineInvariant(ORIGIN, Z), PlaneInvariant((0, 0, 3), Z)]).equals(
        SymmetryGroup.revolute(ORIGIN, Z)
    )
    assert stabilizer([LineInvariant((0, 0, 5), X), PlaneInvariant(ORIGIN, Z)]).equals(
        SymmetryGroup.prismatic(X)
    )
    # two points: R(line through them); point off a line: E
    assert stabilizer([PointInvariant(ORIGIN), PointInvariant((0, 0, 10))]).equals(
        SymmetryGroup.revolute(ORIGIN, Z)
    )
    assert stabilizer([PointInvariant((1, 0, 0)), LineInvariant(ORIGIN, Z)]).kind is Kind.FIXED


def test_congruence_reports_the_first_failing_test_and_its_size():
    s10 = math.sin(math.radians(10))
    c10 = math.cos(math.radians(10))
    # W3b: n_floor . n_wall = 0 but m1 . m2 = -sin 10°
    found = congruence_mismatch(
        [PlaneInvariant(ORIGIN, Z), PlaneInvariant(ORIGIN, X)],
        [PlaneInvariant(ORIGIN, Z), PlaneInvariant(ORIGIN, (c10, 0, -s10))],
    )
    assert found is not None and found.kind == "angle"
    assert found.value == pytest.approx(math.radians(10))
    assert "angle mismatch 10°" in found.message
    skew_t = [LineInvariant(ORIGIN, X), LineInvariant((0, 0, 2), (0, 1, 0))]
    skew_s = [LineInvariant(ORIGIN, X), LineInvariant((0, 0, -2), (0, 1, 0))]
    moment = congruence_mismatch(skew_t, skew_s)
    assert moment is not None and moment.kind == "moment" and moment.value == pytest.approx(4.0)
    assert congruence_mismatch([PointInvariant(ORIGIN)], [LineInvariant(ORIGIN, Z)]).kind == "type"
    assert congruence_mismatch(skew_t, skew_t) is None


def test_pair_frame_of_two_planes_sits_on_their_line():
    f = pair_frame(PlaneInvariant((0, 0, 1), Z), PlaneInvariant((2, 0, 0), X))
    np.testing.assert_allclose(f[:3, 2], Z)
    np.testing.assert_allclose(f[:3, 3], (2, 0, 1), atol=1e-12)  # foot of the origin on the line


def test_transporter_of_skew_lines_is_one_point():
    t = [LineInvariant(ORIGIN, X), LineInvariant((0, 0, 2), (0, 1, 0))]
    g = se3.random_transform(np.random.default_rng(1))
    s = [transform_invariant(se3.inverse(g), i) for i in t]
    c = transporter(t, s)
    assert isinstance(c, Coset) and c.is_point
    np.testing.assert_allclose(c.rep, g, atol=1e-9)


def test_chirality_is_detected_beyond_pairwise_congruence():
    # Three directions: pairwise angles agree but the triple is mirrored.
    t = [DirectionInvariant(X), DirectionInvariant((0, 1, 0)), DirectionInvariant(Z)]
    s = [DirectionInvariant(X), DirectionInvariant((0, 1, 0)), DirectionInvariant((0, 0, -1))]
    out = transporter(t, s)
    assert isinstance(out, EmptySet) and out.mismatch.kind == "handedness" and out.proven


def _random_tuple(rng: np.random.Generator) -> list:
    kinds = rng.integers(0, 4, int(rng.integers(1, 4)))
    out = []
    for k in kinds:
        p, d = rng.normal(size=3) * 5, rng.normal(size=3)
        out.append(
            [PointInvariant(p), LineInvariant(p, d), PlaneInvariant(p, d), DirectionInvariant(d)][k]
        )
    return out


@settings(max_examples=50, deadline=None)
@given(seeds)
def test_transporter_round_trip_in_random_placements(seed):
    rng = np.random.default_rng(seed)
    targets = _random_tuple(rng)
    g = se3.random_transform(rng)
    sources = [transform_invariant(se3.inverse(g), i) for i in targets]
    c = transporter(targets, sources)
    assert isinstance(c, Coset)
    assert c.contains(g)
    for x in c.sample(rng, 3):
        for s, t in zip(sources, targets, strict=True):
            moved = transform_invariant(x, s)
            assert transporter([t], [moved]).contains(np.eye(4))


@settings(max_examples=50, deadline=None)
@given(seeds)
def test_stabilizer_is_equivariant(seed):
    rng = np.random.default_rng(seed)
    invs = _random_tuple(rng)
    h = se3.random_transform(rng)
    moved = [transform_invariant(h, i) for i in invs]
    assert stabilizer(moved).equals(stabilizer(invs).conjugate(h))


# ----------------------------------------------------------------------------- float invariants


def test_characteristic_flats_follow_the_group_frame():
    from assemblykit.algebra.invariants import characteristic_flats

    f = se3.frame((1, 2, 3), (0, 0, 1), (1, 0, 0))
    # Point code 0, line 1, plane 2, direction 3.
    assert characteristic_flats(Kind.REVOLUTE, f) == (
        (0, (1.0, 2.0, 3.0), None),
        (1, (1.0, 2.0, 3.0), (0.0, 0.0, 1.0)),
    )
    assert characteristic_flats(Kind.TRANSLATION2, f) == (
        (2, (1.0, 2.0, 3.0), (0.0, 0.0, 1.0)),
        (3, None, (1.0, 0.0, 0.0)),
    )
    assert characteristic_flats(Kind.FREE, f) == ()
    with pytest.raises(FeatureError, match="helical"):
        characteristic_flats(Kind.HELICAL, f)


@settings(max_examples=30, deadline=None)
@given(seeds)
def test_moved_flats_agree_with_transform_invariant(seed):
    from assemblykit.algebra.invariants import characteristic_flats, frame_invariants, move_flats

    rng = np.random.default_rng(seed)
    frame, t = se3.random_transform(rng), se3.random_transform(rng)
    flats = characteristic_flats(Kind.FIXED, frame)
    moved = move_flats(t, flats)
    back = move_flats(t, moved, inverse=True)
    for (code, p, u), (_, q, w), (_, _, v), inv in zip(
        moved, back, flats, frame_invariants(Kind.FIXED, frame), strict=True
    ):
        ref = transform_invariant(t, inv)
        np.testing.assert_allclose(p, ref.point, atol=1e-12)
        np.testing.assert_allclose(q, inv.point, atol=1e-12)
        if code:
            np.testing.assert_allclose(u, getattr(ref, "direction", getattr(ref, "normal", None)))
            np.testing.assert_allclose(w, v, atol=1e-14)
    assert isinstance(frame_invariants(Kind.FIXED, frame)[1], LineInvariant)


def test_flat_transporter_reports_the_congruence_failure():
    from assemblykit.algebra.cosets import flat_transporter
    from assemblykit.algebra.invariants import characteristic_flats

    targets = characteristic_flats(Kind.PLANAR, np.eye(4))
    # Two floors 1 apart on the body-1 side, 2 apart on the body-2 side.
    two = targets + characteristic_flats(Kind.PLANAR, se3.translation((0, 0, 1)))
    other = targets + characteristic_flats(Kind.PLANAR, se3.translation((0, 0, 2)))
    group = SymmetryGroup.planar((0, 0, 1))
    e = flat_transporter(two, other, group, Tolerance())
    assert isinstance(e, EmptySet) and e.mismatch.kind == "distance"
    assert e.mismatch.value == pytest.approx(1.0)
    c = flat_transporter(two, two, group, Tolerance())
    assert isinstance(c, Coset) and c.group is group
    np.testing.assert_allclose(c.rep, np.eye(4), atol=1e-15)


@pytest.mark.parametrize("rel", [1e-9, 1e-4, 1e-2, 3e-2, 0.1])
def test_transporter_of_a_point_and_two_axial_lines_at_any_tolerance(rel):
    """A point on a line and a second, reversed line along the same axis, 10 apart; the
    sources are the same tuple moved by T(-5, -5, -10). Their frame systems are regular
    (eigenvalues 3, 3, 1), so the transporter is that translation (and a rotation about
    the axis) at every tolerance: a loose tolerance must not call the system singular,
    whose completed solution would depend on the coordinates."""
    z = np.array([0.0, 0.0, 1.0])
    targets = (
        PointInvariant(np.array([5.0, 5.0, 0.0])),
        LineInvariant(np.array([5.0, 5.0, 0.0]), z),
        LineInvariant(np.array([5.0, 5.0, 10.0]), -z),
    )
    sources = (
        PointInvariant(np.array([0.0, 0.0, -10.0])),
        LineInvariant(np.array([0.0, 0.0, -10.0]), z),
        LineInvariant(np.array([0.0, 0.0, 0.0]), -z),
    )
    tol = Tolerance.relative(rel).with_scale(15.0)
    found = transporter(targets, sources, tol)
    assert isinstance(found, Coset)
    assert found.group.kind is Kind.REVOLUTE
    assert found.contains(se3.translation(np.array([5.0, 5.0, 10.0])), Tolerance())


def test_mismatch_kinds_are_their_documented_strings():
    """Mismatch kinds compare, format and serialise as the strings they stand for."""
    import json

    from assemblykit.algebra import MismatchKind

    found = congruence_mismatch(
        [PointInvariant((0, 0, 0)), PointInvariant((1, 0, 0))],
        [PointInvariant((0, 0, 0)), PointInvariant((3, 0, 0))],
    )
    assert found is not None and found.kind is MismatchKind.DISTANCE
    assert found.kind == "distance" and f"{found.kind}" == "distance"
    assert json.dumps({"kind": found.kind}) == '{"kind": "distance"}'
    assert {str(k) for k in MismatchKind} >= {"angle", "distance", "handedness", "residual"}
