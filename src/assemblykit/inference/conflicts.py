"""The statements a conflict names: every one that takes part, and nothing else
(docs/inference.md, "Conflicts").

A statement is a relation, an action (RAPT treats actions exactly as relations: Corner
et al. 1983 §III B) or the implicit link that keeps a body no action moves in place. The
reduction records what each conflict was derived from (its relations and, through every
merge of their instances, the ``fixed`` relations, actions and places kept that merged
them: :attr:`Conflict.support`). That set is narrowed by deletion: each statement in turn
is left out of a task made of the set alone, and stays out when the same conflict (kind
and size) remains; the rounds repeat until one leaves nothing out. What is left is
sufficient (the task of those statements alone has the conflict) and minimal (leaving
out any one of them removes or changes it).

The poses of an inconsistent task are those of the task without the conflicts'
statements (and without those of any conflict that then remains): valid only without
them, and said so (:attr:`Solution.valid_without`).

Leaving out a relation deletes it; leaving out an action, or the link that keeps a body
in place, lets the body move freely into that situation (``move b``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Iterable
from dataclasses import dataclass, replace

from assemblykit.errors import AssemblyKitError
from assemblykit.inference.network import action_label, relation_label, stationary_label
from assemblykit.inference.solution import Conflict, Solution
from assemblykit.model.task import Action, ActionKind, Situation, Task
from assemblykit.tolerance import LENGTH_MISMATCHES, ModelTolerance

Solver = Callable[[Task, bool], Solution]
"""Solves a task (the reduction of Corner et al. 1983 §III, without this module), with
the residue solver or (``False``) without it."""

MAX_CANDIDATES = 64
"""The most statements narrowed one by one (each left out in turn costs a solve of the
others). A conflict derived from more is named by all of them, which have it alone; when
those do not, every statement of the task is a candidate, up to this many."""


@dataclass(frozen=True, order=True)
class Statement:
    """One statement of a task: situation ``index``, ``kind`` (``"relation"``,
    ``"action"`` or ``"stationary"``) and ``item`` (the relation's or action's position in
    the situation, or the body kept in place)."""

    index: int
    kind: str
    item: int | str


def statements(task: Task) -> dict[str, tuple[Statement, ...]]:
    """Every statement of ``task`` by its label (the name conflicts give it). Statements
    sort in the order they are written: by situation, its actions (which lead into it)
    before its relations, then the bodies it keeps in place. Identical statements share
    a label and are left out together."""
    fixed = {name for name, body in task.bodies.items() if body.fixed}
    found: dict[str, list[Statement]] = {}
    for index, situation in enumerate(task.situations):
        for number, relation in enumerate(situation.relations):
            label = relation_label(relation, situation.name)
            found.setdefault(label, []).append(Statement(index, "relation", number))
        if index == 0:
            continue
        for number, action in enumerate(situation.actions):
            if action.ref is not None:
                label = action_label(action, situation.name)
                found.setdefault(label, []).append(Statement(index, "action", number))
        moved = {action.body for action in situation.actions}
        for body in task.bodies:
            if body not in fixed and body not in moved:
                label = stationary_label(body, situation.name)
                found.setdefault(label, []).append(Statement(index, "stationary", body))
    return {label: tuple(items) for label, items in found.items()}


def _situation_keeping(situation: Situation, index: int, kept: Collection[Statement]) -> Situation:
    """``situation`` with only the statements ``kept``: the other relations deleted, the
    other actions and kept places made free moves."""
    relations = tuple(
        r for n, r in enumerate(situation.relations) if Statement(index, "relation", n) in kept
    )
    actions = [
        a
        if a.ref is None or Statement(index, "action", n) in kept
        else Action(ActionKind.MOVE, a.body, where=a.where)
        for n, a in enumerate(situation.actions)
    ]
    return Situation(situation.name, relations, tuple(actions))


def keeping(task: Task, kept: Collection[Statement]) -> Task:
    """The task of the statements ``kept`` alone (module docstring: what leaving out a
    statement means)."""
    situations = []
    for index, situation in enumerate(task.situations):
        narrowed = _situation_keeping(situation, index, kept)
        if index > 0:
            moved = {a.body for a in narrowed.actions}
            free = tuple(
                Action(ActionKind.MOVE, body)
                for body, declared in task.bodies.items()
                if not declared.fixed
                and body not in moved
                and Statement(index, "stationary", body) not in kept
            )
            narrowed = replace(narrowed, actions=narrowed.actions + free)
        situations.append(narrowed)
    return replace(task, situations=tuple(situations))


def _referenced(task: Task, kept: Collection[Statement]) -> Task:
    """``task`` with only its fixed bodies and those the statements ``kept`` name (the
    others would only be free instances, alone in their components)."""
    names = {name for name, body in task.bodies.items() if body.fixed}
    for statement in kept:
        situation = task.situations[statement.index]
        if statement.kind == "relation":
            relation = situation.relations[int(statement.item)]
            names.update(ref.body for ref in relation.refs)
        elif statement.kind == "action":
            action = situation.actions[int(statement.item)]
            names.add(action.body)
        else:
            names.add(str(statement.item))
    narrowed = keeping(task, kept)
    situations = tuple(
        replace(s, actions=tuple(a for a in s.actions if a.body in names))
        for s in narrowed.situations
    )
    bodies = {name: body for name, body in task.bodies.items() if name in names}
    return replace(narrowed, bodies=bodies, situations=situations)


def _same(found: Conflict, wanted: Conflict, tol: ModelTolerance) -> bool:
    """Whether ``found`` is the conflict ``wanted``: the same kind and size (a residual
    found numerically by its kind alone)."""
    if found.kind != wanted.kind:
        return False
    if found.kind == "residual":
        return True
    limit = tol.length if found.kind in LENGTH_MISMATCHES else tol.angle
    return math.isclose(found.value, wanted.value, rel_tol=1e-6, abs_tol=limit)


def _reproduced(
    task: Task, kept: Collection[Statement], wanted: Conflict, solve: Solver, tol: ModelTolerance
) -> Conflict | None:
    """The conflict ``wanted`` as the task of ``kept`` alone has it, or None. Only a
    conflict found numerically needs the residue solver to be found again."""
    try:
        solution = solve(_referenced(task, kept), wanted.kind == "residual")
    except AssemblyKitError:  # a coupled relation left without its carrier
        return None
    return next((c for c in solution.conflicts if _same(c, wanted, tol)), None)


def _expand(labels: Iterable[str], table: dict[str, tuple[Statement, ...]]) -> list[Statement]:
    """The statements of ``labels`` (unknown labels name nothing), in written order."""
    return sorted({s for label in labels for s in table.get(label, ())})


def narrow(
    task: Task,
    conflict: Conflict,
    solve: Solver,
    tol: ModelTolerance,
    table: dict[str, tuple[Statement, ...]],
) -> Conflict:
    """``conflict`` naming the fewest statements that still have it (module docstring):
    the conflict as the task of those statements alone finds it, its relations their
    labels in written order. Unchanged when no candidate set reproduces it. A conflict
    the residue solver found (no solution found numerically, no proof) is not narrowed:
    it names every statement it was derived from."""
    labels = {s: label for label, items in table.items() for s in items}
    candidates = _expand(conflict.support or conflict.relations, table)
    found = _reproduced(task, candidates, conflict, solve, tol)
    if found is None and conflict.kind == "residual":
        derived = tuple(dict.fromkeys(labels[s] for s in candidates))
        return replace(conflict, relations=derived or conflict.relations, support=())
    if found is None:
        everything = sorted(labels)
        if len(everything) > MAX_CANDIDATES:
            return replace(conflict, support=())
        candidates = everything
        found = _reproduced(task, candidates, conflict, solve, tol)
        if found is None:
            return replace(conflict, support=())
    narrowing = (
        conflict.kind != "residual" and len({labels[s] for s in candidates}) <= MAX_CANDIDATES
    )
    while narrowing:
        narrowing = False
        for label in dict.fromkeys(labels[s] for s in candidates):
            trial = [s for s in candidates if labels[s] != label]
            again = _reproduced(task, trial, conflict, solve, tol)
            if again is not None:
                candidates, found, narrowing = trial, again, True
    named = tuple(dict.fromkeys(labels[s] for s in candidates))
    return replace(found, relations=named, support=())


def _coupled(task: Task, near: Collection[Statement]) -> set[Statement]:
    """The coupled relations (gear, rack, mirror) of the situations of ``near``: left out
    with them when their carrier's relations are."""
    places = {s.index for s in near}
    return {
        Statement(index, "relation", number)
        for index in places
        for number, relation in enumerate(task.situations[index].relations)
        if relation.type.coupled
    }


def _solve_without(
    task: Task, every: set[Statement], left_out: set[Statement], solve: Solver
) -> Solution:
    """The task without the statements ``left_out`` solved by the reduction alone (what
    only the numeric solver of the residue would answer stays unanswered: a mechanism of
    unknown dof, as an inconsistent task is not solved numerically); a coupled relation
    left without the body that carries it is left out too (and added to ``left_out``)."""
    try:
        return solve(keeping(task, every - left_out), False)
    except AssemblyKitError:
        left_out |= _coupled(task, left_out)
        return solve(keeping(task, every - left_out), False)


def without_conflicts(
    task: Task, solution: Solution, solve: Solver, tol: ModelTolerance
) -> Solution:
    """``solution`` of an inconsistent task with each conflict narrowed to the statements
    that take part (:func:`narrow`), and the poses and freedoms of the task without
    them, marked as valid only so (:attr:`Solution.valid_without`)."""
    table = statements(task)
    conflicts = tuple(dict.fromkeys(narrow(task, c, solve, tol, table) for c in solution.conflicts))
    every = set().union(*table.values())
    left_out = set(_expand((label for c in conflicts for label in c.relations), table))
    answer = _solve_without(task, every, left_out, solve)
    while answer.conflicts:
        named = (label for c in answer.conflicts for label in c.support or c.relations)
        more = set(_expand(named, table))
        if more <= left_out:
            break
        left_out |= more
        answer = _solve_without(task, every, left_out, solve)
    labels = {s: label for label, items in table.items() for s in items}
    steps = tuple(step for step in solution.trace if step.rule != "free")
    return replace(
        solution,
        bodies=answer.bodies,
        conflicts=conflicts,
        trace=steps + tuple(step for step in answer.trace if step.rule == "free"),
        valid_without=tuple(dict.fromkeys(labels[s] for s in sorted(left_out))),
    )
