"""The Solution value and its JSON form (docs/tutorial.md, "JSON")."""

from __future__ import annotations

import json

import numpy as np
import pytest
from rich.console import Console

from assemblykit.inference.solution import (
    BodyInstanceResult,
    Conflict,
    Solution,
    TraceStep,
    freedom_words,
    remedy_words,
    status_of,
)
from assemblykit.render import render


def shift(x: float) -> np.ndarray:
    pose = np.eye(4)
    pose[0, 3] = x
    return pose


def instance(**changes) -> BodyInstanceResult:
    values = {"body": "b", "situation": "s1", "pose": np.eye(4), "dof": 0, "motion": "fixed"}
    values.update(changes)
    return BodyInstanceResult(**values)


def test_to_dict_has_exactly_the_documented_keys():
    peg = instance(
        body="peg",
        dof=1,
        motion="revolute",
        pose=shift(2),
        invariants={"point": np.array([2.0, 0, 0]), "direction": np.array([0, 0, 1.0])},
    )
    solution = Solution({peg.key: peg})
    data = solution.to_dict()
    assert set(data) == {"status", "bodies", "conflicts"}
    assert data["status"] == "underconstrained"
    body = data["bodies"]["peg@s1"]
    assert set(body) == {"pose", "dof", "motion", "solutions", "alternatives", "invariants"}
    assert body["pose"][0] == [1.0, 0.0, 0.0, 2.0]
    assert body["motion"] == "revolute"
    assert body["solutions"] == 1
    assert body["invariants"] == {"point": [2.0, 0.0, 0.0], "direction": [0.0, 0.0, 1.0]}
    json.dumps(data)


def test_lattice_reports_infinite_solutions():
    nut = instance(solutions=None)
    data = Solution({nut.key: nut}).to_dict()
    assert data["bodies"]["b@s1"]["solutions"] == "infinite"
    assert data["status"] == "underconstrained"


def test_alternatives_make_the_answer_ambiguous():
    peg = instance(solutions=2, alternatives=(shift(1),))
    data = Solution({peg.key: peg}).to_dict()
    assert data["status"] == "ambiguous"
    assert data["bodies"]["b@s1"]["alternatives"][0][0] == [1.0, 0.0, 0.0, 1.0]


def test_conflicts_make_the_answer_inconsistent():
    conflict = Conflict(("against a.f b.g @s1", "against a.h b.k @s1"), "angle", 0.1745, "10 deg")
    solution = Solution({"b@s1": instance()}, (conflict,))
    data = solution.to_dict()
    assert data["status"] == "inconsistent"
    assert data["conflicts"] == [
        {
            "relations": ["against a.f b.g @s1", "against a.h b.k @s1"],
            "kind": "angle",
            "value": 0.1745,
            "message": "10 deg",
            "needed_tolerance": None,
        }
    ]
    assert data["suggested_tolerance"] is None


@pytest.mark.parametrize(
    ("dofs", "counts", "expected"),
    [
        ((0, 0), (1, 1), "solved"),
        ((0, 1), (1, 1), "underconstrained"),
        ((0, 0), (1, 4), "ambiguous"),
    ],
)
def test_status_rules(dofs, counts, expected):
    bodies = {
        f"b{i}@s": instance(
            body=f"b{i}",
            situation="s",
            dof=d,
            solutions=n,
            motion="fixed" if d == 0 else "prismatic",
        )
        for i, (d, n) in enumerate(zip(dofs, counts, strict=True))
    }
    assert status_of(bodies, ()) == expected


def test_trace_only_when_explaining_and_render():
    step = TraceStep("intersect", "world -> b@s1 [against]", 3, 1, "T")
    plain = Solution({"b@s1": instance()}, (), (step,))
    assert "trace" not in plain.to_dict()
    explained = Solution({"b@s1": instance()}, (), (step,), explain=True)
    assert explained.to_dict()["trace"] == [
        {
            "rule": "intersect",
            "link": "world -> b@s1 [against]",
            "dof_before": 3,
            "dof_after": 1,
            "detail": "T",
        }
    ]
    console = Console(record=True, width=120)
    console.print(render(explained))
    text = console.export_text()
    assert "b@s1" in text and "solved" in text and "intersect" in text


def test_unknown_motion_is_rejected():
    with pytest.raises(ValueError, match="unknown motion"):
        instance(motion="wobbly")


def test_freedom_is_said_in_words_and_only_when_there_is_some():
    ball = instance(dof=3, motion="spherical", freedom="b@s1 can turn about (0.5, 1, 1.5): 3 dof")
    assert Solution({ball.key: ball}).to_dict()["bodies"]["b@s1"]["freedom"] == ball.freedom
    assert "freedom" not in Solution({"b@s1": instance()}).to_dict()["bodies"]["b@s1"]
    console = Console(width=200, record=True)
    console.print(render(Solution({ball.key: ball})))
    assert "b@s1 can turn about (0.5, 1, 1.5): 3 dof" in console.export_text()


@pytest.mark.parametrize(
    ("motion", "dof", "invariants", "expected"),
    [
        ("spherical", 3, {"center": [0.5, 1, 1.5]}, "can turn about (0.5, 1, 1.5): 3 dof"),
        (
            "revolute",
            1,
            {"point": [5, 0, 0], "direction": [0, 0, 1]},
            "can turn about the axis through (5, 0, 0) along +Z: 1 dof",
        ),
        ("prismatic", 1, {"direction": [0, -0.0, 1]}, "can slide along +Z: 1 dof"),
        ("fixed", 0, {}, ""),
        (
            "mechanism",
            2,
            {},
            "keeps 2 dof that no joint names (a closed loop, a chain of joints whose product is"
            " no group, or a relation no coset holds)",
        ),
    ],
)
def test_freedom_words(motion, dof, invariants, expected):
    assert freedom_words(motion, dof, invariants) == expected


@pytest.mark.parametrize(
    ("motion", "mechanism", "invariants", "expected"),
    [
        (
            "spherical",
            "",
            {"center": [0.5, 1, 1.5]},
            "a fits or coaxial through (0.5, 1, 1.5) (leaving a turn about that axis) and a"
            " stop off that axis would remove it",
        ),
        (
            "prismatic",
            "",
            {"direction": [0, 0, 1]},
            "a stop across +Z (an against or point_on_plane on a face not parallel to"
            " it) would remove it",
        ),
        (
            "mechanism",
            "planar-point-on-line",
            {"direction": [0, 1, 0], "normal": [0, 0, 1], "point": [4, 1, 0]},
            "a point_on_plane on the same point across +Y (making a revolute about"
            " +Z) and a stop off that axis would remove it",
        ),
        ("mechanism", "", {}, "a stop on it or on a body it moves with would remove one dof"),
    ],
)
def test_remedy_words_name_the_relations_that_remove_the_freedom(
    motion, mechanism, invariants, expected
):
    assert remedy_words(motion, mechanism, invariants) == expected
