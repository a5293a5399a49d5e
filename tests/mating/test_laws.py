"""Step two: mandatory request, equivalent features (orbits), arc and path consistency."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from assemblykit.algebra import Coset, SymmetryGroup, se3
from assemblykit.io.problem import load_problem
from assemblykit.mating.graph import Candidate, build_graph
from assemblykit.mating.laws import (
    arc_consistency,
    compatible,
    compound_orbits,
    equivalent_features,
    mandatory_request,
    path_consistency,
)
from assemblykit.mating.problem import Goal, MatingProblem

GOALS = {n: Goal(n, "fit", f"p{n}", "base") for n in (1, 2, 3)}


def _pair(goal: int, name: str, *uses: str) -> Candidate:
    return Candidate(
        GOALS[goal],
        name,
        "seat",
        (),
        Coset(SymmetryGroup.identity(), np.eye(4)),
        frozenset(("base", u) for u in uses),
        0,
    )


def _names(domains: dict) -> dict:
    return {g: [c.first for c in d] for g, d in domains.items()}


@pytest.fixture(scope="module")
def example1(mating_examples: Path) -> MatingProblem:
    return load_problem(mating_examples / "example1.yaml")


def test_compatible_unless_a_non_sharable_feature_is_shared() -> None:
    assert compatible(_pair(1, "a", "x"), _pair(2, "b", "y"))
    assert not compatible(_pair(1, "a", "x", "y"), _pair(2, "b", "y"))


def test_mandatory_request_propagates_until_quiescent() -> None:
    domains = {
        1: (_pair(1, "a", "x"),),
        2: (_pair(2, "b", "x"), _pair(2, "c", "y")),
        3: (_pair(3, "d", "y"), _pair(3, "e", "z")),
    }
    assert _names(mandatory_request(domains)) == {1: ["a"], 2: ["c"], 3: ["e"]}


def test_mandatory_request_can_empty_a_domain() -> None:
    domains = {1: (_pair(1, "a", "x"),), 2: (_pair(2, "b", "x"),)}
    assert _names(mandatory_request(domains)) == {1: ["a"], 2: []}


def test_arc_consistency_removes_unsupported_values() -> None:
    domains = {
        1: (_pair(1, "a", "x"), _pair(1, "b", "y")),
        2: (_pair(2, "c", "x"), _pair(2, "d", "y")),
        3: (_pair(3, "e", "x", "y"),),
    }
    # e claims x and y: no value of goal 1 is compatible with it, then nothing is left.
    assert _names(arc_consistency(domains)) == {1: [], 2: [], 3: []}
    kept = {1: (_pair(1, "a", "x"), _pair(1, "b", "y")), 2: (_pair(2, "c", "x"),)}
    assert _names(arc_consistency(kept)) == {1: ["b"], 2: ["c"]}


def test_orbits_of_compound_features(example1: MatingProblem) -> None:
    tol = example1.tolerance
    assert compound_orbits(example1.bodies["b1"], tol) == {"comp1": "comp1", "comp2": "comp1"}
    b4 = compound_orbits(example1.bodies["b4"], tol)
    assert b4 == {"comp1": "comp1", "comp12": "comp12", "comp13": "comp13"}


def test_equivalent_feature_law_keeps_one_per_orbit_with_copies(example1: MatingProblem) -> None:
    domains = equivalent_features(example1, build_graph(example1).domains)
    for goal in (1, 2):
        assert [(c.first, c.second, c.copies) for c in domains[goal]] == [
            ("comp1", "comp1", 2),
            ("comp1", "comp13", 2),
        ]
    assert [(c.first, c.second, c.copies) for c in domains[3]] == [("comp1", "comp12", 1)]


def test_equivalent_feature_law_spares_bodies_in_several_goals(mating_examples: Path) -> None:
    problem = load_problem(mating_examples / "example2.yaml")
    symmetric = {**problem.bodies}
    b3 = problem.bodies["b3"]
    # The half-turn about the vertical line through (5, 0) swaps the pins (mesh ignored).
    half_turn = SymmetryGroup.identity().extended_by([se3.rotation((0, 0, 1), np.pi, (5, 0, 0))])
    symmetric["b3"] = type(b3)(
        b3.name, b3.features, b3.compounds, b3.members, None, half_turn, b3.sharable
    )
    swapped = type(problem)(problem.units, symmetric, problem.goals, None, problem.tolerance)
    assert compound_orbits(symmetric["b3"], problem.tolerance) == {
        "comp1": "comp1",
        "comp2": "comp1",
    }
    domains = build_graph(swapped).domains
    assert _names(equivalent_features(swapped, domains)) == _names(domains)


def test_path_consistency_prunes_where_arc_consistency_cannot() -> None:
    # Three pegs, two holes x, y: every value has a partner in every other goal (AC keeps
    # all), but no pair of two goals leaves a hole for the third.
    domains = {g: (_pair(g, "a", "x"), _pair(g, "b", "y")) for g in (1, 2, 3)}
    assert _names(arc_consistency(domains)) == _names(domains)
    result = path_consistency(domains, tuple(GOALS.values()))
    assert _names(result.domains) == {1: [], 2: [], 3: []}
    # Compatible pairs: (a, b) and (b, a) for each of the three pairs of goals.
    assert result.pairs_removed == 6


def test_path_consistency_keeps_the_supported_values() -> None:
    domains = {
        1: (_pair(1, "a", "x"), _pair(1, "b", "z")),
        2: (_pair(2, "c", "x"), _pair(2, "d", "y")),
        3: (_pair(3, "e", "x"), _pair(3, "f", "y")),
    }
    assert _names(arc_consistency(domains)) == _names(domains)
    result = path_consistency(domains, tuple(GOALS.values()))
    # a (hole x) leaves only y for goals 2 and 3 together: a goes; (a, d) and (a, f) go.
    assert _names(result.domains) == {1: ["b"], 2: ["c", "d"], 3: ["e", "f"]}
    assert result.pairs_removed == 2


def test_path_consistency_ignores_goals_without_a_common_body() -> None:
    apart = (GOALS[1], Goal(2, "fit", "p2", "other"))
    domains = {1: (_pair(1, "a", "x"),), 2: (_pair(2, "b", "x"),)}
    result = path_consistency(domains, apart)
    assert _names(result.domains) == {1: ["a"], 2: ["b"]} and result.pairs_removed == 0
