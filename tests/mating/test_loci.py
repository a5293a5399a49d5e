"""Global positions through loops: circle intersections in 3D, representative-point
loci with non-parallel axes, numeric closure, chaining through moving bodies."""

from __future__ import annotations

import math

import numpy as np
import pytest

from assemblykit.algebra import Coset, Locus, SymmetryGroup, se3
from assemblykit.io.problem import parse_problem
from assemblykit.mating.loci import (
    circle_plane,
    circle_sphere,
    loci_branches,
    locus_meet,
    numeric_closure,
)
from assemblykit.mating.search import mate
from assemblykit.tolerance import Tolerance

TOL = Tolerance(10.0)
X, Y, Z = np.eye(3)
UNIT = Locus("circle", point=np.zeros(3), direction=Z, radius=1.0)


def test_circle_meets_a_plane_in_two_one_or_no_points() -> None:
    # The plane x = 0.5 cuts the unit circle at y = ±sqrt(3)/2.
    points = circle_plane(UNIT, np.array([0.5, 0, 0]), X, TOL)
    np.testing.assert_allclose(
        sorted(p.tolist() for p in points),
        [[0.5, -math.sqrt(3) / 2, 0], [0.5, math.sqrt(3) / 2, 0]],
        atol=1e-12,
    )
    np.testing.assert_allclose(circle_plane(UNIT, X, X, TOL), [[1, 0, 0]], atol=1e-12)
    assert circle_plane(UNIT, 2 * X, X, TOL) == []
    assert circle_plane(UNIT, Z, Z, TOL) == []
    assert circle_plane(UNIT, np.zeros(3), Z, TOL) is None


def test_circle_meets_a_sphere_on_the_radical_plane() -> None:
    # The sphere about (1, 0, 1) of radius sqrt(2) holds (0, ±1, 0)... and (±1, 0, 0)?
    # |(x, y, 0) - (1, 0, 1)|^2 = 2 - 2x + 1 - 1 ... = 2 when x = 0.5: y = ±sqrt(3)/2.
    points = circle_sphere(UNIT, np.array([1.0, 0, 1]), math.sqrt(2), TOL)
    np.testing.assert_allclose(
        sorted(p.tolist() for p in points),
        [[0.5, -math.sqrt(3) / 2, 0], [0.5, math.sqrt(3) / 2, 0]],
        atol=1e-12,
    )
    assert circle_sphere(UNIT, np.array([0.0, 0, 1]), math.sqrt(2), TOL) is None
    assert circle_sphere(UNIT, np.array([5.0, 0, 0]), 1.0, TOL) == []


def test_circles_with_perpendicular_axes() -> None:
    # The circle about (0, 0, 1) in the plane y = 0 with radius sqrt(2) passes through
    # (±1, 0, 0), both on the unit circle.
    b = Locus("circle", point=np.array([0.0, 0, 1]), direction=Y, radius=math.sqrt(2))
    np.testing.assert_allclose(
        sorted(p.tolist() for p in locus_meet(UNIT, b, TOL)), [[-1, 0, 0], [1, 0, 0]], atol=1e-12
    )
    # Radius 1 about the same centre: it reaches z = 0 only at (0, 0, 0), not on UNIT.
    smaller = Locus("circle", point=np.array([0.0, 0, 1]), direction=Y, radius=1.0)
    assert locus_meet(UNIT, smaller, TOL) == []
    # A concentric great circle of the same sphere: (±1, 0, 0) again.
    tilted = Locus("circle", point=np.zeros(3), direction=Y, radius=1.0)
    np.testing.assert_allclose(
        sorted(p.tolist() for p in locus_meet(UNIT, tilted, TOL)), [[-1, 0, 0], [1, 0, 0]],
        atol=1e-12,
    )  # fmt: skip
    assert locus_meet(UNIT, UNIT, TOL) is None
    assert locus_meet(UNIT, Locus("sphere", point=np.zeros(3), radius=1.0), TOL) is None


def test_loci_branches_with_non_parallel_axes() -> None:
    # Body u turns about z through the origin; body v about the y-parallel line through
    # (0, 0, 1), placed at T(0, 0, 2); a ball joint at (1, 0, 0) of u's frame (identity
    # relative placement) ties them: u's point (1, 0, 0) must meet v's circle.
    world = {
        "u": Coset(SymmetryGroup.revolute((0, 0, 0), Z), np.eye(4)),
        "v": Coset(SymmetryGroup.revolute((0, 0, 1), Y), se3.translation((0, 0, 2))),
    }
    ball = Coset(SymmetryGroup.spherical((1, 0, 0)), np.eye(4))
    branches = loci_branches(world, "u", "v", ball, TOL)
    turns = sorted(round(se3.rotation_angle(b["u"].rep), 9) for b in branches)
    assert turns == [0.0, round(math.pi, 9)]
    assert all(b["u"].is_point and b["v"] is world["v"] for b in branches)
    prismatic = Coset(SymmetryGroup.prismatic(X), np.eye(4))
    assert loci_branches(world, "u", "v", prismatic, TOL) is None


def test_numeric_closure_finds_the_isolated_solution() -> None:
    # v turns about z and sits at T(2, 0, 0) from the axis; the relation asks for a pure
    # translation along x: only the turn 0 closes the loop.
    world = {
        "u": Coset(SymmetryGroup.identity(), np.eye(4)),
        "v": Coset(SymmetryGroup.revolute((0, 0, 0), Z), se3.translation((2, 0, 0))),
    }
    slide = Coset(SymmetryGroup.prismatic(X), np.eye(4))
    (closed,) = numeric_closure(world, "u", "v", slide, TOL)
    np.testing.assert_allclose(closed["v"].rep, se3.translation((2, 0, 0)), atol=1e-9)
    np.testing.assert_allclose(closed["u"].rep, np.eye(4), atol=0)
    # A planar relation holds for every turn: the solutions are not isolated.
    plane = Coset(SymmetryGroup.planar(Z), np.eye(4))
    assert numeric_closure(world, "u", "v", plane, TOL) is None
    # A relation no member reaches (a lift along z): no start converges.
    lifted = Coset(SymmetryGroup.prismatic(X), se3.translation((0, 0, 1)))
    assert numeric_closure(world, "u", "v", lifted, TOL) == []


ARM = {
    "bodies": {
        "frame": {
            "features": {
                "top": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]},
                "bore": {"type": "hole", "point": [0, 0, 0], "axis": [0, 0, -1], "radius": 1},
                "big": {"type": "hole", "point": [-6, 0, 0], "axis": [0, 0, -1], "radius": 0.5},
                "small": {"type": "hole", "point": [-4, 0, 0], "axis": [0, 0, -1],
                          "radius": 0.25},
            },
            "compound": {"seat": ["top", "bore"], "mount": ["top", "big", "small"]},
        },
        "arm": {
            "features": {
                "face": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, -1]},
                "pin": {"type": "shaft", "point": [0, 0, 0], "axis": [0, 0, -1], "radius": 1},
                "pad": {"type": "plane", "point": [5, 0, 1], "normal": [0, 0, 1]},
                "big": {"type": "hole", "point": [4, 0, 1], "axis": [0, 0, -1], "radius": 0.5},
                "small": {"type": "hole", "point": [6, 0, 1], "axis": [0, 0, -1],
                          "radius": 0.25},
            },
            "compound": {"hinge": ["face", "pin"], "mount": ["pad", "big", "small"]},
        },
        "tag": {
            "features": {
                "base": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, -1]},
                "a": {"type": "shaft", "point": [-1, 0, 0], "axis": [0, 0, -1], "radius": 0.5},
                "b": {"type": "shaft", "point": [1, 0, 0], "axis": [0, 0, -1], "radius": 0.25},
            },
            "compound": {"feet": ["base", "a", "b"]},
        },
    },
    "goals": [["fit", "arm", "frame"], ["fit", "tag", "arm"], ["fit", "cap", "frame"]],
}  # fmt: skip
ARM["bodies"]["cap"] = ARM["bodies"]["tag"]


def test_a_body_fixed_to_a_moving_body_is_placed_by_chaining() -> None:
    result = mate(parse_problem(ARM))
    (config,) = result.configurations
    # The frame (first of the bodies in two goals) is fixed, the cap sits on its mount;
    # the tag sits on the arm's mount (at x = 5, z = 1 of the arm) and turns with it.
    np.testing.assert_allclose(config.poses["frame"], np.eye(4), atol=1e-12)
    np.testing.assert_allclose(config.poses["cap"], se3.translation((-5, 0, 0)), atol=1e-9)
    arm, tag = config.poses["arm"], config.poses["tag"]
    np.testing.assert_allclose(se3.inverse(arm) @ tag, se3.translation((5, 0, 1)), atol=1e-9)
    assert config.motions["tag"].kind == "revolute"
    assert config.motions["arm"].kind == "revolute"


@pytest.mark.parametrize("angle", [0.3, 2.0])
def test_numeric_closure_is_deterministic(angle: float) -> None:
    world = {
        "u": Coset(SymmetryGroup.identity(), se3.rotation(Z, angle)),
        "v": Coset(SymmetryGroup.revolute((0, 0, 0), Z), se3.translation((2, 0, 0))),
    }
    slide = Coset(SymmetryGroup.prismatic(X), np.eye(4))
    first = numeric_closure(world, "u", "v", slide, TOL)
    again = numeric_closure(world, "u", "v", slide, TOL)
    assert first is not None and len(first) == 1
    np.testing.assert_array_equal(first[0]["v"].rep, again[0]["v"].rep)
    np.testing.assert_allclose(
        first[0]["v"].rep, se3.rotation(Z, angle) @ se3.translation((2, 0, 0)), atol=1e-9
    )
