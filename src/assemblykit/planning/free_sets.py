"""The free sets of a directional blocking graph (Wilson & Latombe 1992, "Directional
Blocking Graph"): a set of parts leaves along ``d`` when no arc "j blocks i" of the DBG
along ``d`` goes from one of its parts to a part outside it.

Some proper, non-empty set of parts is free along ``d`` exactly when that DBG is not
strongly connected (:func:`separable`); the minimal free sets are its sink strong
components (:func:`sinks`), and a set free in it holds everything its parts' blockers,
and theirs, reach (:func:`closed_under`). Blocking is pairwise (whether P_j blocks P_i
along d does not depend on the other parts), so the DBG of a subassembly is the
induced subgraph of the assembly's DBG: the closures of Γ_t's sinks under the arcs of
Γ_e found so far give the search its removals (:mod:`~assemblykit.planning.search`)
and the interlocked sets their names (:mod:`~assemblykit.planning.interlocked_sets`)
without Γ_e's whole DBG.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

from assemblykit.blocking.dbg import blocking_components
from assemblykit.blocking.directions import DirectionTable
from assemblykit.part_sets import mask_of, several

if TYPE_CHECKING:
    from assemblykit.planning.extended_directions import ExtendedDirections


def separable(table: DirectionTable, members: int) -> bool:
    """True when some direction of ``table`` frees a proper, non-empty part of ``members``
    (a DBG that is not strongly connected: Wilson & Latombe 1992, "Directional Blocking
    Graph")."""
    if not several(members):
        return False
    if table.free_parts(members).any():
        return True
    return bool(table.separating(members).any())


def sinks(source: DirectionTable | ExtendedDirections, k: int, members: int) -> list[int]:
    """The minimal free sets of ``members`` along direction ``k``: the sink strong
    components of its DBG, as bit masks (Wilson & Latombe 1992, "Directional Blocking
    Graph")."""
    condensed = blocking_components(source.graph(k, members))
    return [
        mask_of(condensed.nodes[c]["members"])
        for c in condensed.nodes
        if condensed.out_degree(c) == 0
    ]


def closed_under(
    start: int,
    blockers: Callable[[int], dict[int, int]],
    necessary: Sequence[int],
    members: int,
    enough: Callable[[int], object],
) -> int:
    """``start`` closed under the arcs ``blockers`` gives (per part of a set, the mask of
    its blockers) and Γ_t's (``necessary``, per part) within ``members``: everything
    their blockers, and theirs, reach; it stops early once ``enough`` holds of it."""
    closed = frontier = start
    while frontier and not enough(closed):
        blocked = 0
        for i, mask in blockers(frontier).items():
            blocked |= mask | necessary[i] & members
        frontier = blocked & ~closed
        closed |= frontier
    return closed
