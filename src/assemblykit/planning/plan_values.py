"""What a disassembly plan is made of: the answers to the questions Wilson & Latombe 1992
ask of an NDBG ("Introduction"): which subassemblies can be removed, in what order, and
which parts are interlocked.

* :class:`Step`: a set of parts taken out of the rest by one translation, with the arcs
  of the DBG that end in a moved part; reversed, an :class:`AssemblyStep`;
* :class:`Interlock`: a minimal set that no extended translation separates, and the
  parts it holds (docs/planning.md, "How a plan is found");
* :class:`Hands` and :class:`HandsMove`: how many hands take the stopped sets apart,
  and the operations with more than two (docs/planning.md, "How many hands");
* :class:`AndOrGraph`: for small assemblies, every two-handed partition that Γ_e
  (extended translations) accepts, and the number of disassembly trees it holds, built
  by :func:`and_or_graph` (Wilson & Latombe 1992, "Introduction": the (dis)assembly
  order);
* :class:`Plan`: the steps, the sets left interlocked and the rest, with the fixed
  parts (docs/planning.md, "Fixed parts") and the ground it was planned on
  (docs/planning.md, "The ground").

Each has its JSON form (docs/planning.md, "JSON"). The search that finds the steps is
:mod:`~assemblykit.planning.search`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cache
from typing import TYPE_CHECKING, Any, Literal

import networkx as nx
import numpy as np
from numpy.typing import NDArray

from assemblykit import formatting as fmt
from assemblykit.blocking.directions import DirectionTable
from assemblykit.part_sets import bits, mask_of, several
from assemblykit.planning.fasteners import Fastener, drawn_summary
from assemblykit.planning.multimove import moving_groups

if TYPE_CHECKING:
    from assemblykit.model.assembly import Overlap
    from assemblykit.planning.stability import GravityReport, StepStability

MotionKind = Literal["translation", "rigid"]


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
    fastener: Fastener | None = None
    """The pin or screw the step draws out of its holes along their axis
    (:mod:`assemblykit.planning.fasteners`)."""
    fasteners: tuple[Fastener, ...] = ()
    """Every pin and screw the step draws out, one per part that leaves on its own (a
    move of one part; the step's :attr:`fastener` when it moves one part only)."""

    def __repr__(self) -> str:
        return fmt.summary(
            "Step", f"{fmt.name_list(self.parts)} along {fmt.direction(self.direction)}"
        )

    def summary(self) -> str:
        """What a fitter does, in words: the fastener's summary for a step drawing one
        (``"unscrew M3 (pitch 0.5, 12 turns)"``); else the motion, then the screws and
        pins its moves draw out (``"translation; unscrew 5 x M3; pull 1 pin"``,
        :func:`~assemblykit.planning.fasteners.drawn_summary`)."""
        if self.fastener is not None:
            return self.fastener.summary()
        drawn = drawn_summary(self.fasteners)
        return f"{self.motion}; {drawn}" if drawn else self.motion

    def to_dict(self) -> dict[str, Any]:
        """JSON form (docs/planning.md, "JSON"): ``parts``, ``direction`` (and ``axis``,
        its name when it lies along a coordinate axis), ``motion``, ``rest``,
        ``blocking``, ``together`` (the moved parts hold one another: one rigid
        group) and, when they do not, ``moves`` (the sets that do, in an order they may
        leave one after another: :func:`~assemblykit.planning.multimove.moving_groups`),
        a move of one part that is a pin or a screw with its ``fastener``."""
        groups = moving_groups(self.parts, self.blocking)
        direction = [float(x) + 0.0 for x in self.direction]
        drawn = {fastener.part: fastener.to_dict() for fastener in self.fasteners}
        moves = [
            {
                "parts": list(group),
                "direction": direction,
                **({"fastener": drawn[group[0]]} if len(group) == 1 and group[0] in drawn else {}),
            }
            for group in groups
        ]
        return {
            "parts": list(self.parts),
            "direction": direction,
            "axis": fmt.axis_name(self.direction),
            "motion": self.motion,
            "rest": list(self.rest),
            "blocking": [list(arc) for arc in self.blocking],
            "together": len(groups) == 1,
            **({} if len(groups) == 1 else {"moves": moves}),
            **({} if self.stability is None else self.stability.to_dict()),
            **({} if self.fastener is None else {"fastener": self.fastener.to_dict()}),
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
    interfering: tuple[tuple[str, str, float], ...] = ()
    """The pairs of the set (``parts`` and ``held``) that share a volume beyond the
    interference threshold, ``(a, b, volume)``: a shared volume blocks a pair in every
    direction, so these, not an interlock of shapes, may be what stops the set."""
    enclosed: tuple[tuple[str, str], ...] = ()
    """The parts of the set that lie in a void of another, ``(inner, outer)``
    (:func:`~assemblykit.geometry.interference.enclosures`): sealed in a cavity, no
    motion takes them out."""

    def to_dict(self) -> dict[str, Any]:
        """JSON form."""
        return {
            "parts": list(self.parts),
            "held": list(self.held),
            "translation_locked": self.translation_locked,
            "rigid_may_free": self.rigid_may_free,
            "interfering": [{"a": a, "b": b, "volume": v} for a, b, v in self.interfering],
            "enclosed": [{"part": inner, "in": outer} for inner, outer in self.enclosed],
        }

    @property
    def reason(self) -> str:
        """Why the set is stopped, in words."""
        if self.interfering:
            pairs = "; ".join(f"{a} / {b} share {v:.3g}" for a, b, v in self.interfering)
            return f"interfering ({pairs})"
        if self.enclosed:
            sealed = "; ".join(f"{a} in a void of {b}" for a, b in self.enclosed)
            return f"enclosed ({sealed})"
        return "interlocked (rigid motion may free)" if self.rigid_may_free else "interlocked"


AndOrNode = frozenset[str] | tuple[str, frozenset[str], frozenset[str]]
"""A node of an :class:`AndOrGraph`: a subassembly (OR) or ``("split", left, right)`` (AND)."""


@dataclass(frozen=True, eq=False)
class AndOrGraph:
    """The AND/OR graph of all feasible two-handed partitions (Wilson & Latombe 1992,
    "Introduction": the (dis)assembly order).

    OR nodes are subassemblies (frozensets of names); an AND node
    ``("split", left, right)`` has arcs to its two halves and an arc from the
    subassembly it splits. ``plans`` counts distinct disassembly trees of the whole.
    """

    graph: nx.DiGraph[AndOrNode]
    plans: int

    @property
    def subassemblies(self) -> int:
        """Number of OR nodes."""
        return sum(1 for node in self.graph if self.graph.nodes[node].get("kind") == "or")

    @property
    def partitions(self) -> int:
        """Number of AND nodes (feasible partitions)."""
        return sum(1 for node in self.graph if self.graph.nodes[node].get("kind") == "and")

    def to_dict(self) -> dict[str, int]:
        """Counts: subassemblies, partitions, plans."""
        return {
            "subassemblies": self.subassemblies,
            "partitions": self.partitions,
            "plans": self.plans,
        }


def and_or_graph(table: DirectionTable) -> AndOrGraph:
    """The AND/OR graph of every two-handed partition of the whole set that ``table``
    (Γ_e) accepts, and the number of disassembly trees it holds (Wilson & Latombe 1992,
    "Introduction": the (dis)assembly order).
    :func:`~assemblykit.planning.planner.plan` gives it one direction per distinct DBG
    of Γ_t plus those its search used, so the count is a lower bound when Γ_e differs
    within a region of Γ_t."""
    names = table.names
    masks = [table.masks(k) for k in range(len(table.directions))]
    graph: nx.DiGraph[AndOrNode] = nx.DiGraph()

    def label(mask: int) -> frozenset[str]:
        return frozenset(names[i] for i in bits(mask))

    def free(part: int, members: int) -> bool:
        # part is free along k when none of its blockers inside members lies outside it
        outside = members & ~part
        return any(all((blockers[i] & outside) == 0 for i in bits(part)) for blockers in masks)

    @cache
    def count(members: int) -> int:
        graph.add_node(label(members), kind="or")
        if not several(members):
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

    plans = count(mask_of(range(len(names))))
    return AndOrGraph(graph, plans)


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
    more_may_free: bool = True
    """When ``needed`` is ``None``: whether more than ``max_hands`` hands might take the
    stuck parts apart. False when no stuck set has more parts than ``max_hands``: each
    part in a hand of its own is the most hands can do, and it was tried."""

    def to_dict(self) -> dict[str, Any]:
        """JSON form: ``needed``, ``max_hands``, the ``groups``, ``directions`` and
        ``speeds`` of the first operation with more than two hands, all ``moves``, and
        ``more_may_free``."""
        first = self.moves[0].to_dict() if self.moves else {}
        return {
            "needed": self.needed,
            "max_hands": self.max_hands,
            "groups": first.get("groups", []),
            "directions": first.get("directions", []),
            "speeds": first.get("speeds", []),
            "moves": [move.to_dict() for move in self.moves],
            "more_may_free": self.needed is None and self.more_may_free,
        }

    def summary(self) -> str:
        """One line: how many hands, e.g. ``needs 3 hands``, ``needs more than 4 hands``
        or, when a part in each hand does not take the stuck parts apart, ``no number of
        hands takes it apart by translations``."""
        if self.needed is None:
            if not self.more_may_free:
                return "no number of hands takes it apart by translations"
            return f"needs more than {self.max_hands} hands"
        return f"needs {self.needed} hand" + ("s" if self.needed > 1 else "")


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
    overlaps: tuple[Overlap, ...] = ()
    """The interfering pairs of the assembly planned and what was done about each
    (:func:`assemblykit.geometry.overlaps.resolve_overlaps`)."""
    joined: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    """The parts planned as one, by the name of the part they became (products of
    several solids, ``--join``: :func:`assemblykit.geometry.overlaps.resolve_overlaps`)."""
    unfinished: tuple[str, ...] = ()
    """The parts not yet taken apart when the plan stopped at its step limit
    (``max_steps`` of :func:`assemblykit.planning.planner.plan`): neither separated nor
    shown stuck."""
    fixed: tuple[str, ...] = ()
    """The parts declared fixed (docs/planning.md, "Fixed parts"): never moved, left
    in place by the plan, the first set of the assembly ``order``."""
    ground: tuple[str, ...] = ()
    """The parts the assembly was planned standing on (docs/planning.md, "The ground"):
    the input's supports, among :attr:`fixed`, with the ground plane under them that no
    step moves down through."""

    @property
    def feasible(self) -> bool:
        """True when every part is separated by the steps."""
        return not self.interlocked and not self.unfinished

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
        """Assembly order: the moved sets of the steps, last removed first inserted,
        after the :attr:`fixed` parts when there are any (docs/planning.md, "Fixed
        parts")."""
        moved = tuple(step.parts for step in reversed(self.steps))
        return ((self.fixed,) if self.fixed else ()) + moved

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
                stands=None if step.stability is None else step.stability.stands,
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
        """JSON form (docs/planning.md, "JSON"): ``feasible``, ``steps``, ``stuck``, plus
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
            "unfinished": list(self.unfinished),
            "overlaps": [overlap.to_dict() for overlap in self.overlaps],
            "joined": {name: list(members) for name, members in self.joined.items()},
            "fixed": list(self.fixed),
            "ground": list(self.ground),
        }

    def __repr__(self) -> str:
        if self.unfinished:
            verdict = f"stopped at its step limit, {fmt.count(len(self.unfinished), 'part')} left"
        elif self.feasible:
            verdict = "feasible"
        else:
            verdict = f"infeasible, stuck: {fmt.name_list(self.stuck)}"
        return fmt.summary(
            "Plan",
            verdict,
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


@dataclass(frozen=True, eq=False)
class AssemblyStep:
    """One assembly step, the disassembly step ``reverses`` (1-based) run backwards:
    ``parts`` are inserted along unit ``direction`` (minus the removal direction) onto
    ``onto`` while ``held`` are held (the inserted parts, and under gravity the parts
    that would fall otherwise); under gravity ``stands`` says whether the states of the
    step stand with those holds (``None`` otherwise)."""

    parts: tuple[str, ...]
    direction: NDArray[np.float64]
    onto: tuple[str, ...]
    held: tuple[str, ...]
    reverses: int
    stands: bool | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON form: ``parts``, ``direction`` (and ``axis``, its name when it lies along
        a coordinate axis: :func:`~assemblykit.formatting.axis_name`), ``onto``, ``held``,
        ``reverses`` and, under gravity, ``stands``."""
        return {
            "parts": list(self.parts),
            "direction": [float(x) + 0.0 for x in self.direction],
            "axis": fmt.axis_name(self.direction),
            "onto": list(self.onto),
            "held": list(self.held),
            "reverses": self.reverses,
            **({} if self.stands is None else {"stands": self.stands}),
        }
