"""YAML and JSON documents read with the place of every fault.

YAML goes through libyaml's C parser when PyYAML was built with it (about six times
faster on large task files) and through PyYAML's pure-Python parser otherwise; both
report the line and column of malformed text, and both reject a key given twice in one
mapping (PyYAML alone keeps the last one silently).
"""

from __future__ import annotations

import json
from typing import Any

import yaml

from assemblykit.errors import SchemaError

_BaseLoader: type = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class _UniqueKeyLoader(_BaseLoader):  # type: ignore[misc, valid-type]
    """A safe YAML loader that rejects a key given twice in one mapping."""

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
