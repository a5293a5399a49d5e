"""Assembly planning by disassembly on non-directional blocking graphs (seed 004).

The planner answers the questions seed 004 lists for an NDBG: which subassemblies can
be removed, in what order, and which parts are interlocked. It uses three NDBGs:

* Γ_t (infinitesimal translations) is *necessary*: a set that is not locally free
  along ``d`` cannot be removed along ``d``. Γ_t is cheap (it only needs the contacts),
  so its regular regions supply the candidate directions (one per region, the vertices
  and edges included: free directions are often isolated, e.g. a pin's axis) and, per
  direction, how many parts it lets leave one by one: a bound that orders the
  candidates and stops the search early.
* Γ_e (extended translations) is *sufficient*: a set with no arc leaving it in the DBG
  of Γ_e along ``d`` is taken out by one straight translation ("Extended
  translations"). Only such removals are accepted as steps. Its DBG along a candidate
  direction is computed exactly (:func:`assemblykit.blocking.extended.extended_arcs`,
  also for parts with holes and slots), only for the pairs the search asks about, and
  kept.
* Γ_g (infinitesimal rigid motions), also *necessary*, tells for a set left interlocked
  whether a motion with rotation might still free it.

Blocking is pairwise (whether P_j blocks P_i along d does not depend on the other
parts), so the DBG of a subassembly is the induced subgraph of the assembly's DBG, and
the pairs tested for one node of the search serve every other.

The chosen plan removes, at each step, every part that leaves alone along one
direction, or when no part leaves alone, every minimal free set (sink strong
component, "Directional Blocking Graph") of one direction: parts that can go in
parallel share a step. The previous step's direction is kept while it frees anything (fewer
direction changes, shallower trees); otherwise the direction freeing the most parts
wins, then directions along a coordinate axis, then lifting (+z). Removing parts never
makes the rest harder to take apart (a partition of a set restricts to a partition of
any subset), so the greedy search only stops on a set that no candidate direction
separates. For assemblies of at most ``max_and_or_parts`` parts the AND/OR graph of
every two-handed partition accepted by Γ_e is built too, and its plans are counted.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from functools import cache
from typing import TYPE_CHECKING, Any, Literal

import networkx as nx
import numpy as np
from numpy.typing import ArrayLike, NDArray
from rich.console import Group
from rich.table import Table

from assemblykit import formatting as fmt
from assemblykit.blocking.constraints import BlockingTerm
from assemblykit.blocking.extended import extended_arcs
from assemblykit.tolerance import Tolerance

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly
    from assemblykit.planning.stability import GravityReport, StepStability

Progress = Callable[[str, int, int], None]
Narrow = Callable[[int, int, list[int]], list[int]]
"""``narrow(members, k, sets)``: the free sets (bit masks) of direction ``k`` to move."""
LOOK_AHEAD = 12
"""Candidate directions still examined after the first removal Γ_e accepts."""

FULL_ARRANGEMENT_REGIONS = 250_000
"""The largest arrangement of Γ_t whose regions all become candidate directions."""
MotionKind = Literal["translation", "rigid"]


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
    _last: dict[str, Any] = field(default_factory=dict, compare=False, repr=False)

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
        return np.array([bool(members >> i & 1) for i in range(len(self.names))], dtype=bool)

    def _active(self, members: int) -> NDArray[np.int64]:
        inside = self.vector(members)
        return np.flatnonzero(inside[self.moving] & inside[self.blocker])

    def free_parts(self, members: int) -> NDArray[np.bool_]:
        """``free[k, i]``: part i of ``members`` has no blocker in ``members`` along k."""
        bits = self.free_bits(members, members)
        return np.unpackbits(bits, axis=1, count=len(self.names), bitorder="little").astype(bool)

    def free_bits(self, members: int, movers: int) -> NDArray[np.uint8]:
        """Per direction, the parts of ``movers`` with no blocker in ``members``, packed
        (bit ``i`` of row ``k`` read little-endian, as :func:`_row_mask` does).

        The search asks this of shrinking sets: when ``members`` is a subset of the set
        asked last, only the parts that had a blocker among the parts since removed are
        recomputed."""
        inside = self.vector(members)
        last = self._last.get("blocked")
        if last is not None and last[0] & members == members:
            removed = self.vector(last[0] & ~members)
            blocked = last[1]
            for i in np.unique(self.moving[removed[self.blocker]]):
                if inside[i]:
                    column = self._blocked_part(int(i), inside).astype(np.uint8)
                    byte, bit = divmod(int(i), 8)
                    blocked[:, byte] &= np.uint8(~(1 << bit) & 0xFF)
                    blocked[:, byte] |= column << np.uint8(bit)
        else:
            unpacked = np.zeros((len(self.directions), len(self.names)), dtype=bool)
            columns = self._active(members)
            if len(columns):
                owners = self.moving[columns]
                starts = np.flatnonzero(np.r_[True, owners[1:] != owners[:-1]])
                # every slot is active in the first call: no copy of the table then
                active = (
                    self.slots if len(columns) == self.slots.shape[1] else self.slots[:, columns]
                )
                # maximum over 0/1 bytes is logical or, and much faster along rows
                unpacked[:, owners[starts]] = np.maximum.reduceat(
                    active.view(np.uint8), starts, axis=1
                ).view(bool)
            blocked = np.packbits(unpacked, axis=1, bitorder="little")
        self._last["blocked"] = (members, blocked)
        chosen = np.packbits(self.vector(movers & members), bitorder="little")
        return ~blocked & chosen

    def _blocked_part(self, i: int, inside: NDArray[np.bool_]) -> NDArray[np.bool_]:
        """Per direction, whether part ``i`` has a blocker among ``inside``."""
        lo, hi = np.searchsorted(self.moving, [i, i + 1])
        columns = np.arange(lo, hi)[inside[self.blocker[lo:hi]]]
        return np.asarray(self.slots[:, columns].any(axis=1))

    def graph(self, k: int, members: int) -> nx.DiGraph:
        """The DBG of direction ``k`` induced on ``members``: arc i→j when j blocks i."""
        columns = self._active(members)
        columns = columns[self.slots[k, columns]]
        graph: nx.DiGraph[int] = nx.DiGraph()
        graph.add_nodes_from(_bits(members))
        graph.add_edges_from(
            zip(self.moving[columns].tolist(), self.blocker[columns].tolist(), strict=True)
        )
        return graph

    def incomplete(self, members: int) -> list[int]:
        """The directions along which some part of ``members`` does not block another:
        the only ones that may separate any subset of ``members`` (Γ_e blocks at least
        where Γ_t does)."""
        columns = self._active(members)
        size = _count(members)
        arcs = self.slots[:, columns].sum(axis=1)
        return [int(k) for k in np.flatnonzero(arcs < size * (size - 1))]

    def blockers(self, k: int, movers: int, among: int) -> dict[int, int]:
        """Per part of ``movers``, the mask of its blockers in ``among`` along ``k``."""
        masks = self.masks(k)
        return {i: masks[i] & among & ~(1 << i) for i in _bits(movers)}

    def appended(self, directions: NDArray[np.float64], slots: NDArray[np.bool_]) -> DirectionTable:
        """The table with more directions (rows of ``slots`` over the same slots)."""
        return DirectionTable(
            self.names,
            np.vstack([self.directions, directions]),
            np.vstack([self.slots, slots]),
            self.moving,
            self.blocker,
        )

    def masks(self, k: int) -> tuple[int, ...]:
        """Per part, the bit mask of its blockers along direction ``k``."""
        masks = [0] * len(self.names)
        for s in np.flatnonzero(self.slots[k]):
            masks[self.moving[s]] |= 1 << int(self.blocker[s])
        return tuple(masks)


class ExtendedDirections:
    """The DBGs of Γ_e along fixed candidate directions, computed exactly
    (:func:`assemblykit.blocking.extended.extended_arcs`) pair by pair as the search
    asks for them, and kept: per direction and moving part, the parts already tested
    as blockers and those found blocking."""

    def __init__(self, assembly: Assembly, directions: NDArray[np.float64], tol: Tolerance) -> None:
        self.assembly = assembly
        self.names = tuple(assembly.names)
        self.index = {name: i for i, name in enumerate(self.names)}
        self.directions = directions
        self.tol = tol
        self._tested: dict[tuple[int, int], int] = {}
        self._blocking: dict[tuple[int, int], int] = {}

    def blockers(self, k: int, movers: int, among: int) -> dict[int, int]:
        """Per part of ``movers``, the mask of its blockers in ``among`` along ``k``;
        only the pairs not tested before are computed, in one call."""
        untested = [i for i in _bits(movers) if among & ~self._tested.get((k, i), 1 << i)]
        if untested:
            arcs = extended_arcs(
                self.assembly,
                self.directions[k],
                [self.names[i] for i in untested],
                [self.names[j] for j in _bits(among)],
                self.tol,
            )
            for i in untested:
                self._tested[(k, i)] = self._tested.get((k, i), 1 << i) | among
            for a, b in arcs:
                key = (k, self.index[a])
                self._blocking[key] = self._blocking.get(key, 0) | 1 << self.index[b]
        return {i: self._blocking.get((k, i), 0) & among & ~(1 << i) for i in _bits(movers)}

    def arcs(self, k: int, members: int | None = None) -> list[tuple[int, int]]:
        """The arcs ``(i, j)``, "j blocks i", of the DBG along direction ``k`` among
        ``members`` (default: all parts)."""
        among = _mask(range(len(self.names))) if members is None else members
        return [(i, j) for i, mask in self.blockers(k, among, among).items() for j in _bits(mask)]

    def graph(self, k: int, members: int) -> nx.DiGraph:
        """The Γ_e DBG along direction ``k`` induced on ``members`` (blocking is
        pairwise, so the arcs found for one subassembly serve every other)."""
        graph: nx.DiGraph[int] = nx.DiGraph()
        graph.add_nodes_from(_bits(members))
        graph.add_edges_from(
            (i, j) for i, mask in self.blockers(k, members, members).items() for j in _bits(mask)
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


@dataclass(frozen=True, eq=False)
class Step:
    """One disassembly step: ``parts`` translate along unit ``direction`` away from
    ``rest`` (the other parts of the subassembly they leave). ``blocking`` lists the
    arcs (i, j), "j blocks i", of the DBG along ``direction`` that end in a moved part:
    the parts of ``rest`` they held in place, and the moved parts that leave together
    because they hold one another."""

    parts: tuple[str, ...]
    direction: NDArray[np.float64]
    rest: tuple[str, ...]
    blocking: tuple[tuple[str, str], ...]
    motion: MotionKind = "translation"
    stability: StepStability | None = None
    """Under gravity: the parts held, those that would fall without the holds, the
    least friction needed (:mod:`assemblykit.planning.stability`)."""

    def __repr__(self) -> str:
        return fmt.summary(
            "Step", f"{fmt.name_list(self.parts)} along {fmt.direction(self.direction)}"
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON form (DESIGN.md §5.3): ``parts``, ``direction``, ``motion`` and ``rest``."""
        return {
            "parts": list(self.parts),
            "direction": [float(x) + 0.0 for x in self.direction],
            "motion": self.motion,
            "rest": list(self.rest),
            "blocking": [list(arc) for arc in self.blocking],
            **({} if self.stability is None else self.stability.to_dict()),
        }


@dataclass(frozen=True)
class Interlock:
    """A minimal interlocked set: no extended translation separates any part of it.

    ``translation_locked`` is true when even infinitesimal translations cannot start
    (its DBGs are strongly connected over all of Γ_t); ``rigid_may_free`` when some DBG
    of Γ_g is not strongly connected, i.e. a motion with rotation is not excluded.
    """

    parts: tuple[str, ...]
    translation_locked: bool
    rigid_may_free: bool
    held: tuple[str, ...] = ()
    """The other parts of the set where the search stopped: free from the minimal set
    or from the rest alone, but no candidate direction separates any of them from the
    others (a part trapped behind the interlock, or a second interlock linked to it)."""

    def to_dict(self) -> dict[str, Any]:
        """JSON form."""
        return {
            "parts": list(self.parts),
            "held": list(self.held),
            "translation_locked": self.translation_locked,
            "rigid_may_free": self.rigid_may_free,
        }


AndOrNode = frozenset[str] | tuple[str, frozenset[str], frozenset[str]]
"""A node of an :class:`AndOrGraph`: a subassembly (OR) or ``("split", left, right)`` (AND)."""


@dataclass(frozen=True, eq=False)
class AndOrGraph:
    """The AND/OR graph of all feasible two-handed partitions (seed 004, "order").

    OR nodes are subassemblies (frozensets of names); an AND node
    ``("split", left, right)`` has arcs to its two halves and an arc from the
    subassembly it splits. ``plans`` counts distinct disassembly trees of the whole.
    """

    graph: nx.DiGraph[AndOrNode]
    plans: int

    @property
    def subassemblies(self) -> int:
        """Number of OR nodes."""
        return sum(1 for _, kind in self.graph.nodes(data="kind") if kind == "or")

    @property
    def partitions(self) -> int:
        """Number of AND nodes (feasible partitions)."""
        return sum(1 for _, kind in self.graph.nodes(data="kind") if kind == "and")

    def to_dict(self) -> dict[str, int]:
        """Counts: subassemblies, partitions, plans."""
        return {
            "subassemblies": self.subassemblies,
            "partitions": self.partitions,
            "plans": self.plans,
        }


@dataclass(frozen=True, eq=False)
class HandsMove:
    """One k-handed operation: ``groups[0]`` stays and every other group translates with
    velocity ``velocities[g]`` (``velocities[0]`` is zero) at the same time."""

    groups: tuple[tuple[str, ...], ...]
    velocities: NDArray[np.float64]

    @property
    def hands(self) -> int:
        """The number of groups moved relative to one another."""
        return len(self.groups)

    @property
    def speeds(self) -> tuple[float, ...]:
        """The speed of each group (0 for the fixed one)."""
        return tuple(float(np.linalg.norm(v)) for v in self.velocities)

    @property
    def directions(self) -> tuple[NDArray[np.float64], ...]:
        """The unit direction of each group (the zero vector for the fixed one)."""
        return tuple(
            v / s if s > 0 else np.zeros_like(v)
            for v, s in zip(self.velocities, self.speeds, strict=True)
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON form: ``groups`` (the fixed one first), unit ``directions``, ``speeds``."""
        return {
            "groups": [list(g) for g in self.groups],
            "directions": [[float(x) + 0.0 for x in d] for d in self.directions],
            "speeds": [round(s, 12) + 0.0 for s in self.speeds],
        }


@dataclass(frozen=True, eq=False)
class Hands:
    """How many hands take the assembly apart: ``needed`` (``None`` when more than
    ``max_hands``), and the operations with more than two hands, in order."""

    needed: int | None
    max_hands: int
    moves: tuple[HandsMove, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """JSON form: ``needed``, ``max_hands``, the ``groups``, ``directions`` and
        ``speeds`` of the first operation with more than two hands, and all ``moves``."""
        first = self.moves[0].to_dict() if self.moves else {}
        return {
            "needed": self.needed,
            "max_hands": self.max_hands,
            "groups": first.get("groups", []),
            "directions": first.get("directions", []),
            "speeds": first.get("speeds", []),
            "moves": [move.to_dict() for move in self.moves],
        }

    def summary(self) -> str:
        """One line: how many hands, e.g. ``3 hands`` or ``more than 4 hands``."""
        if self.needed is None:
            return f"more than {self.max_hands} hands"
        return f"{self.needed} hand" + ("s" if self.needed > 1 else "")

    def render(self) -> Table:
        """A rich table of the operations with more than two hands."""
        table = Table(title=f"Hands: {self.summary()}")
        for column in ("operation", "group", "parts", "direction", "speed"):
            table.add_column(column)
        for number, move in enumerate(self.moves, start=1):
            for g, (group, direction, speed) in enumerate(
                zip(move.groups, move.directions, move.speeds, strict=True)
            ):
                table.add_row(
                    str(number) if g == 0 else "",
                    "fixed" if g == 0 else str(g),
                    ", ".join(group),
                    "-" if g == 0 else format_direction(direction),
                    "-" if g == 0 else f"{speed:.3g}",
                )
        return table


@dataclass(frozen=True, eq=False)
class Plan:
    """A disassembly plan; reversed, it is the assembly plan (``order``). ``directions``
    is the number of candidate directions (regions of Γ_t) the search could use."""

    parts: tuple[str, ...]
    steps: tuple[Step, ...]
    interlocked: tuple[Interlock, ...]
    and_or: AndOrGraph | None
    directions: int
    hands: Hands | None = None
    gravity: GravityReport | None = None
    """Set when planned under gravity: the settings, whether the whole assembly stands
    and whether every state of the plan stands with its holds."""

    @property
    def feasible(self) -> bool:
        """True when every part is separated by the steps."""
        return not self.interlocked

    @property
    def stuck(self) -> tuple[str, ...]:
        """Every part that no translation plan separates from all the others: the sets
        where the search stopped, minimal interlocks and the parts they hold (empty
        when feasible). Blocking is pairwise, so a split of the whole restricts to a
        split of such a set: none of its parts can leave, in any order."""
        return tuple(
            sorted({name for lock in self.interlocked for name in (*lock.parts, *lock.held)})
        )

    @property
    def order(self) -> tuple[tuple[str, ...], ...]:
        """Assembly order: the moved sets of the steps, last removed first inserted."""
        return tuple(step.parts for step in reversed(self.steps))

    @property
    def assembly_steps(self) -> tuple[AssemblyStep, ...]:
        """The assembly plan: the steps reversed, each inserting its parts along minus
        the removal direction, holding what the disassembly step held."""
        return tuple(
            AssemblyStep(
                parts=step.parts,
                direction=-np.asarray(step.direction, dtype=np.float64),
                onto=step.rest,
                held=step.parts if step.stability is None else step.stability.held,
                reverses=len(self.steps) - k,
            )
            for k, step in enumerate(reversed(self.steps))
        )

    def exploded(self, distance: float) -> tuple[dict[str, NDArray[np.float64]], ...]:
        """Offsets of an exploded view, one mapping per frame (frame 0 is the assembly,
        frame k follows step k): a part moved at step s sits ``(k - s + 1) x distance``
        along that step's direction, so parts removed earlier stay further out."""
        frames = []
        for k in range(len(self.steps) + 1):
            offsets = {name: np.zeros(3) for name in self.parts}
            for s, step in enumerate(self.steps[:k], start=1):
                for name in step.parts:
                    offsets[name] = offsets[name] + (k - s + 1) * distance * step.direction
            frames.append(offsets)
        return tuple(frames)

    def to_dict(self) -> dict[str, Any]:
        """JSON form (DESIGN.md §5.3): ``feasible``, ``steps``, ``stuck``, plus
        ``interlocked``, ``order``, ``parts``, ``directions`` and ``and_or``."""
        return {
            "feasible": self.feasible,
            "steps": [step.to_dict() for step in self.steps],
            "stuck": list(self.stuck),
            "interlocked": [lock.to_dict() for lock in self.interlocked],
            "order": [list(parts) for parts in self.order],
            "parts": list(self.parts),
            "directions": self.directions,
            "and_or": None if self.and_or is None else self.and_or.to_dict(),
            "hands": None if self.hands is None else self.hands.to_dict(),
            "assembly_steps": [step.to_dict() for step in self.assembly_steps],
            "gravity": None if self.gravity is None else self.gravity.to_dict(),
        }

    def __repr__(self) -> str:
        return fmt.summary(
            "Plan",
            "feasible" if self.feasible else f"infeasible, stuck: {fmt.name_list(self.stuck)}",
            fmt.count(len(self.steps), "step"),
            fmt.count(len(self.parts), "part"),
        )

    def _repr_html_(self) -> str:
        """The steps as a table (notebooks)."""
        rows = [
            (
                str(k),
                fmt.name_list(s.parts, 8),
                fmt.direction(s.direction),
                s.motion,
                fmt.count(len(s.rest), "part"),
            )
            for k, s in enumerate(self.steps, start=1)
        ]
        headers = ("step", "move", "direction", "motion", "away from")
        return fmt.html_summary(repr(self), headers, rows)

    def render(self) -> Group:
        """Rich tables of the disassembly steps (and the interlocked sets when
        infeasible) and of the assembly order."""
        return Group(self._disassembly_table(), self._assembly_table())

    def _assembly_table(self) -> Table:
        table = Table(title="Assembly order")
        for column in ("step", "insert", "direction", "held"):
            table.add_column(column)
        for number, step in enumerate(self.assembly_steps, start=1):
            table.add_row(
                str(number),
                ", ".join(step.parts),
                format_direction(step.direction),
                fmt.name_list(step.held),
            )
        return table

    def _disassembly_table(self) -> Table:
        title = "feasible" if self.feasible else "infeasible"
        if self.and_or is not None:
            title += f", {self.and_or.plans} plan(s) in the AND/OR graph"
        if self.gravity is not None:
            title += ", " + self.gravity.summary()
        table = Table(title=f"Disassembly plan ({title})")
        columns = ["step", "move", "direction", "motion", "away from"]
        if self.gravity is not None:
            columns += ["held", "would fall", "friction needed"]
        for column in columns:
            table.add_column(column)
        for number, step in enumerate(self.steps, start=1):
            cells = [
                str(number),
                ", ".join(step.parts),
                format_direction(step.direction),
                step.motion,
                fmt.name_list(step.rest),
            ]
            if step.stability is not None:
                cells += step.stability.cells()
            table.add_row(*cells)
        for lock in self.interlocked:
            freed = "rigid motion may free" if lock.rigid_may_free else "locked"
            table.add_row("-", ", ".join(lock.parts), "-", f"interlocked ({freed})", "-")
            if lock.held:
                table.add_row("-", ", ".join(lock.held), "-", "held by the interlock", "-")
        if self.hands is not None and self.hands.moves:
            # the groups of the operations two hands cannot do, one row per group
            for move in self.hands.moves:
                for group, direction in zip(move.groups[1:], move.directions[1:], strict=True):
                    table.add_row(
                        f"{move.hands} hands",
                        ", ".join(group),
                        format_direction(direction),
                        "translation, together",
                        fmt.name_list(move.groups[0]),
                    )
            table.caption = f"needs {self.hands.summary()}"
        elif self.hands is not None and self.hands.needed is None:
            table.caption = f"needs {self.hands.summary()}"
        return table


@dataclass(frozen=True, eq=False)
class AssemblyStep:
    """One assembly step, the disassembly step ``reverses`` (1-based) run backwards:
    ``parts`` are inserted along unit ``direction`` (minus the removal direction) onto
    ``onto`` while ``held`` are held (the inserted parts, and under gravity the parts
    that would fall otherwise)."""

    parts: tuple[str, ...]
    direction: NDArray[np.float64]
    onto: tuple[str, ...]
    held: tuple[str, ...]
    reverses: int

    def to_dict(self) -> dict[str, Any]:
        """JSON form: ``parts``, ``direction``, ``onto``, ``held``, ``reverses``."""
        return {
            "parts": list(self.parts),
            "direction": [float(x) + 0.0 for x in self.direction],
            "onto": list(self.onto),
            "held": list(self.held),
            "reverses": self.reverses,
        }


def format_direction(direction: Sequence[float] | NDArray[np.float64]) -> str:
    """A direction for tables: ``+Z`` along an axis, else ``(x, y, z)`` (the shared
    formatter, :func:`assemblykit.formatting.direction`)."""
    return fmt.direction(np.asarray(direction, dtype=np.float64))


def _bits(mask: int) -> Iterable[int]:
    index = 0
    while mask:
        if mask & 1:
            yield index
        mask >>= 1
        index += 1


def _mask(indices: Iterable[int]) -> int:
    total = 0
    for i in indices:
        total |= 1 << int(i)  # numpy integers would overflow past 63 parts
    return total


def _union(masks: Iterable[int]) -> int:
    total = 0
    for mask in masks:
        total |= mask
    return total


def _row_mask(row: NDArray[np.uint8]) -> int:
    """The bit mask held by one row of little-endian packed bits (``np.packbits(...,
    bitorder="little")``)."""
    return int.from_bytes(row.tobytes(), "little")


def _count(mask: int) -> int:
    return bin(mask).count("1")


def _several(mask: int) -> bool:
    return (mask & (mask - 1)) != 0


def direction_table(ndbg: Any) -> DirectionTable:
    """The DBG of every region of ``ndbg`` (Γ_t or Γ_e of :mod:`assemblykit.blocking.ndbg`)
    with the region's representative direction.

    Every region counts, vertices and edges included (free directions of extended
    translations are often isolated, e.g. a pin's axis), and regions with the same DBG
    are kept apart: Γ_e may free a set along one of them and not another. The NDBG's
    bit-packed slots are read as they are; expanding every region into a graph would
    cost more than planning on large assemblies.
    """
    count = len(ndbg.table.starts)
    slots = np.unpackbits(ndbg.packed, axis=1, count=count).astype(bool)
    return DirectionTable(
        tuple(ndbg.parts),
        np.asarray(ndbg.arrangement.directions, dtype=np.float64),
        slots.reshape(len(slots), count),
        np.asarray(ndbg.table.slot_moving, dtype=np.int64),
        np.asarray(ndbg.table.slot_blocker, dtype=np.int64),
    )


def distinct_directions(table: DirectionTable) -> list[int]:
    """One direction per distinct DBG of ``table``: the one closest to a coordinate axis."""
    _, inverse = np.unique(table.slots, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    order = np.lexsort((-np.abs(table.directions).max(axis=1), inverse))
    return sorted(order[np.r_[True, inverse[order][1:] != inverse[order][:-1]]].tolist())


def separable(table: DirectionTable, members: int) -> bool:
    """True when some direction of ``table`` frees a proper, non-empty part of ``members``
    (a DBG that is not strongly connected, seed 004)."""
    if not _several(members):
        return False
    if table.free_parts(members).any():
        return True
    return not all(
        nx.is_strongly_connected(table.graph(k, members)) for k in range(len(table.directions))
    )


def _sinks(source: DirectionTable | ExtendedDirections, k: int, members: int) -> list[int]:
    """The minimal free sets of ``members`` along direction ``k``: the sink strong
    components of its DBG, as bit masks (seed 004, "Directional Blocking Graph")."""
    condensed = nx.condensation(source.graph(k, members))
    return [
        _mask(condensed.nodes[c]["members"])
        for c in condensed.nodes
        if condensed.out_degree(c) == 0
    ]


def _base(members: int, volumes: Sequence[float]) -> int:
    """The heaviest part of ``members``: it stays, everything else leaves it."""
    return max(_bits(members), key=lambda i: (volumes[i], -i))


def _removal(sinks: list[int], members: int, volumes: Sequence[float]) -> list[int]:
    """The free sets to move: all but the one holding the base (:func:`_base`). Keeping
    the base still is no loss: the other side of a partition along ``d`` is free along
    ``-d``, which is also a candidate (the arrangement is symmetric)."""
    base = 1 << _base(members, volumes)
    return [s for s in sinks if not s & base]


def _group_bounds(
    translations: DirectionTable, members: int, volumes: Sequence[float]
) -> dict[int, int]:
    """Per candidate direction, how many parts the free sets of Γ_t (sink components,
    the base's excluded) take out of ``members``: a bound for those of Γ_e."""
    bounds = {
        k: _count(_union(_removal(_sinks(translations, k, members), members, volumes)))
        for k in range(len(translations.directions))
    }
    return {k: v for k, v in bounds.items() if v}


def _choose_removal(
    translations: DirectionTable,
    extended: DirectionTable | ExtendedDirections,
    members: int,
    volumes: Sequence[float],
    previous: int | None,
    narrow: Narrow | None = None,
) -> tuple[int, list[int]] | None:
    """The direction index and the free sets of Γ_e it removes from ``members``.

    Single parts first: where Γ_t lets single parts leave (counted for all directions at
    once), only those parts are tested against Γ_e. When none leaves alone, the sink
    components of Γ_e, so that groups that must leave together can. ``narrow(members,
    k, sets)``, when given, picks among the free sets of direction ``k`` those to move
    (one at a time, or only removals that leave stable states).
    """
    free = translations.free_bits(members, members & ~(1 << _base(members, volumes)))
    counts = np.bitwise_count(free).sum(axis=1, dtype=np.int64)

    def chosen(k: int, sets: list[int]) -> list[int]:
        return sets if narrow is None or not sets else narrow(members, k, sets)

    def singles(k: int) -> list[int]:
        held = extended.blockers(k, _row_mask(free[k]), members)
        return chosen(k, [1 << i for i, mask in held.items() if not mask])

    def groups(k: int) -> list[int]:
        return chosen(k, _removal(_sinks(extended, k, members), members, volumes))

    choice = None
    if counts.any():
        candidates = np.flatnonzero(counts)
        bounds = dict(zip(candidates.tolist(), counts[candidates].tolist(), strict=True))
        choice = _best_direction(translations, bounds, singles, previous)
    if choice is None:
        bounds = _group_bounds(translations, members, volumes)
        choice = _best_direction(translations, bounds, groups, previous)
    return choice


def _best_direction(
    translations: DirectionTable,
    bounds: dict[int, int],
    removal: Callable[[int], list[int]],
    previous: int | None,
) -> tuple[int, list[int]] | None:
    """The candidate whose ``removal`` moves most, with its free sets.

    The previous step's direction is tried first and kept if it frees anything. Other
    candidates are visited best bound first (most parts, closest to a coordinate axis,
    then +z); the search stops when a bound cannot beat the best removal accepted, or
    ``LOOK_AHEAD`` candidates after the first one accepted.
    """
    if previous in bounds:
        sinks = removal(previous)
        if sinks:
            return previous, sinks

    def rank(k: int, moved: int) -> tuple[float, ...]:
        direction = translations.directions[k]
        return (moved, float(np.abs(direction).max()), float(direction[2]), -k)

    # the candidates by decreasing rank, sorted on arrays (tens of thousands on the dome)
    keys = np.fromiter(bounds, dtype=np.int64, count=len(bounds))
    moved = np.fromiter(bounds.values(), dtype=np.int64, count=len(bounds))
    directions = translations.directions[keys]
    order = np.lexsort((keys, -directions[:, 2], -np.abs(directions).max(axis=1), -moved))
    best: tuple[tuple[float, ...], int, list[int]] | None = None
    patience = LOOK_AHEAD
    for k in keys[order].tolist():
        if best is not None:
            if rank(k, bounds[k]) <= best[0] or patience == 0:
                break
            patience -= 1
        sinks = removal(k)
        if sinks and (best is None or rank(k, _count(_union(sinks))) > best[0]):
            best = (rank(k, _count(_union(sinks))), k, sinks)
    return None if best is None else (best[1], best[2])


@dataclass
class _Search:
    translations: DirectionTable
    extended: DirectionTable | ExtendedDirections
    volumes: tuple[float, ...]
    progress: Progress
    steps: list[Step]
    locked: list[int]
    exact: Callable[[int], NDArray[np.float64]] | None = None
    add_translations: Callable[[NDArray[np.float64]], NDArray[np.bool_]] | None = None
    narrowers: tuple[Narrow, ...] = ()
    """Ways to pick the free sets a step moves, tried in turn (none: every free set)."""
    judge: Callable[[int, int], StepStability] | None = None
    """The stability of moving a set out of a set (planning under gravity)."""
    ground: int = 0
    """Parts that stay where they are (fixed parts declared under gravity): a set holding
    nothing else is not taken apart."""

    def _choose(self, members: int, previous: int | None) -> tuple[int, list[int]] | None:
        """The next removal from ``members``: each narrower in turn, then the same once
        more with the directions of the exact free sets when the sampled ones free
        nothing."""
        narrowers: tuple[Narrow | None, ...] = self.narrowers or (None,)
        for refine in (False, True):
            if refine and not self._refined(members):
                return None
            for narrow in narrowers:
                choice = _choose_removal(
                    self.translations, self.extended, members, self.volumes, previous, narrow
                )
                if choice is not None:
                    return choice
        return None

    def _refined(self, members: int) -> bool:
        """Add the directions of the exact free sets of ``members`` (:func:`exact_candidates`)
        as candidates; whether there were any."""
        if self.exact is None or self.add_translations is None:
            return False
        found = self.exact(members)
        if not len(found) or not isinstance(self.extended, ExtendedDirections):
            return False
        self.translations = self.translations.appended(found, self.add_translations(found))
        self.extended.add(found)
        return True

    def disassemble(self, members: int) -> None:
        """Append the steps that take ``members`` apart, or record it as interlocked."""
        previous: int | None = None
        pending = [members]
        while pending:
            current = pending.pop()
            while _several(current) and current & ~self.ground:
                choice = self._choose(current, previous)
                if choice is None:
                    self.locked.append(current)
                    break
                k, sinks = choice
                moved = _union(sinks)
                self._record(k, moved, current)
                previous = k
                pending.extend(s for s in sinks if _several(s))
                current &= ~moved

    def _record(self, k: int, moved: int, members: int) -> None:
        names = self.translations.names
        rest = members & ~moved
        held = self.extended.blockers(k, rest, moved) | self.extended.blockers(k, moved, moved)
        arcs = sorted((i, j) for i, mask in held.items() for j in _bits(mask))
        self.steps.append(
            Step(
                parts=tuple(names[i] for i in _bits(moved)),
                direction=self.translations.directions[k],
                rest=tuple(names[i] for i in _bits(rest)),
                blocking=tuple((names[i], names[j]) for i, j in arcs),
                stability=None if self.judge is None else self.judge(members, moved),
            )
        )
        self.progress("planning", len(self.steps), len(names))


def one_set(members: int, k: int, sets: list[int]) -> list[int]:
    """The narrower of one-at-a-time planning: the free set with the fewest parts (the
    lowest-numbered of those)."""
    return [min(sets, key=lambda mask: (_count(mask), mask & -mask))]


def minimal_interlocked(table: DirectionTable, members: int) -> int:
    """A minimal subset of ``members`` that no direction of ``table`` separates: parts are
    dropped one at a time while the rest stays interlocked."""
    for i in list(_bits(members)):
        smaller = members & ~(1 << i)
        if _several(smaller) and not separable(table, smaller):
            return minimal_interlocked(table, smaller)
    return members


def and_or_graph(table: DirectionTable) -> AndOrGraph:
    """The AND/OR graph of every two-handed partition of the whole set that ``table``
    (Γ_e) accepts, and the number of disassembly trees it holds (seed 004, "order").
    :func:`~assemblykit.planning.planner.plan` gives it one direction per distinct DBG
    of Γ_t plus those its search used, so the count is a lower bound when Γ_e differs
    within a region of Γ_t."""
    names = table.names
    masks = [table.masks(k) for k in range(len(table.directions))]
    graph: nx.DiGraph[AndOrNode] = nx.DiGraph()

    def label(mask: int) -> frozenset[str]:
        return frozenset(names[i] for i in _bits(mask))

    def free(part: int, members: int) -> bool:
        # part is free along k when none of its blockers inside members lies outside it
        outside = members & ~part
        return any(all((blockers[i] & outside) == 0 for i in _bits(part)) for blockers in masks)

    @cache
    def count(members: int) -> int:
        graph.add_node(label(members), kind="or")
        if not _several(members):
            return 1
        total = 0
        lowest = members & -members
        rest = members & ~lowest
        sub = rest
        while True:
            part = sub | lowest
            if part != members and free(part, members):
                other = members & ~part
                node = ("split", label(part), label(other))
                graph.add_node(node, kind="and")
                graph.add_edge(label(members), node)
                graph.add_edge(node, label(part))
                graph.add_edge(node, label(other))
                total += count(part) * count(other)
            if sub == 0:
                break
            sub = (sub - 1) & rest
        return total

    plans = count(_mask(range(len(names))))
    return AndOrGraph(graph, plans)


def translation_table(assembly: Assembly, tol: Tolerance) -> DirectionTable:
    """Γ_t along the candidate directions of the planner: the regions of the whole
    arrangement when it is small enough (about ``3 c²`` regions for ``c`` circles, at
    most ``FULL_ARRANGEMENT_REGIONS``), else those of each part's own arrangement
    (:func:`local_table`)."""
    from assemblykit.blocking.arrangement import snap_normals
    from assemblykit.blocking.graphs import blocking_graph, blocking_terms

    terms = blocking_terms(assembly, "infinitesimal", tol)
    rows = [t.normals for t in terms]
    circles = len(snap_normals(np.vstack(rows), tol)[0]) if rows else 0
    if 3 * circles**2 <= FULL_ARRANGEMENT_REGIONS:
        return direction_table(blocking_graph(assembly, motion="infinitesimal", tol=tol))
    return local_table(tuple(assembly.names), terms, tol)


def local_table(
    names: tuple[str, ...], terms: Sequence[BlockingTerm], tol: Tolerance
) -> DirectionTable:
    """Γ_t along the regions of each part's own arrangement (the great circles of the
    terms that block it; seed 004's arrangement, one part at a time).

    A part's blockers are constant over each region of its own arrangement, so every
    way Γ_t lets a single part leave any subassembly is among these directions; groups
    that must leave together may be free along others. On the 527-block dome: 49,926
    directions instead of 2.2 million regions."""
    from assemblykit.blocking.arrangement import snap_normals, sphere_arrangement

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
    slots = _term_slots(directions, terms, owners, len(pairs), tol)
    ends = np.array(pairs, dtype=np.int64).reshape(-1, 2)
    return DirectionTable(names, directions, slots, *ends.T)


EXACT_GROUP_PARTS = 12
"""The largest set left by the candidates of Γ_t whose groups get the directions of the
overlay of every pair's blocked set (single parts always get their free set's)."""


def exact_candidates(assembly: Assembly, tol: Tolerance) -> Callable[[int], NDArray[np.float64]]:
    """For a set of parts the sampled candidates do not separate: a direction in every
    face of each part's exact free set among the set (seed 004 §5, checked free), and,
    when none leaves alone and the set has at most ``EXACT_GROUP_PARTS`` parts, one in
    every face of the overlay of the pairs' blocked sets (over which every DBG is
    constant, so groups leaving together are found as well)."""
    from assemblykit.blocking.free_cones import blocked_by, exact_free_directions, overlay_faces

    names = tuple(assembly.names)

    def directions(members: int) -> NDArray[np.float64]:
        among = [names[i] for i in _bits(members)]
        found: list[NDArray[np.float64]] = []
        for name in among:
            found.extend(exact_free_directions(assembly, [name], tol, among, limit=2).directions)
        if found or len(among) > EXACT_GROUP_PARTS:
            return np.array(found).reshape(-1, 3)
        sets = []
        for a in among:
            for b in among:
                if a != b:
                    blocked = blocked_by(assembly, [a], b, tol)
                    if blocked is None:
                        return np.zeros((0, 3))
                    sets.append(blocked)
        return overlay_faces(sets, tol).directions

    return directions


def translation_slots(
    assembly: Assembly, table: DirectionTable, tol: Tolerance
) -> Callable[[NDArray[np.float64]], NDArray[np.bool_]]:
    """Γ_t along new directions over the slots of ``table``: a slot blocks when one of its
    infinitesimal terms holds strictly (beyond the angle tolerance, as the arrangement's
    snapping has it)."""
    from assemblykit.blocking.graphs import blocking_terms

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
        return _term_slots(
            directions, [t for t, _ in kept], [s for _, s in kept], len(table.moving), tol
        )

    return slots


TERM_CHUNK = 256
"""Directions whose inner products with every term normal :func:`_term_slots` holds at
once (a few MB on the dome: the chunk stays in cache)."""


def _term_slots(
    directions: NDArray[np.float64],
    terms: Sequence[BlockingTerm],
    owners: Sequence[int],
    count: int,
    tol: Tolerance,
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
