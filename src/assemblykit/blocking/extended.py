"""Blocking for extended translations, Γ_e (Wilson & Latombe 1992, "Extended translations").

Part ``j`` blocks part ``i`` along ``d`` iff ``i`` swept along ``d`` to infinity meets
the interior of ``j``. Two exact tests decide it, both here and nowhere else:

* both parts made of convex bodies: ``d`` lies in the open cone of one grown obstacle
  ``Q ⊕ (−P)`` of a pair of bodies (:mod:`assemblykit.geometry.minkowski`); the cones
  are computed once per pair and serve every direction, and their great circles give
  the exact NDBG (regions over which the DBG is constant);
* otherwise, one direction at a time, by projecting both meshes on the plane ``⟂ d``
  and comparing the depths of overlapping triangles
  (:mod:`assemblykit.geometry.occlusion`).

Before either, the pairs are narrowed to those whose bounding spheres the sweep of the
moving one can meet. A pair that shares a volume the interference policy counts as
touching (:func:`assemblykit.geometry.interference.interference_threshold`; COMPAS
vault blocks whose generated faces overlap by a few 1e-4) is tested with the moving part
backed out of the other by their separation
(:func:`assemblykit.geometry.settling.settle`): a layer the data cannot resolve is a
contact, not an obstacle in every direction. Bodies, spheres, cones and back-outs are
the assembly's :class:`~assemblykit.blocking.obstacles.Obstacles`, kept in its
:class:`~assemblykit.blocking.cache.BlockingCache`.

:func:`extended_dbg` is G(d, A) over any parts; the planner and the queries ask it (or
:func:`extended_free`) for every direction they accept, so each reported removal is
exact. For assemblies with non-convex parts the NDBG is sampled: its regions are those
of Γ_t (contacts) and each region's DBG is exact at the region's direction
(:func:`assemblykit.blocking.graphs.sampled_ndbg`).
"""

from __future__ import annotations

import itertools
from collections.abc import Collection, Iterable, Mapping, Sequence
from functools import singledispatch
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from assemblykit.blocking.cache import BlockingCache
from assemblykit.blocking.constraints import BlockingTerm
from assemblykit.blocking.dbg import DirectionalBlockingGraph
from assemblykit.blocking.lattice import cells_block, lattice_direction
from assemblykit.geometry.minkowski import blocks_along
from assemblykit.geometry.occlusion import (
    blocking_witnesses,
    faces_near_outlines,
    hulls_may_block,
    shadows,
    view_frame,
    witnesses_hold_along,
)
from assemblykit.model.assembly import Assembly, AssemblyLike
from assemblykit.tolerance import ModelTolerance

if TYPE_CHECKING:
    from assemblykit.blocking.obstacles import Obstacles


def all_convex(assembly: Assembly, parts: Iterable[str]) -> bool:
    """Whether every part is a union of convex bodies (the cone NDBG is then exact)."""
    cache = BlockingCache.of(assembly).obstacles
    return all(cache.convex(name) for name in parts)


def extended_terms(
    assembly: Assembly, tol: ModelTolerance, parts: Iterable[str] | None = None
) -> list[BlockingTerm]:
    """One cone term per pair of convex bodies of every pair of ``parts`` (default: all),
    both ways (those parts must be unions of convex bodies, :func:`all_convex`)."""
    cache = BlockingCache.of(assembly).obstacles
    terms: list[BlockingTerm] = []
    for a, b in itertools.combinations(cache.names if parts is None else parts, 2):
        for cone in cache.cones_of(a, b, tol):
            terms.append(BlockingTerm(a, b, cone))
            terms.append(BlockingTerm(b, a, -cone))
    return terms


@singledispatch
def exact_extended(assembly: AssemblyLike, parts: Iterable[str]) -> bool:
    """Whether the NDBG of Γ_e of the ``parts`` of ``assembly`` built from its terms
    (:func:`assembly_extended_terms`) is exact, dispatched on the assembly's type: for
    an :class:`~assemblykit.model.assembly.Assembly` when those parts are unions of
    convex bodies (:func:`all_convex`); polygons register theirs
    (:mod:`assemblykit.blocking.planar`: always)."""
    raise TypeError(f"no extended translations for a {type(assembly).__name__}")


exact_extended.register(Assembly, all_convex)


@singledispatch
def assembly_extended_terms(assembly: AssemblyLike, tol: ModelTolerance) -> list[BlockingTerm]:
    """The Γ_e terms of the whole assembly, dispatched on its type: the cones between
    the convex bodies of an :class:`~assemblykit.model.assembly.Assembly`'s meshes
    (:func:`extended_terms`); polygons register theirs
    (:func:`assemblykit.blocking.planar.planar_extended_terms`)."""
    raise TypeError(f"no extended translations for a {type(assembly).__name__}")


assembly_extended_terms.register(Assembly, extended_terms)


def sweep_candidates(
    assembly: Assembly, movers: list[str], direction: NDArray[np.float64], among: Iterable[str]
) -> list[list[str]]:
    """Per part of ``movers``, the other parts of ``among`` whose bounding spheres its
    bounding sphere meets when swept along ``direction`` to infinity (a superset of its
    possible blockers), for all movers at once."""
    cache = BlockingCache.of(assembly).obstacles
    index = {name: k for k, name in enumerate(cache.names)}
    rows = np.array([index[name] for name in movers], dtype=np.int64)
    columns = np.array(sorted({index[name] for name in among}), dtype=np.int64)
    rel = cache.centers[columns][None, :, :] - cache.centers[rows][:, None, :]
    along = rel @ direction
    across = np.linalg.norm(rel - along[:, :, None] * direction, axis=2)
    reach = cache.radii[columns][None, :] + cache.radii[rows][:, None]
    near = np.where(along > 0, across, np.linalg.norm(rel, axis=2)) <= reach
    near &= rows[:, None] != columns[None, :]
    return [[cache.names[columns[k]] for k in np.flatnonzero(row)] for row in near]


def extended_arcs(
    assembly: Assembly,
    direction: ArrayLike,
    movers: Iterable[str],
    blockers: Iterable[str],
    tol: ModelTolerance,
    *,
    first_only: bool = False,
    known: Collection[tuple[str, str]] | None = None,
) -> set[tuple[str, str]]:
    """The arcs ``(i, j)``, ``i`` among ``movers`` and ``j ≠ i`` among ``blockers``,
    such that ``j`` blocks the extended translation of ``i`` along ``direction``: cones
    for pairs of convex parts, the projection test for the others (all of their pairs at
    once: one projection of each mesh serves every pair, so no coarser test first).
    With ``first_only``, at least one arc of each blocked mover and maybe no more:
    which movers leave, at the cost of finding one blocker each. ``known``, when given,
    are pairs already shown blocking along ``direction`` (by the faces kept for them,
    :func:`shown_along`): they are arcs without a test, and the faces kept for the
    other pairs are not asked again. Parts all made of unit cells are decided on their
    cells along a lattice direction (:mod:`assemblykit.blocking.lattice`), every arc
    found."""
    d = np.asarray(direction, dtype=np.float64).ravel()
    d = d / np.linalg.norm(d)
    cache = BlockingCache.of(assembly).obstacles
    moving_parts, still = list(movers), list(blockers)
    found = _lattice_arcs(cache, d, moving_parts, still, tol)
    if found is not None:
        return found
    return projected_arcs(assembly, d, moving_parts, still, tol, first_only=first_only, known=known)


def _lattice_arcs(
    cache: Obstacles,
    direction: NDArray[np.float64],
    movers: list[str],
    blockers: list[str],
    tol: ModelTolerance,
) -> set[tuple[str, str]] | None:
    """The arcs of :func:`extended_arcs` when every part is made of unit cells and
    ``direction`` is a lattice direction (:func:`~assemblykit.blocking.lattice.cells_block`);
    ``None`` otherwise."""
    lattice = lattice_direction(direction, tol)
    if lattice is None:
        return None
    cells = {name: cache.cells(name) for name in {*movers, *blockers}}
    if any(found is None for found in cells.values()):
        return None
    return {
        (moving, blocker)
        for moving in movers
        for blocker in blockers
        if blocker != moving and cells_block(cells[moving], cells[blocker], lattice)  # type: ignore[arg-type]
    }


def projected_arcs(
    assembly: Assembly,
    d: NDArray[np.float64],
    moving_parts: list[str],
    blockers: list[str],
    tol: ModelTolerance,
    *,
    first_only: bool = False,
    known: Collection[tuple[str, str]] | None = None,
) -> set[tuple[str, str]]:
    """:func:`extended_arcs` on the parts' meshes, along the unit direction ``d``: cones
    for pairs of convex parts, the projection test for the others; a pair left
    interfering (:attr:`~assemblykit.model.assembly.Assembly.overlaps`, resolution
    ``""``) blocks along every direction, with no test."""
    cache = BlockingCache.of(assembly).obstacles
    near_parts = sweep_candidates(assembly, moving_parts, d, blockers)
    held = {frozenset((o.a, o.b)) for o in getattr(assembly, "overlaps", ()) if not o.resolution}
    arcs: set[tuple[str, str]] = set()
    projected: list[tuple[str, str]] = []
    for moving, near in zip(moving_parts, near_parts, strict=True):
        for blocker in near:
            if frozenset((moving, blocker)) in held:
                arcs.add((moving, blocker))
            elif not (cache.convex(moving) and cache.convex(blocker)):
                projected.append((moving, blocker))
            elif any(
                blocks_along(c, d, tol.angle)[0] for c in cache.cones_of(moving, blocker, tol)
            ):
                arcs.add((moving, blocker))
    plain = [pair for pair in projected if not cache.backout(*pair, tol).any()]
    if known is not None:
        arcs |= {pair for pair in plain if pair in known}
        plain = _may_block(cache, d, [pair for pair in plain if pair not in known], tol)
    else:
        plain = _may_block(cache, d, plain, tol)
        witnessed = shown_pairs(assembly, d, plain, tol)
        arcs |= witnessed
        plain = [pair for pair in plain if pair not in witnessed]
    if first_only:
        blocked = {moving for moving, _ in arcs}
        plain = [pair for pair in plain if pair[0] not in blocked]
    arcs |= _occluded(assembly, d, plain, {}, tol, first_only)
    for moving, blocker in projected:
        if first_only and any(a == moving for a, _ in arcs):
            continue
        shift = cache.backout(moving, blocker, tol)
        if shift.any():
            arcs |= _occluded(assembly, d, [(moving, blocker)], {moving: shift}, tol)
    return arcs


def shown_arcs(
    assembly: Assembly,
    direction: ArrayLike,
    movers: Iterable[str],
    blockers: Iterable[str],
    tol: ModelTolerance,
) -> set[tuple[str, str]]:
    """Some of the arcs of :func:`extended_arcs`, found without projecting a mesh: the
    pairs where the two faces that showed a block along another direction show it along
    this one (:func:`~assemblykit.geometry.occlusion.witnesses_hold`). Every arc
    returned is an arc of Γ_e; a pair not returned may block all the same."""
    d = np.asarray(direction, dtype=np.float64).ravel()
    cache = BlockingCache.of(assembly).obstacles
    others = list(blockers)
    pairs = [(m, b) for m in movers for b in others if (m, b) in cache.witnesses]
    return shown_pairs(assembly, d / np.linalg.norm(d), pairs, tol)


def _may_block(
    cache: Obstacles,
    direction: NDArray[np.float64],
    pairs: list[tuple[str, str]],
    tol: ModelTolerance,
) -> list[tuple[str, str]]:
    """The pairs (moving, blocker) of ``pairs`` whose convex hulls allow a block along
    ``direction`` (:func:`~assemblykit.geometry.occlusion.hulls_may_block`): the others
    need no projection of their meshes."""
    if not pairs:
        return pairs
    names = sorted({name for pair in pairs for name in pair})
    index = {name: k for k, name in enumerate(names)}
    rows = np.array([(index[a], index[b]) for a, b in pairs], dtype=np.int64)
    keep = hulls_may_block([cache.hull(n) for n in names], rows, direction, tol)
    return [pair for pair, kept in zip(pairs, keep.tolist(), strict=True) if kept]


def shown_pairs(
    assembly: Assembly,
    direction: NDArray[np.float64],
    pairs: list[tuple[str, str]],
    tol: ModelTolerance,
) -> set[tuple[str, str]]:
    """The pairs (moving, blocker) of ``pairs`` that block along the unit ``direction`` as shown by
    some two faces that showed it along another direction (kept in the assembly's
    :class:`~assemblykit.blocking.obstacles.Obstacles`, a few per pair): a few triangles
    projected instead of two meshes. A part blocked along one direction mostly is along
    the next ones the search tries, by the same faces."""
    kept = BlockingCache.of(assembly).obstacles.witnesses
    shown = shown_along(
        assembly,
        view_frame(direction)[None],
        {pair: kept[pair] for pair in pairs if pair in kept},
        tol,
    )
    return {pair for pair, along in shown.items() if along[0]}


def shown_along(
    assembly: Assembly,
    frames: NDArray[np.float64],
    witnesses: Mapping[tuple[str, str], Sequence[tuple[int, int]]],
    tol: ModelTolerance,
) -> dict[tuple[str, str], NDArray[np.bool_]]:
    """Per pair (moving, blocker) of ``witnesses``, whether some of the pairs of faces
    given for it (blocking witnesses, as
    :meth:`~assemblykit.blocking.obstacles.Obstacles.keep_witness` keeps them) show it
    blocking along the direction of each of the view ``frames``
    (:func:`~assemblykit.geometry.occlusion.view_frame`): :func:`shown_arcs` along many
    directions at once (:func:`~assemblykit.geometry.occlusion.witnesses_hold_along`)."""
    pairs = [pair for pair, faces in witnesses.items() if faces]
    if not pairs:
        return {}
    names = sorted({name for pair in pairs for name in pair})
    index = {name: k for k, name in enumerate(names)}
    owners = np.repeat(np.arange(len(pairs)), [len(witnesses[pair]) for pair in pairs])
    table = [(index[a], index[b], *faces) for a, b in pairs for faces in witnesses[(a, b)]]
    meshes = [assembly.parts[name].mesh for name in names]
    holds = witnesses_hold_along(meshes, table, frames, tol)
    shown = np.zeros((len(pairs), len(frames)), dtype=bool)
    np.logical_or.at(shown, owners, holds)
    return dict(zip(pairs, shown, strict=True))


def _occluded(
    assembly: Assembly,
    direction: NDArray[np.float64],
    pairs: list[tuple[str, str]],
    shifts: dict[str, NDArray[np.float64]],
    tol: ModelTolerance,
    first_only: bool = False,
) -> set[tuple[str, str]]:
    """Which of ``pairs`` (moving, blocker) block along ``direction`` by the projection
    test, parts in ``shifts`` translated by them first (with ``first_only``, one pair
    at least of each blocked moving part: :func:`extended_arcs`)."""
    if not pairs:
        return set()
    names = sorted({name for pair in pairs for name in pair})
    index = {name: k for k, name in enumerate(names)}
    allowed = np.zeros((len(names), len(names)), dtype=bool)
    for moving, blocker in pairs:
        allowed[index[moving], index[blocker]] = True
    meshes = [assembly.parts[name].mesh for name in names]
    faces = None
    if shifts:
        meshes = [
            mesh.copy().apply_translation(shifts[name]) if name in shifts else mesh
            for name, mesh in zip(names, meshes, strict=True)
        ]
    else:
        # only the faces that may meet the other part's outline are projected
        cache = BlockingCache.of(assembly).obstacles
        faces = faces_near_outlines(
            [cache.spheres(name) for name in names],
            [cache.hull(name) for name in names],
            np.argwhere(allowed),
            direction,
            tol,
        )
    view = shadows(meshes, direction, tol, faces)
    found = blocking_witnesses(view, allowed, tol, first_only=first_only)
    if not shifts:
        cache = BlockingCache.of(assembly).obstacles
        for (i, j), shown in found.items():
            cache.keep_witness((names[i], names[j]), shown)
    return {(names[i], names[j]) for i, j in found}


def extended_dbg(
    assembly: Assembly, direction: ArrayLike, parts: tuple[str, ...], tol: ModelTolerance
) -> DirectionalBlockingGraph:
    """G(d, A) for extended translations along one direction, over ``parts`` (exact)."""
    d = np.asarray(direction, dtype=np.float64).ravel()
    d = d / np.linalg.norm(d)
    return DirectionalBlockingGraph(
        tuple(parts), d, frozenset(extended_arcs(assembly, d, parts, parts, tol))
    )


def extended_free(
    assembly: Assembly,
    subassembly: Iterable[str],
    direction: ArrayLike,
    tol: ModelTolerance,
    among: Iterable[str] | None = None,
) -> bool:
    """Whether ``subassembly`` leaves the other parts of ``among`` (default: all) by one
    extended translation along ``direction`` (exact)."""
    moving = set(subassembly)
    rest = set(assembly.names if among is None else among) - moving
    return not extended_arcs(assembly, direction, sorted(moving), sorted(rest), tol)
