"""Numbers and words for people: the one formatter behind every table assemblykit shows
(the HTML report, notebook tables, ``repr``s, CSV exports).

A value within the tolerance of zero prints as ``0`` (``6.1e-17`` from ``cos(pi/2)`` is
noise, not information); others keep ``DIGITS`` significant digits. A unit vector along a
coordinate axis prints as ``+Z`` or ``-X``; any other vector as ``(0.7071, 0, 0.7071)``.
Column headers carry the model's length unit when one is known (``offset (mm)``).

>>> number(6.123233995736766e-17)
'0'
>>> number(2 / 3)
'0.6667'
>>> direction([0.0, -1.0, 1e-17])
'-Y'
>>> direction([0.6, 0.0, 0.8])
'(0.6, 0, 0.8)'
>>> header("distance", "mm")
'distance (mm)'
>>> name_list(["a", "b", "c", "d", "e", "f"], limit=3)
'a, b, c and 3 more'
"""

from __future__ import annotations

import html
from collections.abc import Iterable, Sequence

import numpy as np
from numpy.typing import ArrayLike

from assemblykit.tolerance import Tolerance, current

DIGITS = 4
"""Significant digits shown for a number in a table."""

AXES = "XYZ"


def zero_threshold(tol: Tolerance | None = None) -> float:
    """Below this a number shown to people (or written as JSON) is 0: the smaller of the
    length and angle tolerances in force, so only what the library itself treats as 0
    is hidden."""
    tol = current() if tol is None else tol
    return min(tol.length, tol.angle)


def number(value: float, tol: Tolerance | None = None, digits: int = DIGITS) -> str:
    """``value`` with ``digits`` significant digits, ``0`` within the tolerance of zero
    (never ``-0``); ``inf`` and ``nan`` as such."""
    x = float(value)
    if not np.isfinite(x):
        return str(x)
    if abs(x) <= zero_threshold(tol):
        return "0"
    text = f"{x:.{digits}g}"
    return "0" if float(text) == 0 else text


def vector(values: ArrayLike, tol: Tolerance | None = None, digits: int = DIGITS) -> str:
    """A vector as ``(x, y, z)``, each component by :func:`number`."""
    return "(" + ", ".join(number(x, tol, digits) for x in np.ravel(values)) + ")"


def direction(values: ArrayLike, tol: Tolerance | None = None, digits: int = DIGITS) -> str:
    """A direction as a signed coordinate axis (``+Z``, ``-X``) when every other
    component is within the angle tolerance of zero, else as :func:`vector`."""
    v = np.asarray(values, dtype=np.float64).ravel()
    tol = current() if tol is None else tol
    big = np.flatnonzero(np.abs(v) > tol.angle)
    if len(big) == 1 and len(v) <= len(AXES):
        i = int(big[0])
        return ("+" if v[i] > 0 else "-") + AXES[i]
    return vector(v, tol, digits)


def header(name: str, units: str | None = None) -> str:
    """A column header, with the length unit in brackets when known."""
    return f"{name} ({units})" if units else name


def name_list(names: Sequence[str], limit: int = 4) -> str:
    """The first ``limit`` names, then how many more there are."""
    shown = ", ".join(names[:limit])
    rest = len(names) - limit
    return shown if rest <= 0 else f"{shown} and {rest} more"


def count(n: int, noun: str, plural: str | None = None) -> str:
    """``1 part``, ``3 parts`` (``plural`` for irregular nouns)."""
    return f"{n} {noun if n == 1 else plural or noun + 's'}"


def html_table(
    headers: Sequence[str], rows: Iterable[Sequence[str]], *, raw: Sequence[bool] = ()
) -> str:
    """An HTML table of text cells, every cell escaped except the columns flagged in
    ``raw`` (which already hold HTML, e.g. a ``<details>`` list).

    >>> html_table(["part", "motion"], [["lid<1>", "fixed"]])
    '<table><tr><th>part</th><th>motion</th></tr><tr><td>lid&lt;1&gt;</td><td>fixed</td></tr></table>'
    """
    flags = list(raw) + [False] * (len(headers) - len(raw))
    head = "".join(f"<th>{html.escape(h)}</th>" for h in headers)
    body = "".join(
        "<tr>"
        + "".join(
            f"<td>{cell if flags[i] else html.escape(cell)}</td>" for i, cell in enumerate(row)
        )
        + "</tr>"
        for row in rows
    )
    return f"<table><tr>{head}</tr>{body}</table>"


def file_name(source: str | None) -> str:
    """The last part of a source path (reprs never show whole paths), or ``""``."""
    return "" if not source else source.replace("\\", "/").rstrip("/").rsplit("/", 1)[-1]


def summary(kind: str, *facts: str) -> str:
    """A one-line ``repr`` for people: ``Kind(fact, fact)``, empty facts left out.

    >>> summary("Plan", "feasible", count(5, "step"), "")
    'Plan(feasible, 5 steps)'
    """
    return f"{kind}({', '.join(f for f in facts if f)})"


def html_summary(
    title: str, headers: Sequence[str], rows: Iterable[Sequence[str]], limit: int = 200
) -> str:
    """A notebook view (``_repr_html_``): ``title`` over a table of the first ``limit``
    rows, and how many more there are."""
    rows = list(rows)
    more = f"<p>... and {len(rows) - limit} more rows</p>" if len(rows) > limit else ""
    return f"<p>{html.escape(title)}</p>{html_table(headers, rows[:limit])}{more}"
