"""Articulated assemblies: joints and the coupled gear train of Liu 1997 Figs. 7-9."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import assemblykit
from assemblykit.io.assembly import load_assembly
from assemblykit.motion.articulation import (
    GearMesh,
    Revolute,
    articulation,
    gear_meshes,
    gear_trains,
)
from assemblykit.tolerance import Tolerance

EXAMPLES = Path(assemblykit.__file__).parent / "examples" / "motion"
TOL = Tolerance(scale=100.0)


def _revolute(name: str, x: float, radius: float, up: float = 1.0) -> Revolute:
    return Revolute(name, np.array([x, 0.0, 0.0]), np.array([0.0, 0.0, up]), radius)


def test_tangent_pitch_circles_mesh_with_the_inverse_radius_ratio() -> None:
    joints = [_revolute("a", 0.0, 10.0), _revolute("b", 30.0, 20.0), _revolute("c", 80.0, 5.0)]
    assert gear_meshes(joints, TOL) == [GearMesh("a", "b", -0.5)]


def test_an_axis_pointing_the_other_way_flips_the_ratio_sign() -> None:
    joints = [_revolute("a", 0.0, 10.0), _revolute("b", 30.0, 20.0, up=-1.0)]
    assert gear_meshes(joints, TOL) == [GearMesh("a", "b", 0.5)]


def test_a_simple_train_has_one_dof_and_the_product_ratios() -> None:
    meshes = [GearMesh("a", "b", -0.5), GearMesh("b", "c", -4.0), GearMesh("c", "d", -0.2)]
    (train,) = gear_trains(meshes, TOL)
    assert (train.gears, train.dof) == (("a", "b", "c", "d"), 1)
    assert train.ratios == pytest.approx({"a": 1.0, "b": -0.5, "c": 2.0, "d": -0.4}, abs=1e-12)


def test_three_gears_in_a_loop_lock() -> None:
    meshes = [GearMesh("a", "b", -1.0), GearMesh("b", "c", -1.0), GearMesh("c", "a", -1.0)]
    (train,) = gear_trains(meshes, TOL)
    assert (train.dof, train.ratios) == (0, {})


def test_gearbox_of_seed_003_is_one_train_with_one_dof() -> None:
    result = articulation(load_assembly(EXAMPLES / "gearbox" / "gearbox.yaml"))
    (train,) = result.trains
    assert train.gears == ("gear_1", "gear_2", "gear_3", "gear_4")
    assert train.dof == 1
    # radii 10, 20, 5, 25: w2 = -w1/2, w3 = -4 w2, w4 = -w3/5
    expected = {"gear_1": 1.0, "gear_2": -0.5, "gear_3": 2.0, "gear_4": -0.4}
    assert train.ratios == pytest.approx(expected, abs=1e-9)
    data = result.to_dict()
    assert data["gear_trains"][0]["dof"] == 1
    assert data["parts"]["gear_1"]["motion"] == "revolute"
    assert [(m["a"], m["b"]) for m in data["gear_trains"][0]["meshes"]] == [
        ("gear_1", "gear_2"),
        ("gear_2", "gear_3"),
        ("gear_3", "gear_4"),
    ]


def test_hinge_has_no_gear_train() -> None:
    result = articulation(load_assembly(EXAMPLES / "hinge" / "hinge.yaml"))
    assert result.trains == ()
    assert result.to_dict()["gear_trains"] == []


def _ring(name: str, x: float, pitch: float, outside: float) -> Revolute:
    return Revolute(name, np.array([x, 0.0, 0.0]), np.array([0.0, 0.0, 1.0]), outside, pitch)


def test_a_gear_inside_a_ring_gear_turns_the_same_way() -> None:
    # ring: bore (pitch) radius 30 about the origin; gear of radius 10 at x = 20, so
    # |N1N2| = 30 - 10; equal pitch-line speeds 30 w_ring = 10 w_gear
    ring, gear = _ring("ring", 0.0, 30.0, 35.0), _revolute("gear", 20.0, 10.0)
    assert gear_meshes([ring, gear], TOL) == [GearMesh("ring", "gear", 3.0)]
    assert gear_meshes([gear, ring], TOL) == [GearMesh("gear", "ring", 1.0 / 3.0)]
    flipped = Revolute("gear", gear.point, -gear.direction, 10.0)
    assert gear_meshes([ring, flipped], TOL) == [GearMesh("ring", "gear", -3.0)]


def test_a_planetary_train_with_the_carrier_held_reverses_the_ring() -> None:
    sun, planet = _revolute("sun", 0.0, 10.0), _revolute("planet", 20.0, 10.0)
    ring = _ring("ring", 0.0, 30.0, 35.0)
    meshes = gear_meshes([sun, planet, ring], TOL)
    # the coaxial sun and ring do not mesh with each other
    assert meshes == [GearMesh("sun", "planet", -1.0), GearMesh("planet", "ring", 1.0 / 3.0)]
    (train,) = gear_trains(meshes, TOL)
    # fixed carrier: w_ring / w_sun = -z_sun / z_ring = -10 / 30
    assert train.ratios == pytest.approx({"sun": 1.0, "planet": -1.0, "ring": -1.0 / 3.0})


def test_a_gear_off_the_ring_pitch_circle_does_not_mesh() -> None:
    ring, gear = _ring("ring", 0.0, 30.0, 35.0), _revolute("gear", 19.0, 10.0)
    assert gear_meshes([ring, gear], TOL) == []
    # a sleeve turning in a coaxial bore of equal radius is no gear pair
    sleeve = _revolute("sleeve", 0.0, 30.0)
    assert gear_meshes([ring, sleeve], TOL) == []
