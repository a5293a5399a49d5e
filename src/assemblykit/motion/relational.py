"""Motion of each body of a task relative to the rest, from the task's relations (Liu 1997).

Liu 1997 takes the compound feature of a moving part from its contacts; a task names them
instead: in a situation, the relations a body takes part in pair its features with
features of other bodies. Each coset relation ``[kind, first, second]`` allows the
relative poses X = L_second⁻¹·L_first ∈ H·x₀ with H on the second feature's body
(:func:`assemblykit.model.relations.relation_coset`, docs/algebra.md §5.1). Holding every
other body in place, a motion g of the body (L ↦ g·L) keeps the relation iff
g ∈ L_second·H·L_second⁻¹, whichever side the body is on; so the body's motion group
relative to the rest (fixed bodies are the world) is the intersection of these placed
groups over its relations (Liu 1997 eq. (2), Prop 3.2.6). Every relation names which
feature meets which, so the swaps of 2-congruent features (Props 3.2.8, 5.0.9) are not
motions here: they would pair a feature with the wrong partner.

A relation keeps holding into later situations as long as no action moves either of its
bodies (docs/tutorial.md §1: a body no action moves keeps its pose, so the pair's relative
pose is unchanged); a relation of a moved body holds only where it is stated again.

The poses L are the representative poses of RAPT inference (``Task.solve``); a placed
group depends only on the second body's pose. Relations that are not cosets (``angle``,
``perpendicular``, ``distance``, ``point_on_plane``, ``point_on_line``, and the coupled
``gear``, ``rack``, ``mirror``) constrain no subgroup; they, and relations whose features cannot
meet (an :class:`~assemblykit.algebra.EmptySet`, e.g. unequal radii), are reported as
``ignored`` with the reason.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from assemblykit.algebra import Coset, SymmetryGroup, intersect_groups
from assemblykit.inference import Solution
from assemblykit.inference.reduction import solve_task, task_tolerance
from assemblykit.model.relations import Relation
from assemblykit.model.task import Task
from assemblykit.motion.freedom import GroupMotion, motion_summary
from assemblykit.tolerance import ModelTolerance, Tolerance


def relation_label(relation: Relation) -> str:
    """``kind first second`` (e.g. ``fits peg.shaft block.bore``)."""
    return " ".join([relation.kind, *(str(ref) for ref in relation.refs)])


@dataclass(frozen=True, eq=False)
class RelationMotion(GroupMotion):
    """The motion of one body in one situation relative to the rest of the task.

    ``group``: the intersection of the placed groups of its coset relations, ``None``
    when it takes part in none (every rigid motion); ``relations``: those relations;
    ``touching``: the bodies they relate it to; ``ignored``: the relations that constrain
    no subgroup, each with the reason."""

    body: str
    situation: str
    group: SymmetryGroup | None
    relations: tuple[str, ...]
    touching: tuple[str, ...]
    ignored: tuple[str, ...]

    @property
    def key(self) -> str:
        """The instance name ``"<body>@<situation>"`` (as in ``solve``)."""
        return f"{self.body}@{self.situation}"

    def to_dict(self) -> dict[str, Any]:
        """``dof``, ``motion``, ``components``, the invariants (as in
        :meth:`assemblykit.motion.freedom.Motion.to_dict`), ``touching``, ``relations``
        and ``ignored``."""
        out = motion_summary(self.group)
        out["touching"] = list(self.touching)
        out["relations"] = list(self.relations)
        out["ignored"] = list(self.ignored)
        return out


@dataclass(frozen=True, eq=False)
class TaskMotionReport:
    """The motion of every movable body in every situation of a task, with the status of
    the inference that placed them (``solved``, ``underconstrained``, ...)."""

    motions: dict[str, RelationMotion]
    status: str
    source: str | None = None

    def __getitem__(self, key: str) -> RelationMotion:
        return self.motions[key]

    def to_dict(self) -> dict[str, Any]:
        """``source``, ``status`` and ``parts`` keyed ``"<body>@<situation>"``."""
        return {
            "source": self.source,
            "status": self.status,
            "parts": {k: m.to_dict() for k, m in self.motions.items()},
        }


def placed_group(
    task: Task, relation: Relation, poses: Mapping[str, np.ndarray], tol: ModelTolerance
) -> SymmetryGroup | str:
    """The world motions of either body that keep ``relation`` with the other body held:
    its coset's group conjugated by the second body's pose (module docstring); or the
    reason it constrains no subgroup."""
    if not relation.type.is_coset:
        return "not a subgroup of motions"
    first, second = (task.feature(ref, relation.where or str(ref)) for ref in relation.refs)
    coset = relation.type.coset(first, second, relation.values, tol)
    if not isinstance(coset, Coset):
        return f"cannot hold: {coset.mismatch.message}"
    return coset.group.conjugate(poses[relation.refs[1].body])


def standing_relations(task: Task) -> dict[str, tuple[Relation, ...]]:
    """The relations holding in each situation, by situation name: its own, then the
    earlier ones between bodies that no action has moved since (module docstring)."""
    standing: list[Relation] = []
    out: dict[str, tuple[Relation, ...]] = {}
    for situation in task.situations:
        moved = {action.body for action in situation.actions}
        stated = {relation_label(r) for r in situation.relations}
        standing = [*situation.relations] + [
            r
            for r in standing
            if not moved & {ref.body for ref in r.refs} and relation_label(r) not in stated
        ]
        out[situation.name] = tuple(standing)
    return out


def situation_motions(
    task: Task,
    situation: str,
    relations: Sequence[Relation],
    solution: Solution,
    tol: ModelTolerance,
) -> list[RelationMotion]:
    """The motion of every movable body in the situation named ``situation`` where
    ``relations`` hold (module docstring)."""
    poses = {
        body: solution.bodies[f"{body}@{situation}"].pose
        for body in task.bodies
        if f"{body}@{situation}" in solution.bodies
    }
    placed = [(relation, placed_group(task, relation, poses, tol)) for relation in relations]
    motions = []
    for name, body in task.bodies.items():
        if body.fixed:
            continue
        mine = [
            (relation, group)
            for relation, group in placed
            if len({ref.body for ref in relation.refs}) == 2
            and name in {ref.body for ref in relation.refs}
        ]
        groups = [g for _, g in mine if isinstance(g, SymmetryGroup)]
        used = tuple(relation_label(r) for r, g in mine if isinstance(g, SymmetryGroup))
        ignored = tuple(f"{relation_label(r)}: {g}" for r, g in mine if isinstance(g, str))
        touching = sorted({ref.body for relation, _ in mine for ref in relation.refs} - {name})
        group = (
            functools.reduce(lambda g, h: intersect_groups(g, h, tol=tol), groups)
            if groups
            else None
        )
        motions.append(RelationMotion(name, situation, group, used, tuple(touching), ignored))
    return motions


def task_motion(task: Task, tol: Tolerance | None = None) -> TaskMotionReport:
    """The motion of every movable body in every situation of ``task`` relative to the
    rest, from the relations it takes part in (module docstring); lengths in the
    tolerance are scaled to the task's size."""
    working = task_tolerance(task, tol)
    solution = solve_task(task, working)
    motions = [
        m
        for name, relations in standing_relations(task).items()
        for m in situation_motions(task, name, relations, solution, working)
    ]
    return TaskMotionReport({m.key: m for m in motions}, solution.status, task.source)
