"""Settling: the gradient of a shared volume and the least translations closing layers."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from assemblykit.geometry import settling
from assemblykit.geometry.interference import overlap_volume, solid
from assemblykit.geometry.settling import (
    cut_to_meeting,
    layer_thickness,
    overlap_gradient,
    settle,
)


def cylinder(offset=(0.0, 0.0, 0.0), sections=400) -> trimesh.Trimesh:
    """A finely tessellated cylinder of radius 0.5 and height 1 (1,600 triangles)."""
    mesh = trimesh.creation.cylinder(radius=0.5, height=1.0, sections=sections)
    mesh.apply_translation(offset)
    return mesh


def cube(offset=(0.0, 0.0, 0.0), extents=(1.0, 1.0, 1.0)) -> trimesh.Trimesh:
    mesh = trimesh.creation.box(extents=extents)
    mesh.apply_translation(offset)
    return mesh


def test_gradient_is_the_area_vector_of_the_moving_boundary_inside_the_other():
    # b overlaps a in the slab 0.49 <= x <= 0.5, -0.2 <= y <= 0.5: a's +x face inside b
    # has area 0.7, its +y face a strip of 0.01 x 1
    a = solid(cube()).as_original()
    b = solid(cube((0.99, 0.3, 0.0))).as_original()
    volume, gradient = overlap_gradient(a, b, a.original_id())
    assert volume == pytest.approx(0.007)
    np.testing.assert_allclose(gradient, [0.7, 0.01, 0.0], atol=1e-12)
    # translation invariance: the other part's gradient is the opposite
    _, other = overlap_gradient(b, a, b.original_id())
    np.testing.assert_allclose(other, -gradient, atol=1e-12)
    # touching only: nothing shared, nothing to move
    c = solid(cube((1.0, 0.0, 0.0))).as_original()
    assert overlap_gradient(a, c, a.original_id()) == (0.0, pytest.approx(np.zeros(3)))


@settings(max_examples=25, deadline=None)
@given(depth=st.floats(1e-6, 0.2), axis=st.integers(0, 2))
def test_a_flat_layer_is_as_thick_as_it_is_deep(depth, axis):
    # two unit cubes overlapping by depth along one axis share a slab of volume depth,
    # whose area vector is the moving cube's face inside the other: length 1
    offset = np.zeros(3)
    offset[axis] = 1.0 - depth
    volume, thickness = layer_thickness(solid(cube()), solid(cube(offset)))
    assert volume == pytest.approx(depth, rel=1e-6)
    assert thickness == pytest.approx(depth, rel=1e-6)


def test_a_part_enclosed_all_round_has_a_layer_of_no_finite_thickness():
    # a small cube inside a large one: moving it any way shares as much, no gradient
    volume, thickness = layer_thickness(solid(cube(extents=(0.2, 0.2, 0.2))), solid(cube()))
    assert volume == pytest.approx(0.008)
    assert thickness == np.inf
    assert layer_thickness(solid(cube()), solid(cube((2.0, 0.0, 0.0)))) == (0.0, 0.0)


def test_a_layer_is_closed_by_moving_each_part_half_its_thickness():
    result = settle([cube(), cube((0.0, 0.0, 0.99))], [(0, 1)])
    assert result.before == pytest.approx((0.01,))
    assert result.after[0] <= 1e-12
    np.testing.assert_allclose(result.shifts, [[0, 0, -0.005], [0, 0, 0.005]], atol=1e-9)
    assert result.largest == pytest.approx(0.005)


def test_a_stack_is_closed_by_the_least_norm_translations():
    # three cubes with layers 0.02 (bottom/middle) and 0.01 (middle/top)
    meshes = [cube(), cube((0.0, 0.0, 0.98)), cube((0.0, 0.0, 1.97))]
    result = settle(meshes, [(0, 1), (1, 2)])
    assert max(result.after) <= 1e-12
    gaps = np.diff(result.shifts[:, 2])
    np.testing.assert_allclose(gaps, [0.02, 0.01], atol=1e-9)
    # least norm: no common translation, z shifts -0.01 - 0.01/3 ... summing to zero
    np.testing.assert_allclose(result.shifts.sum(axis=0), 0.0, atol=1e-9)
    np.testing.assert_allclose(result.shifts[:, 2], [-1 / 60 - 0.0, 1 / 300, 2 / 150], atol=1e-9)


def test_parts_that_share_nothing_stay():
    result = settle([cube(), cube((2.0, 0.0, 0.0))], [(0, 1)])
    assert result.before == (0.0,)
    assert result.largest == 0.0


@settings(max_examples=25, deadline=None)
@given(
    depth=st.floats(1e-4, 0.05),
    side=st.floats(-0.3, 0.3),
    axis=st.integers(0, 2),
)
def test_settled_cubes_share_no_volume_and_move_about_the_layer(depth, side, axis):
    offset = np.zeros(3)
    offset[axis] = 1.0 - depth
    offset[(axis + 1) % 3] = side
    meshes = [cube(), cube(offset)]
    result = settle(meshes, [(0, 1)])
    moved = [m.copy().apply_translation(s) for m, s in zip(meshes, result.shifts, strict=True)]
    assert overlap_volume(*moved) <= 1e-9 * depth
    relative = result.shifts[1] - result.shifts[0]
    assert relative[axis] == pytest.approx(depth, rel=1e-6)
    # the strip of the side face inside the other cube tilts the step a little
    assert np.linalg.norm(relative) <= depth * (1 + depth / (1 - abs(side))) * (1 + 1e-9)


@settings(max_examples=20, deadline=None)
@given(
    shift=st.tuples(*[st.floats(-0.99, 0.99)] * 3),
    depth=st.floats(1e-4, 0.05),
)
def test_cut_solids_share_what_the_whole_ones_share_within_the_margin(shift, depth):
    # two cylinders end to end overlapping by depth, the second also shifted by less
    # than the margin in each coordinate: the cut pair's shared volume and gradient are
    # the whole pair's, measured by booleans of the whole solids
    a = solid(cylinder()).as_original()
    b = solid(cylinder((0.2, 0.1, 1.0 - depth))).as_original()
    cut_a, cut_b, margin = cut_to_meeting(a, b)
    assert cut_a.num_tri() < a.num_tri() and cut_b.num_tri() < b.num_tri()
    d = tuple(margin * np.asarray(shift))
    whole_volume, whole_gradient = overlap_gradient(a, b.translate(d), a.original_id())
    cut_volume, cut_gradient = overlap_gradient(cut_a, cut_b.translate(d), a.original_id())
    assert cut_volume == pytest.approx(whole_volume, rel=1e-9, abs=1e-15)
    np.testing.assert_allclose(cut_gradient, whole_gradient, rtol=1e-9, atol=1e-12)


def test_small_pairs_are_not_cut():
    a, b = solid(cube()), solid(cube((0.5, 0.0, 0.0)))
    assert cut_to_meeting(a, b)[2] == np.inf


def test_settling_cut_pairs_moves_parts_as_settling_whole_ones(monkeypatch):
    # a tilted layer between tessellated cylinders: the shifts found on the cut pairs
    # are those found on the whole pairs (no cut below a huge triangle count)
    meshes = [cylinder(), cylinder((0.3, 0.0, 0.995))]
    meshes[1].apply_transform(trimesh.transformations.rotation_matrix(0.002, [1, 0, 0]))
    cut = settle(meshes, [(0, 1)])
    monkeypatch.setattr(settling, "CUT_TRIANGLES", 10**9)
    whole = settle(meshes, [(0, 1)])
    assert whole.before[0] > 1e-4
    np.testing.assert_allclose(cut.shifts, whole.shifts, rtol=0, atol=1e-12)
    moved = [m.copy().apply_translation(s) for m, s in zip(meshes, cut.shifts, strict=True)]
    assert overlap_volume(*moved) <= 1e-3 * whole.before[0]
