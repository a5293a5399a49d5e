"""Multi-move disassembly of mesh assemblies: translations by the distances where
contacts change.

Wilson & Latombe 1992 plan with one translation per separation and cite separating parts "by a
sequence of translations" [Pollack et al., 1988] as the harder problem; the lattice
search (:mod:`assemblykit.planning.multimove`) solves it for voxel pieces. For parts of
any shape the same breadth-first search runs on these states and moves:

* a *state* is the translation of every part relative to the first; two states whose
  translations agree to the length tolerance are one;
* *directions* are the monotone planner's candidates, the regions of Γ_t's arrangement
  (:func:`assemblykit.blocking.tables.translation_table`), with the contact normals,
  all both ways;
* *distances* come from the Minkowski sums: every part is cut into convex pieces
  (:func:`assemblykit.geometry.minkowski.convex_pieces`); piece ``p`` of a moving part
  placed at ``c`` relative to piece ``q`` of a still one meets it at ``c + t d`` inside
  the obstacle ``q ⊕ (−p)`` (Lozano-Pérez 1983), the hull of their vertex differences.
  Clipping that ray with the hull's facets gives the interval of ``t`` where the two
  touch or overlap, and, with the facets pushed in by the length tolerance, where they
  overlap with positive depth (interference; touching is allowed). A set may move as
  far as the first such overlap (its *free* distance); its moves go to each distance in
  ``(0, free]`` where a pair of pieces starts or stops touching, and it *separates*
  when nothing is in its way (free distance infinite);
* the sets moved along a direction are, for each starting part, the part alone and
  then the set grown by the parts that stop it first, as the lattice search grows its
  groups (a set containing the first part is reported as the others moving the other
  way: the same relative motion).

The search visits states breadth first, so the first separation found takes the fewest
moves; each half is then planned the same way, and the result is the lattice search's
:class:`~assemblykit.planning.multimove.MultiMovePlan` (a tree of separations with
BurrTools-style levels). Directions are those of the assembled state: a motion needing
a direction that only a later state's contacts suggest is not found.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import ConvexHull, QhullError

from assemblykit.errors import GeometryError
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.geometry.minkowski import convex_pieces
from assemblykit.part_sets import mask_vector
from assemblykit.planning.multimove import (
    MAX_STATES,
    Found,
    Move,
    MultiMovePlan,
    MultiMoveSearch,
    Progress,
    fixed_indices,
)
from assemblykit.ragged import group_starts
from assemblykit.tolerance import ModelTolerance, Tolerance

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly


def candidate_directions(assembly: Assembly, tol: ModelTolerance) -> NDArray[np.float64]:
    """Unit directions (rows) to move along: the regions of Γ_t's arrangement and the
    contact normals (of planar patches; axes of curved ones), each both ways, one per
    direction within the angle tolerance; those along an axis first."""
    from assemblykit.blocking.tables import translation_table

    rows = [np.asarray(translation_table(assembly, tol).directions, dtype=np.float64)]
    for contact in assembly_contacts(assembly, tol):
        rows += [np.asarray(p.normal, dtype=np.float64)[None] for p in contact.planar]
        rows += [np.asarray(c.axis)[None] for c in contact.curved if c.axis is not None]
    found = np.vstack(rows)
    found = found / np.linalg.norm(found, axis=1, keepdims=True)
    found = np.vstack([found, -found])
    _, first = np.unique(np.round(found / tol.angle), axis=0, return_index=True)
    found = found[np.sort(first)]
    order = np.lexsort((*(-found.T[::-1]), -np.abs(found).max(axis=1)))
    return np.ascontiguousarray(found[order])


class _Obstacles:
    """The facets of ``q ⊕ (−p)`` for every pair of convex pieces ``p`` of part ``a`` and
    ``q`` of part ``b > a``, concatenated (module docstring): ``normals . x + offsets
    <= 0`` inside, facets of piece pair ``k`` from ``starts[k]``."""

    def __init__(self, pieces: Sequence[list[NDArray[np.float64]]]) -> None:
        normals: list[NDArray[np.float64]] = []
        offsets: list[NDArray[np.float64]] = []
        owner: list[NDArray[np.int64]] = []
        first: list[int] = []
        second: list[int] = []
        for a in range(len(pieces)):
            for b in range(a + 1, len(pieces)):
                for p in pieces[a]:
                    for q in pieces[b]:
                        diffs = (q[:, None, :] - p[None, :, :]).reshape(-1, 3)
                        try:
                            facets = ConvexHull(diffs).equations
                        except QhullError as bad:
                            raise GeometryError(f"degenerate convex piece: {bad}") from None
                        normals.append(facets[:, :3])
                        offsets.append(facets[:, 3])
                        owner.append(np.full(len(facets), len(first)))
                        first.append(a)
                        second.append(b)
        self.normals = np.vstack(normals or [np.zeros((0, 3))])
        self.offsets = np.concatenate(offsets or [np.zeros(0)])
        self.owner = np.concatenate(owner or [np.zeros(0, dtype=np.int64)])
        self.first = np.array(first, dtype=np.int64)
        self.second = np.array(second, dtype=np.int64)
        counts = np.bincount(self.owner, minlength=len(first))
        self.starts = group_starts(counts)


class _Intervals:
    """Per pair of pieces (rows) and direction (columns), for one state: where the ray
    of the first piece's part relative to the second's touches (``touch_lo`` to
    ``touch_hi``) and overlaps with positive depth (``inside_lo`` to ``inside_hi``)."""

    def __init__(
        self,
        obstacles: _Obstacles,
        alpha: NDArray[np.float64],
        offsets: NDArray[np.float64],
        tol: ModelTolerance,
    ) -> None:
        relative = offsets[obstacles.first] - offsets[obstacles.second]
        beta = (
            np.einsum("ij,ij->i", obstacles.normals, relative[obstacles.owner]) + obstacles.offsets
        )[:, None]
        # facets within the angle tolerance of the ray are constant along it
        ahead, behind = alpha > tol.angle, alpha < -tol.angle
        level = ~ahead & ~behind
        safe = np.where(level, 1.0, alpha)
        self.touch_lo, self.touch_hi = self._clip(obstacles, -beta / safe, ahead, behind)
        self.inside_lo, self.inside_hi = self._clip(
            obstacles, -(beta + tol.length) / safe, ahead, behind
        )
        apart = np.logical_or.reduceat(level & (beta > tol.length), obstacles.starts, axis=0)
        clear = np.logical_or.reduceat(level & (beta >= -tol.length), obstacles.starts, axis=0)
        self.touch_lo[apart] = np.inf
        self.inside_lo[clear] = np.inf

    @staticmethod
    def _clip(
        obstacles: _Obstacles,
        bound: NDArray[np.float64],
        ahead: NDArray[np.bool_],
        behind: NDArray[np.bool_],
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        lo = np.maximum.reduceat(np.where(behind, bound, -np.inf), obstacles.starts, axis=0)
        hi = np.minimum.reduceat(np.where(ahead, bound, np.inf), obstacles.starts, axis=0)
        return lo, hi


class _MeshSearch(MultiMoveSearch):
    """The states and moves of the module docstring; a state is its offsets (``(n, 3)``
    floats), its key those offsets in units of the length tolerance."""

    def __init__(
        self,
        assembly: Assembly,
        tol: ModelTolerance,
        max_states: int,
        progress: Progress,
        fixed: Iterable[int] = (),
    ) -> None:
        names = list(assembly.names)
        super().__init__(names, [0] * len(names), max_states, progress, fixed)
        self.tol = tol
        pieces = []
        for k, name in enumerate(names):
            progress("convex pieces", k, len(names))
            pieces.append(convex_pieces(assembly[name].mesh, tol, name=name))
        self.obstacles = _Obstacles(pieces)
        progress("candidate directions", 0, 1)
        self.directions = candidate_directions(assembly, tol)
        keys = np.round(self.directions / tol.angle).astype(np.int64)
        index = {row.tobytes(): k for k, row in enumerate(keys)}
        self.opposite = np.array([index[(-row).tobytes()] for row in keys], dtype=np.int64)
        self.alpha = self.obstacles.normals @ self.directions.T

    def origin(self, members: list[int], start: NDArray[Any]) -> tuple[bytes, Any]:
        offsets = np.asarray(start, dtype=np.float64) - start[members[0]]
        return self._key(members, offsets), offsets

    def _key(self, members: list[int], offsets: NDArray[np.float64]) -> bytes:
        return np.round(offsets[members] / self.tol.length).astype(np.int64).tobytes()

    def expand(
        self, members: list[int], state: Any
    ) -> tuple[Found | None, Iterable[tuple[bytes, Any, Any]]]:
        offsets: NDArray[np.float64] = state
        intervals = _Intervals(self.obstacles, self.alpha, offsets, self.tol)
        inside = np.zeros(len(self.names), dtype=bool)
        inside[members] = True
        among = inside[self.obstacles.first] & inside[self.obstacles.second]
        removals: list[tuple[int, int, int]] = []
        moves: dict[tuple[int, int, float], None] = {}
        for k in range(len(self.directions)):
            for start in range(len(members)):
                group = {members[start]}
                while len(group) < len(members):
                    free, events, stoppers = self._reach(intervals, among, group, k)
                    mask = sum(1 << i for i, m in enumerate(members) if m in group)
                    kept = self.keeps_fixed(members, mask)
                    if free == np.inf:
                        if kept:
                            removals.append((len(group), k, mask))
                        break
                    for t in events if kept else ():
                        moves.setdefault((mask, k, t), None)
                    group |= stoppers
        if removals:
            _, k, mask = min(removals)
            return self._separating(members, mask, k), ()
        children = []
        for mask, k, t in moves:
            moved = mask_vector(mask, len(members))
            after = offsets.copy()
            after[np.array(members)[moved]] += t * self.directions[k]
            after -= after[members[0]]
            children.append((self._key(members, after), after, (mask, k, t)))
        return None, children

    def _reach(
        self, intervals: _Intervals, among: NDArray[np.bool_], group: set[int], k: int
    ) -> tuple[float, list[float], set[int]]:
        """How far ``group`` may move along direction ``k`` (module docstring), the
        distances in ``(0, free]`` where a pair of pieces starts or stops touching, and
        the parts that stop it first."""
        obstacles, length = self.obstacles, self.tol.length
        moving = np.zeros(len(self.names), dtype=bool)
        moving[list(group)] = True
        forward = among & moving[obstacles.first] & ~moving[obstacles.second]
        backward = among & moving[obstacles.second] & ~moving[obstacles.first]
        rows = np.flatnonzero(forward | backward)
        column = np.where(forward[rows], k, self.opposite[k])
        lo, hi = intervals.touch_lo[rows, column], intervals.touch_hi[rows, column]
        deep_lo = intervals.inside_lo[rows, column]
        deep_hi = intervals.inside_hi[rows, column]
        blocking = (deep_lo < deep_hi) & (deep_hi > length)
        entry = np.maximum(lo, 0.0)
        free = float(entry[blocking].min()) if blocking.any() else np.inf
        touching = lo <= hi
        ends = np.concatenate([lo[touching], hi[touching]])
        ends = np.sort(ends[(ends > length) & (ends <= free + length)])
        events = [
            float(t)
            for t, gap in zip(ends, np.diff(ends, prepend=-np.inf), strict=True)
            if gap > length
        ]
        first = rows[blocking & (entry <= free + length)]
        others = np.where(
            moving[obstacles.first[first]], obstacles.second[first], obstacles.first[first]
        )
        return free, events if free > length else [], {int(m) for m in others}

    def move(self, members: list[int], raw: Any) -> Move:
        mask, k, t = raw
        if mask & 1:
            mask, k = ((1 << len(members)) - 1) ^ mask, int(self.opposite[k])
        return self._move(members, mask, k, t)

    def placement(self, members: list[int], state: Any) -> NDArray[Any]:
        return np.asarray(state, dtype=np.float64)

    def _separating(self, members: list[int], mask: int, k: int) -> Found:
        if self.flipped(members, mask):
            # report the smaller half (the one without the fixed parts) as the one
            # removed, moving the other way
            mask, k = ((1 << len(members)) - 1) ^ mask, int(self.opposite[k])
        removed = [m for i, m in enumerate(members) if mask >> i & 1]
        return removed, self._move(members, mask, k, None)

    def _move(self, members: list[int], mask: int, k: int, t: float | None) -> Move:
        parts = tuple(self.names[m] for i, m in enumerate(members) if mask >> i & 1)
        d = self.directions[k] + 0.0  # no negative zeros in what is printed
        return Move(parts, (float(d[0]), float(d[1]), float(d[2])), t)


def plan_meshes(
    assembly: Assembly,
    tol: Tolerance | None = None,
    max_states: int = MAX_STATES,
    progress: Progress | None = None,
    fixed: Iterable[str] = (),
) -> MultiMovePlan:
    """The multi-move disassembly plan of a mesh assembly (module docstring). Each
    separation's search visits at most ``max_states`` states; beyond that its
    subassembly is reported ``cut``. The ``fixed`` parts never move (docs/planning.md,
    "Fixed parts")."""
    tol = assembly.tolerance(tol)
    report: Progress = progress or (lambda stage, done, total: None)
    names = tuple(assembly.names)
    root = None
    if len(names) > 1:
        anchored = fixed_indices(names, fixed)
        search = _MeshSearch(assembly, tol, max_states, report, anchored)
        root = search.plan(list(range(len(names))), np.zeros((len(names), 3)))
    return MultiMovePlan(names, root, max_states)
