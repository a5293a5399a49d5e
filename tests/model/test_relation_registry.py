"""A relation kind is one class registered in one table (docs/algebra.md §5.1): a kind defined
here, outside the package, is read from a task file and solved like the built-in ones."""

from __future__ import annotations

from collections.abc import Iterator, Mapping

import numpy as np
import pytest
import yaml

from assemblykit.algebra import Coset, EmptySet, SymmetryGroup, se3
from assemblykit.errors import AssemblyKitError
from assemblykit.features import Feature, Frame
from assemblykit.inference import solve_task
from assemblykit.io.spec import parse_task
from assemblykit.model.relations import (
    RELATIONS,
    RelationType,
    Residual,
    register_relation,
    relation_dof_removed,
    unregister_relation,
)
from assemblykit.tolerance import Tolerance


class Slides(RelationType):
    """Two datum frames aligned up to a slide along the second's z axis:
    T(z₁)·F₁F₂⁻¹ (a prismatic pair); 5 dof removed."""

    kind = "slides"
    accepts = frozenset({("frame", "frame")})
    is_coset = True
    dof = 5

    def coset(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Coset | EmptySet:
        f1, f2 = second.frame(), first.frame()
        return Coset(SymmetryGroup.prismatic(f1[:3, 2]), f1 @ se3.inverse(f2))

    def residual(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Residual:
        f1, f2 = second.frame(), first.frame()
        axis = f1[:3, 2]

        def residual(x: np.ndarray) -> np.ndarray:
            moved = x @ f2
            offset = moved[:3, 3] - f1[:3, 3]
            turn = (moved[:3, :3] - f1[:3, :3]).ravel() * tol.arm
            return np.concatenate([turn, offset - (offset @ axis) * axis])

        return residual


TASK = """
units: mm
bodies:
  rail:
    fixed: true
    features:
      track: {type: frame, matrix: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 1], [0, 0, 0, 1]]}
      stop: {type: plane, point: [0, 0, 5], normal: [0, 0, -1]}
  carriage:
    features:
      runner: {type: frame, matrix: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}
      face: {type: plane, point: [0, 0, 0], normal: [0, 0, 1]}
situations:
  - name: s1
    relations:
      - [slides, carriage.runner, rail.track]
  - name: s2
    actions:
      - [move, carriage]
    relations:
      - [slides, carriage.runner, rail.track]
      - [against, carriage.face, rail.stop]
"""


@pytest.fixture
def slides() -> Iterator[type[Slides]]:
    register_relation(Slides)
    try:
        yield Slides
    finally:
        unregister_relation(Slides.kind)


def test_a_registered_kind_loads_and_solves(slides: type[Slides]) -> None:
    solution = solve_task(parse_task(yaml.safe_load(TASK)))
    # s1: the runner's frame on the track's, free to slide along its z axis.
    free = solution["carriage@s1"]
    assert (free.motion, free.dof) == ("prismatic", 1)
    np.testing.assert_allclose(free.invariants["direction"], [0, 0, 1], atol=1e-12)
    # s2: the face against the stop at z = 5 holds it there.
    held = solution["carriage@s2"]
    assert (held.motion, held.dof) == ("fixed", 0)
    np.testing.assert_allclose(held.pose, se3.translation((0.0, 0.0, 5.0)), atol=1e-9)
    assert solution.status == "underconstrained"


def test_a_kind_is_registered_once(slides: type[Slides]) -> None:
    assert isinstance(RELATIONS["slides"], Slides)
    assert relation_dof_removed("slides", Frame(np.eye(4)), Frame(np.eye(4))) == 5
    with pytest.raises(AssemblyKitError, match="already registered"):
        register_relation(Slides)


def test_an_unregistered_kind_is_unknown() -> None:
    assert "slides" not in RELATIONS
    with pytest.raises(AssemblyKitError, match="unknown relation 'slides'"):
        parse_task(yaml.safe_load(TASK))
