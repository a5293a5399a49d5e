"""Γ_t of an assembly as direction tables (Wilson & Latombe 1992, "Infinitesimal
translations"): the DBGs of infinitesimal translations along the candidate directions
of a disassembly search, and along any directions added later.

The candidates are the regions of the whole NDBG when its arrangement is small enough,
else the regions of each part's own arrangement
(:func:`assemblykit.blocking.directions.local_table`); both come from the blocking terms
of :func:`assemblykit.blocking.graphs.blocking_terms`, computed once per assembly. For
polygons, Γ_t and Γ_e come together along the regions of their common arrangement of S¹
(:func:`planar_direction_tables`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from assemblykit.blocking.arrangement import circle_partition, snap_normals
from assemblykit.blocking.directions import DirectionTable, local_table, term_slots
from assemblykit.blocking.graphs import blocking_graph, blocking_terms
from assemblykit.model.assembly import AssemblyLike
from assemblykit.tolerance import ModelTolerance

FULL_ARRANGEMENT_REGIONS = 250_000
"""The largest arrangement of Γ_t whose regions all become candidate directions."""


def translation_table(assembly: AssemblyLike, tol: ModelTolerance) -> DirectionTable:
    """Γ_t along the candidate directions of the planner: the regions of the whole
    arrangement when it is small enough (about ``3 c²`` regions for ``c`` circles, at
    most ``FULL_ARRANGEMENT_REGIONS``), else those of each part's own arrangement
    (:func:`~assemblykit.blocking.directions.local_table`)."""
    terms = blocking_terms(assembly, "infinitesimal", tol)
    rows = [t.normals for t in terms]
    circles = len(snap_normals(np.vstack(rows), tol)[0]) if rows else 0
    if 3 * circles**2 <= FULL_ARRANGEMENT_REGIONS:
        return blocking_graph(assembly, motion="infinitesimal", tol=tol).direction_table()
    return local_table(tuple(assembly.names), terms, tol)


def translation_slots(
    assembly: AssemblyLike, table: DirectionTable, tol: ModelTolerance
) -> Callable[[NDArray[np.float64]], NDArray[np.bool_]]:
    """Γ_t along new directions over the slots of ``table``: a slot blocks when one of its
    infinitesimal terms holds strictly (beyond the angle tolerance, as the arrangement's
    snapping has it)."""
    index = {name: i for i, name in enumerate(table.names)}
    column = {
        (int(i), int(j)): s
        for s, (i, j) in enumerate(zip(table.moving, table.blocker, strict=True))
    }
    kept = [
        (term, column[pair])
        for term in blocking_terms(assembly, "infinitesimal", tol)
        if (pair := (index[term.moving], index[term.blocker])) in column
    ]

    def slots(directions: NDArray[np.float64]) -> NDArray[np.bool_]:
        return term_slots(
            directions, [t for t, _ in kept], [s for _, s in kept], len(table.moving), tol
        )

    return slots


def with_obstacles(
    table: DirectionTable,
    slots: Callable[[NDArray[np.float64]], NDArray[np.bool_]],
    pairs: Sequence[tuple[int, int]],
) -> tuple[DirectionTable, Callable[[NDArray[np.float64]], NDArray[np.bool_]]]:
    """Γ_t of ``table`` (and ``slots``, its rows along new directions:
    :func:`translation_slots`) with each of ``pairs`` of parts (indices into its names)
    blocking each other along every direction: parts left interfering, an obstacle to
    each other in every direction (docs/planning.md, "Interfering parts"), as Γ_e has
    them. Γ_t then blocks them where Γ_e does, and a search finds that they go
    together without projecting a mesh."""
    arcs = {(int(i), int(j)) for a, b in pairs for i, j in ((a, b), (b, a))}
    if not arcs:
        return table, slots
    existing = set(zip(table.moving.tolist(), table.blocker.tolist(), strict=True))
    added = sorted(arcs - existing)
    columns = np.array(
        list(zip(table.moving.tolist(), table.blocker.tolist(), strict=True)) + added
    )
    order = np.lexsort((columns[:, 1], columns[:, 0]))
    always = np.array([(int(i), int(j)) in arcs for i, j in columns[order]], dtype=bool)

    def widened(rows: NDArray[np.bool_]) -> NDArray[np.bool_]:
        every = np.hstack([rows, np.zeros((len(rows), len(added)), dtype=bool)])[:, order]
        every[:, always] = True
        return every

    blocked = DirectionTable(table.names, table.directions, widened(table.slots), *columns[order].T)
    return blocked, lambda directions: widened(slots(directions))


def planar_direction_tables(
    assembly: AssemblyLike, tol: ModelTolerance
) -> tuple[DirectionTable, DirectionTable]:
    """Γ_t and Γ_e of a polygon assembly along the regions of one arrangement of S¹: the
    points and open arcs cut by the diameters of both (contacts and grown obstacles). It
    refines both NDBGs, so each DBG is constant over each of its regions (Wilson &
    Latombe 1992, the 2D case)."""
    local = blocking_graph(assembly, "infinitesimal", tol=tol)
    grown = blocking_graph(assembly, "extended", tol=tol)
    normals = np.vstack([local.table.normals, grown.table.normals])
    circles = snap_normals(normals, tol)[0] if len(normals) else normals.reshape(0, 3)
    directions = circle_partition(circles, tol).directions
    return local.direction_table(directions), grown.direction_table(directions)
