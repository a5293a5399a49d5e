"""Assembly planning by disassembly on non-directional blocking graphs (Wilson & Latombe
1992).

The planner answers the questions Wilson & Latombe 1992 ask of an NDBG ("Introduction"):
which subassemblies can be removed, in what order, and which parts are interlocked. It
uses three NDBGs:

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
  whether a motion with rotation might still free it
  (:func:`~assemblykit.planning.planner.rigid_may_free`).

The names of the planner's sequence, from the modules that compute them, each a chapter
to read against the paper and docs/planning.md, "How a plan is found":

* :mod:`~assemblykit.planning.plan_values`: what a plan is made of (:class:`Step`,
  :class:`Interlock`, :class:`Hands`, :class:`Plan`, :class:`AssemblyStep`, ...) and
  the AND/OR graph of every two-handed partition (:func:`and_or_graph`);
* :mod:`~assemblykit.planning.extended_directions`: Γ_e along the candidate directions,
  computed as the search asks for it, and kept (:class:`ExtendedDirections`);
* :mod:`~assemblykit.planning.free_sets`: the free sets of a DBG (:func:`separable`,
  and the sink components and closures the next two share);
* :mod:`~assemblykit.planning.search`: the greedy disassembly search (:class:`Search`,
  its narrowers :class:`FirstAdmitted` and :func:`one_set`, :func:`base_part`);
* :mod:`~assemblykit.planning.interlocked_sets`: the sets where it stops, named by a
  minimal subset (:func:`minimal_interlocked`, :func:`least_interlocked`);
* :mod:`~assemblykit.planning.candidates`: candidate directions beyond the sampled ones
  (:func:`fit_axes`, :func:`exact_candidates`).

This module names them all (``__all__``). The names that moved to the planner or became
a method are found there, with a :class:`DeprecationWarning` (docs/architecture.md,
"Deprecated names").
"""

from __future__ import annotations

from assemblykit.deprecation import moved
from assemblykit.planning.candidates import EXACT_GROUP_PARTS, exact_candidates, fit_axes
from assemblykit.planning.extended_directions import (
    RECENT_BLOCKERS,
    SWEEP_AFTER,
    SWEPT_DIRECTIONS,
    ExtendedDirections,
)
from assemblykit.planning.free_sets import separable, sinks
from assemblykit.planning.interlocked_sets import least_interlocked, minimal_interlocked
from assemblykit.planning.plan_values import (
    AndOrGraph,
    AndOrNode,
    AssemblyStep,
    Hands,
    HandsMove,
    Interlock,
    MotionKind,
    Plan,
    Step,
    and_or_graph,
)
from assemblykit.planning.search import (
    AXIS_SNAP,
    GROUP_REJECTIONS,
    LOOK_AHEAD,
    FirstAdmitted,
    Narrow,
    Progress,
    Search,
    base_part,
    one_set,
)
from assemblykit.planning.search import _choose_removal as _choose_removal
from assemblykit.planning.search import _free_closures as _free_closures
from assemblykit.planning.search import _removal as _removal

__all__ = [
    "AXIS_SNAP",
    "EXACT_GROUP_PARTS",
    "GROUP_REJECTIONS",
    "LOOK_AHEAD",
    "RECENT_BLOCKERS",
    "SWEEP_AFTER",
    "SWEPT_DIRECTIONS",
    "AndOrGraph",
    "AndOrNode",
    "AssemblyStep",
    "ExtendedDirections",
    "FirstAdmitted",
    "Hands",
    "HandsMove",
    "Interlock",
    "MotionKind",
    "Narrow",
    "Plan",
    "Progress",
    "Search",
    "Step",
    "and_or_graph",
    "base_part",
    "exact_candidates",
    "fit_axes",
    "least_interlocked",
    "minimal_interlocked",
    "one_set",
    "separable",
]

_sinks = sinks
""":func:`~assemblykit.planning.free_sets.sinks`, by the name it has here."""

__getattr__ = moved(
    __name__,
    {
        "distinct_directions": "assemblykit.blocking.directions:DirectionTable.distinct_directions",
        "plan": "assemblykit.planning.planner",
        "separable_by_translations": "assemblykit.planning.planner",
    },
)
