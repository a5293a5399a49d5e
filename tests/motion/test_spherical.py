"""The ball-in-socket contact region (geometry/curved.py) and its unilateral reading."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import assemblykit
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.geometry.curved import in_region
from assemblykit.io.assembly import load_assembly
from assemblykit.motion.freedom import MotionSolver
from assemblykit.tolerance import Tolerance

BALL_JOINT = Path(assemblykit.__file__).parent / "examples" / "motion" / "ball_joint"
OCTANT = np.eye(3)[None]  # the spherical triangle x, y, z: the first octant


def test_a_direction_is_in_the_octant_triangle_iff_its_components_are_non_negative() -> None:
    directions = np.array(
        [
            [1.0, 1.0, 1.0],
            [-1.0, 1.0, 1.0],
            [1.0, 0.0, 0.0],  # a corner: boundaries count
            [1.0, 1.0, 0.0],  # on an edge
            [-1.0, -1.0, -1.0],  # the antipode is on the inner side of no great circle
            [0.0, 0.0, -1.0],
        ]
    )
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    found = in_region(directions, OCTANT, Tolerance())
    assert found.tolist() == [True, False, True, True, False, False]


def test_orientation_of_the_triangle_does_not_matter_and_flat_ones_cover_nothing() -> None:
    reversed_octant = OCTANT[:, ::-1]
    flat = np.array([[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]])
    d = np.array([[1.0, 1.0, 1.0]]) / math.sqrt(3.0)
    assert in_region(d, reversed_octant, Tolerance()).tolist() == [True]
    assert in_region(d, flat, Tolerance()).tolist() == [False]


def _region_and_ball(path: Path) -> tuple[np.ndarray, np.ndarray]:
    assembly = load_assembly(path)
    contact = next(c for c in assembly_contacts(assembly) if c.curved)
    patch = contact.curved[0]
    region = patch.points
    assert region is not None
    ball = MotionSolver(assembly).motion_of(patch.inner)
    return region - patch.center, np.array(ball.unilateral.to_dict()["lift_off"])


def _check_cup(region: np.ndarray, rays: np.ndarray, rim: float = 1e-6) -> None:
    # the cup is cut at z = -2 on the sphere of radius 10 about the origin (up to ``rim``)
    assert np.max(region[:, 2]) <= -2.0 + rim
    assert np.min(region[:, 2]) == pytest.approx(-10.0, abs=0.05)
    # free translations d·n ≤ 0 for every n of the cap z ≤ -0.2: bounded by the
    # rim cone, whose extreme rays make the angle asin(0.2) with +z
    assert len(rays) >= 8
    np.testing.assert_allclose(rays[:, 2], math.sqrt(1.0 - 0.2**2), atol=5e-4)


def test_the_meshed_ball_touches_its_cup_only_below_the_rim() -> None:
    _check_cup(*_region_and_ball(BALL_JOINT / "ball_joint.yaml"))


@pytest.mark.cad
def test_the_step_ball_touches_its_cup_only_below_the_rim_and_lifts_out() -> None:
    pytest.importorskip("OCP")
    step = pytest.importorskip("assemblykit.io.step")
    # the STEP cup's mesh lies inside the solid, its rim moved within the linear
    # deflection (docs/geometry.md, "STEP tessellation"): a fraction of the cup's size
    path = BALL_JOINT / "ball_joint.step"
    cup = max(load_assembly(path).parts.values(), key=lambda p: len(p.mesh.faces))
    deflection = step.LINEAR_DEFLECTION * float(np.linalg.norm(np.ptp(cup.mesh.bounds, axis=0)))
    _check_cup(*_region_and_ball(path), rim=deflection)
