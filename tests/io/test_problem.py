"""Mating problem files: validation with field paths, explicit symmetry, tolerance scale."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from assemblykit.algebra import se3
from assemblykit.errors import InputError, SchemaError, UnknownNameError
from assemblykit.io.problem import load_problem, parse_problem

PEG = {
    "features": {
        "face": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, -1]},
        "stem": {"type": "shaft", "point": [0, 0, 0], "axis": [0, 0, -1], "radius": 1},
    },
    "compound": {"plug": ["face", "stem"]},
}


def _problem(**changes: object) -> dict:
    data = {"bodies": {"a": PEG, "b": PEG}, "goals": [["fit", "a", "b"]]}
    data.update(changes)
    return data


def test_example1_is_read_with_compounds_goals_and_symmetry(mating_examples: Path) -> None:
    problem = load_problem(mating_examples / "example1.yaml")
    assert list(problem.bodies) == ["b1", "b2", "b3", "b4"]
    assert [g.describe() for g in problem.goals] == [
        "goal 1 [fit b1 b4]",
        "goal 2 [fit b2 b4]",
        "goal 3 [fit b3 b4]",
    ]
    b1 = problem.bodies["b1"]
    assert b1.members["comp2"] == ("top", "peg_c", "peg_d")
    # The half-turn about the y axis swaps the two faces of b1 (and keeps its mesh).
    assert len(b1.symmetry.reps) == 2
    assert b1.symmetry.contains(se3.rotation((0, 1, 0), math.pi))
    assert len(problem.bodies["b3"].symmetry.reps) == 1
    assert problem.bodies["b4"].sharable == frozenset({"top"})
    assert problem.units == "mm"


def test_explicit_and_disabled_symmetry() -> None:
    quarter = [{"axis": [0, 0, 1], "angle": "90 deg"}]
    body = {**PEG, "symmetry": quarter}
    problem = parse_problem(_problem(bodies={"a": body, "b": {**PEG, "symmetry": "none"}}))
    assert len(problem.bodies["a"].symmetry.reps) == 4
    assert len(problem.bodies["b"].symmetry.reps) == 1


def test_default_compounds_are_the_primitives() -> None:
    body = {"features": PEG["features"]}
    problem = parse_problem(_problem(bodies={"a": body, "b": PEG}))
    assert list(problem.bodies["a"].compounds) == ["face", "stem"]


@pytest.mark.parametrize(
    ("data", "error", "message"),
    [
        ({"bodies": {"a": PEG}}, SchemaError, "missing field 'goals'"),
        (_problem(goals=[["fit", "a", "c"]]), UnknownNameError, "goals[0][2]: no body named 'c'"),
        (_problem(goals=[["fits", "a", "b"]]), SchemaError, "goals[0][0]"),
        (_problem(goals=[["fit", "a", "a"]]), SchemaError, "goals[0]: a goal relates two"),
        (
            _problem(bodies={"a": {**PEG, "compound": {"plug": ["face", "tip"]}}, "b": PEG}),
            UnknownNameError,
            "bodies.a.compound.plug[1]: no feature named 'tip'",
        ),
        (
            _problem(bodies={"a": {**PEG, "sharable": ["rim"]}, "b": PEG}),
            UnknownNameError,
            "bodies.a.sharable[0]",
        ),
        (
            _problem(bodies={"a": {**PEG, "mesh": {"add": [{}]}}, "b": PEG}),
            SchemaError,
            "bodies.a.mesh",
        ),
        (
            _problem(bodies={"a": {"features": {"f": {"type": "plane"}}}, "b": PEG}),
            SchemaError,
            "bodies.a.features.f: a plane needs normal, point",
        ),
    ],
)
def test_errors_name_the_file_and_field(data: dict, error: type, message: str) -> None:
    with pytest.raises(error) as caught:
        parse_problem(data, "p.yaml")
    assert str(caught.value).startswith("p.yaml: ")
    assert message in str(caught.value)


def test_missing_mesh_file_and_bad_suffix(tmp_path: Path) -> None:
    path = tmp_path / "p.yaml"
    path.write_text(
        "bodies:\n  a: {features: {f: {type: point, point: [0, 0, 0]}}, mesh: gone.obj}\n"
        "  b: {features: {f: {type: point, point: [0, 0, 0]}}}\ngoals: [[fit, a, b]]\n"
    )
    with pytest.raises(InputError, match=r"p\.yaml: bodies\.a\.mesh \(gone\.obj\)"):
        load_problem(path)
    other = tmp_path / "p.txt"
    other.write_text("x")
    with pytest.raises(InputError, match="unknown problem file type"):
        load_problem(other)


def test_tolerance_is_scaled_to_the_model(mating_examples: Path) -> None:
    problem = load_problem(mating_examples / "example1.yaml")
    # Bounding box of features and meshes: [-32, 32] x [-12, 12] x [-6, 4].
    assert problem.tolerance.scale == pytest.approx(float(np.linalg.norm([64, 24, 10])))


def test_public_loader_and_bad_primitive_place() -> None:
    import assemblykit
    from assemblykit.io import problem as module

    assert assemblykit.load_problem is module.load_problem
    flat = {"add": [{"box": {"min": [0, 0, 0], "max": [1, 0, 1]}}]}
    with pytest.raises(SchemaError, match=r"p\.yaml: bodies\.a\.mesh: a box needs max > min"):
        parse_problem(_problem(bodies={"a": {**PEG, "mesh": flat}, "b": PEG}), "p.yaml")
