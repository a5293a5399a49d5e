"""Interlocking assemblies: which part, the key, is the only one that can move, over
every direction of motion (docs/interlocking.md).

An assembly is *interlocking* (Song, Fu & Cohen-Or 2012; Wang, Song & Pauly 2018)
when only its key, or a given set of keys, can move relative to the rest: every other
part and every subset of parts is blocked along every direction. It is *recursively
interlocking* when, once the key has left, the rest is interlocking again with a new
key, down to two parts. Wang, Song & Pauly test the six axis directions; here every
direction is examined, from the directional blocking graphs of the NDBG of Wilson &
Latombe 1992 (§3-5, :mod:`assemblykit.blocking`).

The test. A subset ``S`` moves relative to the rest along ``d`` iff it is closed under
the arcs of the DBG ``G(d, A)`` (no arc leaves it): a union of strongly connected
components with everything they reach. Two parts lying in one strong component of
every DBG are never separated by any motion; two parts in different components of some
DBG are (the closure of the component of one leaves the other behind). So the classes
of parts that stay together are the common refinement (the meet) of the strong
components of all the DBGs, one DBG per distinct graph of the regions of the NDBG. An
assembly is interlocking with keys ``K`` iff something moves (there are two classes or
more) and the parts outside ``K`` lie in one class: every subset that moves then has
all of its parts, or all of the others, among the keys. The single keys found are the
parts forming a class of their own with the rest in one other class; when there is
none, the smallest set of keys is everything outside a largest class.

Motions (:func:`assemblykit.blocking.graphs.blocking_graph`): ``infinitesimal`` uses
Γ_t, whose regions are regular, so the classes are exact over every direction;
``extended`` uses Γ_e, exact for polygons and parts made of convex bodies; for other
parts Γ_e is sampled at the regions of Γ_t, and the sets Γ_t lets move along an arc or
a region that the samples leave blocked are decided by their exact free sets and, for
at most ``EXACT_GROUP_PARTS`` parts, the overlay of every pair's blocked set
(:mod:`assemblykit.blocking.free_cones`); ``rigid`` uses the cells of Γ_g, the linear
programs of :class:`~assemblykit.blocking.rigid.RigidBlockingGraph` and, translations
being rigid motions, every DBG of Γ_t.

The result carries a certificate (one :class:`BlockingCell` per distinct DBG: its strong
components and the arcs, which part blocks which, that stop each of them) and, for each
subset that moves, where it is free as regions of the NDBG in words and the contacts
that would block it (:class:`Freedom`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from assemblykit import formatting as fmt
from assemblykit.algebra import se3
from assemblykit.blocking.arrangement import Arrangement
from assemblykit.blocking.dbg import DirectionalBlockingGraph
from assemblykit.blocking.extended import exact_extended
from assemblykit.blocking.free_cones import blocked_by, exact_free_directions, overlay_faces
from assemblykit.blocking.graphs import blocking_graph, blocking_terms
from assemblykit.blocking.ndbg import Motion, NonDirectionalBlockingGraph
from assemblykit.blocking.obstacles import of_meshes
from assemblykit.blocking.rigid import RigidBlockingGraph
from assemblykit.errors import InputError, UnknownNameError
from assemblykit.graphs import component_labels
from assemblykit.model.assembly import Assembly
from assemblykit.model.polygons import PolygonAssembly
from assemblykit.planning.candidates import EXACT_GROUP_PARTS
from assemblykit.tolerance import ModelTolerance, Tolerance, order_key

Verdict = Literal["interlocking", "recursively interlocking", "not interlocking"]
FreeKind = Literal["direction", "arc", "circle", "region", "everywhere"]

MOTION_WORDS = {
    "infinitesimal": "small straight moves",
    "extended": "straight moves all the way out",
    "rigid": "small moves that may turn",
}
"""The kinds of motion (infinitesimal and extended translations, infinitesimal rigid
motions: docs/blocking.md, "Three kinds of motion") in an engineer's words."""
AXES_3D = ((0, 0, 1), (1, 0, 0), (0, 1, 0), (-1, 0, 0), (0, -1, 0), (0, 0, -1))
"""Directions tried first for a set's one direction, in order (lifting first, as the
planner's ranking: docs/planning.md, "How a plan is found")."""
AXES_2D = ((0, 1, 0), (1, 0, 0), (-1, 0, 0), (0, -1, 0))
LISTED = 6
"""Directions (or bounds of a region) written out in words before the rest is counted."""
_RANK = 1e-9
"""Singular values below this fraction of the largest count as zero (contact normals
spanning a line or a plane)."""


# --------------------------------------------------------------------------------------
# results


@dataclass(frozen=True, eq=False)
class FreeDirections:
    """One connected set of directions of the NDBG along which a subset is free
    (Wilson & Latombe 1992, §4: regions of S² or S¹). ``kind``: ``direction`` (one
    isolated direction, a vertex), ``arc`` (an arc of a great circle, or of the circle
    of a planar assembly), ``circle`` (a whole great circle), ``region`` (a region of
    the sphere) or ``everywhere``; ``direction`` is a unit direction inside it,
    ``bounds`` the NDBG vertices bounding it: the two ends of an arc, the vertices on a
    circle, the vertices on a region's boundary (in turn around ``direction``);
    ``normal`` the normal of a whole great circle."""

    kind: FreeKind
    direction: NDArray[np.float64]
    bounds: tuple[NDArray[np.float64], ...] = ()
    normal: NDArray[np.float64] | None = None

    def words(self, tol: Tolerance | None = None) -> str:
        """The set in words: ``+Z``, ``the arc from +X to +Y``, ``the region around
        +Z bounded by +X, +Y, -X and -Y``."""
        here = fmt.direction(self.direction, tol)
        named = [fmt.direction(b, tol) for b in self.bounds]
        if self.kind == "direction":
            return here
        if self.kind == "everywhere":
            return "every direction"
        if self.kind == "arc" and len(named) == 2:
            a, b = self.bounds
            if float(np.dot(a, b)) > -1 + 1e-9:
                return f"the arc from {named[0]} to {named[1]}"
            return f"the half circle from {named[0]} to {named[1]} through {here}"
        if self.kind == "circle" and self.normal is not None:
            return f"the great circle perpendicular to {fmt.direction(self.normal, tol)}"
        if self.kind == "circle":
            return f"the great circle through {_listed(named or [here])}"
        if named:
            return f"the region around {here} bounded by {_listed(named)}"
        return f"the half-sphere around {here}"

    def to_dict(self) -> dict[str, Any]:
        """JSON form: ``kind``, ``direction`` and ``bounds`` (unit vectors)."""
        return {
            "kind": self.kind,
            "direction": _floats(self.direction),
            "bounds": [_floats(b) for b in self.bounds],
            "normal": None if self.normal is None else _floats(self.normal),
        }


@dataclass(frozen=True, eq=False)
class Freedom:
    """A subset that moves relative to the rest: its ``parts``, one exact ``direction``
    that frees it (a unit vector; a unit twist ``(omega; v)`` for rigid motions), the
    NDBG regions where it is free (``free_along``, translations) and how to block it:
    ``block_with`` lists outward normals of faces of the subset such that parts
    touching it there block every direction it is free along (translations), or the
    motion found (rigid: a part touching it at ``at`` on a face whose normal is the
    velocity there). ``touching`` is false when the subset touches no other part."""

    parts: tuple[str, ...]
    direction: NDArray[np.float64]
    free_along: tuple[FreeDirections, ...]
    block_with: tuple[NDArray[np.float64], ...]
    touching: bool = True
    at: NDArray[np.float64] | None = None

    def explanation(self, tol: Tolerance | None = None) -> str:
        """Where the subset is free and what would block it, in words."""
        who = fmt.name_list(self.parts, 8)
        verb = "is" if len(self.parts) == 1 else "are"
        if self.at is not None:
            omega, v = self.direction[:3], self.direction[3:]
            text = (
                f"{who} {verb} free by the twist omega {fmt.vector(omega, tol)},"
                f" v {fmt.vector(v, tol)}"
            )
        else:
            places = [f.words(tol) for f in self.free_along] or [fmt.direction(self.direction, tol)]
            text = f"{who} {verb} free along {_listed(places)}"
        return f"{text}; {self.advice(tol)}"

    def advice(self, tol: Tolerance | None = None) -> str:
        """What to add, in words (the blocking arcs the subset lacks)."""
        if not self.touching:
            them = "it touches" if len(self.parts) == 1 else "they touch"
            return f"{them} no other part: add contacts on every side"
        normals = [fmt.direction(n, tol) for n in self.block_with]
        if self.at is not None and normals:
            return (
                f"stop this motion with a part touching it near {fmt.vector(self.at, tol)}"
                f" on a face whose outward normal is {normals[0]}"
            )
        them = "it" if len(self.parts) == 1 else "them"
        if len(normals) == 1:
            return (
                f"block {them} with a part touching {them} on a face whose outward normal"
                f" is {normals[0]}"
            )
        return (
            f"block {them} with parts touching {them} on faces whose outward normals are "
            + _listed(normals, limit=len(normals))
        )

    def to_dict(self, tol: Tolerance | None = None) -> dict[str, Any]:
        """JSON form: ``parts``, ``direction``, ``free_along``, ``block_with``, ``at``
        (rigid), ``touching`` and the ``explanation`` in words."""
        return {
            "parts": list(self.parts),
            "direction": _floats(self.direction),
            "free_along": [f.to_dict() for f in self.free_along],
            "block_with": [_floats(n) for n in self.block_with],
            "at": None if self.at is None else _floats(self.at),
            "touching": self.touching,
            "explanation": self.explanation(tol),
        }


@dataclass(frozen=True, eq=False)
class Component:
    """A strongly connected component of one DBG: ``parts`` that move together if at
    all, ``free`` when no arc leaves it (it moves along the cell's directions),
    ``stopped_by`` the arcs ``(i, j)`` leaving it (part ``j`` outside blocks part ``i``
    inside) and ``held_by`` the arcs among its parts that make it strongly connected (a
    component holding every part is never ``free``: it has nothing to move from)."""

    parts: tuple[str, ...]
    free: bool
    stopped_by: tuple[tuple[str, str], ...]
    held_by: tuple[tuple[str, str], ...]

    def to_dict(self) -> dict[str, Any]:
        """JSON form."""
        return {
            "parts": list(self.parts),
            "free": self.free,
            "stopped_by": [list(a) for a in self.stopped_by],
            "held_by": [list(a) for a in self.held_by],
        }


@dataclass(frozen=True, eq=False)
class BlockingCell:
    """One distinct DBG of the NDBG (Wilson & Latombe 1992, §3-5): a unit ``direction``
    of a region that has it (the highest-dimensional one: ``dimension`` 2 for a face, 1
    an edge or planar arc, 0 a vertex; 5 a cell of Γ_g's twists), the number of
    ``regions`` sharing it (1 for a direction examined outside the regions) and its
    strong ``components``. A subset moves along the cell's directions iff it is a union
    of components closed under the arcs: every other subset contains a component that
    an arc of ``stopped_by`` leaves."""

    direction: NDArray[np.float64]
    dimension: int
    regions: int
    components: tuple[Component, ...]

    def to_dict(self) -> dict[str, Any]:
        """JSON form."""
        return {
            "direction": _floats(self.direction),
            "dimension": self.dimension,
            "regions": self.regions,
            "components": [c.to_dict() for c in self.components],
        }


@dataclass(frozen=True, eq=False)
class KeyRemoval:
    """One key (or set of keys) leaving: ``keys`` move along unit ``direction`` (a
    twist for rigid motions) away from ``rest``."""

    keys: tuple[str, ...]
    direction: NDArray[np.float64]
    rest: tuple[str, ...]

    def to_dict(self) -> dict[str, Any]:
        """JSON form."""
        return {
            "keys": list(self.keys),
            "direction": _floats(self.direction),
            "rest": list(self.rest),
        }


@dataclass(frozen=True, eq=False)
class Interlocking:
    """Whether an assembly is interlocking, and with which keys (module docstring).

    ``verdict``; ``keys`` the keys given (``keys_given``) or the single parts found that
    are the only ones to move (both parts of a two-part assembly, the lighter first);
    ``smallest_keys`` the fewest parts that, as keys, make the assembly interlocking
    (empty when nothing moves); ``locked`` the classes of parts no motion separates,
    largest first; ``freedoms`` the subsets that move (the keys when interlocking, the
    subsets that stop it otherwise); ``order`` the keys in the order they leave when the
    recursion was followed (``stops``: the parts left where no single key was found);
    ``cells`` the certificate (one per distinct DBG); ``exact`` whether every direction
    was decided (``limits`` says what was not)."""

    parts: tuple[str, ...]
    motion: Motion
    verdict: Verdict
    keys: tuple[str, ...]
    keys_given: bool
    smallest_keys: tuple[str, ...]
    locked: tuple[tuple[str, ...], ...]
    freedoms: tuple[Freedom, ...]
    order: tuple[KeyRemoval, ...]
    stops: tuple[str, ...]
    cells: tuple[BlockingCell, ...]
    exact: bool
    limits: str
    planar: bool
    tol: ModelTolerance

    @property
    def interlocking(self) -> bool:
        """Whether the verdict is interlocking (recursively or not)."""
        return self.verdict != "not interlocking"

    @property
    def recursive(self) -> bool:
        """Whether the verdict is recursively interlocking."""
        return self.verdict == "recursively interlocking"

    @property
    def deadlocked(self) -> bool:
        """Whether no part and no subset moves at all."""
        return len(self.locked) == 1

    def summary(self) -> str:
        """The answer in words: the verdict, the keys and their order, what moves and
        how to block it, the smallest set of keys."""
        tol = self.tol
        head = (
            f"{self.verdict.capitalize()} ({MOTION_WORDS[self.motion]},"
            f" {fmt.count(len(self.parts), 'part')})"
        )
        lines: list[str] = []
        if self.interlocking:
            keys = fmt.name_list(self.keys, 8)
            moving = [f.explanation(tol) for f in self.freedoms]
            which = "the key" if len(self.keys) == 1 else "the keys"
            lines.append(
                f"{head}: only {keys} can move ({which});"
                " every other part and every subset stays in place along every direction"
                # one group per distinct blocking graph (docs/interlocking.md)
                f" ({fmt.count(len(self.cells), 'group')} of directions checked)."
            )
            lines += [f"- {m}" for m in moving]
        elif self.deadlocked:
            lines.append(
                f"{head}: no part and no subset can move along any direction (deadlocked);"
                " no key would make it interlocking."
            )
        else:
            lines.append(f"{head}: these move relative to the rest:")
            lines += [f"- {f.explanation(tol)}" for f in self.freedoms]
            if self.smallest_keys:
                lines.append(
                    "As keys, the fewest parts that make it interlocking: "
                    f"{fmt.name_list(self.smallest_keys, 8)}."
                )
        if self.order:
            steps = [
                f"{', '.join(r.keys)} along {fmt.direction(r.direction, tol)}" for r in self.order
            ]
            left = self.order[-1].rest
            lines.append(
                "Keys in order: "
                + ", then ".join(steps)
                + (f" ({', '.join(left)} stays)." if left and not self.stops else ".")
            )
        if self.stops:
            lines.append(
                f"After them no single key: {fmt.name_list(self.stops, 8)} are not"
                " interlocking on their own."
            )
        if not self.exact:
            lines.append(f"Not every direction was decided: {self.limits}")
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        """JSON form (docs/interlocking.md, "Output")."""
        return {
            "verdict": self.verdict,
            "interlocking": self.interlocking,
            "recursive": self.recursive,
            "deadlocked": self.deadlocked,
            "motion": self.motion,
            "parts": list(self.parts),
            "keys": list(self.keys),
            "keys_given": self.keys_given,
            "smallest_keys": list(self.smallest_keys),
            "locked": [list(c) for c in self.locked],
            "free": [f.to_dict(self.tol) for f in self.freedoms],
            "order": [r.to_dict() for r in self.order],
            "stops": list(self.stops),
            "exact": self.exact,
            "limits": self.limits or None,
            "certificate": {"cells": [c.to_dict() for c in self.cells]},
            "summary": self.summary(),
        }

    def __repr__(self) -> str:
        keys = f"key: {fmt.name_list(self.keys)}" if self.interlocking else ""
        return fmt.summary("Interlocking", self.verdict, keys, fmt.count(len(self.parts), "part"))

    def _repr_html_(self) -> str:
        """The subsets that move, where, and what blocks them (notebooks)."""
        rows = [
            (
                fmt.name_list(f.parts, 8),
                fmt.direction(f.direction, self.tol),
                _listed([d.words(self.tol) for d in f.free_along]) or "-",
                f.advice(self.tol),
            )
            for f in self.freedoms
        ]
        headers = ("moves", "e.g. along", "free along", "to block it")
        return fmt.html_summary(repr(self), headers, rows)


# --------------------------------------------------------------------------------------
# the analysis


def interlocking(
    assembly: Assembly | PolygonAssembly,
    keys: Iterable[str] | None = None,
    motion: Motion = "infinitesimal",
    tol: Tolerance | None = None,
) -> Interlocking:
    """Whether ``assembly`` is interlocking for ``motion`` with the given ``keys`` (or
    with a key found), recursively or not, with its certificate and explanations
    (module docstring; docs/interlocking.md)."""
    if motion not in MOTION_WORDS:
        raise ValueError(f"unknown motion {motion!r}")
    names = tuple(assembly.names)
    planar = assembly.dimension == 2
    if len(names) < 2:
        raise InputError("an interlocking assembly needs at least two parts")
    if motion == "rigid" and planar:
        raise InputError("--motion rigid turns 3D parts: not for a 2D polygon assembly")
    chosen = None if keys is None else frozenset(keys)
    if chosen is not None:
        source = getattr(assembly, "source", None)
        unknown = sorted(chosen - set(names))
        if unknown:
            raise UnknownNameError(f"no part named {unknown[0]!r}", source=source, where="keys")
        if not chosen or chosen == set(names):
            raise InputError(
                "the keys must be some of the parts, not none or all of them",
                source=source,
                where="keys",
            )
    tol = assembly.tolerance(tol)
    weights = assembly.sizes()
    first = _stage(assembly, names, motion, tol)
    found = _single_keys(first.classes, names, weights)
    key_set = chosen if chosen is not None else frozenset(found)
    holds = not first.deadlocked and (
        bool(found) if chosen is None else _within_one(set(names) - key_set, first.classes)
    )
    # of two parts found, both are keys and the lighter leaves
    leaving = key_set if chosen is not None or len(names) > 2 else frozenset(found[:1])
    freedoms = _freedoms(assembly, first, leaving if holds else chosen, holds, weights, tol)
    order: tuple[KeyRemoval, ...] = ()
    stops: tuple[str, ...] = ()
    stages = [first]
    if holds and len(leaving) == 1:
        order, stops, stages = _recursion(assembly, first, leaving, weights, motion, tol)
    undecided = [stage.evidence.limits for stage in stages if not stage.evidence.exact]
    recursive = holds and len(names) > 2 and bool(order) and not stops
    verdict: Verdict = (
        "not interlocking"
        if not holds
        else "recursively interlocking"
        if recursive
        else "interlocking"
    )
    return Interlocking(
        parts=names,
        motion=motion,
        verdict=verdict,
        keys=tuple(_ordered(key_set, names)) if chosen is not None else found,
        keys_given=chosen is not None,
        smallest_keys=_smallest_keys(first.classes, names, weights),
        locked=tuple(tuple(_ordered(c, names)) for c in first.classes),
        freedoms=freedoms,
        order=order,
        stops=stops,
        cells=tuple(_certificate(c, names, planar) for c in first.evidence.cells),
        exact=not undecided,
        limits=undecided[0] if undecided else "",
        planar=planar,
        tol=tol,
    )


@dataclass(frozen=True, eq=False)
class _Cell:
    """A DBG examined: its graph, a direction (or twist) where it holds, the dimension
    of that region and the NDBG regions that have it (none for other directions)."""

    graph: DirectionalBlockingGraph
    direction: NDArray[np.float64]
    dimension: int
    regions: tuple[int, ...]

    @cached_property
    def components(self) -> tuple[frozenset[str], ...]:
        """The strong components, largest first."""
        return tuple(self.graph.sccs())

    def free(self, subset: frozenset[str]) -> bool:
        """Whether ``subset`` moves along this cell's directions (no arc leaves it)."""
        return self.graph.is_free(subset)


@dataclass(frozen=True, eq=False)
class _Evidence:
    """What a motion's blocking graphs say about the parts: the ``cells`` (distinct
    DBGs), ``witnesses`` (subsets found moving along a direction or twist outside the
    cells), the NDBG of translations (``ndbg``) or Γ_g (``rigid``, with Γ_t as
    ``translations``), and whether every direction was decided (``limits`` says what
    was not)."""

    cells: tuple[_Cell, ...]
    witnesses: tuple[tuple[frozenset[str], NDArray[np.float64]], ...]
    ndbg: NonDirectionalBlockingGraph | None
    rigid: RigidBlockingGraph | None
    exact: bool
    limits: str = ""
    translations: NonDirectionalBlockingGraph | None = None


@dataclass(frozen=True, eq=False)
class _Stage:
    """The parts still assembled, what their blocking graphs say and the classes of
    parts no motion separates (largest first)."""

    parts: tuple[str, ...]
    evidence: _Evidence
    classes: tuple[frozenset[str], ...]

    @property
    def deadlocked(self) -> bool:
        return len(self.classes) == 1


def _stage(
    assembly: Assembly | PolygonAssembly,
    parts: tuple[str, ...],
    motion: Motion,
    tol: ModelTolerance,
) -> _Stage:
    """The evidence of ``motion`` among ``parts`` and the classes it leaves together."""
    if motion == "rigid":
        evidence = _rigid_evidence(assembly, parts, tol)
    else:
        evidence = _translation_evidence(assembly, parts, motion, tol)
    return _Stage(parts, evidence, _locked_classes(parts, evidence.cells, evidence.witnesses))


def _locked_classes(
    parts: Sequence[str],
    cells: Iterable[_Cell],
    witnesses: Iterable[tuple[frozenset[str], NDArray[np.float64]]] = (),
) -> tuple[frozenset[str], ...]:
    """The classes of parts that no motion separates: the meet of the strong components
    of every DBG and of the split of each witness subset (module docstring), largest
    first, then by their first part."""
    signature: dict[str, list[int]] = {p: [] for p in parts}
    for cell in cells:
        component = {p: k for k, comp in enumerate(cell.components) for p in comp}
        for p in parts:
            signature[p].append(component[p])
    for moving, _ in witnesses:
        for p in parts:
            signature[p].append(int(p in moving))
    groups: dict[tuple[int, ...], list[str]] = {}
    for p in parts:
        groups.setdefault(tuple(signature[p]), []).append(p)
    index = {p: k for k, p in enumerate(parts)}
    return tuple(
        frozenset(g) for g in sorted(groups.values(), key=lambda g: (-len(g), index[g[0]]))
    )


def _ndbg_cells(graph: NonDirectionalBlockingGraph) -> tuple[_Cell, ...]:
    """One cell per distinct DBG of an NDBG, represented by its highest-dimensional
    region (Wilson & Latombe 1992, §4: the DBG is constant over each region)."""
    arrangement = graph.arrangement
    cells = []
    for dbg, members in graph.unique_dbgs():
        best = int(members[np.argmax(arrangement.dims[members])])
        cells.append(
            _Cell(
                dbg,
                np.asarray(arrangement.directions[best], dtype=np.float64),
                int(arrangement.dims[best]),
                tuple(int(m) for m in members),
            )
        )
    return tuple(sorted(cells, key=lambda c: (-c.dimension, c.regions[0])))


def _translation_evidence(
    assembly: Assembly | PolygonAssembly,
    parts: tuple[str, ...],
    motion: Motion,
    tol: ModelTolerance,
) -> _Evidence:
    """The DBGs of Γ_t or Γ_e over every region; for Γ_e sampled at the regions of
    Γ_t, the sets Γ_t lets move decided over every direction (module docstring)."""
    ndbg = blocking_graph(assembly, motion, parts, tol)
    assert isinstance(ndbg, NonDirectionalBlockingGraph)
    cells = _ndbg_cells(ndbg)
    if motion == "infinitesimal" or exact_extended(assembly, parts):
        return _Evidence(cells, (), ndbg, None, True)
    local = blocking_graph(assembly, "infinitesimal", parts, tol)
    return _refined(of_meshes(assembly), parts, ndbg, local, cells, tol)


def _refined(
    assembly: Assembly,
    parts: tuple[str, ...],
    ndbg: NonDirectionalBlockingGraph,
    local: NonDirectionalBlockingGraph,
    cells: tuple[_Cell, ...],
    tol: ModelTolerance,
) -> _Evidence:
    """Γ_e sampled at the regions of Γ_t (``ndbg``), completed where the samples may
    miss a motion: a set closed in a DBG of Γ_t (``local``, a necessary condition) that
    would split a class, free in Γ_t along an edge or a face (at a vertex the sample is
    the direction itself), is given its exact free set among ``parts`` (Wilson &
    Latombe 1992, §5); if some remain undecided and there are at most
    ``EXACT_GROUP_PARTS`` parts, every face of the overlay of every pair's blocked set
    is examined (over a face every DBG is constant)."""
    witnesses: list[tuple[frozenset[str], NDArray[np.float64]]] = []
    classes = _locked_classes(parts, cells)
    local_cells = _ndbg_cells(local)
    dims = local.arrangement.dims
    # Γ_e is sampled at the regions of this very Γ_t (Wilson & Latombe 1992, §5)
    sampled_here = ndbg.arrangement is local.arrangement
    undecided = False
    candidates = sorted(
        {s for cell in local_cells for s in cell.graph.free_subassemblies()},
        key=lambda s: (len(s), sorted(s)),
    )
    for subset in candidates:
        if not _splits(subset, classes):
            continue
        regions = [r for c in local_cells if c.free(subset) for r in c.regions]
        if sampled_here and all(dims[r] == 0 for r in regions):
            continue  # the samples are these directions: decided
        if len(parts) > EXACT_GROUP_PARTS:
            undecided = True
            continue
        found = exact_free_directions(assembly, subset, tol, parts, limit=1)
        if found.directions:
            witnesses.append((subset, np.asarray(found.directions[0], dtype=np.float64)))
            classes = _locked_classes(parts, cells, witnesses)
        else:
            undecided = True
    if not undecided:
        return _Evidence(cells, tuple(witnesses), ndbg, None, True)
    if len(parts) > EXACT_GROUP_PARTS:
        return _Evidence(
            cells,
            tuple(witnesses),
            ndbg,
            None,
            False,
            f"Γ_e of parts that are not convex was sampled at the regions of Γ_t; with more"
            f" than {EXACT_GROUP_PARTS} parts the sets Γ_t lets move along an arc or a"
            " region were not examined between those directions",
        )
    sets = [blocked_by(assembly, [a], b, tol) for a in parts for b in parts if a != b]
    if any(s is None for s in sets):
        return _Evidence(
            cells,
            tuple(witnesses),
            ndbg,
            None,
            False,
            "some pair of parts has too many triangles for its exact blocked set",
        )
    faces = overlay_faces([s for s in sets if s is not None], tol)
    extra = tuple(
        _Cell(ndbg.dbg(d), np.asarray(d, dtype=np.float64), 2, ())
        for d in np.vstack([faces.directions, faces.thin]).reshape(-1, 3)
    )
    return _Evidence(cells + extra, tuple(witnesses), ndbg, None, True)


def _rigid_evidence(
    assembly: Assembly | PolygonAssembly, parts: tuple[str, ...], tol: ModelTolerance
) -> _Evidence:
    """Γ_g: the DBGs of the full-dimensional cells of the twist arrangement and the
    subsets its linear programs free (:meth:`RigidBlockingGraph.removable`: motions that
    break a contact) and, since translations are rigid motions, every DBG of Γ_t (a
    set sliding along its contacts, such as a pin in its bore, moves too)."""
    graph = blocking_graph(assembly, "rigid", parts, tol)
    assert isinstance(graph, RigidBlockingGraph)
    seen: dict[frozenset[tuple[str, str]], _Cell] = {}
    for region in graph.regions():
        seen.setdefault(region.dbg.arcs, _Cell(region.dbg, region.direction, 5, ()))
    witnesses = [(r.parts, np.asarray(r.directions[0])) for r in graph.removable() if r.directions]
    local = blocking_graph(assembly, "infinitesimal", parts, tol)
    assert isinstance(local, NonDirectionalBlockingGraph)
    translations = tuple(
        _Cell(c.graph, np.r_[np.zeros(3), c.direction], c.dimension, ()) for c in _ndbg_cells(local)
    )
    return _Evidence(
        (*seen.values(), *translations),
        tuple(witnesses),
        None,
        graph,
        False,
        f"Γ_g: the cells of the twist arrangement ({graph.arrangement.status}), every"
        " translation, and linear programs for the sets of up to 2 touching parts;"
        " other sets that only a turn frees were not examined",
        local,
    )


def _splits(subset: frozenset[str], classes: Sequence[frozenset[str]]) -> bool:
    """Whether ``subset`` cuts some class (has some but not all of its parts)."""
    return any(subset & c and not c <= subset for c in classes)


def _within_one(parts: set[str], classes: Sequence[frozenset[str]]) -> bool:
    """Whether ``parts`` lie in one class."""
    return any(parts <= c for c in classes)


def _ordered(parts: Iterable[str], names: Sequence[str]) -> list[str]:
    """``parts`` in the assembly's order."""
    inside = set(parts)
    return [n for n in names if n in inside]


def _heaviest(parts: Sequence[str], weights: dict[str, float]) -> str:
    """The heaviest of ``parts`` (weights rounded to ``ORDER_RESOLUTION``, then the
    first in order)."""
    scale = max((weights[p] for p in parts), default=0.0)
    return max(parts, key=lambda p: (order_key(weights[p], scale), -parts.index(p)))


def _single_keys(
    classes: Sequence[frozenset[str]], parts: Sequence[str], weights: dict[str, float]
) -> tuple[str, ...]:
    """The parts that are the only ones to move: a class of one part with every other
    part in one class (both parts of a two-part assembly, the lighter first)."""
    if len(classes) != 2:
        return ()
    singles = [next(iter(c)) for c in classes if len(c) == 1]
    if len(parts) == 2:
        base = _heaviest(list(parts), weights)
        return tuple(sorted(singles, key=lambda p: p == base))
    return tuple(singles)


def _smallest_keys(
    classes: Sequence[frozenset[str]], parts: Sequence[str], weights: dict[str, float]
) -> tuple[str, ...]:
    """The fewest parts that, as keys, make the assembly interlocking: everything
    outside a largest class (the one holding the heaviest part among equals); none when
    nothing moves."""
    if len(classes) < 2:
        return ()
    size = max(len(c) for c in classes)
    largest = [c for c in classes if len(c) == size]
    base = _heaviest([p for c in largest for p in _ordered(c, parts)], weights)
    kept = next(c for c in largest if base in c)
    return tuple(p for p in parts if p not in kept)


def _moving_side(
    subset: frozenset[str], parts: Sequence[str], keys: frozenset[str] | None, base: str
) -> frozenset[str]:
    """The side of the split ``subset`` / rest that is said to move: the one among the
    keys, else the one without the heaviest part ``base``."""
    other = frozenset(parts) - subset
    if keys:
        if subset <= keys:
            return subset
        if other <= keys:
            return other
    return other if base in subset else subset


def _freedoms(
    assembly: Assembly | PolygonAssembly,
    stage: _Stage,
    keys: frozenset[str] | None,
    holds: bool,
    weights: dict[str, float],
    tol: ModelTolerance,
) -> tuple[Freedom, ...]:
    """The subsets that move, each once: when interlocking, the moves of the keys;
    otherwise the least sets of each DBG (sink components) and the witnesses, with keys
    given only those that split the parts outside the keys (and the least such set of
    each DBG); unions of smaller sets reported are left out."""
    parts = stage.parts
    base = _heaviest(list(parts), weights)
    rest = frozenset(parts) - (keys or frozenset())
    found: list[frozenset[str]] = []
    sources: list[frozenset[str]] = []
    for cell in stage.evidence.cells:
        sources += [c for c in cell.components if cell.free(c) and c != frozenset(parts)]
        if keys and not holds:
            splitting = [s for s in cell.graph.free_subassemblies() if _splits(s, [rest])]
            sources += splitting[:1]
    sources += [s for s, _ in stage.evidence.witnesses]
    for subset in sources:
        side = _moving_side(subset, parts, keys, base)
        if side not in found:
            found.append(side)
    found.sort(key=lambda s: (len(s), _ordered(s, parts)))
    # a union of smaller sets that move is no news
    least = [s for s in found if frozenset().union(*(o for o in found if o < s)) != s]
    if keys and holds:
        least = [s for s in least if s <= keys]
    elif keys:
        least = [s for s in least if _splits(s, [rest])]  # not the keys moving
    return tuple(_freedom(assembly, stage, side, tol) for side in least)


def _freedom(
    assembly: Assembly | PolygonAssembly, stage: _Stage, side: frozenset[str], tol: ModelTolerance
) -> Freedom:
    """Where ``side`` is free, one direction that frees it and how to block it."""
    parts = stage.parts
    moving = tuple(_ordered(side, parts))
    direction = _direction(stage, side)
    evidence = stage.evidence
    ndbg = evidence.ndbg or evidence.translations
    if evidence.rigid is not None and (np.any(direction[:3]) or ndbg is None):
        at, normal = _rigid_block(assembly, moving, direction)
        return Freedom(moving, direction, (), (normal,), True, at)
    free_along: tuple[FreeDirections, ...] = ()
    if ndbg is not None:
        cells = _ndbg_cells(ndbg) if evidence.ndbg is None else evidence.cells
        regions = [r for c in cells if c.regions and c.free(side) for r in c.regions]
        width = ndbg.arrangement.dimension

        def is_free(d: NDArray[np.float64]) -> bool:
            return ndbg.dbg(d[:width]).is_free(side)

        free_along = _free_directions(ndbg.arrangement, regions, is_free)
    normals, touching = _contact_normals(assembly, side, parts, tol)
    planar = assembly.dimension == 2
    return Freedom(
        moving,
        _shown(direction, planar) if evidence.rigid is None else direction,
        tuple(_shown_region(f, planar) for f in free_along),
        tuple(_shown(n, planar) for n in _blocking_normals(normals, 2 if planar else 3)),
        touching,
    )


def _direction(stage: _Stage, side: frozenset[str]) -> NDArray[np.float64]:
    """One exact direction (or twist) along which ``side`` moves: an axis direction
    when one does (``AXES_3D`` order), else the direction of its highest-dimensional
    free region, else a witness's."""
    evidence = stage.evidence
    other = frozenset(stage.parts) - side
    translations = evidence.ndbg or evidence.translations
    if translations is not None:
        planar = translations.arrangement.dimension == 2
        for axis in AXES_2D if planar else AXES_3D:
            d = np.asarray(axis, dtype=np.float64)
            if translations.dbg(d[:2] if planar else d).is_free(side):
                return d if evidence.rigid is None else np.r_[np.zeros(3), d]
    free = [c for c in evidence.cells if c.free(side)]
    if free:
        # translations first (a twist without turn), then the highest dimension
        best = max(
            free,
            key=lambda c: (
                not np.any(c.direction[:3]) if len(c.direction) == 6 else True,
                c.dimension,
            ),
        )
        return np.asarray(best.direction, dtype=np.float64)
    for subset, d in evidence.witnesses:
        if subset == side:
            return np.asarray(d, dtype=np.float64)
        if subset == other:
            return -np.asarray(d, dtype=np.float64)
    raise AssertionError("a set reported free has a direction")


def _shown(direction: NDArray[np.float64], planar: bool) -> NDArray[np.float64]:
    """A direction as shown: 2-vectors for polygons (as the NDBG of the plane)."""
    d = np.asarray(direction, dtype=np.float64)
    return d[:2] if planar and len(d) == 3 else d


def _shown_region(free: FreeDirections, planar: bool) -> FreeDirections:
    return FreeDirections(
        free.kind,
        _shown(free.direction, planar),
        tuple(_shown(b, planar) for b in free.bounds),
        free.normal,
    )


def _unsigned(axis: NDArray[np.float64]) -> NDArray[np.float64]:
    """A direction whose sign means nothing, with its first sizeable component positive
    (docs/architecture.md, "Tolerances")."""
    big = np.flatnonzero(np.abs(axis) > 1e-9 * np.linalg.norm(axis))
    unit = axis / np.linalg.norm(axis)
    return (unit if unit[big[0]] > 0 else -unit) + 0.0


def _recursion(
    assembly: Assembly | PolygonAssembly,
    first: _Stage,
    keys: frozenset[str],
    weights: dict[str, float],
    motion: Motion,
    tol: ModelTolerance,
) -> tuple[tuple[KeyRemoval, ...], tuple[str, ...], list[_Stage]]:
    """The keys in the order they leave: the key, then while at least two parts remain
    the single key of the rest (the lighter of two parts); the parts left where no
    single key is found (none when the assembly is recursively interlocking); and every
    stage examined."""
    planar = assembly.dimension == 2
    stage, leaving = first, keys
    order: list[KeyRemoval] = []
    stages = [first]
    while True:
        rest = tuple(p for p in stage.parts if p not in leaving)
        order.append(
            KeyRemoval(
                tuple(_ordered(leaving, stage.parts)),
                _shown(_direction(stage, leaving), planar),
                rest,
            )
        )
        if len(rest) < 2:
            return tuple(order), (), stages
        stage = _stage(assembly, rest, motion, tol)
        stages.append(stage)
        single = _single_keys(stage.classes, rest, weights)
        if not single:
            return tuple(order), rest, stages
        leaving = frozenset(single[:1])


def _certificate(cell: _Cell, parts: Sequence[str], planar: bool) -> BlockingCell:
    """A cell as its strong components, each with the arcs that leave it and those
    that hold it together."""
    components = []
    for comp in cell.components:
        stopped = sorted((i, j) for i, j in cell.graph.arcs if i in comp and j not in comp)
        held = sorted((i, j) for i, j in cell.graph.arcs if i in comp and j in comp)
        # the whole assembly moving is no motion relative to anything
        free = not stopped and len(comp) < len(parts)
        components.append(
            Component(tuple(_ordered(comp, parts)), free, tuple(stopped), tuple(held))
        )
    return BlockingCell(
        _shown(cell.direction, planar), cell.dimension, max(len(cell.regions), 1), tuple(components)
    )


# --------------------------------------------------------------------------------------
# explanations


def _free_directions(
    arrangement: Arrangement, regions: Sequence[int], is_free: Callable[[NDArray[np.float64]], bool]
) -> tuple[FreeDirections, ...]:
    """The free regions of the NDBG as connected sets of directions, each described by
    its kind, a direction inside it and the vertices bounding it (Wilson & Latombe
    1992, §4: vertices, edges and faces of the arrangement; points and arcs of S¹).
    ``is_free`` tells whether the subset is free along a direction (to name a region
    by its middle or an axis inside it rather than by one of its cells)."""
    n = len(arrangement)
    free = np.zeros(n, dtype=bool)
    free[list(regions)] = True
    if not free.any():
        return ()
    low, high = arrangement.links_low, arrangement.links_high
    both = free[low] & free[high]
    label = component_labels(n, np.stack([low[both], high[both]], axis=1))
    closure = _closure_lists(arrangement)
    out = [
        _described(arrangement, np.flatnonzero((label == value) & free), free, closure, is_free)
        for value in np.unique(label[free])
    ]
    return tuple(sorted(out, key=lambda f: _KIND_ORDER[f.kind]))


_KIND_ORDER = {"everywhere": 0, "region": 1, "circle": 2, "arc": 3, "direction": 4}


def _closure_lists(arrangement: Arrangement) -> list[NDArray[np.int64]]:
    """For every region, the regions whose closure holds it (its incident edges and
    faces for a vertex, faces for an edge; arcs for a point of S¹)."""
    n = len(arrangement)
    low, high = arrangement.links_low, arrangement.links_high
    order = np.argsort(low, kind="stable")
    starts = np.searchsorted(low[order], np.arange(n + 1))
    direct = [high[order[starts[r] : starts[r + 1]]] for r in range(n)]
    return [
        np.unique(np.concatenate([d, *(direct[int(h)] for h in d)])) if len(d) else d
        for d in direct
    ]


def _described(
    arrangement: Arrangement,
    members: NDArray[np.intp],
    free: NDArray[np.bool_],
    closure: Sequence[NDArray[np.int64]],
    is_free: Callable[[NDArray[np.float64]], bool],
) -> FreeDirections:
    """One connected set of free regions (``members``): its kind, a direction inside it
    (the mean of its highest-dimensional regions, or the axis nearest it, when free;
    else the region nearest the mean) and its bounding vertices (the ends of an arc;
    for a region, its vertices next to a region that is not free)."""
    dims = arrangement.dims
    directions = np.asarray(arrangement.directions, dtype=np.float64)
    top = int(dims[members].max())
    tops = members[dims[members] == top]
    mean = directions[tops].sum(axis=0)
    inside = directions[tops[int(np.argmax(directions[tops] @ mean))]]
    if top == arrangement.dimension - 1 and np.linalg.norm(mean) > 1e-9:
        middle = mean / np.linalg.norm(mean)
        axis = np.eye(3)[int(np.argmax(np.abs(middle)))] * np.sign(
            middle[np.argmax(np.abs(middle))]
        )
        for candidate in (axis, middle):
            if candidate @ inside > 0 and is_free(candidate):
                inside = candidate
                break
    if len(members) == len(arrangement):
        return FreeDirections("everywhere", inside)
    if top == 0:
        return FreeDirections("direction", inside)
    vertices = [int(v) for v in members[dims[members] == 0]]
    if top == 1:
        # the ends of an arc: vertices with one free arc of the set next to them
        chosen = set(tops.tolist())
        ends = [v for v in vertices if sum(int(h) in chosen for h in closure[v]) == 1]
        if not ends and arrangement.dimension == 3:
            # the circle of its edges (an edge's links to its faces name it)
            on = arrangement.links_circle[np.isin(arrangement.links_low, tops)]
            normal = _unsigned(np.asarray(arrangement.normals[int(on[0])], dtype=np.float64))
            return FreeDirections("circle", inside, _around(inside, directions[vertices]), normal)
        return FreeDirections("arc", inside, _around(inside, directions[ends]))
    bounding = [v for v in vertices if not free[closure[v]].all()]
    return FreeDirections("region", inside, _around(inside, directions[bounding]))


def _around(
    centre: NDArray[np.float64], points: NDArray[np.float64]
) -> tuple[NDArray[np.float64], ...]:
    """``points`` in turn counter-clockwise around ``centre`` (seen from outside)."""
    if len(points) == 0:
        return ()
    # the angles run from -e1: the frame's turn decides which point comes first
    e1, e2 = se3.axis_basis(centre / np.linalg.norm(centre), turned=True)
    angles = np.arctan2(points @ e2, points @ e1)
    return tuple(np.asarray(points[k], dtype=np.float64) for k in np.argsort(angles, kind="stable"))


def _contact_normals(
    assembly: Assembly | PolygonAssembly,
    side: frozenset[str],
    parts: Sequence[str],
    tol: ModelTolerance,
) -> tuple[NDArray[np.float64], bool]:
    """Unit normals of the contacts of ``side`` with the other ``parts``, out of
    ``side`` (Γ_t's half-spaces: Wilson & Latombe 1992, §4), and whether there are any."""
    inside = set(parts)
    rows = [
        np.asarray(t.normals, dtype=np.float64)
        for t in blocking_terms(assembly, "infinitesimal", tol)
        if t.moving in side and t.blocker in inside and t.blocker not in side and t.single
    ]
    if not rows:
        return np.zeros((0, 3)), False
    normals = np.concatenate(rows)
    return normals / np.linalg.norm(normals, axis=1, keepdims=True), True


def _blocking_normals(normals: NDArray[np.float64], dimension: int) -> list[NDArray[np.float64]]:
    """Outward normals ``m`` of faces of a subset such that contacts there block it
    along every direction it is free along, given its contacts' normals ``n`` (the
    free directions are ``{d : n . d <= 0}``; they are all blocked iff the normals,
    old and new, positively span the space). When the contact normals span the space
    the free directions form a pointed cone and one face does: ``m`` = minus the sum of
    the distinct unit normals, which lies inside the cone they generate. Otherwise the directions
    no contact limits (those perpendicular to all of them) need both ways of each axis
    of that subspace, and, when the normals do not already positively span their own
    span, minus their sum too."""
    if len(normals) == 0:
        return []
    # each direction once: patches split by other parts repeat a normal
    flat = np.unique(np.round(normals[:, :dimension], 9) + 0.0, axis=0)
    total = flat.sum(axis=0)
    _, values, vt = np.linalg.svd(flat)
    rank = int(np.sum(values > _RANK * values[0]))
    if rank == dimension:
        return [_unit(-total, dimension)]
    spanned, missing = vt[:rank], vt[rank:]
    out: list[NDArray[np.float64]] = []
    for w in _axis_basis(missing, spanned, dimension):
        out += [w, -w]
    if not _positively_spanning(flat @ spanned.T):
        out.append(_unit(-total, dimension))
    return out


def _unit(v: NDArray[np.float64], dimension: int) -> NDArray[np.float64]:
    d = np.zeros(3)
    d[:dimension] = v / np.linalg.norm(v)
    return d + 0.0


def _axis_basis(
    missing: NDArray[np.float64], spanned: NDArray[np.float64], dimension: int
) -> list[NDArray[np.float64]]:
    """An orthonormal basis of the subspace ``missing``, along coordinate axes where
    the subspace holds them, each with its first sizeable component positive."""
    basis: list[NDArray[np.float64]] = []
    projector = missing.T @ missing
    for axis in np.eye(dimension):
        v = projector @ axis
        for b in basis:
            v = v - (v @ b) * b
        if np.linalg.norm(v) > 1e-6 and len(basis) < len(missing):
            basis.append(v / np.linalg.norm(v))
    out = []
    for b in basis:
        sign = 1.0 if b[np.flatnonzero(np.abs(b) > 1e-9)[0]] > 0 else -1.0
        out.append(_unit(sign * b, dimension))
    return out


def _positively_spanning(coords: NDArray[np.float64]) -> bool:
    """Whether vectors (rows, in coordinates of their own span of dimension 1 or 2)
    positively span it: both signs on a line; no gap of half a turn in the plane."""
    if coords.shape[1] == 1:
        return bool((coords > 0).any() and (coords < 0).any())
    angles = np.sort(np.arctan2(coords[:, 1], coords[:, 0]))
    gaps = np.diff(np.r_[angles, angles[0] + 2 * np.pi])
    return bool(gaps.max() < np.pi - 1e-9)


def _rigid_block(
    assembly: Assembly | PolygonAssembly, moving: Sequence[str], twist: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Where a part would stop the twist: the vertex of the moving parts that the twist
    moves fastest, and the unit velocity there (a face with that outward normal, touched
    there, is pushed into by the motion)."""
    mesh_assembly = of_meshes(assembly)
    points = np.concatenate([mesh_assembly.parts[n].mesh.vertices for n in moving])
    omega, v = twist[:3], twist[3:]
    velocities = v[None, :] + np.cross(omega[None, :], points)
    k = int(np.argmax(np.linalg.norm(velocities, axis=1)))
    return np.asarray(points[k], dtype=np.float64), _unit(velocities[k], 3)


# --------------------------------------------------------------------------------------
# words and numbers


def _listed(items: Sequence[str], limit: int = LISTED) -> str:
    """``a``, ``a and b``, ``a, b and c``, then how many more."""
    items = list(items)
    if len(items) > limit:
        return ", ".join(items[:limit]) + f" and {len(items) - limit} more"
    if len(items) <= 1:
        return "".join(items)
    return ", ".join(items[:-1]) + " and " + items[-1]


def _floats(values: NDArray[np.float64]) -> list[float]:
    """A vector as JSON numbers (no negative zero)."""
    return [float(x) + 0.0 for x in np.ravel(values)]
