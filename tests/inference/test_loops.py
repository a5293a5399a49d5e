"""Loops and coupled joints (docs/algebra.md §5.2 rule 4): closed-form circle-orbit solvers,
closures of up to four bodies with every assembly mode, gears, racks and screws. Each
branch found is checked against its relations written out by hand in the test."""

from __future__ import annotations

import math

import numpy as np
import pytest
from tests.inference.test_reduction import Z, body, rel, rz, shift, solve

from assemblykit.algebra import Coset, Locus, SymmetryGroup, se3
from assemblykit.errors import FeatureError, SchemaError
from assemblykit.features.primitives import Axis, Ball, Hole, Plane, Shaft, Socket, Thread
from assemblykit.inference.loops import (
    Circle,
    circle_gap,
    circle_line,
    circle_meets,
    circle_plane,
    circle_sphere,
    loop_reach,
    point_loop,
)
from assemblykit.model.relations import Relation, relation_residual
from assemblykit.tolerance import Tolerance

TOL = Tolerance(10.0)
UNIT = Circle(np.zeros(3), np.array([0.0, 0.0, 1.0]), 2.0)


def points(found) -> list[tuple[float, ...]]:
    return sorted(tuple(np.round(p, 9) + 0.0) for p in found)


def test_circle_sphere_two_one_none_and_continuum():
    """|(2cos a, 2sin a, 0) - (3,0,1)|^2 = 14 - 12 cos a: radius^2 8 gives cos a = 1/2."""
    s3 = math.sqrt(3)
    assert points(circle_sphere(UNIT, np.array([3.0, 0, 1]), math.sqrt(8), TOL)) == points(
        [(1, s3, 0), (1, -s3, 0)]
    )
    assert points(circle_sphere(UNIT, np.array([3.0, 0, 1]), math.sqrt(2), TOL)) == [(2, 0, 0)]
    assert circle_sphere(UNIT, np.array([3.0, 0, 1]), 1.0, TOL) == []
    assert circle_sphere(UNIT, np.array([0.0, 0, 3]), math.sqrt(13), TOL) is None


def test_circle_plane_two_tangent_none_and_in_plane():
    """The plane x + z = 1 (normal (1,0,1)/√2) meets the circle where 2cos a = 1."""
    n = np.array([1.0, 0, 1]) / math.sqrt(2)
    s3 = math.sqrt(3)
    assert points(circle_plane(UNIT, np.array([1.0, 0, 0]), n, TOL)) == points(
        [(1, s3, 0), (1, -s3, 0)]
    )
    assert points(circle_plane(UNIT, np.array([2.0, 0, 0]), n, TOL)) == [(2, 0, 0)]
    assert circle_plane(UNIT, np.array([3.0, 0, 0]), n, TOL) == []
    assert circle_plane(UNIT, np.array([5.0, 0, 0]), np.array([0.0, 0, 1]), TOL) is None
    assert circle_plane(UNIT, np.array([0.0, 0, 1]), np.array([0.0, 0, 1]), TOL) == []


def test_circle_line_in_plane_and_across():
    x = np.array([1.0, 0, 0])
    assert points(circle_line(UNIT, np.array([0.0, 1, 0]), x, TOL)) == points(
        [(math.sqrt(3), 1, 0), (-math.sqrt(3), 1, 0)]
    )
    assert points(circle_line(UNIT, np.array([0.0, 2, 0]), x, TOL)) == [(0, 2, 0)]
    assert circle_line(UNIT, np.array([0.0, 3, 0]), x, TOL) == []
    across = np.array([0.0, 0, 1])
    assert points(circle_line(UNIT, np.array([0.0, -2, 5]), across, TOL)) == [(0, -2, 0)]
    assert circle_line(UNIT, np.array([1.0, 0, 5]), across, TOL) == []


def test_circle_meets_a_tilted_circle_at_one_point():
    """The circle about (2,0,1) in the plane y = 0 with radius 1 touches the circle of
    radius 2 in z = 0 only at (2,0,0)."""
    tilted = SymmetryGroup.revolute((2, 0, 1), (0, 1, 0)).orbit((2, 0, 0))
    assert points(circle_meets(UNIT, tilted, TOL)) == [(2, 0, 0)]


def test_point_loop_revolute_ball_against_a_sphere():
    """i→j turns about z; j→k is a ball at (2,0,0) of j; i→k a ball whose centre is 3 from
    k's copy of that point, placed at (3+√8,0,1): the joint point's circle meets the
    sphere about (3,0,1) of radius √8 where cos a = 1/2, so X_ij = Rz(±60°)."""
    first = Coset(SymmetryGroup.revolute((0, 0, 0), (0, 0, 1)), np.eye(4))
    second = Coset(SymmetryGroup.spherical((2, 0, 0)), np.eye(4))
    closing = Coset(SymmetryGroup.spherical((3, 0, 1)), shift(1 + math.sqrt(8), 0, 1))
    solved = point_loop(first, second, closing, TOL)
    assert solved is not None and solved.pattern == "circle-sphere"
    assert len(solved.poses) == 2
    for pose in solved.poses:
        assert any(np.allclose(pose, rz(a), atol=1e-9) for a in (math.pi / 3, -math.pi / 3))
    assert point_loop(second, first, closing, TOL) is None  # needs the revolute first


# ------------------------------------------------------------------ in the reduction

WORLD = body(
    "world",
    fixed=True,
    top=Plane((0, 0, 0), Z),
    ha=Hole((0, 0, 0), Z, 0.5),
    sn=Socket((6, 0, 0), 1.0),
    wall=Plane((2, 0, 0), (-1, 0, 0)),
    deck=Plane((0, 0, 1), Z),
    rail=Plane((0, -1, 0), (0, 1, 0)),
)
CRANK = body(
    "crank",
    bottom=Plane((0, 0, 0), (0, 0, -1)),
    pa=Shaft((0, 0, 0), Z, 0.5),
    sb=Socket((2, 0, 0), 1.0),
)
PIVOT = (rel("fits", "crank.pa", "world.ha"), rel("against", "crank.bottom", "world.top"))


def rules(out) -> list[str]:
    return [step["rule"] for step in out["trace"]]


def crank_angles(out) -> list[float]:
    crank = out["bodies"]["crank@s1"]
    return sorted(
        round(math.atan2(p[1][0], p[0][0]), 9) for p in [crank["pose"], *crank["alternatives"]]
    )


def test_crank_and_rod_between_two_balls_is_circle_sphere():
    """Crank ball B = (2cos a, 2sin a, 0), rod of length 5 to the socket at (6,0,0):
    40 - 24 cos a = 25, cos a = 5/8; the rod spins about the line B-N."""
    rod = body("rod", m1=Ball((2, 0, 0), 1.0), m2=Ball((2, 0, 5), 1.0))
    out = solve(
        [WORLD, CRANK, rod],
        *PIVOT,
        rel("fits", "rod.m1", "crank.sb"),
        rel("fits", "rod.m2", "world.sn"),
        explain=True,
    )
    assert out["status"] == "ambiguous"
    assert "chain-solve circle-sphere" in rules(out) and "residue" not in rules(out)
    a = round(math.acos(5 / 8), 9)
    assert crank_angles(out) == [-a, a]
    r = out["bodies"]["rod@s1"]
    assert (r["dof"], r["motion"]) == (1, "revolute")
    pose = np.asarray(r["pose"])
    tip = se3.apply(pose, np.array([2.0, 0, 5]))
    np.testing.assert_allclose(tip, [6, 0, 0], atol=1e-9)
    b = se3.apply(pose, np.array([2.0, 0, 0]))
    np.testing.assert_allclose(b, [1.25, math.copysign(math.sqrt(39) / 4, b[1]), 0], atol=1e-9)
    direction = np.asarray(r["invariants"]["direction"])
    assert abs(abs(direction @ (b - [6, 0, 0])) - 5) < 1e-9


def test_crank_ball_in_a_slab_against_a_wall_is_circle_plane():
    """The slab's ball centre is 1 behind its face, which lies on the wall x = 2: the
    crank ball is on x = 1, 2cos a = 1, a = ±60°; the slab turns about the x direction."""
    slab = body("slab", ball=Ball((2, 0, 0), 1.0), back=Plane((3, 0, 0), (1, 0, 0)))
    out = solve(
        [WORLD, CRANK, slab],
        *PIVOT,
        rel("fits", "slab.ball", "crank.sb"),
        rel("against", "slab.back", "world.wall"),
        explain=True,
    )
    assert out["status"] == "ambiguous"
    assert "chain-solve circle-plane" in rules(out) and "residue" not in rules(out)
    third = round(math.pi / 3, 9)
    assert crank_angles(out) == [-third, third]
    s = out["bodies"]["slab@s1"]
    assert (s["dof"], s["motion"]) == (1, "revolute")
    assert abs(abs(s["invariants"]["direction"][0]) - 1) < 1e-9
    pose = np.asarray(s["pose"])
    np.testing.assert_allclose(pose[:3, :3] @ [1, 0, 0], [1, 0, 0], atol=1e-9)
    ball = se3.apply(pose, np.array([2.0, 0, 0]))
    np.testing.assert_allclose(abs(ball), [1, math.sqrt(3), 0], atol=1e-9)


def slider_crank(rail_y: float):
    """A rod turning about the origin with a pin hole 5 out; a slider on the deck against
    the rail (a prismatic along x) whose pin at (3,3) fits the hole: the pin is on the
    line y = 3 + rail_y + 1 and on the circle of radius 5."""
    rod = body(
        "rod",
        bottom=Plane((0, 0, 0), (0, 0, -1)),
        pa=Shaft((0, 0, 0), Z, 0.5),
        top=Plane((0, 0, 1), Z),
        hb=Hole((5, 0, 0), Z, 0.5),
    )
    slider = body(
        "slider",
        bottom=Plane((3, 3, 1), (0, 0, -1)),
        side=Plane((3, -1, 0), (0, -1, 0)),
        pb=Shaft((3, 3, 0), Z, 0.5),
    )
    world = body(
        "world",
        fixed=True,
        top=Plane((0, 0, 0), Z),
        ha=Hole((0, 0, 0), Z, 0.5),
        deck=Plane((0, 0, 1), Z),
        rail=Plane((0, rail_y, 0), (0, 1, 0)),
    )
    return solve(
        [world, rod, slider],
        rel("fits", "rod.pa", "world.ha"),
        rel("against", "rod.bottom", "world.top"),
        rel("fits", "slider.pb", "rod.hb"),
        rel("against", "slider.bottom", "rod.top"),
        rel("against", "slider.bottom", "world.deck"),
        rel("against", "slider.side", "world.rail"),
        explain=True,
    )


def test_slider_crank_is_circle_line_with_two_modes():
    """Pin on y = 3 and x² + y² = 25: (4,3) or (-4,3); the slider shifts by 1 or -7."""
    out = slider_crank(-1.0)
    assert out["status"] == "ambiguous"
    assert "chain-solve circle-line" in rules(out) and "residue" not in rules(out)
    rod = out["bodies"]["rod@s1"]
    found = [np.asarray(rod["pose"]), np.asarray(rod["alternatives"][0])]
    a = math.atan2(3, 4)
    for expected in (rz(a), rz(math.pi - a)):
        assert any(np.allclose(expected, f, atol=1e-9) for f in found)
    slider = out["bodies"]["slider@s1"]
    shifts = sorted(np.asarray(p)[0, 3] for p in [slider["pose"], *slider["alternatives"]])
    assert shifts == pytest.approx([-7.0, 1.0], abs=1e-9)


def test_slider_crank_out_of_reach_is_inconsistent():
    """The rail 7 out puts the pin on y = 9, beyond the rod's reach of 5. The slider's
    seat on the deck repeats its seat on the rod (both z = 1): the conflict does without
    it, so it is not named."""
    out = slider_crank(5.0)
    assert out["status"] == "inconsistent"
    (conflict,) = out["conflicts"]
    assert conflict["kind"] == "loop"
    assert "cannot close" in conflict["message"]
    # the pin's circle of radius 5 about the origin misses the line y = 9 by 4
    assert conflict["value"] == pytest.approx(4.0, abs=1e-9)
    assert "against slider.bottom world.deck @s1" not in conflict["relations"]
    assert "against slider.side world.rail @s1" in conflict["relations"]


# ------------------------------------------------- closures of four bodies, coupled joints


def revolute_about(pose, point, direction) -> bool:
    """Whether ``pose`` is a rotation about the line through ``point`` along ``direction``:
    it keeps the point and the direction (written out, independent of the algebra)."""
    pose = np.asarray(pose)
    point, direction = np.asarray(point, float), np.asarray(direction, float)
    return bool(
        np.allclose(pose[:3, :3] @ point + pose[:3, 3], point, atol=1e-9)
        and np.allclose(pose[:3, :3] @ direction, direction, atol=1e-9)
    )


def modes(out, key: str) -> list[np.ndarray]:
    b = out["bodies"][key]
    return [np.asarray(p) for p in (b["pose"], *b["alternatives"])]


def rx(angle: float) -> np.ndarray:
    return se3.rot_x(angle)


def ry(angle: float) -> np.ndarray:
    return se3.rot_y(angle)


# A spherical four-bar: every joint axis passes through the origin O. The ground holds the
# crank about z and the rocker about x; the crank holds the coupler about y; the coupler
# and the rocker turn about each other about a = (1, 1, 1)/√3 (a pin fitted in a bore,
# with a ball in a socket at O to keep each joint from sliding). A stop holds the crank.
UNIT_A = tuple(np.full(3, 1 / math.sqrt(3)))
X_AXIS, Y_AXIS = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)


def spherical_four_bar():
    ground = body(
        "ground",
        fixed=True,
        h1=Hole((0, 0, 0), Z, 0.5),
        s1=Socket((0, 0, 0), 0.5),
        h4=Hole((0, 0, 0), X_AXIS, 0.5),
        s4=Socket((0, 0, 0), 0.5),
        stop=Plane((0, 1, 0), (0, -1, 0)),
    )
    crank = body(
        "crank",
        p1=Shaft((0, 0, 0), Z, 0.5),
        b1=Ball((0, 0, 0), 0.5),
        h2=Hole((0, 0, 0), Y_AXIS, 0.5),
        s2=Socket((0, 0, 0), 0.5),
        side=Plane((0, 1, 0), (0, 1, 0)),
    )
    coupler = body(
        "coupler",
        p2=Shaft((0, 0, 0), Y_AXIS, 0.5),
        b2=Ball((0, 0, 0), 0.5),
        h3=Hole((0, 0, 0), UNIT_A, 0.5),
        s3=Socket((0, 0, 0), 0.5),
    )
    rocker = body(
        "rocker",
        p4=Shaft((0, 0, 0), X_AXIS, 0.5),
        b4=Ball((0, 0, 0), 0.5),
        p3=Shaft((0, 0, 0), UNIT_A, 0.5),
        b3=Ball((0, 0, 0), 0.5),
    )
    joints = [
        rel("fits", "crank.p1", "ground.h1"),
        rel("fits", "crank.b1", "ground.s1"),
        rel("fits", "coupler.p2", "crank.h2"),
        rel("fits", "coupler.b2", "crank.s2"),
        rel("fits", "rocker.p3", "coupler.h3"),
        rel("fits", "rocker.b3", "coupler.s3"),
        rel("fits", "rocker.p4", "ground.h4"),
        rel("fits", "rocker.b4", "ground.s4"),
        rel("against", "crank.side", "ground.stop"),
    ]
    return solve([ground, crank, coupler, rocker], *joints, explain=True)


def test_spherical_four_bar_has_two_assembly_modes():
    """The coupler turns about y by φ and the rocker about x by ψ; they close when both
    carry a to the same u: u·y = a·y = 1/√3 and u·x = 1/√3, so u = (1, 1, ±1)/√3. The
    mode u = a is the pose as written (φ = ψ = 0); u = (1, 1, -1)/√3 needs Ry(φ) to take
    (x, z) = (1, 1) to (1, -1): φ = π/2, and Rx(ψ) to take (y, z) = (1, 1) to (1, -1):
    ψ = -π/2."""
    out = spherical_four_bar()
    assert out["status"] == "ambiguous"
    assert "residue" not in rules(out)
    assert np.allclose(out["bodies"]["crank@s1"]["pose"], np.eye(4), atol=1e-12)
    coupler, rocker = modes(out, "coupler@s1"), modes(out, "rocker@s1")
    assert len(coupler) == len(rocker) == 2
    for found, expected in ((coupler, ry(math.pi / 2)), (rocker, rx(-math.pi / 2))):
        assert any(np.allclose(p, np.eye(4), atol=1e-9) for p in found)
        assert any(np.allclose(p, expected, atol=1e-9) for p in found)
    # every branch, by its own residuals: the coupler turns about the crank's y axis, the
    # rocker about the ground's x axis, and both put the joint axis a on one line
    a = np.asarray(UNIT_A)
    for c, r in zip(coupler, rocker, strict=True):
        assert revolute_about(c, (0, 0, 0), Y_AXIS) and revolute_about(r, (0, 0, 0), X_AXIS)
        np.testing.assert_allclose(c[:3, :3] @ a, r[:3, :3] @ a, atol=1e-9)


# An RRPR (inverted slider-crank): the crank, stopped, carries the pin B = (0, 3); the
# rocker turns about D = (4, 0) and carries a slot along its x axis through D; the slider
# turns on B and slides in the slot. Written, the slider's bore sits at D.
B, D = np.array([0.0, 3.0, 0.0]), np.array([4.0, 0.0, 0.0])


def rrpr():
    r = 0.5
    ground = body(
        "ground",
        fixed=True,
        top=Plane((0, 0, 0), Z),
        ha=Hole((0, 0, 0), Z, r),
        hd=Hole(tuple(D), Z, r),
        stop=Plane((1, 0, 0), (-1, 0, 0)),
    )
    crank = body(
        "crank",
        bottom=Plane((0, 0, 0), (0, 0, -1)),
        pa=Shaft((0, 0, 0), Z, r),
        top=Plane((0, 0, 1), Z),
        pb=Shaft(tuple(B), Z, r),
        side=Plane((1, 0, 0), (1, 0, 0)),
    )
    rocker = body(
        "rocker",
        bottom=Plane(tuple(D), (0, 0, -1)),
        pd=Shaft(tuple(D), Z, r),
        top=Plane((4, 0, 1), Z),
        rail=Plane(tuple(D), (0, 1, 0)),
    )
    slider = body(
        "slider",
        bottom=Plane((4, 0, 1), (0, 0, -1)),
        hb=Hole(tuple(D), Z, r),
        side=Plane(tuple(D), (0, -1, 0)),
    )
    joints = [
        rel("fits", "crank.pa", "ground.ha"),
        rel("against", "crank.bottom", "ground.top"),
        rel("against", "crank.side", "ground.stop"),
        rel("fits", "rocker.pd", "ground.hd"),
        rel("against", "rocker.bottom", "ground.top"),
        rel("fits", "slider.hb", "crank.pb"),
        rel("against", "slider.bottom", "crank.top"),
        rel("against", "slider.bottom", "rocker.top"),
        rel("against", "slider.side", "rocker.rail"),
    ]
    return solve([ground, crank, rocker, slider], *joints, explain=True)


def test_rrpr_has_two_modes_with_the_slot_through_the_pin():
    """The slot is a line through D that must pass through B: along ±(B - D) = ±(-4, 3),
    so the rocker turns to ψ = atan2(3, -4) or atan2(-3, 4). The slider turns with the
    rocker and its bore moves from D to B: pose Tr(B - D)·Rz(ψ about D), a slide of
    s = ±5 along the slot."""
    out = rrpr()
    assert out["status"] == "ambiguous"
    rocker, slider = modes(out, "rocker@s1"), modes(out, "slider@s1")
    assert len(rocker) == len(slider) == 2
    for psi in (math.atan2(3, -4), math.atan2(-3, 4)):
        assert any(np.allclose(p, rz(psi, tuple(D)), atol=1e-9) for p in rocker)
        expected = shift(*(B - D)) @ rz(psi, tuple(D))
        assert any(np.allclose(p, expected, atol=1e-9) for p in slider)
    for r, s in zip(rocker, slider, strict=True):
        assert revolute_about(r, D, Z)  # R: the rocker about D
        np.testing.assert_allclose(se3.apply(s, D), B, atol=1e-9)  # R: the slider on B
        relative = se3.inverse(r) @ s  # P: no turn, a shift along the slot's x only
        np.testing.assert_allclose(relative[:3, :3], np.eye(3), atol=1e-9)
        np.testing.assert_allclose(relative[1:3, 3], 0.0, atol=1e-9)
        assert abs(relative[0, 3]) == pytest.approx(5.0, abs=1e-9)


# A rack and pinion: the pinion (pitch radius 2) turns about z on the carrier, the rack
# slides along x on it. A stop face at 30° about z holds the pinion.
def rack_and_pinion(held: bool):
    a = math.pi / 6
    towards = np.array([-math.sin(a), math.cos(a), 0.0])
    carrier = body(
        "carrier",
        fixed=True,
        top=Plane((0, 0, 0), Z),
        bore=Hole((0, 0, 0), Z, 1.0),
        bed=Plane((0, -2, 0), (0, 1, 0)),
        stop=Plane(tuple(towards), tuple(-towards)),
    )
    pinion = body(
        "pinion",
        bottom=Plane((0, 0, 0), (0, 0, -1)),
        axle=Shaft((0, 0, 0), Z, 1.0),
        flat=Plane((0, 1, 0), (0, 1, 0)),
    )
    rack = body(
        "rack",
        bottom=Plane((0, -2, 0), (0, 0, -1)),
        back=Plane((0, -2, 0), (0, -1, 0)),
        line=Axis((0, -2, 0), X_AXIS),
    )
    joints = [
        rel("fits", "pinion.axle", "carrier.bore"),
        rel("against", "pinion.bottom", "carrier.top"),
        rel("against", "rack.bottom", "carrier.top"),
        rel("against", "rack.back", "carrier.bed"),
        rel("rack", "pinion.axle", "rack.line", radius=2.0),
    ]
    if held:
        joints.append(rel("against", "pinion.flat", "carrier.stop"))
    return solve([carrier, pinion, rack], *joints)


def test_rack_and_pinion_moves_together_then_is_held():
    free = rack_and_pinion(held=False)["bodies"]
    assert (free["pinion@s1"]["dof"], free["pinion@s1"]["motion"]) == (1, "revolute")
    assert (free["rack@s1"]["dof"], free["rack@s1"]["motion"]) == (1, "prismatic")
    out = rack_and_pinion(held=True)
    assert out["status"] == "solved"
    # the pinion's flat normal (0, 1, 0) turned onto the stop's -normal: θ = π/6; the pitch
    # circle rolls along the rack: s = 2·π/6 = π/3 along x
    pinion = np.asarray(out["bodies"]["pinion@s1"]["pose"])
    rack = np.asarray(out["bodies"]["rack@s1"]["pose"])
    np.testing.assert_allclose(pinion, rz(math.pi / 6), atol=1e-9)
    np.testing.assert_allclose(rack, shift(math.pi / 3), atol=1e-9)
    # the relation written out: the rack's shift along x is the radius times the turn
    theta = math.atan2(pinion[1, 0], pinion[0, 0])
    assert rack[0, 3] - 2.0 * theta == pytest.approx(0.0, abs=1e-9)


def test_a_rack_takes_only_line_features_and_needs_its_radius():
    with pytest.raises(FeatureError):
        relation_residual("rack", Plane((0, 0, 0), Z), Axis((0, 0, 0), Z), {"radius": 1.0})
    with pytest.raises(SchemaError, match="radius"):
        Relation.parse(["rack", "a.x", "b.y"])


# A lead screw (right hand, lead 2) turns on a revolute in a frame; the nut slides along z
# against two faces of the frame; the threads couple them. A stop turns the screw by 90°.
def lead_screw(held: bool):
    a = math.pi / 2
    towards = np.array([-math.sin(a), math.cos(a), 0.0])
    frame = body(
        "frame",
        fixed=True,
        seat=Plane((0, 0, 0), Z),
        bore=Hole((0, 0, 0), Z, 1.0),
        guide=Plane((0, 3, 0), (0, -1, 0)),
        side=Plane((-3, 0, 0), (1, 0, 0)),
        stop=Plane(tuple(towards), tuple(-towards)),
    )
    screw = body(
        "screw",
        collar=Plane((0, 0, 0), (0, 0, -1)),
        journal=Shaft((0, 0, 0), Z, 1.0),
        thread=Thread((0, 0, 0), Z, 1.0, 2.0),
        flat=Plane((0, 1, 0), (0, 1, 0)),
    )
    nut = body(
        "nut",
        thread=Thread((0, 0, 0), Z, 1.0, 2.0, male=False),
        back=Plane((0, 3, 0), (0, 1, 0)),
        left=Plane((-3, 0, 0), (-1, 0, 0)),
    )
    joints = [
        rel("fits", "screw.journal", "frame.bore"),
        rel("against", "screw.collar", "frame.seat"),
        rel("against", "nut.back", "frame.guide"),
        rel("against", "nut.left", "frame.side"),
        rel("fits", "nut.thread", "screw.thread"),
    ]
    if held:
        joints.append(rel("against", "screw.flat", "frame.stop"))
    return solve([frame, screw, nut], *joints, explain=True)


def test_lead_screw_drives_the_nut_by_its_lead():
    free = lead_screw(held=False)["bodies"]
    assert (free["screw@s1"]["dof"], free["screw@s1"]["motion"]) == (1, "revolute")
    assert (free["nut@s1"]["dof"], free["nut@s1"]["motion"]) == (1, "prismatic")
    out = lead_screw(held=True)
    screw, nut = out["bodies"]["screw@s1"], out["bodies"]["nut@s1"]
    np.testing.assert_allclose(screw["pose"], rz(math.pi / 2), atol=1e-12)
    # relative to the screw the nut turns by -90°, so a right-hand thread of lead 2 moves it
    # by 2·(-1/4) = -0.5; one turn more or less of the nut is the same contact: a lattice of
    # poses 2 apart along z (the pose itself says nothing of how many turns were made)
    assert (nut["dof"], nut["solutions"]) == (0, "infinite")
    np.testing.assert_allclose(nut["pose"], shift(0, 0, -0.5), atol=1e-12)
    assert "residue" not in rules(out)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("kind", ["point", "line", "plane", "sphere", "circle", "cylinder"])
def test_circle_gap_is_the_least_distance_found_by_brute_force(kind, seed):
    """A random circle against a random locus: the refined gap equals the least distance
    found by sampling the circle (20,000 points round it, then 20,000 between the two
    neighbours of each of the eight least local minima among them: 3e-8 rad apart), or
    is 0 where the circle crosses the locus."""
    rng = np.random.default_rng(seed)
    circle = Circle(rng.normal(size=3), se3.unit(rng.normal(size=3)), float(rng.uniform(0.5, 2)))
    locus = Locus(
        kind,
        point=rng.normal(size=3) * 2,
        direction=se3.unit(rng.normal(size=3)),
        radius=float(rng.uniform(0.5, 2)),
    )
    frame = se3.frame(np.zeros(3), circle.normal)

    def distances(phi: np.ndarray) -> np.ndarray:
        points = circle.center + circle.radius * (
            np.outer(np.cos(phi), frame[:3, 0]) + np.outer(np.sin(phi), frame[:3, 1])
        )
        return locus.distance(points)

    step = 2 * math.pi / 20_000
    phi = np.arange(20_000) * step
    coarse = distances(phi)
    dips = np.flatnonzero((coarse <= np.roll(coarse, 1)) & (coarse < np.roll(coarse, -1)))
    dips = dips[np.argsort(coarse[dips])[:8]]
    fine = np.concatenate([np.linspace(phi[k] - step, phi[k] + step, 20_001) for k in dips])
    brute = float(min(coarse.min(), distances(fine).min()))
    gap = circle_gap(circle, locus)
    assert 0 <= gap <= brute + 1e-12
    if brute > 1e-4:  # a miss: the minimum is smooth, and the samples find it to 1e-11
        assert gap == pytest.approx(brute, abs=1e-10)
    else:  # a crossing: the samples straddle it, 2π/1e6 of the radius apart at most
        assert gap <= 1e-9


# ------------------------------------------------------------ the reach of a planar loop


def test_loop_reach_spans_the_distances_between_each_bodys_axes():
    """Body 0 holds both of its joints on the z axis through the origin, body 1 holds
    its two 3 apart, body 2 its two 4 apart: the joint between 1 and 2 would have to be 3
    and 4 from the origin at once. The spans are (0, 3, 4): open by 4 - 3 - 0 = 1."""
    links = [
        Coset(SymmetryGroup.revolute((0, 0, 0), Z), np.eye(4)),
        Coset(SymmetryGroup.revolute((3, 0, 0), Z), shift(3)),
        Coset(SymmetryGroup.revolute((4, 0, 0), (0, 0, -1)), shift(4) @ se3.rot_x(math.pi)),
    ]
    reach = loop_reach(links, TOL)
    assert reach is not None
    assert reach.spans == pytest.approx((0.0, 3.0, 4.0), abs=1e-12)
    assert (reach.longest, reach.gap) == (2, pytest.approx(1.0, abs=1e-12))
    # a cylindrical joint keeps its axis too; a joint turned off the others' direction
    # (body 2's axis tilted about x) leaves no planar polygon
    sliding = [*links[:2], Coset(SymmetryGroup.cylindrical((4, 0, 0), Z), shift(4))]
    assert loop_reach(sliding, TOL) is not None
    tilted = [*links[:2], Coset(SymmetryGroup.revolute((4, 0, 0), Z), se3.rot_x(0.3))]
    assert loop_reach(tilted, TOL) is None
    slide = [*links[:2], Coset(SymmetryGroup.prismatic((1, 0, 0)), shift(4))]
    assert loop_reach(slide, TOL) is None


def planar_four_bar(pivot: float, rocker_pin: tuple[float, float] = (40.0, 20.0)):
    """The bundled four-bar (examples/tasks/four_bar.yaml) with the ground pivot D and
    the rocker's hole at (pivot, 0) and the rocker's pin C at ``rocker_pin``: crank A-B
    of 10 (A = (0, 0), B = (0, 10)), coupler B-C of √1700 (C = (40, 20)), rocker D-C.
    Links are 1 thick: crank and rocker on the ground, the coupler on the crank."""
    r = 1.0
    ground = body(
        "ground",
        fixed=True,
        top=Plane((0, 0, 0), Z),
        pin_a=Shaft((0, 0, 0), Z, r),
        pin_d=Shaft((pivot, 0, 0), Z, r),
    )
    crank = body(
        "crank",
        bottom=Plane((0, 0, 0), (0, 0, -1)),
        top=Plane((0, 0, 1), Z),
        hole_a=Hole((0, 0, 0), Z, r),
        pin_b=Shaft((0, 10, 1), Z, r),
    )
    coupler = body(
        "coupler",
        bottom=Plane((0, 0, 1), (0, 0, -1)),
        hole_b=Hole((0, 10, 1), Z, r),
        hole_c=Hole((40, 20, 1), Z, r),
    )
    rocker = body(
        "rocker",
        bottom=Plane((0, 0, 0), (0, 0, -1)),
        hole_d=Hole((pivot, 0, 0), Z, r),
        pin_c=Shaft((*rocker_pin, 1), Z, r),
    )
    return solve(
        [ground, crank, coupler, rocker],
        rel("against", "crank.bottom", "ground.top"),
        rel("fits", "crank.hole_a", "ground.pin_a"),
        rel("against", "rocker.bottom", "ground.top"),
        rel("fits", "rocker.hole_d", "ground.pin_d"),
        rel("against", "coupler.bottom", "crank.top"),
        rel("fits", "coupler.hole_b", "crank.pin_b"),
        rel("fits", "coupler.hole_c", "rocker.pin_c"),
        explain=True,
    )


COUPLER = math.sqrt(40**2 + 10**2)


def test_four_bar_out_of_reach_is_a_loop_conflict_found_at_once():
    """Ground pivots 100 apart, crank 10, coupler √1700 ≈ 41.23 and rocker 20: the three
    moving links stretched in one line reach 71.23 of the 100, so the loop stays open by
    100 - 10 - √1700 - 20 ≈ 28.77 whatever the angles. That is an answer, not a search."""
    out = planar_four_bar(100.0, (100.0, 20.0))
    assert out["status"] == "inconsistent"
    (conflict,) = out["conflicts"]
    assert conflict["kind"] == "loop"
    assert conflict["value"] == pytest.approx(100 - 10 - COUPLER - 20, abs=1e-9)
    assert "cannot close" in conflict["message"] and "world spans 100 " in conflict["message"]
    assert "fits coupler.hole_c rocker.pin_c @s1" in conflict["relations"]
    assert conflict["needed_tolerance"] is None
    assert "residue" not in rules(out)


def test_four_bar_with_a_rocker_too_long_names_the_rocker():
    """The rocker's pin 120 from its pivot: more than 10 + √1700 + 40 together."""
    out = planar_four_bar(40.0, (40.0, 120.0))
    assert out["status"] == "inconsistent"
    (conflict,) = out["conflicts"]
    assert conflict["kind"] == "loop"
    assert conflict["value"] == pytest.approx(120 - 10 - COUPLER - 40, abs=1e-9)
    assert "rocker@s1 spans 120 " in conflict["message"]


def test_four_bar_missing_by_a_hair_says_how_far_to_loosen():
    """Open by 1e-3 of a model about 104 across (1e-5 of it): within 1000 times the
    default tolerance, so the conflict says which tolerance would accept it."""
    pivot = 10 + COUPLER + 20 + 1e-3
    out = planar_four_bar(pivot, (pivot, 20.0))
    (conflict,) = out["conflicts"]
    assert conflict["kind"] == "loop"
    assert conflict["value"] == pytest.approx(1e-3, abs=1e-8)
    assert conflict["needed_tolerance"] is not None
    assert 1e-6 < conflict["needed_tolerance"] < 1e-4


def test_four_bar_within_reach_closes_on_its_joints():
    """Ground pivots 60 apart (less than 10 + √1700 + 20): the loop closes. Checked by
    hand on the answer: each body keeps its joints where its partners keep theirs."""
    out = planar_four_bar(60.0, (60.0, 20.0))
    assert out["status"] == "underconstrained" and out["conflicts"] == []
    pose = {key: np.asarray(b["pose"]) for key, b in out["bodies"].items()}
    a, b = np.array([0.0, 0, 0]), se3.apply(pose["crank@s1"], np.array([0.0, 10, 1]))
    c = se3.apply(pose["rocker@s1"], np.array([60.0, 20, 1]))
    np.testing.assert_allclose(se3.apply(pose["crank@s1"], a), a, atol=1e-6)
    np.testing.assert_allclose(se3.apply(pose["rocker@s1"], [60.0, 0, 0]), [60, 0, 0], atol=1e-6)
    np.testing.assert_allclose(se3.apply(pose["coupler@s1"], np.array([0.0, 10, 1])), b, atol=1e-6)
    np.testing.assert_allclose(se3.apply(pose["coupler@s1"], np.array([40.0, 20, 1])), c, atol=1e-6)
    assert b[2] == pytest.approx(1.0, abs=1e-6) and c[2] == pytest.approx(1.0, abs=1e-6)
    assert {k: out["bodies"][k]["dof"] for k in ("crank@s1", "coupler@s1", "rocker@s1")} == {
        "crank@s1": 1,
        "coupler@s1": 1,
        "rocker@s1": 1,
    }
