"""Tests of sets of parts as bit masks (:mod:`assemblykit.part_sets`), against Python
sets of indices."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from assemblykit.part_sets import (
    bits,
    count_bits,
    distinct_rows,
    mask_of,
    mask_vector,
    row_mask,
    several,
    union_of,
)

indices = st.sets(st.integers(0, 150))


@given(indices)
def test_a_set_of_indices_and_its_mask_are_one_set(chosen):
    mask = mask_of(chosen)
    assert list(bits(mask)) == sorted(chosen)
    assert count_bits(mask) == len(chosen)
    assert several(mask) == (len(chosen) > 1)
    # numpy integers index parts as well (no overflow past 63 parts)
    assert mask_of(np.array(sorted(chosen), dtype=np.int64)) == mask


@given(st.lists(indices, max_size=5))
def test_the_union_of_masks_is_the_mask_of_the_union(sets):
    assert union_of(mask_of(s) for s in sets) == mask_of(set().union(*sets))


@given(mask=st.integers(0, 2**80), count=st.integers(0, 90))
def test_a_mask_as_a_vector_holds_its_first_bits(mask, count):
    assert mask_vector(mask, count).tolist() == [bool(mask >> i & 1) for i in range(count)]


@given(indices)
def test_a_packed_row_holds_the_mask_of_its_set_bits(chosen):
    vector = np.zeros(160, dtype=bool)
    vector[sorted(chosen)] = True
    assert row_mask(np.packbits(vector, bitorder="little")) == mask_of(chosen)


@given(
    st.integers(0, 12).flatmap(
        lambda width: st.lists(
            st.lists(st.integers(0, 3), min_size=width, max_size=width), max_size=30
        ).map(lambda rows: np.array(rows, dtype=np.uint8).reshape(len(rows), width))
    )
)
def test_distinct_rows_are_those_of_numpy_unique_in_its_order(rows):
    distinct, inverse = distinct_rows(rows)
    if len(rows):
        expected, where = np.unique(rows, axis=0, return_inverse=True)
        assert distinct.tolist() == expected.tolist()
        assert inverse.tolist() == where.ravel().tolist()
    # each row is the distinct row it is sent to
    assert distinct[inverse].tolist() == rows.tolist()


def test_distinct_rows_of_booleans_keep_their_type():
    rows = np.array([[True, False], [False, True], [True, False]])
    distinct, inverse = distinct_rows(rows)
    assert distinct.dtype == bool
    assert distinct.tolist() == [[False, True], [True, False]]
    assert inverse.tolist() == [1, 0, 1]
