"""The relational network of a RAPT task (Corner et al. 1983 §III, docs/algebra.md §5.2).

Nodes are **body instances** ``(body, situation)``: the pose of one body in one
situation. Fixed bodies are the world: all their instances are the one node
:data:`WORLD` (pose = identity). Links carry the set of relative poses
``X = inv(L_source) @ L_target``:

* a spatial relation ``[kind, first, second]`` within a situation links the second
  body's instance to the first's with the coset of its kind (the set of
  ``inv(L_second) @ L_first``, :class:`~assemblykit.model.relations.RelationType`);
  relations that are not cosets (point_on_plane, distance, gear, rack, mirror, ...)
  become general constraints (residual functions);
* an action between consecutive situations links the body's two instances
  (Corner et al. 1983 §III B: "f ** p2 = rel(v) ** f ** p1"): ``move b along f by s`` is the fixed
  transform F·Tr(0,0,s)·F⁻¹, ``along f`` without ``by`` the prismatic coset F·T(z)·F⁻¹,
  ``turn b about f by θ`` the fixed F·Rz(θ)·F⁻¹, without ``by`` the revolute coset
  F·R(z)·F⁻¹; a free ``move b`` adds no link;
* a body that no action of a transition moves keeps its pose: an identity link;
* the higher pairs holding one point of an instance in planes and lines of another are
  met first: in a single point they become a spherical coset link, otherwise one
  constraint carrying the met locus (:class:`PointLocus`) for the reduction's closed forms.

Every link also has a residual, so the whole network can be handed to the numeric
residue solver (:mod:`assemblykit.inference.numeric`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Hashable, MutableMapping, Sequence
from dataclasses import dataclass
from functools import partial
from typing import Any

import networkx as nx
import numpy as np

from assemblykit.algebra import Coset, EmptySet, Mismatch, MismatchKind, SymmetryGroup, se3
from assemblykit.errors import SchemaError
from assemblykit.features import Feature
from assemblykit.inference.joints import PointHold, line_joint, plane_joint
from assemblykit.inference.numeric import Constraint, Node, Residual
from assemblykit.model.relations import HeldLine, HeldPoint, Relation, RelationType
from assemblykit.model.task import Action, ActionKind, Situation, Task
from assemblykit.tolerance import ModelTolerance, current

WORLD: Node = ("world", "")


@dataclass(frozen=True)
class Link:
    """A coset link ``source → target``: ``inv(L_source) @ L_target`` lies in ``value``
    (an :class:`~assemblykit.algebra.cosets.EmptySet` when no pose satisfies it).

    ``labels`` name the relations or actions it came from; ``make_residual`` builds the
    same condition as a residual function of ``X``, only when the numeric path needs it.
    ``key`` describes the condition in body coordinates (relation kind, the features'
    geometry and options; or the fixed transform of an action): links with equal keys
    have equal values, which lets the reduction reuse intersections.
    """

    source: Node
    target: Node
    value: Coset | EmptySet
    labels: tuple[str, ...]
    make_residual: Callable[[], Callable[[np.ndarray], np.ndarray]]
    key: Hashable = None


@dataclass(frozen=True)
class Network:
    """Body instances, coset links, general constraints and the situation order."""

    instances: tuple[Node, ...]
    links: tuple[Link, ...]
    constraints: tuple[Constraint, ...]
    situations: tuple[str, ...]
    bodies: tuple[str, ...]
    fixed: frozenset[str]

    def node(self, body: str, situation: str) -> Node:
        """The node of a body instance (the world for a fixed body)."""
        return WORLD if body in self.fixed else (body, situation)

    def graph(self) -> nx.MultiGraph[Node]:
        """The undirected multigraph of instances and coset links (link index as key)."""
        graph: nx.MultiGraph[Node] = nx.MultiGraph()
        graph.add_node(WORLD)
        graph.add_nodes_from(self.instances)
        for index, link in enumerate(self.links):
            graph.add_edge(link.source, link.target, key=index)
        return graph

    def link_constraint(self, link: Link) -> Constraint:
        """The residual of a coset link over the world poses of its two ends."""
        residual = link.make_residual()
        return Constraint(
            (link.source, link.target),
            _between(residual),
            link.labels,
        )


def _between(relative: Callable[[np.ndarray], np.ndarray]) -> Residual:
    """A residual of X = inv(L_source)·L_target as one of the poses (L_source, L_target)."""
    return lambda poses: relative(se3.inverse(poses[0]) @ poses[1])


def _plain_value(value: Any) -> Hashable:
    """A hashable copy of a feature field (arrays become their shape and bytes)."""
    if isinstance(value, np.ndarray):
        return value.shape, value.tobytes()
    plain: Hashable = value
    return plain


def feature_key(feature: Feature) -> Hashable:
    """The type and geometry of a feature (every field but its name): features with equal
    keys have equal frames, groups and parameters."""
    return (
        type(feature),
        *(_plain_value(v) for k, v in vars(feature).items() if k != "name"),
    )


def point_key(pose: np.ndarray) -> Hashable:
    """The key of a fixed link (a single relative pose)."""
    return "point", _plain_value(np.asarray(pose, dtype=np.float64))


def point_coset(pose: np.ndarray) -> Coset:
    """The single relative pose ``pose`` as a coset of the identity group (a fix link)."""
    return Coset(SymmetryGroup.identity(), np.asarray(pose, dtype=np.float64))


def instance_key(node: Node) -> str:
    """``"<body>@<situation>"``, or ``"world"`` for the world."""
    return "world" if node == WORLD else f"{node[0]}@{node[1]}"


def relation_label(relation: Relation, situation: str) -> str:
    """A readable name of a relation with its place in the task file when known:
    ``"against block.bottom table.top @s1 (line 14)"``."""
    refs = " ".join(str(r) for r in relation.refs)
    place = f" ({relation.where})" if relation.where else ""
    return f"{relation.kind} {refs} @{situation}{place}"


def action_label(action: Action, situation: str) -> str:
    """A readable name of an action into ``situation`` with its place in the task file
    when known: ``"move plate plate.hole_1 by 30 @lifted (line 18)"``, a turn's angle in
    degrees as tasks write it (``"turn plate plate.hole_1 by 90 deg @s2"``)."""
    label = f"{action.kind} {action.body}"
    if action.ref is not None:
        label += f" {action.ref}"
    if action.by is not None and action.kind == ActionKind.TURN:
        label += f" by {math.degrees(action.by):.6g} deg"
    elif action.by is not None:
        label += f" by {action.by:g}"
    label += f" @{situation}"
    if action.where:
        label += f" ({action.where})"
    return label


def stationary_label(body: str, situation: str) -> str:
    """The name of the link that keeps a body no action moves into ``situation`` where it
    was (Corner et al. 1983 §II: a body not moved keeps its pose)."""
    return f"stationary {body} @{situation}"


def _fixed_residual(target: np.ndarray, scale: float) -> Callable[[np.ndarray], np.ndarray]:
    """Residual of ``X == target``: rotation entries (times the length ``scale``, the
    tolerance's arm, so every entry is a length, as in the relations' residuals) and
    translation."""

    def residual(x: np.ndarray) -> np.ndarray:
        rotation = (x[:3, :3] - target[:3, :3]).ravel() * scale
        return np.concatenate([rotation, x[:3, 3] - target[:3, 3]])

    return residual


def _axis_residual(
    frame: np.ndarray, rotate: bool, scale: float
) -> Callable[[np.ndarray], np.ndarray]:
    """Residual of ``X ∈ F·T(z)·F⁻¹`` (``rotate`` False) or ``X ∈ F·R(z)·F⁻¹`` (True):
    the axis kept (and, turning, its point fixed), or no rotation and no sideways shift."""
    origin, axis = frame[:3, 3], frame[:3, 2]

    def residual(x: np.ndarray) -> np.ndarray:
        if rotate:
            moved = x[:3, :3] @ origin + x[:3, 3] - origin
            return np.concatenate([(x[:3, :3] @ axis - axis) * scale, moved])
        t = x[:3, 3]
        rotation = (x[:3, :3] - np.eye(3)).ravel() * scale
        return np.concatenate([rotation, t - np.dot(t, axis) * axis])

    return residual


def _action_link(task: Task, action: Action, prev: Node, nxt: Node) -> Link | None:
    """The link ``prev → next`` of one action (Corner et al. 1983 §III B), or None for a free move.

    The feature's frame has +z along its axis or normal (docs/architecture.md,
    "Conventions"), so moving along it by ``s`` is F·Tr(0,0,s)·F⁻¹ and turning about it by θ
    is F·Rz(θ)·F⁻¹ in body coordinates.
    """
    ref = action.ref
    if ref is None:
        return None
    label = action_label(action, nxt[1])
    frame = np.asarray(task.feature(ref, action.where or label).frame(), dtype=np.float64)
    rotate = action.kind == ActionKind.TURN
    if action.by is None:
        group = (
            SymmetryGroup.revolute(frame[:3, 3], frame[:3, 2])
            if rotate
            else SymmetryGroup.prismatic(frame[:3, 2])
        )
        residual = partial(_axis_residual, frame, rotate, current().arm)
        key = (action.kind, _plain_value(frame))
        return Link(prev, nxt, Coset(group, np.eye(4)), (label,), residual, key)
    step = se3.rot_z(action.by) if rotate else se3.translation(np.array([0.0, 0.0, action.by]))
    target = frame @ step @ se3.inverse(frame)
    return Link(
        prev,
        nxt,
        point_coset(target),
        (label,),
        partial(_fixed_residual, target, current().arm),
        point_key(target),
    )


def _carrier(situation: Situation, pair: tuple[str, str], node: Callable[[str], Node]) -> Node:
    """The instance both bodies of a coupled relation are related to (the first in order):
    the carrier of a gear pair, the palm of a gripper."""
    related: dict[str, list[Node]] = {pair[0]: [], pair[1]: []}
    for relation in situation.relations:
        if relation.type.coupled:
            continue
        ends = [r.body for r in relation.refs]
        for here, there in (ends, ends[::-1]):
            if here in related and there not in pair:
                related[here].append(node(there))
    common = [n for n in related[pair[0]] if n in related[pair[1]]]
    if not common:
        raise SchemaError(
            f"{pair[0]} and {pair[1]} are coupled but no body is related to both"
            f" in situation {situation.name!r}"
        )
    return common[0]


def _coupled_constraint(
    task: Task,
    situation: Situation,
    relation: Relation,
    node: Callable[[str], Node],
    label: str,
    law: RelationType,
) -> Constraint:
    """A gear, rack or mirror relation as a general constraint over the world poses of its
    two bodies and their carrier (:meth:`RelationType.coupling`)."""
    where = relation.where or label
    first, second = (task.feature(r, where) for r in relation.refs)
    bodies = tuple(node(r.body) for r in relation.refs)
    carrier = _carrier(situation, (relation.refs[0].body, relation.refs[1].body), node)
    try:
        residual = law.coupling(first, second, law.values(relation.options), current())
    except SchemaError as error:
        raise SchemaError(error.detail, source=task.source, where=where) from None
    return Constraint((*bodies, carrier), residual, (label,))


@dataclass(frozen=True)
class PointLocus:
    """A point of one instance held in an affine locus of another (a higher pair).

    The point ``point`` (in ``point_node``'s body frame) satisfies ``rows @ (y - origin)
    = 0`` in ``locus_node``'s body frame: ``rows`` are orthonormal normals, one for a
    plane, two for a line, three for a single point (docs/algebra.md §3: the contact set of a
    point and a plane is Tr(plane)·S(point), not a coset)."""

    point_node: Node
    point: np.ndarray
    locus_node: Node
    origin: np.ndarray
    rows: np.ndarray

    @property
    def rank(self) -> int:
        """Number of independent equations: 1 plane, 2 line, 3 point."""
        return len(self.rows)


@dataclass(frozen=True)
class LineOnPlane:
    """A line of one instance lying parallel to a plane of another, at a signed distance
    along its normal (a cylinder on a plane: ``distance`` between a line and a plane).

    ``point`` and ``direction`` are in ``line_node``'s body frame, ``origin`` (already
    offset by the distance) and ``normal`` in ``plane_node``'s (docs/algebra.md §3: a double
    coset of dimension 3 + 2 − 1 = 4, not a coset)."""

    line_node: Node
    point: np.ndarray
    direction: np.ndarray
    plane_node: Node
    origin: np.ndarray
    normal: np.ndarray


def _placed(held: HeldPoint | HeldLine, first: Node, second: Node) -> PointLocus | LineOnPlane:
    """The geometry of a higher pair between the instances of its first and second
    features' bodies."""
    node, locus_node = (first, second) if held.on_first else (second, first)
    if isinstance(held, HeldLine):
        return LineOnPlane(node, held.point, held.direction, locus_node, held.origin, held.normal)
    return PointLocus(node, held.point, locus_node, held.origin, held.rows)


def meet_loci(
    origin: np.ndarray,
    rows: np.ndarray,
    extra: Sequence[tuple[np.ndarray, np.ndarray]],
    tol: ModelTolerance,
) -> tuple[np.ndarray, np.ndarray] | float:
    """The intersection of the affine locus ``rows @ (y - origin) = 0`` with the planes
    ``n @ (y - o) = 0`` of ``extra`` (unit normals ``n``), as ``(origin, rows)`` with
    orthonormal rows; or, when a plane parallel to the locus misses it, that distance.

    Each plane is met in turn: its normal's part across the current rows (larger than
    ``tol.angle``) becomes a new row and the origin steps along it onto the plane, so the
    origin keeps every earlier equation."""
    basis = [np.asarray(r, dtype=np.float64) for r in rows]
    point = np.asarray(origin, dtype=np.float64)
    for normal, through in extra:
        across = normal - sum((normal @ r) * r for r in basis)
        gap = float(normal @ (through - point))
        reach = float(np.linalg.norm(across))
        if reach <= tol.angle:
            if abs(gap) > tol.length:
                return abs(gap)
            continue
        point = point + gap / float(normal @ across) * across
        basis.append(across / reach)
    return point, np.array(basis).reshape(len(basis), 3)


def _incidences(
    constraint: Constraint, tol: ModelTolerance
) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The higher pair as points of the held body in planes of the other: ``(point,
    origin, normal)``. A point in a locus is its point in each plane of the locus; a line
    lying parallel to a plane at its distance is two of its points (a model size apart)
    in the offset plane."""
    geometry = constraint.geometry
    if isinstance(geometry, LineOnPlane):
        far = geometry.point + max(1.0, tol.scale) * geometry.direction
        return [(p, geometry.origin, geometry.normal) for p in (geometry.point, far)]
    return [(geometry.point, geometry.origin, row) for row in geometry.rows]


def _held_points(group: Sequence[Constraint], tol: ModelTolerance) -> list[PointHold] | float:
    """The distinct points a pair's higher pairs hold, each with the locus its planes
    meet in; or, when two planes of one point are parallel and apart, that distance."""
    points: list[np.ndarray] = []
    planes: list[list[tuple[np.ndarray, np.ndarray]]] = []
    for constraint in group:
        for point, origin, normal in _incidences(constraint, tol):
            for index, known in enumerate(points):
                if np.abs(known - point).max() <= tol.length:
                    planes[index].append((normal, origin))
                    break
            else:
                points.append(point)
                planes.append([(normal, origin)])
    held: list[PointHold] = []
    for point, its in zip(points, planes, strict=True):
        met = meet_loci(np.zeros(3), np.zeros((0, 3)), its, tol)
        if isinstance(met, float):
            return met
        held.append(PointHold(point, *met))
    return held


def _joint_link(group: Sequence[Constraint], tol: ModelTolerance) -> Link | None:
    """The coset link of the higher pairs between one pair of instances when they make a
    joint together (:mod:`assemblykit.inference.joints`: points on one line, points on
    parallel planes), or its conflict; None when they make none."""
    held = _held_points(group, tol)
    if isinstance(held, float) or len(held) < 2:
        return None
    found = line_joint(held, tol)
    if found is None and not any(isinstance(c.geometry, LineOnPlane) for c in group):
        found = plane_joint(held, tol)
    if found is None:
        return None
    pair = _pair_of(group[0])
    assert pair is not None
    target, source = pair
    value = EmptySet(found) if isinstance(found, Mismatch) else found
    labels = tuple(label for c in group for label in c.labels)
    return Link(source, target, value, labels, partial(_group_residual, tuple(group), source))


def _pair_of(constraint: Constraint) -> tuple[Node, Node] | None:
    """The (held, locus) instances of a higher pair between two instances, else None."""
    geometry = constraint.geometry
    if isinstance(geometry, PointLocus):
        pair = geometry.point_node, geometry.locus_node
    elif isinstance(geometry, LineOnPlane):
        pair = geometry.line_node, geometry.plane_node
    else:
        return None
    return None if pair[0] == pair[1] else pair


def _fold_joints(
    constraints: list[Constraint], tol: ModelTolerance
) -> tuple[list[Link], list[Constraint]]:
    """The higher pairs between each pair of instances that make a joint together,
    replaced by its coset link (:func:`_joint_link`); the others left as they are."""
    pairs: dict[tuple[Node, Node], list[Constraint]] = {}
    for constraint in constraints:
        pair = _pair_of(constraint)
        if pair is not None:
            pairs.setdefault(pair, []).append(constraint)
    links: list[Link] = []
    used: set[int] = set()
    for group in pairs.values():
        link = _joint_link(group, tol) if len(group) > 1 else None
        if link is not None:
            links.append(link)
            used.update(id(c) for c in group)
    return links, [c for c in constraints if id(c) not in used]


def _fold_point_loci(
    constraints: list[Constraint], tol: ModelTolerance
) -> tuple[list[Link], list[Constraint]]:
    """Higher pairs of one point met together (docs/algebra.md §3, §5.2 rule 1 for loci).

    First the higher pairs between one pair of instances that make a joint together
    become its coset link (:func:`_fold_joints`). Then the ``point_on_plane``,
    ``point_on_line`` and point-plane ``distance`` relations that
    hold the same point of one instance in loci of the same other instance are
    intersected in closed form: loci meeting in one point P make the coset
    S(P)·Tr(P − c) (a spherical link, as ``coincident``); loci missing each other make an
    empty link (a distance mismatch); a line or a plane stays one constraint carrying the
    met locus. Returns the new links and the remaining constraints."""
    links, constraints = _fold_joints(constraints, tol)
    pairs: dict[tuple[Node, Node], list[list[Constraint]]] = {}
    rest: list[Constraint] = []
    for constraint in constraints:
        geometry = constraint.geometry
        if not isinstance(geometry, PointLocus) or geometry.point_node == geometry.locus_node:
            rest.append(constraint)
            continue
        groups = pairs.setdefault((geometry.point_node, geometry.locus_node), [])
        for group in groups:
            if np.abs(group[0].geometry.point - geometry.point).max() <= tol.length:
                group.append(constraint)
                break
        else:
            groups.append([constraint])
    for group in (group for groups in pairs.values() for group in groups):
        head = group[0].geometry
        planes = [(row, c.geometry.origin) for c in group for row in c.geometry.rows]
        met = meet_loci(np.zeros(3), np.zeros((0, 3)), planes, tol)
        labels = tuple(label for c in group for label in c.labels)
        source, target = head.locus_node, head.point_node
        make = partial(_group_residual, tuple(group), source)
        if isinstance(met, float):
            miss = Mismatch(MismatchKind.DISTANCE, met, "the point's loci are parallel and apart")
            links.append(Link(source, target, EmptySet(miss), labels, make))
            continue
        origin, rows = met
        if len(rows) == 3:
            coset = Coset(SymmetryGroup.spherical(origin), se3.translation(origin - head.point))
            links.append(Link(source, target, coset, labels, make))
            continue
        located = PointLocus(target, head.point, source, origin, rows)
        residual = _group_residual(tuple(group), source)
        rest.append(
            Constraint(
                (source, target),
                _between(residual),
                labels,
                located,
            )
        )
    return links, rest


def _group_residual(
    group: tuple[Constraint, ...], source: Node
) -> Callable[[np.ndarray], np.ndarray]:
    """The residuals of ``group`` together, as a function of X = inv(L_source)·L_target."""
    eye = np.eye(4)

    def residual(x: np.ndarray) -> np.ndarray:
        return np.concatenate(
            [c.residual([eye, x] if c.nodes[0] == source else [x, eye]) for c in group]
        )

    return residual


def _memo_key(feature: Feature, memo: MutableMapping[Hashable, Any]) -> Hashable:
    """:func:`feature_key`, computed once per feature object of the task being built."""
    found = memo.get(id(feature))
    if found is None:
        found = memo[id(feature)] = feature_key(feature)
    return found


def _relation_part(
    task: Task,
    situation: Situation,
    relation: Relation,
    node: Callable[[str], Node],
    cosets: MutableMapping[Hashable, Any],
) -> Link | Constraint:
    """The link (coset relations) or constraint (all others) of one spatial relation.

    ``cosets`` caches the cosets of identical feature pairs with their option values (a
    stack of equal parts asks for the same coset once) and the keys of the task's
    features (by object id: the task holds them while the network is built)."""
    label = relation_label(relation, situation.name)
    law = relation.type
    if law.coupled:
        return _coupled_constraint(task, situation, relation, node, label, law)
    where = relation.where or label
    first_ref, second_ref = relation.refs[0], relation.refs[1]
    first, second = task.feature(first_ref, where), task.feature(second_ref, where)
    options = dict(relation.options or {})
    source, target = node(second_ref.body), node(first_ref.body)
    if not law.is_coset:
        values = law.values(options)
        held = law.geometry(first, second, values)
        return Constraint(
            (source, target),
            _between(law.residual(first, second, values, current())),
            (label,),
            None if held is None else _placed(held, target, source),
        )
    key = (
        relation.kind,
        _memo_key(first, cosets),
        _memo_key(second, cosets),
        tuple(sorted((k, _plain_value(v)) for k, v in options.items())),
    )
    found = cosets.get(key)
    if found is None:
        values = law.values(options)
        found = cosets[key] = (law.coset(first, second, values, current()), values)
    value, values = found
    make = partial(law.residual, first, second, values, current())
    return Link(source, target, value, (label,), make, key)


def build_network(task: Task) -> Network:
    """The relational network of a (validated) task: body instances and links (Corner et al. 1983
    §III)."""
    fixed = frozenset(name for name, body in task.bodies.items() if body.fixed)
    situations = tuple(s.name for s in task.situations)
    instances = tuple((b, s) for s in situations for b in task.bodies if b not in fixed)
    links: list[Link] = []
    constraints: list[Constraint] = []
    cosets: dict[Hashable, Any] = {}
    for index, situation in enumerate(task.situations):

        def node(body: str, name: str = situation.name) -> Node:
            return WORLD if body in fixed else (body, name)

        if index > 0:
            links.extend(_transition(task, situation, situations[index - 1], fixed))
        for relation in situation.relations:
            part = _relation_part(task, situation, relation, node, cosets)
            if isinstance(part, Link):
                links.append(part)
            else:
                constraints.append(part)
    folded, constraints = _fold_point_loci(constraints, ModelTolerance.of(current()))
    return Network(
        instances,
        (*links, *folded),
        tuple(constraints),
        situations,
        tuple(task.bodies),
        fixed,
    )


def _transition(
    task: Task, situation: Situation, previous: str, fixed: frozenset[str]
) -> list[Link]:
    """Action links into ``situation`` and identity links for the bodies left in place."""
    links: list[Link] = []
    moved = {action.body for action in situation.actions}
    for action in situation.actions:
        link = _action_link(task, action, (action.body, previous), (action.body, situation.name))
        if link is not None:
            links.append(link)
    for body in task.bodies:
        if body in fixed or body in moved:
            continue
        links.append(
            Link(
                (body, previous),
                (body, situation.name),
                point_coset(np.eye(4)),
                (stationary_label(body, situation.name),),
                partial(_fixed_residual, np.eye(4), current().arm),
                point_key(np.eye(4)),
            )
        )
    return links
