"""The non-directional blocking graph (Wilson & Latombe 1992): regular regions of directions, each
with its DBG, computed by the crossing rule.

The blocking terms (:mod:`assemblykit.blocking.constraints`) are snapped onto great
circles and become the columns of a :class:`ConstraintTable`: one *weight* column per
ordered pair of parts for its single half-space terms (the arc weight of Wilson & Latombe
1992, "Computation of Blocking Graph": the number of strictly positive inner products)
and one *count* column per cone term (extended translations). A pair blocks when its
weight is positive or one of its cone counts is full. The DBG of the root region is
computed directly; every other region
is reached by a breadth-first walk over the boundary links of the arrangement and
obtained by the crossing rule: entering a higher-dimensional region adds the terms
that become positive on the crossed circles, leaving it for its boundary retracts them
(Wilson & Latombe 1992, "Computation of Blocking Graph", 2D crossing rule and its 3D adaptation).
A whole breadth-first layer is updated at once with array operations.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from assemblykit.blocking.arrangement import (
    Arrangement,
    circle_partition,
    side_signs,
    snap_normals,
    sphere_arrangement,
)
from assemblykit.blocking.constraints import BlockingTerm
from assemblykit.blocking.dbg import DirectionalBlockingGraph, Region, Removal
from assemblykit.blocking.directions import DirectionTable
from assemblykit.model.assembly import AssemblyLike as AssemblyLike
from assemblykit.part_sets import distinct_rows
from assemblykit.ragged import group_of, group_starts, ranges
from assemblykit.tolerance import ModelTolerance

Motion = Literal["infinitesimal", "extended", "rigid"]
_CHUNK = 8192
_PAD = -2


@dataclass(frozen=True, eq=False)
class ConstraintTable:
    """Blocking terms snapped to circles, as crossing-rule columns (module docstring).

    ``plus[k]`` / ``minus[k]`` count, per column, the half-spaces that hold on the +/-
    side of circle ``k``; a column is satisfied when its count reaches ``need``;
    ``slot_moving`` / ``slot_blocker`` (part indices) give the arc of each slot and
    ``starts`` the first column of each slot."""

    normals: NDArray[np.float64]
    plus: NDArray[np.float64]
    minus: NDArray[np.float64]
    need: NDArray[np.float64]
    starts: NDArray[np.int64]
    slot_moving: NDArray[np.int64]
    slot_blocker: NDArray[np.int64]

    @classmethod
    def build(
        cls,
        parts: Sequence[str],
        terms: Sequence[BlockingTerm],
        tol: ModelTolerance,
        normals: NDArray[np.float64] | None = None,
        spare: Iterable[int] | None = None,
    ) -> ConstraintTable:
        """Snap the terms' normals to circles (appended to ``normals`` when given) and
        lay out the columns, slots grouped by moving part. Each part of ``spare`` (all
        parts by default) gets a *pad*: a self-slot that never blocks, which
        :meth:`NonDirectionalBlockingGraph.with_terms` fills when a part is added."""
        index = {p: i for i, p in enumerate(parts)}
        columns: dict[tuple[int, int, int], list[NDArray[np.float64]]] = defaultdict(list)
        for m in range(len(parts)) if spare is None else spare:
            columns[(m, m, _PAD)].append(np.zeros((0, 3)))
        for t, term in enumerate(terms):
            slot = (index[term.moving], index[term.blocker])
            key = (*slot, -1) if term.single else (*slot, t)
            columns[key].append(np.asarray(term.normals, dtype=np.float64).reshape(-1, 3))
        keys = sorted(columns)
        stacked = [np.concatenate(columns[k]) for k in keys]
        owner = np.concatenate([np.full(len(s), i) for i, s in enumerate(stacked)] or [np.zeros(0)])
        flat = np.concatenate(stacked) if stacked else np.zeros((0, 3))
        base = np.zeros((0, 3)) if normals is None else normals
        circles, circle_of, orient = snap_normals(np.concatenate([base, flat]), tol)
        circle_of, orient = circle_of[len(base) :], orient[len(base) :]
        c, ncol = len(circles), len(keys)
        plus, minus = np.zeros((c, ncol)), np.zeros((c, ncol))
        owner = owner.astype(np.int64)
        np.add.at(plus, (circle_of[orient > 0], owner[orient > 0]), 1.0)
        np.add.at(minus, (circle_of[orient < 0], owner[orient < 0]), 1.0)
        need = np.array(
            [
                np.inf if k[2] == _PAD else 1.0 if k[2] < 0 else len(s)
                for k, s in zip(keys, stacked, strict=True)
            ]
        )
        slots = np.array([k[:2] for k in keys], dtype=np.int64).reshape(-1, 2)
        first = np.flatnonzero(np.r_[True, np.any(slots[1:] != slots[:-1], axis=1)])
        return cls(circles, plus, minus, need, first, slots[first, 0], slots[first, 1])

    def weights(self, signs: NDArray[np.int8]) -> NDArray[np.float64]:
        """Column counts for regions with the given sides of every circle (direct)."""
        return (signs > 0).astype(np.float64) @ self.plus + (signs < 0) @ self.minus

    def arcs(self, weights: NDArray[np.float64] | NDArray[np.int16]) -> NDArray[np.bool_]:
        """Which slots block, from column counts."""
        satisfied = weights >= self.need
        if len(self.starts) == weights.shape[1]:  # one column per slot
            return satisfied
        return np.logical_or.reduceat(satisfied, self.starts, axis=1)

    def direct_arcs(
        self, directions: NDArray[np.float64], tol: ModelTolerance
    ) -> NDArray[np.bool_]:
        """Which slots block along each direction, computed from scratch."""
        out = [
            self.arcs(self.weights(side_signs(self.normals, directions[lo : lo + _CHUNK], tol)))
            for lo in range(0, len(directions), _CHUNK)
        ]
        return np.concatenate(out) if out else np.zeros((0, len(self.starts)), dtype=bool)


def crossing_rule(arrangement: Arrangement, table: ConstraintTable) -> NDArray[np.uint8]:
    """The blocking slots of every region (rows, bit-packed), by the crossing rule from
    the root region, one breadth-first layer at a time (module docstring)."""
    n = len(arrangement)
    low, high = arrangement.links_low, arrangement.links_high
    keys, pair_of = np.unique(low * n + high, return_inverse=True)
    pair_of = pair_of.ravel()
    # the crossed circles of each linked pair, as rows of the stacked +/- deltas
    by_pair = np.argsort(pair_of, kind="stable")
    rows = (2 * arrangement.links_circle + (arrangement.links_sign < 0))[by_pair]
    row_start = np.searchsorted(pair_of[by_pair], np.arange(len(keys)))
    row_count = np.diff(np.r_[row_start, len(rows)])
    c = len(table.normals)
    stack = np.empty((2 * c, table.plus.shape[1]), dtype=np.int16)
    stack[0::2], stack[1::2] = table.plus, table.minus
    # both directions of every link: entering the higher region adds, leaving retracts
    src = np.r_[keys // n, keys % n]
    dst = np.r_[keys % n, keys // n]
    pid = np.r_[np.arange(len(keys)), np.arange(len(keys))]
    sign = np.r_[np.ones(len(keys), np.int16), -np.ones(len(keys), np.int16)]
    order = np.argsort(src, kind="stable")
    dst, pid, sign = dst[order], pid[order], sign[order]
    indptr = np.searchsorted(src[order], np.arange(n + 1))
    width = (len(table.starts) + 7) // 8
    packed = np.zeros((n, width), dtype=np.uint8)
    visited = np.zeros(n, dtype=bool)
    frontier = np.array([arrangement.root])
    visited[frontier] = True
    # counts stay small (patches per pair of parts): 16 bits halve the memory traffic
    weights = table.weights(arrangement.root_signs[None, :]).astype(np.int16)
    packed[frontier] = np.packbits(table.arcs(weights), axis=1)
    claim = np.full(n, -1, dtype=np.int64)
    while len(frontier):
        half = ranges(indptr[frontier], indptr[frontier + 1] - indptr[frontier])
        parent_row = group_of(indptr[frontier + 1] - indptr[frontier])
        fresh = np.flatnonzero(~visited[dst[half]])
        # one link per new region: the one whose claim on it survives
        claim[dst[half[fresh]]] = fresh
        first = fresh[claim[dst[half[fresh]]] == fresh]
        children, link = dst[half[first]], half[first]
        counts = row_count[pid[link]]
        picked = rows[ranges(row_start[pid[link]], counts)]
        if np.all(counts == 1):
            change = stack[picked]
        else:
            change = np.add.reduceat(stack[picked], group_starts(counts), axis=0)
        weights = weights[parent_row[first]] + sign[link][:, None] * change
        packed[children] = np.packbits(table.arcs(weights), axis=1)
        visited[children] = True
        frontier = children
    return packed


@dataclass(frozen=True, eq=False)
class NonDirectionalBlockingGraph:
    """Γ_t or Γ_e of an assembly (Wilson & Latombe 1992): the regular regions of the directions and
    the DBG of each (``packed``: bit-packed blocking slots per region). ``exact``, when
    given, computes G(d, A) over the given parts for any direction instead of the
    table (Γ_e of non-convex parts, :func:`assemblykit.blocking.extended.sampled_ndbg`)."""

    parts: tuple[str, ...]
    motion: str
    arrangement: Arrangement
    table: ConstraintTable
    packed: NDArray[np.uint8]
    contacts: int
    tol: ModelTolerance
    exact: Callable[[NDArray[np.float64], tuple[str, ...]], DirectionalBlockingGraph] | None = None

    def _graph(
        self, direction: NDArray[np.float64], slots: NDArray[np.bool_]
    ) -> DirectionalBlockingGraph:
        arcs = frozenset(
            (self.parts[self.table.slot_moving[s]], self.parts[self.table.slot_blocker[s]])
            for s in np.flatnonzero(slots)
        )
        return DirectionalBlockingGraph(self.parts, direction, arcs)

    def _unpacked(self, row: NDArray[np.uint8]) -> NDArray[np.bool_]:
        return np.unpackbits(row, count=len(self.table.starts)).astype(bool)

    def _direction(self, direction: ArrayLike) -> NDArray[np.float64]:
        d = np.asarray(direction, dtype=np.float64).ravel()
        d = np.r_[d, np.zeros(3 - len(d))]
        unit: NDArray[np.float64] = d / np.linalg.norm(d)
        return unit

    def dbg(self, direction: ArrayLike) -> DirectionalBlockingGraph:
        """G(d, A) for any direction (2- or 3-vector), computed directly from the terms."""
        d = self._direction(direction)
        if self.exact is not None:
            return self.exact(d, self.parts)
        slots = self.table.direct_arcs(d[None, :], self.tol)[0]
        out = d[:2] if self.arrangement.dimension == 2 else d
        return self._graph(out, slots)

    def region_dbg(self, region: int) -> DirectionalBlockingGraph:
        """The DBG of one region as found by the crossing rule."""
        d = self.arrangement.directions[region]
        out = d[:2] if self.arrangement.dimension == 2 else d
        return self._graph(out, self._unpacked(self.packed[region]))

    def regions(self) -> list[Region]:
        """Every regular region with its representative direction and DBG."""
        dims = self.arrangement.dims
        return [
            Region(self.region_dbg(r).direction, int(dims[r]), self.region_dbg(r))
            for r in range(len(dims))
        ]

    def unique_dbgs(self) -> list[tuple[DirectionalBlockingGraph, NDArray[np.int64]]]:
        """Each distinct DBG of the regions, once, with the regions (increasing) that
        have it; the DBG's direction is the zero vector (it stands for all of them)."""
        unique, inverse = distinct_rows(self.packed)
        by_row = np.argsort(inverse, kind="stable")
        cuts = np.cumsum(np.bincount(inverse, minlength=len(unique)))[:-1]
        return [
            (self._graph(np.zeros(3), self._unpacked(row)), members)
            for row, members in zip(unique, np.split(by_row, cuts), strict=True)
        ]

    def direction_table(self, directions: NDArray[np.float64] | None = None) -> DirectionTable:
        """The DBGs along ``directions``, computed from the terms; by default the DBG of
        every region (vertices and edges included: free directions are often isolated,
        e.g. a pin's axis) at its representative direction, read from the crossing
        rule's slots as they are. Regions with the same DBG are kept apart."""
        if directions is None:
            directions = np.asarray(self.arrangement.directions, dtype=np.float64)
            slots = self._slot_matrix().reshape(len(directions), len(self.table.starts))
        else:
            slots = self.table.direct_arcs(directions, self.tol)
        return DirectionTable(
            tuple(self.parts),
            directions,
            slots,
            np.asarray(self.table.slot_moving, dtype=np.int64),
            np.asarray(self.table.slot_blocker, dtype=np.int64),
        )

    def removable(self, max_size: int | None = None) -> list[Removal]:
        """Every locally free subassembly closed under blocking (up to ``max_size``
        parts) with the directions of the regions that free it, faces first.

        Regions with the same DBG are analysed once."""
        found: dict[frozenset[str], list[int]] = defaultdict(list)
        for graph, members in self.unique_dbgs():
            for subset in graph.free_subassemblies():
                if max_size is None or len(subset) <= max_size:
                    found[subset].extend(members.tolist())
        dims = self.arrangement.dims
        removals = []
        for subset, regions in found.items():
            ordered = sorted(regions, key=lambda r: (-dims[r], r))
            width = self.arrangement.dimension
            directions = tuple(self.arrangement.directions[r, :width] for r in ordered)
            removals.append(Removal(subset, directions))
        return sorted(removals, key=lambda rm: (len(rm.parts), sorted(rm.parts)))

    def _with_slots(
        self,
        parts: tuple[str, ...],
        table: ConstraintTable,
        slots: NDArray[np.bool_],
        contacts: int,
    ) -> NonDirectionalBlockingGraph:
        return NonDirectionalBlockingGraph(
            parts,
            self.motion,
            self.arrangement,
            table,
            np.packbits(slots, axis=1),
            contacts,
            self.tol,
            self.exact,
        )

    def _slot_matrix(self) -> NDArray[np.bool_]:
        return np.unpackbits(self.packed, axis=1, count=len(self.table.starts)).view(bool)

    def without_parts(self, names: Iterable[str]) -> NonDirectionalBlockingGraph:
        """The NDBG of the assembly without some parts, updated instead of recomputed
        (Wilson & Latombe 1992, "Incremental modification"): the arrangement is kept (its regions
        stay regular), and every slot touching a removed part is cleared in all regions
        at once (a bitwise AND) and becomes a *pad*: a self-arc ``m -> m`` of a
        neighbouring kept mover that can never block. Slots stay grouped by moving part;
        :meth:`with_terms` reuses the pads."""
        gone = set(names)
        keep_parts = tuple(p for p in self.parts if p not in gone)
        remap = np.full(len(self.parts), -1, dtype=np.int64)
        for k, p in enumerate(keep_parts):
            remap[self.parts.index(p)] = k
        t = self.table
        moving, blocker = remap[t.slot_moving], remap[t.slot_blocker]
        keep = (moving >= 0) & (blocker >= 0)
        if not keep_parts:
            return self._with_slots(
                keep_parts,
                ConstraintTable.build((), [], self.tol),
                np.zeros((len(self.arrangement), 0), bool),
                self.contacts,
            )
        # a removed mover's slots join the previous kept mover's group (the next if none)
        owner = np.maximum.accumulate(np.where(moving >= 0, np.arange(len(moving)), -1))
        first_kept = int(np.argmax(moving >= 0))
        owner[owner < 0] = first_kept
        pad_part = moving[owner]
        sizes = np.diff(np.r_[t.starts, t.plus.shape[1]])
        table = ConstraintTable(
            t.normals,
            t.plus,
            t.minus,
            np.where(np.repeat(keep, sizes), t.need, np.inf),
            t.starts,
            np.where(keep, moving, pad_part),
            np.where(keep, blocker, pad_part),
        )
        return NonDirectionalBlockingGraph(
            keep_parts,
            self.motion,
            self.arrangement,
            table,
            self.packed & np.packbits(keep),
            self.contacts,
            self.tol,
            self.exact,
        )

    def with_terms(
        self, new_parts: Sequence[str], terms: Sequence[BlockingTerm], contacts: int
    ) -> NonDirectionalBlockingGraph:
        """The NDBG with parts added whose terms are given (Wilson & Latombe 1992, "Incremental
        modification"). When their normals lie on circles already in the arrangement,
        only the new slots are evaluated, on the circles they use, at every region's
        direction; otherwise the NDBG is rebuilt. Slots stay sorted by moving part."""
        parts = self.parts + tuple(p for p in new_parts if p not in self.parts)
        added = ConstraintTable.build(
            parts, terms, self.tol, self.table.normals, range(len(self.parts), len(parts))
        )
        if len(added.normals) > len(self.table.normals):
            return build_ndbg(
                parts,
                self.motion,
                [*self._terms_of_table(), *terms],
                self.contacts + contacts,
                self.tol,
                self.arrangement.dimension,
            )
        used = np.flatnonzero(np.any(added.plus, axis=1) | np.any(added.minus, axis=1))
        only_new = ConstraintTable(
            added.normals[used],
            added.plus[used],
            added.minus[used],
            added.need,
            added.starts,
            added.slot_moving,
            added.slot_blocker,
        )
        new_slots = only_new.direct_arcs(self.arrangement.directions, self.tol)
        fast = self._into_pads(parts, added, new_slots, contacts)
        if fast is not None:
            return fast
        t = self.table
        moving = np.r_[t.slot_moving, added.slot_moving]
        blocker = np.r_[t.slot_blocker, added.slot_blocker]
        order = np.lexsort((blocker, moving))
        plus, minus = np.hstack([t.plus, added.plus]), np.hstack([t.minus, added.minus])
        need = np.r_[t.need, added.need]
        ncol = t.plus.shape[1]
        starts = np.r_[t.starts, added.starts + ncol]
        sizes = np.diff(np.r_[starts, plus.shape[1]])
        cols = ranges(starts[order], sizes[order])
        table = ConstraintTable(
            t.normals,
            plus[:, cols],
            minus[:, cols],
            need[cols],
            group_starts(sizes[order]),
            moving[order],
            blocker[order],
        )
        slots = np.hstack([self._slot_matrix(), new_slots])[:, order]
        return self._with_slots(parts, table, slots, self.contacts + contacts)

    def _into_pads(
        self,
        parts: tuple[str, ...],
        added: ConstraintTable,
        arcs: NDArray[np.bool_],
        contacts: int,
    ) -> NonDirectionalBlockingGraph | None:
        """Place the new slots without moving the old ones: a slot of an old mover goes
        into a one-column pad of its group, a slot of a new mover after the old slots
        (padded to a whole byte). ``None`` when some old mover has no pad left."""
        t = self.table
        sizes = np.diff(np.r_[t.starts, t.plus.shape[1]])
        free = list(np.flatnonzero((t.slot_moving == t.slot_blocker) & (sizes == 1)))
        added_sizes = np.diff(np.r_[added.starts, added.plus.shape[1]])
        inner = np.flatnonzero(added.slot_moving < len(self.parts))
        outer = np.flatnonzero(added.slot_moving >= len(self.parts))
        placed: list[int] = []
        for s in inner:
            pad = next((f for f in free if t.slot_moving[f] == added.slot_moving[s]), None)
            if pad is None or added_sizes[s] != 1:
                return None
            free.remove(pad)
            placed.append(int(pad))
        plus, minus, need = t.plus.copy(), t.minus.copy(), t.need.copy()
        moving, blocker = t.slot_moving.copy(), t.slot_blocker.copy()
        packed = self.packed.copy()
        for s, slot in zip(inner, placed, strict=True):
            col, new_col = t.starts[slot], added.starts[s]
            plus[:, col], minus[:, col] = added.plus[:, new_col], added.minus[:, new_col]
            need[col] = added.need[new_col]
            moving[slot], blocker[slot] = added.slot_moving[s], added.slot_blocker[s]
            packed[:, slot // 8] |= (arcs[:, s].astype(np.uint8) << (7 - slot % 8)).astype(np.uint8)
        align = -len(t.starts) % 8
        last = moving[-1] if len(moving) else 0
        new_cols = ranges(added.starts[outer], added_sizes[outer])
        ncol = plus.shape[1]
        table = ConstraintTable(
            t.normals,
            np.hstack([plus, np.zeros((len(t.normals), align)), added.plus[:, new_cols]]),
            np.hstack([minus, np.zeros((len(t.normals), align)), added.minus[:, new_cols]]),
            np.r_[need, np.full(align, np.inf), added.need[new_cols]],
            np.r_[
                t.starts,
                ncol + np.arange(align),
                ncol + align + group_starts(added_sizes[outer]),
            ],
            np.r_[moving, np.full(align, last), added.slot_moving[outer]],
            np.r_[blocker, np.full(align, last), added.slot_blocker[outer]],
        )
        packed = np.hstack([packed, np.packbits(arcs[:, outer], axis=1)])
        return NonDirectionalBlockingGraph(
            parts,
            self.motion,
            self.arrangement,
            table,
            packed,
            self.contacts + contacts,
            self.tol,
        )

    def _terms_of_table(self) -> list[BlockingTerm]:
        t = self.table
        ends = np.r_[t.starts[1:], t.plus.shape[1]]
        terms: list[BlockingTerm] = []
        for s, (lo, hi) in enumerate(zip(t.starts, ends, strict=True)):
            moving, blocker = self.parts[t.slot_moving[s]], self.parts[t.slot_blocker[s]]
            for col in range(lo, hi):
                if not np.isfinite(t.need[col]):  # a pad or a removed part's slot
                    continue
                normals = np.concatenate(
                    [t.normals[t.plus[:, col] > 0], -t.normals[t.minus[:, col] > 0]]
                )
                if t.need[col] == 1 and len(normals) > 1:
                    terms.extend(BlockingTerm(moving, blocker, n[None, :]) for n in normals)
                else:
                    terms.append(BlockingTerm(moving, blocker, normals))
        return terms

    def __repr__(self) -> str:
        from assemblykit import formatting as fmt

        counts = self.arrangement.counts
        return fmt.summary(
            "NonDirectionalBlockingGraph",
            self.motion,
            fmt.count(len(self.parts), "part"),
            fmt.count(self.contacts, "contact"),
            fmt.count(sum(counts.values()), "region"),
        )

    def _repr_html_(self) -> str:
        """The removable subassemblies and a direction for each (notebooks)."""
        from assemblykit import formatting as fmt

        rows = [
            (", ".join(sorted(r.parts)), fmt.direction(r.directions[0], self.tol))
            for r in self.removable()
            if r.directions
        ]
        return fmt.html_summary(repr(self), ("removable", "e.g. along"), rows)

    def to_dict(self) -> dict[str, Any]:
        """JSON of docs/blocking.md, "Output": ``parts``, ``contacts``, ``regions``
        counts and ``removable`` sets with their unit directions."""
        return {
            "motion": self.motion,
            "parts": list(self.parts),
            "contacts": self.contacts,
            "regions": self.arrangement.counts,
            "removable": [r.to_dict() for r in self.removable()],
        }


def build_ndbg(
    parts: Sequence[str],
    motion: str,
    terms: Sequence[BlockingTerm],
    contacts: int,
    tol: ModelTolerance,
    dimension: int = 3,
) -> NonDirectionalBlockingGraph:
    """The NDBG of the parts for the given terms: arrangement of the snapped circles
    (S¹ for ``dimension`` 2, S² for 3) and crossing rule."""
    table = ConstraintTable.build(parts, terms, tol)
    if dimension == 2:
        arrangement = circle_partition(table.normals, tol)
    else:
        arrangement = sphere_arrangement(table.normals)
    packed = crossing_rule(arrangement, table)
    return NonDirectionalBlockingGraph(
        tuple(parts), motion, arrangement, table, packed, contacts, tol
    )
