"""Ragged arrays (ragged.py): the index arrays of groups stored one after another,
against the same written as Python loops."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from assemblykit.ragged import group_of, group_starts, ranges

SIZES = st.lists(st.integers(0, 6), max_size=12)


@given(SIZES)
def test_each_group_starts_after_the_ones_before(sizes):
    assert group_starts(sizes).tolist() == [sum(sizes[:k]) for k in range(len(sizes))]


@given(SIZES)
def test_each_item_knows_its_group(sizes):
    assert group_of(sizes).tolist() == [k for k, size in enumerate(sizes) for _ in range(size)]


@given(SIZES, st.data())
def test_ranges_are_concatenated_in_order(sizes, data):
    starts = data.draw(st.lists(st.integers(-50, 50), min_size=len(sizes), max_size=len(sizes)))
    expected = [s + i for s, size in zip(starts, sizes, strict=True) for i in range(size)]
    assert ranges(starts, sizes).tolist() == expected


def test_no_groups_give_empty_arrays():
    assert group_starts([]).tolist() == group_of([]).tolist() == ranges([], []).tolist() == []
