"""The relation vocabulary: parsing, checks, cosets (docs/algebra.md §5.1, §6), residuals."""

from __future__ import annotations

import math
from functools import reduce

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from assemblykit.algebra import EmptySet, se3
from assemblykit.errors import FeatureError, SchemaError
from assemblykit.features import Ball, Cone, Frame, Hole, Plane, Point, Prism, Shaft, Socket, Thread
from assemblykit.model.relations import (
    RELATIONS,
    FeatureRef,
    Relation,
    check_relation,
    relation_coset,
    relation_dof_removed,
    relation_residual,
)

Z, MZ = (0, 0, 1), (0, 0, -1)
I4 = np.eye(4)
tr, rz, rx = se3.translation, se3.rot_z, se3.rot_x


def meet(*cosets):
    """The intersection of relation cosets (body 1 frame), left to right."""
    return reduce(lambda a, b: a if isinstance(a, EmptySet) else a.intersect(b), cosets)


def against(first, second, **options):
    return relation_coset("against", first, second, options)


def fits(first, second):
    return relation_coset("fits", first, second)


def members(coset, inside, outside):
    for x in inside:
        assert coset.contains(x), x
    for x in outside:
        assert not coset.contains(x), x


# ------------------------------------------------------------------ parsing and checks


def test_feature_ref_round_trip():
    ref = FeatureRef.parse("block.bottom")
    assert (ref.body, ref.feature) == ("block", "bottom")
    assert str(ref) == "block.bottom"
    for bad in ("block", ".x", "y.", 3):
        with pytest.raises(SchemaError):
            FeatureRef.parse(bad, where="situations[0].relations[0]")


def test_relation_parse():
    rel = Relation.parse(["against", "block.bottom", "table.top", {"offset": 2}], "s1[0]")
    assert rel.kind == "against"
    assert [str(r) for r in rel.refs] == ["block.bottom", "table.top"]
    assert rel.options == {"offset": 2}
    assert rel.where == "s1[0]"
    with pytest.raises(SchemaError, match="unknown relation 'glued'"):
        Relation.parse(["glued", "a.x", "b.y"], "s1[1]")
    with pytest.raises(SchemaError, match="relates 2 features"):
        Relation.parse(["fits", "a.x"], "s1[2]")
    with pytest.raises(SchemaError, match="no option offset"):
        Relation.parse(["fits", "a.x", "b.y", {"offset": 1}], "s1[3]")
    with pytest.raises(SchemaError, match="needs the option angle"):
        Relation.parse(["angle", "a.x", "b.y"], "s1[4]")
    angle = Relation.parse(["angle", "a.x", "b.y", {"angle": "30 deg"}]).options["angle"]
    assert angle == pytest.approx(math.pi / 6, abs=1e-15)
    with pytest.raises(SchemaError, match="offset is a length in model units, not an angle"):
        Relation.parse(["against", "a.x", "b.y", {"offset": "90 deg"}], "s1[5]")


def test_every_kind_is_registered():
    assert set(RELATIONS) == {
        "against",
        "coplanar",
        "fits",
        "coaxial",
        "fixed",
        "parallel",
        "perpendicular",
        "angle",
        "coincident",
        "point_on_plane",
        "point_on_line",
        "distance",
        "gear",
        "rack",
        "mirror",
    }
    assert all(spec.arity == 2 for spec in RELATIONS.values())
    cosets = {kind for kind, spec in RELATIONS.items() if spec.is_coset}
    assert cosets == {"against", "coplanar", "fits", "coaxial", "fixed", "parallel", "coincident"}


def test_wrong_feature_types_are_feature_errors_naming_the_relation():
    plane, shaft = Plane((0, 0, 0), Z, name="top"), Shaft((0, 0, 0), Z, 2, name="pin")
    rel = Relation.parse(["against", "a.top", "b.pin"], "situations[0].relations[3]")
    with pytest.raises(FeatureError) as info:
        check_relation(rel, plane, shaft)
    assert info.value.where == "situations[0].relations[3]"
    assert "shaft 'pin'" in str(info.value)
    male = Cone((0, 0, 0), Z, 0.3)
    with pytest.raises(FeatureError, match="male cone"):
        check_relation(Relation("fits", rel.refs, {}, "r"), male, male)
    # A radius mismatch is not an error: it is an inconsistency (below).
    check_relation(
        Relation("fits", rel.refs, {}, "r"), Shaft((0, 0, 0), Z, 4.9), Hole((0, 0, 0), Z, 5)
    )


def test_non_coset_kinds_raise_in_relation_coset():
    with pytest.raises(FeatureError, match="not a coset"):
        relation_coset("perpendicular", Plane((0, 0, 0), Z), Plane((0, 0, 0), (1, 0, 0)))


# ------------------------------------------------------------------ docs/algebra.md §6


def test_w1_single_against_is_planar():
    coset = against(Plane((0, 0, 0), MZ), Plane((0, 0, 0), Z))
    assert (str(coset.kind), coset.dof, coset.n_components) == ("planar", 3, 1)
    members(coset, [tr((1, 2, 0)) @ rz(0.3)], [tr((0, 0, 0.1)), rx(0.1)])


def test_against_offset_is_a_gap_along_the_normal():
    coset = against(Plane((0, 0, 0), MZ), Plane((0, 0, 0), Z), offset=2)
    members(coset, [tr((1, 2, 2)) @ rz(0.3)], [I4])


FLOOR, WALL_X, WALL_Y = (
    Plane((0, 0, 0), Z),
    Plane((0, 0, 0), (1, 0, 0)),
    Plane((0, 0, 0), (0, 1, 0)),
)


def test_w2_two_perpendicular_against_is_prismatic_along_y():
    for bottom, left in [
        (Plane((0, 0, 0), MZ), Plane((0, 0, 0), (-1, 0, 0))),
        (Plane((1, 1, 0), MZ), Plane((0, 1, 1), (-1, 0, 0))),  # the cube [0, 2]^3
    ]:
        coset = meet(against(bottom, FLOOR), against(left, WALL_X))
        assert (str(coset.kind), coset.dof) == ("prismatic", 1)
        members(coset, [tr((0, -3, 0)), tr((0, 2.5, 0))], [tr((0.1, 0, 0)), rz(0.1)])


def test_w3_three_against_fix_the_block():
    faces = [Plane((0, 0, 0), MZ), Plane((0, 0, 0), (-1, 0, 0)), Plane((0, 0, 0), (0, -1, 0))]
    coset = meet(*(against(f, w) for f, w in zip(faces, (FLOOR, WALL_X, WALL_Y), strict=True)))
    assert coset.dof == 0 and coset.n_components == 1
    assert np.allclose(coset.rep, I4, atol=1e-9)
    corner = [Plane((1, 2, 3), n) for n in (Z, (1, 0, 0), (0, 1, 0))]
    moved = meet(*(against(f, w) for f, w in zip(faces, corner, strict=True)))
    assert np.allclose(moved.rep, tr((1, 2, 3)), atol=1e-9)


def test_w3b_angle_mismatch_is_inconsistent():
    tilt = math.radians(10)
    tilted = Plane((0, 0, 0), (-math.cos(tilt), 0, math.sin(tilt)))
    result = meet(against(Plane((0, 0, 0), MZ), FLOOR), against(tilted, WALL_X))
    assert isinstance(result, EmptySet)
    assert result.mismatch.kind == "angle"
    assert result.mismatch.value == pytest.approx(tilt)


PLATE_TOP, BORE = Plane((0, 0, 0), Z), Hole((0, 0, 0), MZ, 5)
HEAD, PIN = Plane((0, 0, 0), MZ), Shaft((0, 0, 0), MZ, 5)


def test_w4_shaft_in_hole_with_shoulder_is_revolute():
    fit = fits(PIN, BORE)
    assert (str(fit.kind), fit.dof, fit.n_components) == ("cylindrical", 2, 1)
    coset = meet(fit, against(HEAD, PLATE_TOP))
    assert (str(coset.kind), coset.dof) == ("revolute", 1)
    members(coset, [rz(1.0), rz(-2)], [tr((0, 0, 1)), tr((1, 0, 0))])


def test_w4_radius_mismatch_is_an_inconsistency_not_an_error():
    result = fits(Shaft((0, 0, 0), MZ, 4.9), BORE)
    assert isinstance(result, EmptySet)
    assert result.mismatch.kind == "radius"
    assert result.mismatch.value == pytest.approx(0.1)


def test_fits_is_symmetric_in_which_side_is_the_shaft():
    coset = fits(BORE, PIN)  # the hole's body in the pin's frame
    members(coset, [rz(0.4) @ tr((0, 0, 3))], [tr((1, 0, 0))])


def test_w5_two_parallel_pins_prismatic():
    holes = [Hole((0, 0, 0), Z, 2), Hole((10, 0, 0), Z, 2)]
    pins = [Shaft((0, 0, 0), Z, 2), Shaft((0, 10, 0), Z, 2)]
    coset = meet(*(fits(p, h) for p, h in zip(pins, holes, strict=True)))
    assert (str(coset.kind), coset.dof, coset.n_components) == ("prismatic", 1, 1)
    members(coset, [rz(-math.pi / 2), tr((0, 0, 7)) @ rz(-math.pi / 2)], [I4])


def test_w5_undirected_pins_give_two_components():
    holes = [Hole((0, 0, 0), Z, 2, directed=False), Hole((10, 0, 0), Z, 2, directed=False)]
    pins = [Shaft((0, 0, 0), Z, 2, directed=False), Shaft((10, 0, 0), Z, 2, directed=False)]
    coset = meet(*(fits(p, h) for p, h in zip(pins, holes, strict=True)))
    assert (coset.dof, coset.n_components) == (1, 2)
    members(coset, [tr((0, 0, 3)), rx(math.pi) @ tr((0, 0, -2))], [rz(math.pi)])


def test_w6_unequal_spacing_is_inconsistent_by_2():
    holes = [Hole((0, 0, 0), Z, 2), Hole((10, 0, 0), Z, 2)]
    pins = [Shaft((0, 0, 0), Z, 2), Shaft((12, 0, 0), Z, 2)]
    result = meet(*(fits(p, h) for p, h in zip(pins, holes, strict=True)))
    assert isinstance(result, EmptySet)
    assert result.mismatch.kind == "distance"
    assert result.mismatch.value == pytest.approx(2)


def test_w7_shaft_parallel_to_face_prismatic_and_height_mismatch():
    floor, bore = Plane((0, 0, 0), Z), Hole((0, 0, 5), (1, 0, 0), 1)
    bottom = Plane((0, 0, 0), MZ)
    coset = meet(fits(Shaft((0, 0, 5), (1, 0, 0), 1), bore), against(bottom, floor))
    assert (str(coset.kind), coset.dof, coset.n_components) == ("prismatic", 1, 1)
    members(coset, [tr((4, 0, 0))], [tr((0, 1, 0)), rz(math.pi)])
    loose = Hole((0, 0, 5), (1, 0, 0), 1, directed=False)
    both = meet(fits(Shaft((0, 0, 5), (1, 0, 0), 1), loose), against(bottom, floor))
    assert (both.dof, both.n_components) == (1, 2)
    assert both.contains(rz(math.pi) @ tr((2, 0, 0)))
    low = meet(fits(Shaft((0, 0, 4), (1, 0, 0), 1), bore), against(bottom, floor))
    assert isinstance(low, EmptySet)
    assert low.mismatch.value == pytest.approx(1)


def test_w9_w10_balls_in_sockets():
    s1, s2, s3 = Socket((0, 0, 0), 1), Socket((0, 0, 10), 1), Socket((10, 0, 0), 1)
    two = meet(fits(Ball((0, 0, 0), 1), s1), fits(Ball((0, 0, 10), 1), s2))
    assert (str(two.kind), two.dof) == ("revolute", 1)
    members(two, [rz(0.7)], [rx(0.7)])
    turned = meet(fits(Ball((0, 0, 0), 1), s1), fits(Ball((0, 10, 0), 1), s2))
    members(turned, [rz(0.3) @ rx(math.pi / 2)], [I4])
    assert isinstance(meet(fits(Ball((0, 0, 0), 1), s1), fits(Ball((0, 0, 9), 1), s2)), EmptySet)
    three = meet(two, fits(Ball((10, 0, 0), 1), s3))
    assert three.dof == 0 and np.allclose(three.rep, I4, atol=1e-9)


def test_w11_ball_and_face_revolute_about_the_normal():
    coset = meet(
        fits(Ball((0, 0, 1), 1), Socket((0, 0, 1), 1)), against(Plane((0, 0, 0), MZ), FLOOR)
    )
    assert (str(coset.kind), coset.dof) == ("revolute", 1)
    members(coset, [rz(2.0)], [tr((1, 0, 0))])
    high = meet(
        fits(Ball((0, 0, 2), 1), Socket((0, 0, 1), 1)), against(Plane((0, 0, 0), MZ), FLOOR)
    )
    assert isinstance(high, EmptySet)


@pytest.mark.parametrize(("sides", "count"), [(4, 4), (2, 2), (24, 24)])
def test_w14_keyed_peg_with_shoulder_has_finitely_many_positions(sides, count):
    hole = Prism((0, 0, 0), MZ, sides=sides, size=3, male=False)
    peg = Prism((0, 0, 0), MZ, sides=sides, size=3)
    coset = meet(fits(peg, hole), against(HEAD, PLATE_TOP))
    assert (coset.dof, coset.n_components) == (0, count)
    members(coset, [rz(2 * math.pi * k / sides) for k in range(sides)], [rz(math.pi / sides)])


def test_prism_mismatches():
    hole = Prism((0, 0, 0), Z, sides=4, size=3, male=False)
    sides = fits(Prism((0, 0, 0), Z, sides=6, size=3), hole)
    assert isinstance(sides, EmptySet) and sides.mismatch.kind == "sides"
    assert sides.mismatch.value == 2
    size = fits(Prism((0, 0, 0), Z, sides=4, size=3.5), hole)
    assert isinstance(size, EmptySet) and size.mismatch.kind == "size"


def test_w16_thread_and_key_leave_a_lattice_of_lead_steps():
    nut = Thread((0, 0, 0), Z, radius=5, lead=1.5, male=False)
    bolt = Thread((0, 0, 0), Z, radius=5, lead=1.5)
    screw = fits(bolt, nut)
    assert (str(screw.kind), screw.dof) == ("helical", 1)
    assert screw.contains(se3.screw((0, 0, 0), Z, 1.5 / (2 * math.pi), 0.8))
    key = fits(Prism((3, 0, 0), Z, sides=2, size=0.5), Prism((3, 0, 0), Z, 2, 0.5, male=False))
    both = meet(screw, key)
    assert both.dof == 0 and both.n_components == math.inf
    members(both, [tr((0, 0, 1.5 * k)) for k in (-2, 1, 3)], [tr((0, 0, 0.75))])


def test_thread_lead_and_hand_mismatches():
    nut = Thread((0, 0, 0), Z, radius=5, lead=1.5, male=False)
    lead = fits(Thread((0, 0, 0), Z, radius=5, lead=1.25), nut)
    assert isinstance(lead, EmptySet) and lead.mismatch.kind == "pitch"
    assert lead.mismatch.value == pytest.approx(0.25)
    hand = fits(Thread((0, 0, 0), Z, radius=5, lead=1.5, hand="left"), nut)
    assert isinstance(hand, EmptySet) and hand.mismatch.kind == "handedness"


def test_w20_slot_is_redundant_or_inconsistent():
    floor, ceiling = Plane((0, 0, 0), Z), Plane((0, 0, 10), MZ)
    slab = meet(against(Plane((0, 0, 0), MZ), floor), against(Plane((0, 0, 10), Z), ceiling))
    assert (str(slab.kind), slab.dof) == ("planar", 3)
    thin = meet(against(Plane((0, 0, 0), MZ), floor), against(Plane((0, 0, 9.9), Z), ceiling))
    assert isinstance(thin, EmptySet)


def test_other_coset_kinds():
    coplanar = relation_coset("coplanar", Plane((0, 0, 0), Z), Plane((0, 0, 1), Z))
    members(coplanar, [tr((3, 0, 1)) @ rz(1)], [I4])
    coaxial = relation_coset("coaxial", Cone((0, 0, 0), Z, 0.3), Shaft((1, 0, 0), Z, 2))
    assert (str(coaxial.kind), coaxial.dof, coaxial.n_components) == ("cylindrical", 2, 1)
    members(coaxial, [tr((1, 0, 5)) @ rz(2)], [I4])
    fixed = relation_coset("fixed", Frame(tr((1, 2, 3))), Frame(rz(0.5)))
    assert fixed.dof == 0 and np.allclose(fixed.rep, rz(0.5) @ tr((-1, -2, -3)))
    with pytest.raises(FeatureError):
        relation_coset("fixed", Point((1, 2, 3)), Point((0, 0, 0)))
    parallel = relation_coset("parallel", Plane((0, 0, 0), (1, 0, 0)), Plane((5, 5, 5), Z))
    assert (str(parallel.kind), parallel.dof, parallel.n_components) == ("schoenflies", 4, 2)
    members(parallel, [se3.rot_y(-math.pi / 2), se3.rot_y(math.pi / 2) @ tr((1, 2, 3))], [I4])
    coincident = relation_coset("coincident", Ball((1, 0, 0), 2), Point((0, 0, 5)))
    assert (str(coincident.kind), coincident.dof) == ("spherical", 3)
    members(
        coincident, [tr((-1, 0, 5)), se3.rotation((1, 1, 0), 0.4, (0, 0, 5)) @ tr((-1, 0, 5))], [I4]
    )


# ------------------------------------------------------------ equivariance (docs/algebra.md §6)

rigid = st.builds(
    lambda seed: se3.random_transform(np.random.default_rng(seed), 5.0),
    st.integers(min_value=0, max_value=2**32 - 1),
)

PAIRS = [
    ("against", Plane((0, 0, 0), MZ), Plane((0, 0, 0), Z)),
    ("fits", Shaft((0, 0, 0), MZ, 5), Hole((1, 0, 0), MZ, 5, directed=False)),
    ("fits", Ball((0, 0, 1), 1), Socket((0, 2, 1), 1)),
    ("fits", Thread((0, 0, 0), Z, 5, 1.5, phase=0.3), Thread((0, 0, 0), Z, 5, 1.5, male=False)),
    ("fits", Prism((0, 0, 0), Z, 4, 2), Prism((0, 0, 1), Z, 4, 2, male=False, ref=(1, 1, 0))),
    ("coaxial", Shaft((0, 0, 0), Z, 5), Hole((0, 1, 0), (1, 0, 0), 2)),
    ("parallel", Plane((0, 0, 0), Z), Shaft((0, 0, 0), (1, 0, 0), 2)),
    ("coincident", Point((1, 2, 3)), Ball((0, 0, 0), 1)),
    ("fixed", Frame(tr((1, 2, 3)) @ rx(0.3)), Frame(se3.rotation((0, 1, 1), 2.0, (4, 0, 0)))),
]


@settings(max_examples=15, deadline=None)
@given(rigid, rigid)
def test_equivariance(g, h):
    for kind, first, second in PAIRS:
        base = relation_coset(kind, first, second)
        moved2 = relation_coset(kind, first.transformed(se3.inverse(g)), second)
        assert moved2.group.equals(base.group), kind
        assert moved2.contains(base.rep @ g), kind
        moved1 = relation_coset(kind, first, second.transformed(h))
        assert moved1.group.equals(base.group.conjugate(h)), kind
        assert moved1.contains(h @ base.rep), kind


# ------------------------------------------------------------------ residuals


@settings(max_examples=20, deadline=None)
@given(st.integers(min_value=0, max_value=2**32 - 1))
def test_residuals_vanish_on_coset_members_only(seed):
    rng = np.random.default_rng(seed)
    for kind, first, second in PAIRS:
        coset = relation_coset(kind, first, second)
        residual = relation_residual(kind, first, second)
        for h in coset.group.sample(rng, 3, scale=5.0):
            x = h @ coset.rep
            assert np.abs(residual(x)).max() < 1e-9, kind
            off = x @ se3.random_transform(rng, 1.0)
            assert coset.contains(off) == (np.abs(residual(off)).max() < 1e-9), kind


def test_residual_of_a_mismatch_never_vanishes():
    residual = relation_residual("fits", Shaft((0, 0, 0), Z, 4.9), Hole((0, 0, 0), Z, 5))
    assert np.abs(residual(I4)).max() == pytest.approx(0.1)


@pytest.mark.parametrize(
    ("kind", "first", "second", "options", "good", "bad"),
    [
        ("perpendicular", Plane((0, 0, 0), Z), Plane((0, 0, 0), (1, 0, 0)), {}, I4, se3.rot_y(0.2)),
        (
            "angle",
            Plane((0, 0, 0), Z),
            Plane((0, 0, 0), Z),
            {"angle": "30 deg"},
            rx(math.pi / 6),
            I4,
        ),
        ("point_on_plane", Point((0, 0, 1)), Plane((0, 0, 0), Z), {}, tr((3, 4, -1)), I4),
        (
            "point_on_plane",
            Plane((0, 0, 0), Z),
            Point((5, 5, 0)),
            {},
            tr((1, 1, 0)) @ rz(1),
            tr((0, 0, 1)),
        ),
        ("point_on_line", Point((0, 0, 0)), Shaft((1, 0, 0), Z, 1), {}, tr((1, 0, 9)), I4),
        ("distance", Point((0, 0, 0)), Point((3, 4, 0)), {"distance": 5}, I4, tr((1, 0, 0))),
        (
            "distance",
            Point((0, 0, 2)),
            Plane((0, 0, 0), Z),
            {"distance": 2},
            tr((7, 1, 0)),
            tr((0, 0, 1)),
        ),
        (
            "distance",
            Plane((0, 0, 3), Z),
            Plane((0, 0, 0), Z),
            {"distance": 3},
            tr((9, 0, 0)),
            rx(0.1),
        ),
        # a cylinder of radius 1 on the plane z = 0: its axis parallel to it, 1 above
        (
            "distance",
            Shaft((0, 0, 1), (1, 0, 0), 1),
            Plane((0, 0, 0), Z),
            {"distance": 1},
            tr((4, 5, 0)) @ rz(1),
            se3.rot_y(0.1),
        ),
        (
            "distance",
            Plane((0, 0, 0), Z),
            Shaft((0, 0, 1), (0, 1, 0), 1),
            {"distance": 1},
            rz(0.3),
            tr((0, 0, 1)),
        ),
    ],
)
def test_non_coset_residuals(kind, first, second, options, good, bad):
    residual = relation_residual(kind, first, second, options)
    assert np.abs(residual(good)).max() < 1e-12
    assert np.abs(residual(bad)).max() > 1e-3


def test_residual_scaling_weighs_angles_by_the_model_scale():
    from assemblykit.tolerance import Tolerance

    first, second = Plane((0, 0, 0), Z), Plane((0, 0, 0), (1, 0, 0))
    small = relation_residual("perpendicular", first, second)(se3.rot_y(0.1))
    large = relation_residual("perpendicular", first, second, tol=Tolerance(scale=100.0))(
        se3.rot_y(0.1)
    )
    assert large == pytest.approx(100 * small)


@pytest.mark.parametrize(
    ("kind", "first", "second", "options", "dof"),
    [
        ("against", Plane((0, 0, 0), MZ), Plane((0, 0, 0), Z), {}, 3),
        ("fits", PIN, BORE, {}, 4),
        ("fits", Ball((0, 0, 0), 1), Socket((0, 0, 0), 1), {}, 3),
        ("fits", Thread((0, 0, 0), Z, 5, 1.5), Thread((0, 0, 0), Z, 5, 1.5, male=False), {}, 5),
        ("point_on_plane", Point((0, 0, 0)), Plane((0, 0, 0), Z), {}, 1),
        ("distance", Point((0, 0, 0)), Point((0, 0, 0)), {}, 1),
        ("distance", Plane((0, 0, 0), Z), Plane((0, 0, 0), Z), {}, 3),
        ("distance", Shaft((0, 0, 0), Z, 1), Plane((0, 0, 0), Z), {}, 2),
        ("distance", Plane((0, 0, 0), Z), Hole((0, 0, 0), Z, 1), {}, 2),
        ("distance", Cone((0, 0, 0), Z, 0.3), Plane((0, 0, 0), Z), {}, 1),
        ("parallel", Plane((0, 0, 0), Z), Plane((0, 0, 0), Z), {}, 2),
        ("perpendicular", Plane((0, 0, 0), Z), Plane((0, 0, 0), Z), {}, 1),
        ("angle", Plane((0, 0, 0), Z), Plane((0, 0, 0), Z), {}, 1),
        ("coincident", Point((0, 0, 0)), Point((0, 0, 0)), {}, 3),
        ("point_on_line", Point((0, 0, 0)), Shaft((0, 0, 0), Z, 1), {}, 2),
        ("fixed", Frame(I4), Frame(I4), {}, 6),
    ],
)
def test_dof_removed(kind, first, second, options, dof):
    assert relation_dof_removed(kind, first, second) == dof


def test_dof_removed_matches_the_coset_dimension():
    for kind, first, second in PAIRS:
        assert (
            relation_dof_removed(kind, first, second) == 6 - relation_coset(kind, first, second).dof
        )


def test_coupled_relations_have_no_pair_residual():
    with pytest.raises(FeatureError, match="couples"):
        relation_residual("gear", Shaft((0, 0, 0), Z, 1), Shaft((5, 0, 0), Z, 1), {"ratio": -2})
