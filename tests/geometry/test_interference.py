"""Interference by manifold3d volumes: touching is not interfering."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from assemblykit.geometry.interference import (
    enclosures,
    interference_threshold,
    interferences,
    interferes,
    overlap_volume,
    part_solid,
    solid,
)
from assemblykit.geometry.overlaps import mesh_of
from assemblykit.model.assembly import Assembly, Part
from assemblykit.tolerance import Tolerance


def box(lo, hi) -> trimesh.Trimesh:
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return trimesh.creation.box(
        extents=hi - lo, transform=trimesh.transformations.translation_matrix((lo + hi) / 2)
    )


def test_a_part_solid_is_made_once_and_follows_a_replaced_part():
    asm = Assembly([Part("a", box([0, 0, 0], [2, 2, 2])), Part("b", box([2, 0, 0], [3, 1, 1]))])
    assert part_solid(asm, "a") is part_solid(asm, "a")
    assert part_solid(asm, "a").volume() == pytest.approx(8.0)
    # the sub-assembly keeps the same part, so the same solid
    assert part_solid(asm.subset(["a"]), "a") is part_solid(asm, "a")
    # a part replaced by another mesh under its name gets that mesh's solid
    moved = asm.with_part(Part("a", box([1, 0, 0], [3, 2, 2])))
    assert part_solid(moved, "a").bounding_box() == pytest.approx((1, 0, 0, 3, 2, 2))
    # (the replaced part comes last)
    assert interferences(moved, Tolerance()) == [("b", "a", pytest.approx(1.0))]
    assert interferences(asm, Tolerance()) == []


def test_overlap_volume_of_boxes_is_exact():
    assert overlap_volume(box([0, 0, 0], [2, 2, 2]), box([1, 1, 1], [3, 3, 3])) == pytest.approx(
        1.0, abs=1e-12
    )
    assert overlap_volume(box([0, 0, 0], [1, 1, 1]), box([0, 0, 1], [1, 1, 2])) == pytest.approx(
        0.0, abs=1e-12
    )


def test_touching_is_not_interfering_but_a_sunken_box_is():
    tol = Tolerance(rel_length=1e-6)
    base = box([0, 0, 0], [1, 1, 1])
    assert not interferes(base, box([0, 0, 1], [1, 1, 2]), tol)
    assert interferes(base, box([0, 0, 0.9], [1, 1, 1.9]), tol)
    assert not interferes(base, box([5, 5, 5], [6, 6, 6]), tol)


def test_threshold_is_tolerance_times_the_smaller_area():
    tol = Tolerance(rel_length=1e-3)
    assert interference_threshold(
        box([0, 0, 0], [1, 1, 1]), box([0, 0, 0], [2, 2, 2]), tol
    ) == pytest.approx(6e-3)


def test_interferences_of_an_assembly_report_the_volume():
    asm = Assembly(
        [
            Part("a", box([0, 0, 0], [1, 1, 1])),
            Part("b", box([0, 0, 1], [1, 1, 2])),
            Part("c", box([0.5, 0, 1.5], [1.5, 1, 2.5])),
        ]
    )
    found = interferences(asm)
    assert [(a, b) for a, b, _ in found] == [("b", "c")]
    assert found[0][2] == pytest.approx(0.25, abs=1e-12)


def test_a_part_in_a_cavity_is_enclosed_and_one_in_an_open_cup_is_not():
    """A 20 cube with a 16 cube cavity (one mesh of two shells, the inner one facing
    into the cavity) holds a 4 cube at its centre: all of its 64 lies in the cavity,
    so it is enclosed. A cube above the housing is not, nor a cube in a cup whose
    cavity opens through its top."""
    housing = mesh_of(solid(box([0, 0, 0], [20, 20, 20])) - solid(box([2, 2, 2], [18, 18, 18])))
    assert housing.body_count == 2 and housing.volume == pytest.approx(20**3 - 16**3)
    cup = mesh_of(solid(box([30, 0, 0], [50, 20, 20])) - solid(box([32, 2, 2], [48, 18, 21])))
    asm = Assembly(
        [
            Part("housing", housing),
            Part("ball", box([8, 8, 8], [12, 12, 12])),
            Part("above", box([0, 0, 25], [4, 4, 29])),
            Part("cup", cup),
            Part("cube", box([38, 8, 8], [42, 12, 12])),
        ]
    )
    assert enclosures(asm) == [("ball", "housing")]
    assert enclosures(asm, ["housing", "above", "cup", "cube"]) == []
