"""Directional blocking graphs along a list of directions, as one table (Wilson &
Latombe 1992, "Directional Blocking Graph"), and the bit masks that stand for sets of
parts.

A :class:`DirectionTable` holds, for every direction, which ordered pairs of parts
block (*slots*, sorted by moving part). It is what the blocking graphs give the planner:
:meth:`assemblykit.blocking.ndbg.NonDirectionalBlockingGraph.direction_table` reads an
NDBG's regions into one, :func:`local_table` evaluates blocking terms along the regions
of each part's own arrangement, and :func:`term_slots` evaluates them along any
directions. Sets of parts are Python integers, bit ``i`` for the ``i``-th part
(:func:`bits`, :func:`mask_of` and the helpers below).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import networkx as nx
import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from assemblykit.blocking.arrangement import snap_normals, sphere_arrangement
from assemblykit.blocking.constraints import BlockingTerm
from assemblykit.part_sets import bits, count_bits, distinct_rows, mask_vector
from assemblykit.tolerance import ModelTolerance


@dataclass(frozen=True, eq=False)
class DirectionTable:
    """DBGs of one NDBG along a list of directions, over a fixed list of parts.

    ``directions[k]`` is the k-th direction (a region's representative). The
    possible arcs are *slots*, sorted by moving part: slot ``s`` is the arc
    ``moving[s] → blocker[s]`` ("``blocker[s]`` blocks ``moving[s]``"), present along
    direction ``k`` when ``slots[k, s]``. Sets of parts are bit masks over ``names``.
    """

    names: tuple[str, ...]
    directions: NDArray[np.float64]
    slots: NDArray[np.bool_]
    moving: NDArray[np.int64]
    blocker: NDArray[np.int64]

    @classmethod
    def from_arcs(
        cls,
        names: Sequence[str],
        directions: ArrayLike,
        arcs: Sequence[Iterable[tuple[int, int]]],
    ) -> DirectionTable:
        """A table from the arcs ``(i, j)`` ("j blocks i") of each direction."""
        pairs = sorted({arc for per_direction in arcs for arc in per_direction})
        column = {pair: s for s, pair in enumerate(pairs)}
        slots = np.zeros((len(arcs), len(pairs)), dtype=bool)
        for k, per_direction in enumerate(arcs):
            slots[k, [column[arc] for arc in per_direction]] = True
        ends = np.array(pairs, dtype=np.int64).reshape(-1, 2)
        return cls(tuple(names), np.asarray(directions, dtype=np.float64), slots, *ends.T)

    def vector(self, members: int) -> NDArray[np.bool_]:
        """The set ``members`` as a boolean vector over ``names``."""
        return mask_vector(members, len(self.names))

    def _active(self, members: int) -> NDArray[np.int64]:
        inside = self.vector(members)
        return np.flatnonzero(inside[self.moving] & inside[self.blocker])

    def free_parts(self, members: int) -> NDArray[np.bool_]:
        """``free[k, i]``: part i of ``members`` has no blocker in ``members`` along k."""
        packed = self.free_bits(members, members)
        return np.unpackbits(packed, axis=1, count=len(self.names), bitorder="little").astype(bool)

    def free_bits(self, members: int, movers: int) -> NDArray[np.uint8]:
        """Per direction, the parts of ``movers`` with no blocker in ``members``, packed
        (bit ``i`` of row ``k`` read little-endian, as :func:`row_mask` does). A search
        that asks of shrinking sets keeps a :class:`BlockedRows` instead."""
        return self.free_of(self.blocked_bits(members), members, movers)

    def free_of(self, blocked: NDArray[np.uint8], members: int, movers: int) -> NDArray[np.uint8]:
        """:meth:`free_bits` from the rows of :meth:`blocked_bits` for ``members``."""
        return ~blocked & np.packbits(self.vector(movers & members), bitorder="little")

    def blocked_bits(self, members: int) -> NDArray[np.uint8]:
        """Per direction, the parts of ``members`` with a blocker in ``members``, packed
        as :meth:`free_bits` packs them."""
        unpacked = np.zeros((len(self.directions), len(self.names)), dtype=bool)
        columns = self._active(members)
        if len(columns):
            owners = self.moving[columns]
            starts = np.flatnonzero(np.r_[True, owners[1:] != owners[:-1]])
            # every slot is active in the first call: no copy of the table then
            active = self.slots if len(columns) == self.slots.shape[1] else self.slots[:, columns]
            # maximum over 0/1 bytes is logical or, and much faster along rows
            unpacked[:, owners[starts]] = np.maximum.reduceat(
                active.view(np.uint8), starts, axis=1
            ).view(bool)
        return np.packbits(unpacked, axis=1, bitorder="little")

    def blocked_after_removing(
        self, blocked: NDArray[np.uint8], members: int, removed: int
    ) -> None:
        """Turn ``blocked``, the rows of :meth:`blocked_bits` for ``members | removed``,
        into those for ``members``, in place: only the parts of ``members`` that had a
        blocker in ``removed`` are measured again."""
        inside = self.vector(members)
        gone = self.vector(removed)
        for i in np.unique(self.moving[gone[self.blocker]]):
            if inside[i]:
                column = self._blocked_part(int(i), inside).astype(np.uint8)
                byte, bit = divmod(int(i), 8)
                blocked[:, byte] &= np.uint8(~(1 << bit) & 0xFF)
                blocked[:, byte] |= column << np.uint8(bit)

    def _blocked_part(self, i: int, inside: NDArray[np.bool_]) -> NDArray[np.bool_]:
        """Per direction, whether part ``i`` has a blocker among ``inside``."""
        lo, hi = np.searchsorted(self.moving, [i, i + 1])
        columns = np.arange(lo, hi)[inside[self.blocker[lo:hi]]]
        return np.asarray(self.slots[:, columns].any(axis=1))

    def graph(self, k: int, members: int) -> nx.DiGraph[int]:
        """The DBG of direction ``k`` induced on ``members``: arc i→j when j blocks i."""
        columns = self._active(members)
        columns = columns[self.slots[k, columns]]
        graph: nx.DiGraph[int] = nx.DiGraph()
        graph.add_nodes_from(bits(members))
        graph.add_edges_from(
            zip(self.moving[columns].tolist(), self.blocker[columns].tolist(), strict=True)
        )
        return graph

    def _components(
        self, members: int
    ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.bool_]]:
        """The strong components of each distinct DBG induced on ``members``: per
        direction, the row of its DBG; per row and member (in bit order), its component;
        per component, whether it is a sink (no arc leaves it). The distinct DBGs are
        taken as one graph, their disjoint union, whose strong components are theirs:
        one call to scipy's ``connected_components`` for all of them, the components
        :func:`~assemblykit.blocking.dbg.blocking_components` gives one DBG at a time."""
        inside = self.vector(members)
        nodes = np.flatnonzero(inside)
        index = np.full(len(self.names), -1, dtype=np.int64)
        index[nodes] = np.arange(len(nodes))
        columns = self._active(members)
        moving, blocker = index[self.moving[columns]], index[self.blocker[columns]]
        patterns, which = distinct_rows(np.packbits(self.slots[:, columns], axis=1))
        rows, arcs = np.nonzero(np.unpackbits(patterns, axis=1, count=len(columns)))
        tails, heads = rows * len(nodes) + moving[arcs], rows * len(nodes) + blocker[arcs]
        size = len(patterns) * len(nodes)
        union = coo_matrix((np.ones(len(tails)), (tails, heads)), shape=(size, size))
        count, label = connected_components(union, directed=True, connection="strong")
        sink = np.ones(count, dtype=bool)
        sink[label[tails][label[tails] != label[heads]]] = False
        return which, label.reshape(len(patterns), len(nodes)), sink

    def free_set_sizes(self, members: int, keep: int) -> NDArray[np.int64]:
        """Per direction, how many parts of ``members`` its free sets take away: the
        parts of the sink strong components of its DBG induced on ``members`` (Wilson &
        Latombe 1992, "Directional Blocking Graph"), but for the component holding part ``keep``.
        Directions with the same DBG share one computation."""
        place = count_bits(members & ((1 << keep) - 1))
        which, label, sink = self._components(members)
        taken = sink[label] & (label != label[:, place : place + 1])
        sizes: NDArray[np.int64] = np.count_nonzero(taken, axis=1).astype(np.int64)
        return sizes[which]

    def separating(self, members: int) -> NDArray[np.bool_]:
        """Per direction, whether its DBG induced on ``members`` is not strongly
        connected: some proper, non-empty part of ``members`` is free along it."""
        which, label, _ = self._components(members)
        split: NDArray[np.bool_] = np.any(label != label[:, :1], axis=1)
        return split[which]

    def incomplete(self, members: int) -> list[int]:
        """The directions along which some part of ``members`` does not block another:
        the only ones that may separate any subset of ``members`` (Γ_e blocks at least
        where Γ_t does)."""
        columns = self._active(members)
        size = count_bits(members)
        arcs = self.slots[:, columns].sum(axis=1)
        return [int(k) for k in np.flatnonzero(arcs < size * (size - 1))]

    def blockers(self, k: int, movers: int, among: int) -> dict[int, int]:
        """Per part of ``movers``, the mask of its blockers in ``among`` along ``k``."""
        masks = self.masks(k)
        return {i: masks[i] & among & ~(1 << i) for i in bits(movers)}

    def appended(self, directions: NDArray[np.float64], slots: NDArray[np.bool_]) -> DirectionTable:
        """The table with more directions (rows of ``slots`` over the same slots)."""
        return DirectionTable(
            self.names,
            np.vstack([self.directions, directions]),
            np.vstack([self.slots, slots]),
            self.moving,
            self.blocker,
        )

    def distinct_directions(self) -> list[int]:
        """One direction per distinct DBG: the one closest to a coordinate axis."""
        inverse = distinct_rows(self.slots)[1]
        order = np.lexsort((-np.abs(self.directions).max(axis=1), inverse))
        return sorted(order[np.r_[True, inverse[order][1:] != inverse[order][:-1]]].tolist())

    def held_pair(self, members: int) -> int:
        """The first pair of ``members`` (in index order) blocked both ways along every
        direction, as a mask; 0 when there is none. No translation separates such a
        pair."""
        everywhere = self.slots.all(axis=0)
        inside = self.vector(members)
        arcs = {
            (int(i), int(j))
            for i, j in zip(self.moving[everywhere], self.blocker[everywhere], strict=True)
            if inside[i] and inside[j]
        }
        pairs = sorted((i, j) for i, j in arcs if i < j and (j, i) in arcs)
        return (1 << pairs[0][0]) | (1 << pairs[0][1]) if pairs else 0

    def masks(self, k: int) -> tuple[int, ...]:
        """Per part, the bit mask of its blockers along direction ``k``."""
        masks = [0] * len(self.names)
        for s in np.flatnonzero(self.slots[k]):
            masks[self.moving[s]] |= 1 << int(self.blocker[s])
        return tuple(masks)


@dataclass(eq=False)
class BlockedRows:
    """The memory a search keeps of :meth:`DirectionTable.blocked_bits` for the set it
    asked last: the greedy search asks of shrinking sets (a step takes parts away), and
    when a set is a subset of the one asked last, only the parts that had a blocker
    among the parts since removed are measured again
    (:meth:`DirectionTable.blocked_after_removing`). Owned by the search, for one table:
    a table with more directions needs a memory of its own."""

    table: DirectionTable
    members: int = 0
    blocked: NDArray[np.uint8] | None = None

    def free_bits(self, members: int, movers: int) -> NDArray[np.uint8]:
        """:meth:`DirectionTable.free_bits`, from the rows kept for the set asked last
        where ``members`` is a subset of it."""
        if self.blocked is not None and self.members & members == members:
            self.table.blocked_after_removing(self.blocked, members, self.members & ~members)
        else:
            self.blocked = self.table.blocked_bits(members)
        self.members = members
        return self.table.free_of(self.blocked, members, movers)


def local_table(
    names: tuple[str, ...], terms: Sequence[BlockingTerm], tol: ModelTolerance
) -> DirectionTable:
    """Γ_t along the regions of each part's own arrangement (the great circles of the
    terms that block it: the arrangement of Wilson & Latombe 1992, "3D case", one part
    at a time).

    A part's blockers are constant over each region of its own arrangement, so every
    way Γ_t lets a single part leave any subassembly is among these directions; groups
    that must leave together may be free along others. On the 527-block dome: 49,926
    directions instead of 2.2 million regions."""
    index = {name: i for i, name in enumerate(names)}
    own: dict[str, list[NDArray[np.float64]]] = {}
    for term in terms:
        own.setdefault(term.moving, []).append(term.normals)
    directions = np.vstack(
        [
            sphere_arrangement(snap_normals(np.vstack(rows), tol)[0]).directions
            for rows in own.values()
        ]
        or [np.array([[0.0, 0.0, 1.0]])]
    )
    pairs = sorted({(index[t.moving], index[t.blocker]) for t in terms})
    column = {pair: s for s, pair in enumerate(pairs)}
    owners = [column[(index[t.moving], index[t.blocker])] for t in terms]
    slots = term_slots(directions, terms, owners, len(pairs), tol)
    ends = np.array(pairs, dtype=np.int64).reshape(-1, 2)
    return DirectionTable(names, directions, slots, *ends.T)


TERM_CHUNK = 256
"""Directions whose inner products with every term normal :func:`term_slots` holds at
once (a few MB on the dome: the chunk stays in cache)."""


def term_slots(
    directions: NDArray[np.float64],
    terms: Sequence[BlockingTerm],
    owners: Sequence[int],
    count: int,
    tol: ModelTolerance,
) -> NDArray[np.bool_]:
    """``slots[k, s]``: some term of slot ``s`` (``owners[t]`` is term ``t``'s slot) holds
    strictly along direction ``k``, every normal ``n`` of it with ``n . d > tol.angle``: a
    direction on a circle (edge, vertex) is on neither side, within the angle tolerance,
    as the arrangement's snapping has it. All terms at once, a chunk of directions at a
    time."""
    # column-major: the search gathers the slots of one moving part over every direction
    slots = np.zeros((len(directions), count), dtype=bool, order="F")
    sizes = np.array([len(np.atleast_2d(t.normals)) for t in terms], dtype=np.int64)
    always = np.array(owners, dtype=np.int64)[sizes == 0]
    slots[:, always] = True  # a term without normals holds everywhere
    used = [t for t, size in zip(terms, sizes.tolist(), strict=True) if size]
    if not used:
        return slots
    normals = np.vstack([np.atleast_2d(t.normals) for t in used]).T.copy()
    firsts = np.r_[0, np.cumsum(sizes[sizes > 0])[:-1]]
    slot_of = np.array(owners, dtype=np.int64)[sizes > 0]
    order = np.argsort(slot_of, kind="stable")
    ordered = slot_of[order]
    starts = np.flatnonzero(np.r_[True, ordered[1:] != ordered[:-1]])
    single = bool((sizes[sizes > 0] == 1).all())
    # one normal per term and one term per slot (COMPAS vaults): no reduction, the
    # normals put in slot order
    direct = single and np.array_equal(ordered, np.arange(count))
    if direct:
        normals = normals[:, order]
    for lo in range(0, len(directions), TERM_CHUNK):
        chunk = directions[lo : lo + TERM_CHUNK]
        inner = chunk[:, :1] * normals[0] + chunk[:, 1:2] * normals[1] + chunk[:, 2:] * normals[2]
        if direct:
            slots[lo : lo + TERM_CHUNK] |= inner > tol.angle
            continue
        ahead = (inner > tol.angle).view(np.uint8)
        # minimum and maximum over 0/1 bytes: "all normals" per term, "any term" per slot
        held = ahead if single else np.minimum.reduceat(ahead, firsts, axis=1)
        slots[lo : lo + TERM_CHUNK, ordered[starts]] |= np.maximum.reduceat(
            held[:, order], starts, axis=1
        ).view(bool)
    return slots
