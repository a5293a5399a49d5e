"""Step two of the assembly constraint satisfaction process (Liu & Popplestone 1990): the laws that
shrink the goals' domains.

* **Mandatory request law**: a goal with one candidate left claims its non-sharable
  features; candidates of other goals using them are deleted, until quiescent.
* **Equivalent feature law**: compound features of a body in the same orbit of the
  body's symmetry group are equivalent; one representative is kept and the others are
  counted as copies. It is applied only to bodies in a single goal: for a body in
  several goals, dismissing orbit members would end the process (Liu & Popplestone 1990 Example 2).
* **Arc consistency** (Mackworth 1985; Mohr & Henderson 1986, AC-3): two candidates of
  different goals are compatible unless they use a common non-sharable feature or, for
  goals sharing a body, the two other bodies interfere in every position the candidates
  allow (Liu & Popplestone 1990 Example one: "intersection is found by arc consistency checking",
  Figure 2; judged over both freedoms by :mod:`assemblykit.mating.clearance`); a
  candidate without a compatible one in some other goal is deleted.
* **Path consistency** (Mohr & Henderson 1986; Liu & Popplestone 1990 step two, "arc/path
  consistency"): the allowed pairs of candidates of two goals start as the compatible
  ones; a pair is deleted when some third goal sharing a body with both has no candidate
  allowed with each of the two; a candidate left in no allowed pair with some
  neighbouring goal is deleted; repeated until quiescent.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass, field
from itertools import combinations

from assemblykit.features import Relationship, relationship
from assemblykit.features.compound import feature_transporter
from assemblykit.mating.clearance import Verdict, judge_pair, mover, sweepable
from assemblykit.mating.graph import Candidate, Domains
from assemblykit.mating.problem import Goal, MatingBody, MatingProblem
from assemblykit.tolerance import ModelTolerance


def compatible(a: Candidate, b: Candidate) -> bool:
    """Whether two candidates of different goals can hold together: no non-sharable
    feature is used by both (Liu & Popplestone 1990 footnote 3)."""
    return not (a.uses & b.uses)


def mandatory_request(domains: Domains) -> Domains:
    """The mandatory request law (Liu & Popplestone 1990 step two), propagated until quiescent."""
    current = dict(domains)
    queue = deque(g for g, d in current.items() if len(d) == 1)
    settled: set[int] = set()
    while queue:
        goal = queue.popleft()
        if goal in settled or len(current[goal]) != 1:
            continue
        settled.add(goal)
        (claim,) = current[goal]
        for other, domain in current.items():
            if other == goal:
                continue
            kept = tuple(c for c in domain if compatible(c, claim))
            if len(kept) != len(domain):
                current[other] = kept
                if len(kept) == 1:
                    queue.append(other)
    return current


def _congruent(a: object, b: object, tol: ModelTolerance) -> bool:
    return type(a) is type(b) and relationship(a, b, tol) in (  # type: ignore[arg-type]
        Relationship.ONE_CONGRUENT,
        Relationship.TWO_CONGRUENT,
    )


def compound_orbits(body: MatingBody, tol: ModelTolerance) -> dict[str, str]:
    """The representative (first in file order) of each compound feature's orbit under
    the body's symmetry group (Liu & Popplestone 1990 equivalent feature law): ``c ~ c'`` when some
    discrete element g of the group maps every primitive of ``c`` onto one of ``c'``."""
    names = list(body.compounds)
    reps: dict[str, str] = {}
    elements = body.symmetry.reps[1:]
    for index, name in enumerate(names):
        source = body.compounds[name].features
        reps[name] = name
        for earlier in names[:index]:
            if reps[earlier] != earlier:
                continue
            target = body.compounds[earlier].features
            if len(target) == len(source) and any(
                all(
                    any(
                        _congruent(p, q, tol) and feature_transporter(q, p).contains(g, tol)
                        for q in target
                    )
                    for p in source
                )
                for g in elements
            ):
                reps[name] = earlier
                break
    return reps


def equivalent_features(problem: MatingProblem, domains: Domains) -> Domains:
    """The equivalent feature law (Liu & Popplestone 1990 step two): for each body in exactly one
    goal, keep the candidates of one compound feature per orbit and count the others as copies.
    """
    tol = problem.tolerance
    involvement: dict[str, int] = {}
    for goal in problem.goals:
        for name in (goal.first, goal.second):
            involvement[name] = involvement.get(name, 0) + 1
    current = dict(domains)
    for goal in problem.goals:
        for side in ("first", "second"):
            body = problem.bodies[getattr(goal, side)]
            if involvement[body.name] != 1 or len(body.symmetry.reps) < 2:
                continue
            current[goal.number] = _representatives(
                current[goal.number], side, compound_orbits(body, tol)
            )
    return current


def _representatives(
    domain: tuple[Candidate, ...], side: str, orbit: Mapping[str, str]
) -> tuple[Candidate, ...]:
    """Candidates grouped by (orbit of this side's compound, other side's compound): the
    representative's candidates stand for the whole group."""
    other = "second" if side == "first" else "first"
    groups: dict[tuple[str, str], list[Candidate]] = {}
    for c in domain:
        groups.setdefault((orbit[getattr(c, side)], getattr(c, other)), []).append(c)
    kept: list[Candidate] = []
    for (rep, _), members in groups.items():
        chosen = [c for c in members if getattr(c, side) == rep] or members
        factor = len({getattr(c, side) for c in members}) if chosen is not members else 1
        kept.extend(c.with_copies(c.copies * factor) for c in chosen)
    order = {id(c): i for i, c in enumerate(domain)}
    return tuple(sorted(kept, key=lambda c: order.get(id(c), len(order))))


@dataclass(eq=False)
class Clashes:
    """Interference between candidates of two goals sharing a body (Liu & Popplestone 1990 Example
    one, Figure 2): with the shared body as the frame, each candidate places the goal's
    other body on its relative coset; the candidates clash when those two bodies
    interfere in every pair of positions (a certified verdict, never a sample). Verdicts
    are cached; ``reasons`` keeps, per goal, why arc consistency deleted its candidates.
    """

    problem: MatingProblem
    reasons: dict[int, str] = field(default_factory=dict)
    _cache: dict[tuple[int, int], bool] = field(default_factory=dict)

    def others(self, a: Candidate, b: Candidate) -> tuple[str, str] | None:
        """The two bodies placed relative to the common body, if the goals share one."""
        ga, gb = a.goal, b.goal
        common = {ga.first, ga.second} & {gb.first, gb.second}
        if len(common) != 1:
            return None
        (shared,) = common
        p = ga.second if ga.first == shared else ga.first
        q = gb.second if gb.first == shared else gb.first
        bodies = self.problem.bodies
        if p == q or bodies[p].mesh is None or bodies[q].mesh is None:
            return None
        return p, q

    def __call__(self, a: Candidate, b: Candidate) -> bool:
        key = (id(a), id(b)) if id(a) < id(b) else (id(b), id(a))
        if key not in self._cache:
            self._cache[key] = self._judge(a, b)
        return self._cache[key]

    def _judge(self, a: Candidate, b: Candidate) -> bool:
        names = self.others(a, b)
        if names is None:
            return False
        tol = self.problem.tolerance
        movers = []
        for candidate, name in zip((a, b), names, strict=True):
            # X = L_second⁻¹·L_first: the first body sits on the coset in the second's
            # frame, the second on its inverse in the first's.
            coset = candidate.coset if candidate.goal.first == name else candidate.coset.inverse()
            if not sweepable(coset):
                return False
            mesh = self.problem.bodies[name].mesh
            assert mesh is not None  # others() names only bodies with a mesh
            movers.append(mover(name, mesh, coset, tol))
        return judge_pair(movers[0], movers[1], tol).verdict is Verdict.BLOCKED


def arc_consistency(domains: Domains, clashes: Clashes | None = None) -> Domains:
    """AC-3 over the pairwise compatibility of candidates of different goals: no common
    non-sharable feature and, with ``clashes``, no interference in every position."""
    current = {g: tuple(d) for g, d in domains.items()}
    goals = list(current)

    def linked(g: int, h: int) -> bool:
        if _constrained(current[g], current[h]):
            return True
        if clashes is None or not current[g] or not current[h]:
            return False
        return clashes.others(current[g][0], current[h][0]) is not None

    def allowed(c: Candidate, d: Candidate) -> bool:
        return compatible(c, d) and not (clashes is not None and clashes(c, d))

    neighbours = {g: [h for h in goals if h != g and linked(g, h)] for g in goals}
    queue = deque((g, h) for g in goals for h in neighbours[g])
    while queue:
        g, h = queue.popleft()
        kept = tuple(c for c in current[g] if any(allowed(c, d) for d in current[h]))
        if len(kept) != len(current[g]):
            if clashes is not None:
                dropped = [c for c in current[g] if c not in kept]
                for c in dropped:
                    names = next(
                        (clashes.others(c, d) for d in current[h] if compatible(c, d)), None
                    )
                    if names is not None:
                        clashes.reasons[g] = (
                            f"{names[0]} and {names[1]} interfere in every position of "
                            f"goals {g} and {h}"
                        )
            current[g] = kept
            queue.extend((k, g) for k in neighbours[g] if k != h)
    return current


def _constrained(a: tuple[Candidate, ...], b: tuple[Candidate, ...]) -> bool:
    used = frozenset().union(*(c.uses for c in a)) if a else frozenset()
    return any(c.uses & used for c in b)


@dataclass(frozen=True)
class PathResult:
    """The domains left by :func:`path_consistency` and the number of candidate pairs
    it deleted (its pruning statistic beyond the domain sizes)."""

    domains: Domains
    pairs_removed: int


def path_consistency(domains: Domains, goals: tuple[Goal, ...]) -> PathResult:
    """Path consistency over triples of goals sharing bodies (Mohr & Henderson 1986).

    Only goals with a common body constrain each other (a non-sharable feature belongs to
    one body), so the relations are kept for those pairs and a pair (c, d) of goals g, h
    needs, for every goal k sharing a body with both, a candidate e of k allowed with c
    and with d. Relations are sets of index pairs into the given domains."""
    bodies = {goal.number: {goal.first, goal.second} for goal in goals}
    linked = [(g, h) for g, h in combinations(sorted(domains), 2) if bodies[g] & bodies[h]]
    allowed = {
        (g, h): {
            (i, j)
            for i, c in enumerate(domains[g])
            for j, d in enumerate(domains[h])
            if compatible(c, d)
        }
        for g, h in linked
    }
    initial = sum(len(pairs) for pairs in allowed.values())
    neighbours: dict[int, set[int]] = {g: set() for g in domains}
    for g, h in linked:
        neighbours[g].add(h)
        neighbours[h].add(g)

    def ok(g: int, i: int, h: int, j: int) -> bool:
        return (i, j) in allowed[(g, h)] if g < h else (j, i) in allowed[(h, g)]

    def supported(g: int, i: int) -> bool:
        return all(any(ok(g, i, h, j) for j in range(len(domains[h]))) for h in neighbours[g])

    changed = True
    while changed:
        changed = False
        for g, h in linked:
            for k in sorted(neighbours[g] & neighbours[h]):
                kept = {
                    (i, j)
                    for i, j in allowed[(g, h)]
                    if any(ok(g, i, k, m) and ok(h, j, k, m) for m in range(len(domains[k])))
                }
                if len(kept) != len(allowed[(g, h)]):
                    allowed[(g, h)] = kept
                    changed = True
        alive = {g: {i for i in range(len(domains[g])) if supported(g, i)} for g in domains}
        for g, h in linked:
            kept = {(i, j) for i, j in allowed[(g, h)] if i in alive[g] and j in alive[h]}
            if len(kept) != len(allowed[(g, h)]):
                allowed[(g, h)] = kept
                changed = True
    removed = initial - sum(len(pairs) for pairs in allowed.values())
    return PathResult(
        {g: tuple(c for i, c in enumerate(d) if supported(g, i)) for g, d in domains.items()},
        removed,
    )
