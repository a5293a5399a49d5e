"""Step one: candidate mating pairs, their relative positions, node consistency, layers."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest

from assemblykit.algebra import EmptySet, Kind, se3
from assemblykit.features import Hole, Plane, Shaft, Thread
from assemblykit.io.problem import load_problem, parse_problem
from assemblykit.mating.graph import (
    RARITY,
    build_graph,
    goal_candidates,
    matable,
    pair_coset,
    pairings,
    up_to_symmetry,
)
from assemblykit.mating.problem import MatingProblem
from assemblykit.tolerance import Tolerance

TOL = Tolerance()


@pytest.fixture(scope="module")
def example1(mating_examples: Path) -> MatingProblem:
    return load_problem(mating_examples / "example1.yaml")


def test_matable_primitives() -> None:
    up = Plane((0, 0, 0), (0, 0, 1))
    shaft = Shaft((0, 0, 0), (0, 0, 1), 2.0)
    assert matable(up, Plane((1, 2, 3), (1, 0, 0)), TOL) == "against"
    assert matable(shaft, Hole((5, 0, 0), (0, 0, -1), 2.0), TOL) == "fits"
    assert matable(shaft, Hole((5, 0, 0), (0, 0, -1), 1.0), TOL) is None
    assert matable(shaft, Shaft((5, 0, 0), (0, 0, 1), 2.0), TOL) is None
    assert matable(up, shaft, TOL) is None


def test_one_pairing_for_plane_and_two_unequal_pegs(example1: MatingProblem) -> None:
    b1, b4 = example1.bodies["b1"], example1.bodies["b4"]
    found = list(pairings(b1.compounds["comp1"].features, b4.compounds["comp13"].features, TOL))
    assert found == [((0, 0, "against"), (1, 1, "fits"), (2, 2, "fits"))]


def test_relative_position_is_the_single_seat(example1: MatingProblem) -> None:
    b1, b4 = example1.bodies["b1"], example1.bodies["b4"]
    first, second = b1.compounds["comp1"].features, b4.compounds["comp13"].features
    coset = pair_coset(first, second, next(pairings(first, second, TOL)), TOL)
    # b1's bottom face (z = -1) lies on b4's top (z = 0), its pegs in the holes at x = 15, 25.
    assert coset.kind is Kind.FIXED and coset.is_point
    np.testing.assert_allclose(coset.rep, se3.translation((20, 0, 1)), atol=1e-12)
    # Through the other face: b1 is turned over (half-turn about y).
    flipped = pair_coset(
        b1.compounds["comp2"].features,
        second,
        next(pairings(b1.compounds["comp2"].features, second, TOL)),
        TOL,
    )
    expected = se3.translation((20, 0, 1)) @ se3.rotation((0, 1, 0), np.pi)
    np.testing.assert_allclose(flipped.rep, expected, atol=1e-12)


def test_an_empty_later_pair_makes_the_pairing_empty() -> None:
    # Thread leads 3 tol apart: the same surface for matable (pitches lead/2π are within
    # tol), but fits needs equal leads, so the second pair's coset is empty.
    lead = 1.0
    first = [Plane((0, 0, 0), (0, 0, 1)), Thread((0, 0, 0), (0, 0, 1), 5.0, lead, male=True)]
    second = [
        Plane((0, 0, 0), (0, 0, -1)),
        Thread((0, 0, 0), (0, 0, 1), 5.0, lead + 3 * TOL.length, male=False),
    ]
    (pairing,) = pairings(first, second, TOL)
    assert pairing == ((0, 0, "against"), (1, 1, "fits"))
    empty = pair_coset(first, second, pairing, TOL)
    assert isinstance(empty, EmptySet) and empty.proven
    assert empty.mismatch.kind == "pitch"
    assert empty.mismatch.value == pytest.approx(3 * TOL.length)


def test_candidates_of_goal_1(example1: MatingProblem) -> None:
    found = goal_candidates(example1, example1.goals[0], {})
    assert sorted((c.first, c.second) for c in found) == sorted(
        (a, b) for a in ("comp1", "comp2") for b in ("comp1", "comp12", "comp13")
    )
    assert all(c.determined for c in found)
    first = next(c for c in found if (c.first, c.second) == ("comp1", "comp1"))
    assert first.pairing == (("bottom", "top"), ("peg_a", "h8"), ("peg_b", "h9"))
    # Planes are sharable: only the pegs and holes are claimed.
    assert first.uses == {("b1", "peg_a"), ("b1", "peg_b"), ("b4", "h8"), ("b4", "h9")}
    assert first.priority == RARITY[Shaft] == 2
    assert first.describe() == "[fit [b1 comp1] [b4 comp1]]"


def test_node_consistency_rejects_the_interfering_seats(example1: MatingProblem) -> None:
    graph = build_graph(example1)
    assert {g: len(d) for g, d in graph.initial.items()} == {1: 6, 2: 6, 3: 3}
    assert {g: sorted({c.second for c in d}) for g, d in graph.domains.items()} == {
        1: ["comp1", "comp13"],
        2: ["comp1", "comp13"],
        3: ["comp12"],
    }
    assert graph.top.number_of_nodes() == 4 + 3
    assert graph.top.number_of_edges() == 6
    assert graph.bottom.number_of_nodes() == 2 + 2 + 1 + 3
    assert graph.bottom.number_of_edges() == 4 + 4 + 1
    edge = graph.bottom.get_edge_data(("b3", "comp1"), ("b4", "comp12"))[0]
    assert edge["goal"] == 3 and edge["group"].kind is Kind.FIXED


TRIANGLE = {
    "bodies": {
        "base": {
            "features": {
                "top": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]},
                "slot": {
                    "type": "prism",
                    "point": [0, 0, 0],
                    "axis": [0, 0, -1],
                    "sides": 3,
                    "size": 2,
                    "male": False,
                },
            },
            "compound": {"seat": ["top", "slot"]},
            "symmetry": "none",
        },
        "peg": {
            "features": {
                "face": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, -1]},
                "key": {"type": "prism", "point": [0, 0, 0], "axis": [0, 0, -1], "sides": 3,
                        "size": 2},
            },
            "compound": {"plug": ["face", "key"]},
            # A 48-sided cylinder: the third-turns of the features map it onto itself.
            "mesh": {"add": [{"cylinder": {"point": [0, 0, 0], "axis": [0, 0, 1],
                                           "radius": 1, "height": 2}}]},
        },
    },
    "goals": [["fit", "peg", "base"]],
}  # fmt: skip


def test_common_group_equal_to_body_symmetry_determines_the_position() -> None:
    problem = parse_problem(TRIANGLE)
    peg = problem.bodies["peg"]
    assert len(peg.symmetry.reps) == 3
    (candidate,) = build_graph(problem).initial[1]
    # The common group C3 is the peg's own group: one position, the peg at the origin.
    assert candidate.determined
    np.testing.assert_allclose(candidate.coset.rep, np.eye(4), atol=1e-12)
    assert up_to_symmetry(
        pair_coset(
            peg.compounds["plug"].features,
            problem.bodies["base"].compounds["seat"].features,
            ((0, 0, "against"), (1, 1, "fits")),
            problem.tolerance,
        ),
        peg,
        problem.bodies["base"],
        problem.tolerance,
    )
    # Without the peg's symmetry the three third-turns are three candidates.
    plain = copy.deepcopy(TRIANGLE)
    plain["bodies"]["peg"]["symmetry"] = "none"
    assert len(build_graph(parse_problem(plain)).initial[1]) == 3


def test_node_consistency_up_to_symmetry_checks_interference() -> None:
    walled = copy.deepcopy(TRIANGLE)
    walled["bodies"]["base"]["mesh"] = {
        "add": [
            {"box": {"min": [-5, -5, -2], "max": [5, 5, 0]}},
            {"box": {"min": [0.5, -0.2, 0], "max": [3, 0.2, 3]}},
        ]
    }
    graph = build_graph(parse_problem(walled))
    assert len(graph.initial[1]) == 1 and graph.domains[1] == ()
    clear = copy.deepcopy(walled)
    clear["bodies"]["base"]["mesh"]["add"].pop(1)
    assert len(build_graph(parse_problem(clear)).domains[1]) == 1
