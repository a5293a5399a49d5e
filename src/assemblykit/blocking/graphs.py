"""The blocking-graph factory (Wilson & Latombe 1992): the blocking terms of an assembly
for a motion, and its NDBG (or rigid blocking graph) for the whole assembly or a
sub-assembly, computed once per assembly and tolerance and kept in the assembly's
:class:`~assemblykit.blocking.cache.BlockingCache`.

It sits above the graph modules it chooses between: the NDBG built by the crossing rule
(:mod:`assemblykit.blocking.ndbg`), the extended-translation terms and exact DBGs
(:mod:`assemblykit.blocking.extended`, with which :func:`sampled_ndbg` builds the NDBG
of non-convex parts), the exact planar terms (:mod:`assemblykit.blocking.planar`) and
the rigid-motion graph (:mod:`assemblykit.blocking.rigid`).
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING, Literal, overload

import numpy as np

from assemblykit.blocking.cache import BlockingCache
from assemblykit.blocking.constraints import BlockingTerm, infinitesimal_terms
from assemblykit.blocking.extended import (
    assembly_extended_terms,
    exact_extended,
    extended_arcs,
    extended_dbg,
    extended_terms,
)
from assemblykit.blocking.ndbg import (
    ConstraintTable,
    Motion,
    NonDirectionalBlockingGraph,
    build_ndbg,
)
from assemblykit.blocking.obstacles import of_meshes
from assemblykit.blocking.rigid import RigidBlockingGraph
from assemblykit.errors import UnknownNameError
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.model.assembly import AssemblyLike
from assemblykit.tolerance import ModelTolerance, Tolerance

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly


def blocking_terms(assembly: AssemblyLike, motion: str, tol: ModelTolerance) -> list[BlockingTerm]:
    """The blocking terms of the whole assembly for a motion, computed once per
    assembly and tolerance (subsets filter them)."""
    cache = BlockingCache.of(assembly).terms
    key = (motion, tol)
    if key not in cache:
        if motion == "extended":
            cache[key] = assembly_extended_terms(assembly, tol)
        else:
            cache[key] = infinitesimal_terms(assembly_contacts(assembly, tol))
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
    """The non-directional blocking graph of ``assembly`` (or of the sub-assembly
    ``parts``): the directions of motion cut into regions over each of which one
    directional blocking graph says which part blocks which (Wilson & Latombe 1992,
    "Non-Directional Blocking Graph"; docs/blocking.md, "Three kinds of motion").

    Contacts and pairwise obstacles are computed once per assembly; subsets filter them;
    each NDBG is kept while the assembly lives, and once the whole assembly's is known,
    a sub-assembly's is derived from it by
    :meth:`NonDirectionalBlockingGraph.without_parts` (same regions, finer than the
    sub-assembly needs but still regular).

    Parameters
    ----------
    assembly : Assembly or PolygonAssembly
        The parts in assembled position (:func:`assemblykit.load_assembly`); polygons
        give the graph on the circle of directions S¹.
    motion : {"infinitesimal", "extended", "rigid"}, default "infinitesimal"
        Infinitesimal translations (Γ_t: a free set may still be blocked farther along),
        extended translations (Γ_e: a free set leaves along a straight line to
        infinity) or infinitesimal rigid motions (Γ_g, a
        :class:`~assemblykit.blocking.rigid.RigidBlockingGraph`: rotations allowed).
    parts : iterable of str, optional
        The sub-assembly whose graph is asked for (the whole assembly when ``None``).
    tol : Tolerance, optional
        The tolerance policy (the assembly's own when ``None``).

    Returns
    -------
    NonDirectionalBlockingGraph or RigidBlockingGraph
        The regions and, through ``dbg(direction)``, the directional blocking graph
        along any direction; ``removable()`` the sets that some direction frees.

    Raises
    ------
    ValueError
        ``motion`` is none of the three.
    UnknownNameError
        ``parts`` names a part the assembly does not have.

    Examples
    --------
    >>> import trimesh
    >>> import assemblykit
    >>> lower = trimesh.creation.box(bounds=[[0, 0, 0], [1, 1, 1]])
    >>> upper = trimesh.creation.box(bounds=[[0, 0, 1], [1, 1, 2]])
    >>> parts = [assemblykit.Part("lower", lower), assemblykit.Part("upper", upper)]
    >>> boxes = assemblykit.Assembly(parts)
    >>> ndbg = assemblykit.blocking_graph(boxes)
    >>> ndbg
    NonDirectionalBlockingGraph(infinitesimal, 2 parts, 1 contact, 3 regions)
    >>> ndbg.dbg([0, 0, 1]), ndbg.dbg([1, 0, 0])
    (DirectionalBlockingGraph(+Z, 2 parts, 1 arc), DirectionalBlockingGraph(+X, 2 parts, 0 arcs))
    """
    if motion not in ("infinitesimal", "extended", "rigid"):
        raise ValueError(f"unknown motion {motion!r}")
    tol = assembly.tolerance(tol)
    names = _subset(assembly, parts)
    inside = set(names)
    contacts = [c for c in assembly_contacts(assembly, tol) if c.a in inside and c.b in inside]
    if motion == "rigid":
        return RigidBlockingGraph(names, tuple(contacts), tol)
    graphs = BlockingCache.of(assembly).graphs
    key = (motion, names, tol)
    whole = graphs.get((motion, tuple(assembly.names), tol))
    if key not in graphs and isinstance(whole, NonDirectionalBlockingGraph):
        # a sub-assembly of an assembly already analysed: drop the other parts' slots
        graphs[key] = whole.without_parts(set(whole.parts) - inside)
    if key not in graphs and motion == "extended" and not exact_extended(assembly, names):
        local = blocking_graph(assembly, "infinitesimal", names, tol)
        graphs[key] = sampled_ndbg(of_meshes(assembly), names, local, tol)
    if key not in graphs and motion == "extended" and not exact_extended(assembly, assembly.names):
        # convex parts of an assembly with others that are not: cones among them alone
        # (a stopped set of boards in a cabinet with slotted brackets)
        terms = extended_terms(of_meshes(assembly), tol, names)
        dimension = assembly.dimension
        graphs[key] = build_ndbg(names, motion, terms, len(contacts), tol, dimension)
    if key not in graphs:
        terms = [
            t
            for t in blocking_terms(assembly, motion, tol)
            if t.moving in inside and t.blocker in inside
        ]
        dimension = assembly.dimension
        graphs[key] = build_ndbg(names, motion, terms, len(contacts), tol, dimension)
    graph = graphs[key]
    assert isinstance(graph, NonDirectionalBlockingGraph)
    return graph


def sampled_ndbg(
    assembly: Assembly,
    parts: tuple[str, ...],
    local: NonDirectionalBlockingGraph,
    tol: ModelTolerance,
) -> NonDirectionalBlockingGraph:
    """Γ_e over the regions of the Γ_t graph ``local`` of the same parts, each region's
    DBG computed exactly at its representative direction; ``dbg(d)`` is exact for any
    ``d``. Used when some part is not convex: the regions are then regular for Γ_t, not
    necessarily for Γ_e, so free directions strictly between them may be missed."""
    index = {name: k for k, name in enumerate(parts)}
    pairs = [(i, j) for i in range(len(parts)) for j in range(len(parts)) if i != j]
    moving = np.array([p[0] for p in pairs], dtype=np.int64)
    blocker = np.array([p[1] for p in pairs], dtype=np.int64)
    circles = local.arrangement.normals
    table = ConstraintTable(
        circles,
        np.zeros((len(circles), len(pairs))),
        np.zeros((len(circles), len(pairs))),
        np.full(len(pairs), np.inf),
        np.arange(len(pairs), dtype=np.int64),
        moving,
        blocker,
    )
    column = {pair: s for s, pair in enumerate(pairs)}
    slots = np.zeros((len(local.arrangement), len(pairs)), dtype=bool)
    for r, d in enumerate(local.arrangement.directions):
        for i, j in extended_arcs(assembly, d, parts, parts, tol):
            slots[r, column[(index[i], index[j])]] = True
    return NonDirectionalBlockingGraph(
        parts,
        "extended",
        local.arrangement,
        table,
        np.packbits(slots, axis=1),
        local.contacts,
        tol,
        lambda d, names: extended_dbg(assembly, d, names, tol),
    )
