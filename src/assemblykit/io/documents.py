"""YAML and JSON documents read with the place of every fault.

Well-formed YAML is read by ``yaml-rs`` (a compiled YAML 1.2 parser: a 1,000-body task
file in 0.04 s, against 0.6 s for PyYAML even on libyaml's C parser). Text it rejects
is read again by PyYAML (through libyaml when PyYAML was built with it), whose errors
give the line and column of the fault and which, with the loader below, rejects a key
given twice in one mapping (PyYAML alone keeps the last one silently).

Documents are refused, with :class:`SchemaError`, before anything walks them when they
nest deeper than :data:`MAX_DEPTH` or, through YAML aliases, expand to more than
:data:`MAX_NODES` values (a "billion laughs" file is a few hundred bytes that expands to
10^9 strings). Files that are not UTF-8 text are refused by :func:`read_text`.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Any

import yaml
import yaml_rs

from assemblykit.errors import InputError, SchemaError

MAX_DEPTH = 64
"""Deepest nesting of lists and mappings accepted in a document. The deepest file format
here (a 4x4 pose in a part of a manifest) nests 5 levels; recursive code downstream
(pydantic, the report writer) would exhaust Python's stack near 1,000."""

MAX_NODES = 1_000_000
"""Most values a document may hold once its YAML aliases are expanded: ten times the
largest bundled example, and small enough to count in well under a second."""

FLOAT_MAX = sys.float_info.max
"""The largest number a document may hold: every number is computed with as a float."""

MAX_COORDINATE = 1e10
"""Largest coordinate of a mesh vertex or polygon point accepted: trimesh merges vertices
by hashing coordinates scaled by 1e8 as 64-bit integers (at most 9.2e18), which
overflows beyond about 9e10, and a model's size sets every tolerance."""

FLOAT_DIGITS = len(str(int(FLOAT_MAX)))
"""Digits of the integer part of :data:`FLOAT_MAX` (309): a number written with more is
beyond it, told before Python converts it (which it refuses beyond 4,300 digits)."""

_ALIAS_LIMITS = yaml_rs.AliasLimits(
    max_total_replayed_events=MAX_NODES, max_replay_stack_depth=MAX_DEPTH
)

_BaseLoader: type = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class _UniqueKeyLoader(_BaseLoader):
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


def read_text(path: str | Path, what: str = "file") -> str:
    """The text of ``path`` read as UTF-8; :class:`InputError` naming the file when it
    cannot be read or is not UTF-8 text (binary, Latin-1, UTF-16). ``what`` names the
    file's role in the message (``task file``, ``manifest``)."""
    source = str(path)
    try:
        return Path(path).read_text(encoding="utf-8")
    except UnicodeDecodeError as bad:
        raise InputError(
            f"the {what} is not UTF-8 text (byte {bad.start}); save it as UTF-8",
            source=source,
        ) from None
    except OSError as error:
        reason = error.strerror or type(error).__name__
        raise InputError(f"cannot read the {what}: {reason}", source=source) from None


def checked_shape(data: Any, source: str | None = None) -> Any:
    """``data`` when it nests at most :data:`MAX_DEPTH` levels, holds at most
    :data:`MAX_NODES` values counting every alias again and no integer beyond the range
    of a float (every number is computed with as one); else :class:`SchemaError`.

    The walk uses its own stack (no recursion) and stops at the first limit exceeded, so
    an alias bomb costs at most :data:`MAX_NODES` steps."""
    _check_number(data, source)
    if not isinstance(data, dict | list):
        return data
    stack: list[tuple[dict[Any, Any] | list[Any], int]] = [(data, 0)]
    count = 1
    while stack:
        value, depth = stack.pop()
        if depth >= MAX_DEPTH:
            raise SchemaError(f"nested deeper than {MAX_DEPTH} levels", source=source)
        children = value.values() if isinstance(value, dict) else value
        count += len(children)
        if count > MAX_NODES:
            raise SchemaError(
                f"document expands to more than {MAX_NODES} values (YAML aliases?)",
                source=source,
            )
        for child in children:
            if isinstance(child, dict | list):
                stack.append((child, depth + 1))
            elif type(child) is int and abs(child) > FLOAT_MAX:
                _check_number(child, source)
    return data


def _check_number(value: Any, source: str | None) -> None:
    """:class:`SchemaError` for an integer beyond the range of a float."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) > FLOAT_MAX:
        digits = int(value.bit_length() * math.log10(2)) + 1
        raise SchemaError(
            f"a number of about {digits} digits is beyond the range of a float ({FLOAT_MAX:.4g})",
            source=source,
        )


def read_yaml(text: str, source: str | None = None) -> Any:
    """Parse YAML text; :class:`SchemaError` with the line for malformed text, a
    duplicate key, or a document too deep or too large (module docstring)."""
    try:
        return checked_shape(
            yaml_rs.loads(text, parse_datetime=False, alias_limits=_ALIAS_LIMITS), source
        )
    except yaml_rs.YAMLDecodeError as error:
        message = str(error)
        if "recursion limit exceeded" in message:
            raise SchemaError(f"nested deeper than {MAX_DEPTH} levels", source=source) from None
        if "alias replay limit exceeded" in message:
            # PyYAML would build the same bomb: refuse it here
            raise SchemaError(
                f"YAML aliases expand to more than {MAX_NODES} values", source=source
            ) from None
    except RecursionError:
        raise SchemaError(f"nested deeper than {MAX_DEPTH} levels", source=source) from None
    # PyYAML below names the line and column of the fault
    try:
        return checked_shape(yaml.load(text, Loader=_UniqueKeyLoader), source)
    except RecursionError:
        raise SchemaError(f"nested deeper than {MAX_DEPTH} levels", source=source) from None
    except SchemaError as error:
        raise SchemaError(error.detail, source=source, where=error.where) from None
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = None if mark is None else f"line {mark.line + 1}, column {mark.column + 1}"
        if isinstance(error, yaml.reader.ReaderError):  # a character YAML does not allow
            where = f"line {text.count(chr(10), 0, error.position) + 1}"
            problem = f"character {error.character!r} is not allowed"
        else:
            # PyYAML's text spans lines; the place is already in ``where``
            problem = getattr(error, "problem", None) or str(error).splitlines()[0]
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
        return checked_shape(json.loads(text, object_pairs_hook=unique), source)
    except RecursionError:
        raise SchemaError(f"nested deeper than {MAX_DEPTH} levels", source=source) from None
    except json.JSONDecodeError as error:
        raise SchemaError(
            f"malformed JSON: {error.msg}",
            source=source,
            where=f"line {error.lineno}, column {error.colno}",
        ) from None
    except ValueError as error:  # an integer of more digits than Python converts
        raise SchemaError(f"a number too long to read: {error}", source=source) from None
