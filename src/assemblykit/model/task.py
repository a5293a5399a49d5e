"""A RAPT task: bodies with features, and situations of relations and actions (Corner et al. 1983
§II).

A task lists the bodies (each with named features, some fixed: the world), then a sequence
of *situations*. In each situation spatial relations (``against``, ``fits``, ...) hold
between features of bodies; *actions* say how bodies moved from the previous situation
(Corner et al. 1983 §II: ``move / body``, ``move / body parallel shaft of body``, optionally by a
given amount). A body that no action moves keeps its pose into the next situation
(docs/tutorial.md §1). This module holds the validated model; the file formats live in
``assemblykit.io.spec`` (YAML/JSON) and ``assemblykit.io.rapt`` (text).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

from assemblykit.errors import FeatureError, SchemaError, UnknownNameError
from assemblykit.features import Feature
from assemblykit.features.primitives import Vector
from assemblykit.model.body import Body
from assemblykit.model.relations import FeatureRef, Relation, check_relation, relation_type
from assemblykit.tolerance import Tolerance, current


class ActionKind(StrEnum):
    """How a body moved from the previous situation (Corner et al. 1983 §II)."""

    MOVE = "move"
    TURN = "turn"


ACTION_KINDS: tuple[ActionKind, ...] = tuple(ActionKind)


@dataclass(frozen=True)
class Action:
    """How ``body`` moved from the previous situation into this one (Corner et al. 1983 §II).

    ``move`` alone leaves the new pose free; ``move`` ``along`` a feature keeps the body
    on a translation along that feature's axis (or normal), by exactly ``by`` model units
    when given; ``turn`` ``about`` a feature rotates it about the feature's axis, by
    ``by`` radians when given. The feature belongs to the moved body and is taken at its
    pose before the action (Corner et al. 1983 §III B: ``f ** p1 = rel(v) ** f ** p2``).
    """

    kind: ActionKind
    body: str
    along: FeatureRef | None = None
    about: FeatureRef | None = None
    by: float | None = None
    where: str | None = field(default=None, compare=False)

    @property
    def ref(self) -> FeatureRef | None:
        """The feature the action is relative to (``along`` or ``about``)."""
        return self.along if self.kind == ActionKind.MOVE else self.about


@dataclass(frozen=True)
class Situation:
    """One stage of the task: the relations that hold and the actions that led to it."""

    name: str
    relations: tuple[Relation, ...] = ()
    actions: tuple[Action, ...] = ()


@dataclass(frozen=True)
class Rounding:
    """How precisely a task's numbers are written
    (:func:`assemblykit.tolerance.written_resolution`): ``length``, half a unit in the
    last place of its coarsest rounded length (model units), and ``angle``, the largest
    turn that rounding its direction vectors' components may give (radians); 0 where
    every number is as designed or computed."""

    length: float = 0.0
    angle: float = 0.0


@dataclass(frozen=True, eq=False)
class Task:
    """A validated RAPT task (docs/tutorial.md §1).

    Two tasks are equal when they describe the same model: same units, bodies, features,
    relations and actions, whatever file (and syntax) they were read from. Numbers are
    compared with the tolerance in force, because features store unit normals and axes,
    and normalising a written unit vector again may change its last bit.
    """

    units: str
    bodies: Mapping[str, Body]
    situations: tuple[Situation, ...]
    source: str | None = None
    rounding: Rounding = Rounding()
    """How precisely its file wrote its numbers (the tolerance is at least ten times it:
    :func:`assemblykit.inference.reduction.task_tolerance`)."""

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Task):
            return NotImplemented
        return _same(self.canonical(), other.canonical(), current())

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        from assemblykit import formatting as fmt

        return fmt.summary(
            "Task",
            fmt.count(len(self.bodies), "body", "bodies"),
            fmt.count(len(self.situations), "situation"),
            self.units,
            fmt.file_name(self.source),
        )

    def _repr_html_(self) -> str:
        """The bodies as a table (notebooks)."""
        from assemblykit import formatting as fmt

        rows = [
            (name, "yes" if body.fixed else "", ", ".join(body.features))
            for name, body in self.bodies.items()
        ]
        return fmt.html_summary(repr(self), ("body", "fixed", "features"), rows)

    def canonical(self) -> tuple[Any, ...]:
        """The model as plain nested values, without file names or places in files."""
        bodies = tuple(
            (
                name,
                body.fixed,
                tuple(
                    (fname, _plain(feature.to_dict())) for fname, feature in body.features.items()
                ),
            )
            for name, body in self.bodies.items()
        )
        situations = tuple(
            (
                s.name,
                tuple(
                    (
                        r.kind,
                        tuple((ref.body, ref.feature) for ref in r.refs),
                        tuple(sorted((k, float(v)) for k, v in (r.options or {}).items())),
                    )
                    for r in s.relations
                ),
                tuple(
                    (
                        a.kind,
                        a.body,
                        None if a.ref is None else (a.ref.body, a.ref.feature),
                        None if a.by is None else float(a.by),
                    )
                    for a in s.actions
                ),
            )
            for s in self.situations
        )
        return (self.units, bodies, situations)

    def validate(self) -> Task:
        """Check names and references; return the task itself.

        Raises :class:`SchemaError` for duplicate or misplaced names,
        :class:`UnknownNameError` for a reference to a missing body or feature and
        :class:`FeatureError` for a feature that cannot take part in a relation or action;
        each names the file and the relation's or action's place in it. A task is a
        value: once its checks pass they are not run again (a task read from a file is
        checked as it is read, and solving it asks again).
        """
        if not self.__dict__.get("_checked", False):
            self._check()
            object.__setattr__(self, "_checked", True)
        return self

    def _check(self) -> None:
        """The checks of :meth:`validate` (each raises where it fails)."""
        for name, body in self.bodies.items():
            if body.name != name:
                raise SchemaError(
                    f"body {body.name!r} is listed under the name {name!r}",
                    source=self.source,
                    where=f"bodies.{name}",
                )
        if not self.situations:
            raise SchemaError("a task needs at least one situation", source=self.source)
        seen: set[str] = set()
        for index, situation in enumerate(self.situations):
            place = f"situations[{index}]"
            if situation.name in seen:
                raise SchemaError(
                    f"duplicate situation name {situation.name!r}", source=self.source, where=place
                )
            seen.add(situation.name)
            if index == 0 and situation.actions:
                raise SchemaError(
                    "the first situation cannot have actions (no situation comes before it)",
                    source=self.source,
                    where=situation.actions[0].where or place,
                )
            for number, relation in enumerate(situation.relations):
                self._check_relation(relation, relation.where or f"{place}.relations[{number}]")
            moved: set[str] = set()
            for number, action in enumerate(situation.actions):
                where = action.where or f"{place}.actions[{number}]"
                if action.body in moved:
                    raise SchemaError(
                        f"body {action.body!r} is moved twice into situation {situation.name!r}",
                        source=self.source,
                        where=where,
                    )
                moved.add(action.body)
                self._check_action(action, where)

    def _body(self, name: str, where: str) -> Body:
        """The body called ``name``; :class:`UnknownNameError` naming ``where`` if none."""
        body = self.bodies.get(name)
        if body is None:
            raise UnknownNameError(
                f"unknown body {name!r} (bodies: {', '.join(self.bodies)})",
                source=self.source,
                where=where,
            )
        return body

    def feature(self, ref: FeatureRef, where: str) -> Feature:
        """The feature ``ref`` names; :class:`UnknownNameError` naming ``where`` if none."""
        body = self._body(ref.body, where)
        found = body.features.get(ref.feature)
        if found is None:
            known = ", ".join(body.features) or "none"
            raise UnknownNameError(
                f"body {ref.body!r} has no feature {ref.feature!r} (features: {known})",
                source=self.source,
                where=where,
            )
        return found

    def _check_relation(self, relation: Relation, where: str) -> None:
        try:
            arity = relation_type(relation.kind).arity
        except SchemaError as error:
            raise SchemaError(error.detail, source=self.source, where=where) from None
        features = tuple(self.feature(ref, where) for ref in relation.refs)
        if len(features) != arity:
            raise SchemaError(
                f"{relation.kind} relates {arity} features, got {len(features)}",
                source=self.source,
                where=where,
            )
        bodies = [ref.body for ref in relation.refs]
        if len(set(bodies)) < len(bodies):
            # a relation constrains the relative pose of two bodies; a body's pose
            # relative to itself is the identity, so such a relation is a slip
            raise SchemaError(
                f"{relation.kind} relates body {bodies[0]!r} to itself (name two bodies)",
                source=self.source,
                where=where,
            )
        try:
            check_relation(relation, *features)
        except (FeatureError, SchemaError) as error:
            raise type(error)(error.detail, source=self.source, where=where) from None

    def _check_action(self, action: Action, where: str) -> None:
        if action.kind not in ACTION_KINDS:
            raise SchemaError(
                f"unknown action {action.kind!r} (expected move or turn)",
                source=self.source,
                where=where,
            )
        body = self._body(action.body, where)
        if body.fixed:
            raise SchemaError(
                f"the fixed body {action.body!r} cannot move", source=self.source, where=where
            )
        wrong = action.about if action.kind == ActionKind.MOVE else action.along
        if wrong is not None:
            key = "about" if action.kind == ActionKind.MOVE else "along"
            raise SchemaError(
                f"'{action.kind}' does not take '{key}'", source=self.source, where=where
            )
        ref = action.ref
        if ref is None:
            if action.kind == ActionKind.TURN or action.by is not None:
                raise SchemaError(
                    f"'{action.kind}' needs a feature "
                    + ("to turn about" if action.kind == ActionKind.TURN else "to move along"),
                    source=self.source,
                    where=where,
                )
            return
        feature = self.feature(ref, where)
        if ref.body != action.body:
            raise FeatureError(
                f"{action.kind} {action.body!r} relative to {ref.body}.{ref.feature}: "
                "the feature must belong to the moved body",
                source=self.source,
                where=where,
            )
        if axis_of(feature) is None:
            raise FeatureError(
                f"cannot {action.kind} {'along' if action.kind == ActionKind.MOVE else 'about'} "
                f"{ref.body}.{ref.feature}: a {feature.type_name} has no axis",
                source=self.source,
                where=where,
            )


def axis_of(feature: Feature) -> Vector | None:
    """The axis (or plane normal) an action may move along or turn about, or ``None``.

    Balls, sockets, points and frames have no single axis (a frame has three).
    """
    for name in ("axis", "normal"):
        value = getattr(feature, name, None)
        if value is not None:
            return value
    return None


def _plain(value: Any) -> Any:
    """Nested lists made hashable tuples, so a feature mapping can be compared."""
    if isinstance(value, Mapping):
        return tuple(sorted((k, _plain(v)) for k, v in value.items()))
    if isinstance(value, list | tuple):
        return tuple(_plain(v) for v in value)
    return value


def _same(a: Any, b: Any, tol: Tolerance) -> bool:
    """Equal nested values, numbers equal within the length tolerance (absolute and
    relative)."""
    if isinstance(a, tuple) and isinstance(b, tuple):
        return len(a) == len(b) and all(_same(x, y, tol) for x, y in zip(a, b, strict=True))
    numbers = (int, float)
    if (
        isinstance(a, numbers)
        and isinstance(b, numbers)
        and not isinstance(a, bool)
        and not isinstance(b, bool)
    ):
        return math.isclose(a, b, rel_tol=tol.rel_length, abs_tol=tol.length)
    return bool(a == b)
