"""Mating problem values: body symmetry from features and mesh, compounds, model size."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from assemblykit.algebra import se3
from assemblykit.features import Plane, Shaft
from assemblykit.features.compound import compound_group
from assemblykit.geometry.solids import Box, generated_mesh
from assemblykit.io.problem import load_problem
from assemblykit.mating.problem import body_symmetry, mating_body, preserves, problem_diagonal
from assemblykit.tolerance import Tolerance

TOL = Tolerance(10.0)
FEATURES = {
    "face": Plane((0, 0, 0), (0, 0, -1)),
    "left": Shaft((-2, 0, 0), (0, 0, -1), 1.0),
    "right": Shaft((2, 0, 0), (0, 0, -1), 1.0),
}


def test_feature_symmetry_not_kept_by_the_mesh_is_dropped(mating_examples: Path) -> None:
    b3 = load_problem(mating_examples / "example2.yaml").bodies["b3"]
    # The two equal pins are swapped by a half-turn, but the wall on one side is not.
    assert len(compound_group(tuple(b3.features.values())).reps) == 2
    assert len(b3.symmetry.reps) == 1


def test_body_symmetry_from_features_mesh_or_generators() -> None:
    half = se3.rotation((0, 0, 1), math.pi)
    assert len(body_symmetry(FEATURES, None, tol=TOL).reps) == 2
    centred = generated_mesh([Box((-3, -1, 0), (3, 1, 1))])
    assert len(body_symmetry(FEATURES, centred, tol=TOL).reps) == 2
    offset = generated_mesh([Box((-3, -1, 0), (4, 1, 1))])
    assert preserves(centred, half, TOL) and not preserves(offset, half, TOL)
    assert len(body_symmetry(FEATURES, offset, tol=TOL).reps) == 1
    assert len(body_symmetry(FEATURES, None, [], TOL).reps) == 1
    quarter = se3.rotation((0, 0, 1), math.pi / 2)
    assert len(body_symmetry(FEATURES, None, [quarter], TOL).reps) == 4


def test_mating_body_defaults_and_sharable_planes() -> None:
    body = mating_body("a", FEATURES, {}, None, body_symmetry(FEATURES, None, [], TOL), ["left"])
    assert body.members == {"face": ("face",), "left": ("left",), "right": ("right",)}
    assert body.sharable == {"face", "left"}
    grouped = mating_body("a", FEATURES, {"plug": ["face", "right"]}, None, body.symmetry)
    assert grouped.compounds["plug"].features == (FEATURES["face"], FEATURES["right"])


def test_problem_diagonal() -> None:
    mesh = generated_mesh([Box((0, 0, 0), (3, 4, 12))])
    assert problem_diagonal({"a": FEATURES}, {"a": mesh}) == pytest.approx(
        float(np.linalg.norm([5, 4, 12]))
    )
    assert problem_diagonal({"a": {"p": FEATURES["face"]}}, {"a": None}) == 1.0
