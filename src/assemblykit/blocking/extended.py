"""Blocking for extended translations, Γ_e (seed 004, "Extended translations").

Part ``j`` blocks part ``i`` along ``d`` iff ``i`` swept along ``d`` to infinity meets
``j``: iff ``d`` lies in the open cone of the grown obstacle ``P_j ⊕ (−P_i)``
(:mod:`assemblykit.geometry.minkowski`). With convex pieces, each pair of pieces gives
one cone term, and the pair blocks iff one of its cones contains ``d``; ``P_i`` is
blocked by ``P_j`` along ``−B`` when ``P_j`` is blocked by ``P_i`` along ``B``.

For the NDBG every pair of parts is needed (any two parts block each other along some
direction). For one direction, :func:`extended_dbg` only examines the pairs whose
bounding spheres can meet during the sweep, which makes single-direction queries on
large assemblies cheap.
"""

from __future__ import annotations

import itertools
import weakref
from typing import Any

import numpy as np
from numpy.typing import NDArray

from assemblykit.blocking.constraints import BlockingTerm
from assemblykit.blocking.dbg import DirectionalBlockingGraph
from assemblykit.geometry.minkowski import blocking_cone, blocks_along, convex_pieces
from assemblykit.tolerance import Tolerance


class _Obstacles:
    """Convex pieces, bounding spheres and pairwise cones of one assembly's parts."""

    def __init__(self, assembly: Any) -> None:
        self.assembly = assembly
        self.pieces: dict[str, list[NDArray[np.float64]]] = {}
        self.cones: dict[tuple[str, str, Tolerance], list[NDArray[np.float64]]] = {}
        names = list(assembly.names)
        self.names = names
        bounds = np.array([assembly.parts[n].mesh.bounds for n in names]).reshape(-1, 2, 3)
        self.centers = bounds.mean(axis=1)
        self.radii = np.linalg.norm(bounds[:, 1] - bounds[:, 0], axis=1) / 2

    def of(self, name: str) -> list[NDArray[np.float64]]:
        if name not in self.pieces:
            self.pieces[name] = convex_pieces(self.assembly.parts[name].mesh)
        return self.pieces[name]

    def cones_of(self, moving: str, blocker: str, tol: Tolerance) -> list[NDArray[np.float64]]:
        """The cones along which ``blocker`` blocks ``moving``."""
        key = (moving, blocker, tol)
        if key not in self.cones:
            flipped = (blocker, moving, tol)
            if flipped in self.cones:
                self.cones[key] = [-c for c in self.cones[flipped]]
            else:
                self.cones[key] = [
                    blocking_cone(q, p, tol)
                    for p, q in itertools.product(self.of(moving), self.of(blocker))
                ]
        return self.cones[key]


_CACHE: weakref.WeakKeyDictionary[Any, _Obstacles] = weakref.WeakKeyDictionary()


def obstacles(assembly: Any) -> _Obstacles:
    """The obstacle cache of an assembly (computed lazily, kept while it lives)."""
    if assembly not in _CACHE:
        _CACHE[assembly] = _Obstacles(assembly)
    return _CACHE[assembly]


def extended_terms(assembly: Any, tol: Tolerance) -> list[BlockingTerm]:
    """One cone term per pair of convex pieces of every pair of parts, both ways."""
    cache = obstacles(assembly)
    terms: list[BlockingTerm] = []
    for a, b in itertools.combinations(cache.names, 2):
        for cone in cache.cones_of(a, b, tol):
            terms.append(BlockingTerm(a, b, cone))
            terms.append(BlockingTerm(b, a, -cone))
    return terms


def sweep_candidates(assembly: Any, moving: str, direction: NDArray[np.float64]) -> list[str]:
    """Parts whose bounding spheres the bounding sphere of ``moving`` meets when swept
    along ``direction`` to infinity (a superset of its possible blockers)."""
    cache = obstacles(assembly)
    i = cache.names.index(moving)
    rel = cache.centers - cache.centers[i]
    along = rel @ direction
    across = np.linalg.norm(rel - along[:, None] * direction, axis=1)
    reach = cache.radii + cache.radii[i]
    near = np.where(along > 0, across, np.linalg.norm(rel, axis=1)) <= reach
    return [n for k, n in enumerate(cache.names) if near[k] and k != i]


def extended_dbg(
    assembly: Any, direction: NDArray[np.float64], parts: tuple[str, ...], tol: Tolerance
) -> DirectionalBlockingGraph:
    """G(d, A) for extended translations along one direction, over ``parts``."""
    d = np.asarray(direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    inside = set(parts)
    cache = obstacles(assembly)
    arcs = set()
    for moving in parts:
        for blocker in sweep_candidates(assembly, moving, d):
            if blocker in inside and any(
                blocks_along(cone, d)[0] for cone in cache.cones_of(moving, blocker, tol)
            ):
                arcs.add((moving, blocker))
    return DirectionalBlockingGraph(parts, d, frozenset(arcs))
