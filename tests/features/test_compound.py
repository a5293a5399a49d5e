"""Pairwise relationships (Liu 1997 Def. 3.1.2) and compound-feature groups (§4.1)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from assemblykit.algebra import Kind, se3
from assemblykit.errors import FeatureError
from assemblykit.features import (
    Axis,
    Ball,
    CompoundFeature,
    Cone,
    Hole,
    Plane,
    Point,
    Prism,
    Relationship,
    Shaft,
    Socket,
    Thread,
    Torus,
    compound_group,
    relationship,
)
from assemblykit.tolerance import Tolerance

D, ONE, TWO, COMP = (
    Relationship.DISTINCT,
    Relationship.ONE_CONGRUENT,
    Relationship.TWO_CONGRUENT,
    Relationship.COMPLEMENTARY,
)


@pytest.mark.parametrize(
    ("f1", "f2", "expected"),
    [
        # Liu 1997 Fig. 1: adjacent faces of a cube are swapped by a half-turn.
        (Plane((0, 0, 0), (1, 0, 0)), Plane((0, 0, 0), (0, 1, 0)), TWO),
        # Liu 1997: parallel planes, normals the same way -> 1-congruent ...
        (Plane((0, 0, 0), (0, 0, 1)), Plane((0, 0, 3), (0, 0, 1)), ONE),
        # ... normals opposite (a slot, or a slab) -> 2-congruent.
        (Plane((0, 0, 0), (0, 0, 1)), Plane((0, 0, 10), (0, 0, -1)), TWO),
        (Plane((0, 0, 0), (0, 0, 1)), Plane((0, 0, 10), (0, 0, 1)), ONE),
        # Liu 1997 Fig. 5: parallel cylinders of equal radius, same side.
        (Shaft((0, 0, 0), (0, 0, 1), 2), Shaft((5, 0, 0), (0, 0, 1), 2), TWO),
        (Shaft((0, 0, 0), (0, 0, 1), 2), Shaft((5, 0, 0), (0, 1, 0), 2), TWO),
        # Liu 1997 Fig. 2(b) / Fig. 6: a hole and a shaft of one radius are complementary.
        (Hole((0, 0, 0), (0, 0, 1), 2), Shaft((5, 0, 0), (0, 0, 1), 2), COMP),
        (Ball((0, 0, 0), 1), Socket((3, 0, 0), 1), COMP),
        (Shaft((0, 0, 0), (0, 0, 1), 2), Shaft((0, 0, 0), (0, 0, 1), 3), D),
        (Shaft((0, 0, 0), (0, 0, 1), 2), Plane((0, 0, 0), (0, 0, 1)), D),
        (Ball((0, 0, 0), 1), Ball((3, 0, 0), 1), TWO),
        # Liu 1997 Fig. 4: coaxial cones, apexes apart along the axis -> 1-congruent.
        (Cone((0, 0, 0), (0, 0, 1), 0.3), Cone((0, 0, 2), (0, 0, 1), 0.3), ONE),
        (Cone((0, 0, 0), (0, 0, 1), 0.3), Cone((0, 0, 2), (0, 0, -1), 0.3), TWO),
        (Cone((0, 0, 0), (0, 0, 1), 0.3), Cone((4, 0, 0), (0, 0, 1), 0.3), TWO),
        (Cone((0, 0, 0), (0, 0, 1), 0.3), Cone((0, 0, 0), (0, 0, 1), 0.3, male=False), COMP),
        (Cone((0, 0, 0), (0, 0, 1), 0.3), Cone((0, 0, 0), (0, 0, 1), 0.4), D),
        # A torus has the flip, so stacked coaxial tori are swapped by a half-turn.
        (Torus((0, 0, 0), (0, 0, 1), 5, 1), Torus((0, 0, 3), (0, 0, 1), 5, 1), TWO),
        (Torus((0, 0, 0), (0, 0, 1), 5, 1), Torus((1, 2, 3), (1, 0, 0), 5, 1), ONE),
        (Torus((0, 0, 0), (0, 0, 1), 5, 1), Torus((3, 0, 0), (0, 0, 1), 5, 1), TWO),
        (Point((0, 0, 0)), Point((1, 2, 3)), TWO),
        (Axis((0, 0, 0), (0, 0, 1)), Axis((1, 0, 0), (0, 1, 0)), TWO),
    ],
)
def test_pairwise_relationship(f1, f2, expected):
    assert relationship(f1, f2) is expected
    assert relationship(f2, f1) is expected  # the relationships are symmetrical


def test_threads_differ_by_lead_or_hand():
    right = Thread((0, 0, 0), (0, 0, 1), radius=5, lead=1.5)
    assert relationship(right, Thread((0, 0, 0), (0, 0, 1), radius=5, lead=2.0)) is D
    assert relationship(right, Thread((0, 0, 0), (0, 0, 1), radius=5, lead=1.5, hand="left")) is D
    nut = Thread((0, 0, 0), (0, 0, 1), radius=5, lead=1.5, male=False)
    assert relationship(right, nut) is COMP


def test_prisms_differ_by_sides():
    square = Prism((0, 0, 0), (0, 0, 1), sides=4, size=1)
    assert relationship(square, Prism((0, 0, 0), (0, 0, 1), sides=6, size=1)) is D
    assert relationship(square, Prism((0, 0, 0), (0, 0, 1), sides=4, size=1, male=False)) is COMP


def test_complementary_features_share_their_group():
    """Liu 1997 Prop. 3.1.5: with S1 = S2 the groups are equal."""
    shaft, hole = Shaft((1, 2, 3), (0, 1, 0), 2), Hole((1, 2, 3), (0, 1, 0), 2)
    assert shaft.group().equals(hole.group())
    ball, socket = Ball((1, 2, 3), 4), Socket((1, 2, 3), 4)
    assert ball.group().equals(socket.group())


def test_adjacent_cube_faces_prismatic_along_the_edge_with_the_swap():
    """Liu 1997 §2, Fig. 1: faces x = 1 and y = 1 of the unit cube, edge at (1, 1, z)."""
    group = compound_group([Plane((1, 0, 0), (1, 0, 0)), Plane((0, 1, 0), (0, 1, 0))])
    assert (str(group.kind), group.dof, group.n_components) == ("prismatic", 1, 2)
    assert np.allclose(abs(group.axis @ (0, 0, 1)), 1.0)
    swap = se3.rotation((1, 1, 0), math.pi, (1, 1, 0))
    assert group.contains(swap)
    assert group.contains(se3.translation((0, 0, 3)) @ swap)
    assert not group.contains(se3.rotation((0, 0, 1), math.pi / 2, (1, 1, 0)))


def test_shaft_and_shoulder_are_revolute():
    group = compound_group([Shaft((0, 0, 0), (0, 0, 1), 2), Plane((0, 0, 0), (0, 0, 1))])
    assert (str(group.kind), group.dof, group.n_components) == ("revolute", 1, 1)
    assert group.contains(se3.rot_z(0.7))
    assert not group.contains(se3.translation((0, 0, 1)))


def test_parallel_shafts_prismatic_with_the_swap():
    """Directed, same way: T(z) and the half-turn about the mid-line (2 components).
    Undirected: also the half-turns about the x-line through both axes and about the
    y-line through the midpoint, T(z)⋊(Z2×Z2) (4 components)."""
    directed = compound_group([Shaft((0, 0, 0), (0, 0, 1), 2), Shaft((5, 0, 0), (0, 0, 1), 2)])
    assert (str(directed.kind), directed.dof, directed.n_components) == ("prismatic", 1, 2)
    assert directed.contains(se3.rotation((0, 0, 1), math.pi, (2.5, 0, 0)))
    assert not directed.contains(se3.rot_x(math.pi))
    loose = compound_group(
        [
            Shaft((0, 0, 0), (0, 0, 1), 2, directed=False),
            Shaft((5, 0, 0), (0, 0, 1), 2, directed=False),
        ]
    )
    assert (loose.dof, loose.n_components) == (1, 4)
    assert loose.contains(se3.rot_x(math.pi))
    assert loose.contains(se3.rotation((0, 1, 0), math.pi, (2.5, 0, 0)))


def test_four_pins_on_a_square():
    pins = [Shaft((x, y, 0), (0, 0, 1), 1) for x, y in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
    group = CompoundFeature("pins", tuple(pins)).group()
    assert (str(group.kind), group.dof, group.n_components) == ("prismatic", 1, 4)
    assert group.contains(se3.rot_z(math.pi / 2) @ se3.translation((0, 0, 2)))
    assert not group.contains(se3.rot_z(math.pi / 4))
    seated = compound_group([*pins, Plane((0, 0, 0), (0, 0, 1))])
    assert (seated.dof, seated.n_components) == (0, 4)


def test_gearbox_gear_hub_is_revolute():
    """Liu 1997 §4, Fig. 9: L_i = a_i SO(2) a_i⁻¹ from a bore and its shoulder faces; the
    gear's two faces are 2-congruent, so with an undirected bore it may also sit flipped."""
    hub = [
        Hole((0, 0, 0), (0, 0, 1), 3, directed=False),
        Plane((0, 0, 0), (0, 0, -1)),
        Plane((0, 0, 5), (0, 0, 1)),
    ]
    group = compound_group(hub)
    assert (str(group.kind), group.dof, group.n_components) == ("revolute", 1, 2)
    assert group.contains(se3.rotation((1, 0, 0), math.pi, (0, 0, 2.5)))
    one_face = compound_group(hub[:2])
    assert (str(one_face.kind), one_face.n_components) == ("revolute", 1)


def test_empty_compound_is_an_error():
    with pytest.raises(FeatureError):
        compound_group([])


@pytest.mark.parametrize("tilt", [1e-5, 1e-3])
def test_a_plane_and_a_bore_tilted_beyond_the_angle_tolerance_keep_only_the_identity(tilt):
    # the turns about the bore are not turns about the plane's normal, and its slides
    # leave the plane: the compound is rigid (the identity permutation always transports)
    plane = Plane(point=[0, 0, 0], normal=[0, 0, -1])
    bore = Hole(point=[0, 0, 0], axis=[0, tilt, 1], radius=2, directed=True)
    pin = Shaft(point=[10, 0, 2], axis=[0, 0, 1], radius=1.5, directed=True)
    top = Plane(point=[0, 0, 2], normal=[0, 0, 1])
    tol = Tolerance(scale=19.0)
    assert compound_group((bore, plane), tol).kind is Kind.FIXED
    assert compound_group((bore, plane, pin, top), tol).kind is Kind.FIXED


@pytest.mark.parametrize("tilt", [1e-8, 1e-7, 9e-7])
def test_a_bore_tilted_within_the_angle_tolerance_turns_about_the_plane_normal(tilt):
    # written to six decimals, an axis is within the default angle tolerance (1e-6 rad)
    plane = Plane(point=[0, 0, 0], normal=[0, 0, -1])
    bore = Hole(point=[0, 0, 0], axis=[0, tilt, 1], radius=2, directed=True)
    assert compound_group((bore, plane), Tolerance(scale=19.0)).kind is Kind.REVOLUTE
    looser = compound_group((bore, plane), Tolerance(scale=19.0, angle=1e-5))
    assert looser.kind is Kind.REVOLUTE
