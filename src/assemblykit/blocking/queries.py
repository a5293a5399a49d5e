"""Questions the NDBG answers (Wilson & Latombe 1992, introduction and conclusion).

* which parts and subassemblies can be removed directly, and along which directions
  (Γ_e gives a sufficient condition, Γ_t and Γ_g necessary ones);
* whether a given subassembly can be extracted without removing other parts first;
* the fewest parts to remove before extracting a part;
* whether the assembly comes apart with extended translations only.

For extended translations the directions examined are, in order: those where the moving
parts are locally free (Γ_t, a necessary condition, from the contacts that leave them
only, a small arrangement), regions of the highest dimension first (the interior of the
free cone when it has one), then its lower-dimensional regions (isolated directions such
as a pin's axis), then the principal axes of the moving parts and the directions away
from their contacts that pass the same local test. Each is checked exactly
(:func:`assemblykit.blocking.extended.extended_free`): a direction reported is truly
free; free directions strictly between those examined may be missed.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import networkx as nx
import numpy as np
from numpy.typing import NDArray

from assemblykit.blocking.constraints import BlockingTerm
from assemblykit.blocking.dbg import Removal
from assemblykit.blocking.extended import extended_arcs, extended_free
from assemblykit.blocking.free_cones import blocked_sets, exact_free_directions, overlay_faces
from assemblykit.blocking.graphs import blocking_graph, blocking_terms
from assemblykit.blocking.ndbg import (
    AssemblyLike,
    Motion,
    NonDirectionalBlockingGraph,
    build_ndbg,
)
from assemblykit.blocking.obstacles import of_meshes
from assemblykit.deprecation import moved
from assemblykit.errors import UnknownNameError
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.tolerance import Tolerance

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly

_AXES = np.concatenate([np.eye(3), -np.eye(3)])


def removable_subassemblies(
    assembly: AssemblyLike,
    motion: Motion = "extended",
    parts: Iterable[str] | None = None,
    tol: Tolerance | None = None,
    max_size: int | None = None,
) -> list[Removal]:
    """All directly removable subassemblies (up to ``max_size`` parts) with the
    directions that free them, from the NDBG of the motion."""
    return blocking_graph(assembly, motion, parts, tol).removable(max_size)


def _local_graph(
    assembly: AssemblyLike, subassembly: set[str], tol: Tolerance
) -> NonDirectionalBlockingGraph | None:
    """Γ_t of the contacts leaving ``subassembly`` only (``None`` when it touches
    nothing)."""
    terms: list[BlockingTerm] = [
        t
        for t in blocking_terms(assembly, "infinitesimal", tol)
        if t.moving in subassembly and t.blocker not in subassembly
    ]
    if not terms:
        return None
    names = tuple(sorted(subassembly | {t.blocker for t in terms}))
    return build_ndbg(names, "infinitesimal", terms, 0, tol)


def _local_free_regions(
    assembly: AssemblyLike, subassembly: set[str], tol: Tolerance
) -> tuple[NDArray[np.float64], NDArray[np.int8]]:
    """Directions and dimensions of the Γ_t regions where ``subassembly`` is locally
    free, faces first; the six axis directions (as faces) when it touches nothing."""
    graph = _local_graph(assembly, subassembly, tol)
    if graph is None:
        return _AXES, np.full(len(_AXES), 2, np.int8)
    dims = graph.arrangement.dims
    free = np.flatnonzero(~np.any(graph.packed, axis=1))
    order = free[np.lexsort((free, -dims[free]))]
    return graph.arrangement.directions[order], dims[order]


def _extra_directions(
    assembly: AssemblyLike, subassembly: set[str], tol: Tolerance
) -> NDArray[np.float64]:
    """The principal axes (both ways) of the moving parts' meshes and the unit normals
    of their contacts pointing away from the rest, kept where Γ_t leaves them locally
    free (module docstring)."""
    candidates = []
    for name in sorted(subassembly):
        mesh = assembly.parts[name].mesh  # type: ignore[attr-defined]
        candidates.extend([*mesh.principal_inertia_vectors, *-mesh.principal_inertia_vectors])
    for c in assembly_contacts(assembly, tol):
        if (c.a in subassembly) != (c.b in subassembly):
            away = -1.0 if c.a in subassembly else 1.0
            candidates.extend(away * np.asarray(p.normal, dtype=np.float64) for p in c.planar)
    if not candidates:
        return np.zeros((0, 3))
    directions = np.array(candidates, dtype=np.float64)
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    graph = _local_graph(assembly, subassembly, tol)
    if graph is None:
        return directions
    free: NDArray[np.bool_] = ~np.any(graph.table.direct_arcs(directions, tol), axis=1)
    return directions[free]


def locally_free_directions(
    assembly: AssemblyLike, subassembly: Iterable[str], tol: Tolerance | None = None
) -> list[NDArray[np.float64]]:
    """Representative directions of the Γ_t regions along which ``subassembly`` is
    locally free, from the terms between it and the rest only (faces first); the six
    axis directions when it touches nothing."""
    directions, _ = _local_free_regions(assembly, set(subassembly), assembly.tolerance(tol))
    return list(directions)


def can_extract(
    assembly: AssemblyLike,
    subassembly: Iterable[str],
    motion: Motion = "extended",
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
        twist = graph.free_twist(moving)
        return None if twist is None else Removal(chosen, (twist,))
    directions, dims = _local_free_regions(assembly, moving, tol)
    if motion == "extended" and len(dims):
        # the highest dimension first (the open free cone when it has one), then the rest
        top = dims == dims[0]
        meshes = of_meshes(assembly)
        for batch in (directions[top], directions[~top], _extra_directions(assembly, moving, tol)):
            free = [d for d in batch if extended_free(meshes, moving, d, tol, names)]
            if free:
                return Removal(chosen, tuple(free))
        # none of the sampled directions: a face of the exact free set (a tunnel)
        exact = exact_free_directions(meshes, moving, tol)
        if exact.directions:
            return Removal(chosen, exact.directions, exact.tolerance_dependent)
        return None
    return Removal(chosen, tuple(directions)) if len(directions) else None


def removable_parts(
    assembly: AssemblyLike,
    motion: Motion = "extended",
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


@dataclass(frozen=True, eq=False)
class Prerequisite:
    """The parts to take out before ``part`` (Wilson & Latombe 1992, introduction): ``parts`` leave
    first (in some order, one at a time, each by an extended translation), then
    ``part`` leaves along ``direction``. ``minimal`` is true when no smaller set
    works along any direction; false when a smaller set of direct blockers exists that
    could not be shown removable one part at a time (the answer is then a heuristic)."""

    part: str
    parts: frozenset[str]
    direction: NDArray[np.float64] | None
    minimal: bool


def removal_before(assembly: Assembly, part: str, tol: Tolerance | None = None) -> Prerequisite:
    """The fewest parts to remove before ``part`` can leave by an extended translation,
    over all directions (Wilson & Latombe 1992 §5): the directions are one per face of the overlay
    of the sets each other part blocks (over a face, the parts blocking ``part`` are
    constant), so every set of direct blockers is seen; the sets are tried smallest
    first, and the first whose parts can be taken out one at a time (each along a face
    of its exact free set) is the answer."""
    if part not in assembly.names:
        raise UnknownNameError(f"no part named {part!r}")
    tol = assembly.tolerance(tol)
    names = list(assembly.names)
    others = [n for n in names if n != part]
    sets = blocked_sets(assembly, [part], names, tol)
    if sets is None:
        directions = np.vstack([_AXES, *locally_free_directions(assembly, [part], tol)])
    else:
        faces = overlay_faces(list(sets.values()), tol)
        directions = np.vstack([faces.directions, faces.thin]).reshape(-1, 3)
    options: dict[frozenset[str], NDArray[np.float64]] = {}
    for d in directions:
        # inside a face the blocked sets say who blocks; the direction kept for each
        # set is checked exactly below
        if sets is None:
            blockers = frozenset(j for _, j in extended_arcs(assembly, d, [part], others, tol))
        else:
            blockers = frozenset(j for j, blocked in sets.items() if blocked.contains(d))
        options.setdefault(blockers, d)
    for blockers, d in list(options.items()):
        exact = frozenset(j for _, j in extended_arcs(assembly, d, [part], others, tol))
        if exact != blockers:
            del options[blockers]
            options.setdefault(exact, d)
    smallest = min((len(r) for r in options), default=0)
    for blockers in sorted(options, key=lambda r: (len(r), sorted(r))):
        if _removable_first(assembly, blockers, names, tol):
            return Prerequisite(
                part, blockers, options[blockers], len(blockers) == smallest and sets is not None
            )
    return Prerequisite(part, frozenset(others), None, False)


def _removable_first(
    assembly: Assembly, chosen: frozenset[str], names: list[str], tol: Tolerance
) -> bool:
    """Whether the parts of ``chosen`` can be taken out of ``names`` one at a time, each
    along a face of its exact free set among the parts still there (removing parts only
    removes obstacles, so any part that can leave may leave first)."""
    remaining, pending = set(names), set(chosen)
    while pending:
        leaving = next(
            (
                r
                for r in sorted(pending)
                if exact_free_directions(assembly, [r], tol, remaining, limit=1).directions
            ),
            None,
        )
        if leaving is None:
            return False
        pending.discard(leaving)
        remaining.discard(leaving)
    return True


def parts_to_remove_before(
    assembly: AssemblyLike,
    part: str,
    motion: Motion = "extended",
    tol: Tolerance | None = None,
) -> frozenset[str]:
    """The smallest set of other parts that must leave before ``part`` can be taken
    out. Extended translations: :func:`removal_before` (over all directions, the set
    removable itself). Other motions: over every region's DBG, the parts ``part`` would
    push along (everything reachable from it); the least such set."""
    if part not in assembly.names:
        raise UnknownNameError(f"no part named {part!r}")
    if motion == "extended":
        return removal_before(of_meshes(assembly), part, tol).parts
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
    for dbg, _ in ndbg.unique_dbgs():
        pushed = frozenset(nx.descendants(dbg.graph, part))
        if len(pushed) < len(best_set):
            best_set = pushed
    return best_set


__getattr__ = moved(__name__, {"separable_by_translations": "assemblykit.planning.planner"})
