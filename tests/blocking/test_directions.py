"""Tests of direction tables (:mod:`assemblykit.blocking.directions`) on random tables
and blocking terms."""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from assemblykit.blocking.constraints import BlockingTerm
from assemblykit.blocking.directions import BlockedRows, DirectionTable, term_slots
from assemblykit.part_sets import row_mask, several
from assemblykit.tolerance import Tolerance


def table_from(names, directions, arcs) -> DirectionTable:
    return DirectionTable.from_arcs(names, directions, arcs)


def test_free_parts_of_shrinking_sets_match_a_fresh_count():
    rng = np.random.default_rng(7)
    names = tuple("abcdefgh")
    arcs = [
        [(i, j) for i in range(8) for j in range(8) if i != j and rng.random() < 0.3]
        for _ in range(20)
    ]
    tab = table_from(names, rng.normal(size=(20, 3)), arcs)
    rows = BlockedRows(tab)
    members = (1 << 8) - 1
    while members:
        fresh = table_from(names, tab.directions, arcs)
        np.testing.assert_array_equal(
            rows.free_bits(members, members), fresh.free_bits(members, members)
        )
        np.testing.assert_array_equal(tab.free_parts(members), fresh.free_parts(members))
        members &= ~(1 << int(rng.choice([i for i in range(8) if members >> i & 1])))


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**16),
    asked=st.lists(st.tuples(st.integers(0, 2**12 - 1), st.integers(0, 2**12 - 1)), max_size=12),
)
def test_the_memory_of_blocked_rows_answers_any_sets_as_a_fresh_table(seed, asked):
    """Sets asked in any order (shrinking, growing, unrelated) get from the memory the
    rows the table computes from scratch."""
    rng = np.random.default_rng(seed)
    names = tuple(f"p{i}" for i in range(12))
    arcs = [
        [(i, j) for i in range(12) for j in range(12) if i != j and rng.random() < 0.2]
        for _ in range(9)
    ]
    tab = table_from(names, rng.normal(size=(9, 3)), arcs)
    rows = BlockedRows(tab)
    for members, movers in asked:
        np.testing.assert_array_equal(
            rows.free_bits(members, movers), tab.free_bits(members, movers)
        )


def test_free_bits_past_one_byte_count_the_free_movers_of_shrinking_sets():
    rng = np.random.default_rng(11)
    names = tuple(f"p{i}" for i in range(19))
    arcs = [
        [(i, j) for i in range(19) for j in range(19) if i != j and rng.random() < 0.15]
        for _ in range(30)
    ]
    tab = table_from(names, rng.normal(size=(30, 3)), arcs)
    rows = BlockedRows(tab)
    members = (1 << 19) - 1
    while several(members):
        movers = members & int(rng.integers(1 << 19))
        blocked = np.zeros((30, 19), dtype=bool)
        for k, per_direction in enumerate(arcs):
            for i, j in per_direction:
                blocked[k, i] |= bool(members >> j & 1)
        chosen = np.array([bool(movers >> i & 1) for i in range(19)])
        expected = ~blocked & chosen
        bits = rows.free_bits(members, movers)
        assert [row_mask(row) for row in bits] == [
            sum(1 << int(i) for i in np.flatnonzero(row)) for row in expected
        ]
        np.testing.assert_array_equal(np.bitwise_count(bits).sum(axis=1), expected.sum(axis=1))
        members &= ~(1 << int(rng.choice([i for i in range(19) if members >> i & 1])))


@pytest.mark.parametrize("sizes", [(1, 1, 1, 1), (0, 1, 3, 2, 1, 3, 1)])
def test_term_slots_match_the_terms_one_at_a_time(sizes):
    rng = np.random.default_rng(len(sizes))
    tol = Tolerance()
    terms = [BlockingTerm("a", "b", rng.normal(size=(m, 3))) for m in sizes]
    owners = [int(s) for s in rng.integers(0, 3, len(terms))]
    directions = rng.normal(size=(2500, 3))  # more than one chunk
    directions[0] = 0.0  # on every circle: blocked by no term with normals
    expected = np.zeros((len(directions), 3), dtype=bool)
    for term, s in zip(terms, owners, strict=True):
        expected[:, s] |= np.all(directions @ term.normals.T > tol.angle, axis=1)
    found = term_slots(directions, terms, owners, 3, tol)
    np.testing.assert_array_equal(found, expected)
    # one term per slot, given out of slot order
    single = [BlockingTerm("a", "b", rng.normal(size=(1, 3))) for _ in range(4)]
    expected = np.column_stack([directions @ t.normals[0] > tol.angle for t in single])
    order = [2, 0, 3, 1]
    found = term_slots(directions, [single[s] for s in order], order, 4, tol)
    np.testing.assert_array_equal(found, expected)


def test_free_set_sizes_count_the_sink_components_but_the_kept_ones():
    """Against networkx's condensation of each direction's DBG (and its strong
    connectivity for ``separating``), on random tables with repeated DBGs, on shrinking
    sets, and with no arc at all."""
    rng = np.random.default_rng(3)
    names = tuple(f"p{i}" for i in range(12))
    shapes = [
        [(i, j) for i in range(12) for j in range(12) if i != j and rng.random() < p]
        for p in (0.0, 0.05, 0.1, 0.2, 0.4)
    ]
    arcs = [shapes[int(rng.integers(len(shapes)))] for _ in range(40)]
    tab = table_from(names, rng.normal(size=(40, 3)), arcs)
    members = (1 << 12) - 1
    while members:
        keep = int(rng.choice([i for i in range(12) if members >> i & 1]))
        expected = []
        for k in range(40):
            condensed = nx.condensation(tab.graph(k, members))
            sinks = [
                condensed.nodes[c]["members"]
                for c in condensed.nodes
                if condensed.out_degree(c) == 0 and keep not in condensed.nodes[c]["members"]
            ]
            expected.append(sum(len(s) for s in sinks))
        assert tab.free_set_sizes(members, keep).tolist() == expected
        assert tab.separating(members).tolist() == [
            not nx.is_strongly_connected(tab.graph(k, members)) for k in range(40)
        ]
        members &= ~(1 << keep)
    assert table_from(names, np.eye(3), [[], [], []]).free_set_sizes(0b111, 0).tolist() == [2] * 3


def test_a_pair_blocked_both_ways_everywhere_is_held_and_no_other():
    names = ("a", "b", "c")
    both = [(0, 1), (1, 0)]
    arcs = [[*both, (2, 0)], [*both], [*both, (0, 2), (2, 0)]]
    tab = table_from(names, np.eye(3), arcs)
    assert tab.held_pair(0b111) == 0b011
    assert tab.held_pair(0b101) == 0  # a and c are apart along the second direction
    assert table_from(names, np.eye(3), [[(0, 1)], [(1, 0)], []]).held_pair(0b111) == 0


def test_one_direction_per_distinct_dbg_the_closest_to_an_axis():
    directions = [[0.6, 0.0, 0.8], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.8, 0.6, 0.0]]
    tab = table_from(("a", "b"), directions, [[(0, 1)], [(0, 1)], [], []])
    assert tab.distinct_directions() == [1, 2]
