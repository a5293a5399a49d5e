"""One-dimensional lattice arithmetic (src/assemblykit/algebra/lattices.py;
docs/algebra.md §2.4 "Finite parts", §7 "Lattice rationality")."""

from __future__ import annotations

import math
from fractions import Fraction

from hypothesis import given, settings
from hypothesis import strategies as st

from assemblykit.algebra.lattices import (
    MAX_LATTICE_DENOMINATOR,
    IntegerPoints,
    commensurate,
    integer_points,
    lattice_denominator,
)
from assemblykit.tolerance import DEFAULT, Tolerance


def test_commensurate_recovers_ratios_of_lengths():
    assert commensurate(1.5 / 1.0, tol=DEFAULT) == Fraction(3, 2)
    assert commensurate(1.0 / 0.6, tol=DEFAULT) == Fraction(5, 3)
    assert commensurate(-2.5, tol=DEFAULT) == Fraction(-5, 2)
    assert commensurate(0.0, tol=DEFAULT) == Fraction(0)


def test_incommensurate_ratios_and_the_denominator_bound():
    assert commensurate(math.sqrt(2), tol=DEFAULT) is None
    assert commensurate(math.e, tol=DEFAULT) is None
    assert commensurate(float("nan"), tol=DEFAULT) is None
    tight = Tolerance(1.0, rel_length=1e-9)
    assert commensurate(math.pi, tight) is None
    assert commensurate(1.0 / (MAX_LATTICE_DENOMINATOR + 1), tight) is None
    largest = Fraction(1, MAX_LATTICE_DENOMINATOR)
    assert commensurate(float(largest), tight) == largest


def test_the_denominator_bound_shrinks_with_the_tolerance():
    # 1 / sqrt(10 tol): 10^4 at 1e-9, 316 at the default 1e-6, 10 at 1e-3
    bounds = [lattice_denominator(Tolerance(1.0, rel_length=t)) for t in (1e-9, 1e-6, 1e-3, 0.1)]
    assert bounds == [MAX_LATTICE_DENOMINATOR, 316, 10, 1]
    # 355/113 is within 8.5e-8 of pi (relative): a fraction at 1e-6, not at 1e-9
    assert commensurate(math.pi, tol=DEFAULT) == Fraction(355, 113)
    # an exact ratio of a large denominator cannot be told from an irrational at 1e-6
    assert commensurate(1393 / 985, tol=DEFAULT) is None
    assert commensurate(1393 / 985, Tolerance(1.0, rel_length=1e-9)) == Fraction(1393, 985)


def test_the_rational_test_uses_the_relative_length_tolerance():
    # the best fraction with denominator <= 316 misses sqrt(2) by 1.2e-5 (239/169)
    assert commensurate(math.sqrt(2), tol=DEFAULT) is None
    assert commensurate(math.sqrt(2), Tolerance(1.0, rel_length=1e-5)) is None
    assert commensurate(math.sqrt(2), Tolerance(1.0, rel_length=1e-4)) is None
    assert commensurate(239 / 169 + 1e-7, tol=DEFAULT) == Fraction(239, 169)
    assert commensurate(239 / 169 + 1e-5, tol=DEFAULT) is None


@given(st.floats(min_value=1e-9, max_value=0.1), st.sampled_from([2.0, 5.0]))
def test_badly_approximable_ratios_are_never_commensurate(rel_length, square):
    # sqrt(2) = [1; 2, 2, ...] and the golden ratio (1 + sqrt(5)) / 2 = [1; 1, 1, ...]
    # miss every p/q by more than 1 / (4 q^2) and 1 / (3 q^2): at the bound's
    # denominators (1 / q^2 >= 10 tol) by more than the tolerance, whatever it is
    ratio = math.sqrt(2) if square == 2.0 else (1 + math.sqrt(5)) / 2
    assert commensurate(ratio, Tolerance(1.0, rel_length=rel_length)) is None


def test_single_integer_points():
    # offset + 0 Z: only the offset itself, when it is an integer.
    assert integer_points(3.0, Fraction(0), 1.5, tol=DEFAULT) == IntegerPoints(3, 0)
    assert integer_points(-2.0, Fraction(0), 1.5, tol=DEFAULT) == IntegerPoints(-2, 0)
    assert integer_points(2.5, Fraction(0), 1.5, tol=DEFAULT) is None


def test_progressions_with_rational_periods():
    # 1/3 + (2/3) j is an integer for j = 1 (k = 1), then every 2.
    assert integer_points(1 / 3, Fraction(2, 3), 1.0, tol=DEFAULT) == IntegerPoints(1, 2)
    # 0.5 + 1.5 j: j = 1 gives 2, spacing 3.
    assert integer_points(0.5, Fraction(3, 2), 1.0, tol=DEFAULT) == IntegerPoints(2, 3)
    # 0.25 + 1.5 j never is an integer (2 * 0.25 is not one).
    assert integer_points(0.25, Fraction(3, 2), 1.0, tol=DEFAULT) is None
    # Integer periods: every |r|-th integer from the offset.
    assert integer_points(7.0, Fraction(-4), 1.0, tol=DEFAULT) == IntegerPoints(3, 4)


def test_the_offset_test_is_in_model_lengths():
    # An offset 1e-12 off an integer in steps of 1.5 is within 1e-9 * scale.
    assert integer_points(2.0 + 1e-12, Fraction(0), 1.5, tol=DEFAULT) == IntegerPoints(2, 0)
    assert integer_points(2.0 + 1e-6, Fraction(0), 1.5, tol=DEFAULT) is None


@settings(max_examples=50, deadline=None)
@given(
    st.integers(-50, 50),
    st.integers(-30, 30),
    st.integers(1, 12),
    st.integers(-20, 20),
)
def test_every_point_of_the_progression_is_found(k, r, n, j):
    """k = offset + j r / n for an integer k: k is in the answer, and every answer is of
    that form."""
    period = Fraction(r, n)
    offset = k - j * float(period)
    found = integer_points(offset, period, 1.0, tol=DEFAULT)
    assert found is not None
    if found.step == 0:
        assert r == 0 and found.start == k
        return
    assert found.step == abs(period.numerator)
    assert (k - found.start) % found.step == 0
    for i in (-2, 0, 3):
        j_found = (found.start + i * found.step - offset) / float(period)
        assert abs(j_found - round(j_found)) < 1e-9
