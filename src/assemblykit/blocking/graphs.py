"""The blocking-graph factory (Wilson & Latombe 1992): the blocking terms of an assembly
for a motion, and its NDBG (or rigid blocking graph) for the whole assembly or a
sub-assembly, computed once per assembly and tolerance.

It sits above the graph modules it chooses between: the NDBG built by the crossing rule
(:mod:`assemblykit.blocking.ndbg`), its sampled variant for non-convex parts and the
extended-translation terms (:mod:`assemblykit.blocking.extended`), the exact planar terms
(:mod:`assemblykit.blocking.planar`) and the rigid-motion graph
(:mod:`assemblykit.blocking.rigid`).
"""

from __future__ import annotations

import weakref
from collections.abc import Iterable
from typing import Any, Literal, overload

from assemblykit.blocking.constraints import BlockingTerm, infinitesimal_terms
from assemblykit.blocking.extended import all_convex, extended_terms, sampled_ndbg
from assemblykit.blocking.ndbg import AssemblyLike, Motion, NonDirectionalBlockingGraph, build_ndbg
from assemblykit.blocking.planar import planar_extended_terms
from assemblykit.blocking.rigid import RigidBlockingGraph
from assemblykit.errors import UnknownNameError
from assemblykit.tolerance import Tolerance

_TERMS: weakref.WeakKeyDictionary[Any, dict[tuple[str, Tolerance], list[BlockingTerm]]] = (
    weakref.WeakKeyDictionary()
)


_GRAPHS: weakref.WeakKeyDictionary[
    Any, dict[tuple[str, tuple[str, ...], Tolerance], NonDirectionalBlockingGraph]
] = weakref.WeakKeyDictionary()


def blocking_terms(assembly: AssemblyLike, motion: str, tol: Tolerance) -> list[BlockingTerm]:
    """The blocking terms of the whole assembly for a motion, computed once per
    assembly and tolerance (subsets filter them)."""
    cache = _TERMS.setdefault(assembly, {})
    key = (motion, tol)
    if key not in cache:
        if motion == "extended" and getattr(assembly, "dimension", 3) == 2:
            cache[key] = planar_extended_terms(assembly, tol)
        elif motion == "extended":
            cache[key] = extended_terms(assembly, tol)
        else:
            cache[key] = infinitesimal_terms(assembly.contacts(tol))
    return cache[key]


def _subset(assembly: AssemblyLike, parts: Iterable[str] | None) -> tuple[str, ...]:
    names = list(assembly.names)
    if parts is None:
        return tuple(names)
    wanted = set(parts)
    unknown = wanted - set(names)
    if unknown:
        raise UnknownNameError(f"no part named {sorted(unknown)[0]!r}")
    return tuple(n for n in names if n in wanted)


@overload
def blocking_graph(
    assembly: AssemblyLike,
    motion: Literal["infinitesimal", "extended"] = ...,
    parts: Iterable[str] | None = None,
    tol: Tolerance | None = None,
) -> NonDirectionalBlockingGraph: ...


@overload
def blocking_graph(
    assembly: AssemblyLike,
    motion: Literal["rigid"],
    parts: Iterable[str] | None = None,
    tol: Tolerance | None = None,
) -> RigidBlockingGraph: ...


@overload
def blocking_graph(
    assembly: AssemblyLike,
    motion: Motion,
    parts: Iterable[str] | None = None,
    tol: Tolerance | None = None,
) -> NonDirectionalBlockingGraph | RigidBlockingGraph: ...


def blocking_graph(
    assembly: AssemblyLike,
    motion: Motion = "infinitesimal",
    parts: Iterable[str] | None = None,
    tol: Tolerance | None = None,
) -> NonDirectionalBlockingGraph | RigidBlockingGraph:
    """The NDBG of ``assembly`` (or of the sub-assembly ``parts``) for infinitesimal
    translations (Γ_t), extended translations (Γ_e) or infinitesimal rigid motions (Γ_g,
    :class:`~assemblykit.blocking.rigid.RigidBlockingGraph`). Contacts and pairwise
    obstacles are computed once per assembly; subsets filter them; each NDBG is kept
    while the assembly lives, and once the whole assembly's is known, a sub-assembly's
    is derived from it by :meth:`NonDirectionalBlockingGraph.without_parts` (same
    regions, finer than the sub-assembly needs but still regular)."""
    if motion not in ("infinitesimal", "extended", "rigid"):
        raise ValueError(f"unknown motion {motion!r}")
    tol = assembly.tolerance(tol)
    names = _subset(assembly, parts)
    inside = set(names)
    contacts = [c for c in assembly.contacts(tol) if c.a in inside and c.b in inside]
    if motion == "rigid":
        return RigidBlockingGraph(names, tuple(contacts), tol)
    graphs = _GRAPHS.setdefault(assembly, {})
    key = (motion, names, tol)
    whole = graphs.get((motion, tuple(assembly.names), tol))
    if key not in graphs and whole is not None:
        # a sub-assembly of an assembly already analysed: drop the other parts' slots
        graphs[key] = whole.without_parts(set(whole.parts) - inside)
    planar = getattr(assembly, "dimension", 3) == 2  # polygons: exact terms, any shape
    if (
        key not in graphs
        and motion == "extended"
        and not planar
        and not all_convex(assembly, names)
    ):
        local = blocking_graph(assembly, "infinitesimal", names, tol)
        graphs[key] = sampled_ndbg(assembly, names, local, tol)
    if key not in graphs:
        terms = [
            t
            for t in blocking_terms(assembly, motion, tol)
            if t.moving in inside and t.blocker in inside
        ]
        dimension = getattr(assembly, "dimension", 3)
        graphs[key] = build_ndbg(names, motion, terms, len(contacts), tol, dimension)
    return graphs[key]
