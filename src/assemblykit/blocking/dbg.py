"""The directional blocking graph G(d, A) (Wilson & Latombe 1992, "Directional Blocking Graph").

Nodes are the parts; an arc ``i -> j`` means that part ``j`` blocks the motion of part
``i`` along the direction ``d``. A subassembly ``S`` is locally free along ``d`` iff no
arc leaves ``S``; the strongly connected components of the graph tell which such
subassemblies exist (a sink component always does unless the graph is strongly
connected).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import networkx as nx
import numpy as np
from numpy.typing import NDArray


def blocking_components(graph: nx.DiGraph[str] | nx.DiGraph[int]) -> nx.DiGraph[int]:
    """The strong components of a blocking graph (its parts, an arc ``i -> j`` where
    ``j`` blocks ``i``) as the acyclic graph of them, each node's ``members`` the parts
    of one component: networkx's condensation, the one routine every DBG's components
    come from (:meth:`DirectionalBlockingGraph.sccs`, the sets a step moves, the
    minimal free sets of a plan's search; blocking/directions.py labels the same
    components for many DBGs at once). Its sinks are the minimal locally free sets
    (Wilson & Latombe 1992, "Directional Blocking Graph")."""
    return nx.condensation(graph)


@dataclass(frozen=True, eq=False)
class DirectionalBlockingGraph:
    """G(d, A): ``parts`` in order, the motion ``direction`` (a unit 2-, 3- or 6-vector)
    and ``arcs`` ``(i, j)`` meaning ``j`` blocks ``i`` along ``direction``."""

    parts: tuple[str, ...]
    direction: NDArray[np.float64]
    arcs: frozenset[tuple[str, str]] = field(default_factory=frozenset)

    @cached_property
    def graph(self) -> nx.DiGraph[str]:
        """The graph as a networkx DiGraph over every part."""
        g: nx.DiGraph[str] = nx.DiGraph()
        g.add_nodes_from(self.parts)
        g.add_edges_from(self.arcs)
        return g

    def __repr__(self) -> str:
        from assemblykit import formatting as fmt

        return fmt.summary(
            "DirectionalBlockingGraph",
            fmt.direction(self.direction),
            fmt.count(len(self.parts), "part"),
            fmt.count(len(self.arcs), "arc"),
        )

    def blocks(self, blocker: str, moving: str) -> bool:
        """Whether ``blocker`` blocks ``moving`` along the direction."""
        return (moving, blocker) in self.arcs

    def sccs(self) -> list[frozenset[str]]:
        """The strongly connected components (:func:`blocking_components`), largest
        first."""
        members = nx.get_node_attributes(self.condensation, "members")
        comps = [frozenset(c) for c in members.values()]
        return sorted(comps, key=lambda c: (-len(c), sorted(c)))

    @cached_property
    def condensation(self) -> nx.DiGraph[int]:
        """The acyclic graph of the components; node attribute ``members``
        (:func:`blocking_components`)."""
        return blocking_components(self.graph)

    def is_free(self, subassembly: frozenset[str] | set[str]) -> bool:
        """Whether ``subassembly`` is locally free: no arc from it to the rest (Wilson & Latombe
        1992)."""
        inside = set(subassembly)
        return not any(i in inside and j not in inside for i, j in self.arcs)

    def free_subassemblies(self) -> list[frozenset[str]]:
        """The proper subassemblies that are locally free and closed under blocking.

        Every locally free subassembly is a union of these: for each component, the set
        of parts reachable from it (everything it pushes against must come along). The
        whole assembly is left out; sinks of the condensation give the smallest sets.
        """
        cond = self.condensation
        members = nx.get_node_attributes(cond, "members")
        everything = frozenset(self.parts)
        found: set[frozenset[str]] = set()
        for node in cond.nodes:
            reach = {node} | nx.descendants(cond, node)
            closed = frozenset().union(*(members[r] for r in reach))
            if closed != everything:
                found.add(closed)
        return sorted(found, key=lambda s: (len(s), sorted(s)))

    def to_dict(self) -> dict[str, object]:
        """JSON form: the direction and the sorted arcs."""
        return {
            "direction": [float(x) for x in self.direction],
            "arcs": [list(a) for a in sorted(self.arcs)],
        }


@dataclass(frozen=True, eq=False)
class Region:
    """A regular region of an NDBG: a unit ``direction`` inside it, its ``dimension``
    (0 vertex/point, 1 edge/arc, 2 face) and its ``dbg`` (Wilson & Latombe 1992, G(R, A))."""

    direction: NDArray[np.float64]
    dimension: int
    dbg: DirectionalBlockingGraph


@dataclass(frozen=True, eq=False)
class Removal:
    """A subassembly ``parts`` and unit ``directions`` (translations, or twists
    ``(omega; v)`` for rigid motions) along which it is free of the rest."""

    parts: frozenset[str]
    directions: tuple[NDArray[np.float64], ...]
    # the directions lie in faces of the free set thinner than the mesh angle
    # tolerance: the parts leave only if the tolerance lets them touch
    tolerance_dependent: bool = False

    def to_dict(self) -> dict[str, object]:
        """JSON form (docs/blocking.md, "Output"): sorted part names and direction lists
        (and ``tolerance_dependent`` when set)."""
        out: dict[str, object] = {
            "parts": sorted(self.parts),
            "directions": [[float(x) for x in d] for d in self.directions],
        }
        if self.tolerance_dependent:
            out["tolerance_dependent"] = True
        return out
