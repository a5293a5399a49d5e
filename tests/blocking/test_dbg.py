"""DirectionalBlockingGraph: components and locally free subassemblies (Wilson & Latombe 1992, Fig.
1)."""

from __future__ import annotations

import numpy as np

from assemblykit.blocking.dbg import DirectionalBlockingGraph, Removal

PARTS = ("P1", "P2", "P3", "P4")


def graph(arcs) -> DirectionalBlockingGraph:
    return DirectionalBlockingGraph(PARTS, np.array([1.0, 0.0]), frozenset(arcs))


def test_free_subassemblies_follow_arcs():
    # P1 <-> P2 blocked mutually, P3 blocks P2's partner chain, P4 blocks P3
    g = graph({("P1", "P2"), ("P2", "P1"), ("P3", "P4")})
    assert g.sccs()[0] == frozenset({"P1", "P2"})
    assert g.free_subassemblies() == [
        frozenset({"P4"}),
        frozenset({"P1", "P2"}),
        frozenset({"P3", "P4"}),
    ]
    assert g.is_free({"P1", "P2"})
    assert not g.is_free({"P3"})
    assert g.blocks("P4", "P3") and not g.blocks("P3", "P4")


def test_strongly_connected_graph_has_no_free_subassembly():
    cycle = {("P1", "P2"), ("P2", "P3"), ("P3", "P4"), ("P4", "P1")}
    g = graph(cycle)
    assert g.sccs() == [frozenset(PARTS)]
    assert g.free_subassemblies() == []
    assert g.condensation.number_of_nodes() == 1


def test_condensation_is_acyclic_chain():
    g = graph({("P1", "P2"), ("P2", "P3"), ("P3", "P4")})
    assert g.condensation.number_of_nodes() == 4
    assert g.free_subassemblies() == [
        frozenset({"P4"}),
        frozenset({"P3", "P4"}),
        frozenset({"P2", "P3", "P4"}),
    ]


def test_to_dict_and_removal():
    g = graph({("P2", "P1")})
    assert g.to_dict() == {"direction": [1.0, 0.0], "arcs": [["P2", "P1"]]}
    r = Removal(frozenset({"P2", "P1"}), (np.array([0.0, 1.0, 0.0]),))
    assert r.to_dict() == {"parts": ["P1", "P2"], "directions": [[0.0, 1.0, 0.0]]}
