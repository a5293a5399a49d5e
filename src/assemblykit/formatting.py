"""Numbers and words for people: the one formatter behind every table assemblykit shows
(the HTML report, notebook tables, ``repr``s, CSV exports).

A value within the tolerance of zero prints as ``0`` (``6.1e-17`` from ``cos(pi/2)`` is
noise, not information); others keep ``DIGITS`` significant digits. A direction within
the angle tolerance of a coordinate axis prints as ``+Z`` or ``-X``; any other as its
components to ``DIGITS`` decimals of its length, ``(0.7071, 0, 0.7071)``: never an
exponent, never ``-0`` (docs/architecture.md, "Numbers for people"). Column headers
carry the model's length unit when one is known (``offset (mm)``).

>>> number(6.123233995736766e-17)
'0'
>>> number(2 / 3)
'0.6667'
>>> direction([0.0, -1.0, 1e-17])
'-Y'
>>> direction([0.6, 0.0, 0.8])
'(0.6, 0, 0.8)'
>>> direction([1.0, 2.952e-05, -6.795e-06])  # 3e-5 rad from +X: not within 1e-9 rad
'(1, 0, 0)'
>>> direction([1.0, 2.952e-05, -6.795e-06], Tolerance(angle=1e-4))
'+X'
>>> header("distance", "mm")
'distance (mm)'
>>> name_list(["a", "b", "c", "d", "e", "f"], limit=3)
'a, b, c and 3 more'
"""

from __future__ import annotations

import html
import math
from collections.abc import Iterable, Sequence
from decimal import Decimal

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


def axis_angle(values: ArrayLike) -> tuple[int, float]:
    """The coordinate axis nearest the vector ``values`` (its largest component's index)
    and the angle to it in radians (``atan2`` of the other components' length over that
    component's size); ``(-1, nan)`` for a zero or non-finite vector."""
    v = np.asarray(values, dtype=np.float64).ravel()
    if not len(v) or not np.all(np.isfinite(v)) or not np.any(v):
        return -1, math.nan
    i = int(np.argmax(np.abs(v)))
    rest = float(np.linalg.norm(np.delete(v, i)))
    return i, math.atan2(rest, abs(float(v[i])))


def axis_name(values: ArrayLike, tol: Tolerance | None = None) -> str | None:
    """``+X``, ``-Y``, ... when the direction ``values`` (2 or 3 components) lies within
    the angle tolerance (``tol.angle``, tolerance.py) of that axis, else ``None``."""
    tol = current() if tol is None else tol
    v = np.asarray(values, dtype=np.float64).ravel()
    i, angle = axis_angle(v)
    if i < 0 or len(v) > len(AXES) or not angle <= tol.angle:
        return None
    return ("+" if v[i] > 0 else "-") + AXES[i]


def fixed(value: int, decimals: int) -> str:
    """The number ``value x 10**-decimals`` written out in full (no exponent, no trailing
    zeros, ``0`` never signed), computed exactly from the integer ``value``.

    >>> fixed(-70710, 5), fixed(0, 4), fixed(123, -2)
    ('-0.7071', '0', '12300')
    """
    if value == 0:
        return "0"
    text = format(Decimal(value).scaleb(-decimals).normalize(), "f")
    return text.rstrip("0").rstrip(".") if "." in text else text


def length(values: ArrayLike) -> float:
    """The Euclidean length of a finite vector, without overflow for huge components."""
    v = np.asarray(values, dtype=np.float64).ravel()
    largest = float(np.max(np.abs(v))) if len(v) else 0.0
    return largest * float(np.linalg.norm(v / largest)) if largest > 0 else 0.0


def components(values: ArrayLike, digits: int = DIGITS, size: float | None = None) -> str:
    """A vector as ``(x, y, z)``, each component rounded to ``digits`` decimals of
    ``size`` (default: the vector's length; ``1e-4`` of a unit vector): a component far
    below the others prints as ``0``, not as an exponent, and never as ``-0``."""
    v = np.asarray(values, dtype=np.float64).ravel()
    if not np.all(np.isfinite(v)):
        return vector(v)
    size = length(v) if size is None else size
    if not size > 0:
        return "(" + ", ".join("0" for _ in v) + ")"
    decimals = digits - math.floor(math.log10(size))
    scaled = (Decimal(float(x)).scaleb(decimals).to_integral_value() for x in v)
    return "(" + ", ".join(fixed(int(k), decimals) for k in scaled) + ")"


def direction(values: ArrayLike, tol: Tolerance | None = None, digits: int = DIGITS) -> str:
    """A direction for people: a signed coordinate axis (``+Z``, ``-X``) when it lies
    within the angle tolerance of one (:func:`axis_name`), else its :func:`components`
    (docs/architecture.md, "Numbers for people"). JSON keeps the exact vector."""
    return axis_name(values, tol) or components(values, digits)


def twist(values: ArrayLike, digits: int = DIGITS) -> str:
    """An infinitesimal rigid motion ``(omega; v)`` (six components, Wilson & Latombe
    1992; docs/architecture.md, "Conventions") as ``(wx, wy, wz; vx, vy, vz)``, both
    halves by :func:`components` to ``digits`` decimals of the whole twist's length.

    >>> twist([0.0, 0.0, 1.0, 2e-17, -0.5, 0.0])
    '(0, 0, 1; 0, -0.5, 0)'
    """
    v = np.asarray(values, dtype=np.float64).ravel()
    half, size = len(v) // 2, length(v) if np.all(np.isfinite(v)) else None
    first, second = components(v[:half], digits, size), components(v[half:], digits, size)
    return f"{first[:-1]}; {second[1:]}"


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
