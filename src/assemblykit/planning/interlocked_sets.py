"""The interlocked sets where the disassembly search stops, named by a minimal subset
(docs/planning.md, "How a plan is found": interlocked and stuck sets).

Removing parts never makes the rest harder to take apart (a partition of a set
restricts to a partition of any subset), so the greedy search only stops on a set that
no candidate direction separates (Wilson & Latombe 1992, "Introduction": which parts are
interlocked). Such a set is explained by a minimal subset that no direction separates
either: parts are dropped one at a time while the rest stays interlocked
(:func:`minimal_interlocked`). Γ_t (infinitesimal translations) is *necessary*: a set
that is not locally free along ``d`` cannot be removed along ``d``, so a set Γ_t cannot
separate is interlocked, and Γ_e (extended translations) is asked only along the
directions where Γ_t separates what is left, until one separates it
(:func:`least_interlocked`). Whether a motion with rotation might still free the set is
asked of Γ_g by the planner (:func:`~assemblykit.planning.planner.rigid_may_free`).

Interlocking assemblies, where only a key can move (Song, Fu & Cohen-Or 2012), are
:mod:`~assemblykit.planning.interlocking`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from assemblykit.blocking.directions import DirectionTable
from assemblykit.part_sets import bits, several
from assemblykit.planning.extended_directions import ExtendedDirections
from assemblykit.planning.free_sets import closed_under, separable, sinks


def minimal_interlocked(table: DirectionTable, members: int) -> int:
    """A minimal subset of ``members`` that no direction of ``table`` separates: parts are
    dropped one at a time while the rest stays interlocked."""
    for i in list(bits(members)):
        smaller = members & ~(1 << i)
        if several(smaller) and not separable(table, smaller):
            return minimal_interlocked(table, smaller)
    return members


def least_interlocked(translations: DirectionTable, extended: Any, members: int) -> int:
    """A minimal subset of ``members`` that no direction separates under Γ_e
    (``extended``: :class:`ExtendedDirections`, or its counterpart for polygons), found
    without Γ_e's whole DBGs. Γ_e blocks at least where Γ_t does (``translations``), so
    a set Γ_t cannot separate is interlocked: parts are first dropped while Γ_t alone
    cannot separate the rest (:func:`minimal_interlocked` on Γ_t: a pair drawn
    interfering, a pin in a blind hole), then while Γ_e cannot, asked only along the
    directions where Γ_t separates the rest, and only until one separates it. A pair
    that Γ_t blocks both ways along every direction (parts left interfering:
    :func:`~assemblykit.blocking.tables.with_obstacles`) is such a subset at once."""
    held = translations.held_pair(members)
    if held:
        return held
    core = members
    if not separable(translations, members):
        core = minimal_interlocked(translations, members)

    def separates(subset: int) -> bool:
        return any(
            not _connected_as_shown(translations, extended, k, subset)
            and separable(extended.table([k], subset), subset)
            for k in np.flatnonzero(translations.separating(subset)).tolist()
        )

    def drop(subset: int) -> int:
        for i in list(bits(subset)):
            smaller = subset & ~(1 << i)
            if several(smaller) and not separates(smaller):
                return drop(smaller)
        return subset

    return drop(core)


def _connected_as_shown(translations: DirectionTable, extended: Any, k: int, members: int) -> bool:
    """Whether the DBG of Γ_e along ``k`` induced on ``members`` is strongly connected as
    far as arcs known without projecting a mesh show it
    (:meth:`ExtendedDirections.shown_blockers`, with Γ_t's arcs): a set that leaves
    along ``k`` is closed under both, so it holds a sink component of Γ_t, whose
    closure under the arcs shown is within it; when every such closure is ``members``,
    no proper set leaves. ``False`` says nothing (polygons: nothing is shown)."""
    if not isinstance(extended, ExtendedDirections):
        return False
    necessary = translations.masks(k)

    def shown(parts: int) -> dict[int, int]:
        return extended.shown_blockers(k, parts, members)

    return all(
        closed_under(start, shown, necessary, members, lambda closed: closed == members) == members
        for start in sinks(translations, k, members)
    )
