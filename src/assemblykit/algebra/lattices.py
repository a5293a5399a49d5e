"""Arithmetic of one-dimensional lattices: commensurability and integer points of
arithmetic progressions (docs/algebra.md §2.4 "Finite parts", §7 "Lattice rationality").

A discrete one-parameter family {tau^k} meets another set in the k of a progression
``offset + period * Z``; the answer is decided in closed form when ``period`` is
rational within tolerance (bounded-denominator continued fraction) and treated as
incommensurate otherwise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

from assemblykit.tolerance import Tolerance

__all__ = [
    "MAX_LATTICE_DENOMINATOR",
    "IntegerPoints",
    "commensurate",
    "integer_points",
    "lattice_denominator",
]

#: Largest denominator ever accepted when deciding that two lattice periods are
#: commensurate (docs/algebra.md §2.4, "Finite parts": bounded-denominator continued
#: fraction); the bound in force shrinks with the tolerance (:func:`lattice_denominator`).
MAX_LATTICE_DENOMINATOR = 10_000


def lattice_denominator(tol: Tolerance) -> int:
    """The largest denominator a ratio may have to count as commensurate at ``tol``:
    ``1 / sqrt(10 x rel_length)``, at most :data:`MAX_LATTICE_DENOMINATOR` (docs/algebra.md
    §7). Every number lies within about ``1 / n**2`` of a fraction of denominator up to
    ``n`` (Dirichlet), so with larger denominators every ratio would be one; at this bound
    a ratio is taken for a fraction only when it is ten times nearer to it than a number
    in general is: √2 is not commensurate at 1e-6 (239/169 is 1.2e-5 away) nor at 1e-9."""
    return max(1, min(MAX_LATTICE_DENOMINATOR, math.floor(1 / math.sqrt(10 * tol.rel_length))))


def commensurate(ratio: float, tol: Tolerance) -> Fraction | None:
    """The fraction r/n (n <= :func:`lattice_denominator`) equal to ``ratio`` within the
    relative length tolerance, or ``None`` when the ratio is incommensurate (§7)."""
    if not math.isfinite(ratio):
        return None
    frac = Fraction(ratio).limit_denominator(lattice_denominator(tol))
    if abs(float(frac) - ratio) > tol.rel_length * max(1.0, abs(ratio)):
        return None
    return frac


@dataclass(frozen=True)
class IntegerPoints:
    """The integers ``start + step * Z`` (``step`` 0: the single integer ``start``)."""

    start: int
    step: int


def integer_points(
    offset: float, period: Fraction, unit: float, tol: Tolerance
) -> IntegerPoints | None:
    """The integers k in ``offset + period * Z`` (``period`` 0: k = ``offset``), or
    ``None`` when there are none.

    ``unit`` is the length of one step of k, so that ``offset`` counts as an integer
    when it is one within the length tolerance. With period r/n in lowest terms,
    k = offset + j r / n is an integer iff n * offset is one, and then j is fixed
    modulo n by j r = -n offset (mod n): the solutions are spaced |r| apart.
    """
    slack = tol.length / abs(unit)
    r, n = period.numerator, period.denominator
    scaled = n * offset
    whole = round(scaled)
    if abs(scaled - whole) > n * slack:
        return None
    if r == 0:
        return IntegerPoints(whole, 0)
    # gcd(r, n) = 1, so r has an inverse modulo n.
    j = (-whole * pow(r, -1, n)) % n if n > 1 else 0
    start = (whole + j * r) // n
    step = abs(r)
    return IntegerPoints(start % step, step)
