"""Tests of the candidate directions added where the sampled ones separate nothing
(:mod:`assemblykit.planning.candidates`)."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from assemblykit.model.assembly import Assembly, Part
from assemblykit.planning.candidates import fit_axes
from stability_blocks import box


def test_the_axes_tried_when_sampled_directions_free_nothing_are_the_fits_and_coordinates():
    # a pin of radius 1 tilted 30 degrees about x in a block's hole of its radius: its
    # fit's axis (0, -sin 30, cos 30), both ways, joins the coordinate axes; no other
    # contact is curved
    tilt = trimesh.transformations.rotation_matrix(np.pi / 6, [1, 0, 0])
    drill = trimesh.creation.cylinder(1.0, 20, sections=48)
    drill.apply_transform(tilt)
    block = trimesh.boolean.difference([box((8, 8, 4), (-4, -4, -2)), drill], engine="manifold")
    pin = trimesh.creation.cylinder(1.0, 8, sections=48)
    pin.apply_transform(tilt)
    assembly = Assembly([Part("block", block), Part("pin", pin)])
    axes = fit_axes(assembly, assembly.tolerance(None))
    axis = np.array([0.0, -0.5, np.sqrt(3) / 2])
    expected = np.vstack([np.eye(3), axis, -np.eye(3), -axis])
    assert len(axes) == len(expected)
    for direction in expected:
        assert np.abs(axes @ direction).max() == pytest.approx(1.0, abs=1e-9)
        assert (axes @ direction).max() == pytest.approx(1.0, abs=1e-9)
