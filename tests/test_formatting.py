"""The one formatter of numbers and words in tables (formatting.py)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from assemblykit import formatting as fmt
from assemblykit.tolerance import Tolerance


def test_numbers_snap_to_zero_within_the_tolerance_and_keep_four_digits():
    tol = Tolerance()
    assert fmt.number(math.cos(math.pi / 2), tol) == "0"
    assert fmt.number(-1e-12, tol) == "0"  # never "-0"
    assert fmt.number(2e-6, tol) == "2e-06"  # above the tolerance: shown
    assert fmt.number(1234.5678, tol) == "1235"
    assert fmt.number(-0.000123456, tol) == "-0.0001235"
    assert fmt.number(math.inf) == "inf"
    coarse = Tolerance(rel_length=1e-3, angle=1e-3)
    assert fmt.number(5e-4, coarse) == "0"


def test_directions_along_an_axis_are_words():
    assert fmt.direction([0.0, 0.0, 1.0]) == "+Z"
    assert fmt.direction([-1.0, 6e-17, 0.0]) == "-X"
    assert fmt.direction([-0.0, -0.0, -1.0]) == "-Z"
    assert fmt.direction([0.0, -1.0]) == "-Y"  # a planar direction
    assert fmt.direction([0.6, 0.0, -0.8]) == "(0.6, 0, -0.8)"
    # 1e-5 rad off +X: not an axis at the default 1e-6 rad, rounded to 4 decimals
    assert fmt.direction([1.0, 1e-5, 0.0]) == "(1, 0, 0)"
    assert fmt.direction([1.0, 1e-5, 0.0], Tolerance(angle=1e-4)) == "+X"
    assert fmt.direction([1.0, 1e-7, 0.0]) == "+X"


def test_directions_off_an_axis_print_rounded_components_without_noise():
    # the cross vault's rows and the ASAP beam under gravity, as they were printed
    row = [1.0, 2.952e-05, -6.795e-06]
    assert fmt.direction(row) == "(1, 0, 0)"
    assert fmt.direction(row, Tolerance(angle=1e-5)) == "(1, 0, 0)"  # 3e-5 rad away
    assert fmt.direction(row, Tolerance(angle=1e-4)) == "+X"
    assert fmt.direction([0.0, 1.786e-07, 1.0], Tolerance(angle=1e-5)) == "+Z"  # mesh angle
    assert fmt.direction([-3.172e-08, -0.0003935, 1.0]) == "(0, -0.0004, 1)"
    assert fmt.direction([-0.7071067811865476, 0.0, 0.7071067811865475]) == "(-0.7071, 0, 0.7071)"
    assert fmt.direction([-1e-5, -0.6, -0.8], digits=3) == "(0, -0.6, -0.8)"
    assert fmt.direction([0.0, 0.0, 0.0]) == "(0, 0, 0)"
    assert fmt.direction([math.nan, 0.0, 1.0]) == "(nan, 0, 1)"
    assert fmt.direction([3.0, 4.0, 0.0]) == "(3, 4, 0)"  # to 4 decimals of its length


def test_the_angle_to_an_axis_decides_not_each_component():
    tol = Tolerance(angle=1e-5)
    # each component below the tolerance, together 1.4e-5 rad away from +Z
    assert fmt.direction([9.9e-6, 9.9e-6, 1.0], tol) == "(0, 0, 1)"
    assert fmt.direction([7e-6, 7e-6, 1.0], tol) == "+Z"
    assert fmt.axis_angle([0.0, 1.0, 1.0])[1] == pytest.approx(math.pi / 4)
    assert fmt.axis_angle([0.0, 0.0, 0.0])[0] == -1


def test_twists_print_both_halves_to_the_length_of_the_whole():
    assert fmt.twist([0.0, 0.0, 0.0143, -1e-17, 0.0, 0.9999]) == "(0, 0, 0.0143; 0, 0, 0.9999)"
    assert fmt.twist([-0.0, 1e-20, 0.0, 1.0, 0.0, 0.0]) == "(0, 0, 0; 1, 0, 0)"


unit_vectors = (
    st.lists(
        st.floats(min_value=-1.0, max_value=1.0, allow_nan=False, allow_subnormal=True),
        min_size=3,
        max_size=3,
    )
    .filter(lambda v: np.linalg.norm(v) > 1e-3)
    .map(lambda v: np.asarray(v) / np.linalg.norm(v))
)


@settings(max_examples=60, deadline=None)
@given(unit_vectors, st.sampled_from([1e-9, 1e-5, 1e-3]))
def test_a_printed_direction_is_an_axis_within_the_tolerance_or_rounded_components(v, angle):
    tol = Tolerance(angle=angle)
    text = fmt.direction(v, tol)
    i, off = fmt.axis_angle(v)
    if re.fullmatch(r"[-+][XYZ]", text):
        assert off <= angle and text == ("+" if v[i] > 0 else "-") + "XYZ"[i]
        return
    assert off > angle
    assert "e" not in text and not re.search(r"(?<![\d.])-0(?![.\d])", text)
    items = text.strip("()").split(", ")
    assert len(items) == 3
    # each component within half a unit of the 4th decimal of the exact one
    assert np.allclose([float(x) for x in items], v, rtol=0, atol=5.000001e-5)


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(min_value=-1e6, max_value=1e6, allow_nan=False), min_size=2, max_size=6))
def test_components_never_print_exponents_or_signed_zeros(values):
    text = fmt.components(values)
    assert "e" not in text and "-0," not in text + "," and "-0)" not in text
    assert not re.search(r"(?<![\d.])-0(?:\.0*)?(?![.\d])", text)


def test_headers_lists_and_counts():
    assert fmt.header("through", "mm") == "through (mm)" and fmt.header("step") == "step"
    assert fmt.name_list(["a", "b"]) == "a, b"
    assert fmt.name_list(list("abcdef")) == "a, b, c, d and 2 more"
    assert fmt.count(1, "part") == "1 part" and fmt.count(0, "part") == "0 parts"
    assert fmt.count(2, "body", "bodies") == "2 bodies"
    assert fmt.file_name("/home/x/data/dome.json") == "dome.json" and fmt.file_name(None) == ""


def test_html_tables_escape_cells_unless_raw():
    table = fmt.html_table(["a", "b"], [["<x>", "<i>y</i>"]], raw=[False, True])
    assert table == (
        "<table><tr><th>a</th><th>b</th></tr><tr><td>&lt;x&gt;</td><td><i>y</i></td></tr></table>"
    )
    long = fmt.html_summary("T", ["n"], [[str(i)] for i in range(5)], limit=2)
    assert long.endswith("<p>... and 3 more rows</p>") and long.count("<tr>") == 3
