"""The task file in YAML or JSON (docs/tutorial.md §1), read into a validated :class:`Task`.

The layout is checked with pydantic models; features are built by
``assemblykit.features.primitives.feature_from_dict`` and relations by
``Relation.parse``; then :meth:`Task.validate` checks every reference. Every error names
the file and the place at fault, e.g. ``task.yaml: situations[1].relations[0]: unknown
relation 'agains'``. The ``.rapt`` text language (``assemblykit.io.rapt``) builds the
same mapping and passes the line of every entry as its place.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import MISSING, fields
from typing import Annotated, Any, Literal, TypeVar

from pydantic import BaseModel, ConfigDict, Field, StrictBool, StringConstraints, ValidationError

from assemblykit.errors import InputError, SchemaError
from assemblykit.features.primitives import FEATURE_TYPES, Feature, feature_from_dict, parse_angle
from assemblykit.model.body import Body
from assemblykit.model.relations import FeatureRef, Relation
from assemblykit.model.task import ACTION_KINDS, Action, ActionKind, Rounding, Situation, Task
from assemblykit.tolerance import written_resolution

NAME_PATTERN = r"^[A-Za-z_][A-Za-z0-9_]*$"
"""Body, feature and situation names: identifiers, so that ``body.feature`` and the
``.rapt`` text can name them."""

UNITS = ("mm", "cm", "m", "um", "in", "ft")

Name = Annotated[str, StringConstraints(pattern=NAME_PATTERN)]
Locate = Callable[[str], str]
M = TypeVar("M", bound=BaseModel)


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class BodyModel(_Model):
    """``bodies.<name>``: whether the body is the world, and its features by name."""

    fixed: StrictBool = False
    features: dict[Name, dict[str, Any]] = Field(default_factory=dict)


class SituationModel(_Model):
    """``situations[i]``: a name, relation lists and action lists."""

    name: Name
    relations: list[list[Any]] = Field(default_factory=list)
    actions: list[list[Any]] = Field(default_factory=list)


class TaskModel(_Model):
    """The whole task file (docs/tutorial.md §1)."""

    units: Literal[UNITS] = "mm"  # type: ignore[valid-type]
    bodies: dict[Name, BodyModel]
    situations: list[SituationModel]


def parse_task(
    data: Any, source: str | None = None, places: Mapping[str, str] | None = None
) -> Task:
    """Build and validate a :class:`Task` from the task-file mapping.

    ``places`` maps field paths (``bodies.peg``, ``situations[0].relations[1]``) to places
    shown in messages instead (the ``.rapt`` reader gives ``line N``); a path without an
    entry is located by its longest listed prefix, or shown as it is.
    """
    locate = _locator(places or {})
    model = validated(
        TaskModel,
        data,
        "a task file must hold a mapping with bodies and situations",
        source,
        locate,
    )
    try:
        bodies = {
            name: Body(
                name,
                {
                    fname: feature_from_dict(
                        fname, fdata, locate(f"bodies.{name}.features.{fname}")
                    )
                    for fname, fdata in body.features.items()
                },
                fixed=body.fixed,
            )
            for name, body in model.bodies.items()
        }
        situations = tuple(
            _situation(situation, locate, f"situations[{index}]")
            for index, situation in enumerate(model.situations)
        )
    except InputError as error:
        raise with_source(error, source) from None
    return Task(model.units, bodies, situations, source, written_rounding(data)).validate()


DIRECTIONS = frozenset({"normal", "axis", "ref"})
"""The feature fields that are directions: their rounding turns them (an angle)."""


def written_rounding(data: Mapping[str, Any]) -> Rounding:
    """How precisely the task-file mapping ``data`` writes its numbers
    (:class:`Rounding`): the coarsest :func:`written_resolution` of its lengths (every
    number but a direction's), and of its directions the largest turn their rounded
    components allow, ``|resolutions| / |v|``."""
    length, angle = 0.0, 0.0
    stack: list[tuple[str, Any]] = [("", data)]
    while stack:
        key, value = stack.pop()
        if isinstance(value, Mapping):
            stack.extend((str(k), v) for k, v in value.items() if not isinstance(v, str))
        elif isinstance(value, list):
            if value and all(type(v) is int for v in value):
                continue  # whole numbers: written exactly, whether lengths or directions
            if not value or not all(map(_is_real, value)):
                stack.extend((key, v) for v in value if not isinstance(v, str))
            elif key in DIRECTIONS:
                norm = math.hypot(*value)
                if norm > 0:
                    angle = max(angle, math.hypot(*map(written_resolution, value)) / norm)
            else:
                length = max(length, *map(written_resolution, value))
        elif _is_real(value):
            length = max(length, written_resolution(float(value)))
    return Rounding(length, angle)


def _is_real(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def _situation(model: SituationModel, locate: Locate, place: str) -> Situation:
    relations = tuple(
        _relation(items, locate(f"{place}.relations[{index}]"))
        for index, items in enumerate(model.relations)
    )
    actions = tuple(
        _action(items, locate(f"{place}.actions[{index}]"))
        for index, items in enumerate(model.actions)
    )
    return Situation(model.name, relations, actions)


def _relation(items: list[Any], where: str) -> Relation:
    """``[kind, body.feature, ..., {options}]``; an ``angle`` option may be written
    ``"30 deg"`` (:meth:`Relation.values`, which refuses an angle given for a length)."""
    return Relation.parse(items, where)


def _action(items: list[Any], where: str) -> Action:
    """``[move, body]``, ``[move, body, {along: b.f, by: 5}]`` or
    ``[turn, body, {about: b.f, by: 90 deg}]`` (``by`` in model units or radians)."""
    if not (2 <= len(items) <= 3 and all(isinstance(item, str) for item in items[:2])):
        raise SchemaError(f"expected [move|turn, body, {{options}}], got {items!r}", where=where)
    # an unknown kind is kept as written, for Task.validate to name it
    kind = ActionKind(items[0]) if items[0] in ACTION_KINDS else items[0]
    body = items[1]
    options = items[2] if len(items) == 3 else {}
    if not isinstance(options, Mapping):
        raise SchemaError(f"action options must be a mapping, got {options!r}", where=where)
    if unknown := sorted(set(options) - {"along", "about", "by"}):
        raise SchemaError(
            f"unknown action option(s) {', '.join(map(str, unknown))} (allowed: along, about, by)",
            where=where,
        )
    along, about = (
        None if options.get(key) is None else FeatureRef.parse(options[key], f"{where}.{key}")
        for key in ("along", "about")
    )
    return Action(kind, body, along, about, _amount(kind, options.get("by"), where), where)


def _amount(kind: str, value: Any, where: str) -> float | None:
    if value is None:
        return None
    if kind == ActionKind.TURN:
        return parse_angle(value, f"{where}.by")
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise SchemaError(f"'by' must be a finite length, got {value!r}", where=f"{where}.by")
    return float(value)


def task_to_dict(task: Task) -> dict[str, Any]:
    """The task-file mapping of ``task`` (docs/tutorial.md §1); keys equal to their defaults
    are left out, so the output reads like a hand-written file."""
    return {
        "units": task.units,
        "bodies": {
            name: {
                **({"fixed": True} if body.fixed else {}),
                "features": {fname: feature_to_dict(f) for fname, f in body.features.items()},
            }
            for name, body in task.bodies.items()
        },
        "situations": [
            {
                "name": s.name,
                "relations": [
                    [r.kind, *map(str, r.refs), *([dict(r.options)] if r.options else [])]
                    for r in s.relations
                ],
                "actions": [_action_to_list(a) for a in s.actions],
            }
            for s in task.situations
        ],
    }


def feature_to_dict(feature: Feature) -> dict[str, Any]:
    """A feature's task-file mapping without the keys that hold their default value."""
    defaults = {
        item.name: item.default
        for item in fields(FEATURE_TYPES[feature.type_name])  # type: ignore[arg-type]
        if item.default is not MISSING
    }
    return {
        key: value
        for key, value in feature.to_dict().items()
        if not (key in defaults and defaults[key] is not None and value == defaults[key])
    }


def _action_to_list(action: Action) -> list[Any]:
    options: dict[str, Any] = {}
    if action.ref is not None:
        options["along" if action.kind == ActionKind.MOVE else "about"] = str(action.ref)
    if action.by is not None:
        options["by"] = action.by
    return [str(action.kind), action.body, *([options] if options else [])]


def _locator(places: Mapping[str, str]) -> Locate:
    if not places:
        return str  # a YAML or JSON file: each place is shown as its path

    def locate(path: str) -> str:
        probe = path
        while probe:
            if probe in places:
                return places[probe]
            cut = max(probe.rfind("."), probe.rfind("["))
            probe = probe[:cut] if cut > 0 else ""
        return path

    return locate


def _path(loc: tuple[int | str, ...]) -> str:
    text = ""
    for part in loc:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text


def validated(model: type[M], data: Any, message: str, source: str | None, locate: Locate) -> M:
    """``data`` read by the schema ``model``; :class:`SchemaError` with ``message`` when
    it is no mapping, or naming the first field in error (:func:`_schema_error`, places
    shown through ``locate``)."""
    if not isinstance(data, Mapping):
        raise SchemaError(message, source=source)
    try:
        return model.model_validate(data)
    except ValidationError as error:
        raise _schema_error(error, source, locate) from None


def _schema_error(error: ValidationError, source: str | None, locate: Locate) -> SchemaError:
    """The first pydantic error as one line naming the field path."""
    first = error.errors()[0]
    loc = tuple(first["loc"])
    if first["type"] == "extra_forbidden":
        message = f"unknown field {loc[-1]!r}"
        loc = loc[:-1]
    elif first["type"] == "missing":
        message = f"missing field {loc[-1]!r}"
        loc = loc[:-1]
    elif first["type"] == "string_pattern_mismatch":
        message = f"{first['input']!r} is not a valid name (letters, digits and _)"
    else:
        message = first["msg"]
        if "input" in first and not isinstance(first["input"], Mapping | list):
            message += f", got {first['input']!r}"
    more = len(error.errors()) - 1
    if more:
        message += f" (and {more} more error{'s' if more > 1 else ''})"
    path = _path(loc)
    return SchemaError(message, source=source, where=locate(path) if path else None)


def with_source(error: InputError, source: str | None) -> InputError:
    """The same error, naming the file."""
    if error.source or source is None:
        return error
    return type(error)(error.detail, source=source, where=error.where)
