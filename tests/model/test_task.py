"""The task model: validation of names and references, equality, and solving."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from assemblykit.errors import FeatureError, SchemaError, UnknownNameError
from assemblykit.features import Ball, Frame, Hole, Plane, Shaft
from assemblykit.inference import solve_task
from assemblykit.model.body import Body
from assemblykit.model.relations import FeatureRef, Relation
from assemblykit.model.task import Action, Situation, Task, axis_of


def bodies() -> dict[str, Body]:
    return {
        "table": Body("table", {"top": Plane((0, 0, 0), (0, 0, 1), name="top")}, fixed=True),
        "block": Body(
            "block",
            {
                "bottom": Plane((0, 0, 0), (0, 0, -1), name="bottom"),
                "bore": Hole((0, 0, 5), (0, 0, -1), 2, name="bore"),
                "knob": Ball((0, 0, 9), 1, name="knob"),
                "datum": Frame(np.eye(4), name="datum"),
            },
        ),
        "peg": Body("peg", {"shaft": Shaft((0, 0, 0), (0, 0, -1), 2, name="shaft")}),
    }


def ref(text: str) -> FeatureRef:
    return FeatureRef.parse(text)


S1 = Situation(
    "s1",
    (
        Relation("against", (ref("block.bottom"), ref("table.top")), {}, "rel A"),
        Relation("fits", (ref("peg.shaft"), ref("block.bore")), {}, "rel B"),
    ),
)


def task(*later: Situation, first: Situation = S1) -> Task:
    return Task("mm", bodies(), (first, *later), "t.yaml")


def test_a_good_task_validates_to_itself():
    good = task(Situation("s2", (), (Action("move", "block", ref("block.bore"), None, 3.0),)))
    assert good.validate() is good and good.validate() is good
    assert good.feature(ref("block.bore"), "x").radius == 2.0


def test_a_bad_task_is_refused_each_time_it_is_checked():
    bad = Situation("s1", (Relation("fits", (ref("pin.shaft"), ref("block.bore")), {}, None),))
    unchecked = Task("mm", bodies(), (bad,), "t.yaml")
    for _ in range(2):
        with pytest.raises(UnknownNameError, match="unknown body 'pin'"):
            unchecked.validate()


def test_equality_ignores_file_names_and_places():
    moved = Situation("s2", (), (Action("move", "peg", ref("peg.shaft"), None, 1.0, "line 3"),))
    other = Situation("s2", (), (Action("move", "peg", ref("peg.shaft"), None, 1.0, "a[0]"),))
    first = Task("mm", bodies(), (S1, moved), "a.rapt")
    second = Task("mm", bodies(), (S1, other), None)
    assert first == second
    assert first != Task("cm", bodies(), (S1, moved))
    shorter = Situation("s2", (), (Action("move", "peg", ref("peg.shaft"), None, 2.0),))
    assert first != Task("mm", bodies(), (S1, shorter))


def test_equality_compares_numbers_within_the_tolerance():
    near = bodies()
    near["peg"] = Body("peg", {"shaft": Shaft((0, 0, 1e-13), (0, 0, -1), 2, name="shaft")})
    far = bodies()
    far["peg"] = Body("peg", {"shaft": Shaft((0, 0, 1e-4), (0, 0, -1), 2, name="shaft")})
    assert Task("mm", near, (S1,)) == task()
    assert Task("mm", far, (S1,)) != task()


def test_axis_of_features():
    b = bodies()["block"].features
    np.testing.assert_array_equal(axis_of(b["bore"]), [0, 0, -1])
    np.testing.assert_array_equal(axis_of(b["bottom"]), [0, 0, -1])
    assert axis_of(b["knob"]) is None
    assert axis_of(b["datum"]) is None


def fails(error: type[Exception], make: Callable[[], Task]) -> str:
    with pytest.raises(error) as caught:
        make().validate()
    assert type(caught.value) is error
    return str(caught.value)


def action(*items: Action) -> Situation:
    return Situation("s2", (), items)


def test_reference_errors_name_the_file_and_the_relation():
    bad = Situation("s1", (Relation("fits", (ref("peg.shaft"), ref("block.hole")), {}, "rel C"),))
    assert fails(UnknownNameError, lambda: task(first=bad)) == (
        "t.yaml: rel C: body 'block' has no feature 'hole' (features: bottom, bore, knob, datum)"
    )
    bad = Situation("s1", (Relation("fits", (ref("pin.shaft"), ref("block.bore")), {}, None),))
    assert fails(UnknownNameError, lambda: task(first=bad)) == (
        "t.yaml: situations[0].relations[0]: unknown body 'pin' (bodies: table, block, peg)"
    )


def test_feature_types_are_checked():
    bad = Situation("s1", (Relation("against", (ref("peg.shaft"), ref("table.top")), {}, "r"),))
    message = fails(FeatureError, lambda: task(first=bad))
    assert message == "t.yaml: r: against cannot relate the shaft 'shaft' and the plane 'top'"
    bad = Situation("s1", (Relation("against", (ref("block.bottom"),), {}, "r"),))
    assert (
        fails(SchemaError, lambda: task(first=bad))
        == "t.yaml: r: against relates 2 features, got 1"
    )
    bad = Situation("s1", (Relation("glued", (ref("block.bottom"), ref("table.top")), {}, "r"),))
    assert fails(SchemaError, lambda: task(first=bad)).startswith(
        "t.yaml: r: unknown relation 'glued'"
    )


def test_action_errors():
    cases = [
        (UnknownNameError, Action("move", "pin"), "unknown body 'pin' (bodies: table, block, peg)"),
        (SchemaError, Action("move", "table"), "the fixed body 'table' cannot move"),
        (SchemaError, Action("turn", "peg"), "'turn' needs a feature to turn about"),
        (SchemaError, Action("move", "peg", by=2.0), "'move' needs a feature to move along"),
        (
            SchemaError,
            Action("move", "peg", about=ref("peg.shaft")),
            "'move' does not take 'about'",
        ),
        (
            SchemaError,
            Action("turn", "peg", along=ref("peg.shaft")),
            "'turn' does not take 'along'",
        ),
        (
            FeatureError,
            Action("move", "peg", along=ref("block.bore")),
            "move 'peg' relative to block.bore: the feature must belong to the moved body",
        ),
        (
            FeatureError,
            Action("turn", "block", about=ref("block.knob"), by=1.0),
            "cannot turn about block.knob: a ball has no axis",
        ),
        (
            FeatureError,
            Action("move", "block", along=ref("block.datum")),
            "cannot move along block.datum: a frame has no axis",
        ),
    ]
    for error, act, message in cases:
        assert fails(error, lambda act=act: task(action(act))) == (
            f"t.yaml: situations[1].actions[0]: {message}"
        )


def test_situation_level_errors():
    twice = action(Action("move", "peg"), Action("move", "peg", where="line 9"))
    assert fails(SchemaError, lambda: task(twice)) == (
        "t.yaml: line 9: body 'peg' is moved twice into situation 's2'"
    )
    early = Situation("s1", S1.relations, (Action("move", "peg"),))
    assert fails(SchemaError, lambda: task(first=early)) == (
        "t.yaml: situations[0]: the first situation cannot have actions "
        "(no situation comes before it)"
    )
    assert fails(SchemaError, lambda: task(Situation("s1"))) == (
        "t.yaml: situations[1]: duplicate situation name 's1'"
    )
    assert fails(SchemaError, lambda: Task("mm", bodies(), (), "t.yaml")) == (
        "t.yaml: a task needs at least one situation"
    )
    renamed = bodies()
    renamed["other"] = renamed.pop("peg")
    assert fails(SchemaError, lambda: Task("mm", renamed, (Situation("s1"),), "t.yaml")) == (
        "t.yaml: bodies.other: body 'peg' is listed under the name 'other'"
    )


def test_solve_runs_the_inference_engine():
    solution = solve_task(task())
    assert solution.status == "underconstrained"
    assert solution.bodies["block@s1"].motion == "planar"
    assert solution.bodies["peg@s1"].dof == 4
