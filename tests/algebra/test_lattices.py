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
)
from assemblykit.tolerance import Tolerance


def test_commensurate_recovers_ratios_of_lengths():
    assert commensurate(1.5 / 1.0) == Fraction(3, 2)
    assert commensurate(1.0 / 0.6) == Fraction(5, 3)
    assert commensurate(-2.5) == Fraction(-5, 2)
    assert commensurate(0.0) == Fraction(0)


def test_incommensurate_ratios_and_the_denominator_bound():
    assert commensurate(math.sqrt(2)) is None
    assert commensurate(math.pi) is None
    assert commensurate(float("nan")) is None
    assert commensurate(1.0 / (MAX_LATTICE_DENOMINATOR + 1)) is None
    assert commensurate(1.0 / MAX_LATTICE_DENOMINATOR) == Fraction(1, MAX_LATTICE_DENOMINATOR)


def test_the_rational_test_uses_the_relative_length_tolerance():
    # The best fraction with denominator <= 10^4 misses sqrt(2) by 1.07e-8 (relative 7.6e-9).
    loose = Tolerance(1.0, rel_length=1e-7)
    assert commensurate(math.sqrt(2), loose) == Fraction(11482, 8119)
    assert commensurate(math.sqrt(2)) is None


def test_single_integer_points():
    # offset + 0 Z: only the offset itself, when it is an integer.
    assert integer_points(3.0, Fraction(0), 1.5) == IntegerPoints(3, 0)
    assert integer_points(-2.0, Fraction(0), 1.5) == IntegerPoints(-2, 0)
    assert integer_points(2.5, Fraction(0), 1.5) is None


def test_progressions_with_rational_periods():
    # 1/3 + (2/3) j is an integer for j = 1 (k = 1), then every 2.
    assert integer_points(1 / 3, Fraction(2, 3), 1.0) == IntegerPoints(1, 2)
    # 0.5 + 1.5 j: j = 1 gives 2, spacing 3.
    assert integer_points(0.5, Fraction(3, 2), 1.0) == IntegerPoints(2, 3)
    # 0.25 + 1.5 j never is an integer (2 * 0.25 is not one).
    assert integer_points(0.25, Fraction(3, 2), 1.0) is None
    # Integer periods: every |r|-th integer from the offset.
    assert integer_points(7.0, Fraction(-4), 1.0) == IntegerPoints(3, 4)


def test_the_offset_test_is_in_model_lengths():
    # An offset 1e-12 off an integer in steps of 1.5 is within 1e-9 * scale.
    assert integer_points(2.0 + 1e-12, Fraction(0), 1.5) == IntegerPoints(2, 0)
    assert integer_points(2.0 + 1e-6, Fraction(0), 1.5) is None


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
    found = integer_points(offset, period, 1.0)
    assert found is not None
    if found.step == 0:
        assert r == 0 and found.start == k
        return
    assert found.step == abs(period.numerator)
    assert (k - found.start) % found.step == 0
    for i in (-2, 0, 3):
        j_found = (found.start + i * found.step - offset) / float(period)
        assert abs(j_found - round(j_found)) < 1e-9
