"""Step three and the answer: seed 002 Examples 1-2, emptied domains, loci, sweeping."""

from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from assemblykit.algebra import Locus, se3
from assemblykit.io.problem import load_problem, parse_problem
from assemblykit.mating import search
from assemblykit.mating.graph import build_graph
from assemblykit.mating.laws import equivalent_features
from assemblykit.mating.loci import locus_meet
from assemblykit.mating.search import MatingResult, mate, solve_csp
from assemblykit.tolerance import Tolerance

TOL = Tolerance()


def _answer(result: MatingResult) -> set[frozenset[tuple[int, str, str, str, str]]]:
    return {
        frozenset(
            (c.goal.number, c.goal.first, c.first, c.goal.second, c.second) for c in config.pairs
        )
        for config in result.configurations
    }


@pytest.fixture(scope="module")
def example1(mating_examples: Path) -> MatingResult:
    return mate(load_problem(mating_examples / "example1.yaml"))


@pytest.fixture(scope="module")
def example2_data(mating_examples: Path) -> dict:
    return yaml.safe_load((mating_examples / "example2.yaml").read_text())


def test_example1_gives_the_seed_answer(example1: MatingResult) -> None:
    assert _answer(example1) == {
        frozenset({(1, "b1", "comp1", "b4", "comp13"), (2, "b2", "comp1", "b4", "comp1"),
                   (3, "b3", "comp1", "b4", "comp12")}),
        frozenset({(1, "b1", "comp1", "b4", "comp1"), (2, "b2", "comp1", "b4", "comp13"),
                   (3, "b3", "comp1", "b4", "comp12")}),
    }  # fmt: skip
    assert example1.count == 8
    assert [c.copies for c in example1.configurations] == [4, 4]
    assert dict(example1.statistics) == {
        1: (6, 4, 4, 2, 2, 2),
        2: (6, 4, 4, 2, 2, 2),
        3: (3, 1, 1, 1, 1, 1),
    }
    assert example1.emptied is None and example1.rejected == 0


def test_example1_poses(example1: MatingResult) -> None:
    config = next(c for c in example1.configurations if c.pairs[0].second == "comp1")
    np.testing.assert_allclose(config.poses["b4"], np.eye(4), atol=1e-12)
    np.testing.assert_allclose(config.poses["b1"], se3.translation((-20, 0, 1)), atol=1e-9)
    np.testing.assert_allclose(config.poses["b2"], se3.translation((20, 0, 1)), atol=1e-9)
    np.testing.assert_allclose(config.poses["b3"], se3.translation((0, 0, 1)), atol=1e-9)
    assert config.motions == {}


def test_example1_json_and_or_and(example1: MatingResult) -> None:
    data = example1.to_dict()
    assert data["count"] == 8 and data["representatives"] == 2 and data["status"] == "solved"
    assert data["configurations"][0]["pairs"][2] == {
        "goal": 3,
        "first": ["b3", "comp1"],
        "second": ["b4", "comp12"],
    }
    assert data["statistics"]["domains"]["3"] == [3, 1, 1, 1, 1, 1]
    assert data["emptied"] is None
    assert example1.or_and().startswith("** [Or [And [fit [b1 comp1] [b4 comp1]]")


def test_example2_gives_the_seed_answer_through_loci(example2_data: dict) -> None:
    result = mate(parse_problem(example2_data))
    assert _answer(result) == {
        frozenset({(1, "b3", "comp1", "b1", "comp2"), (2, "b3", "comp2", "b2", "comp2"),
                   (3, "b1", "comp1", "b2", "comp1")}),
        frozenset({(1, "b3", "comp2", "b1", "comp2"), (2, "b3", "comp1", "b2", "comp2"),
                   (3, "b1", "comp1", "b2", "comp1")}),
    }  # fmt: skip
    assert result.count == 2
    # b1 is fixed (first in the file); b3 turns about b1's bore, b2 closes the triangle.
    config = next(c for c in result.configurations if c.pairs[0].first == "comp2")
    np.testing.assert_allclose(config.poses["b1"], np.eye(4), atol=1e-12)
    apex = se3.apply(config.poses["b1"], np.array([10.0, 0, 2]))
    np.testing.assert_allclose(
        se3.apply(config.poses["b2"], np.array([10.0, 0, 2])), apex, atol=1e-9
    )
    pins = [se3.apply(config.poses["b3"], np.array(p)) for p in ([0.0, 0, 2], [10.0, 0, 2])]
    # The triangle is equilateral with side 10: every joint is 10 from the others.
    for a, b in ((pins[0], pins[1]), (pins[0], apex), (pins[1], apex)):
        assert np.linalg.norm(a[:2] - b[:2]) == pytest.approx(10.0, abs=1e-9)


def test_example2_without_the_wall_has_both_loci_points(example2_data: dict) -> None:
    data = copy.deepcopy(example2_data)
    data["bodies"]["b3"]["mesh"]["add"].pop(1)
    result = mate(parse_problem(data))
    assert result.count == 4 and len(_answer(result)) == 2


def test_no_solution_names_the_goal_and_law(mating_examples: Path) -> None:
    result = mate(load_problem(mating_examples / "one_socket.yaml"))
    assert result.configurations == () and result.count == 0
    assert (result.emptied.goal, result.emptied.law) == (2, "mandatory request")
    assert result.to_dict()["emptied"] == {"goal": 2, "law": "mandatory request"}


def test_node_consistency_can_empty_a_domain(mating_examples: Path) -> None:
    data = yaml.safe_load((mating_examples / "example1.yaml").read_text())
    # A wall beside comp12 on b3's side too: b3 now collides in every seat.
    data["bodies"]["b4"]["mesh"]["add"].append({"box": {"min": [-8, -10, 0], "max": [8, -6, 4]}})
    result = mate(parse_problem(data))
    assert (result.emptied.goal, result.emptied.law) == (3, "node consistency")
    assert result.statistics[3] == (3, 0, 0, 0, 0, 0)


def test_circle_loci_meet_in_two_one_or_no_points() -> None:
    z = np.array([0.0, 0, 1])
    a = Locus("circle", point=np.zeros(3), direction=z, radius=10.0)
    b = Locus("circle", point=np.array([10.0, 0, 0]), direction=z, radius=10.0)
    points = locus_meet(a, b, TOL)
    np.testing.assert_allclose(points, [[5, math.sqrt(75), 0], [5, -math.sqrt(75), 0]], atol=1e-12)
    touching = Locus("circle", point=np.array([20.0, 0, 0]), direction=z, radius=10.0)
    np.testing.assert_allclose(locus_meet(a, touching, TOL), [[10, 0, 0]], atol=1e-12)
    far = Locus("circle", point=np.array([30.0, 0, 0]), direction=z, radius=5.0)
    assert locus_meet(a, far, TOL) == []
    lifted = Locus("circle", point=np.array([10.0, 0, 1]), direction=z, radius=10.0)
    assert locus_meet(a, lifted, TOL) == []


HINGE = {
    "bodies": {
        "frame": {
            "features": {
                "top": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]},
                "bore": {"type": "hole", "point": [0, 0, 0], "axis": [0, 0, -1], "radius": 1},
            },
            "compound": {"seat": ["top", "bore"]},
            "mesh": {
                "add": [
                    {"box": {"min": [-5, -5, -2], "max": [5, 5, 0]}},
                    {"box": {"min": [3, -1, 0], "max": [5, 1, 3]}},
                ],
                "cut": [
                    {"cylinder": {"point": [0, 0, -3], "axis": [0, 0, 1], "radius": 1, "height": 4}}
                ],
            },
        },
        "door": {
            "features": {
                "face": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, -1]},
                "pin": {"type": "shaft", "point": [0, 0, 0], "axis": [0, 0, -1], "radius": 1},
            },
            "compound": {"hinge": ["face", "pin"]},
            "mesh": {
                "add": [
                    {"box": {"min": [-1, -1, 0], "max": [8, 1, 1]}},
                    {
                        "cylinder": {
                            "point": [0, 0, 0],
                            "axis": [0, 0, -1],
                            "radius": 0.9,
                            "height": 1.5,
                        }
                    },
                ]
            },
        },
    },
    "goals": [["fit", "door", "frame"]],
}


def test_sweep_reports_the_range_of_motion_of_a_hinge() -> None:
    result = mate(parse_problem(HINGE))
    (config,) = result.configurations
    motion = config.motions["door"]
    assert (motion.kind, motion.parameter) == ("revolute", "angle")
    # The arm (half-width 1) clears the stop's corner (3, 1) beyond 2 atan(1/3); the
    # touching threshold of the interference policy allows a sliver of about 0.01 rad.
    (interval,) = motion.intervals
    limit = 2 * math.atan(1 / 3)
    assert interval == pytest.approx((limit, 2 * math.pi - limit), abs=0.02)
    assert interval[0] <= limit + 1e-9
    assert result.to_dict()["configurations"][0]["motions"]["door"]["motion"] == "revolute"


def test_sweep_rejects_a_body_with_no_free_position() -> None:
    data = copy.deepcopy(HINGE)
    data["bodies"]["frame"]["mesh"]["add"].append({"box": {"min": [-9, -9, 0], "max": [9, 9, 3]}})
    data["bodies"]["frame"]["mesh"]["cut"].append(
        {"box": {"min": [-1.5, -1.5, 0], "max": [1.5, 1.5, 4]}}
    )
    result = mate(parse_problem(data))
    assert result.configurations == () and result.rejected == 1


def test_cp_sat_finds_the_same_assignments(
    mating_examples: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pytest.importorskip("ortools")
    problem = load_problem(mating_examples / "example1.yaml")
    domains = equivalent_features(problem, build_graph(problem).domains)
    small = solve_csp(domains)
    monkeypatch.setattr(search, "SMALL_SEARCH", 0)
    large = solve_csp(domains)
    key = [{g: (c.first, c.second) for g, c in a.items()} for a in small]
    assert key == [{g: (c.first, c.second) for g, c in a.items()} for a in large]
    assert len(key) == 2
