"""Step one of the assembly constraint satisfaction process (Liu & Popplestone 1990): the two-layer
constraint graph and node consistency.

* The **top layer** has the bodies as nodes and the goals as arcs (the dual of the
  constraint graph); here each goal is a node joined to its two bodies.
* The **bottom layer** has the compound features as nodes and the candidate mating
  pairs as arcs, each labelled with its symmetry constraint (the common group) and the
  relative position of the two bodies (Liu & Popplestone 1990 eqs (1)-(3)).
* A candidate pair is two compound features of the goal's bodies that are complementary
  (Liu 1997 Prop. 3.1.5): their primitives pair up one to one (plane against plane,
  shaft in hole, ball in socket, ...), the intersection of the pairs' relation cosets is
  not empty, and its group is the group of the second compound (conjugate groups).
* **Node consistency**: when the relative position is determined (identity; a common
  group equal to one body's symmetry group, which determines it up to that symmetry; or
  a finite common group: one candidate per position), the two meshes are checked for
  interference (Liu & Popplestone 1990: the *intersect* predicate of PADL2; here manifold3d
  volumes).
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
from assemblykit.geometry.solids import placed
from assemblykit.mating.problem import Goal, MatingBody, MatingProblem
from assemblykit.model.relations import relation_coset
from assemblykit.tolerance import ModelTolerance

#: Rarity of primitive feature types (Liu & Popplestone 1990 step one: threads, gears and cylinders
#: are matched first because surfaces with given parameters are rare). Higher is rarer.
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
    relative position ``coset`` (X = L_second⁻¹·L_first, Liu & Popplestone 1990 eq. (3)), the
    number of equivalent ``copies`` it stands for (equivalent feature law), the non-sharable
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
        """Liu & Popplestone's (1990) form ``[fit [b1 comp1] [b4 comp13]]``."""
        g = self.goal
        return f"[{g.relation} [{g.first} {self.first}] [{g.second} {self.second}]]"

    def words(self) -> str:
        """The pair as the commands print it, ``b1 comp1 fits b4 comp13`` (docs/mating.md,
        "Walk-through: Example 1 of Liu & Popplestone 1990")."""
        g = self.goal
        verb = "fits" if g.relation == "fit" else g.relation
        return f"{g.first} {self.first} {verb} {g.second} {self.second}"


Domains = dict[int, tuple[Candidate, ...]]
"""The domain of each goal (by goal number): its remaining candidates."""


def matable(a: Feature, b: Feature, tol: ModelTolerance) -> str | None:
    """The relation by which primitive ``a`` mates with ``b``: ``against`` for two planes,
    ``fits`` for complementary features (Liu 1997 Def. 3.1.2), else ``None``."""
    if isinstance(a, Plane) and isinstance(b, Plane):
        return "against"
    return "fits" if relationship(a, b, tol) is Relationship.COMPLEMENTARY else None


def pairings(
    first: Sequence[Feature],
    second: Sequence[Feature],
    tol: ModelTolerance,
    kinds: Sequence[Sequence[str | None]] | None = None,
) -> Iterator[tuple[tuple[int, int, str], ...]]:
    """Every one-to-one pairing of two primitive lists in which each pair mates:
    tuples of (index in first, index in second, relation). ``kinds[i][j]`` may give
    ``matable(first[i], second[j])`` already known."""
    if len(first) != len(second):
        return
    if kinds is None:
        kinds = [[matable(a, b, tol) for b in second] for a in first]
    for order in itertools.permutations(range(len(second))):
        pairing = tuple((i, j, kind) for i, j in enumerate(order) if (kind := kinds[i][j]))
        if len(pairing) == len(order):
            yield pairing


def pair_coset(
    first: Sequence[Feature],
    second: Sequence[Feature],
    pairing: Sequence[tuple[int, int, str]],
    tol: ModelTolerance,
) -> Coset | EmptySet:
    """The relative position allowed by all the paired primitives at once: the
    intersection of their relation cosets (Liu & Popplestone 1990 eq. (3), docs/algebra.md §2.5)."""
    result: Coset | None = None
    for i, j, kind in pairing:
        step = relation_coset(kind, first[i], second[j], tol=tol)
        if result is not None and isinstance(step, Coset):
            step = result.intersect(step, tol=tol)
        if isinstance(step, EmptySet):
            return step
        result = step
    assert result is not None
    return result


def up_to_symmetry(
    coset: Coset, first: MatingBody, second: MatingBody, tol: ModelTolerance
) -> bool:
    """Whether the common group equals the symmetry group of one of the bodies, so that
    every member of the coset places that body onto the same point set: the relative
    position is determined up to the body's own symmetry (Liu & Popplestone 1990 step one, Example
    Three). X = h·x₀ with h ∈ H in ``second``'s frame, so H must equal sym(second), or
    x₀⁻¹·H·x₀ (the same motions seen in ``first``'s frame) must equal sym(first)."""
    group = coset.group
    return not coset.is_point and (
        group.equals(second.symmetry, tol)
        or group.conjugate(coset.rep_inverse).equals(first.symmetry, tol)
    )


def positions(
    coset: Coset, first: MatingBody, second: MatingBody, tol: ModelTolerance
) -> list[Coset]:
    """The relative positions a candidate stands for: a finite coset determined up to a
    body's symmetry is one position (its representative); another finite coset is split
    into its single positions; any other coset is kept whole."""
    if coset.dof == 0 and not coset.group.lattice and coset.n_components > 1:
        if up_to_symmetry(coset, first, second, tol):
            return [Coset(SymmetryGroup.identity(), coset.rep)]
        return [Coset(SymmetryGroup.identity(), p) for p in coset.points()]
    return [coset]


def goal_candidates(
    problem: MatingProblem, goal: Goal, groups: dict[tuple[str, str], SymmetryGroup]
) -> list[Candidate]:
    """All candidate mating pairs of ``goal`` (Liu & Popplestone 1990 step one; Liu 1997 Prop.
    3.1.5); ``groups`` caches compound groups by (body, compound)."""
    tol = problem.tolerance
    a, b = problem.bodies[goal.first], problem.bodies[goal.second]
    found: list[Candidate] = []
    # Compounds share primitives (a face in every seat): each primitive pair is judged once.
    known: dict[tuple[str, str], str | None] = {}

    def kind(x: str, y: str) -> str | None:
        if (x, y) not in known:
            known[(x, y)] = matable(a.features[x], b.features[y], tol)
        return known[(x, y)]

    for (ca, fa), (cb, fb) in itertools.product(a.compounds.items(), b.compounds.items()):
        if len(fa.features) != len(fb.features):
            continue
        kinds = [[kind(x, y) for y in b.members[cb]] for x in a.members[ca]]
        for pairing in pairings(fa.features, fb.features, tol, kinds):
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
                for position in positions(coset, a, b, tol)
            )
    found.sort(key=lambda c: -c.priority)
    return found


def interfering(
    first: MatingBody, second: MatingBody, relative: np.ndarray, tol: ModelTolerance
) -> bool:
    """Whether ``first`` placed at ``relative`` in ``second``'s frame shares a volume with
    ``second`` (mesh tolerance); bodies without meshes never interfere."""
    if first.mesh is None or second.mesh is None:
        return False
    return interferes(placed(first.mesh, relative), second.mesh, tol.for_mesh())


def node_consistent(problem: MatingProblem, candidate: Candidate) -> bool:
    """Node consistency (Liu & Popplestone 1990 step one): a candidate whose relative position is
    determined, alone or up to a body's symmetry, is kept only if the two bodies do not
    interfere at its representative position."""
    g = candidate.goal
    first, second = problem.bodies[g.first], problem.bodies[g.second]
    tol = problem.tolerance
    if not (candidate.determined or up_to_symmetry(candidate.coset, first, second, tol)):
        return True
    return not interfering(first, second, candidate.coset.rep, tol)


@dataclass(frozen=True, eq=False)
class ConstraintGraph:
    """The two-layer graph (Liu & Popplestone 1990 step one): ``top`` (bodies and goals, networkx
    ``Graph``), ``bottom`` (compound features joined by candidate pairs, ``MultiGraph``),
    and the ``initial`` and node-consistent ``domains`` of the goals."""

    top: nx.Graph[tuple[str, str | int]]
    bottom: nx.MultiGraph[tuple[str, str]]
    initial: Domains
    domains: Domains


def build_graph(problem: MatingProblem) -> ConstraintGraph:
    """Set up the two-layer graph with the candidate pairs of every goal and apply node
    consistency (Liu & Popplestone 1990 step one)."""
    top: nx.Graph[tuple[str, str | int]] = nx.Graph()
    bottom: nx.MultiGraph[tuple[str, str]] = nx.MultiGraph()
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
