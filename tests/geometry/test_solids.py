"""Generated solids (manifold3d booleans of boxes and cylinders) and placed copies."""

from __future__ import annotations

import math

import numpy as np
import pytest

from assemblykit.algebra import se3
from assemblykit.errors import GeometryError, SchemaError
from assemblykit.geometry.solids import CYLINDER_SECTIONS, Box, Cylinder, generated_mesh, placed


def test_generated_mesh_is_box_minus_cylinder() -> None:
    mesh = generated_mesh(
        [Box((-5, -5, 0), (5, 5, 2))], [Cylinder((0, 0, -1), (0, 0, 1), 1.0, 4.0)]
    )
    # The cut is the inscribed 48-gon prism of radius 1 and height 2 (inside the box).
    polygon = 0.5 * CYLINDER_SECTIONS * math.sin(2 * math.pi / CYLINDER_SECTIONS)
    assert mesh.is_watertight
    assert mesh.volume == pytest.approx(200 - 2 * polygon, rel=1e-9)


def test_union_of_overlapping_boxes() -> None:
    mesh = generated_mesh([Box((0, 0, 0), (2, 1, 1)), Box((1, 0, 0), (3, 1, 1))])
    assert mesh.volume == pytest.approx(3.0, rel=1e-12)


def test_bad_primitives_and_empty_result() -> None:
    with pytest.raises(SchemaError, match="max > min"):
        generated_mesh([Box((0, 0, 0), (1, 0, 1))])
    with pytest.raises(SchemaError, match="non-zero"):
        generated_mesh([Cylinder((0, 0, 0), (0, 0, 0), 1.0, 1.0)])
    with pytest.raises(GeometryError, match="m: the generated mesh is empty"):
        generated_mesh([Box((0, 0, 0), (1, 1, 1))], [Box((-1, -1, -1), (2, 2, 2))], where="m")


def test_placed_moves_a_copy() -> None:
    mesh = generated_mesh([Box((0, 0, 0), (1, 1, 1))])
    pose = se3.translation((5, 0, 0)) @ se3.rotation((0, 0, 1), math.pi / 2)
    moved = placed(mesh, pose)
    np.testing.assert_allclose(moved.bounds, [[4, 0, 0], [5, 1, 1]], atol=1e-12)
    np.testing.assert_allclose(mesh.bounds, [[0, 0, 0], [1, 1, 1]], atol=0)
