"""Interference by manifold3d volumes: touching is not interfering."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from assemblykit.geometry.interference import (
    interference_threshold,
    interferences,
    interferes,
    overlap_volume,
)
from assemblykit.model.assembly import Assembly, Part
from assemblykit.tolerance import Tolerance


def box(lo, hi) -> trimesh.Trimesh:
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return trimesh.creation.box(
        extents=hi - lo, transform=trimesh.transformations.translation_matrix((lo + hi) / 2)
    )


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
