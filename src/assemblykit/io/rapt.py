"""The ``.rapt`` task language (Corner et al. 1983 §II), read with lark and written back.

The text maps 1:1 onto the YAML/JSON task file (docs/tutorial.md §1): one statement per line,
``body ... end`` and ``situation ... end`` blocks, relations written in RAPT's
``against bottom of block, top of table`` form and actions ``move peg parallel shaft of
peg by 5`` / ``turn peg about shaft of peg by 90 deg``. The grammar is ``rapt.lark`` next
to this module; docs/tutorial.md describes it. Parsing builds the task-file mapping with
the line of every entry, and :func:`assemblykit.io.spec.parse_task` does the rest, so
both syntaxes share one validation and every error names ``file: line N``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from functools import cache
from pathlib import Path
from typing import Any

from lark import Lark, Token, Transformer, v_args
from lark.exceptions import (
    UnexpectedCharacters,
    UnexpectedEOF,
    UnexpectedInput,
    UnexpectedToken,
    VisitError,
)

from assemblykit.errors import SchemaError, TaskSyntaxError
from assemblykit.io.documents import FLOAT_DIGITS, FLOAT_MAX
from assemblykit.io.spec import parse_task, task_to_dict
from assemblykit.model.task import ActionKind, Task

GRAMMAR = Path(__file__).with_name("rapt.lark")

FLAGS: dict[str, tuple[str, bool]] = {
    "male": ("male", True),
    "female": ("male", False),
    "directed": ("directed", True),
    "undirected": ("directed", False),
}
"""Bare words in a feature line and the task-file key each one sets."""

_READABLE = {
    "NAME": "a name",
    "SIGNED_NUMBER": "a number",
    "_NL": "end of line",
    "$END": "end of file",
}


@cache
def parser() -> Lark:
    """The LALR parser of ``rapt.lark`` (contextual lexer: keywords are names elsewhere)."""
    return Lark(
        GRAMMAR.read_text(encoding="utf-8"),
        parser="lalr",
        lexer="contextual",
        propagate_positions=True,
        maybe_placeholders=False,
    )


def parse_rapt(text: str, source: str | None = None) -> Task:
    """Read a ``.rapt`` text into a validated :class:`Task`.

    Raises :class:`TaskSyntaxError` with the line, column and what was expected when the
    text does not parse, and the errors of :func:`~assemblykit.io.spec.parse_task` (naming
    ``line N``) for a task that parses but is wrong.
    """
    data, places = rapt_to_dict(text, source)
    return parse_task(data, source, places)


def rapt_to_dict(text: str, source: str | None = None) -> tuple[dict[str, Any], dict[str, str]]:
    """The task-file mapping of a ``.rapt`` text and the line of each of its entries
    (keyed by field path, e.g. ``situations[0].relations[1]`` -> ``line 12``)."""
    try:
        tree = parser().parse(text + "\n")
    except UnexpectedInput as error:
        raise _syntax_error(error, text, source) from None
    try:
        return _Builder().transform(tree)
    except VisitError as failure:
        cause = failure.orig_exc
        if isinstance(cause, SchemaError):
            raise SchemaError(cause.detail, source=source, where=cause.where) from None
        raise


def task_to_rapt(task: Task) -> str:
    """The ``.rapt`` text of ``task``; ``parse_rapt(task_to_rapt(task)) == task``."""
    data = task_to_dict(task)
    lines = [f"units {data['units']}"]
    for name, body in data["bodies"].items():
        lines += ["", f"body {name}" + (" fixed" if body.get("fixed") else "")]
        for fname, feature in body["features"].items():
            args = " ".join(
                _argument(key, value) for key, value in feature.items() if key != "type"
            )
            lines.append(f"  {feature['type']} {fname} {args}".rstrip())
        lines.append("end")
    for situation in data["situations"]:
        lines += ["", f"situation {situation['name']}"]
        lines += [f"  {_relation_text(items)}" for items in situation["relations"]]
        lines += [f"  {_action_text(items)}" for items in situation["actions"]]
        lines.append("end")
    return "\n".join(lines) + "\n"


def _argument(key: str, value: Any) -> str:
    for word, (field, flag) in FLAGS.items():
        if key == field and value is flag:
            return word
    return f"{key} {_value(value)}"


def _value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return value
    if isinstance(value, list | tuple):
        return "(" + ", ".join(_value(item) for item in value) + ")"
    if isinstance(value, float) and value.is_integer() and abs(value) < 2**53:
        return str(int(value))
    return repr(value)


def _ref_text(text: str) -> str:
    body, _, feature = text.partition(".")
    return f"{feature} of {body}"


def _relation_text(items: list[Any]) -> str:
    kind, *rest = items
    options = rest.pop() if rest and isinstance(rest[-1], dict) else {}
    text = f"{kind} " + ", ".join(_ref_text(ref) for ref in rest)
    return text + "".join(f" {key} {_value(value)}" for key, value in options.items())


def _action_text(items: list[Any]) -> str:
    kind, body, *rest = items
    options = rest[0] if rest else {}
    text = f"{kind} {body}"
    if "along" in options:
        text += f" parallel {_ref_text(options['along'])}"
    if "about" in options:
        text += f" about {_ref_text(options['about'])}"
    if "by" in options:
        text += f" by {_value(options['by'])}"
    return text


def _expected(names: Iterable[str]) -> str:
    """Terminal names as the words a user would type."""
    by_name = {t.name: t for t in parser().terminals}
    words = set()
    for name in names:
        terminal = by_name.get(name)
        if name in _READABLE:
            words.add(_READABLE[name])
        elif terminal is not None and terminal.pattern.type == "str":
            words.add(repr(terminal.pattern.value))
        else:
            words.add(name.lower())
    return ", ".join(sorted(words))


def _at_end(error: UnexpectedInput) -> bool:
    token = getattr(error, "token", None)
    return token is None or token.type == "$END"


def _syntax_error(error: UnexpectedInput, text: str, source: str | None) -> TaskSyntaxError:
    """One line: where the text stops making sense and what would have been accepted
    (the end of the text itself when it stops too early)."""
    line, column = max(error.line, 1), max(error.column, 1)
    if isinstance(error, UnexpectedToken | UnexpectedEOF) and _at_end(error):
        line, column = text.count("\n") + 1, len(text.rpartition("\n")[2]) + 1
    if isinstance(error, UnexpectedToken):
        found = "end of file" if error.token.type == "$END" else repr(str(error.token).strip())
        if error.token.type == "_NL":
            found = "end of line"
        message = f"unexpected {found}, expected {_expected(error.expected)}"
    elif isinstance(error, UnexpectedCharacters):
        message = f"unexpected character {error.char!r}"
        if error.allowed:
            message += f", expected {_expected(error.allowed)}"
    elif isinstance(error, UnexpectedEOF):
        message = f"unexpected end of file, expected {_expected(error.expected)}"
    else:
        message = str(error)
    return TaskSyntaxError(message, source=source, line=line, column=column)


def _line(meta: Any) -> str:
    return f"line {meta.line}"


@v_args(inline=True)
class _Builder(Transformer[Token, tuple[dict[str, Any], dict[str, str]]]):
    """Turns the parse tree into the task-file mapping plus the line of each entry."""

    def number(self, token: Token, unit: Token | None = None) -> int | float | str:
        text = str(token)
        where = f"line {token.line}, column {token.column}"
        digits = len(text.lstrip("+-").partition(".")[0].lower().partition("e")[0])
        if digits > FLOAT_DIGITS:
            raise SchemaError(
                f"a number of {digits} digits is beyond the range of a float", where=where
            )
        value: int | float = float(text) if any(c in text for c in ".eE") else int(text)
        if not math.isfinite(value) or abs(value) > FLOAT_MAX:
            raise SchemaError(f"{text[:40]} is beyond the range of a float", where=where)
        # an angle stays as written ("90 deg"), as in a task file, so that only the
        # options and fields that are angles read it (a length refuses it)
        return value if unit is None else f"{text} {unit}"

    def vector(self, *items: Any) -> list[Any]:
        return list(items)

    def word(self, token: Token) -> bool | str:
        return {"true": True, "false": False}.get(str(token), str(token))

    def pair(self, key: Token, value: Any) -> tuple[str, Any, Token]:
        return str(key), value, key

    def flag(self, word: Token) -> tuple[str, Any, Token]:
        if str(word) not in FLAGS:
            raise SchemaError(
                f"{str(word)!r} needs a value (bare words: {', '.join(FLAGS)})",
                where=f"line {word.line}, column {word.column}",
            )
        key, value = FLAGS[str(word)]
        return key, value, word

    def ref(self, feature: Token, body: Token) -> str:
        return f"{body}.{feature}"

    def by(self, value: Any) -> tuple[str, Any]:
        return "by", value

    def option(self, key: Token, value: Any) -> tuple[str, Any, Token]:
        return str(key), value, key

    @v_args(meta=True)
    def feature(self, meta: Any, children: list[Any]) -> tuple[str, dict[str, Any], Any]:
        kind, name, *arguments = children
        return str(name), {"type": str(kind), **_unique(arguments, f"feature {name}")}, meta

    @v_args(meta=True)
    def relation(self, meta: Any, children: list[Any]) -> tuple[str, list[Any], Any]:
        kind, *rest = children
        refs = [item for item in rest if isinstance(item, str)]
        options = _unique([item for item in rest if isinstance(item, tuple)], str(kind))
        return "relations", [str(kind), *refs, *([options] if options else [])], meta

    @v_args(meta=True)
    def action(self, meta: Any, children: list[Any]) -> tuple[str, list[Any], Any]:
        kind, body, *rest = children
        options: dict[str, Any] = {}
        for item in rest:
            if isinstance(item, tuple):
                options["by"] = item[1]
            else:
                options["along" if kind == ActionKind.MOVE else "about"] = item
        return "actions", [str(kind), str(body), *([options] if options else [])], meta

    @v_args(meta=True)
    def body(self, meta: Any, children: list[Any]) -> tuple[str, Any, Any]:
        name, *rest = children
        fixed = bool(rest) and isinstance(rest[0], Token) and rest[0].type == "FIXED"
        features: dict[str, tuple[dict[str, Any], Any]] = {}
        for fname, data, fmeta in rest[1:] if fixed else rest:
            if fname in features:
                raise SchemaError(
                    f"duplicate feature {fname!r} in body {str(name)!r} "
                    f"(first at line {features[fname][1].line})",
                    where=_line(fmeta),
                )
            features[fname] = (data, fmeta)
        return "body", (str(name), fixed, features), meta

    @v_args(meta=True)
    def situation(self, meta: Any, children: list[Any]) -> tuple[str, Any, Any]:
        name, *entries = children
        return "situation", (str(name), entries), meta

    @v_args(meta=True)
    def units(self, meta: Any, children: list[Any]) -> tuple[str, Any, Any]:
        return "units", str(children[0]), meta

    def start(self, *statements: Any) -> tuple[dict[str, Any], dict[str, str]]:
        data: dict[str, Any] = {"bodies": {}, "situations": []}
        places: dict[str, str] = {}
        body_lines: dict[str, int] = {}
        for kind, value, meta in statements:
            if kind == "units":
                if "units" in data:
                    raise SchemaError("units given twice", where=_line(meta))
                data["units"], places["units"] = value, _line(meta)
            elif kind == "body":
                name, fixed, features = value
                if name in body_lines:
                    raise SchemaError(
                        f"duplicate body {name!r} (first at line {body_lines[name]})",
                        where=_line(meta),
                    )
                body_lines[name] = meta.line
                places[f"bodies.{name}"] = _line(meta)
                data["bodies"][name] = {
                    **({"fixed": True} if fixed else {}),
                    "features": {fname: fdata for fname, (fdata, _) in features.items()},
                }
                for fname, (_, fmeta) in features.items():
                    places[f"bodies.{name}.features.{fname}"] = _line(fmeta)
            else:
                name, entries = value
                place = f"situations[{len(data['situations'])}]"
                places[place] = _line(meta)
                situation: dict[str, Any] = {"name": name, "relations": [], "actions": []}
                for group, items, emeta in entries:
                    places[f"{place}.{group}[{len(situation[group])}]"] = _line(emeta)
                    situation[group].append(items)
                data["situations"].append(situation)
        return data, places


def _unique(arguments: list[tuple[str, Any, Token]], owner: str) -> dict[str, Any]:
    """``key value`` arguments as a mapping; a key given twice is a :class:`SchemaError`."""
    out: dict[str, Any] = {}
    for key, value, token in arguments:
        if key in out:
            raise SchemaError(
                f"{key} given twice for {owner}", where=f"line {token.line}, column {token.column}"
            )
        out[key] = value
    return out
