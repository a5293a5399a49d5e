"""Reduction of the relational network to a fixpoint (Corner et al. 1983 §III C-F,
docs/algebra.md §5.2).

The rules, in the order of Corner et al. 1983 §III:

1. **Intersection** (standard solutions): two links between the same pair of instances
   are intersected (``Coset.intersect``); an empty result is an inconsistency, recorded
   with the relations involved and the mismatch (docs/algebra.md §2.5).
2. **Merge** on a fixed link (a single point ``X``): the target instance is merged into
   the source, and every link of the merged instance is re-expressed
   (``Q ↦ X·Q``, ``P ↦ P·X⁻¹``), which may enable new intersections.
3. **Branching** on a link of finitely many points: every point is tried (depth first);
   the answers of the consistent branches are listed together (status ``ambiguous``).
   A **lattice** (dof 0, infinitely many components) is flagged and not merged.
4. **Cycles** of length ≤ 4, only when no intersection or merge applies: the links of a
   cycle but one are chained (``Coset.product``) and intersected with the last; a result
   with fewer dof replaces it. A revolute-revolute chain closing on a revolute link (the
   planar four-bar with its crank stopped, two revolutes closing a loop) is solved in
   closed form by circle-circle intersection (0, 1 or 2 points). A cycle of joints with
   parallel axes that no rule closes is checked against its reach: one body spanning
   more between its axes than the others together is a conflict (the loop cannot close).
5. **Termination**: each remaining instance gets its pose set relative to the world:
   a coset (product along a tree path from the world), a finite set, or, for what the
   rules cannot express (non-coset relations, unresolved cycles, chains that are not
   cosets), the residue solved numerically (:mod:`assemblykit.inference.numeric`).
   Higher pairs hanging from the world (a point in a plane or a line, a line on a
   plane), alone or with one lower pair, are solved in closed form first. A pose is the
   one of least motion from the pose as written (the identity) that the answer allows.

Work is driven by a worklist (insertions and merges), so a network that merges from the
world outward is reduced in near-linear time; cycles are searched only at a fixpoint.
"""

from __future__ import annotations

import itertools
import math
from collections import deque
from collections.abc import Hashable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import networkx as nx
import numpy as np

from assemblykit import formatting as fmt
from assemblykit.algebra import (
    Chain,
    Coset,
    EmptySet,
    Kind,
    Locus,
    LocusKind,
    Mismatch,
    MismatchKind,
    SymmetryGroup,
    congruence_mismatch,
    intersect_groups,
    se3,
    transform_invariant,
)
from assemblykit.algebra.invariants import (
    DirectionInvariant,
    Invariant,
    LineInvariant,
    PlaneInvariant,
    PointInvariant,
    frame_invariants,
)
from assemblykit.collector import collector_paused
from assemblykit.inference.conflicts import without_conflicts
from assemblykit.inference.loops import (
    Circle,
    LoopPoses,
    circle_circle,
    circle_gap,
    foot,
    loop_reach,
    point_loop,
    rotation_about,
)
from assemblykit.inference.network import (
    WORLD,
    LineOnPlane,
    Link,
    Network,
    PointLocus,
    build_network,
    instance_key,
    meet_loci,
    point_coset,
)
from assemblykit.inference.numeric import (
    Constraint,
    Node,
    ResidueProblem,
    solve_residue,
)
from assemblykit.inference.products import chain_product, extend
from assemblykit.inference.solution import (
    MECHANISM,
    BodyInstanceResult,
    BranchCut,
    Conflict,
    Mechanism,
    Solution,
    TraceStep,
    freedom_words,
    remedy_words,
    unsigned_axes,
)
from assemblykit.model.relations import line_normals, signed_angle
from assemblykit.model.task import Task
from assemblykit.tolerance import (
    MAX_ANGLE,
    MAX_REL_LENGTH,
    ROUNDING_MARGIN,
    ModelTolerance,
    Tolerance,
    current,
    using,
)

CYCLE_LENGTH = 4  # Corner et al. 1983 §III F: "we restrict the size of the cycles ... to four"

_EYE = np.eye(4)
_EYE.flags.writeable = False  # shared by every find() of a representative

GroupEvent = tuple[int, int, int, str] | tuple[int, EmptySet]
"""One step of intersecting the parallel links of a group: ``(index, dof before, dof
after, kind)`` for an intersection with link ``index``, ``(index, empty)`` for a
conflict (the link is then skipped)."""


def _kind_name(value: Any) -> str:
    """The Hervé family of a coset's group, named as the solve JSON's motions."""
    return str(value.kind)


def _components(value: Any) -> int | None:
    """Number of components, ``None`` for infinitely many (a lattice)."""
    n = value.n_components
    return None if n is None or (isinstance(n, float) and math.isinf(n)) else int(n)


def _is_finite_branch(value: Any) -> bool:
    n = _components(value)
    return value.dof == 0 and n is not None and n > 1


@dataclass
class _Edge:
    """A live link between two representative instances: ``inv(L_source) @ L_target``."""

    source: Node
    target: Node
    value: Any
    labels: tuple[str, ...]

    def oriented(self, source: Node) -> Any:
        """The set of ``inv(L_source) @ L_other`` seen from ``source``."""
        return self.value if source == self.source else self.value.inverse()


@dataclass
class Reducer:
    """The state of one reduction: merged instances, live links, conflicts and trace."""

    tol: ModelTolerance
    parent: dict[Node, tuple[Node, np.ndarray]] = field(default_factory=dict)
    edges: dict[frozenset[Node], _Edge] = field(default_factory=dict)
    adjacency: dict[Node, set[Node]] = field(default_factory=dict)
    conflicts: list[Conflict] = field(default_factory=list)
    trace: list[TraceStep] = field(default_factory=list)
    pending: deque[tuple[Node, Node, Any, tuple[str, ...]]] = field(default_factory=deque)
    merges: deque[frozenset[Node]] = field(default_factory=deque)
    loops: list[list[list[tuple[frozenset[Node], Node, np.ndarray]]]] = field(default_factory=list)
    deferred: set[frozenset[Node]] = field(default_factory=set)
    merged_by: dict[Node, tuple[Node, tuple[str, ...]]] = field(default_factory=dict)

    def copy(self) -> Reducer:
        """An independent copy for branching (link values are immutable)."""
        return Reducer(
            self.tol,
            dict(self.parent),
            {k: _Edge(e.source, e.target, e.value, e.labels) for k, e in self.edges.items()},
            {k: set(v) for k, v in self.adjacency.items()},
            list(self.conflicts),
            list(self.trace),
            deque(self.pending),
            deque(self.merges),
            list(self.loops),
            set(self.deferred),
            dict(self.merged_by),
        )

    def find(self, node: Node) -> tuple[Node, np.ndarray]:
        """The representative of ``node`` and ``X`` with ``L_node = L_rep @ X``."""
        if node not in self.parent:
            return node, _EYE
        path = []
        transform = _EYE
        while node in self.parent:
            path.append(node)
            up, step = self.parent[node]
            transform = step @ transform
            node = up
        if len(path) > 1:  # path compression keeps later finds short
            acc = np.eye(4)
            for member in reversed(path):
                acc = acc @ self.parent[member][1]
                self.parent[member] = (node, acc)
        return node, transform

    def add(self, link: Link) -> None:
        """Queue a link of the network (a relation that is empty by itself is a conflict)."""
        if isinstance(link.value, EmptySet):
            self._record_conflict(link.labels, link.value)
            return
        self.pending.append((link.source, link.target, link.value, link.labels))

    def add_parallel(
        self, links: Sequence[Link], cache: dict[Hashable, tuple[Any, list[GroupEvent], int]]
    ) -> None:
        """Queue the links between one pair of instances as one link (rule 1 applied on
        input): their cosets intersected in order, each intersection traced and each
        empty one recorded as a conflict, as if they were inserted one by one.

        ``cache`` maps the links' keys (their geometry in body coordinates) to the result,
        so a repeated part (a stack of equal cubes) costs one intersection in all."""
        valid = [link for link in links if not isinstance(link.value, EmptySet)]
        cosets = [link.value for link in links if isinstance(link.value, Coset)]
        for link in links:
            if isinstance(link.value, EmptySet):
                self.add(link)
        if not valid:
            return
        head = valid[0]
        if len(valid) == 1 or any(coset.group.lattice for coset in cosets):
            for link in valid:
                self.add(link)
            return
        forward = [link.source == head.source for link in valid]
        keys = tuple(zip((link.key for link in valid), forward, strict=True))
        cached = cache.get(keys) if all(k is not None for k, _ in keys) else None
        if cached is None:
            cached = _intersect_parallel(
                [
                    coset if same else coset.inverse()
                    for coset, same in zip(cosets, forward, strict=True)
                ],
                self.tol,
            )
            if all(k is not None for k, _ in keys):
                cache[keys] = cached
        value, events, used = cached
        labels = head.labels
        text = f"{instance_key(head.source)} -> {instance_key(head.target)}"
        for event in events:
            extra = valid[event[0]].labels
            if len(event) == 2:
                self._record_conflict(labels + extra, event[1])
                continue
            _, before, after, kind = event
            names = "; ".join(dict.fromkeys(labels + extra))
            self.trace.append(TraceStep("intersect", f"{text} [{names}]", before, after, kind))
            labels = labels + extra
        self.pending.append((head.source, head.target, value, labels))
        for link in valid[used:]:
            self.add(link)

    def _record_conflict(self, labels: tuple[str, ...], empty: Any) -> None:
        mismatch = empty.mismatch
        self.conflicts.append(
            Conflict.measured(
                tuple(dict.fromkeys(labels)),
                str(mismatch.kind),
                float(mismatch.value),
                str(mismatch.message),
                self.tol,
            )
        )

    def _insert(self, source: Node, target: Node, value: Any, labels: tuple[str, ...]) -> None:
        rs, a = self.find(source)
        rt, b = self.find(target)
        if rs != source:
            value = value.left(a)
        if rt != target:
            value = value.right(se3.inverse(b))
        if rs == rt:
            if not value.contains(np.eye(4)):
                check = meet(value, point_coset(np.eye(4)), self.tol)
                if isinstance(check, EmptySet):
                    self._record_conflict(labels, check)
            return
        key = frozenset((rs, rt))
        edge = self.edges.get(key)
        if edge is None:
            self.edges[key] = _Edge(rs, rt, value, labels)
            self.adjacency.setdefault(rs, set()).add(rt)
            self.adjacency.setdefault(rt, set()).add(rs)
            if value.is_point:
                self.merges.append(key)
            return
        incoming = value if edge.source == rs else value.inverse()
        if edge.value.group.lattice or incoming.group.lattice:
            # lattices are flagged, not intersected: the pair is left to the residue
            self.deferred.add(key)
            self.trace.append(TraceStep("lattice", self._edge_text(edge, labels), 0, 0, "kept"))
            return
        result = meet(edge.value, incoming, self.tol)
        if isinstance(result, EmptySet):
            self._record_conflict(edge.labels + labels, result)
            return
        self.trace.append(
            TraceStep(
                "intersect",
                self._edge_text(edge, labels),
                min(edge.value.dof, incoming.dof),
                result.dof,
                _kind_name(result),
            )
        )
        edge.value = result
        edge.labels = edge.labels + labels
        if result.is_point:
            self.merges.append(key)

    def _edge_text(self, edge: _Edge, extra: tuple[str, ...] = ()) -> str:
        names = "; ".join(dict.fromkeys(edge.labels + extra))
        return f"{instance_key(edge.source)} -> {instance_key(edge.target)} [{names}]"

    def _merge(self, key: frozenset[Node]) -> None:
        edge = self.edges.get(key)
        if edge is None or not edge.value.is_point:
            return
        x = edge.value.rep  # a point coset is {I}·x0
        keep, gone = edge.source, edge.target
        if gone == WORLD or (
            keep != WORLD and len(self.adjacency[keep]) < len(self.adjacency[gone])
        ):
            keep, gone, x = gone, keep, se3.inverse(x)
        del self.edges[key]
        self.adjacency[keep].discard(gone)
        self.adjacency[gone].discard(keep)
        self.parent[gone] = (keep, x)
        self.merged_by[gone] = (keep, edge.labels)
        offset = np.round(x[:3, 3], 9).tolist()
        self.trace.append(
            TraceStep(
                "merge",
                self._edge_text(edge),
                0,
                0,
                f"{instance_key(gone)} fixed relative to {instance_key(keep)}, offset {offset}",
            )
        )
        for other in self.adjacency.pop(gone, set()):
            moved = self.edges.pop(frozenset((gone, other)))
            self.adjacency[other].discard(gone)
            self.pending.appendleft((moved.source, moved.target, moved.value, moved.labels))

    def settle(self) -> None:
        """Apply intersections and merges until neither applies (rules 1 and 2).

        Merges go first, so later relations meet instances already merged into the world
        and cost a membership test instead of an intersection."""
        while self.pending or self.merges:
            if self.merges:
                self._merge(self.merges.popleft())
            else:
                self._insert(*self.pending.popleft())

    def branch_choice(self) -> list[list[tuple[frozenset[Node], Node, np.ndarray]]] | None:
        """Alternatives to branch on (rule 3): the points of a finite link, or the
        assembly modes of a closed loop; each alternative sets links to single points."""
        if self.loops:
            return self.loops.pop()
        for key, edge in self.edges.items():
            if _is_finite_branch(edge.value):
                return [[(key, edge.source, np.asarray(p))] for p in edge.value.points()]
        return None

    def choose(self, alternative: list[tuple[frozenset[Node], Node, np.ndarray]]) -> None:
        """Set links to single points (one branch of rule 3)."""
        for key, source, point in alternative:
            edge = self.edges[key]
            value = point_coset(point)
            edge.value = value if source == edge.source else value.inverse()
            self.trace.append(TraceStep("branch", self._edge_text(edge), 0, 0, "one point"))
            self.merges.append(key)

    def links(self, among: set[Node] | None = None) -> Iterator[tuple[Node, Node]]:
        """The two ends of each live link (only those between nodes of ``among`` if given)."""
        for key in self.edges:
            if among is None or key <= among:
                first, second = key
                yield first, second

    def cycles(self) -> Iterator[list[Node]]:
        """Cycles of 3 or 4 live links (rule 4)."""
        graph: nx.Graph[Node] = nx.Graph(list(self.links()))
        return (c for c in nx.simple_cycles(graph, length_bound=CYCLE_LENGTH) if len(c) >= 3)

    def reduce_cycle(self, cycle: list[Node]) -> bool:
        """Chain all links of ``cycle`` but one and intersect with it; True on progress."""
        n = len(cycle)
        if any(
            self.edges[frozenset((cycle[k], cycle[k - 1]))].value.group.lattice for k in range(n)
        ):
            return False  # lattices are not chained (rule 3: flagged, left to the residue)
        for start in range(n):
            a, b = cycle[start], cycle[(start + 1) % n]
            closing = self.edges[frozenset((a, b))]
            path = [cycle[(start - k) % n] for k in range(n)]  # a, then around to b
            chained = self._chain(path)
            direct = closing.oriented(a)
            labels = tuple(
                label
                for k in range(n - 1)
                for label in self.edges[frozenset((path[k], path[k + 1]))].labels
            )
            if isinstance(chained, Coset):
                result = meet(direct, chained, self.tol)
                if isinstance(result, EmptySet):
                    self._record_conflict(closing.labels + labels, result)
                    return True
                if _progress(direct, result):
                    self._replace(closing, a, result, labels, "chain")
                    return True
            elif n == 3:
                closed = revolute_loop(
                    self.edges[frozenset((path[0], path[1]))].oriented(path[0]),
                    self.edges[frozenset((path[1], path[2]))].oriented(path[1]),
                    direct,
                    self.tol,
                )
                if closed is not None:
                    return self._apply_loop(closing, path, *closed, labels)
                for way in (path, path[::-1]):  # the revolute may come first either way
                    solved = point_loop(
                        self.edges[frozenset((way[0], way[1]))].oriented(way[0]),
                        self.edges[frozenset((way[1], way[2]))].oriented(way[1]),
                        closing.oriented(way[0]),
                        self.tol,
                    )
                    if solved is not None:
                        return self._apply_point_loop(closing, way, solved, labels)
        return self._check_reach(cycle)

    def _chain(self, path: list[Node]) -> Any:
        """The product of the links along ``path`` (a Coset, or a Chain when not a coset:
        :func:`chain_product`)."""
        links = [
            self.edges[frozenset((path[k], path[k + 1]))].oriented(path[k])
            for k in range(len(path) - 1)
        ]
        return chain_product(links, self.tol)

    def _replace(
        self, closing: _Edge, source: Node, value: Any, labels: tuple[str, ...], rule: str
    ) -> None:
        before = closing.value.dof
        oriented = value if source == closing.source else value.inverse()
        closing.value = oriented
        closing.labels = tuple(dict.fromkeys(closing.labels + labels))
        self.trace.append(
            TraceStep(rule, self._edge_text(closing), before, oriented.dof, _kind_name(oriented))
        )
        if oriented.is_point:
            self.merges.append(frozenset((closing.source, closing.target)))

    def _apply_loop(
        self,
        closing: _Edge,
        path: list[Node],
        points: list[tuple[np.ndarray, np.ndarray]],
        gap: float,
        labels: tuple[str, ...],
    ) -> bool:
        """Record the closed-form loop answer: no point is a conflict (of size ``gap``, the
        distance between the joint circles), one or two points become a branch over the
        assembly modes (each sets both links to a point)."""
        if not points:
            self.conflicts.append(
                Conflict.measured(
                    tuple(dict.fromkeys(closing.labels + labels)),
                    "loop",
                    gap,
                    "the two revolute joints cannot close the loop (the joint circles miss"
                    f" by {gap:.6g})",
                    self.tol,
                )
            )
            return True
        self.trace.append(
            TraceStep(
                "loop",
                self._edge_text(closing, labels),
                closing.value.dof,
                0,
                f"revolute-revolute closure, {fmt.count(len(points), 'point')}",
            )
        )
        first_key = frozenset((path[0], path[1]))
        close_key = frozenset((path[0], path[-1]))
        self.loops.append([[(first_key, path[0], p), (close_key, path[0], q)] for p, q in points])
        return True

    def _apply_point_loop(
        self, closing: _Edge, path: list[Node], solved: LoopPoses, labels: tuple[str, ...]
    ) -> bool:
        """Record a point-orbit loop answer (:func:`point_loop`): no pose is a conflict;
        otherwise a branch over the poses of the first link, whose merge leaves the rest of
        the loop to rule 1."""
        first_key = frozenset((path[0], path[1]))
        names = tuple(dict.fromkeys(closing.labels + labels))
        if not solved.poses:
            self.conflicts.append(
                Conflict.measured(
                    names,
                    "loop",
                    solved.gap,
                    f"the loop cannot close ({solved.pattern}: the joint point's circle"
                    f" misses its orbit under the closing link by {solved.gap:.6g})",
                    self.tol,
                )
            )
            return True
        self.trace.append(
            TraceStep(
                f"chain-solve {solved.pattern}",
                self._edge_text(self.edges[first_key], labels + closing.labels),
                self.edges[first_key].value.dof,
                0,
                fmt.count(len(solved.poses), "point"),
            )
        )
        self.loops.append([[(first_key, path[0], p)] for p in solved.poses])
        return True

    def _check_reach(self, cycle: list[Node]) -> bool:
        """The reach bound of a cycle no rule closes (:func:`loop_reach`): when one body
        spans more between its parallel joint axes than the others together, by more than
        the length tolerance, the loop cannot close and the cycle is a ``loop`` conflict
        whose value is by how much it stays open. True on a conflict."""
        keys = [frozenset((cycle[i], cycle[(i + 1) % len(cycle)])) for i in range(len(cycle))]
        reach = loop_reach(
            [self.edges[key].oriented(node) for key, node in zip(keys, cycle, strict=True)],
            self.tol,
        )
        if reach is None or reach.gap <= self.tol.length:
            return False
        widest = reach.longest
        spans = ", ".join(
            f"{instance_key(node)} {span:.6g}"
            for node, span in zip(cycle, reach.spans, strict=True)
        )
        self.conflicts.append(
            Conflict.measured(
                tuple(dict.fromkeys(label for key in keys for label in self.edges[key].labels)),
                "loop",
                reach.gap,
                "the loop cannot close (its joint axes are parallel and"
                f" {instance_key(cycle[widest])} spans {reach.spans[widest]:.6g} between"
                f" its joints, more than the others together by {reach.gap:.6g}; spans:"
                f" {spans})",
                self.tol,
            )
        )
        return True

    def run(self) -> None:
        """Rules 1-2 to a fixpoint, then cycles (rule 4) while they make progress."""
        self.settle()
        while not self.loops and not self.conflicts and not self._has_finite():
            if not any(self.reduce_cycle(c) for c in self.cycles()):
                return
            self.settle()

    def _has_finite(self) -> bool:
        return any(_is_finite_branch(e.value) for e in self.edges.values())


def _intersect_parallel(
    values: list[Any], tol: ModelTolerance
) -> tuple[Any, list[GroupEvent], int]:
    """Intersect the cosets of parallel links in order (rule 1); an empty intersection is
    an event and leaves the value as it was (later links still meet it). Stops at a
    lattice, which is flagged rather than intersected: returns how many values were used."""
    value = values[0]
    events: list[GroupEvent] = []
    for index, incoming in enumerate(values[1:], start=1):
        if value.group.lattice:
            return value, events, index
        result = meet(value, incoming, tol)
        if isinstance(result, EmptySet):
            events.append((index, result))
            continue
        events.append((index, min(value.dof, incoming.dof), result.dof, _kind_name(result)))
        value = result
    return value, events, len(values)


def _parallel_groups(links: Sequence[Link]) -> list[list[Link]]:
    """The links grouped by their unordered pair of instances, in order of appearance."""
    groups: dict[frozenset[Node], list[Link]] = {}
    for link in links:
        groups.setdefault(frozenset((link.source, link.target)), []).append(link)
    return list(groups.values())


_NOUNS = {
    PointInvariant: "points",
    LineInvariant: "axes",
    PlaneInvariant: "planes",
    DirectionInvariant: "directions",
}
"""What the relations' invariants are called in a conflict's words (docs/algebra.md §2.4,
the characteristic invariants of each family)."""


def _invariant_miss(first: Invariant, second: Invariant, tol: ModelTolerance) -> Mismatch | None:
    """The mismatch between two invariants of one type that should coincide: the angle
    between their directions, else the distance between the planes, axes or points."""
    noun = _NOUNS[type(first)]
    ua = getattr(first, "normal", getattr(first, "direction", None))
    ub = getattr(second, "normal", getattr(second, "direction", None))
    if ua is not None and ub is not None:
        angle = math.atan2(float(np.linalg.norm(np.cross(ua, ub))), float(ua @ ub))
        if angle > tol.angle:
            text = f"angle mismatch {math.degrees(angle):.6g}° between the {noun}"
            return Mismatch(MismatchKind.ANGLE, angle, text)
    if not isinstance(first, PointInvariant | LineInvariant | PlaneInvariant):
        return None
    assert isinstance(second, PointInvariant | LineInvariant | PlaneInvariant)
    gap = second.point - first.point
    if isinstance(first, PlaneInvariant):
        distance = abs(float(first.normal @ gap))
    elif isinstance(first, LineInvariant):
        distance = float(np.linalg.norm(gap - (gap @ first.direction) * first.direction))
    else:
        distance = float(np.linalg.norm(gap))
    if distance <= tol.length:
        return None
    text = f"distance mismatch {distance:.6g} between the {noun}"
    return Mismatch(MismatchKind.DISTANCE, distance, text)


def _point_mismatch(value: Coset, x: np.ndarray, tol: ModelTolerance) -> Mismatch | None:
    """Why the pose ``x`` is not in the coset H·x0 of a relation, in the words of the
    relation's own features: x ∈ H·x0 exactly when x carries the body-2 objects x0⁻¹·I
    onto the body-1 objects I that H keeps (its characteristic invariants, docs/algebra.md
    §2.4-§2.5), so the mismatch is between I and x·x0⁻¹·I ("distance mismatch 5 between
    the planes"). None for a group with no such objects (helical, discrete parts)."""
    group = value.group
    if not (group.is_connected and group.is_tr) or group.kind == Kind.FIXED:
        return None
    carry = x @ value.rep_inverse
    for target in frame_invariants(group.kind, group.frame):
        found = _invariant_miss(target, transform_invariant(carry, target), tol)
        if found is not None:
            return found
    return None


_FIRST = {LineInvariant: 0, PlaneInvariant: 1, DirectionInvariant: 2, PointInvariant: 3}
"""The order in which a conflict's words compare invariants: the axes and planes the
relations name before the points where they meet (docs/algebra.md §2.4)."""


def _features_mismatch(
    first: Coset, second: Coset, found: Mismatch, tol: ModelTolerance
) -> Mismatch:
    """The mismatch ``found`` between two cosets of connected TR groups said, when it can
    be, between the axes or planes of the relations rather than a point where they meet
    (the marked point of a revolute pair): the congruence tests of docs/algebra.md §2.5
    taken with the lines and planes first; the same kind and size, or ``found``."""
    targets: list[Invariant] = []
    sources: list[Invariant] = []
    for value in (first, second):
        group = value.group
        if not (group.is_connected and group.is_tr) or group.kind == Kind.FIXED:
            return found
        own = frame_invariants(group.kind, group.frame)
        targets.extend(own)
        sources.extend(transform_invariant(value.rep_inverse, i) for i in own)
    order = sorted(range(len(targets)), key=lambda i: _FIRST[type(targets[i])])
    again = congruence_mismatch([targets[i] for i in order], [sources[i] for i in order], tol)
    if (
        again is not None
        and again.kind == found.kind
        and math.isclose(again.value, found.value, rel_tol=1e-9, abs_tol=tol.length)
    ):
        return again
    return found


def meet(first: Any, second: Any, tol: ModelTolerance) -> Any:
    """``first ∩ second`` (docs/algebra.md §2.5); when it is empty the mismatch is said in
    the words of the relations' features: against a single pose (an instance merged, a
    fixed relation or action) by :func:`_point_mismatch`, else between their axes or
    planes where it can be (:func:`_features_mismatch`)."""
    result = first.intersect(second, tol)
    if not isinstance(result, EmptySet):
        return result
    for point, other in ((first, second), (second, first)):
        if isinstance(point, Coset) and point.is_point and isinstance(other, Coset):
            said = _point_mismatch(other, point.rep, tol)
            if said is not None:
                return EmptySet(said, result.proven)
    if (
        isinstance(first, Coset)
        and isinstance(second, Coset)
        and "point" in result.mismatch.message
    ):
        said = _features_mismatch(first, second, result.mismatch, tol)
        return EmptySet(said, result.proven)
    return result


def _progress(before: Any, after: Any) -> bool:
    """Whether a chained intersection removed freedom (dof, then number of components)."""
    if after.dof != before.dof:
        return bool(after.dof < before.dof)
    b, a = _components(before), _components(after)
    return a is not None and (b is None or a < b)


def _axis(value: Any) -> tuple[np.ndarray, np.ndarray] | None:
    """Axis point and unit direction of a revolute coset (world of its source)."""
    if _kind_name(value) != Kind.REVOLUTE or _components(value) != 1:
        return None
    return value.group.origin, value.group.axis


def revolute_loop(
    first: Any, second: Any, closing: Any, tol: ModelTolerance
) -> tuple[list[tuple[np.ndarray, np.ndarray]], float] | None:
    """Closed-form R·R ∩ R (docs/algebra.md §5.2 rule 4: "the orbit of a point under two
    revolutes gives circle-circle intersections").

    ``first`` (i→j), ``second`` (j→k) and ``closing`` (i→k) are revolute cosets with
    parallel axes. The joint point q on the j→k axis traces a circle under ``first``
    (in i's frame) and, carried by k, a circle under ``closing``; each common point fixes
    both angles. Returns the pairs ``(X_ij, X_ik)`` (0, 1 or 2) with, when there is none
    because the circles miss, the distance between them; None when the pattern does not
    apply (not three revolutes, non-parallel axes, or a continuum).
    """
    axes = [axis for v in (first, second, closing) if (axis := _axis(v)) is not None]
    if len(axes) < 3:
        return None
    (p1, u1), (p2, _), (p3, u3) = axes  # the joint axis point p2 is in j's frame
    x_first, x_close = first.rep, closing.rep
    q_world = x_first @ np.append(p2, 1.0)  # joint point at the first's representative
    # the joint point in k's frame is fixed by every pose of the second link (its axis
    # passes through it); the closing link carries it into i's frame
    q_in_k = (se3.inverse(second.rep) @ np.append(p2, 1.0))[:3]
    q0 = q_world[:3]
    q1 = (x_close @ np.append(q_in_k, 1.0))[:3]
    c1, c3 = foot(q0, p1, u1), foot(q1, p3, u3)
    if np.dot(u1, u3) < 0:
        u3 = -u3
    meets = circle_circle(
        Circle(c1, u1, float(np.linalg.norm(q0 - c1))),
        Circle(c3, u3, float(np.linalg.norm(q1 - c3))),
        tol,
    )
    if meets is None:
        return None
    if not meets:
        far = Locus(LocusKind.CIRCLE, point=c3, direction=u3, radius=float(np.linalg.norm(q1 - c3)))
        return [], circle_gap(Circle(c1, u1, float(np.linalg.norm(q0 - c1))), far)
    answers = []
    for point in meets:
        a1 = signed_angle(q0 - c1, point - c1, u1)
        a3 = signed_angle(q1 - c3, point - c3, u3)
        x_ij = rotation_about(p1, u1, a1) @ x_first
        x_ik = rotation_about(p3, u3, a3) @ x_close
        if second.contains(se3.inverse(x_ij) @ x_ik):
            answers.append((x_ij, x_ik))
    return answers, 0.0


@dataclass(frozen=True)
class _Instance:
    """What one leaf of the reduction says about one representative instance."""

    pose: np.ndarray
    dof: int
    motion: str
    solutions: int | None = 1
    alternatives: tuple[np.ndarray, ...] = ()
    invariants: Mapping[str, Any] = field(default_factory=dict)
    mechanism: str = ""


def _motion(value: Any) -> tuple[str, Mapping[str, Any]]:
    """Motion name and world invariants of a coset relative to the world (its group is
    in the world frame): axis ``point`` and ``direction``, ``normal``, ``center``, ``pitch``."""
    invariants = dict(value.group.invariants)
    if "axis" in invariants:
        invariants["direction"] = invariants.pop("axis")
    if _kind_name(value) == Kind.SPHERICAL:
        invariants["center"] = invariants.pop("point")
    return _kind_name(value), invariants


def explore(reducer: Reducer, max_branches: int) -> tuple[list[Reducer], int]:
    """Run the reduction, branching depth first on finite alternatives (rule 3).

    At most ``max_branches`` leaves are explored: a choice with more alternatives than
    there is room for follows only as many as fit (at least one). Returns the leaves and
    the number of alternatives not followed, so that a cut search says so in its answer.
    """
    reducer.run()
    leaves: list[Reducer] = []
    stack = [reducer]
    skipped = 0
    while stack:
        state = stack.pop()
        choice = None if state.conflicts else state.branch_choice()
        if choice is None:
            leaves.append(state)
            continue
        room = max(1, max_branches - len(leaves) - len(stack))
        if len(choice) > room:
            skipped += len(choice) - room
            choice = choice[:room]
        children = []
        for alternative in choice:
            child = state.copy()
            child.choose(alternative)
            child.run()
            children.append(child)
        stack.extend(reversed(children))
    return leaves, skipped


def _components_of(network: Network, reducer: Reducer) -> list[set[Node]]:
    """Connected groups of representatives (live links and general constraints)."""
    graph: nx.Graph[Node] = nx.Graph()
    graph.add_node(WORLD)
    for node in network.instances:
        graph.add_node(reducer.find(node)[0])
    graph.add_edges_from(reducer.links())
    for constraint in network.constraints:
        reps = [reducer.find(n)[0] for n in constraint.nodes]
        graph.add_edges_from(itertools.pairwise(reps))
    return [set(c) for c in nx.connected_components(graph)]


def _tree_sets(
    reducer: Reducer, component: set[Node], root: Node
) -> tuple[dict[Node, np.ndarray], dict[Node, Any]]:
    """Poses along a BFS tree from ``root`` and the chained set of each node relative to it.

    Each pose is the one of least motion its link allows: the pose as written (the
    identity) when the link holds there, the link's representative otherwise."""
    poses = {root: np.eye(4)}
    sets: dict[Node, Any] = {}
    tree: nx.Graph[Node] = nx.Graph()
    tree.add_nodes_from(component)
    tree.add_edges_from(reducer.links(component))
    for parent, child in nx.bfs_edges(tree, root):
        link = reducer.edges[frozenset((parent, child))].oriented(parent)
        as_written = link.contains(se3.inverse(poses[parent]), reducer.tol)
        poses[child] = np.eye(4) if as_written else poses[parent] @ link.rep
        sets[child] = extend(sets.get(parent), link, reducer.tol)
    return poses, sets


def _residue_constraints(
    network: Network, reducer: Reducer, component: set[Node]
) -> tuple[Constraint, ...]:
    """The original relations of a component, over the poses of the representatives."""
    out: list[Constraint] = []
    items = [network.link_constraint(link) for link in network.links]
    for constraint in (*items, *network.constraints):
        found = [reducer.find(n) for n in constraint.nodes]
        if not all(rep in component for rep, _ in found):
            continue
        reps = tuple(dict.fromkeys(rep for rep, _ in found))
        places = [reps.index(rep) for rep, _ in found]
        offsets = [x for _, x in found]

        def residual(
            poses: Sequence[np.ndarray],
            c: Constraint = constraint,
            places: list[int] = places,
            offsets: list[np.ndarray] = offsets,
        ) -> np.ndarray:
            return c.residual([poses[i] @ x for i, x in zip(places, offsets, strict=True)])

        out.append(Constraint(reps, residual, constraint.labels))
    return tuple(out)


def _solve_component(
    network: Network, reducer: Reducer, component: set[Node], tol: ModelTolerance, residue: bool
) -> tuple[dict[Node, _Instance], list[Conflict]]:
    """Rule 5 for one connected group of representatives; without ``residue`` what only
    the residue solver would answer is left unanswered (a mechanism of unknown dof)."""
    if WORLD not in component:
        root = min(component)
        poses, _ = _tree_sets(reducer, component, root)
        return {n: _Instance(poses.get(n, np.eye(4)), 6, "free") for n in component}, []
    poses, sets = _tree_sets(reducer, component, WORLD)
    constrained = any(
        all(reducer.find(n)[0] in component for n in c.nodes) for c in network.constraints
    )
    tree_like = (
        len(poses) == len(component)
        and sum(1 for k in reducer.edges if k <= component) == len(component) - 1
        and not any(k <= component for k in reducer.deferred)
    )
    if (tree_like and not constrained) or reducer.conflicts:
        # a tree of links needs no residue: each instance moves in the product of the
        # links from the world (a coset, or a chain of its generic dof); an inconsistent
        # network is not solved further
        out = {WORLD: _Instance(np.eye(4), 0, Kind.FIXED)}
        for node in component - {WORLD}:
            value = sets.get(node)
            if isinstance(value, Coset):
                motion, invariants = _motion(value)
                out[node] = _Instance(
                    poses[node], value.dof, motion, _components(value), (), invariants
                )
            else:
                dof = value.dof if tree_like and isinstance(value, Chain) else 0
                out[node] = _Instance(poses.get(node, np.eye(4)), dof, MECHANISM)
        return out, []
    closed = _higher_pairs(network, reducer, component, tol)
    if closed is not None:
        return closed
    if not residue:
        out = {WORLD: _Instance(np.eye(4), 0, Kind.FIXED)}
        out.update((n, _Instance(poses.get(n, _EYE), 0, MECHANISM)) for n in component - {WORLD})
        return out, []
    return _numeric_component(network, reducer, component, poses, tol, candidates=sets)


def _higher_pairs(
    network: Network, reducer: Reducer, component: set[Node], tol: ModelTolerance
) -> tuple[dict[Node, _Instance], list[Conflict]] | None:
    """Rule 5 in closed form for a component whose instances hang from the world alone,
    each by at most one coset link and at most one higher pair (:func:`_point_in_locus`,
    :func:`_line_on_plane`), or by a line contact and a point (:func:`_line_and_point`).
    None when some instance does not fit that pattern (the residue solver takes it)."""
    if any(k <= component for k in reducer.deferred):
        return None
    nodes = component - {WORLD}
    own: dict[Node, list[Constraint]] = {n: [] for n in nodes}
    for constraint in network.constraints:
        reps = {reducer.find(n)[0] for n in constraint.nodes}
        if not reps <= component:
            continue
        closed = isinstance(constraint.geometry, PointLocus | LineOnPlane)
        if not closed or WORLD not in reps or len(reps) != 2:
            return None
        own[next(iter(reps - {WORLD}))].append(constraint)
    out = {WORLD: _Instance(np.eye(4), 0, Kind.FIXED)}
    conflicts: list[Conflict] = []
    for node in sorted(nodes):
        edge = reducer.edges.get(frozenset((WORLD, node)))
        value = None if edge is None else edge.oriented(WORLD)
        if reducer.adjacency.get(node, set()) - {WORLD} or len(own[node]) > 2:
            return None
        if not own[node]:
            if not isinstance(value, Coset):
                return None
            motion, invariants = _motion(value)
            pose = _EYE if value.contains(_EYE, tol) else np.asarray(value.rep)
            out[node] = _Instance(pose, value.dof, motion, _components(value), (), invariants)
            continue
        labels = tuple(label for c in own[node] for label in c.labels)
        labels = labels if edge is None else edge.labels + labels
        found = _held(reducer, node, own[node], value, labels, tol)
        if found is None:
            return None
        out[node], miss = found
        conflicts.extend(miss)
    return out, conflicts


def _trace_held(
    reducer: Reducer,
    node: Node,
    labels: tuple[str, ...],
    before: int,
    after: int,
    detail: str,
) -> None:
    """Record in the trace a higher pair of ``node`` solved from the world in closed form
    (docs/algebra.md §3): dof ``before`` and ``after``."""
    reducer.trace.append(
        TraceStep(
            "higher-pair",
            f"world -> {instance_key(node)} [{'; '.join(labels)}]",
            before,
            after,
            detail,
        )
    )


def _held(
    reducer: Reducer,
    node: Node,
    pairs: list[Constraint],
    value: Coset | None,
    labels: tuple[str, ...],
    tol: ModelTolerance,
) -> tuple[_Instance, list[Conflict]] | None:
    """The closed form for one instance's higher pairs from the world: one point or line
    contact (with at most one coset ``value``), or a line contact and a point with no
    coset; None otherwise."""
    lines = [c for c in pairs if isinstance(c.geometry, LineOnPlane)]
    if len(pairs) == 1:
        solve = _line_on_plane if lines else _point_in_locus
        return solve(reducer, node, pairs[0], value, labels, tol)
    if len(lines) != 1 or value is not None:
        return None
    point = next(c for c in pairs if c is not lines[0])
    return _line_and_point(reducer, node, lines[0], point, labels, tol)


def _point_in_locus(
    reducer: Reducer,
    node: Node,
    constraint: Constraint,
    value: Coset | None,
    labels: tuple[str, ...],
    tol: ModelTolerance,
    subject: str = "point",
) -> tuple[_Instance, list[Conflict]] | None:
    """A point held in a world locus (a plane or a line, :class:`PointLocus`), alone or
    with a planar coset G(m)·x0 from the world, in closed form (docs/algebra.md §3, §5.3).

    The pose kept is the one of least motion: the pose as written (the identity, or the
    coset's representative when the identity is not in it) moved by the shortest
    translation that puts the point c on its locus (no arbitrary turn).

    * Alone: the poses Tr(locus)·S(c), a plane (5 dof) or a line (4 dof): not a coset,
      the mechanism is named with its locus as invariants.
    * With a coset H·x0 whose rotations keep the locus normals' components (a cylinder
      or revolute along a plane's normal, a prismatic pair, translations): a coset,
      :func:`_coset_meets_locus` (a peg in a hole resting on a floor: a revolute).
    * With G(m)·x0 otherwise: c moves in the plane Π through x0·c normal to m; the locus
      meets Π in a point Q (the revolute coset R(Q, m)·x1, 1 dof), a line (slide along it
      and turn about m through c: 2 dof, not a coset) or nothing (a distance conflict).

    ``subject`` names the point in the trace and conflicts (a line's point stands for
    the line, :func:`_line_with_coset`). None when the pattern does not apply."""
    geometry = constraint.geometry
    point_rep, point_x = reducer.find(geometry.point_node)
    locus_rep, locus_x = reducer.find(geometry.locus_node)
    if (point_rep, locus_rep) != (node, WORLD):
        return None
    corner = se3.apply(point_x, geometry.point)
    origin = se3.apply(locus_x, geometry.origin)
    rows = geometry.rows @ locus_x[:3, :3].T
    base = _EYE
    if value is not None:
        if _components(value) != 1:
            return None
        base = _EYE if value.contains(_EYE, tol) else np.asarray(value.rep, dtype=np.float64)
        reached = se3.apply(base, corner)
        met: Any = _coset_meets_locus(value.group, reached, origin, rows, tol)
        if isinstance(met, Coset):
            met = Coset(met.group, met.rep @ base)
            motion, invariants = _motion(met)
            found = _Instance(met.rep, met.dof, motion, 1, (), invariants)
            _trace_held(
                reducer,
                node,
                labels,
                value.dof,
                met.dof,
                f"the {subject}'s locus meets its orbit under the joint: {motion}",
            )
            return found, []
        if met is None and value.group.kind == Kind.PLANAR:
            met = meet_loci(origin, rows, [(value.group.axis, reached)], tol)
        if met is None:
            return None
        if isinstance(met, float):
            message = _PARALLEL_MISS.format(subject)
            miss = Conflict.measured(labels, "distance", met, message, tol)
            return _Instance(base, 0, MECHANISM, 0), [miss]
        origin, rows = met
    elif len(rows) == 3:
        return None
    reached = se3.apply(base, corner)
    target = reached - rows.T @ (rows @ (reached - origin))
    pose = se3.translation(target - reached) @ base
    if value is not None and len(rows) == 3:
        motion, invariants = _motion(Coset(SymmetryGroup.revolute(target, value.group.axis), pose))
        found = _Instance(pose, 1, motion, 1, (), invariants)
    elif value is not None:
        m = value.group.axis
        invariants = {"normal": m, "direction": np.cross(rows[0], rows[1]) + 0.0, "point": target}
        found = _Instance(pose, 2, MECHANISM, 1, (), invariants, Mechanism.PLANAR_POINT_ON_LINE)
    elif len(rows) == 1:
        invariants = {"normal": rows[0], "point": target}
        found = _Instance(pose, 5, MECHANISM, 1, (), invariants, Mechanism.POINT_IN_PLANE)
    else:
        invariants = {"direction": np.cross(rows[0], rows[1]) + 0.0, "point": target}
        found = _Instance(pose, 4, MECHANISM, 1, (), invariants, Mechanism.POINT_ON_LINE)
    _trace_held(
        reducer,
        node,
        labels,
        6 if value is None else value.dof,
        found.dof,
        f"the {subject}'s loci meet in {_LOCI[len(rows)]}",
    )
    return found, []


def _lay_line(
    point: np.ndarray,
    along: np.ndarray,
    normal: np.ndarray,
    origin: np.ndarray,
    tol: ModelTolerance,
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The pose of least motion laying the line through ``point`` along ``along`` parallel
    to the plane ``normal · (y − origin) = 0``, with the line's point and direction there.

    The smallest rotation turns a onto the plane (about n × a through the line's point),
    then the line moves straight along the normal n onto the plane. None for a line along
    the normal (no smallest rotation)."""
    flat = along - (along @ normal) * normal
    if np.linalg.norm(flat) <= tol.angle:
        return None
    flat = flat / np.linalg.norm(flat)
    turn = np.cross(along, flat)
    sine = float(np.linalg.norm(turn))
    pose = _EYE
    if sine > tol.angle:
        pose = rotation_about(point, turn / sine, math.atan2(sine, float(along @ flat)))
    pose = se3.translation(-float(normal @ (point - origin)) * normal) @ pose
    return pose, se3.apply(pose, point), flat


def _line_in_world(
    reducer: Reducer, geometry: LineOnPlane
) -> tuple[Node, Node, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The representatives of a line contact's two instances, with its line's point and
    direction and its plane's normal and origin in their representatives' frames."""
    line_rep, line_x = reducer.find(geometry.line_node)
    plane_rep, plane_x = reducer.find(geometry.plane_node)
    return (
        line_rep,
        plane_rep,
        se3.apply(line_x, geometry.point),
        line_x[:3, :3] @ geometry.direction,
        plane_x[:3, :3] @ geometry.normal,
        se3.apply(plane_x, geometry.origin),
    )


def _line_on_plane(
    reducer: Reducer,
    node: Node,
    constraint: Constraint,
    value: Coset | None,
    labels: tuple[str, ...],
    tol: ModelTolerance,
) -> tuple[_Instance, list[Conflict]] | None:
    """A line of an instance lying parallel to a world plane at a distance (a cylinder on a
    plane, an edge on a face: :class:`LineOnPlane`) in closed form (docs/algebra.md §3).

    Alone, the poses form a 4-dof double coset, not a coset: slide in the plane, turn
    about its normal and about the line; the pose kept is :func:`_lay_line`'s. With a
    coset from the world, :func:`_line_with_coset`. None for a line along the normal or
    on the world."""
    if value is not None:
        return _line_with_coset(reducer, node, constraint, value, labels, tol)
    line_rep, plane_rep, point, along, normal, origin = _line_in_world(reducer, constraint.geometry)
    if (line_rep, plane_rep) != (node, WORLD):
        return None
    laid = _lay_line(point, along, normal, origin, tol)
    if laid is None:
        return None
    pose, placed, flat = laid
    invariants = {"normal": normal, "direction": flat, "point": placed}
    found = _Instance(pose, 4, MECHANISM, 1, (), invariants, Mechanism.LINE_ON_PLANE)
    _trace_held(reducer, node, labels, 6, 4, "a line parallel to a plane at its distance")
    return found, []


def _line_with_coset(
    reducer: Reducer,
    node: Node,
    constraint: Constraint,
    value: Coset,
    labels: tuple[str, ...],
    tol: ModelTolerance,
) -> tuple[_Instance, list[Conflict]] | None:
    """A line contact met with a lower pair H·x0 from the world, in closed form (docs/algebra.md
    §3, §5.3), when every rotation of H keeps the plane's normal n or the line's direction
    a (H in X(n) or in X(a)).

    Then the angle between the line and the plane is the same over the whole coset: not
    zero, the pair cannot lie flat (an ``angle`` conflict). Zero, every pose of H carries
    the line to a line parallel to the plane whose height is the height of its point q;
    the line contact is the point q held in the plane, and :func:`_point_in_locus` meets it
    with H: a coset (a cylinder coaxial with a bearing at the right height: the
    ``cylindrical`` pair, the line contact redundant; a box on a table with its edge on
    the table: ``planar``), a ``distance`` conflict (the bearing at another height), or,
    with a planar pair along a (a roller or a box edge on a table with its end face
    against a wall), the 2-dof ``roll-and-slide``: turn about the line and slide it
    across itself in the plane, not a coset (the two generate the planar group). None
    when H turns both the normal and the line (the residue solver takes it)."""
    geometry = constraint.geometry
    line_rep, plane_rep, _, along, normal, _ = _line_in_world(reducer, geometry)
    if (line_rep, plane_rep) != (node, WORLD) or _components(value) != 1:
        return None
    base = _EYE if value.contains(_EYE, tol) else np.asarray(value.rep, dtype=np.float64)
    along = base[:3, :3] @ along
    if not any(
        SymmetryGroup.schoenflies(kept).includes(value.group, tol) for kept in (normal, along)
    ):
        return None
    tilt = abs(float(along @ normal))
    if tilt > tol.angle:
        angle = math.asin(min(tilt, 1.0))
        miss = Conflict.measured(
            labels,
            "angle",
            angle,
            f"the joint keeps the line at {math.degrees(angle):.6g} degrees to the plane it"
            " should lie parallel to",
            tol,
        )
        return _Instance(base, 0, MECHANISM, 0), [miss]
    held = PointLocus(
        geometry.line_node,
        geometry.point,
        geometry.plane_node,
        geometry.origin,
        geometry.normal.reshape(1, 3),
    )
    found = _point_in_locus(
        reducer, node, replace(constraint, geometry=held), value, labels, tol, "line point"
    )
    if found is None or found[0].mechanism != Mechanism.PLANAR_POINT_ON_LINE:
        return found
    instance, _ = found
    invariants = {"point": instance.invariants["point"], "direction": along, "normal": normal}
    return replace(instance, invariants=invariants, mechanism=Mechanism.ROLL_AND_SLIDE), []


def _line_and_point(
    reducer: Reducer,
    node: Node,
    line: Constraint,
    point: Constraint,
    labels: tuple[str, ...],
    tol: ModelTolerance,
) -> tuple[_Instance, list[Conflict]] | None:
    """A line contact and a point of the same instance held in a parallel world plane (a
    roller on a table with a lever's tip on the table), in closed form (docs/algebra.md §3).

    The line laid by :func:`_lay_line` can still turn about itself: the point c, at a
    distance ρ from the line, then rises by ρ·cos(φ − φ₀) above the line's plane, which
    must be the height h of its own plane: φ = φ₀ ± arccos(h/ρ), two rolls (one when
    |h| = ρ, the point grazing its plane). After the roll every pose that keeps both
    heights is a slide in the plane and a turn about its normal: the ``planar`` coset
    G(n) through the roll of least angle (3 dof, the number of rolls as its solutions).
    The point farther than ρ from its plane is a ``distance`` conflict of |h| − ρ; on the
    line it adds nothing or misses by |h|. None for a plane not parallel to the line's
    (the residue solver takes it) or instances other than this one and the world."""
    geometry, spot = line.geometry, point.geometry
    line_rep, plane_rep, start, along, normal, origin = _line_in_world(reducer, geometry)
    point_rep, point_x = reducer.find(spot.point_node)
    locus_rep, locus_x = reducer.find(spot.locus_node)
    rows = spot.rows @ locus_x[:3, :3].T
    if (line_rep, plane_rep, point_rep, locus_rep) != (node, WORLD, node, WORLD) or len(rows) != 1:
        return None
    laid = _lay_line(start, along, normal, origin, tol)
    if laid is None or np.linalg.norm(np.cross(rows[0], normal)) > tol.angle:
        return None
    pose, placed, flat = laid
    arm = se3.apply(pose, se3.apply(point_x, spot.point)) - placed
    arm = arm - (arm @ flat) * flat
    reach = float(np.linalg.norm(arm))
    height = float(normal @ (se3.apply(locus_x, spot.origin) - origin))
    gap = abs(height) - reach
    if gap > tol.length:
        message = (
            f"the point turns about the line at {reach:.6g} from it, and its plane is"
            f" {abs(height):.6g} from the line's"
        )
        return _Instance(pose, 0, MECHANISM, 0), [
            Conflict.measured(labels, "distance", gap, message, tol)
        ]
    if reach <= tol.length:
        return _line_on_plane(reducer, node, line, None, labels, tol)
    level = math.atan2(float(normal @ np.cross(flat, arm)), float(normal @ arm))
    spread = math.acos(min(1.0, max(-1.0, height / reach)))
    rolls = [math.remainder(level + sign * spread, math.tau) for sign in (1, -1)]
    roll = min(rolls, key=abs)
    met = Coset(SymmetryGroup.planar(normal), rotation_about(placed, flat, roll) @ pose)
    motion, invariants = _motion(met)
    count = 1 if reach * math.sin(spread) <= tol.length else 2
    _trace_held(
        reducer,
        node,
        labels,
        6,
        3,
        f"a line and a point on parallel planes: {fmt.count(count, 'roll')} about the line,"
        f" {motion}",
    )
    return _Instance(met.rep, 3, motion, count, (), invariants), []


def _coset_meets_locus(
    group: SymmetryGroup,
    reached: np.ndarray,
    origin: np.ndarray,
    rows: np.ndarray,
    tol: ModelTolerance,
) -> Coset | float | None:
    """The members h of a connected ``group`` that put the point at ``reached`` into the
    locus ``rows @ (y - origin) = 0`` (a plane or a line), when they form a coset.

    When every rotation of the group keeps the locus normals' components (the group lies
    in X(n) for a plane of normal n, in T3 for a line), h ↦ N·(h·q − q) is N·t_h, a
    homomorphism: its fibres are cosets of its kernel, the group met with G(n) (a plane)
    or T(d) (a line along d), docs/algebra.md §2.4. The fibre reached is K·Tr(t) with t the
    shortest translation of the group onto the locus (least motion); a locus the
    translations cannot reach is missed by that distance (returned as a float). None
    when the group turns the normals or screws (a fibre that is not a coset, or a helical
    coupling), for the residue solver or another closed form.

    The map is a homomorphism too when every rotation of the group fixes the point (a
    revolute, cylindrical or spherical group about an axis or centre through it): h·q − q
    is then h's slide along the group's translations, which its rotations keep; the
    kernel is the whole group when those slides keep N·y, else the group met with S(q)
    (a cylinder crossing the locus: the revolute about its axis)."""
    helical = {Kind.HELICAL, Kind.PSEUDO_PLANAR}
    keeping = SymmetryGroup.schoenflies(rows[0]) if len(rows) == 1 else SymmetryGroup.translation3()
    kept = keeping.includes(group, tol)
    if len(rows) == 3 or not (kept or _fixes(group, reached, tol)):
        return None
    shifts = _translations(intersect_groups(group, SymmetryGroup.translation3(), tol))
    if kept:
        kernel_of = (
            SymmetryGroup.planar(rows[0])
            if len(rows) == 1
            else SymmetryGroup.prismatic(np.cross(rows[0], rows[1]))
        )
    elif np.abs(rows @ shifts.T).max(initial=0.0) <= tol.angle:
        kernel_of = group
    else:
        kernel_of = SymmetryGroup.spherical(reached)
    need = rows @ (origin - reached)
    step = np.zeros(3)
    if len(shifts):
        solved = np.linalg.lstsq(rows @ shifts.T, need, rcond=tol.precision)[0]
        step = shifts.T @ solved
    miss = float(np.linalg.norm(rows @ step - need))
    if miss > tol.length:
        return None if group.kind in helical else miss
    return Coset(intersect_groups(group, kernel_of, tol), se3.translation(step))


def _fixes(group: SymmetryGroup, point: np.ndarray, tol: ModelTolerance) -> bool:
    """Whether every rotation of a connected ``group`` fixes ``point``: a revolute or
    cylindrical group whose axis passes through it, a spherical group centred on it."""
    kind = group.kind
    if kind == Kind.SPHERICAL:
        return bool(np.linalg.norm(point - group.origin) <= tol.length)
    if kind not in (Kind.REVOLUTE, Kind.CYLINDRICAL):
        return False
    offset = point - group.origin
    return bool(np.linalg.norm(offset - (offset @ group.axis) * group.axis) <= tol.length)


def _translations(group: SymmetryGroup) -> np.ndarray:
    """Orthonormal rows spanning a translation group (fixed, prismatic, T2 or T3)."""
    kind = group.kind
    if kind == Kind.PRISMATIC:
        return group.axis.reshape(1, 3)
    if kind == Kind.TRANSLATION2:
        return line_normals(group.axis)
    return np.eye(3) if kind == Kind.TRANSLATION3 else np.zeros((0, 3))


_LOCI = {1: "a plane", 2: "a line", 3: "a point"}

_PARALLEL_MISS = "the {}'s orbit under its joint runs parallel to its locus, at a distance"


def _numeric_component(
    network: Network,
    reducer: Reducer,
    component: set[Node],
    start: Mapping[Node, np.ndarray],
    tol: ModelTolerance,
    starts: int = 8,
    candidates: Mapping[Node, Any] | None = None,
) -> tuple[dict[Node, _Instance], list[Conflict]]:
    """The residue of one component, solved numerically (Corner et al. 1983 §III G).

    An instance's feasible set lies inside its direct link from the world and inside the
    product along its tree path (``candidates``); when one of those is a coset of the
    dof measured at the solution, the instance moves in (an open part of) that coset and
    takes its motion and invariants; otherwise its motion is ``mechanism``.
    """
    unknowns = tuple(sorted(n for n in component if n != WORLD))
    constraints = _residue_constraints(network, reducer, component)
    problem = ResidueProblem(
        unknowns,
        {n: start.get(n, np.eye(4)) for n in unknowns},
        {WORLD: np.eye(4)},
        constraints,
    )
    result = solve_residue(problem, tol, starts=starts)
    # before: the freedom each instance has along its chain of links from the world
    before = sum(getattr((candidates or {}).get(n), "dof", 6) for n in unknowns)
    reducer.trace.append(
        TraceStep(
            "residue",
            ", ".join(instance_key(n) for n in unknowns),
            before,
            result.solutions[0].total_dof if result.found else None,
            f"{fmt.count(len(result.solutions), 'solution')},"
            f" best residual {result.best_residual:.3g}",
        )
    )
    out = {WORLD: _Instance(np.eye(4), 0, Kind.FIXED)}
    if not result.found:
        labels = tuple(dict.fromkeys(lb for c in constraints for lb in c.labels))
        conflict = Conflict.measured(
            labels,
            "residual",
            result.best_residual,
            f"no solution found numerically (best residual {result.best_residual:.3g});"
            " this is not a proof that none exists",
            tol,
        )
        for n in unknowns:
            out[n] = _Instance(np.asarray(problem.start[n]), 0, MECHANISM, 0)
        return out, [conflict]
    first = result.solutions[0]
    isolated = first.total_dof == 0
    for n in unknowns:
        dof = first.dof[n]
        motion = Kind.FIXED if dof == 0 else MECHANISM
        invariants: Mapping[str, Any] = {}
        link = reducer.edges.get(frozenset((WORLD, n)))
        options = [link.oriented(WORLD) if link else None, (candidates or {}).get(n)]
        match = next(
            (c for c in options if isinstance(c, Coset) and dof > 0 and c.dof == dof), None
        )
        if match is not None:
            motion, invariants = _motion(match)
        alternatives = tuple(s.poses[n] for s in result.solutions[1:]) if isolated else ()
        out[n] = _Instance(
            first.poses[n],
            dof,
            motion,
            len(result.solutions) if isolated else 1,
            alternatives,
            invariants,
        )
    return out, []


def _ends(network: Network) -> dict[str, list[Node]]:
    """The instances each statement's links and constraints join, by label."""
    ends: dict[str, list[Node]] = {}
    for link in network.links:
        for label in link.labels:
            ends.setdefault(label, []).extend((link.source, link.target))
    for constraint in network.constraints:
        for label in constraint.labels:
            ends.setdefault(label, []).extend(constraint.nodes)
    return ends


def _support(
    labels: tuple[str, ...], ends: Mapping[str, list[Node]], reducer: Reducer
) -> tuple[str, ...]:
    """The statements a conflict between ``labels`` was derived from: those labels, and
    for every instance they join, the statements of each merge on its way to its
    representative (a ``fixed`` relation, a body left in place, an action), and so on
    for the instances those join (docs/inference.md, "Conflicts")."""
    found = dict.fromkeys(labels)
    work = list(labels)
    while work:
        for node in ends.get(work.pop(), ()):
            while node in reducer.merged_by:
                node, why = reducer.merged_by[node]
                for label in why:
                    if label not in found:
                        found[label] = None
                        work.append(label)
    return tuple(found)


def _leaf_report(
    network: Network, reducer: Reducer, tol: ModelTolerance, residue: bool = True
) -> tuple[dict[Node, _Instance], list[Conflict]]:
    """Rule 5: every representative's pose set, then every instance through its merge.
    Each conflict carries the statements it was derived from (:func:`_support`)."""
    reps: dict[Node, _Instance] = {}
    conflicts = list(reducer.conflicts)
    for component in _components_of(network, reducer):
        found, extra = _solve_component(network, reducer, component, tol, residue)
        reps.update(found)
        conflicts.extend(extra)
    if conflicts:
        ends = _ends(network)
        conflicts = [replace(c, support=_support(c.relations, ends, reducer)) for c in conflicts]
    out = {}
    for node in network.instances:
        rep, x = reducer.find(node)
        base = reps[rep]
        out[node] = _Instance(
            base.pose @ x,
            base.dof,
            base.motion,
            base.solutions,
            tuple(a @ x for a in base.alternatives),
            base.invariants,
            base.mechanism,
        )
    return out, conflicts


def _said(key: str, instance: _Instance) -> str:
    """The sentence saying what of ``key`` is free and which relations would remove it
    (empty when nothing is free)."""
    text = freedom_words(instance.motion, instance.dof, instance.invariants, instance.mechanism)
    if not text:
        return ""
    remedy = remedy_words(instance.motion, instance.mechanism, instance.invariants)
    return f"{key} {text}; {remedy}"


def _combine(
    network: Network,
    reports: list[tuple[dict[Node, _Instance], list[Conflict]]],
    tol: ModelTolerance,
) -> tuple[dict[str, BodyInstanceResult], list[Conflict]]:
    """Merge the answers of the consistent branches: distinct poses become alternatives."""
    consistent = [r for r in reports if not r[1]] or reports[:1]
    bodies: dict[str, BodyInstanceResult] = {}
    for situation in network.situations:
        for body in network.bodies:
            node = network.node(body, situation)
            if node == WORLD:
                bodies[f"{body}@{situation}"] = BodyInstanceResult(
                    body, situation, np.eye(4), 0, Kind.FIXED
                )
                continue
            first = consistent[0][0][node]
            first = replace(first, invariants=unsigned_axes(first.invariants))
            poses: list[np.ndarray] = []
            for report, _ in consistent:
                item = report[node]
                for pose in (item.pose, *item.alternatives):
                    if not any(se3.poses_equal(pose, p, tol, numeric=True) for p in poses):
                        poses.append(pose)
            count = first.solutions
            if count is not None and first.dof == 0:
                count = max(len(poses), count)
            bodies[f"{body}@{situation}"] = BodyInstanceResult(
                body,
                situation,
                first.pose,
                first.dof,
                first.motion,
                count,
                tuple(poses[1:]) if first.dof == 0 and count is not None else (),
                first.invariants,
                _said(f"{body}@{situation}", first),
                first.mechanism,
            )
    return bodies, consistent[0][1]


MAX_BRANCHES = 64
"""Default number of branches (finite alternatives, assembly modes) followed to the end;
an answer whose search was cut says how many alternatives it did not follow."""


def solve_network(
    network: Network,
    tol: Tolerance | None = None,
    explain: bool = False,
    max_branches: int = MAX_BRANCHES,
    residue: bool = True,
) -> Solution:
    """Reduce a network (rules 1-4), then report every instance (rule 5); without
    ``residue`` the residue solver is not called (what it would answer stays unknown:
    the reduction's own conflicts and closed forms only). ``tol`` (default: the one in
    force) is taken as the network's own (:class:`~assemblykit.tolerance.ModelTolerance`)."""
    tol = ModelTolerance.of(tol or current())
    root = Reducer(tol)
    cache: dict[Hashable, tuple[Any, list[GroupEvent], int]] = {}
    for group in _parallel_groups(network.links):
        root.add_parallel(group, cache)
    leaves, skipped = explore(root, max_branches)
    reports = [_leaf_report(network, leaf, tol, residue) for leaf in leaves]
    bodies, conflicts = _combine(network, reports, tol)
    trace = tuple(dict.fromkeys(step for leaf in leaves for step in leaf.trace))
    free = tuple(
        TraceStep("free", key, b.dof, b.dof, b.freedom) for key, b in bodies.items() if b.freedom
    )
    cut = BranchCut(len(leaves), skipped, max_branches) if skipped else None
    return Solution(bodies, tuple(conflicts), trace + free, explain, cut)


_EXTENTS = ("radius", "size", "major_radius", "minor_radius")
"""Feature lengths that reach out from the feature's origin (a pin of radius 5 at the
origin is a model of size 10, not 0)."""


def model_scale(task: Task) -> float:
    """Bounding-box diagonal of all feature origins, each grown by its feature's radius or
    size (the length scale of the tolerances)."""
    low, high = [], []
    for body in task.bodies.values():
        for f in body.features.values():
            origin = np.asarray(f.point if hasattr(f, "point") else f.frame()[:3, 3], float)
            reach = sum(float(getattr(f, name, 0.0) or 0.0) for name in _EXTENTS)
            low.append(origin - reach)
            high.append(origin + reach)
    if not low:
        return 1.0
    diagonal = float(np.linalg.norm(np.max(high, axis=0) - np.min(low, axis=0)))
    return diagonal if diagonal > 0 else 1.0


def task_tolerance(task: Task, tol: Tolerance | None = None) -> ModelTolerance:
    """The tolerance ``task`` is solved with: ``tol`` (default: the one in force) scaled to
    :func:`model_scale`, its length and angle raised to :data:`ROUNDING_MARGIN` times
    the rounding of the numbers its file wrote (:attr:`Task.rounding`; docs/inference.md,
    "Tolerances and rounded numbers"), as a mesh's tolerance is raised to its measured
    precision."""
    policy = (tol or current()).with_scale(model_scale(task))
    written = task.rounding
    return replace(
        ModelTolerance.of(policy),
        rel_length=min(
            max(policy.rel_length, ROUNDING_MARGIN * written.length / policy.scale),
            MAX_REL_LENGTH,
        ),
        angle=min(max(policy.angle, ROUNDING_MARGIN * written.angle), MAX_ANGLE),
    )


def solve_task(
    task: Task,
    tol: Tolerance | None = None,
    explain: bool = False,
    max_branches: int | None = None,
) -> Solution:
    """RAPT inference on a task: poses of every body in every situation (Corner et al. 1983 §III).

    A conflict names every statement that takes part and nothing else, and the poses of
    an inconsistent task are those without its conflicts' statements
    (:mod:`assemblykit.inference.conflicts`). ``max_branches`` (default
    :data:`MAX_BRANCHES`) bounds the finite alternatives followed (rule 3); a cut search
    is reported in :attr:`Solution.cut`."""
    tol = task_tolerance(task, tol)
    branches = max_branches or MAX_BRANCHES

    def solve(part: Task, residue: bool = True) -> Solution:
        return solve_network(build_network(part), tol, explain, branches, residue)

    with using(tol), collector_paused():
        solution = solve(task.validate())
        if solution.conflicts:
            solution = without_conflicts(task, solution, solve, tol)
    return replace(solution, units=task.units)


def solve_numeric_only(task: Task, tol: Tolerance | None = None, starts: int = 8) -> Solution:
    """The whole network solved by the residue solver alone, without reduction (the
    "equation solving" system Corner et al. 1983 §III G compares against; used for benchmarks)."""
    tol = ModelTolerance.of((tol or current()).with_scale(model_scale(task)))
    with using(tol):
        network = build_network(task.validate())
        reducer = Reducer(tol)
        component = {WORLD, *network.instances}
        reps, conflicts = _numeric_component(network, reducer, component, {}, tol, starts)
        bodies, conflicts = _combine(network, [(reps, conflicts)], tol)
        return Solution(bodies, tuple(conflicts), tuple(reducer.trace))
