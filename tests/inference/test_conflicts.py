"""A conflict names every statement that takes part and nothing else (docs/inference.md,
"Conflicts"): relations, the ``fixed`` placement of another body, the link that keeps a
body no action moves in place, and actions.

Each expected set is worked out by hand in the test's docstring. The deletion checks
edit the task here, apart from the solver: leaving out a relation deletes it; leaving
out an action or a body's staying in place makes it a free ``move``. Leaving out any
named statement makes the task consistent or changes the conflict; leaving out every
statement not named keeps the same conflict. The poses of an inconsistent task are those
of the task without the named statements, and are said to be."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from assemblykit.inference import solve_task
from assemblykit.inference.network import action_label, relation_label, stationary_label
from assemblykit.io.tasks import load_task
from assemblykit.model.task import Action, ActionKind, Task

TASKS = Path(__file__).parent / "tasks"
EXACT = 1e-9


def named(task: Task) -> dict[str, tuple[int, str, int | str]]:
    """Every statement of the task by the name a conflict gives it: (situation, what,
    which)."""
    fixed = {b for b, body in task.bodies.items() if body.fixed}
    out: dict[str, tuple[int, str, int | str]] = {}
    for i, situation in enumerate(task.situations):
        for k, relation in enumerate(situation.relations):
            out[relation_label(relation, situation.name)] = (i, "relation", k)
        for k, action in enumerate(situation.actions):
            out[action_label(action, situation.name)] = (i, "action", k)
        moved = {a.body for a in situation.actions}
        for body in task.bodies if i else ():
            if body not in fixed and body not in moved:
                out[stationary_label(body, situation.name)] = (i, "stationary", body)
    return out


def leave_out(task: Task, labels: set[str]) -> Task:
    """The task without the statements ``labels``."""
    where = named(task)
    gone = {where[label] for label in labels}
    situations = []
    for i, situation in enumerate(task.situations):
        relations = tuple(
            r for k, r in enumerate(situation.relations) if (i, "relation", k) not in gone
        )
        actions = [
            Action(ActionKind.MOVE, a.body) if (i, "action", k) in gone else a
            for k, a in enumerate(situation.actions)
        ]
        actions += [
            Action(ActionKind.MOVE, str(b))
            for (j, what, b) in gone
            if j == i and what == "stationary"
        ]
        situations.append(replace(situation, relations=relations, actions=tuple(actions)))
    return replace(task, situations=tuple(situations))


def conflict_of(task: Task) -> tuple[str, float, tuple[str, ...]] | None:
    """The task's one conflict (kind, size, statements named), None when consistent."""
    conflicts = solve_task(task).conflicts
    assert len(conflicts) <= 1
    return (
        None if not conflicts else (conflicts[0].kind, conflicts[0].value, conflicts[0].relations)
    )


def same(a, b) -> bool:
    return (
        a is not None
        and b is not None
        and a[0] == b[0]
        and a[2] == b[2]
        and math.isclose(a[1], b[1], abs_tol=EXACT)
    )


def check_deletions(task: Task) -> tuple[str, float, tuple[str, ...]]:
    """The conflict of ``task``, after checking it is sufficient and minimal."""
    found = conflict_of(task)
    assert found is not None
    for label in found[2]:
        assert not same(conflict_of(leave_out(task, {label})), found), label
    others = set(named(task)) - set(found[2])
    assert same(conflict_of(leave_out(task, others)), found)
    return found


def line(task: Task, text: str) -> str:
    """The full name of the one statement whose name starts with ``text``."""
    (found,) = [label for label in named(task) if label.startswith(text)]
    return found


def test_a_fixed_placement_of_another_body_is_named():
    """By hand: the bracket is fixed 12 along x, so its post is 12 from the pin; the
    plate's holes are 10 apart: distance 2 between the axes of the two fits. The
    bracket's fixed takes part (without it the bracket could go anywhere); the plate's
    seat does not (both axes are along its normal)."""
    task = load_task(TASKS / "bracket_fixed_off_its_place.rapt")
    kind, value, names = check_deletions(task)
    assert (kind, value) == ("distance", pytest.approx(2.0, abs=EXACT))
    assert names == (
        line(task, "fixed bracket.seat world.dock @s1"),
        line(task, "fits plate.h1 world.pin @s1"),
        line(task, "fits plate.h2 bracket.post @s1"),
    )
    message = solve_task(task).conflicts[0].message
    assert "between axes" in message and "point" not in message


def test_a_body_left_in_place_between_situations_is_named():
    """By hand: the block sits on the table (z = 0) in s1 and stays there into s2, where
    it should sit on the shelf (z = 5): distance 5 between the planes. The walls only
    hold it in its corner and the cup is another body: neither takes part."""
    task = load_task(TASKS / "block_left_on_the_table.rapt")
    kind, value, names = check_deletions(task)
    assert (kind, value) == ("distance", pytest.approx(5.0, abs=EXACT))
    assert names == (
        line(task, "against block.bottom table.top @s1"),
        line(task, "against block.bottom table.shelf @s2"),
        "stationary block @s2",
    )
    assert "between planes" in solve_task(task).conflicts[0].message


def test_a_move_is_named_as_a_relation():
    """By hand: the plate seated on the table (z = 0) is lifted 30 along its hole's axis
    into s2, where it should sit on the table again: distance 30 between the planes. The
    pins leave the lift along their axes free: they take no part."""
    task = load_task(TASKS / "plate_lifted_on_the_table.rapt")
    kind, value, names = check_deletions(task)
    assert (kind, value) == ("distance", pytest.approx(30.0, abs=EXACT))
    assert names == (
        line(task, "against plate.bottom table.top @stacked"),
        line(task, "move plate plate.hole_1 by 30 @lifted"),
        line(task, "against plate.bottom table.top @lifted"),
    )


def test_a_turn_is_named_as_a_relation():
    """By hand: the second hole on its pin (20, 0) in s1, the plate turned 90° about its
    first hole's axis carries that hole to 20·(-1, 1) from the pin, whatever the plate
    did on the pin: distance 20·√2 between the axes. Neither the first pin nor the seat
    takes part."""
    task = load_task(TASKS / "plate_turned_off_its_pin.yaml")
    kind, value, names = check_deletions(task)
    assert (kind, value) == ("distance", pytest.approx(20 * math.sqrt(2), abs=EXACT))
    assert names == (
        line(task, "fits plate.hole_2 table.pin_2 @s1"),
        line(task, "turn plate plate.hole_1 by 90 deg @s2"),
        line(task, "fits plate.hole_2 table.pin_2 @s2"),
    )


def test_poses_of_an_inconsistent_task_hold_only_without_the_named_statements():
    """The block's poses are those of the task without the three statements: in s1 the
    walls leave it a slide along z, in s2 nothing holds it."""
    task = load_task(TASKS / "block_left_on_the_table.rapt")
    out = solve_task(task).to_dict()
    (conflict,) = out["conflicts"]
    assert out["valid_without"] == conflict["relations"]
    alone = solve_task(leave_out(task, set(conflict["relations"]))).to_dict()
    assert alone["conflicts"] == []
    for key, body in out["bodies"].items():
        np.testing.assert_allclose(body["pose"], alone["bodies"][key]["pose"], atol=EXACT)
        assert (body["dof"], body["motion"]) == (
            alone["bodies"][key]["dof"],
            alone["bodies"][key]["motion"],
        )
    assert (out["bodies"]["block@s1"]["motion"], out["bodies"]["block@s2"]["dof"]) == (
        "prismatic",
        6,
    )
