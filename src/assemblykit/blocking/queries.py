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
free. When none of them frees the parts, the exact free set is asked
(:mod:`assemblykit.blocking.free_cones`): a direction in each of its faces, then in each
of its arcs and at each of its points, where a part held between two others may only
slide (a lid clamped on a rim, a drawer between rails). Polygons have an exact NDBG:
its regions (points and arcs of S¹) are examined instead (docs/blocking.md, "Three
kinds of motion").
"""

from __future__ import annotations

from collections.abc import Collection, Iterable
from dataclasses import dataclass
from functools import singledispatch

import networkx as nx
import numpy as np
from numpy.typing import NDArray

from assemblykit.blocking.constraints import BlockingTerm
from assemblykit.blocking.dbg import Removal
from assemblykit.blocking.directions import DirectionTable
from assemblykit.blocking.extended import extended_arcs, extended_free
from assemblykit.blocking.free_cones import blocked_sets, exact_free_directions, overlay_faces
from assemblykit.blocking.graphs import blocking_graph, blocking_terms
from assemblykit.blocking.ndbg import (
    Motion,
    NonDirectionalBlockingGraph,
    build_ndbg,
)
from assemblykit.deprecation import moved
from assemblykit.errors import UnknownNameError
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.model.assembly import Assembly, AssemblyLike
from assemblykit.model.polygons import PolygonAssembly
from assemblykit.tolerance import ModelTolerance, Tolerance

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
    assembly: AssemblyLike,
    subassembly: set[str],
    tol: ModelTolerance,
    among: Collection[str] | None = None,
) -> NonDirectionalBlockingGraph | None:
    """Γ_t of the contacts leaving ``subassembly`` for the other parts of ``among``
    (default: all) only (``None`` when it touches none)."""
    terms: list[BlockingTerm] = [
        t
        for t in blocking_terms(assembly, "infinitesimal", tol)
        if t.moving in subassembly
        and t.blocker not in subassembly
        and (among is None or t.blocker in among)
    ]
    if not terms:
        return None
    names = tuple(sorted(subassembly | {t.blocker for t in terms}))
    return build_ndbg(names, "infinitesimal", terms, 0, tol)


def _local_free_regions(
    assembly: AssemblyLike,
    subassembly: set[str],
    tol: ModelTolerance,
    among: Collection[str] | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.int8]]:
    """Directions and dimensions of the Γ_t regions where ``subassembly`` is locally
    free among ``among`` (default: all parts), faces first; the six axis directions (as
    faces) when it touches nothing."""
    graph = _local_graph(assembly, subassembly, tol, among)
    if graph is None:
        return _AXES, np.full(len(_AXES), 2, np.int8)
    dims = graph.arrangement.dims
    free = np.flatnonzero(~np.any(graph.packed, axis=1))
    order = free[np.lexsort((free, -dims[free]))]
    return graph.arrangement.directions[order], dims[order]


def _extra_directions(
    assembly: AssemblyLike,
    subassembly: set[str],
    tol: ModelTolerance,
    among: Collection[str] | None = None,
) -> NDArray[np.float64]:
    """The principal axes (both ways) of the moving parts' meshes and the unit normals
    of their contacts pointing away from the rest, kept where Γ_t leaves them locally
    free (module docstring)."""
    candidates = []
    for name in sorted(subassembly):
        mesh = assembly.parts[name].mesh  # type: ignore[attr-defined]
        candidates.extend([*mesh.principal_inertia_vectors, *-mesh.principal_inertia_vectors])
    for c in assembly_contacts(assembly, tol):
        if among is not None and not (c.a in among and c.b in among):
            continue
        if (c.a in subassembly) != (c.b in subassembly):
            away = -1.0 if c.a in subassembly else 1.0
            candidates.extend(away * np.asarray(p.normal, dtype=np.float64) for p in c.planar)
    if not candidates:
        return np.zeros((0, 3))
    directions = np.array(candidates, dtype=np.float64)
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    graph = _local_graph(assembly, subassembly, tol, among)
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
    removing any other part first, or ``None`` when there is none.

    Extended translations (docs/blocking.md, "Three kinds of motion"): in 3D the
    directions of the module docstring, each checked exactly, then those of the exact
    free set (:func:`assemblykit.blocking.free_cones.exact_free_directions`: its faces,
    then its arcs and points, for a part that may only slide); for polygons the regions
    of the exact NDBG (points and arcs of S¹) where the set is free, arcs first, as
    3-vectors with ``z = 0``."""
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
    if motion == "extended":
        return _extended_removal(assembly, moving, names, tol)
    directions, _ = _local_free_regions(assembly, moving, tol)
    return Removal(chosen, tuple(directions)) if len(directions) else None


@singledispatch
def _extended_removal(
    assembly: AssemblyLike, moving: set[str], among: Collection[str], tol: ModelTolerance
) -> Removal | None:
    """:func:`can_extract` by an extended translation among the parts ``among``,
    dispatched on the assembly's type: meshes (:func:`_mesh_removal`) or polygons
    (:func:`_planar_removal`)."""
    raise TypeError(f"no extended translations for a {type(assembly).__name__}")


@_extended_removal.register(Assembly)
def _mesh_removal(
    assembly: Assembly, moving: set[str], among: Collection[str], tol: ModelTolerance
) -> Removal | None:
    """:func:`_extended_removal` of meshes: none when Γ_t holds ``moving`` along every
    direction; else the locally free regions of Γ_t (the highest dimension first, the
    open free cone when it has one), the other regions, the principal axes and contact
    normals, each checked exactly; then the exact free set (faces, then arcs and
    points)."""
    chosen = frozenset(moving)
    directions, dims = _local_free_regions(assembly, moving, tol, among)
    if not len(dims):
        # Γ_t, a necessary condition, holds it along every direction
        return None
    top = dims == dims[0]
    extra = _extra_directions(assembly, moving, tol, among)
    for batch in (directions[top], directions[~top], extra):
        free = [d for d in batch if extended_free(assembly, moving, d, tol, among)]
        if free:
            return Removal(chosen, tuple(free))
    exact = exact_free_directions(assembly, moving, tol, among)
    if exact.directions:
        return Removal(chosen, exact.directions, exact.tolerance_dependent)
    return None


def _planar_table(
    model: PolygonAssembly, among: Collection[str], tol: ModelTolerance
) -> DirectionTable:
    """Γ_e of the polygons ``among`` over every region of its exact NDBG: the points and
    open arcs of S¹ (docs/blocking.md, "Three kinds of motion"), arcs first."""
    graph = blocking_graph(model, "extended", [n for n in model.names if n in among], tol)
    dims = graph.arrangement.dims
    table = graph.direction_table()
    order = np.lexsort((np.arange(len(dims)), -dims))
    return DirectionTable(
        table.names, table.directions[order], table.slots[order], table.moving, table.blocker
    )


def _planar_free(
    model: PolygonAssembly, moving: set[str], among: Collection[str], tol: ModelTolerance
) -> NDArray[np.float64]:
    """The directions of the regions of the exact NDBG of the polygons ``among`` along
    which ``moving`` leaves the others (:func:`_planar_table`)."""
    table = _planar_table(model, among, tol)
    inside = np.array([n in moving for n in table.names])
    leaving = inside[table.moving] & ~inside[table.blocker]
    free = ~np.any(table.slots[:, leaving], axis=1)
    found: NDArray[np.float64] = table.directions[free]
    return found


@_extended_removal.register(PolygonAssembly)
def _planar_removal(
    model: PolygonAssembly, moving: set[str], among: Collection[str], tol: ModelTolerance
) -> Removal | None:
    """:func:`_extended_removal` of polygons: the regions of their exact NDBG along which
    ``moving`` leaves (:func:`_planar_free`)."""
    exact = _planar_free(model, moving, among, tol)
    return Removal(frozenset(moving), tuple(exact)) if len(exact) else None


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


def removal_before(assembly: AssemblyLike, part: str, tol: Tolerance | None = None) -> Prerequisite:
    """The fewest parts to remove before ``part`` can leave by an extended translation,
    over all directions (Wilson & Latombe 1992 §5): the directions are one per face of
    the overlay of the sets each other part blocks (over a face, the parts blocking
    ``part`` are constant) and one per arc and point of the circles where those sets
    meet without a gap (:func:`assemblykit.blocking.free_cones.overlay_faces`: a part
    that leaves by sliding between two others, or only after one that slides), so
    every set of direct blockers is seen; the sets are tried smallest first, and the
    first whose parts can be taken out one at a time (each by an extended translation,
    a slide included) is the answer. Polygons: the same over the regions of their
    exact NDBG (docs/blocking.md, "Questions (Python)")."""
    if part not in assembly.names:
        raise UnknownNameError(f"no part named {part!r}")
    tol = assembly.tolerance(tol)
    return _removal_before(assembly, part, list(assembly.names), tol)


@singledispatch
def _removal_before(
    assembly: AssemblyLike, part: str, names: list[str], tol: ModelTolerance
) -> Prerequisite:
    """:func:`removal_before`, dispatched on the assembly's type: meshes
    (:func:`_mesh_removal_before`) or polygons (:func:`_planar_removal_before`)."""
    raise TypeError(f"no extended translations for a {type(assembly).__name__}")


@_removal_before.register(Assembly)
def _mesh_removal_before(
    assembly: Assembly, part: str, names: list[str], tol: ModelTolerance
) -> Prerequisite:
    """:func:`removal_before` of meshes: over the faces of the overlay of the sets the
    other parts block and the arcs and points where they meet (:func:`removal_before`)."""
    others = [n for n in names if n != part]
    sets = blocked_sets(assembly, [part], names, tol)
    if sets is None:
        directions = np.vstack([_AXES, *locally_free_directions(assembly, [part], tol)])
    else:
        faces = overlay_faces(list(sets.values()), tol)
        directions = np.vstack([faces.directions, faces.thin]).reshape(-1, 3)
    options: dict[frozenset[str], NDArray[np.float64]] = {}
    for d in directions:
        # the blocked sets say who blocks along d; the direction kept for each set is
        # checked exactly below
        if sets is None:
            blockers = frozenset(j for _, j in extended_arcs(assembly, d, [part], others, tol))
        else:
            blockers = frozenset(j for j, blocked in sets.items() if blocked.contains(d, tol))
        options.setdefault(blockers, d)
    for blockers, d in list(options.items()):
        exact = frozenset(j for _, j in extended_arcs(assembly, d, [part], others, tol))
        if exact != blockers:
            del options[blockers]
            options.setdefault(exact, d)
    return _first_removable(assembly, part, options, names, tol, sets is not None)


def _first_removable(
    assembly: AssemblyLike,
    part: str,
    options: dict[frozenset[str], NDArray[np.float64]],
    names: list[str],
    tol: ModelTolerance,
    complete: bool,
) -> Prerequisite:
    """The smallest set of ``options`` (each with a direction along which ``part`` leaves
    once it is gone) whose parts can be taken out first; minimal when the options are
    every set of direct blockers (``complete``) and it is one of the smallest; else
    every other part, not minimal."""
    smallest = min((len(r) for r in options), default=0)
    for blockers in sorted(options, key=lambda r: (len(r), sorted(r))):
        if _removable_first(assembly, blockers, names, tol):
            minimal = complete and len(blockers) == smallest
            return Prerequisite(part, blockers, options[blockers], minimal)
    return Prerequisite(part, frozenset(n for n in names if n != part), None, False)


@_removal_before.register(PolygonAssembly)
def _planar_removal_before(
    model: PolygonAssembly, part: str, names: list[str], tol: ModelTolerance
) -> Prerequisite:
    """:func:`removal_before` of polygons: the parts blocking ``part`` over each region
    of the exact NDBG (points and arcs of S¹), so every set of direct blockers is seen."""
    table = _planar_table(model, names, tol)
    index = table.names.index(part)
    mine = table.moving == index
    options: dict[frozenset[str], NDArray[np.float64]] = {}
    for d, row in zip(table.directions, table.slots[:, mine], strict=True):
        blockers = frozenset(table.names[j] for j in table.blocker[mine][row])
        options.setdefault(blockers, d)
    return _first_removable(model, part, options, names, tol, True)


def _removable_first(
    assembly: AssemblyLike, chosen: frozenset[str], names: list[str], tol: ModelTolerance
) -> bool:
    """Whether the parts of ``chosen`` can be taken out of ``names`` one at a time, each
    by an extended translation among the parts still there (:func:`_extended_removal`,
    slides included; polygons: :func:`_planar_free`). Removing parts only removes
    obstacles, so any part that can leave may leave first."""
    remaining, pending = set(names), set(chosen)
    while pending:
        leaving = next((r for r in sorted(pending) if _leaves(assembly, r, remaining, tol)), None)
        if leaving is None:
            return False
        pending.discard(leaving)
        remaining.discard(leaving)
    return True


def _leaves(assembly: AssemblyLike, name: str, among: set[str], tol: ModelTolerance) -> bool:
    """Whether the part ``name`` leaves the other parts of ``among`` by one extended
    translation."""
    return _extended_removal(assembly, {name}, among, tol) is not None


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
        return removal_before(assembly, part, tol).parts
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
