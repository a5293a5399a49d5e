"""Hervé subgroups, membership, intersection, discrete parts and orbits
(src/assemblykit/algebra/lie.py, groups.py, loci.py, subspaces.py, connected_meets.py,
meets.py; docs/algebra.md §2.1-§2.4, W14, W16, W21)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from assemblykit.algebra import Coset, Kind, Locus, SymmetryGroup, intersect_groups, se3
from assemblykit.algebra.connected_meets import connected_meet
from assemblykit.algebra.groups import classify_algebra
from assemblykit.algebra.subspaces import psd_solve
from assemblykit.errors import GroupError
from assemblykit.tolerance import DEFAULT, Tolerance

G = SymmetryGroup
Z = (0.0, 0.0, 1.0)
ORIGIN = (0.0, 0.0, 0.0)
seeds = st.integers(min_value=0, max_value=2**32 - 1)


def tr(x, y, z):
    return se3.translation((x, y, z))


# ----------------------------------------------------------------------------- kinds


def test_kind_values_are_herve_names():
    assert [k.value for k in Kind] == [
        "fixed", "revolute", "prismatic", "helical", "cylindrical", "translation2",
        "translation3", "spherical", "planar", "pseudo-planar", "schoenflies", "free",
    ]  # fmt: skip
    assert Kind("pseudo-planar") is Kind.PSEUDO_PLANAR


@pytest.mark.parametrize(
    ("group", "dof"),
    [
        (G.identity(), 0),
        (G.revolute(ORIGIN, Z), 1),
        (G.prismatic(Z), 1),
        (G.helical(ORIGIN, Z, 0.5), 1),
        (G.cylindrical(ORIGIN, Z), 2),
        (G.translation2(Z), 2),
        (G.translation3(), 3),
        (G.spherical(ORIGIN), 3),
        (G.planar(Z), 3),
        (G.pseudo_planar(Z, 0.5), 3),
        (G.schoenflies(Z), 4),
        (G.free(), 6),
    ],
)
def test_dof_matches_the_table_and_algebra_rank(group, dof):
    assert group.dof == dof
    assert group.algebra.shape == (6, dof)
    if dof:
        assert np.linalg.matrix_rank(group.algebra) == dof
    assert group.n_components == 1


def test_zero_pitch_helical_is_revolute():
    assert G.helical(ORIGIN, Z, 0.0).kind is Kind.REVOLUTE
    assert G.pseudo_planar(Z, 0.0).kind is Kind.PLANAR


# ----------------------------------------------------------------------------- membership


def test_membership_predicates_of_section_2_3():
    line = G.revolute((1, 0, 0), Z)
    assert line.contains(se3.rotation(Z, 0.7, (1, 0, 0)))
    assert not line.contains(se3.rot_z(0.7))
    assert G.prismatic(Z).contains(tr(0, 0, -4)) and not G.prismatic(Z).contains(tr(0, 1e-5, 0))
    helix = G.helical(ORIGIN, Z, 0.5)
    assert helix.contains(tr(0, 0, 0.5 * 0.3) @ se3.rot_z(0.3))
    # 2 pi periodicity: the same rotation with the translation of the next turn.
    assert helix.contains(tr(0, 0, 0.5 * (0.3 + 2 * math.pi)) @ se3.rot_z(0.3))
    assert not helix.contains(tr(0, 0, 0.5 * 0.3 + 0.1) @ se3.rot_z(0.3))
    assert G.planar(Z).contains(tr(1, 2, 0) @ se3.rot_z(0.3))
    assert not G.planar(Z).contains(tr(0, 0, 0.1))
    assert not G.planar(Z).contains(se3.rot_x(0.1))
    assert G.spherical((0, 0, 1)).contains(se3.rotation((1, 1, 0), 2.0, (0, 0, 1)))
    assert not G.spherical((0, 0, 1)).contains(se3.rot_x(1.0))
    assert G.schoenflies(Z).contains(tr(4, 5, 6) @ se3.rot_z(1))
    assert not G.schoenflies(Z).contains(se3.rot_y(1))
    assert G.translation2(Z).contains(tr(3, -1, 0)) and not G.translation2(Z).contains(tr(0, 0, 1))
    assert G.pseudo_planar(Z, 1.0).contains(tr(5, 6, 0.2) @ se3.rot_z(0.2))
    assert not G.pseudo_planar(Z, 1.0).contains(tr(5, 6, 0.3) @ se3.rot_z(0.2))


def test_length_tolerance_scales_with_the_model():
    t = tr(0, 0, 1e-5)
    assert not G.planar(Z).contains(t, Tolerance())
    assert G.planar(Z).contains(t, Tolerance(scale=1000.0))


def test_invariants_and_describe():
    r = G.revolute((0, 0, 1), Z)
    assert r.describe() == "revolute about line through (0, 0, 1) along +Z"
    inv = G.helical((1, 2, 3), (0, 1, 0), 0.25).invariants
    np.testing.assert_allclose(inv["point"], (1, 2, 3))
    np.testing.assert_allclose(inv["axis"], (0, 1, 0))
    assert inv["pitch"] == 0.25
    np.testing.assert_allclose(G.planar((0, 0, 2)).invariants["normal"], Z)
    assert set(G.translation3().invariants) == set()


def test_element_places_the_canonical_family():
    c = G.cylindrical((1, 0, 0), Z)
    np.testing.assert_allclose(
        c.element((math.pi, 2.0)), tr(0, 0, 2) @ se3.rotation(Z, math.pi, (1, 0, 0)), atol=1e-12
    )


# ----------------------------------------------------------------------------- classification


@pytest.mark.parametrize(
    "group",
    [
        G.revolute((1, 2, 0), (0, 1, 1)),
        G.helical((1, 0, 0), (1, 1, 1), -0.3),
        G.cylindrical((0, 5, 0), (1, 0, 0)),
        G.prismatic((1, 2, 3)),
        G.translation2((0, 1, 0)),
        G.translation3(),
        G.spherical((1, -2, 3)),
        G.planar((1, 0, 1)),
        G.pseudo_planar((0, 1, 0), 0.7),
        G.schoenflies((0, 0, 1)),
        G.free(),
    ],
)
def test_classify_algebra_recovers_the_group(group):
    found = classify_algebra(group.algebra, tol=DEFAULT)
    assert found.kind is group.kind
    assert found.equals(group)
    if group.kind in (Kind.HELICAL, Kind.PSEUDO_PLANAR):
        assert found.pitch == pytest.approx(group.pitch)


# ----------------------------------------------------------------------------- intersections


def test_tr_intersection_table():
    x, y = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)
    # W2 algebra check: G(z) ∩ G(x) = T(y)
    t = intersect_groups(G.planar(Z), G.planar(x))
    assert t.kind is Kind.PRISMATIC and t.equals(G.prismatic(y))
    assert intersect_groups(G.prismatic(x), G.prismatic(y)).kind is Kind.FIXED
    assert intersect_groups(G.translation2(Z), G.translation2(x)).equals(G.prismatic(y))
    assert intersect_groups(G.revolute(ORIGIN, Z), G.revolute((1, 0, 0), Z)).kind is Kind.FIXED
    assert intersect_groups(G.revolute(ORIGIN, Z), G.spherical((0, 0, 4))).equals(
        G.revolute(ORIGIN, Z)
    )
    assert intersect_groups(G.revolute(ORIGIN, Z), G.spherical((1, 0, 4))).kind is Kind.FIXED
    assert intersect_groups(G.cylindrical(ORIGIN, Z), G.cylindrical((3, 0, 0), Z)).equals(
        G.prismatic(Z)
    )
    # W4: C(z) ∩ G(z) = R(z); W7: C(x-axis at height 5) ∩ G(z) = T(x)
    assert intersect_groups(G.cylindrical(ORIGIN, Z), G.planar(Z)).equals(G.revolute(ORIGIN, Z))
    assert intersect_groups(G.cylindrical((0, 0, 5), x), G.planar(Z)).equals(G.prismatic(x))
    assert intersect_groups(G.cylindrical(ORIGIN, Z), G.schoenflies(x)).equals(G.prismatic(Z))
    # W9: S(N1) ∩ S(N2) = R(line N1 N2); W11: S(N) ∩ G(z) = R(N, z)
    assert intersect_groups(G.spherical(ORIGIN), G.spherical((0, 0, 10))).equals(
        G.revolute(ORIGIN, Z)
    )
    assert intersect_groups(G.spherical((0, 0, 1)), G.planar(Z)).equals(G.revolute((0, 0, 1), Z))
    assert intersect_groups(G.planar(Z), G.schoenflies(x)).equals(G.translation2(Z))
    assert intersect_groups(G.schoenflies(Z), G.schoenflies(x)).equals(G.translation3())


def test_helical_lattice_rows_of_the_table():
    p = 1.5 / (2 * math.pi)
    h = G.helical(ORIGIN, Z, p)
    # W16: H(z, p) ∩ T(z) = <Tr(0, 0, 2 pi p)> = {Tr(0, 0, 1.5 k)}
    lat = intersect_groups(h, G.prismatic(Z))
    assert lat.dof == 0 and lat.n_components == math.inf
    for k in (-2, 1, 3):
        assert lat.contains(tr(0, 0, 1.5 * k))
    assert not lat.contains(tr(0, 0, 1.0))
    assert not lat.contains(se3.rot_z(0.1))
    # H ∩ C on a parallel distinct axis and H ∩ G(v), v ⊥ u: the same lattice
    assert intersect_groups(h, G.cylindrical((1, 0, 0), Z)).equals(lat)
    assert intersect_groups(h, G.planar((1, 0, 0))).equals(lat)
    assert intersect_groups(h, G.revolute(ORIGIN, Z)).kind is Kind.FIXED
    assert intersect_groups(h, G.revolute(ORIGIN, Z)).n_components == 1
    assert intersect_groups(h, G.cylindrical(ORIGIN, Z)).equals(h)
    # Y(u, p) ∩ C(N, u) = H(N, u, p); Y ∩ G(u) = T2(u); Y ∩ T3 = T2(u) x <Tr(2 pi p u)>
    y = G.pseudo_planar(Z, p)
    assert intersect_groups(y, G.cylindrical((2, 0, 0), Z)).equals(G.helical((2, 0, 0), Z, p))
    assert intersect_groups(y, G.planar(Z)).equals(G.translation2(Z))
    yt = intersect_groups(y, G.translation3())
    assert yt.kind is Kind.TRANSLATION2 and yt.n_components == math.inf
    assert yt.contains(tr(7, -3, 3.0)) and not yt.contains(tr(7, -3, 2.0))


def test_discrete_screw_group_of_two_pitches():
    # H(p) ∩ H(q), same axis: <Scr(phi; q)> with phi = 2 pi p / (q - p); p=1, q=3: phi = pi.
    s = intersect_groups(G.helical(ORIGIN, Z, 1.0), G.helical(ORIGIN, Z, 3.0))
    assert s.dof == 0 and s.n_components == math.inf
    g = se3.screw(ORIGIN, Z, 3.0, math.pi)
    assert s.contains(g) and s.contains(g @ g) and s.contains(se3.inverse(g))
    assert not s.contains(se3.screw(ORIGIN, Z, 3.0, math.pi / 2))


def test_lattices_of_incommensurate_periods_meet_trivially():
    a = G.lattice_group([tr(0, 0, 1.0)])
    b = G.lattice_group([tr(0, 0, math.sqrt(2))])
    assert intersect_groups(a, b).n_components == 1
    c = intersect_groups(a, G.lattice_group([tr(0, 0, 1.5)]))
    assert c.contains(tr(0, 0, 3.0)) and not c.contains(tr(0, 0, 1.5))


def test_cyclic_lattice_meets_by_the_lcm_rule():
    """<Tr(0,0,1.5)> ∩ B in closed form (§2.4 "Finite parts"): the lcm of the periods."""
    a = G.lattice_group([tr(0, 0, 1.5)])
    steps = {
        "lead 1": intersect_groups(a, G.helical(ORIGIN, Z, 1.0 / (2 * math.pi))),
        "lead 0.6": intersect_groups(a, G.helical(ORIGIN, Z, 0.6 / (2 * math.pi))),
        "lattice 1": intersect_groups(a, G.lattice_group([tr(0, 0, 1.0)])),
        "lattice 0.5": intersect_groups(a, G.lattice_group([tr(0, 0, -0.5)])),
    }
    for name, met in steps.items():
        assert met.kind is Kind.FIXED and len(met.lattice) == 1, name
        assert abs(met.lattice[0][2, 3]) == pytest.approx(3.0 if name != "lattice 0.5" else 1.5)
    assert intersect_groups(a, G.prismatic(Z)).lattice[0][2, 3] == pytest.approx(1.5)
    # Incommensurate lead, or a direction the lattice never reaches: only I.
    assert intersect_groups(a, G.helical(ORIGIN, Z, math.sqrt(2) / (2 * math.pi))).n_components == 1
    assert intersect_groups(a, G.prismatic((1, 0, 0))).n_components == 1


def test_discrete_screw_lattice_meets_in_closed_form():
    """<Scr(-3 pi; 1)> (from H(1) ∩ H(3)) rotates by pi per step."""
    s = intersect_groups(G.helical(ORIGIN, Z, 1.0), G.helical(ORIGIN, Z, 3.0))
    # No rotation: every second step, a translation by -6 pi.
    np.testing.assert_allclose(
        intersect_groups(s, G.prismatic(Z)).lattice[0], tr(0, 0, -6 * math.pi), atol=1e-12
    )
    # No axial motion: only I.
    assert intersect_groups(s, G.revolute(ORIGIN, Z)).n_components == 1
    # H(2): -3 pi k = 2 (-3 pi k + 2 pi m) holds for k in 4Z.
    np.testing.assert_allclose(
        intersect_groups(s, G.helical(ORIGIN, Z, 2.0)).lattice[0],
        tr(0, 0, -12 * math.pi),
        atol=1e-12,
    )
    # Its own group: all of it.
    assert intersect_groups(s, G.helical(ORIGIN, Z, 3.0)).equals(s)


def test_one_parameter_groups_through_lattice_generators():
    from assemblykit.algebra.groups import lattice_parameter, one_parameter

    t = one_parameter(tr(0, 0, 1.5), tol=DEFAULT)
    assert t is not None and t.kind is Kind.PRISMATIC
    assert lattice_parameter(t, tr(0, 0, 1.5), tr(0, 0, -4.5)) == pytest.approx(-3.0)
    tau = se3.screw((1, 0, 0), Z, 0.5, 2.0)
    h = one_parameter(tau, tol=DEFAULT)
    assert h is not None and h.kind is Kind.HELICAL and h.pitch == pytest.approx(0.5)
    assert h.contains(tau) and h.contains(tau @ tau @ tau)
    assert lattice_parameter(h, tau, tau @ tau @ tau) == pytest.approx(3.0)
    assert one_parameter(se3.rot_z(0.5), tol=DEFAULT) is None


def test_with_known_discrete_merges_components_without_closure_checks():
    half = se3.rot_z(math.pi)
    # Rz(pi) . Tr(0, 0, 3) is in the same T(z)-coset as Rz(pi): merged.
    g = G.prismatic(Z).with_known_discrete(reps=(half, half @ tr(0, 0, 3)))
    assert g.n_components == 2 and g.contains(half @ tr(0, 0, -7)) and g.contains(tr(0, 0, 2))
    assert not g.contains(se3.rot_z(math.pi / 2))
    assert g.equals(G.prismatic(Z).with_discrete(reps=(half,)))


def test_finite_parts_w14():
    c4 = tuple(se3.rot_z(k * math.pi / 2) for k in range(4))
    peg = G.prismatic(Z).with_discrete(reps=c4)
    assert peg.n_components == 4 and peg.dof == 1
    met = intersect_groups(peg, G.planar(Z))
    assert met.kind is Kind.FIXED and met.n_components == 4
    assert met.equals(G.cyclic(ORIGIN, Z, 4))
    assert intersect_groups(G.cyclic(ORIGIN, Z, 4), G.cyclic(ORIGIN, Z, 6)).equals(
        G.cyclic(ORIGIN, Z, 2)
    )


def test_with_discrete_rejects_non_groups():
    with pytest.raises(GroupError):
        G.finite([se3.rot_z(math.pi / 2)])  # its square is missing
    with pytest.raises(GroupError):
        G.revolute(ORIGIN, Z).with_discrete(reps=(se3.rot_x(0.3),))  # does not normalise R(z)


def test_extended_by_generates_the_dihedral_group():
    d4 = G.cyclic(ORIGIN, Z, 4).extended_by([se3.rot_x(math.pi)])
    assert d4.n_components == 8
    assert d4.contains(se3.rot_z(math.pi / 2) @ se3.rot_x(math.pi))
    flipped = G.cylindrical(ORIGIN, Z).extended_by([se3.rot_x(math.pi)])
    assert flipped.n_components == 2 and flipped.contains(se3.rot_y(math.pi) @ tr(0, 0, 3))


# ----------------------------------------------------------------------------- many components


def prism_group(n: int, phase: float = 0.0) -> SymmetryGroup:
    """T(z) ⋊ Cₙ about the z axis as a prism feature lists it: I and the n - 1 turns (the
    frame's x axis, through a vertex, at ``phase``)."""
    turns = tuple(se3.rot_z(math.tau * k / n) for k in range(1, n))
    return SymmetryGroup(Kind.PRISMATIC, se3.rot_z(phase), 0.0, (np.eye(4), *turns))


SIDES = 360
"""Sides of the large prisms (each turn a component); ``benchmarks/bench_algebra.py``
times the same meets with 1000 sides against their targets."""


def test_a_prism_of_many_sides_in_its_hole_against_a_face_has_one_position_a_side():
    """W14 with 360 sides: the prism fit (T(z) ⋊ C₃₆₀) meets the face contact G(z) in
    the 360 turns Rz(2πk/360), no more (not the half steps)."""
    met = Coset(prism_group(SIDES), np.eye(4)).intersect(Coset(G.planar(Z), np.eye(4)))
    assert isinstance(met, Coset)
    assert (met.dof, met.n_components) == (0, SIDES)
    assert met.group.equals(G.cyclic(ORIGIN, Z, SIDES))
    step = math.tau / SIDES
    assert met.contains(se3.rot_z(217 * step)) and met.contains(se3.rot_z(-step))
    assert not met.contains(se3.rot_z(217.5 * step)) and not met.contains(tr(0, 0, 1e-3))


def test_meets_of_large_cyclic_parts_keep_the_common_turns():
    """C₃₆₀ ∩ C₅₄₀ = C₁₈₀ (gcd), and the same turns with the slide of two coaxial
    prisms of 360 and 540 sides: T(z) ⋊ C₁₈₀."""
    met = intersect_groups(G.cyclic(ORIGIN, Z, SIDES), G.cyclic(ORIGIN, Z, 3 * SIDES // 2))
    assert met.kind is Kind.FIXED and met.equals(G.cyclic(ORIGIN, Z, SIDES // 2))
    slid = intersect_groups(prism_group(SIDES), prism_group(3 * SIDES // 2))
    assert slid.kind is Kind.PRISMATIC and slid.n_components == SIDES // 2
    assert slid.contains(se3.rot_z(math.tau * 3 / (SIDES // 2)) @ tr(0, 0, 7))
    assert not slid.contains(se3.rot_z(math.tau / SIDES))


def test_with_discrete_checks_the_closure_of_many_components():
    """The 359 turns of C₃₆₀ over T(z) close into 360 components; without one of them
    they do not."""
    turns = [se3.rot_z(math.tau * k / SIDES) for k in range(1, SIDES)]
    group = G.prismatic(Z).with_discrete(reps=tuple(turns))
    assert group.n_components == SIDES and group.equals(prism_group(SIDES))
    with pytest.raises(GroupError, match="not closed"):
        G.prismatic(Z).with_discrete(reps=tuple(turns[: SIDES // 2] + turns[SIDES // 2 + 1 :]))


def all_pairs_meet(a: SymmetryGroup, b: SymmetryGroup) -> SymmetryGroup:
    """A ∩ B from the meets A0 α ∩ B0 β of every pair of components (§2.4, the definition)."""
    a0, b0 = a.connected_part, b.connected_part
    found = [
        met.rep
        for x in a.reps
        for y in b.reps
        if isinstance(met := Coset(a0, x).intersect(Coset(b0, y)), Coset)
    ]
    return connected_meet(a0, b0, Tolerance()).with_known_discrete(reps=tuple(found))


FLIP = se3.rot_x(math.pi)
MEET_CASES = {
    "coaxial prisms": (prism_group(12), prism_group(18), 6),
    "prism and turns": (prism_group(12), G.cyclic(ORIGIN, Z, 8), 4),
    "turns and prism": (G.cyclic(ORIGIN, Z, 8), prism_group(12, phase=math.pi / 12), 4),
    "dihedral and flipped prism": (
        G.cyclic(ORIGIN, Z, 4).extended_by([FLIP]),
        prism_group(6).extended_by([FLIP]),
        4,
    ),
    "turns about parallel axes": (G.cyclic((1.0, 0.0, 0.0), Z, 6), G.cyclic(ORIGIN, Z, 6), 1),
    "flipped cylinder and turns": (
        G.cylindrical(ORIGIN, Z).extended_by([FLIP]),
        G.cyclic(ORIGIN, Z, 6).extended_by([FLIP]),
        12,
    ),
    "crossed prisms": (prism_group(4), prism_group(6).conjugate(se3.rot_y(math.pi / 2)), 1),
}


@pytest.mark.parametrize("case", MEET_CASES)
def test_meets_pair_only_the_components_that_can_meet(case):
    """When one connected part contains the other, a component meets only those of the
    other group near it: the same components, in the same order, as meeting every pair."""
    a, b, components = MEET_CASES[case]
    met, expected = intersect_groups(a, b), all_pairs_meet(a, b)
    assert met.kind is expected.kind and np.array_equal(met.frame, expected.frame)
    assert len(met.reps) == len(expected.reps) == components
    assert all(np.array_equal(x, y) for x, y in zip(met.reps, expected.reps, strict=True))


KINDS_WITH_PITCH = [
    (kind, 0.7 if kind in (Kind.HELICAL, Kind.PSEUDO_PLANAR) else 0.0) for kind in Kind
]


def scan_dedupe(g0: SymmetryGroup, elements: list, tol: Tolerance) -> list:
    """One element per G0-coset by testing every kept one (the definition)."""
    kept: list = []
    for g in elements:
        if not any(g0.contains(g @ se3.inverse(f), tol) for f in kept):
            kept.append(g)
    return kept


def near_copies(rng: np.random.Generator, g0: SymmetryGroup, g, tol: Tolerance) -> list:
    """``g`` moved by elements of G0 and by perturbations of 0.3 to 4 tolerances."""
    out = []
    for size in (0.0, 0.3, 0.8, 1.5, 4.0):
        params = rng.uniform(-1.0, 1.0, g0.dof) * np.where(g0.angle_parameters(), math.pi, 5.0)
        axis = se3.unit(rng.normal(size=3))
        nudge = se3.rotation(axis, size * tol.angle) @ se3.translation(
            size * tol.length * se3.unit(rng.normal(size=3))
        )
        out.append(nudge @ g0.element(params) @ g)
    return out


@pytest.mark.parametrize(("kind", "pitch"), KINDS_WITH_PITCH)
@pytest.mark.parametrize("tol", [Tolerance(), Tolerance(scale=50.0, rel_length=1e-6, angle=1e-6)])
@settings(max_examples=3, deadline=None)
@given(seed=seeds)
def test_keyed_components_answer_as_a_scan_of_all_components(kind, pitch, tol, seed):
    """Merging components and membership test only the components with nearby coset keys;
    the answers are those of testing every component, for every family, also for
    elements within and just beyond the tolerance of each other."""
    rng = np.random.default_rng(seed)
    g0 = G.connected(kind, se3.random_transform(rng), pitch)
    elements = [
        copy for _ in range(6) for copy in near_copies(rng, g0, se3.random_transform(rng), tol)
    ]
    order = rng.permutation(len(elements))
    elements = [elements[i] for i in order]
    group = g0.with_known_discrete(reps=tuple(elements), tol=tol)
    expected = scan_dedupe(g0, [np.eye(4), *elements], tol)
    assert len(group.reps) == len(expected)
    assert all(np.array_equal(a, b) for a, b in zip(group.reps[1:], expected[1:], strict=True))
    queries = [
        copy
        for g in (*elements[:8], se3.random_transform(rng))
        for copy in near_copies(rng, g0, g, tol)
    ]
    for q in queries:
        scan = any(g0.contains(q @ se3.inverse(r), tol) for r in group.reps)
        assert group.contains(q, tol) is scan


# ----------------------------------------------------------------------------- orbits W21


def test_orbits_w21():
    circle = G.revolute(ORIGIN, Z).orbit((3, 4, 0))
    assert circle.kind == "circle" and circle.radius == pytest.approx(5.0)
    assert circle.contains((5, 0, 0)) and not circle.contains((5, 0, 1))
    plane = G.planar(Z).orbit((3, 4, 0))
    assert plane.kind == "plane" and plane.contains((-7, 1, 0)) and not plane.contains((0, 0, 1))
    axis = G.helical(ORIGIN, Z, 0.4).orbit((0, 0, 2))
    assert axis.kind == "line" and axis.contains((0, 0, -9))
    assert G.pseudo_planar(Z, 0.4).orbit((3, 4, 0)).kind == "space"
    sphere = G.spherical(ORIGIN).orbit((1, 0, 0))
    assert sphere.kind == "sphere" and sphere.radius == 1.0 and sphere.contains((0, 0.6, 0.8))
    helix = G.helical(ORIGIN, Z, 0.5).orbit((1, 0, 0))
    assert helix.kind == "helix"
    assert helix.contains((0, 1, 0.5 * math.pi / 2)) and not helix.contains((0, 1, 0))
    four = G.cyclic(ORIGIN, Z, 4).orbit((1, 0, 0))
    assert four.kind == "union" and four.contains((0, -1, 0)) and not four.contains((1, 1, 0))


# ----------------------------------------------------------------------------- properties


def _random_group(rng: np.random.Generator) -> SymmetryGroup:
    place = se3.random_transform(rng)
    canon = [
        G.revolute(ORIGIN, Z),
        G.prismatic(Z),
        G.helical(ORIGIN, Z, float(rng.uniform(0.2, 2.0))),
        G.cylindrical(ORIGIN, Z),
        G.translation2(Z),
        G.spherical(ORIGIN),
        G.planar(Z),
        G.pseudo_planar(Z, float(rng.uniform(0.2, 2.0))),
        G.schoenflies(Z),
    ]
    return canon[int(rng.integers(len(canon)))].conjugate(place)


@settings(max_examples=50, deadline=None)
@given(seeds)
def test_group_laws_on_samples(seed):
    rng = np.random.default_rng(seed)
    g = _random_group(rng)
    a, b = g.sample(rng, 2)
    assert g.contains(a @ b)
    assert g.contains(se3.inverse(a))
    assert g.contains(np.eye(4))


@settings(max_examples=50, deadline=None)
@given(seeds)
def test_contains_is_invariant_under_conjugation(seed):
    rng = np.random.default_rng(seed)
    g = _random_group(rng)
    t = se3.random_transform(rng)
    x = g.sample(rng, 1)[0]
    assert g.conjugate(t).contains(t @ x @ se3.inverse(t))
    y = se3.random_transform(rng)
    assert g.contains(y) == g.conjugate(t).contains(t @ y @ se3.inverse(t))


def assert_meet_sound_and_equivariant(
    rng: np.random.Generator, a: SymmetryGroup, b: SymmetryGroup
) -> None:
    """Sampled members of a ∩ b lie in both, and the meet commutes with conjugation."""
    m = intersect_groups(a, b)
    for x in m.sample(rng, 3):
        assert a.contains(x) and b.contains(x)
    t = se3.random_transform(rng)
    assert intersect_groups(a.conjugate(t), b.conjugate(t)).equals(m.conjugate(t))


def _tr_group(rng: np.random.Generator) -> SymmetryGroup:
    # Random TR groups whose invariants sometimes coincide (so meets are non-trivial).
    pts = [np.zeros(3), np.array([0.0, 0.0, 2.0])]
    dirs = [np.array(Z), np.array([1.0, 0.0, 0.0])]
    p, d = pts[int(rng.integers(2))], dirs[int(rng.integers(2))]
    make = [
        lambda: G.revolute(p, d),
        lambda: G.cylindrical(p, d),
        lambda: G.prismatic(d),
        lambda: G.spherical(p),
        lambda: G.planar(d).conjugate(se3.translation(p)),
        lambda: G.schoenflies(d),
        lambda: G.translation2(d),
    ]
    return make[int(rng.integers(len(make)))]()


@settings(max_examples=50, deadline=None)
@given(seeds)
def test_intersection_members_lie_in_both_and_conjugation_commutes(seed):
    rng = np.random.default_rng(seed)
    assert_meet_sound_and_equivariant(rng, _tr_group(rng), _tr_group(rng))


@settings(max_examples=50, deadline=None)
@given(seeds)
def test_closed_form_tr_meet_agrees_with_the_lie_algebra_route(seed):
    rng = np.random.default_rng(seed)
    a, b = _tr_group(rng), _tr_group(rng)
    from assemblykit.algebra.lie import null_space, scaled_twists

    tol = Tolerance()
    null = null_space(scaled_twists(np.hstack((a.algebra, -b.algebra)), tol), tol)
    via_algebra = classify_algebra(a.algebra @ null[: a.dof], tol)
    assert connected_meet(a, b, tol).equals(via_algebra)


def _any_group(rng: np.random.Generator) -> SymmetryGroup:
    # All connected families, with axes that often coincide or are parallel.
    p = [np.zeros(3), np.array([1.0, 0.0, 0.0])][int(rng.integers(2))]
    d = [np.array(Z), np.array([1.0, 0.0, 0.0])][int(rng.integers(2))]
    pitch = [0.5, 1.0, 1.5][int(rng.integers(3))]
    make = [
        lambda: G.revolute(p, d),
        lambda: G.prismatic(d),
        lambda: G.helical(p, d, pitch),
        lambda: G.cylindrical(p, d),
        lambda: G.translation2(d),
        lambda: G.translation3(),
        lambda: G.spherical(p),
        lambda: G.planar(d),
        lambda: G.pseudo_planar(d, pitch),
        lambda: G.schoenflies(d),
    ]
    return make[int(rng.integers(len(make)))]()


@settings(max_examples=50, deadline=None)
@given(seeds)
def test_intersections_with_helical_groups_are_sound_and_equivariant(seed):
    rng = np.random.default_rng(seed)
    assert_meet_sound_and_equivariant(rng, _any_group(rng), _any_group(rng))


@pytest.mark.parametrize("rel", [1e-9, 1e-2, 0.1])
def test_psd_solve_is_regular_whatever_the_tolerance(rel):
    """diag(3, 3, 1) x = (15, 15, -10) has the one solution (5, 5, -10) (by hand); a loose
    tolerance must not make it a minimum-norm least-squares answer."""
    x = psd_solve((3.0, 0.0, 0.0, 3.0, 0.0, 1.0), (15.0, 15.0, -10.0), Tolerance.relative(rel))
    assert x == pytest.approx((5.0, 5.0, -10.0), abs=1e-12)


@pytest.mark.parametrize(
    ("kind", "radius", "expected"),
    [
        ("point", 0.0, math.sqrt(29)),
        ("circle", 1.0, math.hypot(2, 4)),
        ("cylinder", 2.0, 3.0),
        ("line", 0.0, 5.0),
        ("plane", 0.0, 2.0),
        ("sphere", 1.0, math.sqrt(29) - 1),
    ],
)
def test_locus_distance_of_a_point_by_hand(kind, radius, expected):
    """(3, 4, 2) from loci about the z axis through the origin: 4 out and 2 up."""
    locus = Locus(kind, point=np.zeros(3), direction=np.array([0.0, 0.0, 1.0]), radius=radius)
    assert locus.distance(np.array([3.0, 4.0, 2.0]))[0] == pytest.approx(expected, abs=1e-12)


def test_a_helix_has_no_closed_form_distance():
    with pytest.raises(GroupError):
        Locus("helix", point=np.zeros(3), direction=np.array([0.0, 0.0, 1.0])).distance(np.zeros(3))


def test_intersect_groups_meets_connected_and_finite_groups():
    """:func:`intersect_groups` for connected groups and for finite ones (the turns of a
    square about z meet those of a hexagon in the half turns: C4 ∩ C6 = C2, 2
    components), the same either way round."""
    cylinder = SymmetryGroup.cylindrical((0, 0, 0), (0, 0, 1))
    plane = SymmetryGroup.planar((0, 0, 1))
    assert intersect_groups(cylinder, plane).kind is Kind.REVOLUTE
    assert intersect_groups(cylinder, plane).equals(intersect_groups(plane, cylinder))
    square = SymmetryGroup.cyclic((0, 0, 0), (0, 0, 1), 4)
    hexagon = SymmetryGroup.cyclic((0, 0, 0), (0, 0, 1), 6)
    met = intersect_groups(square, hexagon)
    assert met.equals(intersect_groups(hexagon, square))
    assert (met.dof, met.n_components) == (0, 2)


def test_orbit_kinds_are_locus_kinds_equal_to_their_strings():
    from assemblykit.algebra import LocusKind

    circle = SymmetryGroup.revolute(ORIGIN, Z).orbit((1.0, 0.0, 0.0))
    assert circle.kind is LocusKind.CIRCLE and circle.kind == "circle"
    assert SymmetryGroup.free().orbit(ORIGIN).kind is LocusKind.SPACE
    union = SymmetryGroup.cyclic(ORIGIN, Z, 2).orbit((1.0, 0.0, 0.0))
    assert union.kind is LocusKind.UNION and len(union.members) == 2
    # a locus given by its kind's string keeps working
    assert Locus("sphere", point=np.zeros(3), radius=1.0).contains((0.0, 1.0, 0.0))
