"""Joints named whenever the poses form one (docs/inference.md, "Joints made by several
contacts" and "Joints made by chains"): a rod with two points on a rail and a roller in a
V-block are cylindrical, a tripod on the floor planar, a gimbal's head spherical.

Each answer is worked out by hand in the test's docstring, then checked apart from the
solver: poses sampled from the reported group satisfy every relation, measured here from
the features' geometry; small motions outside the group break one. The task files are in
``tests/inference/tasks``."""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from assemblykit.algebra import se3
from assemblykit.inference import solve_task
from assemblykit.io.rapt import parse_rapt
from assemblykit.io.tasks import load_task
from assemblykit.model.task import Task

TASKS = Path(__file__).parent / "tasks"
EXACT = 1e-9
X, Y, Z = np.eye(3)


def solved(name: str) -> tuple[Task, dict]:
    task = load_task(TASKS / name)
    return task, solve_task(task).to_dict()


# ------------------------------------------------------ relations measured apart from the solver


def _placed(task: Task, ref, poses: Mapping[str, np.ndarray]):
    """The feature of ``ref`` in the world: its point, its axis or normal (or None)."""
    feature = task.bodies[ref.body].features[ref.feature]
    pose = poses.get(ref.body, np.eye(4))
    point = pose[:3, :3] @ np.asarray(feature.point) + pose[:3, 3]
    direction = getattr(feature, "normal", getattr(feature, "axis", None))
    return point, None if direction is None else pose[:3, :3] @ np.asarray(direction)


def _off_line(point, origin, direction) -> float:
    gap = point - origin
    return float(np.linalg.norm(gap - (gap @ direction) * direction))


def miss(task: Task, relation, poses: Mapping[str, np.ndarray]) -> float:
    """How far one relation is from holding at ``poses`` (0 when it holds): lengths, and
    angles as the arc they sweep at a length of 10."""
    first, second = (_placed(task, ref, poses) for ref in relation.refs)
    (p, u), (q, v) = first, second
    kind = relation.kind
    if kind == "point_on_line":
        return _off_line(p, q, v)
    if kind == "point_on_plane":
        return abs(float(v @ (p - q)))
    if kind == "distance":  # a line lying parallel to a plane at its distance
        return max(10 * abs(float(u @ v)), abs(float(v @ (p - q)) - relation.options["distance"]))
    if kind == "fits":  # coaxial, same direction
        return max(10 * float(np.linalg.norm(u - v)), _off_line(p, q, v))
    if kind == "against":  # opposed normals, one plane
        return max(10 * float(np.linalg.norm(u + v)), abs(float(v @ (p - q))))
    raise AssertionError(f"no independent measure of {kind}")


def worst(task: Task, poses: Mapping[str, np.ndarray]) -> float:
    return max(miss(task, r, poses) for s in task.situations for r in s.relations)


# ------------------------------------------------------------------ groups and their motions


def about(point, axis, angle: float) -> np.ndarray:
    return se3.rotation(np.asarray(axis, float), angle, np.asarray(point, float))


def shift(vector) -> np.ndarray:
    return se3.translation(np.asarray(vector, float))


def cylindrical_samples(point, direction, rng) -> list[np.ndarray]:
    """Members of C(point, direction)⋊{I, flip}: turns about the line, slides along it,
    and the half-turn about a line across it through ``point``."""
    across = np.cross(direction, X if abs(direction[0]) < 0.9 else Y)
    flip = about(point, across, math.pi)
    out = []
    for k in range(8):
        g = shift(rng.uniform(-20, 20) * direction) @ about(point, direction, rng.uniform(-4, 4))
        out.append(g @ flip if k % 2 else g)
    return out


def planar_samples(normal, level: float, rng) -> list[np.ndarray]:
    """Members of G(normal)⋊{I, flip}: slides in the plane, turns about its normal, and
    the half-turn about a line of the plane at height ``level``."""
    across = np.cross(normal, X if abs(normal[0]) < 0.9 else Y)
    flip = about(level * normal, across, math.pi)
    out = []
    for k in range(8):
        step = rng.uniform(-20, 20, 3)
        step -= (step @ normal) * normal
        g = shift(step) @ about(rng.uniform(-5, 5, 3), normal, rng.uniform(-4, 4))
        out.append(g @ flip if k % 2 else g)
    return out


def algebra(motion: str, invariants: Mapping[str, list[float]]) -> np.ndarray:
    """The twists (ω; v) of the reported group, v the velocity of the point at the
    origin (docs/algebra.md §1): rows."""
    if motion == "cylindrical":
        p, u = np.asarray(invariants["point"]), np.asarray(invariants["direction"])
        return np.array([[*u, *np.cross(p, u)], [0, 0, 0, *u]])
    if motion == "planar":
        n = np.asarray(invariants["normal"])
        a = np.cross(n, X if abs(n[0]) < 0.9 else Y)
        a /= np.linalg.norm(a)
        return np.array([[*n, 0, 0, 0], [0, 0, 0, *a], [0, 0, 0, *np.cross(n, a)]])
    if motion == "spherical":
        c = np.asarray(invariants["center"])
        return np.array([[*e, *np.cross(c, e)] for e in np.eye(3)])
    raise AssertionError(motion)


def outside(motion: str, invariants, rng, size: float = 1e-3) -> list[np.ndarray]:
    """Small motions exp(ξ) with ξ a random twist with no part along the group."""
    basis = np.linalg.qr(algebra(motion, invariants).T)[0]
    out = []
    for _ in range(6):
        xi = rng.normal(size=6)
        xi -= basis @ (basis.T @ xi)
        out.append(se3.exp(size * xi / np.linalg.norm(xi)))
    return out


# ------------------------------------------------------------------ several contacts


def test_rod_with_two_points_on_a_rail_is_cylindrical_about_the_rail():
    """By hand: the rod's points (1, 2, 0) and (4, 6, 0) lie on its line along
    (0.6, 0.8, 0); every pose puts that line on the rail (y = 0, z = 5 along x), either
    way round: C(rail)⋊{I, flip}, 2 dof, 2 solutions. Least motion: the least turn
    Rz(-atan(4/3)) brings (0.6, 0.8, 0) onto +x and carries (1, 2, 0) to (2.2, 0.4, 0),
    then the shortest shift (0, -0.4, 5) puts it on the rail."""
    task, out = solved("rod_on_a_rail.rapt")
    rod = out["bodies"]["rod@s1"]
    assert out["status"] == "underconstrained"
    assert (rod["dof"], rod["motion"], rod["solutions"]) == (2, "cylindrical", 2)
    assert "mechanism" not in rod
    np.testing.assert_allclose(rod["invariants"]["direction"], X, atol=EXACT)
    assert _off_line(np.asarray(rod["invariants"]["point"]), (0, 0, 5), X) < EXACT
    expected = shift((0, -0.4, 5)) @ se3.rot_z(-math.atan2(4, 3))
    np.testing.assert_allclose(rod["pose"], expected, atol=EXACT)
    assert rod["freedom"].startswith("rod@s1 can slide along and turn about the axis")
    pose = np.asarray(rod["pose"])
    rng = np.random.default_rng(1)
    for g in cylindrical_samples(np.array([0.0, 0.0, 5.0]), X, rng):
        assert worst(task, {"rod": g @ pose}) < EXACT
    for step in outside("cylindrical", rod["invariants"], rng):
        assert worst(task, {"rod": step @ pose}) > 1e-6


def test_roller_in_a_90_degree_v_block_is_cylindrical_about_its_seat_line():
    """By hand: the faces' normals (∓1, 0, 1)/√2 are at 90°; the axis must lie parallel
    to both (along their common direction y) and 2 from each: x = 0 and (±x + z)/√2 = 2,
    so z = 2√2. The roller is already along y: the least motion is the lift (0, 0, 2√2).
    Every pose turns about that line, slides along it or is turned end for end."""
    task, out = solved("roller_in_a_v_block.yaml")
    roller = out["bodies"]["roller@s1"]
    assert (roller["dof"], roller["motion"], roller["solutions"]) == (2, "cylindrical", 2)
    seat = np.array([0.0, 0.0, 2 * math.sqrt(2)])
    np.testing.assert_allclose(roller["invariants"]["direction"], Y, atol=EXACT)
    assert _off_line(np.asarray(roller["invariants"]["point"]), seat, Y) < EXACT
    np.testing.assert_allclose(roller["pose"], shift(seat), atol=EXACT)
    pose = np.asarray(roller["pose"])
    rng = np.random.default_rng(2)
    for g in cylindrical_samples(seat, Y, rng):
        assert worst(task, {"roller": g @ pose}) < EXACT
    for step in outside("cylindrical", roller["invariants"], rng):
        assert worst(task, {"roller": step @ pose}) > 1e-6


def test_tripod_with_three_feet_on_the_floor_is_planar():
    """By hand: the feet (2, 0, 0), (0, 2, 0), (0, 0, 2) lie on the plane x + y + z = 2 of
    normal e = (1, 1, 1)/√3; every pose lays that plane on the floor, either side up:
    G(z)⋊{I, flip}, 3 dof, 2 solutions. Least motion: the least turn of e onto +z, by
    acos(1/√3) about (1, -1, 0)/√2, puts every foot at height e·f = 2/√3; then the
    shift (0, 0, -2/√3)."""
    task, out = solved("tripod_on_the_floor.rapt")
    tripod = out["bodies"]["tripod@s1"]
    assert (tripod["dof"], tripod["motion"], tripod["solutions"]) == (3, "planar", 2)
    np.testing.assert_allclose(tripod["invariants"]["normal"], Z, atol=EXACT)
    turn = about((0, 0, 0), (1, -1, 0), math.acos(1 / math.sqrt(3)))
    np.testing.assert_allclose(tripod["pose"], shift((0, 0, -2 / math.sqrt(3))) @ turn, atol=EXACT)
    pose = np.asarray(tripod["pose"])
    rng = np.random.default_rng(3)
    for g in planar_samples(Z, 0.0, rng):
        assert worst(task, {"tripod": g @ pose}) < EXACT
    for step in outside("planar", tripod["invariants"], rng):
        assert worst(task, {"tripod": step @ pose}) > 1e-6


def test_feet_that_cannot_reach_their_steps_conflict_by_what_they_lack():
    """By hand: with the foot (2, 0, 0) on a step 4 above the floor, the body direction m
    carried onto +z needs m·(f1 - f2) = m·(f1 - f3) = 4, i.e. m = (t, t - 2, t - 2), whose
    length is at least √(8/3) (at t = 4/3) > 1: no pose. Along the steepest direction
    (2, -1, -1)/√6 the feet span √6 where the steps need 4: 4 - √6 short. No pose is
    reported as if it held: the poses are those without the three feet."""
    text = (TASKS / "tripod_on_the_floor.rapt").read_text()
    text = text.replace(
        "plane top point (0, 0, 0) normal (0, 0, 1)",
        "plane top point (0, 0, 0) normal (0, 0, 1)\n  plane step point (0, 0, 4) normal (0, 0, 1)",
    ).replace(
        "point_on_plane f1 of tripod, top of floor", "point_on_plane f1 of tripod, step of floor"
    )
    out = solve_task(parse_rapt(text)).to_dict()
    assert out["status"] == "inconsistent"
    (conflict,) = out["conflicts"]
    assert conflict["kind"] == "distance"
    assert conflict["value"] == pytest.approx(4 - math.sqrt(6), abs=EXACT)
    assert len(conflict["relations"]) == 3
    assert out["valid_without"] == conflict["relations"]
    assert out["bodies"]["tripod@s1"]["dof"] == 6


def test_two_points_too_close_for_their_planes_conflict_by_the_gap():
    """By hand: the rod's points are 5 apart; on two parallel planes 7 apart no pose
    holds them, whatever the tilt: 7 - 5 = 2 short."""
    text = (TASKS / "rod_on_a_rail.rapt").read_text()
    text = text.replace(
        "axis rail point (0, 0, 5) axis (1, 0, 0)",
        "plane low point (0, 0, 0) normal (0, 0, 1)\n  plane high point (0, 0, 7) normal (0, 0, 1)",
    )
    text = text.replace(
        "point_on_line a of rod, rail of world", "point_on_plane a of rod, low of world"
    )
    text = text.replace(
        "point_on_line b of rod, rail of world", "point_on_plane b of rod, high of world"
    )
    (conflict,) = solve_task(parse_rapt(text)).conflicts
    assert (conflict.kind, conflict.value) == ("distance", pytest.approx(2.0, abs=EXACT))


# ------------------------------------------------------------------ chains of joints


def gimbal_poses(rotation: np.ndarray) -> dict[str, np.ndarray]:
    """The rings' poses for a head turned by ``rotation`` about the origin: the intrinsic
    z-x-y angles, R = Rz(a)·Rx(b)·Ry(c) (outer Rz(a), inner Rz(a)·Rx(b))."""
    a, b, c = Rotation.from_matrix(rotation[:3, :3]).as_euler("ZXY")
    outer = se3.rot_z(a)
    inner = outer @ se3.rot_x(b)
    return {"outer": outer, "inner": inner, "head": inner @ se3.rot_y(c)}


def least_reach(task: Task, head: np.ndarray, start: Mapping[str, np.ndarray]) -> float:
    """The least worst miss of the relations over the rings' poses with the head held
    at ``head`` (a local search from ``start``, then from the identity)."""

    def residual(x: np.ndarray) -> np.ndarray:
        poses = {"head": head}
        for i, name in enumerate(("outer", "inner")):
            poses[name] = se3.exp(x[6 * i : 6 * i + 6]) @ start[name]
        return np.array([miss(task, r, poses) for r in task.situations[0].relations])

    fit = least_squares(residual, np.zeros(12), xtol=1e-10, ftol=1e-10, gtol=1e-10)
    return float(np.abs(residual(fit.x)).max())


def test_gimbal_head_is_spherical_about_where_the_axes_meet():
    """By hand: the head turns about y in the inner ring, which turns about x in the
    outer ring, which turns about z on the base, all through the origin; x is
    perpendicular to z and to y, so every turn about the origin is Rz(a)·Rx(b)·Ry(c)
    (the intrinsic z-x-y angles): S(origin), 3 dof, at the pose as written. The inner
    ring keeps the two turns Rz·Rx, no group: a mechanism of 2 dof."""
    task, out = solved("gimbal.rapt")
    bodies = out["bodies"]
    head = bodies["head@s1"]
    assert (head["dof"], head["motion"], head["solutions"]) == (3, "spherical", 1)
    np.testing.assert_allclose(head["invariants"]["center"], [0, 0, 0], atol=EXACT)
    np.testing.assert_allclose(head["pose"], np.eye(4), atol=EXACT)
    assert head["freedom"].startswith("head@s1 can turn about (0, 0, 0): 3 dof")
    assert (bodies["outer@s1"]["motion"], bodies["inner@s1"]["dof"]) == ("revolute", 2)
    assert bodies["inner@s1"]["motion"] == "mechanism"
    for turn in Rotation.random(6, random_state=4).as_matrix():
        rotation = np.eye(4)
        rotation[:3, :3] = turn
        poses = gimbal_poses(rotation)
        np.testing.assert_allclose(poses["head"], rotation, atol=EXACT)
        assert worst(task, poses) < EXACT
    rng = np.random.default_rng(5)
    for step in outside("spherical", head["invariants"], rng)[:2]:
        moved = step @ np.asarray(head["pose"])
        assert least_reach(task, moved, gimbal_poses(moved)) > 1e-6


def test_gimbal_whose_middle_axis_leans_is_no_spherical_joint():
    """With the outer ring's pin along (1, 0, 1) the middle axis is not perpendicular to
    the first: the head's y axis stays between 45° and 135° from z (a cone about the
    middle axis), so the half-turn Rx(90°), which takes y onto z, is out of reach. The
    head keeps 3 dof that no joint names."""
    text = (TASKS / "gimbal.rapt").read_text()
    for old, new in (
        (
            "shaft pin   point (0, 0, 0)  axis (1, 0, 0)",
            "shaft pin   point (0, 0, 0)  axis (1, 0, 1)",
        ),
        (
            "hole  bore  point (0, 0, 0)  axis (1, 0, 0)",
            "hole  bore  point (0, 0, 0)  axis (1, 0, 1)",
        ),
        (
            "plane seat  point (-5, 0, 0) normal (1, 0, 0)",
            "plane seat  point (-5, 0, -5) normal (1, 0, 1)",
        ),
        (
            "plane under point (-5, 0, 0) normal (-1, 0, 0)",
            "plane under point (-5, 0, -5) normal (-1, 0, -1)",
        ),
    ):
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    task = parse_rapt(text)
    head = solve_task(task).to_dict()["bodies"]["head@s1"]
    assert (head["dof"], head["motion"]) == (3, "mechanism")
    quarter = se3.rot_x(math.pi / 2)
    assert least_reach(task, quarter, {"outer": np.eye(4), "inner": np.eye(4)}) > 1e-3


CROSS_SLIDE = """\
units mm
body base fixed
  shaft pin   point (0, 0, 0) axis (0, 0, 1) radius 1
  plane seat  point (0, 0, 0) normal (0, 0, 1)
end
body table
  hole  bore  point (0, 0, 0) axis (0, 0, 1) radius 1
  plane under point (0, 0, 0) normal (0, 0, -1)
  plane top   point (0, 0, 1) normal (0, 0, 1)
  plane fence point (0, 0, 0) normal (0, 1, 0)
end
body saddle
  plane under point (0, 0, 1) normal (0, 0, -1)
  plane side  point (0, 0, 0) normal (0, -1, 0)
  plane top   point (0, 0, 2) normal (0, 0, 1)
  plane fence point (0, 0, 0) normal (1, 0, 0)
end
body slide
  plane under point (0, 0, 2) normal (0, 0, -1)
  plane side  point (0, 0, 0) normal (-1, 0, 0)
end
situation s1
  fits bore of table, pin of base
  against under of table, seat of base
  against under of saddle, top of table
  against side of saddle, fence of table
  against under of slide, top of saddle
  against side of slide, fence of saddle
end
"""


def test_a_turntable_carrying_a_cross_slide_moves_the_slide_in_the_plane():
    """By hand: the table turns about z (R), the saddle slides along x on it (P), the
    slide along y on the saddle (P): R·P·P = R·T₂ = G(z), the planar joint, although R·P
    alone is no group. Any planar pose Tr(p)·Rz(θ) is Rz(θ)·Tr(s, 0, 0)·Tr(0, t, 0) with
    (s, t) = Rz(-θ)·p: table Rz(θ), saddle Rz(θ)·Tr(s, 0, 0)."""
    task = parse_rapt(CROSS_SLIDE)
    bodies = solve_task(task).to_dict()["bodies"]
    slide = bodies["slide@s1"]
    assert (slide["dof"], slide["motion"], slide["solutions"]) == (3, "planar", 1)
    np.testing.assert_allclose(slide["invariants"]["normal"], Z, atol=EXACT)
    assert (bodies["saddle@s1"]["motion"], bodies["saddle@s1"]["dof"]) == ("mechanism", 2)
    rng = np.random.default_rng(6)
    for _ in range(6):
        theta, p = rng.uniform(-3, 3), np.append(rng.uniform(-20, 20, 2), 0.0)
        s, t, _ = se3.rot_z(-theta)[:3, :3] @ p
        table = se3.rot_z(theta)
        poses = {"table": table, "saddle": table @ shift((s, 0, 0))}
        poses["slide"] = poses["saddle"] @ shift((0, t, 0))
        np.testing.assert_allclose(poses["slide"], shift(p) @ se3.rot_z(theta), atol=EXACT)
        assert worst(task, poses) < EXACT
