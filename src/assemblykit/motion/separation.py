"""Separable subassemblies: the smallest moving sets whose motion group separates them.

Liu 1997 §4 (the non-linearizable assembly of its Fig. 10): every single part has the
identity group, yet a two-part subassembly S₁ ∪ S₂ has a T₁ group, "a one dimensional
translation which can separate the assembly". The search grows connected subsets of the
contact graph (networkx) one neighbour at a time, size 1, 2, ..., and stops at the first
size where some subset's compound-feature group (Liu 1997 eq. (2)) contains a motion
that carries it away (:attr:`Motion.separates`). A set and its complement separate
along the same motion, so of two complementary sets of equal size only the one holding
the assembly's first part is reported.
"""

from __future__ import annotations

from collections.abc import Iterable

import networkx as nx

from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.model.assembly import Assembly
from assemblykit.motion.freedom import Motion, MotionSolver
from assemblykit.tolerance import Tolerance


def contact_graph(assembly: Assembly, tol: Tolerance | None = None) -> nx.Graph[str]:
    """Parts as nodes (assembly order), an edge between every two parts in contact."""
    graph: nx.Graph[str] = nx.Graph()
    graph.add_nodes_from(assembly.names)
    graph.add_edges_from(c.pair for c in assembly_contacts(assembly, tol))
    return graph


def _grown(graph: nx.Graph, sets: Iterable[frozenset[str]]) -> set[frozenset[str]]:
    """Every connected set made by adding one neighbour to one of ``sets``."""
    grown: set[frozenset[str]] = set()
    for members in sets:
        frontier = set().union(*(graph[n] for n in members)) - members
        grown.update(members | {n} for n in frontier)
    return grown


def separable_subassemblies(
    assembly: Assembly, max_size: int | None = None, tol: Tolerance | None = None
) -> list[Motion]:
    """The separable connected subassemblies of the smallest size that has any.

    Sizes run from 1 to ``max_size`` (default: half the parts, since a larger set is
    the complement of a smaller one); an empty list means no connected set up to that
    size can be carried away."""
    graph = contact_graph(assembly, tol)
    order = {name: i for i, name in enumerate(assembly.names)}
    limit = len(order) // 2 if max_size is None else min(max_size, len(order) - 1)
    solver = MotionSolver(assembly, tol)
    first = assembly.names[0] if assembly.names else ""
    level: set[frozenset[str]] = {frozenset([name]) for name in assembly.names}
    for size in range(1, limit + 1):
        if size > 1:
            level = _grown(graph, level)
        candidates = [
            tuple(sorted(members, key=order.__getitem__))
            for members in sorted(level, key=lambda s: sorted(order[n] for n in s))
            if 2 * size != len(order) or first in members
        ]
        # whether a set separates depends on the identity component of its group only
        quick = solver.motions_of(candidates, components=False)
        found = solver.motions_of([m.parts for m in quick if m.separates])
        if found:
            return found
    return []
