"""Questions the NDBG answers (seed 004, introduction and conclusion).

* which parts and subassemblies can be removed directly, and along which directions
  (Γ_e gives a sufficient condition, Γ_t and Γ_g necessary ones);
* whether a given subassembly can be extracted without removing other parts first;
* the fewest parts to remove before extracting a part;
* whether the assembly comes apart with extended translations only.

For extended translations on large assemblies the directions examined are those where
the moving parts are locally free (Γ_t, a necessary condition, from the contacts that
leave them only, a small arrangement), those of the highest dimension (the interior of
the free cone when it has one); each is then checked exactly against the obstacles
whose bounding spheres its sweep can meet. A direction reported is thus
truly free; directions between those examined may be missed.
"""

from __future__ import annotations

from collections.abc import Iterable

import networkx as nx
import numpy as np
from numpy.typing import NDArray

from assemblykit.blocking.constraints import BlockingTerm
from assemblykit.blocking.dbg import Removal
from assemblykit.blocking.extended import obstacles, sweep_candidates
from assemblykit.blocking.ndbg import AssemblyLike, blocking_graph, blocking_terms, build_ndbg
from assemblykit.blocking.rigid import RigidBlockingGraph
from assemblykit.errors import UnknownNameError
from assemblykit.geometry.minkowski import blocks_along
from assemblykit.tolerance import Tolerance

_AXES = np.concatenate([np.eye(3), -np.eye(3)])


def removable_subassemblies(
    assembly: AssemblyLike,
    motion: str = "extended",
    parts: Iterable[str] | None = None,
    tol: Tolerance | None = None,
    max_size: int | None = None,
) -> list[Removal]:
    """All directly removable subassemblies (up to ``max_size`` parts) with the
    directions that free them, from the NDBG of the motion."""
    return blocking_graph(assembly, motion, parts, tol).removable(max_size)  # type: ignore[no-any-return]


def _local_free_regions(
    assembly: AssemblyLike, subassembly: set[str], tol: Tolerance
) -> tuple[NDArray[np.float64], NDArray[np.int8]]:
    """Directions and dimensions of the Γ_t regions where ``subassembly`` is locally
    free, faces first; the six axis directions (as faces) when it touches nothing."""
    terms: list[BlockingTerm] = [
        t
        for t in blocking_terms(assembly, "infinitesimal", tol)
        if t.moving in subassembly and t.blocker not in subassembly
    ]
    if not terms:
        return _AXES, np.full(len(_AXES), 2, np.int8)
    names = tuple(sorted(subassembly | {t.blocker for t in terms}))
    graph = build_ndbg(names, "infinitesimal", terms, 0, tol)
    dims = graph.arrangement.dims
    free = np.flatnonzero(~np.any(graph.packed, axis=1))
    order = free[np.lexsort((free, -dims[free]))]
    return graph.arrangement.directions[order], dims[order]


def locally_free_directions(
    assembly: AssemblyLike, subassembly: Iterable[str], tol: Tolerance | None = None
) -> list[NDArray[np.float64]]:
    """Representative directions of the Γ_t regions along which ``subassembly`` is
    locally free, from the terms between it and the rest only (faces first); the six
    axis directions when it touches nothing."""
    directions, _ = _local_free_regions(assembly, set(subassembly), assembly.tolerance(tol))
    return list(directions)


def _extended_free(
    assembly: AssemblyLike,
    subassembly: set[str],
    direction: NDArray[np.float64],
    tol: Tolerance,
    among: set[str],
) -> bool:
    cache = obstacles(assembly)
    for moving in subassembly:
        for blocker in sweep_candidates(assembly, moving, direction):
            if blocker in subassembly or blocker not in among:
                continue
            if any(blocks_along(c, direction)[0] for c in cache.cones_of(moving, blocker, tol)):
                return False
    return True


def can_extract(
    assembly: AssemblyLike,
    subassembly: Iterable[str],
    motion: str = "extended",
    tol: Tolerance | None = None,
) -> Removal | None:
    """The directions (or twist) along which ``subassembly`` leaves the rest without
    removing any other part first, or ``None`` when there is none."""
    tol = assembly.tolerance(tol)
    names = set(assembly.names)
    moving = set(subassembly)
    if not moving <= names:
        raise UnknownNameError(f"no part named {sorted(moving - names)[0]!r}")
    chosen = frozenset(moving)
    if motion == "rigid":
        graph = blocking_graph(assembly, "rigid", tol=tol)
        assert isinstance(graph, RigidBlockingGraph)
        twist = graph.free_twist(moving)
        return None if twist is None else Removal(chosen, (twist,))
    directions, dims = _local_free_regions(assembly, moving, tol)
    if motion == "extended" and len(dims):
        # the regions of the highest dimension: the open free cone itself when it has one
        top = directions[dims == dims[0]]
        directions = np.array([d for d in top if _extended_free(assembly, moving, d, tol, names)])
    return Removal(chosen, tuple(directions)) if len(directions) else None


def removable_parts(
    assembly: AssemblyLike,
    motion: str = "extended",
    parts: Iterable[str] | None = None,
    tol: Tolerance | None = None,
) -> list[Removal]:
    """Every single part that can be removed directly, with its free directions
    (:func:`can_extract` part by part; scales to large assemblies)."""
    names = list(assembly.names) if parts is None else list(parts)
    out = []
    for name in names:
        found = can_extract(assembly, [name], motion, tol)
        if found is not None:
            out.append(found)
    return out


def parts_to_remove_before(
    assembly: AssemblyLike,
    part: str,
    motion: str = "extended",
    tol: Tolerance | None = None,
) -> frozenset[str]:
    """The smallest set of other parts that must leave before ``part`` can be taken
    out: over every region's DBG, the parts ``part`` would push along (everything
    reachable from it); the least such set."""
    if part not in assembly.names:
        raise UnknownNameError(f"no part named {part!r}")
    if motion == "rigid":
        graph = blocking_graph(assembly, "rigid", tol=tol)
        best = min(
            (r.parts for r in graph.removable(len(assembly.names) - 1) if part in r.parts),
            key=len,
            default=frozenset(assembly.names),
        )
        return frozenset(best - {part})
    ndbg = blocking_graph(assembly, motion, tol=tol)
    best_set = frozenset(assembly.names) - {part}
    for row in np.unique(ndbg.packed, axis=0):
        slots = np.unpackbits(row, count=len(ndbg.table.starts)).astype(bool)
        dbg = ndbg._graph(np.zeros(3), slots)
        pushed = frozenset(nx.descendants(dbg.graph, part))
        if len(pushed) < len(best_set):
            best_set = pushed
    return best_set


def separable_by_translations(
    assembly: AssemblyLike, parts: Iterable[str] | None = None, tol: Tolerance | None = None
) -> bool:
    """Whether the assembly comes completely apart with extended translations, one
    subassembly moving at a time (seed 004, conclusion). Any removable subassembly can
    be taken first: removing parts only removes obstacles."""
    names = list(assembly.names) if parts is None else list(parts)
    if len(names) <= 1:
        return True
    removals = blocking_graph(assembly, "extended", names, tol).removable()
    if not removals:
        return False
    first = removals[0].parts
    rest = [n for n in names if n not in first]
    return separable_by_translations(assembly, first, tol) and separable_by_translations(
        assembly, rest, tol
    )
