"""The residue solver on hand-built constraint systems (Corner et al. 1983 §III G, docs/algebra.md
§2.5)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from assemblykit.inference.numeric import (
    Constraint,
    ResidueProblem,
    _same_solution,
    pose_from_twist,
    solve_residue,
)
from assemblykit.model.relations import gear_residual, mirror_residual, signed_angle, wrap_angle
from assemblykit.tolerance import Tolerance

TOL = Tolerance(scale=10.0)
E3 = np.array([0.0, 0.0, 1.0])


def rz(angle: float, about: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    pose = np.eye(4)
    pose[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
    pose[:3, 3] = np.asarray(about) - pose[:3, :3] @ np.asarray(about)
    return pose


def shift(x: float, y: float = 0.0, z: float = 0.0) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, 3] = [x, y, z]
    return pose


def at(pose: np.ndarray, point) -> np.ndarray:
    return pose[:3, :3] @ np.asarray(point, dtype=float) + pose[:3, 3]


def pin(world_point, local_point) -> Constraint:
    """A revolute joint to the world about a vertical axis, written as residuals."""
    return lambda poses: np.concatenate(
        [at(poses[0], local_point) - np.asarray(world_point, float), poses[0][:3, 2] - E3]
    )


def joint(local_a, local_b):
    """A revolute joint between two bodies about parallel vertical axes."""
    return lambda poses: np.concatenate(
        [at(poses[0], local_a) - at(poses[1], local_b), poses[0][:3, 2] - poses[1][:3, 2]]
    )


def fixed(target: np.ndarray):
    return lambda poses: (poses[0][:3] - target[:3]).ravel()


def slider_x(poses):
    """A prismatic joint to the world along x: no rotation, y = z = 0."""
    return np.concatenate([(poses[0][:3, :3] - np.eye(3)).ravel(), poses[0][1:3, 3]])


def four_bar(crank_stopped: bool) -> ResidueProblem:
    """Ground pivots A=(0,-2), D=(6,0); crank AB 2, coupler BC 5, rocker DC 5.

    With the crank stopped vertical, B=(0,0) and C is a common point of the circles
    |C-B| = 5 and |C-D| = 5: C = (3, 4) or (3, -4), the two assembly modes.
    """
    crank = np.eye(4)
    crank[:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]  # body x axis along world +y
    crank[:3, 3] = [0, -2, 0]
    constraints = [
        Constraint(("rocker",), pin((6, 0, 0), (0, 0, 0))),
        Constraint(("crank", "coupler"), joint((2, 0, 0), (0, 0, 0))),
        Constraint(("coupler", "rocker"), joint((5, 0, 0), (5, 0, 0))),
    ]
    known: dict = {}
    if crank_stopped:
        known["crank"] = crank
    else:
        constraints.append(Constraint(("crank",), pin((0, -2, 0), (0, 0, 0))))
    unknowns = tuple(n for n in ("crank", "coupler", "rocker") if n not in known)
    start = {"crank": crank, "coupler": np.eye(4), "rocker": shift(6)}
    return ResidueProblem(unknowns, {n: start[n] for n in unknowns}, known, tuple(constraints))


def test_pose_from_twist_is_left_rotation_plus_translation():
    start = shift(1, 2, 3)
    pose = pose_from_twist(start, np.array([0, 0, math.pi / 2, 1, 0, 0]))
    assert np.allclose(pose[:3, :3], rz(math.pi / 2)[:3, :3])
    assert np.allclose(pose[:3, 3], [2, 2, 3])


def test_wrap_and_signed_angle():
    assert wrap_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)
    assert wrap_angle(-math.pi) == pytest.approx(math.pi)
    assert signed_angle(np.array([1.0, 0, 0]), np.array([0.0, 1, 0]), E3) == pytest.approx(
        math.pi / 2
    )
    assert signed_angle(np.array([1.0, 0, 0]), np.array([0.0, -1, 0]), E3) == pytest.approx(
        -math.pi / 2
    )


def test_four_bar_with_crank_stopped_has_two_assembly_modes():
    result = solve_residue(four_bar(crank_stopped=True), TOL, starts=12)
    assert result.found
    assert len(result.solutions) == 2
    tips = sorted(tuple(np.round(at(s.poses["coupler"], (5, 0, 0)), 9)) for s in result.solutions)
    assert tips == [(3.0, -4.0, 0.0), (3.0, 4.0, 0.0)]
    for solution in result.solutions:
        assert solution.total_dof == 0
        assert solution.dof == {"coupler": 0, "rocker": 0}
        c = at(solution.poses["coupler"], (5, 0, 0))
        assert np.allclose(at(solution.poses["rocker"], (5, 0, 0)), c, atol=1e-9)
        assert np.allclose(at(solution.poses["coupler"], (0, 0, 0)), 0, atol=1e-9)
        assert np.allclose(solution.poses["rocker"][:3, 3], [6, 0, 0], atol=1e-9)


def test_free_four_bar_has_one_dof_for_every_link():
    result = solve_residue(four_bar(crank_stopped=False), TOL, starts=4)
    assert result.found
    solution = result.solutions[0]
    assert solution.total_dof == 1
    assert solution.dof == {"crank": 1, "coupler": 1, "rocker": 1}


def test_no_solution_found_reports_best_residual():
    # a point of the body at distance 5 from the origin and at distance 1 from (10, 0, 0)
    constraints = (
        Constraint(("b",), lambda p: np.array([np.linalg.norm(p[0][:3, 3]) - 5])),
        Constraint(("b",), lambda p: np.array([np.linalg.norm(p[0][:3, 3] - [10, 0, 0]) - 1])),
    )
    result = solve_residue(ResidueProblem(("b",), {"b": np.eye(4)}, {}, constraints), TOL, starts=3)
    assert not result.found
    assert result.best_residual == pytest.approx(2.0, abs=1e-4)  # gap 10 - 5 - 1 = 4, split


def test_gear_pair_turns_in_ratio():
    """Gear 1 about (0,0), gear 2 about (3,0); ratio -2: gear 1 by 0.3 turns gear 2 by -0.6."""
    gear = gear_residual(np.eye(4), shift(3), -2.0)
    problem = ResidueProblem(
        ("g2",),
        {"g2": np.eye(4)},
        {"g1": rz(0.3), "carrier": np.eye(4)},
        (
            Constraint(("g2",), pin((3, 0, 0), (3, 0, 0))),
            Constraint(("g1", "g2", "carrier"), gear),
        ),
    )
    result = solve_residue(problem, TOL, starts=6)
    assert len(result.solutions) == 1
    assert np.allclose(result.solutions[0].poses["g2"], rz(-0.6, (3, 0, 0)), atol=1e-9)
    assert result.solutions[0].total_dof == 0


def test_gear_residual_is_measured_in_the_carrier():
    gear = gear_residual(np.eye(4), shift(3), -2.0, scale=10.0)
    assert gear([rz(0.25), rz(-0.5, (3, 0, 0)), np.eye(4)]) == pytest.approx([0.0], abs=1e-12)
    assert gear([rz(0.25), rz(0.5, (3, 0, 0)), np.eye(4)]) == pytest.approx([10.0], abs=1e-12)
    carrier = shift(4, 5) @ rz(1.0)  # the whole gearbox moved: same relation
    moved = [carrier @ rz(0.25), carrier @ rz(-0.5, (3, 0, 0)), carrier]
    assert gear(moved) == pytest.approx([0.0], abs=1e-12)


def test_gear_pair_free_moves_together_with_one_dof():
    gear = gear_residual(np.eye(4), shift(3), -2.0)
    problem = ResidueProblem(
        ("g1", "g2"),
        {"g1": np.eye(4), "g2": np.eye(4)},
        {"carrier": np.eye(4)},
        (
            Constraint(("g1",), pin((0, 0, 0), (0, 0, 0))),
            Constraint(("g2",), pin((3, 0, 0), (3, 0, 0))),
            Constraint(("g1", "g2", "carrier"), gear),
        ),
    )
    solution = solve_residue(problem, TOL, starts=2).solutions[0]
    assert solution.total_dof == 1
    assert solution.dof == {"g1": 1, "g2": 1}


def test_mirror_gripper_jaws_move_equal_and_opposite():
    """Jaw faces at x = -2 (normal +x) and x = 2; jaw a closes by 0.5, so jaw b by -0.5."""
    face_a, face_b = shift(-2), shift(2)
    mirror = mirror_residual(face_a, face_b, np.array([1.0, 0, 0]))
    constraints = (
        Constraint(("b",), slider_x),
        Constraint(("a", "b", "palm"), mirror),
    )
    problem = ResidueProblem(
        ("b",), {"b": np.eye(4)}, {"a": shift(0.5), "palm": np.eye(4)}, constraints
    )
    result = solve_residue(problem, TOL, starts=4)
    assert len(result.solutions) == 1
    assert np.allclose(result.solutions[0].poses["b"], shift(-0.5), atol=1e-9)
    free = ResidueProblem(
        ("a", "b"),
        {"a": np.eye(4), "b": np.eye(4)},
        {"palm": shift(7, 1)},
        (
            Constraint(("a", "palm"), lambda p: slider_x([np.linalg.inv(p[1]) @ p[0]])),
            Constraint(("b", "palm"), lambda p: slider_x([np.linalg.inv(p[1]) @ p[0]])),
            Constraint(("a", "b", "palm"), mirror),
        ),
    )
    solution = solve_residue(free, TOL, starts=2).solutions[0]
    assert solution.total_dof == 1
    assert solution.dof == {"a": 1, "b": 1}
    a_shift = solution.poses["a"][0, 3] - 7
    b_shift = solution.poses["b"][0, 3] - 7
    assert a_shift == pytest.approx(-b_shift, abs=1e-9)


def test_known_only_problem_checks_the_residual():
    problem = ResidueProblem((), {}, {"a": shift(1)}, (Constraint(("a",), fixed(shift(1))),))
    assert solve_residue(problem, TOL).found
    wrong = ResidueProblem((), {}, {"a": shift(1)}, (Constraint(("a",), fixed(shift(2))),))
    result = solve_residue(wrong, TOL)
    assert not result.found
    assert result.best_residual == pytest.approx(1.0)


def _slide(x: float) -> np.ndarray:
    pose = np.eye(4)
    pose[0, 3] = x
    return pose


def test_two_stops_on_one_badly_conditioned_solution_are_one_solution():
    """x is held only weakly (weight 1e-9): poses at x = 0 and x = 0.3 both satisfy the
    constraint within the tolerance, and so does every pose between them: one solution."""
    tol = Tolerance(scale=1.0)

    def weak(poses):
        return np.concatenate([[1e-9 * poses[0][0, 3]], poses[0][1:3, 3]])

    problem = ResidueProblem(("a",), {"a": np.eye(4)}, {}, (Constraint(("a",), weak),))
    assert _same_solution(problem, {"a": _slide(0.0)}, {"a": _slide(0.3)}, tol)


def test_two_assembly_modes_are_kept_apart():
    """x² = 1 (no rotation, y = z = 0) has the solutions x = ±1; the pose halfway (x = 0)
    violates it by 1, so the multi-start keeps both."""
    tol = Tolerance(scale=1.0)

    def square(poses):
        pose = poses[0]
        rotation = (pose[:3, :3] - np.eye(3)).ravel()
        return np.concatenate([[pose[0, 3] ** 2 - 1.0], pose[1:3, 3], rotation])

    problem = ResidueProblem(("a",), {"a": np.eye(4)}, {}, (Constraint(("a",), square),))
    assert not _same_solution(problem, {"a": _slide(1.0)}, {"a": _slide(-1.0)}, tol)
    result = solve_residue(problem, tol, starts=8)
    xs = sorted(round(s.poses["a"][0, 3], 6) for s in result.solutions)
    assert xs == [-1.0, 1.0]


def test_acceptance_follows_the_tolerance_and_never_loosens_the_solve():
    """Two ``fixed`` constraints 2e-6 apart along x: the best pose is halfway, each
    constraint misses by 1e-6 (by hand), i.e. 1e-7 of the scale 10. It is rejected
    below that and accepted at every looser tolerance, with the same tight residual
    (the solver stops on ``tol.precision``, not on the acceptance threshold)."""
    problem = ResidueProblem(
        ("b",),
        {"b": np.eye(4)},
        {},
        (Constraint(("b",), fixed(shift(0.0))), Constraint(("b",), fixed(shift(2e-6)))),
    )
    for rel in (1e-9, 5e-8):
        result = solve_residue(problem, Tolerance.relative(rel).with_scale(10.0), starts=2)
        assert not result.found
        assert result.best_residual == pytest.approx(1e-6, rel=1e-6)
    for rel in (2e-7, 1e-5, 1e-3, 1e-2, 0.1):
        result = solve_residue(problem, Tolerance.relative(rel).with_scale(10.0), starts=2)
        assert result.found
        (solution,) = result.solutions
        assert solution.residual == pytest.approx(1e-6, rel=1e-6)
        assert solution.total_dof == 0
        np.testing.assert_allclose(solution.poses["b"][:3, 3], [1e-6, 0, 0], atol=1e-12)
