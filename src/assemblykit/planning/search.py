"""The greedy disassembly search (Wilson & Latombe 1992): which subassemblies can be
removed, and in what order, each by one extended translation (docs/planning.md, "How a
plan is found").

It asks two NDBGs along the candidate directions:

* Γ_t (infinitesimal translations) is *necessary*: a set that is not locally free
  along ``d`` cannot be removed along ``d``. Γ_t is cheap (it only needs the contacts),
  so its regular regions supply the candidate directions and, per direction, how many
  parts it lets leave one by one: a bound that orders the candidates and stops the
  search early.
* Γ_e (extended translations) is *sufficient*: a set with no arc leaving it in the DBG
  of Γ_e along ``d`` is taken out by one straight translation ("Extended
  translations"). Only such removals are accepted as steps
  (:class:`~assemblykit.planning.extended_directions.ExtendedDirections`).

The chosen plan removes, at each step, every part that leaves alone along one
direction, or when no part leaves alone, every minimal free set (sink strong
component, "Directional Blocking Graph") of one direction: parts that can go in
parallel share a step, and the sets of one step, which stay together, are then taken
apart as one set. The previous step's direction is kept while it frees anything (fewer
direction changes, shallower trees); otherwise the direction freeing the most parts
wins, then directions along a coordinate axis, then lifting (+z). The heaviest part
stays as the base, the fixed parts with it (docs/planning.md, "Fixed parts"); under
gravity a narrower picks the removals that stand, and no direction goes down
(docs/planning.md, "Under gravity"). Removing parts never makes the rest harder to take
apart (a partition of a set restricts to a partition of any subset), so the greedy
search only stops on a set that no candidate direction separates, even with the
directions added where the sampled ones separate nothing
(:mod:`~assemblykit.planning.candidates`); such a set is named by a minimal interlocked
subset (:mod:`~assemblykit.planning.interlocked_sets`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from assemblykit.blocking.directions import BlockedRows, DirectionTable
from assemblykit.blocking.extended import extended_arcs
from assemblykit.part_sets import bits, count_bits, row_mask, several, union_of
from assemblykit.planning.extended_directions import ExtendedDirections
from assemblykit.planning.free_sets import closed_under, separable, sinks
from assemblykit.planning.plan_values import Step
from assemblykit.tolerance import ORDER_RESOLUTION, order_key

if TYPE_CHECKING:
    from assemblykit.planning.stability import StepStability

Progress = Callable[[str, int, int], None]
Narrow = Callable[[int, int, list[int]], list[int]]
"""``narrow(members, k, sets)``: the free sets (bit masks) of direction ``k`` to move."""
LOOK_AHEAD = 12
"""Candidate directions still examined after the first removal Γ_e accepts."""
GROUP_REJECTIONS = 16
"""Candidate directions whose groups a narrower may reject (none of them stands under
gravity) before the search for groups stops, and the next narrower is asked (under
gravity: the removal leaving the fewest parts falling). A large vault, where no single
block may go, has more than ten thousand candidate directions, each with its groups to
close under extended blocking."""
AXIS_SNAP = 0.01
"""The angle (radians) within which a step's direction is taken along the coordinate axis
near it, when the parts moved leave along that axis too (:meth:`Search._step_direction`)."""


@dataclass(frozen=True)
class FirstAdmitted:
    """A narrower (:data:`Narrow`) that moves the first free set, in its ``order``, that
    it ``admits`` (``admits(members, set)``: under gravity, whether the removal stands).
    Its verdicts do not depend on the direction; ``rejected(members)`` tells, at no
    cost, the single parts (a mask) already found not admitted: the search leaves them
    out of the extended blocking that each direction costs again
    (:func:`_choose_removal`)."""

    order: Callable[[list[int]], list[int]]
    admits: Callable[[int, int], bool]
    rejected: Callable[[int], int]

    def __call__(self, members: int, k: int, sets: list[int]) -> list[int]:
        return next(([m] for m in self.order(sets) if self.admits(members, m)), [])


def one_set(members: int, k: int, sets: list[int]) -> list[int]:
    """The narrower of one-at-a-time planning: the free set with the fewest parts (the
    lowest-numbered of those)."""
    return [min(sets, key=lambda mask: (count_bits(mask), mask & -mask))]


def base_part(members: int, volumes: Sequence[float]) -> int:
    """The heaviest part of ``members`` (to :data:`~assemblykit.tolerance.ORDER_RESOLUTION`
    of the largest volume; the lowest index of equals): it stays, everything else leaves
    it."""
    scale = max(volumes[i] for i in bits(members))
    return max(bits(members), key=lambda i: (order_key(volumes[i], scale), -i))


def _removal(sinks: list[int], members: int, volumes: Sequence[float], fixed: int = 0) -> list[int]:
    """The free sets to move: all but those holding the base (:func:`base_part`) or a
    ``fixed`` part (docs/planning.md, "Fixed parts"). Keeping the base still is no loss:
    the other side of a partition along ``d`` is free along ``-d``, which is also a
    candidate (the arrangement is symmetric)."""
    anchor = (1 << base_part(members, volumes)) | fixed
    return [s for s in sinks if not s & anchor]


def _group_bounds(
    translations: DirectionTable, members: int, volumes: Sequence[float]
) -> dict[int, int]:
    """Per candidate direction, how many parts the free sets of Γ_t (sink components,
    the base's excluded: :func:`_removal`) take out of ``members``: a bound for those of
    Γ_e."""
    sizes = translations.free_set_sizes(members, base_part(members, volumes))
    return {int(k): int(sizes[k]) for k in np.flatnonzero(sizes)}


def _free_closures(
    translations: DirectionTable,
    extended: ExtendedDirections,
    k: int,
    members: int,
    base: int,
    fixed: int = 0,
) -> list[int]:
    """The minimal sets of ``members`` that leave ``base`` behind along direction ``k``
    with no arc of Γ_t (necessary) or Γ_e (sufficient) leaving them: the sink
    components of the union of the two DBGs, found from Γ_t's sinks without Γ_e's whole
    DBG. Such a set is closed in Γ_t, so it holds a sink component of Γ_t; the sink
    component of the union holding it is that sink's closure under both graphs' arcs
    (everything its parts' blockers, and theirs, reach), and the sinks of the union are
    the least of these closures. A closure stops as soon as it reaches the base, so only
    the Γ_e blockers of parts in the sets found, and of those on the way to the base,
    are computed. The ``fixed`` parts stay with the base part as one immovable body
    (docs/planning.md, "Fixed parts"). Before that, a closure under the
    arcs already known that reaches the base rules its start out, as it lies within the
    whole closure: first the arcs shown without projecting
    (:meth:`ExtendedDirections.shown_blockers`), then with the parts that blocked each
    part last along other directions, tested along ``k`` alone
    (:meth:`ExtendedDirections.known_blockers`). (Γ_t's arcs are Γ_e's but where a direction
    grazes a contact, within the tolerances: there the part stays, as a single part Γ_t
    holds does.)"""
    necessary = translations.masks(k)
    anchor = (1 << base) | fixed

    def closure(start: int, blockers: Callable[[int], dict[int, int]]) -> int:
        return closed_under(start, blockers, necessary, members, lambda closed: closed & anchor)

    closures = set()
    for start in sinks(translations, k, members):
        if closure(start, lambda parts: extended.shown_blockers(k, parts, members)) & anchor:
            continue
        if closure(start, lambda parts: extended.known_blockers(k, parts, members)) & anchor:
            continue
        closed = closure(start, lambda parts: extended.blockers(k, parts, members, whole=True))
        if not closed & anchor:
            closures.add(closed)
    return sorted(s for s in closures if not any(o != s and o & s == o for o in closures))


def _choose_removal(
    rows: BlockedRows,
    extended: DirectionTable | ExtendedDirections,
    members: int,
    volumes: Sequence[float],
    previous: int | None,
    narrow: Narrow | None = None,
    up: NDArray[np.float64] | None = None,
    fixed: int = 0,
) -> tuple[int, list[int]] | None:
    """The direction index and the free sets of Γ_e it removes from ``members``, Γ_t
    being the table of ``rows`` (the search's memory of it).

    Single parts first: where Γ_t lets single parts leave (counted for all directions at
    once), only those parts are tested against Γ_e. When none leaves alone, the sink
    components of Γ_e (and Γ_t: :func:`_free_closures`), so that groups that must
    leave together can. ``narrow(members, k, sets)``, when given, picks among the free
    sets of direction ``k`` those to move (one at a time, or only removals that leave
    stable states); once it has rejected the groups of :data:`GROUP_REJECTIONS`
    directions, no more groups are tried. No set holding a ``fixed`` part is moved: with
    the base, they are one immovable body (docs/planning.md, "Fixed parts").
    """
    translations = rows.table
    base = base_part(members, volumes)
    anchor = (1 << base) | (fixed & members)
    free = rows.free_bits(members, members & ~anchor)
    counts = np.bitwise_count(free).sum(axis=1, dtype=np.int64)
    rejected = 0

    def chosen(k: int, sets: list[int]) -> list[int]:
        return sets if narrow is None or not sets else narrow(members, k, sets)

    def singles(k: int) -> list[int]:
        movers = row_mask(free[k])
        if isinstance(narrow, FirstAdmitted):
            # a part the narrower already rejected would be rejected again: no Γ_e for it
            movers &= ~narrow.rejected(members)
        if isinstance(extended, ExtendedDirections):
            return chosen(k, [1 << i for i in bits(extended.leaving(k, movers, members))])
        held = extended.blockers(k, movers, members)
        return chosen(k, [1 << i for i, mask in held.items() if not mask])

    def groups(k: int) -> list[int]:
        nonlocal rejected
        if rejected >= GROUP_REJECTIONS:
            return []
        if isinstance(extended, ExtendedDirections):
            found = _free_closures(translations, extended, k, members, base, anchor)
        else:
            found = _removal(sinks(extended, k, members), members, volumes, fixed)
        kept = chosen(k, found)
        rejected += bool(found) and not kept
        return kept

    choice = None
    if counts.any():
        candidates = np.flatnonzero(counts)
        bounds = dict(zip(candidates.tolist(), counts[candidates].tolist(), strict=True))
        # a narrower picks one set: one single part
        choice = _best_direction(
            translations, bounds, singles, previous, None if narrow is None else 1, up
        )
    if choice is None:
        bounds = _group_bounds(translations, members, volumes)
        choice = _best_direction(translations, bounds, groups, previous, None, up)
    return choice


def _best_direction(
    translations: DirectionTable,
    bounds: dict[int, int],
    removal: Callable[[int], list[int]],
    previous: int | None,
    most: int | None = None,
    up: NDArray[np.float64] | None = None,
) -> tuple[int, list[int]] | None:
    """The candidate whose ``removal`` moves most, with its free sets.

    The previous step's direction is tried first and kept if it frees anything. Other
    candidates are visited best bound first (most parts, closest to a coordinate axis,
    then +z); the search stops when a bound cannot beat the best removal accepted, or
    ``LOOK_AHEAD`` candidates after the first one accepted. When a removal moves
    ``most`` parts at most (a single part, where one set is picked), a candidate that
    could not beat the best one even so is passed over without asking ``removal``, as
    it would be after asking.

    Under gravity (``up``, the unit vector against it) a direction with a downward
    component is no candidate: a part taken to infinity along it would pass through the
    ground the fixed parts stand on. Of the others, lifting ranks before sliding
    sideways, after the parts moved (docs/planning.md, "Under gravity").
    """
    # directions compared to ORDER_RESOLUTION: mirror images rank alike, by index
    levels = np.round(translations.directions / ORDER_RESOLUTION)
    rise = np.zeros(len(levels)) if up is None else np.sign(levels @ up)
    if up is not None:
        bounds = {k: n for k, n in bounds.items() if rise[k] >= 0}
    if previous in bounds:
        sinks = removal(previous)
        if sinks:
            return previous, sinks

    def rank(k: int, moved: int) -> tuple[float, ...]:
        direction = levels[k]
        return (moved, float(rise[k]), float(np.abs(direction).max()), float(direction[2]), -k)

    # the candidates by decreasing rank, sorted on arrays (tens of thousands on the dome)
    keys = np.fromiter(bounds, dtype=np.int64, count=len(bounds))
    moved = np.fromiter(bounds.values(), dtype=np.int64, count=len(bounds))
    directions = levels[keys]
    order = np.lexsort(
        (keys, -directions[:, 2], -np.abs(directions).max(axis=1), -rise[keys], -moved)
    )
    best: tuple[tuple[float, ...], int, list[int]] | None = None
    patience = LOOK_AHEAD
    for k in keys[order].tolist():
        if best is not None:
            if rank(k, bounds[k]) <= best[0] or patience == 0:
                break
            patience -= 1
            if most is not None and rank(k, min(bounds[k], most)) <= best[0]:
                continue
        sinks = removal(k)
        if sinks and (best is None or rank(k, count_bits(union_of(sinks))) > best[0]):
            best = (rank(k, count_bits(union_of(sinks))), k, sinks)
    return None if best is None else (best[1], best[2])


@dataclass
class Search:
    """The greedy disassembly search (module docstring): Γ_t along the candidate
    directions (``translations``) bounds and orders them, Γ_e (``extended``) accepts the
    removals; ``steps`` and the sets left interlocked (``locked``, bit masks) grow as
    :meth:`disassemble` runs. ``exact`` and ``add_translations`` supply more candidate
    directions where the sampled ones separate nothing."""

    translations: DirectionTable
    extended: DirectionTable | ExtendedDirections
    volumes: tuple[float, ...]
    progress: Progress = field(default=lambda stage, done, total: None)
    steps: list[Step] = field(default_factory=list)
    locked: list[int] = field(default_factory=list)
    exact: Callable[[int], NDArray[np.float64]] | None = None
    add_translations: Callable[[NDArray[np.float64]], NDArray[np.bool_]] | None = None
    narrowers: tuple[Narrow, ...] = ()
    """Ways to pick the free sets a step moves, tried in turn (none: every free set)."""
    judge: Callable[[int, int], StepStability] | None = None
    """The stability of moving a set out of a set (planning under gravity)."""
    ground: int = 0
    """Parts that stay where they are (fixed parts declared under gravity): a set holding
    nothing else is not taken apart."""
    fixed: int = 0
    """Parts never moved (docs/planning.md, "Fixed parts"): no set holding one leaves,
    they stay with the base as one body, and a set holding nothing else (with
    :attr:`ground`) is not taken apart."""
    up: NDArray[np.float64] | None = None
    """Under gravity, the unit vector against it: no direction with a downward component
    is taken, and lifting goes before sliding (:func:`_best_direction`)."""
    max_steps: int | None = None
    """Stop after this many steps (``None``: go on until every set is apart or stopped)."""
    axes: NDArray[np.float64] | None = None
    """Directions added once, before the exact free sets, when the sampled ones free
    nothing (:func:`~assemblykit.planning.candidates.fit_axes`)."""
    unfinished: list[int] = field(default_factory=list)
    """The sets not taken apart because :attr:`max_steps` was reached (bit masks)."""
    rows: BlockedRows | None = field(default=None, init=False, repr=False)
    """The search's memory of Γ_t's blocked parts for the set it asked last."""

    def _choose(self, members: int, previous: int | None) -> tuple[int, list[int]] | None:
        """The next removal from ``members``: each narrower in turn, then the same again
        with more candidate directions while the sampled ones free nothing (:attr:`axes`,
        then the directions of the exact free sets)."""
        narrowers: tuple[Narrow | None, ...] = self.narrowers or (None,)
        for refine in (False, True, True):
            if refine and not self._refined(members):
                return None
            for narrow in narrowers:
                choice = _choose_removal(
                    self._blocked_rows(),
                    self.extended,
                    members,
                    self.volumes,
                    previous,
                    narrow,
                    self.up,
                    self.fixed,
                )
                if choice is not None:
                    return choice
        return None

    def _blocked_rows(self) -> BlockedRows:
        """The search's memory of Γ_t's blocked parts (:class:`BlockedRows`), for the
        table of candidate directions it has now."""
        if self.rows is None or self.rows.table is not self.translations:
            self.rows = BlockedRows(self.translations)
        return self.rows

    def _refined(self, members: int) -> bool:
        """Add the directions of the exact free sets of ``members``
        (:func:`~assemblykit.planning.candidates.exact_candidates`) as candidates; whether
        there were any. None where Γ_t separates no subset of ``members``: no subset can
        start to move, so none leaves by an extended translation (Γ_e blocks at least
        where Γ_t does)."""
        if self.exact is None or self.add_translations is None:
            return False
        if self.axes is not None and isinstance(self.extended, ExtendedDirections):
            found, self.axes = self.axes, None
        elif not separable(self.translations, members):
            return False
        else:
            found = self.exact(members)
        if not len(found) or not isinstance(self.extended, ExtendedDirections):
            return False
        self.translations = self.translations.appended(found, self.add_translations(found))
        self.extended.add(found)
        return True

    def disassemble(self, members: int) -> None:
        """Append the steps that take ``members`` apart, or record it as interlocked.

        A step moves its free sets to infinity together, so they are then taken apart
        as one set: each is in the way of the others, as a set left stopped is in the
        way of whatever is still to come out near it (docs/planning.md, "How a plan is
        found", "Sets that leave together stay together"). Taken apart sink by sink,
        the posts beside a drawer whose joints are modelled overlapping would leave
        their brackets through its sides, which left with them. Single parts moved at
        one step need no more steps."""
        previous: int | None = None
        pending = [members]
        while pending:
            current = pending.pop()
            while several(current) and current & ~(self.ground | self.fixed):
                if self.max_steps is not None and len(self.steps) >= self.max_steps:
                    self.unfinished.append(current)
                    break
                choice = self._choose(current, previous)
                if choice is None:
                    self.locked.append(current)
                    break
                k, sinks = choice
                moved = union_of(sinks)
                self._record(k, moved, current)
                previous = k
                if any(several(s) for s in sinks):
                    pending.append(moved)  # together, not sink by sink
                current &= ~moved

    def _record(self, k: int, moved: int, members: int) -> None:
        names = self.translations.names
        rest = members & ~moved
        held = self.extended.blockers(k, rest, moved) | self.extended.blockers(k, moved, moved)
        arcs = sorted((i, j) for i, mask in held.items() for j in bits(mask))
        self.steps.append(
            Step(
                parts=tuple(names[i] for i in bits(moved)),
                direction=self._step_direction(k, moved, rest),
                rest=tuple(names[i] for i in bits(rest)),
                blocking=tuple((names[i], names[j]) for i, j in arcs),
                stability=None if self.judge is None else self.judge(members, moved),
            )
        )
        self.progress("planning", len(self.steps), len(names))

    def _step_direction(self, k: int, moved: int, rest: int) -> NDArray[np.float64]:
        """The direction a step takes ``moved`` away from ``rest`` along: candidate
        ``k``, or the coordinate axis within :data:`AXIS_SNAP` of it (beyond rounding)
        when the moved parts leave the rest along that axis too (Γ_e, exact), and it
        does not go down under gravity. A candidate is a point inside a region of the
        arrangement, off the circles that bound it: a part lifted off a pin's axis
        otherwise leaves along (0, -0.0034, 1), not +z, as a fitter takes it."""
        direction: NDArray[np.float64] = np.asarray(self.translations.directions[k])
        extended = self.extended
        if not isinstance(extended, ExtendedDirections):
            return direction
        along = int(np.argmax(np.abs(direction)))
        axis = np.zeros(3)
        axis[along] = np.sign(direction[along])
        off = float(np.linalg.norm(direction / np.linalg.norm(direction) - axis))
        if not ORDER_RESOLUTION < off <= AXIS_SNAP:
            return direction
        if self.up is not None and float(axis @ self.up) < 0:
            return direction
        movers = [extended.names[i] for i in bits(moved)]
        others = [extended.names[i] for i in bits(rest)]
        arcs = extended_arcs(extended.assembly, axis, movers, others, extended.tol)
        return direction if arcs else axis
