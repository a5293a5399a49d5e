"""Tests of swept volumes for extended translations (seed 004)."""

from __future__ import annotations

import manifold3d
import numpy as np
import trimesh

from assemblykit.geometry.interference import interferes
from assemblykit.planning.sweep import swept_volume
from assemblykit.tolerance import Tolerance

TOL = Tolerance(scale=10.0).for_mesh()


def from_manifold(solid: manifold3d.Manifold) -> trimesh.Trimesh:
    mesh = solid.to_mesh64()
    return trimesh.Trimesh(np.array(mesh.vert_properties[:, :3]), np.array(mesh.tri_verts))


def test_cube_sweeps_a_box():
    cube = trimesh.creation.box(extents=(1, 1, 1))
    sweep = swept_volume(cube, np.array([0.0, 0.0, 2.0]), 2.0, TOL)
    assert np.isclose(sweep.volume, 3.0)
    assert np.allclose(sweep.bounds, [[-0.5, -0.5, -0.5], [0.5, 0.5, 2.5]])
    diagonal = swept_volume(cube, np.array([1.0, 1.0, 0.0]), np.sqrt(2.0), TOL)
    # a unit square swept by (1, 1): 1 + 2 parallelograms of area 1, times height 1
    assert np.isclose(diagonal.volume, 3.0)


def test_pin_slides_through_its_hole_but_not_sideways():
    pin = manifold3d.Manifold.cylinder(4.0, 0.5, 0.5, 16).translate((0.0, 0.0, -2.0))
    plate = manifold3d.Manifold.cube((4.0, 4.0, 1.0), True) - manifold3d.Manifold.cylinder(
        4.0, 0.5, 0.5, 16
    ).translate((0.0, 0.0, -2.0))
    pin_mesh, plate_mesh = from_manifold(pin), from_manifold(plate)
    assert not interferes(pin_mesh, plate_mesh, TOL)
    for direction in ([0.0, 0.0, 1.0], [0.0, 0.0, -1.0]):
        along = swept_volume(pin_mesh, np.array(direction), 10.0, TOL)
        assert not interferes(along, plate_mesh, TOL)
    sideways = swept_volume(pin_mesh, np.array([1.0, 0.0, 0.0]), 10.0, TOL)
    assert interferes(sideways, plate_mesh, TOL)


def test_t_shaped_post_lifts_out_of_its_slot():
    # a post through a plate with a wider head above it: free upwards, blocked downwards
    post = manifold3d.Manifold.cube((1.0, 1.0, 3.0)).translate((-0.5, -0.5, 0.0))
    head = manifold3d.Manifold.cube((2.0, 2.0, 1.0)).translate((-1.0, -1.0, 3.0))
    plate = manifold3d.Manifold.cube((6.0, 6.0, 1.0)).translate((-3.0, -3.0, 0.0)) - post
    tee, plate_mesh = from_manifold(post + head), from_manifold(plate)
    up = swept_volume(tee, np.array([0.0, 0.0, 1.0]), 10.0, TOL)
    down = swept_volume(tee, np.array([0.0, 0.0, -1.0]), 10.0, TOL)
    assert not interferes(up, plate_mesh, TOL)
    assert interferes(down, plate_mesh, TOL)
