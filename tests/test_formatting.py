"""The one formatter of numbers and words in tables (formatting.py)."""

from __future__ import annotations

import math

from assemblykit import formatting as fmt
from assemblykit.tolerance import Tolerance


def test_numbers_snap_to_zero_within_the_tolerance_and_keep_four_digits():
    tol = Tolerance()
    assert fmt.number(math.cos(math.pi / 2), tol) == "0"
    assert fmt.number(-1e-12, tol) == "0"  # never "-0"
    assert fmt.number(2e-9, tol) == "2e-09"  # above the tolerance: shown
    assert fmt.number(1234.5678, tol) == "1235"
    assert fmt.number(-0.000123456, tol) == "-0.0001235"
    assert fmt.number(math.inf) == "inf"
    coarse = Tolerance(rel_length=1e-3, angle=1e-3)
    assert fmt.number(5e-4, coarse) == "0"


def test_directions_along_an_axis_are_words():
    assert fmt.direction([0.0, 0.0, 1.0]) == "+Z"
    assert fmt.direction([-1.0, 6e-17, 0.0]) == "-X"
    assert fmt.direction([0.0, -1.0]) == "-Y"  # a planar direction
    assert fmt.direction([0.6, 0.0, -0.8]) == "(0.6, 0, -0.8)"
    assert fmt.direction([1.0, 1e-6, 0.0]) == "(1, 1e-06, 0)"  # not an axis at 1e-9 rad
    assert fmt.direction([1.0, 1e-6, 0.0], Tolerance(angle=1e-5)) == "+X"


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
