"""Connected components of index pairs, against networkx's."""

from __future__ import annotations

import networkx as nx
import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from assemblykit.graphs import component_labels


@given(
    st.integers(1, 12).flatmap(
        lambda n: st.tuples(
            st.just(n),
            st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)), max_size=20),
        )
    )
)
def test_nodes_share_a_label_exactly_when_networkx_joins_them(case):
    count, edges = case
    labels = component_labels(count, np.array(edges, dtype=np.int64).reshape(-1, 2))
    graph = nx.Graph()
    graph.add_nodes_from(range(count))
    graph.add_edges_from(edges)
    groups = {frozenset(c) for c in nx.connected_components(graph)}
    assert {frozenset(np.flatnonzero(labels == k).tolist()) for k in set(labels.tolist())} == groups
    # numbered in order of each component's lowest node, from 0
    firsts = [labels[min(c)] for c in sorted(groups, key=min)]
    assert firsts == list(range(len(groups)))
