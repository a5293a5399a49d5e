"""The input's measured precision: float coordinates, faces out of plane, rounded poses,
block joints."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh

from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.geometry.precision import (
    combined,
    coordinate_precision,
    decimals,
    joint_mismatch,
    mesh_precision,
    pose_precision,
    round_up,
    surface_warp,
)
from assemblykit.model.assembly import Assembly, Part, Precision
from assemblykit.planning.planner import plan
from plan_checks import assert_steps_clear

UNIT_BOX = trimesh.creation.box(extents=[1, 1, 1])


def box(lo, hi) -> trimesh.Trimesh:
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return trimesh.creation.box(
        extents=hi - lo, transform=trimesh.transformations.translation_matrix((lo + hi) / 2)
    )


def tilted_block(rise: float) -> trimesh.Trimesh:
    """A unit block above z = 1 whose bottom face rises by ``rise`` from x = 0 to x = 1
    (hinged along the edge x = 0, z = 1)."""
    corners = []
    for x in (0.0, 1.0):
        for y in (0.0, 1.0):
            corners += [(x, y, 1 + rise * x), (x, y, 2.0)]
    return trimesh.convex.convex_hull(np.array(corners))


def test_round_up_keeps_two_significant_digits_and_never_rounds_down():
    assert round_up(0.0286178) == pytest.approx(0.029, rel=1e-12)
    assert round_up(1.0678e-4) == pytest.approx(1.1e-4, rel=1e-12)
    assert round_up(0.0) == 0.0
    assert round_up(0.0286178) >= 0.0286178


def test_decimals_of_written_numbers():
    assert [decimals(v) for v in (3.8152, 12.245, 1.570796, 0.0, 7.0, 1e-5)] == [4, 3, 6, 0, 0, 5]


def test_coordinates_exact_in_float32_have_float32_precision():
    assert coordinate_precision(np.array([[0.5, -2.0, 1.0]])) == Precision(
        2.0**-22 / 2,
        "float32 coordinates",  # spacing at 2.0, the largest
    )
    assert coordinate_precision(np.array([[0.1, 0.0, 1.0]])) == Precision(
        2.0**-52 / 2, "float64 coordinates"
    )


def jittered(mesh: trimesh.Trimesh, amplitude: float, seed: int) -> trimesh.Trimesh:
    """``mesh`` with its faces split (so that flat faces have inner vertices) and every
    vertex moved by up to ``amplitude`` along each axis."""
    fine = mesh.subdivide().subdivide()
    rng = np.random.default_rng(seed)
    moved = fine.vertices + rng.uniform(-amplitude, amplitude, fine.vertices.shape)
    return trimesh.Trimesh(moved, fine.faces, process=False)


def test_exact_flat_faces_and_curved_surfaces_are_not_warped():
    assert surface_warp(box([0, 0, 0], [3, 2, 1]).subdivide()) == 0.0
    # a curved surface turns by more than the flat angle over its extent, however fine
    assert surface_warp(trimesh.creation.icosphere(6)) == 0.0
    assert surface_warp(trimesh.creation.cylinder(1.0, 5.0, sections=2000)) < 1e-15
    assert mesh_precision(UNIT_BOX) == coordinate_precision(UNIT_BOX.vertices)


def test_a_face_with_one_corner_lifted_is_warped_by_a_quarter_of_the_lift():
    # by hand: the top's two triangles meet along a diagonal; lifting the corner of one by
    # h tilts it by the gradient (h, h), its mean plane by (h/2, h/2) (equal areas).
    # Above that plane the four corners stand at 0, -h/2, -h/2 and 0: a spread of h/2,
    # a warp of h/4, a precision of twice that
    h = 1e-5
    top = UNIT_BOX.copy()
    corner = np.flatnonzero(np.all(top.vertices == [0.5, 0.5, 0.5], axis=1))
    top.vertices[corner] += [0.0, 0.0, h]
    assert surface_warp(top) == pytest.approx(h / 4, rel=1e-3)
    measured = mesh_precision(top)
    assert measured.length == pytest.approx(h / 2, rel=0.03)
    assert "out of plane" in measured.source


def test_jittered_meshes_touch_and_come_apart_as_exact_ones():
    """A lid on a base, every vertex jittered by up to 1e-6 of the model's size: their
    faces cross by up to twice that, beyond the policy's 1e-6, and the lid would be held
    by interference; measured, the warp makes them a contact, the lid lifts off along +Z,
    and the step is clear of the base in an independent sweep."""
    size = math.sqrt(10**2 + 10**2 + 4**2)
    amplitude = 1e-6 * size
    base = jittered(box([0, 0, 0], [10, 10, 3]), amplitude, 1)
    lid = jittered(box([0, 0, 3], [10, 10, 4]), amplitude, 2)
    measured = combined([mesh_precision(base), mesh_precision(lid)])
    assert measured is not None and amplitude <= measured.length <= 4 * amplitude
    parts = [Part("base", base), Part("lid", lid)]
    noisy = Assembly(parts, precision=measured)
    assert noisy.tolerance().length == measured.length
    result = plan(noisy)
    assert result.feasible and [step.parts for step in result.steps] == [("lid",)]
    np.testing.assert_allclose(result.steps[0].direction, [0, 0, 1], atol=1e-3)
    assert_steps_clear(noisy, result)
    # a real misfit, the lid sunk by 1e-3 of the model, stays one
    sunk = Assembly([parts[0], Part("lid", lid.copy().apply_translation([0, 0, -1e-3 * size]))])
    assert not plan(sunk, max_and_or_parts=0).feasible


def test_pose_rounding_bound_is_hand_computed():
    found = pose_precision([[1.25, 0, 3, 0, 0, 0.5]], radius=2.0)
    assert found is not None
    assert found.length == pytest.approx(math.sqrt(3) * (0.005 + 2.0 * 0.05), rel=1e-12)
    assert "2 decimals" in found.source
    assert pose_precision([[0, 0, 1, 0, 0, 0]], radius=2.0) is None


def test_combined_is_the_coarsest():
    fine, coarse = Precision(1e-9, "fine"), Precision(1e-3, "coarse")
    assert combined([fine, coarse]) == coarse
    assert combined([]) is None


def test_a_tilted_joint_measures_its_mismatch_and_becomes_a_contact():
    asm = Assembly([Part("low", box([0, 0, 0], [1, 1, 1])), Part("high", tilted_block(0.01))])
    measured = joint_mismatch(asm)
    # the lower top face is 0.01 / sqrt(1.0001) from the tilted plane, rounded up: 0.01
    assert measured.length == pytest.approx(0.01, rel=1e-12)
    assert "1 block pairs" in measured.source
    asm.precision = measured
    (contact,) = assembly_contacts(asm)
    assert contact.pair == ("low", "high")
    assert contact.area == pytest.approx(1.0, rel=1e-9)
    assert assembly_contacts(Assembly(asm.parts)) == []


@pytest.mark.parametrize("lifted", [0.001, -0.5])
def test_a_gap_or_a_sunk_block_is_not_a_joint(lifted):
    asm = Assembly(
        [Part("low", box([0, 0, 0], [1, 1, 1])), Part("high", box([0, 0, 1 + lifted], [1, 1, 2]))]
    )
    assert joint_mismatch(asm) == Precision(0.0, "no block joints")
