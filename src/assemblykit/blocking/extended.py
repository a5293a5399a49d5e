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
contact, not an obstacle in every direction.

:func:`extended_dbg` is G(d, A) over any parts; the planner and the queries ask it (or
:func:`extended_free`) for every direction they accept, so each reported removal is
exact. For assemblies with non-convex parts the NDBG is sampled: its regions are those
of Γ_t (contacts) and each region's DBG is exact at the region's direction
(:func:`sampled_ndbg`).
"""

from __future__ import annotations

import itertools
import weakref
from collections.abc import Iterable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from assemblykit.blocking.constraints import BlockingTerm
from assemblykit.blocking.dbg import DirectionalBlockingGraph
from assemblykit.blocking.ndbg import ConstraintTable, NonDirectionalBlockingGraph
from assemblykit.geometry.interference import interference_threshold, overlap_volume
from assemblykit.geometry.minkowski import blocking_cone, blocks_along, convex_bodies
from assemblykit.geometry.occlusion import occluded_pairs, shadows
from assemblykit.geometry.settling import settle
from assemblykit.tolerance import Tolerance


class _Obstacles:
    """Convex bodies, bounding spheres and pairwise cones of one assembly's parts."""

    def __init__(self, assembly: Any) -> None:
        self.assembly = assembly
        self.pieces: dict[str, list[NDArray[np.float64]] | None] = {}
        self.cones: dict[tuple[str, str, Tolerance], list[NDArray[np.float64]]] = {}
        self.backouts: dict[tuple[str, str, Tolerance], NDArray[np.float64]] = {}
        # exact blocked sets (free_cones.blocked_by), by moving parts, blocker, tolerance
        self.blocked: dict[tuple[tuple[str, ...], str, Tolerance], Any] = {}
        names = list(assembly.names)
        self.names = names
        bounds = np.array([assembly.parts[n].mesh.bounds for n in names]).reshape(-1, 2, 3)
        self.centers = bounds.mean(axis=1)
        self.radii = np.linalg.norm(bounds[:, 1] - bounds[:, 0], axis=1) / 2

    def of(self, name: str) -> list[NDArray[np.float64]] | None:
        """The convex bodies of a part, ``None`` when one of them is not convex."""
        if name not in self.pieces:
            self.pieces[name] = convex_bodies(
                self.assembly.parts[name].mesh, self.assembly.tolerance()
            )
        return self.pieces[name]

    def convex(self, name: str) -> bool:
        """Whether the part is a union of convex bodies (cones are exact for it)."""
        return self.of(name) is not None

    def hulls(self, name: str) -> list[NDArray[np.float64]]:
        """The convex bodies of a convex part, else the part's convex hull (its vertices):
        a hull contains the part, so a direction its cones leave free is free for the part."""
        pieces = self.of(name)
        if pieces is not None:
            return pieces
        return [np.asarray(self.assembly.parts[name].mesh.convex_hull.vertices, dtype=np.float64)]

    def backout(self, moving: str, blocker: str, tol: Tolerance) -> NDArray[np.float64]:
        """The translation that backs ``moving`` out of ``blocker`` before blocking is
        decided: their separation when they share a volume counted as touching (module
        docstring) and it is longer than the length tolerance the tests allow anyway,
        else zero."""
        key = (moving, blocker, tol)
        if key not in self.backouts:
            flipped = (blocker, moving, tol)
            if flipped in self.backouts:
                self.backouts[key] = -self.backouts[flipped]
            else:
                a, b = self.assembly.parts[moving].mesh, self.assembly.parts[blocker].mesh
                shift = np.zeros(3)
                if 0 < overlap_volume(a, b) <= interference_threshold(a, b, tol):
                    shifts = settle([a, b], [(0, 1)]).shifts
                    if np.linalg.norm(shifts[0] - shifts[1]) > tol.length:
                        shift = shifts[0] - shifts[1]
                self.backouts[key] = shift
        return self.backouts[key]

    def cones_of(self, moving: str, blocker: str, tol: Tolerance) -> list[NDArray[np.float64]]:
        """The cones along which ``blocker`` blocks ``moving``: exact for convex parts, a
        superset (the hulls' cones) otherwise. For convex parts, an empty cone (they
        overlap) is recomputed with ``moving`` backed out of ``blocker``
        (:meth:`backout`); other parts go to the projection test, which backs them out."""
        key = (moving, blocker, tol)
        if key not in self.cones:
            flipped = (blocker, moving, tol)
            if flipped in self.cones:
                self.cones[key] = [-c for c in self.cones[flipped]]
            else:
                self.cones[key] = self._cones(moving, blocker, tol, np.zeros(3))
                convex = self.convex(moving) and self.convex(blocker)
                if convex and any(len(c) == 0 for c in self.cones[key]):
                    shift = self.backout(moving, blocker, tol)
                    if shift.any():
                        self.cones[key] = self._cones(moving, blocker, tol, shift)
        return self.cones[key]

    def _cones(
        self, moving: str, blocker: str, tol: Tolerance, shift: NDArray[np.float64]
    ) -> list[NDArray[np.float64]]:
        return [
            blocking_cone(q, p + shift, tol)
            for p, q in itertools.product(self.hulls(moving), self.hulls(blocker))
        ]


_CACHE: weakref.WeakKeyDictionary[Any, _Obstacles] = weakref.WeakKeyDictionary()


def obstacles(assembly: Any) -> _Obstacles:
    """The obstacle cache of an assembly (computed lazily, kept while it lives)."""
    if assembly not in _CACHE:
        _CACHE[assembly] = _Obstacles(assembly)
    return _CACHE[assembly]


def all_convex(assembly: Any, parts: Iterable[str]) -> bool:
    """Whether every part is a union of convex bodies (the cone NDBG is then exact)."""
    cache = obstacles(assembly)
    return all(cache.convex(name) for name in parts)


def extended_terms(assembly: Any, tol: Tolerance) -> list[BlockingTerm]:
    """One cone term per pair of convex bodies of every pair of parts, both ways (all
    parts must be unions of convex bodies, :func:`all_convex`)."""
    cache = obstacles(assembly)
    terms: list[BlockingTerm] = []
    for a, b in itertools.combinations(cache.names, 2):
        for cone in cache.cones_of(a, b, tol):
            terms.append(BlockingTerm(a, b, cone))
            terms.append(BlockingTerm(b, a, -cone))
    return terms


def sweep_candidates(
    assembly: Any, movers: list[str], direction: NDArray[np.float64], among: Iterable[str]
) -> list[list[str]]:
    """Per part of ``movers``, the other parts of ``among`` whose bounding spheres its
    bounding sphere meets when swept along ``direction`` to infinity (a superset of its
    possible blockers), for all movers at once."""
    cache = obstacles(assembly)
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
    assembly: Any,
    direction: ArrayLike,
    movers: Iterable[str],
    blockers: Iterable[str],
    tol: Tolerance,
) -> set[tuple[str, str]]:
    """The arcs ``(i, j)``, ``i`` among ``movers`` and ``j ≠ i`` among ``blockers``,
    such that ``j`` blocks the extended translation of ``i`` along ``direction``: cones
    for pairs of convex parts; for the others the hulls' cones first (a free direction for
    the hulls is free for the parts) and the projection test where they block."""
    d = np.asarray(direction, dtype=np.float64).ravel()
    d = d / np.linalg.norm(d)
    cache = obstacles(assembly)
    moving_parts = list(movers)
    near_parts = sweep_candidates(assembly, moving_parts, d, blockers)
    arcs: set[tuple[str, str]] = set()
    projected: list[tuple[str, str]] = []
    for moving, near in zip(moving_parts, near_parts, strict=True):
        for blocker in near:
            if not any(blocks_along(c, d)[0] for c in cache.cones_of(moving, blocker, tol)):
                continue
            if cache.convex(moving) and cache.convex(blocker):
                arcs.add((moving, blocker))
            else:
                projected.append((moving, blocker))
    plain = [pair for pair in projected if not cache.backout(*pair, tol).any()]
    arcs |= _occluded(assembly, d, plain, {}, tol)
    for moving, blocker in projected:
        shift = cache.backout(moving, blocker, tol)
        if shift.any():
            arcs |= _occluded(assembly, d, [(moving, blocker)], {moving: shift}, tol)
    return arcs


def _occluded(
    assembly: Any,
    direction: NDArray[np.float64],
    pairs: list[tuple[str, str]],
    shifts: dict[str, NDArray[np.float64]],
    tol: Tolerance,
) -> set[tuple[str, str]]:
    """Which of ``pairs`` (moving, blocker) block along ``direction`` by the projection
    test, parts in ``shifts`` translated by them first."""
    if not pairs:
        return set()
    names = sorted({name for pair in pairs for name in pair})
    index = {name: k for k, name in enumerate(names)}
    allowed = np.zeros((len(names), len(names)), dtype=bool)
    for moving, blocker in pairs:
        allowed[index[moving], index[blocker]] = True
    meshes = [assembly.parts[name].mesh for name in names]
    meshes = [
        mesh.copy().apply_translation(shifts[name]) if name in shifts else mesh
        for name, mesh in zip(names, meshes, strict=True)
    ]
    view = shadows(meshes, direction, tol)
    return {(names[i], names[j]) for i, j in occluded_pairs(view, allowed, tol)}


def extended_dbg(
    assembly: Any, direction: ArrayLike, parts: tuple[str, ...], tol: Tolerance
) -> DirectionalBlockingGraph:
    """G(d, A) for extended translations along one direction, over ``parts`` (exact)."""
    d = np.asarray(direction, dtype=np.float64).ravel()
    d = d / np.linalg.norm(d)
    return DirectionalBlockingGraph(
        tuple(parts), d, frozenset(extended_arcs(assembly, d, parts, parts, tol))
    )


def extended_free(
    assembly: Any,
    subassembly: Iterable[str],
    direction: ArrayLike,
    tol: Tolerance,
    among: Iterable[str] | None = None,
) -> bool:
    """Whether ``subassembly`` leaves the other parts of ``among`` (default: all) by one
    extended translation along ``direction`` (exact)."""
    moving = set(subassembly)
    rest = set(assembly.names if among is None else among) - moving
    return not extended_arcs(assembly, direction, sorted(moving), sorted(rest), tol)


def sampled_ndbg(
    assembly: Any, parts: tuple[str, ...], local: NonDirectionalBlockingGraph, tol: Tolerance
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
