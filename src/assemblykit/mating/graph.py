"""Step one of the assembly constraint satisfaction process (seed 002): the two-layer
constraint graph and node consistency.

* The **top layer** has the bodies as nodes and the goals as arcs (the dual of the
  constraint graph); here each goal is a node joined to its two bodies.
* The **bottom layer** has the compound features as nodes and the candidate mating
  pairs as arcs, each labelled with its symmetry constraint (the common group) and the
  relative position of the two bodies (seed 002 eqs (1)-(3)).
* A candidate pair is two compound features of the goal's bodies that are complementary
  (seed 003 Prop. 3.1.5): their primitives pair up one to one (plane against plane,
  shaft in hole, ball in socket, ...), the intersection of the pairs' relation cosets is
  not empty, and its group is the group of the second compound (conjugate groups).
* **Node consistency**: when the relative position is determined (identity, or a finite
  common group: one candidate per position), the two meshes are checked for interference
  (seed 002: the *intersect* predicate of PADL2; here manifold3d volumes).
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, replace

import networkx as nx
import numpy as np

from assemblykit.algebra import Coset, EmptySet, SymmetryGroup
from assemblykit.features import (
    Ball,
    Cone,
    Feature,
    Hole,
    Plane,
    Prism,
    Relationship,
    Shaft,
    Socket,
    Thread,
    relationship,
)
from assemblykit.features.compound import compound_group
from assemblykit.geometry.interference import interferes
from assemblykit.io.meshes import placed
from assemblykit.mating.problem import Goal, MatingBody, MatingProblem
from assemblykit.model.relations import relation_coset
from assemblykit.tolerance import Tolerance

#: Rarity of primitive feature types (seed 002 step one: threads, gears and cylinders are
#: matched first because surfaces with given parameters are rare). Higher is rarer.
RARITY: Mapping[type[Feature], int] = {
    Thread: 4,
    Prism: 3,
    Cone: 2,
    Shaft: 2,
    Hole: 2,
    Ball: 1,
    Socket: 1,
    Plane: 0,
}


@dataclass(frozen=True, eq=False)
class Candidate:
    """A candidate mating pair of a goal: compound ``first`` of the goal's first body with
    compound ``second`` of its second body, the primitive ``pairing`` (feature names), the
    relative position ``coset`` (X = L_second⁻¹·L_first, seed 002 eq. (3)), the number of
    equivalent ``copies`` it stands for (equivalent feature law), the non-sharable
    features it ``uses`` as (body, feature), and its ``priority`` (rarity)."""

    goal: Goal
    first: str
    second: str
    pairing: tuple[tuple[str, str], ...]
    coset: Coset
    uses: frozenset[tuple[str, str]]
    priority: int
    copies: int = 1

    @property
    def determined(self) -> bool:
        """Whether the relative position is a single transform."""
        return self.coset.is_point

    def with_copies(self, copies: int) -> Candidate:
        """The same pair standing for ``copies`` equivalent ones."""
        return replace(self, copies=copies)

    def describe(self) -> str:
        """Seed 002's form ``[fit [b1 comp1] [b4 comp13]]``."""
        g = self.goal
        return f"[{g.relation} [{g.first} {self.first}] [{g.second} {self.second}]]"


Domains = dict[int, tuple[Candidate, ...]]
"""The domain of each goal (by goal number): its remaining candidates."""


def matable(a: Feature, b: Feature, tol: Tolerance) -> str | None:
    """The relation by which primitive ``a`` mates with ``b``: ``against`` for two planes,
    ``fits`` for complementary features (seed 003 Def. 3.1.2), else ``None``."""
    if isinstance(a, Plane) and isinstance(b, Plane):
        return "against"
    return "fits" if relationship(a, b, tol) is Relationship.COMPLEMENTARY else None


def pairings(
    first: Sequence[Feature], second: Sequence[Feature], tol: Tolerance
) -> Iterator[tuple[tuple[int, int, str], ...]]:
    """Every one-to-one pairing of two primitive lists in which each pair mates:
    tuples of (index in first, index in second, relation)."""
    if len(first) != len(second):
        return
    kinds = [[matable(a, b, tol) for b in second] for a in first]
    for order in itertools.permutations(range(len(second))):
        if all(kinds[i][j] for i, j in enumerate(order)):
            yield tuple((i, j, kinds[i][j]) for i, j in enumerate(order))  # type: ignore[misc]


def pair_coset(
    first: Sequence[Feature],
    second: Sequence[Feature],
    pairing: Sequence[tuple[int, int, str]],
    tol: Tolerance,
) -> Coset | EmptySet:
    """The relative position allowed by all the paired primitives at once: the
    intersection of their relation cosets (seed 002 eq. (3), ALGEBRA.md §2.5)."""
    result: Coset | EmptySet | None = None
    for i, j, kind in pairing:
        step = relation_coset(kind, first[i], second[j], tol=tol)
        result = step if result is None else result.intersect(step, tol=tol)  # type: ignore[union-attr]
        if isinstance(result, EmptySet):
            return result
    assert result is not None
    return result


def _positions(coset: Coset) -> list[Coset]:
    """A finite set of positions split into single positions; other cosets as they are."""
    if coset.dof == 0 and not coset.group.lattice and coset.n_components > 1:
        return [Coset(SymmetryGroup.identity(), p) for p in coset.points()]
    return [coset]


def goal_candidates(
    problem: MatingProblem, goal: Goal, groups: dict[tuple[str, str], SymmetryGroup]
) -> list[Candidate]:
    """All candidate mating pairs of ``goal`` (seed 002 step one; seed 003 Prop. 3.1.5);
    ``groups`` caches compound groups by (body, compound)."""
    tol = problem.tolerance
    a, b = problem.bodies[goal.first], problem.bodies[goal.second]
    found: list[Candidate] = []
    for (ca, fa), (cb, fb) in itertools.product(a.compounds.items(), b.compounds.items()):
        for pairing in pairings(fa.features, fb.features, tol):
            coset = pair_coset(fa.features, fb.features, pairing, tol)
            if isinstance(coset, EmptySet):
                continue
            if (b.name, cb) not in groups:
                groups[(b.name, cb)] = compound_group(fb.features, tol)
            if not coset.group.equals(groups[(b.name, cb)], tol):
                continue
            names = tuple((a.members[ca][i], b.members[cb][j]) for i, j, _ in pairing)
            uses = frozenset(
                {(a.name, x) for x, _ in names if x not in a.sharable}
                | {(b.name, y) for _, y in names if y not in b.sharable}
            )
            priority = max(RARITY.get(type(f), 0) for f in fa.features)
            found.extend(
                Candidate(goal, ca, cb, names, position, uses, priority)
                for position in _positions(coset)
            )
    found.sort(key=lambda c: -c.priority)
    return found


def interfering(
    first: MatingBody, second: MatingBody, relative: np.ndarray, tol: Tolerance
) -> bool:
    """Whether ``first`` placed at ``relative`` in ``second``'s frame shares a volume with
    ``second`` (mesh tolerance); bodies without meshes never interfere."""
    if first.mesh is None or second.mesh is None:
        return False
    return interferes(placed(first.mesh, relative), second.mesh, tol.for_mesh())


def node_consistent(problem: MatingProblem, candidate: Candidate) -> bool:
    """Node consistency (seed 002 step one): a candidate whose relative position is
    determined is kept only if the two bodies do not interfere there."""
    if not candidate.determined:
        return True
    g = candidate.goal
    return not interfering(
        problem.bodies[g.first], problem.bodies[g.second], candidate.coset.rep, problem.tolerance
    )


@dataclass(frozen=True, eq=False)
class ConstraintGraph:
    """The two-layer graph (seed 002 step one): ``top`` (bodies and goals, networkx
    ``Graph``), ``bottom`` (compound features joined by candidate pairs, ``MultiGraph``),
    and the ``initial`` and node-consistent ``domains`` of the goals."""

    top: nx.Graph
    bottom: nx.MultiGraph
    initial: Domains
    domains: Domains


def build_graph(problem: MatingProblem) -> ConstraintGraph:
    """Set up the two-layer graph with the candidate pairs of every goal and apply node
    consistency (seed 002 step one)."""
    top = nx.Graph()
    bottom = nx.MultiGraph()
    for body in problem.bodies.values():
        top.add_node(("body", body.name))
        bottom.add_nodes_from((body.name, c) for c in body.compounds)
    groups: dict[tuple[str, str], SymmetryGroup] = {}
    initial: Domains = {}
    domains: Domains = {}
    for goal in problem.goals:
        top.add_node(("goal", goal.number), goal=goal)
        top.add_edges_from((("goal", goal.number), ("body", b)) for b in (goal.first, goal.second))
        found = goal_candidates(problem, goal, groups)
        initial[goal.number] = tuple(found)
        kept = tuple(c for c in found if node_consistent(problem, c))
        domains[goal.number] = kept
        for c in kept:
            bottom.add_edge(
                (goal.first, c.first),
                (goal.second, c.second),
                goal=goal.number,
                group=c.coset.group,
                candidate=c,
            )
    return ConstraintGraph(top, bottom, initial, domains)
