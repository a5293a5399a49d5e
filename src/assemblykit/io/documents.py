"""YAML and JSON documents read with the place of every fault.

Well-formed YAML is read by ``yaml-rs`` (a compiled YAML 1.2 parser: a 1,000-body task
file in 0.04 s, against 0.6 s for PyYAML even on libyaml's C parser). Text it rejects
is read again by PyYAML (through libyaml when PyYAML was built with it), whose errors
give the line and column of the fault and which, with the loader below, rejects a key
given twice in one mapping (PyYAML alone keeps the last one silently).
"""

from __future__ import annotations

import json
from typing import Any

import yaml
import yaml_rs

from assemblykit.errors import SchemaError

_BaseLoader: type = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class _UniqueKeyLoader(_BaseLoader):  # type: ignore[misc, valid-type]
    """A safe YAML loader that rejects a key given twice in one mapping and resolves each
    distinct plain scalar's type once (generated files repeat ``0``, ``plane``, ``-1``
    thousands of times; PyYAML tries its regular expressions on every occurrence)."""

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._plain_tags: dict[str, str] = {}

    def resolve(self, kind: type, value: Any, implicit: tuple[bool, bool]) -> str:
        if kind is not yaml.ScalarNode or not implicit[0]:
            return super().resolve(kind, value, implicit)
        tag = self._plain_tags.get(value)
        if tag is None:
            tag = self._plain_tags[value] = super().resolve(kind, value, implicit)
        return tag

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: set[Any] = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            if key in seen:
                raise SchemaError(
                    f"duplicate key {key!r}", where=f"line {key_node.start_mark.line + 1}"
                )
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


def read_yaml(text: str, source: str | None = None) -> Any:
    """Parse YAML text; :class:`SchemaError` with the line for malformed text or a
    duplicate key."""
    try:
        return yaml_rs.loads(text, parse_datetime=False)
    except yaml_rs.YAMLDecodeError:
        pass  # PyYAML below names the line and column of the fault
    try:
        return yaml.load(text, Loader=_UniqueKeyLoader)
    except SchemaError as error:
        raise SchemaError(error.detail, source=source, where=error.where) from None
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = None if mark is None else f"line {mark.line + 1}, column {mark.column + 1}"
        problem = getattr(error, "problem", None) or str(error)
        raise SchemaError(f"malformed YAML: {problem}", source=source, where=where) from None


def read_json(text: str, source: str | None = None) -> Any:
    """Parse JSON text; :class:`SchemaError` with the line for malformed text or a
    duplicate key."""

    def unique(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for key, value in pairs:
            if key in out:
                raise SchemaError(f"duplicate key {key!r}", source=source)
            out[key] = value
        return out

    try:
        return json.loads(text, object_pairs_hook=unique)
    except json.JSONDecodeError as error:
        raise SchemaError(
            f"malformed JSON: {error.msg}",
            source=source,
            where=f"line {error.lineno}, column {error.colno}",
        ) from None
