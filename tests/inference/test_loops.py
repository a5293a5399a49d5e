"""Closed-form loop solvers (ALGEBRA.md §5.2 rule 4): circle against a point orbit."""

from __future__ import annotations

import math

import numpy as np
import pytest
from tests.inference.test_reduction import Z, body, rel, rz, shift, solve

from assemblykit.algebra import Coset, SymmetryGroup, se3
from assemblykit.features.primitives import Ball, Hole, Plane, Shaft, Socket
from assemblykit.inference.loops import (
    Circle,
    circle_line,
    circle_meets,
    circle_plane,
    circle_sphere,
    point_loop,
)
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
    """The rail 7 out puts the pin on y = 9, beyond the rod's reach of 5."""
    out = slider_crank(5.0)
    assert out["status"] == "inconsistent"
    assert out["conflicts"][0]["kind"] == "loop"
    assert "circle-line" in out["conflicts"][0]["message"]
