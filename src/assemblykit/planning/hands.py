"""How many hands an assembly needs (Wilson & Latombe 1992, "Conclusion": every operation
of an NDBG plan moves one subassembly relative to the rest, i.e. two hands; an arbitrary device
may need more [Natarajan, 1988]).

A *k-handed* operation splits a set of parts into ``k`` groups: group 0 stays, and each
other group ``g`` translates with its own constant velocity ``v_g`` to infinity, all at
once. Groups ``g`` and ``h`` then move relative to each other along ``v_g − v_h``, a
straight line, so the operation is collision-free iff for every two groups (the fixed
one has ``v = 0``) the parts of ``h`` do not block those of ``g`` for the extended
translation along ``v_g − v_h`` (Γ_e, pairwise as everywhere in Wilson & Latombe 1992).
Two hands are the case ``k = 2``.

The search runs where the two-handed planner stops (a set no translation separates):

* the partitions of the set into ``k`` groups (``k = 3`` first, then up to
  ``max_hands``), the group with the largest part fixed;
* for each moving group, the directions that free it from the fixed group: the regions
  of the set's Γ_e arrangement (exact for polygons and convex parts, sampled at the
  regions of Γ_t otherwise, as in the planner);
* speeds: with ``v_g = r d_g`` and ``v_h = d_h``, the relative direction ``r d_g − d_h``
  sweeps the arc from ``−d_h`` to ``d_g`` as ``r`` runs over ``(0, ∞)``; it crosses the
  circle of normal ``n`` at ``r = (n . d_h) / (n . d_g)``. Those crossings and one ratio
  inside each interval between them visit every region of the arrangement the arc
  meets, and each relative direction is checked exactly (``dbg(d)`` of the NDBG).

Every operation reported is therefore collision-free; the search may miss one whose
directions lie strictly inside regions other than at their representatives. Each group
is then taken apart the same way (two hands first), so ``needed`` is the largest ``k``
used, ``None`` when ``max_hands`` do not suffice.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from assemblykit.blocking.directions import DirectionTable
from assemblykit.blocking.extended import all_convex, extended_arcs
from assemblykit.blocking.graphs import blocking_graph
from assemblykit.blocking.ndbg import NonDirectionalBlockingGraph
from assemblykit.model.polygons import PolygonAssembly
from assemblykit.part_sets import bits, mask_of, several
from assemblykit.planning.extended_directions import ExtendedDirections
from assemblykit.planning.plan_values import Hands, HandsMove
from assemblykit.planning.search import Search
from assemblykit.tolerance import ModelTolerance, Tolerance

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly

MAX_HANDS = 4
"""The most hands the planner tries by default."""

HANDS_MAX_PARTS = 8
"""The largest set split into groups (the partitions grow as k^n / k!)."""


def partitions(items: Sequence[int], k: int) -> Iterator[tuple[tuple[int, ...], ...]]:
    """Every partition of ``items`` into exactly ``k`` non-empty groups, the group of
    ``items[0]`` first (restricted growth strings)."""
    n = len(items)
    if not 1 <= k <= n:
        return
    labels = [0] * n

    def grow(i: int, used: int) -> Iterator[tuple[tuple[int, ...], ...]]:
        if n - i < k - used:
            return
        if i == n:
            yield tuple(tuple(items[j] for j in range(n) if labels[j] == g) for g in range(k))
            return
        for g in range(min(used + 1, k)):
            labels[i] = g
            yield from grow(i + 1, max(used, g + 1))

    yield from grow(1, 1)


@dataclass
class _HandsSearch:
    """The search of :func:`hands_needed` over candidate directions: Γ_t along them
    (``translations``) is necessary for a group to leave, Γ_e (``extended``: a table,
    or computed part by part as asked) decides; ``leaves(group, others, d)`` decides
    exactly along any direction ``d`` (the relative directions of two moving groups)."""

    translations: DirectionTable
    extended: DirectionTable | ExtendedDirections
    leaves: Callable[[int, int, NDArray[np.float64]], bool]
    circles: NDArray[np.float64]
    sizes: tuple[float, ...]
    max_hands: int
    tol: ModelTolerance

    def __post_init__(self) -> None:
        self.necessary = [self.translations.masks(k) for k in range(len(self.directions))]

    @property
    def directions(self) -> NDArray[np.float64]:
        return self.translations.directions

    def free(self, group: int, others: int, k: int) -> bool:
        """Whether ``group`` leaves ``others`` along candidate direction ``k``: no part
        of ``others`` blocks one of ``group`` in Γ_t, then in Γ_e."""
        if any(self.necessary[k][i] & others for i in bits(group)):
            return False
        held = self.extended.blockers(k, group, group | others)
        return not any(mask & others for mask in held.values())

    def free_along(self, group: int, others: int, direction: NDArray[np.float64]) -> bool:
        """Whether ``group`` leaves ``others`` along any ``direction`` (exact)."""
        return self.leaves(group, others, direction)

    def ratios(self, d_g: NDArray[np.float64], d_h: NDArray[np.float64]) -> list[float]:
        """Speed ratios ``r`` at which ``r d_g − d_h`` meets each region of the
        arrangement along its arc (module docstring), equal speeds first."""
        along = self.circles @ d_g
        ok = np.abs(along) > self.tol.angle
        cuts = (self.circles[ok] @ d_h) / along[ok]
        cuts = np.unique(cuts[cuts > 0])
        inner = np.sqrt(cuts[1:] * cuts[:-1]) if len(cuts) > 1 else np.zeros(0)
        ends = [cuts[0] / 2, cuts[-1] * 2] if len(cuts) else [1.0]
        return sorted({1.0, *cuts.tolist(), *inner.tolist(), *ends}, key=lambda r: abs(np.log(r)))

    def relative_ok(
        self, g: int, h: int, v_g: NDArray[np.float64], v_h: NDArray[np.float64]
    ) -> bool:
        """Whether groups ``g`` and ``h`` (masks) miss each other with these velocities."""
        e = v_g - v_h
        length = float(np.linalg.norm(e))
        if length <= self.tol.angle * max(np.linalg.norm(v_g), np.linalg.norm(v_h)):
            return False  # they would move as one: the set was not separated
        return self.free_along(g, h, e / length)

    def velocities(self, groups: tuple[int, ...]) -> NDArray[np.float64] | None:
        """Velocities that take ``groups`` apart, group 0 fixed, or ``None``: the last
        group at unit speed along one of its free directions, each other moving group
        along one of its own with a speed ratio against the last (module docstring),
        every two moving groups checked. A group that leaves the fixed one along no
        direction is found before the free directions of the others are listed."""
        directions = self.directions
        candidates = range(len(directions))
        leaves = functools.cache(lambda g, k: self.free(g, groups[0], k))
        if not all(any(leaves(g, k) for k in candidates) for g in groups[1:]):
            return None
        options = [[k for k in candidates if leaves(g, k)] for g in groups[1:]]
        for k_last in options[-1]:
            chosen = self._extend(groups, options, [], directions[k_last])
            if chosen is not None:
                return np.vstack([np.zeros(3), *chosen, directions[k_last]])
        return None

    def _extend(
        self,
        groups: tuple[int, ...],
        options: list[list[int]],
        chosen: list[NDArray[np.float64]],
        d_last: NDArray[np.float64],
    ) -> list[NDArray[np.float64]] | None:
        g, last = len(chosen) + 1, len(groups) - 1
        if g == last:
            return chosen
        for k in options[g - 1]:
            d = self.directions[k]
            for r in self.ratios(d, d_last):
                v = r * d
                if not self.relative_ok(groups[g], groups[last], v, d_last):
                    continue
                if not all(
                    self.relative_ok(groups[g], groups[h], v, chosen[h - 1]) for h in range(1, g)
                ):
                    continue
                result = self._extend(groups, options, [*chosen, v], d_last)
                if result is not None:
                    return result
        return None

    def split(self, members: int) -> HandsMove | None:
        """The first operation with the fewest hands (3 to ``max_hands``) that splits
        ``members``, the group of its largest part fixed."""
        parts = sorted(bits(members), key=lambda i: (-self.sizes[i], i))
        if len(parts) > HANDS_MAX_PARTS:
            return None
        names = self.translations.names
        for k in range(3, self.max_hands + 1):
            for split in partitions(parts, k):
                groups = tuple(mask_of(g) for g in split)
                velocities = self.velocities(groups)
                if velocities is not None:
                    labels = tuple(tuple(names[i] for i in sorted(g)) for g in split)
                    return HandsMove(labels, velocities)
        return None

    def take_apart(self, members: int, locked: bool = False) -> tuple[int | None, list[HandsMove]]:
        """Hands needed for ``members`` and the operations with more than two, taking
        it apart with two hands wherever the planner's search can (``locked``: it is
        known that it cannot, ``members`` goes straight to the split)."""
        if not several(members):
            return 1, []
        stopped = [members]
        if not locked:
            search = Search(
                translations=self.translations,
                extended=self.extended,
                volumes=self.sizes,
            )
            search.disassemble(members)
            stopped = search.locked
        needed = 2
        moves: list[HandsMove] = []
        index = {name: i for i, name in enumerate(self.translations.names)}
        for locked_set in stopped:
            move = self.split(locked_set)
            if move is None:
                return None, moves
            moves.append(move)
            needed = max(needed, move.hands)
            for group in move.groups:
                inner, more = self.take_apart(mask_of(index[n] for n in group))
                moves.extend(more)
                if inner is None:
                    return None, moves
                needed = max(needed, inner)
        return needed, moves


def hands_needed(
    assembly: Assembly | PolygonAssembly,
    parts: Sequence[str] | None = None,
    max_hands: int = MAX_HANDS,
    tol: Tolerance | None = None,
    *,
    locked: bool = False,
) -> Hands:
    """How many hands (up to ``max_hands``) take ``parts`` (default: all) of
    ``assembly`` apart by translations, and the operations with more than two hands
    (module docstring). Works for 3D assemblies and polygon assemblies alike.
    ``locked``: the parts are known not to come apart with two hands (a set where the
    planner stopped), so no two-handed search is made of them first."""
    tol = assembly.tolerance(tol)
    names = tuple(assembly.names if parts is None else parts)
    if assembly.dimension == 2 or all_convex(assembly, names):
        search = _exact_search(assembly, names, max_hands, tol)
    else:
        search = _sampled_search(assembly, names, max_hands, tol)
    needed, moves = search.take_apart(mask_of(range(len(search.translations.names))), locked)
    return Hands(needed, max_hands, tuple(moves), more_may_free=len(names) > max_hands)


def _exact_search(
    assembly: Assembly | PolygonAssembly,
    names: tuple[str, ...],
    max_hands: int,
    tol: ModelTolerance,
) -> _HandsSearch:
    """The search over the exact Γ_e NDBG (polygons, convex parts): its regions'
    DBGs serve as both tables, its terms decide any direction."""
    ndbg = blocking_graph(assembly, "extended", parts=names, tol=tol)
    assert isinstance(ndbg, NonDirectionalBlockingGraph)
    table = ndbg.direction_table()

    def leaves(group: int, others: int, direction: NDArray[np.float64]) -> bool:
        arcs = ndbg.dbg(direction).arcs
        inside = {table.names[i] for i in bits(group)}
        outside = {table.names[j] for j in bits(others)}
        return not any(i in inside and j in outside for i, j in arcs)

    sizes = assembly.sizes()
    circles = np.asarray(ndbg.arrangement.normals, dtype=np.float64)
    parts = tuple(sizes[n] for n in table.names)
    return _HandsSearch(table, table, leaves, circles, parts, max_hands, tol)


def _sampled_search(
    assembly: Assembly, names: tuple[str, ...], max_hands: int, tol: ModelTolerance
) -> _HandsSearch:
    """The search for parts that are not all convex, as the planner searches: the
    regions of Γ_t of ``names`` give the candidate directions, Γ_e is computed exactly
    along them only where Γ_t lets a group leave, and along any relative direction by
    the projection test (:func:`~assemblykit.blocking.extended.extended_arcs`)."""
    local = blocking_graph(assembly, "infinitesimal", parts=names, tol=tol)
    translations = local.direction_table()
    order = translations.names
    # tested in the whole assembly: the blocking data of its parts and pairs is shared
    extended = ExtendedDirections(assembly, translations.directions, tol, parts=order)

    def leaves(group: int, others: int, direction: NDArray[np.float64]) -> bool:
        moving = [order[i] for i in bits(group)]
        still = [order[j] for j in bits(others)]
        return not extended_arcs(assembly, direction, moving, still, tol)

    sizes = assembly.sizes()
    circles = np.asarray(local.arrangement.normals, dtype=np.float64)
    volumes = tuple(sizes[n] for n in order)
    return _HandsSearch(translations, extended, leaves, circles, volumes, max_hands, tol)
