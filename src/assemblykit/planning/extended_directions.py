"""Γ_e, the NDBG of extended translations, along the planner's candidate directions, as
the search asks for it (Wilson & Latombe 1992, "Extended translations").

Γ_e is *sufficient*: a set with no arc leaving it in the DBG of Γ_e along ``d`` is taken
out by one straight translation, and only such removals are accepted as steps. Its DBG
along a candidate direction is computed exactly
(:func:`assemblykit.blocking.extended.extended_arcs`, also for parts with holes and
slots), only for the pairs the search asks about, and kept
(:class:`ExtendedDirections`). Blocking is pairwise (whether P_j blocks P_i along d does
not depend on the other parts), so the DBG of a subassembly is the induced subgraph of
the assembly's DBG, and the pairs tested for one node of the search serve every other
(docs/planning.md, "How a plan is found").

What keeps the questions affordable on real CAD (docs/planning.md, "Real CAD at scale"):
along a new direction, the parts that blocked a part last are tried first, alone
(:data:`RECENT_BLOCKERS`); the faces that showed a pair blocking are tested before any
mesh is projected, along one direction at a time (:data:`SWEEP_AFTER` of them), then
along runs of :data:`SWEPT_DIRECTIONS` consecutive candidates at once.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable, Sequence
from functools import cached_property
from typing import TYPE_CHECKING

import networkx as nx
import numpy as np
from numpy.typing import NDArray

from assemblykit.blocking.cache import BlockingCache
from assemblykit.blocking.directions import DirectionTable
from assemblykit.blocking.extended import extended_arcs, shown_along, shown_pairs
from assemblykit.geometry.occlusion import view_frame
from assemblykit.part_sets import bits, mask_of
from assemblykit.tolerance import ModelTolerance

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly

RECENT_BLOCKERS = 4
"""How many of the parts found last blocking a part are tried first, alone, along a new
direction (:meth:`ExtendedDirections.leaving`)."""
SWEPT_DIRECTIONS = 256
"""How many consecutive candidate directions the faces that showed a pair of parts
blocking are tested along at once (:meth:`ExtendedDirections.shown_blockers`), once
they have been asked along :data:`SWEEP_AFTER` directions one at a time."""
SWEEP_AFTER = 4
"""How many directions the faces that showed a pair blocking are tested along one at a
time before they are tested along :data:`SWEPT_DIRECTIONS` at once: a step that finds a
part to remove asks along a few directions, a proof that a set is stuck along hundreds."""


class ExtendedDirections:
    """The DBGs of Γ_e along fixed candidate directions, computed exactly
    (:func:`assemblykit.blocking.extended.extended_arcs`) part by part as the search
    asks for them, and kept: per direction, the moving parts already tested and the
    parts that block each of them.

    ``parts`` (default: all of the assembly's) are the parts it tests, numbered in
    their order: a set of parts of a larger assembly is tested in that assembly, whose
    blocking data (:class:`~assemblykit.blocking.cache.BlockingCache`: each part's
    hull and convex bodies, each pair's witnesses) the search of the whole assembly
    already holds.

    A part is tested along a direction against the set of parts asked about (the parts
    still together, as the search takes them apart), and again only if asked about a
    set holding others: blocking is pairwise, so its blockers among any subset are read
    off, and late in a plan the few parts left are projected, not all of them. Parts
    that are not unions of convex bodies go to the projection test
    (:mod:`assemblykit.geometry.occlusion`), whose cost is projecting the meshes around
    them: a closure (:func:`~assemblykit.planning.search._free_closures`) asks about a
    few more parts at a time, dozens of times along one direction, so it has all such
    parts of the set tested there at once (``whole``), and the meshes are projected
    once. Convex parts' cones are cheap to read and are tested only when asked about (a
    vault has thousands of candidate directions)."""

    def __init__(
        self,
        assembly: Assembly,
        directions: NDArray[np.float64],
        tol: ModelTolerance,
        parts: Sequence[str] | None = None,
    ) -> None:
        self.assembly = assembly
        self.names = tuple(assembly.names if parts is None else parts)
        self.index = {name: i for i, name in enumerate(self.names)}
        self.directions = directions
        self.tol = tol
        self._tested: dict[tuple[int, int], int] = {}
        self._blocking: dict[tuple[int, int], int] = {}
        self._first: dict[tuple[int, ...], int] = {}
        self._witness: dict[tuple[int, int], int] = {}
        self._recent: dict[int, list[int]] = {}
        self._hinted: set[tuple[int, int]] = set()
        self._clear: dict[tuple[int, int], int] = {}
        self._sweeps: dict[
            tuple[int, int, int], tuple[frozenset[tuple[int, int]], NDArray[np.bool_]]
        ] = {}
        self._witnessed: tuple[int, dict[int, int]] = (0, {})
        self._asked: dict[tuple[int, int], int] = {}
        self._frames: dict[int, NDArray[np.float64]] = {}
        self._same: dict[int, int] = {}

    def same_as(self, k: int) -> int:
        """The first candidate direction the same as direction ``k`` to the mesh angle
        tolerance (their coordinates rounded to it) where some part goes to the
        projection test: each part's arrangement of contact circles gives its own copy
        of a direction such as +z, a few 1e-8 apart on tessellated CAD, and the search
        asks along many of them; Γ_e is computed along the first. Where every part is a
        union of convex bodies, cones decide exactly along ``k`` itself. Once found, a
        direction's first stays so: it is kept (the search asks along each direction at
        every step)."""
        same = self._same.get(k)
        if same is None:
            same = k
            if any(self._projected):
                rounded = np.round(self.directions[k] / self.tol.mesh_angle).astype(np.int64)
                same = self._first.setdefault(tuple(rounded.tolist()), k)
            self._same[k] = same
        return same

    @cached_property
    def _projected(self) -> tuple[bool, ...]:
        """Per part, whether it is not a union of convex bodies (its blocking goes to
        the projection test)."""
        obstacles = BlockingCache.of(self.assembly).obstacles
        return tuple(not obstacles.convex(name) for name in self.names)

    def blockers(self, k: int, movers: int, among: int, *, whole: bool = False) -> dict[int, int]:
        """Per part of ``movers``, the mask of its blockers in ``among`` along ``k``;
        the parts not tested along ``k`` before are tested, in one call, with every
        untested part of ``among`` that goes to the projection test when ``whole``
        (class docstring)."""
        k = self.same_as(k)
        untested = [i for i in bits(movers) if not self._knows(k, i, among)]
        if whole and any(self._projected[i] for i in untested):
            asked = set(untested)
            untested += [
                i
                for i in bits(among)
                if self._projected[i] and not self._knows(k, i, among) and i not in asked
            ]
        if untested:
            # the pairs that the faces kept for them show blocking need no projection
            shown = self.shown_blockers(k, mask_of(untested), among)
            known = {(self.names[i], self.names[j]) for i in untested for j in bits(shown[i])}
            for i in untested:
                self._tested[(k, i)] = self._tested.get((k, i), 0) | among
            for i, j in self._extended(k, untested, bits(among), known=known):
                self._blocking[(k, i)] = self._blocking.get((k, i), 0) | 1 << j
                self._remember(i, j)
        return {i: self._blocking.get((k, i), 0) & among & ~(1 << i) for i in bits(movers)}

    def _knows(self, k: int, i: int, among: int) -> bool:
        """Whether every blocker of part ``i`` in ``among`` along ``k`` is known: it was
        tested against a set holding ``among``."""
        return among & ~self._tested.get((k, i), 0) == 0

    def leaving(self, k: int, movers: int, among: int) -> int:
        """The parts of ``movers`` that no part of ``among`` blocks along ``k``, as a
        mask. Where the blockers of a part are not known, one blocker is enough to keep
        it (:func:`~assemblykit.blocking.extended.extended_arcs` with ``first_only``);
        a part found free of a set stays free of its subsets, and a part's blocker
        keeps it while that blocker is in ``among``."""
        k = self.same_as(k)
        free, unknown = 0, []
        for i in bits(movers):
            if self._knows(k, i, among):
                free |= 0 if self._blocking.get((k, i), 0) & among & ~(1 << i) else 1 << i
            elif among & ~self._clear.get((k, i), 0) == 0:
                free |= 1 << i
            else:
                witness = self._witness.get((k, i))
                if witness is None or not among >> witness & 1:
                    unknown.append(i)
        if unknown:
            unknown = self._blocked_as_before(k, unknown, among)
        if unknown:
            found = self._first_blockers(k, unknown, bits(among))
            self._witness.update(((k, i), j) for i, j in found.items())
            for i in unknown:
                if i not in found:
                    self._clear[(k, i)] = among
                    free |= 1 << i
        return free

    def _first_blockers(self, k: int, movers: list[int], blockers: Iterable[int]) -> dict[int, int]:
        """Per part of ``movers`` that some part of ``blockers`` blocks along ``k``, one
        such blocker (the lowest index found), which is kept among the part's
        :data:`RECENT_BLOCKERS` last ones."""
        found: dict[int, int] = {}
        for i, j in self._extended(k, movers, blockers, first_only=True):
            found[i] = min(j, found.get(i, j))
        for i, j in found.items():
            self._remember(i, j)
        return found

    def _extended(
        self,
        k: int,
        movers: Iterable[int],
        blockers: Iterable[int],
        *,
        first_only: bool = False,
        known: Collection[tuple[str, str]] | None = None,
    ) -> list[tuple[int, int]]:
        """The arcs ``(i, j)`` of Γ_e along ``k`` from ``movers`` to ``blockers``, as
        indices (:func:`~assemblykit.blocking.extended.extended_arcs`, with ``first_only``
        one blocker at least of each blocked mover)."""
        arcs = extended_arcs(
            self.assembly,
            self.directions[k],
            [self.names[i] for i in movers],
            [self.names[j] for j in blockers],
            self.tol,
            first_only=first_only,
            known=known,
        )
        return [(self.index[a], self.index[b]) for a, b in arcs]

    def _remember(self, i: int, j: int) -> None:
        """Keep ``j`` first among the :data:`RECENT_BLOCKERS` last blockers of ``i``."""
        recent = self._recent.setdefault(i, [])
        if j in recent:
            recent.remove(j)
        recent.insert(0, j)
        del recent[RECENT_BLOCKERS:]

    def known_blockers(self, k: int, movers: int, among: int) -> dict[int, int]:
        """Per part of ``movers``, some of its blockers in ``among`` along ``k`` (every
        one where it was tested along ``k``): besides those, the parts that blocked it
        last along other directions are tested along ``k``, alone, until one of them
        blocks it (a few projected meshes). A closure under these arcs is within the
        closure under all of them (:func:`~assemblykit.planning.search._free_closures`):
        one blocker on the way to the base proves what all of them would."""
        k = self.same_as(k)
        asked = [
            i for i in bits(movers) if not self._knows(k, i, among) and (k, i) not in self._hinted
        ]
        hints = sorted({j for i in asked for j in self._recent.get(i, ()) if among >> j & 1})
        if asked and hints:
            for i, j in self._extended(k, asked, hints, first_only=True):
                self._blocking[(k, i)] = self._blocking.get((k, i), 0) | 1 << j
        self._hinted.update((k, i) for i in asked)
        return {i: self._blocking.get((k, i), 0) & among & ~(1 << i) for i in bits(movers)}

    def shown_blockers(self, k: int, movers: int, among: int) -> dict[int, int]:
        """Per part of ``movers``, blockers in ``among`` along ``k`` known without
        projecting a mesh: those found before, and those shown by the faces that showed
        the pair blocking along other directions
        (:func:`~assemblykit.blocking.extended.shown_along`). Once a pair has been
        asked along :data:`SWEEP_AFTER` directions, its faces are tested along the run of
        :data:`SWEPT_DIRECTIONS` candidates around ``k`` at once, and again only for faces
        kept since (:meth:`_sweep`): a search that proves a set stuck asks along hundreds
        of directions, mostly of the same pairs."""
        k = self.same_as(k)
        masks = self._witnessed_masks()
        asked = [
            (i, j)
            for i in bits(movers)
            if not self._knows(k, i, among)
            for j in bits(among & masks.get(i, 0) & ~(1 << i))
        ]
        for pair in asked:
            self._asked[pair] = self._asked.get(pair, 0) + 1
        swept = [pair for pair in asked if self._asked[pair] > SWEEP_AFTER]
        self._sweep(k, swept)
        chunk, at = divmod(k, SWEPT_DIRECTIONS)
        shown = [(i, j) for i, j in swept if self._sweeps[(i, j, chunk)][1][at]]
        once = [pair for pair in asked if self._asked[pair] <= SWEEP_AFTER]
        if once:
            unit = self.directions[k] / np.linalg.norm(self.directions[k])
            named = [(self.names[i], self.names[j]) for i, j in once]
            found = shown_pairs(self.assembly, unit, named, self.tol)
            shown += [(self.index[a], self.index[b]) for a, b in found]
        for i, j in shown:
            self._blocking[(k, i)] = self._blocking.get((k, i), 0) | 1 << j
        return {i: self._blocking.get((k, i), 0) & among & ~(1 << i) for i in bits(movers)}

    def _witnessed_masks(self) -> dict[int, int]:
        """Per part, the mask of the parts it has blocking witnesses with (the pairs the
        projection test found blocking), kept up to date as witnesses are found."""
        witnesses = BlockingCache.of(self.assembly).obstacles.witnesses
        if len(witnesses) != self._witnessed[0]:
            masks: dict[int, int] = {}
            for a, b in witnesses:
                i, j = self.index.get(a), self.index.get(b)
                if i is not None and j is not None:
                    masks[i] = masks.get(i, 0) | 1 << j
            self._witnessed = (len(witnesses), masks)
        return self._witnessed[1]

    def _sweep(self, k: int, pairs: list[tuple[int, int]]) -> None:
        """Test the faces kept for each of ``pairs`` and not yet tested along ``k``, along
        the :data:`SWEPT_DIRECTIONS` consecutive candidates around ``k`` (as many as
        there are), all at once. What faces showed stays shown when they are no longer
        kept (a block shown is a block)."""
        witnesses = BlockingCache.of(self.assembly).obstacles.witnesses
        chunk = k // SWEPT_DIRECTIONS
        low = chunk * SWEPT_DIRECTIONS
        rows = self.directions[low : low + SWEPT_DIRECTIONS]
        fresh: dict[tuple[str, str], list[tuple[int, int]]] = {}
        for i, j in pairs:
            pair = (self.names[i], self.names[j])
            swept = self._sweeps.get((i, j, chunk))
            if swept is not None and len(swept[1]) < len(rows):
                # candidates added since: every face again, along all of them
                del self._sweeps[(i, j, chunk)]
                swept = None
            new = [faces for faces in witnesses[pair] if swept is None or faces not in swept[0]]
            if new:
                fresh[pair] = new
        if not fresh:
            return
        frames = self._frames.get(chunk)
        if frames is None or len(frames) < len(rows):
            frames = np.array([view_frame(row / np.linalg.norm(row)) for row in rows]).reshape(
                -1, 3, 3
            )
            self._frames[chunk] = frames
        for (a, b), along in shown_along(self.assembly, frames, fresh, self.tol).items():
            key = (self.index[a], self.index[b], chunk)
            faces, before = self._sweeps.get(key, (frozenset(), along))
            self._sweeps[key] = (faces | set(fresh[(a, b)]), before | along)

    def _blocked_as_before(self, k: int, movers: list[int], among: int) -> list[int]:
        """The parts of ``movers`` not shown blocked along ``k`` by a part of ``among``:
        first by the faces that showed a pair blocking along another direction
        (:meth:`shown_blockers`, no mesh projected), then by a part that blocked them
        along another direction (:data:`RECENT_BLOCKERS` each, tested alone: a few
        projected meshes, where the whole test projects every part near the sweep). A
        part blocked along one direction mostly is along its neighbours by the same
        part, as the search visits them."""
        shown = self.shown_blockers(k, mask_of(movers), among)
        for i, mask in shown.items():
            if mask:
                self._witness[(k, i)] = (mask & -mask).bit_length() - 1
        movers = [i for i in movers if not shown[i]]
        hinted = [i for i in movers if any(among >> j & 1 for j in self._recent.get(i, ()))]
        if not hinted:
            return movers
        hints = sorted({j for i in hinted for j in self._recent[i] if among >> j & 1})
        found = self._first_blockers(k, hinted, hints)
        self._witness.update(((k, i), j) for i, j in found.items())
        return [i for i in movers if i not in found]

    def arcs(self, k: int, members: int | None = None) -> list[tuple[int, int]]:
        """The arcs ``(i, j)``, "j blocks i", of the DBG along direction ``k`` among
        ``members`` (default: all parts)."""
        among = mask_of(range(len(self.names))) if members is None else members
        return [(i, j) for i, mask in self.blockers(k, among, among).items() for j in bits(mask)]

    def graph(self, k: int, members: int) -> nx.DiGraph[int]:
        """The Γ_e DBG along direction ``k`` induced on ``members`` (blocking is
        pairwise, so the arcs found for one subassembly serve every other)."""
        graph: nx.DiGraph[int] = nx.DiGraph()
        graph.add_nodes_from(bits(members))
        graph.add_edges_from(
            (i, j) for i, mask in self.blockers(k, members, members).items() for j in bits(mask)
        )
        return graph

    def add(self, directions: NDArray[np.float64]) -> None:
        """Append candidate directions (indices follow the existing ones)."""
        self.directions = np.vstack([self.directions, directions])

    @property
    def evaluated(self) -> set[int]:
        """The directions along which some pair has been tested."""
        return {k for k, _ in self._tested}

    def table(self, indices: Iterable[int], members: int | None = None) -> DirectionTable:
        """The DBGs among ``members`` (default: all parts) along the directions
        ``indices``, as a table."""
        chosen = sorted(set(indices))
        arcs = [self.arcs(k, members) for k in chosen]
        return DirectionTable.from_arcs(self.names, self.directions[chosen], arcs)
