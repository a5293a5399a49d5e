"""The input's measured precision: float coordinates, rounded poses, block joints."""

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
    pose_precision,
    round_up,
)
from assemblykit.model.assembly import Assembly, Part, Precision

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
