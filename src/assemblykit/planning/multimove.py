"""Multi-move disassembly of interlocking voxel pieces: sequences of translations.

Wilson & Latombe 1992 plan with one translation per separation (a *monotone* plan) and cite
separating parts "by a sequence of translations" [Pollack et al., 1988] as the harder
problem; interlocking puzzles (burrs) need such sequences, sometimes of a hundred moves.
On the lattice the problem is exact and finite:

* a *state* is the relative placement of the pieces: an integer offset per piece,
  normalised so that the first piece stays put (moving a group one way equals moving
  the others the other way);
* a *move* translates a group of pieces by ``k`` cells along ±x, ±y or ±z without
  collision at any intermediate cell; the groups tried are, per direction and starting
  piece, the smallest set that can move at all and then the sets grown by the pieces
  that stop it, each by every distance it can go (the moves BurrTools counts);
* a state *separates* when a group can go to infinity along an axis with nothing in its
  way.

The search is breadth-first on the number of moves, so the first separation found takes
the fewest moves; then each of the two subassemblies is planned the same way. The
plan is a tree of separations, like the ones BurrTools stores, whose *level* lists the
moves of each separation (``4.9.3``). A group whose pieces all share one nonzero group
number (BurrTools' grouping: pieces meant to stay together) is not taken apart.

Collision distances come from precomputed tables: pieces ``i`` and ``j`` overlap iff
``o_i - o_j`` lies in ``D_ij = {v_j - v_i}``; for each axis and sign a table over the
bounding box of ``D_ij`` holds the distance to the next such offset along the axis, so a
state's distances for all pairs and directions are one gather.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections import deque
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import networkx as nx
import numpy as np
from numpy.typing import NDArray

from assemblykit import formatting as fmt
from assemblykit.blocking.dbg import blocking_components
from assemblykit.errors import UnknownNameError
from assemblykit.ragged import group_of, ranges

MAX_STATES = 250_000
"""Default limit of states visited per separation: Pelikan's 98-move first separation
visits about 6,700, and a search past this many states is cut (and says so) rather
than running for minutes."""

AXES = ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1))
"""The six lattice directions, in the order of the distance tables."""

_INF = 1 << 40  # "never collides": far beyond any offset a search can reach

Progress = Callable[[str, int, int], None]


def moving_groups(
    parts: Sequence[str], arcs: Iterable[tuple[str, str]]
) -> tuple[tuple[str, ...], ...]:
    """The parts a step moves, split into the sets that hold one another: the strongly
    connected components of the step's DBG restricted to them (an arc ``(i, j)``: ``j``
    blocks ``i``), each after the sets that block it, so that moved one after another
    along the step's direction none meets another (docs/planning.md, "JSON"). One set:
    the parts move as one rigid group; several: each may move on its own."""
    inside = set(parts)
    graph: nx.DiGraph[str] = nx.DiGraph()
    graph.add_nodes_from(parts)
    graph.add_edges_from((i, j) for i, j in arcs if i in inside and j in inside and i != j)
    condensed = blocking_components(graph)
    rank = {name: k for k, name in enumerate(parts)}

    def first(component: int) -> int:
        return min(rank[name] for name in condensed.nodes[component]["members"])

    # an arc i -> j asks for j's set to move first: the reverse of a topological order
    order = list(nx.lexicographical_topological_sort(condensed.reverse(), key=first))
    return tuple(tuple(sorted(condensed.nodes[c]["members"], key=rank.__getitem__)) for c in order)


@dataclass(frozen=True)
class Move:
    """``parts`` translate by ``distance`` along the unit ``direction`` relative to the
    other parts of the subassembly (on the lattice: a whole number of cells along an
    axis); ``distance`` None means to infinity (the move that separates). ``groups``,
    when known, splits ``parts`` into the sets that hold one another, in an order in
    which they may move one after another (:func:`moving_groups`); empty: one rigid
    group."""

    parts: tuple[str, ...]
    direction: tuple[float, float, float]
    distance: float | None
    groups: tuple[tuple[str, ...], ...] = ()

    @property
    def label(self) -> str:
        """The direction for people (docs/architecture.md, "Numbers for people")."""
        return fmt.direction(self.direction)

    @property
    def together(self) -> bool:
        """Whether the parts move as one rigid group (they hold one another), not as
        independent parts."""
        return len(self.groups) <= 1

    def to_dict(self) -> dict[str, Any]:
        """JSON form: ``parts``, ``direction``, ``distance`` (null: to infinity),
        ``together`` and, when the parts move independently, ``moves`` (one per set that
        holds together, in an order they may move one after another: ``parts``,
        ``direction``, ``distance``)."""
        return {
            "parts": list(self.parts),
            "direction": list(self.direction),
            "distance": self.distance,
            **self.grouping(list(self.direction)),
        }

    def grouping(self, direction: list[Any]) -> dict[str, Any]:
        """The JSON keys that say what moves with what (:meth:`to_dict`), each set's
        direction written as ``direction``."""
        if self.together:
            return {"together": True}
        moves = [
            {"parts": list(g), "direction": direction, "distance": self.distance}
            for g in self.groups
        ]
        return {"together": False, "moves": moves}


@dataclass(frozen=True)
class Separation:
    """How one subassembly (``parts``) comes apart: ``moves`` up to and including the
    one that takes ``removed`` to infinity, leaving ``left``; each half is a further
    :class:`Separation` when it has several parts. ``status`` is ``separated``,
    ``group`` (parts meant to stay together: not searched), ``fixed`` (fixed parts
    only, docs/planning.md, "Fixed parts": not searched), ``stuck`` (no sequence of
    moves separates it: every reachable state was visited) or ``cut`` (the search
    stopped at the state limit). ``states`` counts the states visited."""

    parts: tuple[str, ...]
    moves: tuple[Move, ...]
    removed: Separation | None
    left: Separation | None
    status: str
    states: int
    removed_parts: tuple[str, ...] = ()

    def levels(self) -> tuple[int, ...]:
        """Moves of this separation then of those below it, ``removed`` before ``left``."""
        if self.status != "separated":
            return ()
        below = [s.levels() for s in (self.removed, self.left) if s is not None]
        return (len(self.moves), *(n for part in below for n in part))

    def unfinished(self) -> list[Separation]:
        """The subassemblies in this tree that are ``stuck`` or ``cut``."""
        if self.status in ("stuck", "cut"):
            return [self]
        return [u for s in (self.removed, self.left) if s is not None for u in s.unfinished()]

    def flattened(self) -> list[Move]:
        """Every move of the tree in disassembly order (this separation, then removed,
        then left)."""
        below = [m for s in (self.removed, self.left) if s is not None for m in s.flattened()]
        return [*self.moves, *below]

    def to_dict(self) -> dict[str, Any]:
        """JSON form: ``parts``, ``status``, ``states``, ``moves``, ``removed_parts`` and
        the ``removed`` / ``left`` separations (null for a single part)."""
        return {
            "parts": list(self.parts),
            "status": self.status,
            "states": self.states,
            "moves": [m.to_dict() for m in self.moves],
            "removed_parts": list(self.removed_parts),
            "removed": None if self.removed is None else self.removed.to_dict(),
            "left": None if self.left is None else self.left.to_dict(),
        }


@dataclass(frozen=True)
class MultiMovePlan:
    """A multi-move disassembly plan (module docstring; of meshes:
    :mod:`assemblykit.planning.multimove_mesh`); ``root`` is
    None for a single piece. ``reference_level`` is a level to compare with (BurrTools'
    stored one), ``max_states`` the limit each search ran under."""

    parts: tuple[str, ...]
    root: Separation | None
    max_states: int
    reference_level: str | None = None

    @property
    def feasible(self) -> bool:
        """True when every part is separated (groups kept together count as done)."""
        return self.root is None or not self.root.unfinished()

    @property
    def cut(self) -> bool:
        """True when some search stopped at the state limit."""
        return self.root is not None and any(s.status == "cut" for s in self.root.unfinished())

    @property
    def stuck(self) -> tuple[str, ...]:
        """Parts of the subassemblies left stuck or cut."""
        if self.root is None:
            return ()
        return tuple(sorted({p for s in self.root.unfinished() for p in s.parts}))

    @property
    def level(self) -> str:
        """Moves of each separation joined by dots (``4.9.3``); empty when none."""
        return "" if self.root is None else ".".join(map(str, self.root.levels()))

    @property
    def first_moves(self) -> int | None:
        """Moves of the first separation, None when the whole does not separate."""
        if self.root is None or self.root.status != "separated":
            return None
        return len(self.root.moves)

    @property
    def states(self) -> int:
        """States visited by all the searches."""

        def total(node: Separation | None) -> int:
            return 0 if node is None else node.states + total(node.removed) + total(node.left)

        return total(self.root)

    def to_dict(self) -> dict[str, Any]:
        """JSON form: the plan keys of docs/planning.md, "JSON" (``feasible``, ``steps``,
        ``stuck``) plus ``moves`` (``multi``), ``level``, ``reference_level``,
        ``first_moves``, ``cut``, ``states``, ``max_states`` and ``separations`` (the
        tree)."""
        moves = [] if self.root is None else self.root.flattened()
        return {
            "feasible": self.feasible,
            "steps": [
                {
                    "parts": list(m.parts),
                    "direction": [float(x) for x in m.direction],
                    "motion": "translation",
                    "distance": m.distance,
                    **m.grouping([float(x) for x in m.direction]),
                }
                for m in moves
            ],
            "stuck": list(self.stuck),
            "parts": list(self.parts),
            "moves": "multi",
            "level": self.level,
            "reference_level": self.reference_level,
            "first_moves": self.first_moves,
            "cut": self.cut,
            "states": self.states,
            "max_states": self.max_states,
            "separations": None if self.root is None else self.root.to_dict(),
        }


class _Tables:
    """Next-collision distances of every ordered pair of pieces along the six
    directions (module docstring), flattened into one array for a gather per state."""

    def __init__(self, voxels: Sequence[NDArray[np.int64]]) -> None:
        n = len(voxels)
        chunks: list[NDArray[np.int64]] = []
        rows: list[list[int]] = []  # first, second, direction, base, low, strides, shape
        size = 0
        for i in range(n):
            for j in range(n):
                if i == j:
                    continue
                diff = (voxels[j][None, :, :] - voxels[i][:, None, :]).reshape(-1, 3)
                # one empty cell of margin: offsets beyond the box clamp onto it
                low = diff.min(axis=0) - 1
                shape = diff.max(axis=0) - low + 2
                occupied = np.zeros(tuple(shape), dtype=bool)
                occupied[tuple((diff - low).T)] = True
                strides = [int(shape[1] * shape[2]), int(shape[2]), 1]
                for d, step in enumerate(AXES):
                    table = _next_hits(occupied, d // 2, step[d // 2])
                    rows.append([i, j, d, size, *low.tolist(), *strides, *shape.tolist()])
                    chunks.append(table.ravel())
                    size += table.size
        self.n = n
        self.flat = np.concatenate(chunks) if chunks else np.zeros(0, dtype=np.int64)
        entries = np.array(rows, dtype=np.int64).reshape(-1, 13)
        self.first, self.second, self.direction, self.base = entries[:, :4].T
        self.low = entries[:, 4:7]
        self.strides = entries[:, 7:10]
        self.high = self.low + entries[:, 10:13] - 1
        self.axis = self.direction // 2
        self.sign = np.where(self.direction % 2 == 0, 1, -1)

    def subset(self, members: Sequence[int]) -> NDArray[np.bool_]:
        """Entries whose two pieces are both among ``members``."""
        inside = np.zeros(self.n, dtype=bool)
        inside[list(members)] = True
        both: NDArray[np.bool_] = inside[self.first] & inside[self.second]
        return both

    def free(self, offsets: NDArray[np.int64], entries: NDArray[np.bool_]) -> NDArray[np.int64]:
        """``free[d, i, j]``: how many cells piece ``i`` can move along ``AXES[d]`` before
        it meets piece ``j`` (≥ ``_INF // 2``: never), for the pairs in ``entries``."""
        first, second = self.first[entries], self.second[entries]
        relative = offsets[first] - offsets[second]
        low, high = self.low[entries], self.high[entries]
        clamped = np.clip(relative, low, high)
        index = self.base[entries] + ((clamped - low) * self.strides[entries]).sum(axis=1)
        rows = np.arange(len(first))
        axis = self.axis[entries]
        beyond = self.sign[entries] * (clamped[rows, axis] - relative[rows, axis])
        out = np.full((6, self.n, self.n), _INF, dtype=np.int64)
        out[self.direction[entries], first, second] = self.flat[index] + beyond - 1
        return out


def _next_hits(occupied: NDArray[np.bool_], axis: int, sign: int) -> NDArray[np.int64]:
    """For each cell, the number of steps along ``sign`` x ``axis`` to the next occupied
    cell (≥ 1), ``_INF`` when there is none."""
    grid = np.moveaxis(occupied, axis, 0)
    if sign < 0:
        grid = grid[::-1]
    hits = np.full(grid.shape, _INF, dtype=np.int64)
    for p in range(grid.shape[0] - 2, -1, -1):
        hits[p] = np.where(grid[p + 1], 1, np.minimum(hits[p + 1] + 1, _INF))
    if sign < 0:
        hits = hits[::-1]
    return np.moveaxis(hits, 0, axis)


def _moves(free: NDArray[np.int64]) -> tuple[list[tuple[int, int]], NDArray[np.int64]]:
    """The moves of a state whose ``m`` pieces have the free distances ``free[d, i, j]``:
    the groups that leave, as ``(mask, direction)``, and the finite moves, as rows
    ``(mask, direction, distance)``.

    Moving piece ``i`` by ``k`` cells drags every piece reachable from it through pairs
    that stop each other within fewer than ``k`` cells; with ``B[i, j]`` the bottleneck
    (minimax) distance of the paths from ``i`` to ``j`` that group is
    ``{j : B[i, j] < k}``. As in BurrTools, each such group of at most ``m // 2`` pieces
    moves by each ``k`` it stays the same for (larger groups are the complement of
    one moving the other way), and groups moving the same distance the same way also
    move together (their unions)."""
    m = free.shape[1]
    bottleneck = free.copy()
    diagonal = np.arange(m)
    bottleneck[:, diagonal, diagonal] = -1
    for k in range(m):
        through = np.maximum(bottleneck[:, :, k : k + 1], bottleneck[:, k : k + 1, :])
        np.minimum(bottleneck, through, out=bottleneck)
    weights = np.left_shift(1, np.arange(m, dtype=np.int64))
    # for start i and bound v = B[d, i, j]: the group {l : B[d, i, l] < v}, its size,
    # and the largest bound below v (the group holds for distances above it up to v)
    inside = bottleneck[:, :, None, :] < bottleneck[:, :, :, None]
    masks = (inside * weights).sum(axis=3)
    sizes = inside.sum(axis=3)
    below = np.where(inside, bottleneck[:, :, None, :], -1).max(axis=3)
    direction = np.broadcast_to(np.arange(6)[:, None, None], masks.shape)
    small = (sizes <= m // 2) & (bottleneck >= 1)
    leaves = small & (bottleneck >= _INF // 2)
    removals = sorted(set(zip(masks[leaves].tolist(), direction[leaves].tolist(), strict=True)))
    finite = small & ~leaves
    rows = np.unique(
        np.stack(
            [
                masks[finite],
                direction[finite],
                np.maximum(below[finite], 0) + 1,
                bottleneck[finite],
            ],
            axis=1,
        ),
        axis=0,
    )
    counts = rows[:, 3] - rows[:, 2] + 1
    which = group_of(counts)
    moves = np.stack([rows[which, 0], rows[which, 1], ranges(rows[:, 2], counts)], axis=1)
    return removals, _merged(moves, (1 << m) - 1)


def _merged(moves: NDArray[np.int64], full: int) -> NDArray[np.int64]:
    """``moves`` with the unions of groups moving the same way by the same distance
    (short of all the pieces) added."""
    if len(moves) < 2:
        return moves
    order = np.lexsort((moves[:, 2], moves[:, 1]))
    moves = moves[order]
    keys = moves[:, 1] * _INF + moves[:, 2]
    starts = np.flatnonzero(np.r_[True, keys[1:] != keys[:-1]])
    ends = np.r_[starts[1:], len(moves)]
    extra: list[tuple[int, int, int]] = []
    for start, end in zip(starts.tolist(), ends.tolist(), strict=True):
        if end - start < 2:
            continue
        groups = set(moves[start:end, 0].tolist())
        frontier = set(groups)
        while frontier:
            grown = {a | b for a in frontier for b in groups} - groups - {full}
            groups |= grown
            frontier = grown
        _, d, k = moves[start].tolist()
        extra.extend((g, d, k) for g in groups - set(moves[start:end, 0].tolist()))
    if not extra:
        return moves
    return np.concatenate([moves, np.array(extra, dtype=np.int64)])


def _bits(mask: int, members: Sequence[int]) -> list[int]:
    """The members whose local bit (position in ``members``) is set in ``mask``."""
    return [m for k, m in enumerate(members) if mask >> k & 1]


@dataclass(frozen=True)
class _Split:
    """A separation found by the search: its ``moves``, the placement of every piece
    before the last one (``final``), the pieces ``removed`` and the states visited."""

    moves: tuple[Move, ...]
    final: NDArray[Any]
    removed: list[int]
    states: int


Found = tuple[list[int], Move]
"""A separating move of a state: the pieces it removes and the move to infinity."""


class MultiMoveSearch(ABC):
    """Breadth-first multi-move search over subassemblies, shared by the lattice
    (:func:`plan_voxels`) and by meshes (:mod:`assemblykit.planning.multimove_mesh`).

    A subclass defines the states: :meth:`origin` (a state from a placement),
    :meth:`expand` (a state's separating move, else its successors), :meth:`move` (a
    recorded move as reported) and :meth:`placement`. States are told apart by a key
    (bytes), so equivalent placements are visited once."""

    def __init__(
        self,
        names: Sequence[str],
        groups: Sequence[int],
        max_states: int,
        progress: Progress,
        fixed: Iterable[int] = (),
    ) -> None:
        self.names = list(names)
        self.groups = list(groups)
        self.max_states = max_states
        self.progress = progress
        self.done = 0
        self.fixed = frozenset(fixed)
        """The pieces that never move (docs/planning.md, "Fixed parts"): placed first in
        every subassembly, so that they are the piece that stays put; no move takes some
        of them and not the others, and no separation removes them."""

    def fixed_bits(self, members: Sequence[int]) -> int:
        """The fixed pieces of ``members`` as local bits (bit ``i``: ``members[i]``)."""
        return sum(1 << i for i, m in enumerate(members) if m in self.fixed)

    def keeps_fixed(self, members: Sequence[int], group: int) -> bool:
        """Whether moving the local bits ``group`` of ``members`` keeps the fixed pieces
        where they are relative to one another: it holds all of them or none."""
        anchor = self.fixed_bits(members)
        return group & anchor in (0, anchor)

    def flipped(self, members: Sequence[int], group: int) -> bool:
        """Whether the separating ``group`` (local bits) is reported as the others
        leaving the other way: when it holds the fixed pieces, else when it is the
        larger half."""
        anchor = self.fixed_bits(members)
        if anchor:
            return bool(group & anchor)
        return 2 * bin(group).count("1") > len(members)

    @abstractmethod
    def origin(self, members: list[int], start: NDArray[Any]) -> tuple[bytes, Any]:
        """The key and state of ``members`` placed as in ``start`` (one row per piece)."""

    @abstractmethod
    def expand(
        self, members: list[int], state: Any
    ) -> tuple[Found | None, Iterable[tuple[bytes, Any, Any]]]:
        """A separating move of ``state`` when there is one, and the successors as
        ``(key, state, move)`` (``move`` as given to :meth:`move`)."""

    @abstractmethod
    def move(self, members: list[int], raw: Any) -> Move:
        """A successor's recorded move as reported."""

    @abstractmethod
    def placement(self, members: list[int], state: Any) -> NDArray[Any]:
        """The placement of ``state`` with one row per piece of the whole."""

    def plan(self, members: list[int], start: NDArray[Any]) -> Separation:
        """The separation tree of ``members`` starting at ``start`` (one row per piece
        of the whole; rows of other pieces are ignored)."""
        members = sorted(members, key=lambda m: (m not in self.fixed, m))
        parts = tuple(self.names[m] for m in members)
        if all(m in self.fixed for m in members):
            return Separation(parts, (), None, None, "fixed", 0)
        shared = {self.groups[m] for m in members}
        if len(shared) == 1 and 0 not in shared:
            return Separation(parts, (), None, None, "group", 0)
        found = self._search(members, start)
        self.progress("planning", self.done, len(self.names))
        if not isinstance(found, _Split):
            status, states = found
            return Separation(parts, (), None, None, status, states)
        left = [m for m in members if m not in found.removed]
        halves = []
        for half in (found.removed, left):
            halves.append(self.plan(half, found.final) if len(half) > 1 else None)
            if len(half) == 1:
                self.done += 1
        return Separation(
            parts,
            found.moves,
            halves[0],
            halves[1],
            "separated",
            found.states,
            tuple(self.names[m] for m in found.removed),
        )

    def _search(self, members: list[int], start: NDArray[Any]) -> _Split | tuple[str, int]:
        """Breadth-first search from ``start`` for the fewest moves that separate
        ``members``: the :class:`_Split`, else ``("stuck", states)`` or
        ``("cut", states)``."""
        key, state = self.origin(members, start)
        parents: dict[bytes, tuple[bytes, Any] | None] = {key: None}
        queue = deque([(key, state)])
        while queue:
            key, state = queue.popleft()
            found, children = self.expand(members, state)
            if found is not None:
                path = []
                at = parents[key]
                while at is not None:
                    path.append(at[1])
                    at = parents[at[0]]
                moves = [self.move(members, raw) for raw in reversed(path)]
                removed, last = found
                final = self.placement(members, state)
                return _Split((*moves, last), final, removed, len(parents))
            for child, after, raw in children:
                if child not in parents:
                    parents[child] = (key, raw)
                    queue.append((child, after))
            if len(parents) > self.max_states:
                return ("cut", len(parents))
        return ("stuck", len(parents))


class _Planner(MultiMoveSearch):
    """The lattice states of the module docstring: integer offsets, moves from the
    distance tables; a state is its own key."""

    def __init__(
        self,
        names: Sequence[str],
        voxels: Sequence[NDArray[np.int64]],
        groups: Sequence[int],
        max_states: int,
        progress: Progress,
        fixed: Iterable[int] = (),
    ) -> None:
        super().__init__(names, groups, max_states, progress, fixed)
        self.tables = _Tables([np.asarray(v, dtype=np.int64).reshape(-1, 3) for v in voxels])
        self.steps = np.array(AXES, dtype=np.int64)
        self.entries: dict[tuple[int, ...], NDArray[np.bool_]] = {}

    def origin(self, members: list[int], start: NDArray[Any]) -> tuple[bytes, Any]:
        local = np.array(members)
        key = (start[local] - start[local[0]]).astype(np.int64).tobytes()
        return key, key

    def expand(
        self, members: list[int], state: Any
    ) -> tuple[Found | None, Iterable[tuple[bytes, Any, Any]]]:
        entries = self.entries.setdefault(tuple(members), self.tables.subset(members))
        offsets = np.frombuffer(state, dtype=np.int64).reshape(-1, 3)
        whole = np.zeros((self.tables.n, 3), dtype=np.int64)
        whole[members] = offsets
        free = self.tables.free(whole, entries)[np.ix_(range(6), members, members)]
        removals, moves = _moves(free)
        anchor = self.fixed_bits(members)
        removals = [r for r in removals if self.keeps_fixed(members, r[0])]
        moves = moves[((moves[:, 0] & anchor) == 0) | ((moves[:, 0] & anchor) == anchor)]
        if removals:
            group, d = min(removals, key=lambda r: (bin(r[0]).count("1"), r[1], r[0]))
            return self._separating(members, group, d, state), ()
        bits = np.left_shift(1, np.arange(len(members), dtype=np.int64))
        moved = (moves[:, 0:1] & bits) != 0
        step = self.steps[moves[:, 1]] * moves[:, 2:3]
        after = offsets + moved[:, :, None] * step[:, None, :]
        after = after - after[:, :1, :]
        keys = [row.tobytes() for row in after]
        # each move keeps the state it starts from, to tell what moves with what
        raws = [(*row, state) for row in moves.tolist()]
        return None, zip(keys, keys, raws, strict=True)

    def move(self, members: list[int], raw: Any) -> Move:
        # the first piece stays put: a group holding it is reported as the others
        # moving the opposite way (the same relative motion)
        group, d, k, state = raw
        if group & 1:
            group, d = ((1 << len(members)) - 1) ^ group, d ^ 1
        return self._move(group, d, k, members, state)

    def placement(self, members: list[int], state: Any) -> NDArray[Any]:
        final = np.zeros((self.tables.n, 3), dtype=np.int64)
        final[members] = np.frombuffer(state, dtype=np.int64).reshape(-1, 3)
        return final

    def _separating(self, members: list[int], group: int, d: int, state: bytes) -> Found:
        removed = _bits(group, members)
        if self.flipped(members, group):
            # report the smaller half (the one without the fixed pieces) as the one
            # removed, moving the other way
            removed = [m for m in members if m not in removed]
            d ^= 1
            group = sum(1 << k for k, m in enumerate(members) if m in removed)
        return removed, self._move(group, d, None, members, state)

    def _move(self, group: int, d: int, k: int | None, members: list[int], state: bytes) -> Move:
        """The move of the pieces ``group`` (local bits) by ``k`` cells along ``AXES[d]``
        from ``state``, with the sets of them that hold one another: a piece blocks
        another of the group when it stands within ``k`` cells ahead of it (anywhere
        ahead, to infinity) at ``state`` (:func:`moving_groups`)."""
        moved = _bits(group, members)
        parts = tuple(self.names[m] for m in moved)
        whole = np.zeros((self.tables.n, 3), dtype=np.int64)
        whole[members] = np.frombuffer(state, dtype=np.int64).reshape(-1, 3)
        entries = self.entries.setdefault(tuple(members), self.tables.subset(members))
        free = self.tables.free(whole, entries)[d]
        reach = _INF // 2 if k is None else k
        arcs = [
            (self.names[i], self.names[j])
            for i in moved
            for j in moved
            if i != j and free[i, j] < reach
        ]
        return Move(parts, AXES[d], k, moving_groups(parts, arcs))


def fixed_indices(names: Sequence[str], fixed: Iterable[str]) -> list[int]:
    """The indices of the ``fixed`` pieces among ``names`` (docs/planning.md, "Fixed
    parts"); ``UnknownNameError`` for a name not among them."""
    found = []
    for name in fixed:
        if name not in names:
            raise UnknownNameError(f"no part named {name!r} (parts: {', '.join(names)})")
        found.append(list(names).index(name))
    return found


def plan_voxels(
    names: Sequence[str],
    voxels: Sequence[NDArray[np.int64]],
    groups: Sequence[int] | None = None,
    max_states: int = MAX_STATES,
    reference_level: str | None = None,
    progress: Progress | None = None,
    fixed: Iterable[str] = (),
) -> MultiMovePlan:
    """The multi-move disassembly plan of the voxel pieces ``voxels`` (``(N, 3)`` integer
    cells, pieces in assembled position, none overlapping) named ``names``; pieces
    sharing a nonzero number in ``groups`` may stay together. Each separation's search
    visits at most ``max_states`` states; beyond that its subassembly is reported
    ``cut`` (module docstring). The ``fixed`` pieces never move (docs/planning.md,
    "Fixed parts")."""
    if len(names) != len(voxels):
        raise ValueError("one name per voxel piece")
    report: Progress = progress or (lambda stage, done, total: None)
    planner = _Planner(
        names, voxels, groups or [0] * len(names), max_states, report, fixed_indices(names, fixed)
    )
    root = None
    if len(names) > 1:
        root = planner.plan(list(range(len(names))), np.zeros((len(names), 3), dtype=np.int64))
    return MultiMovePlan(tuple(names), root, max_states, reference_level)
