"""Step three of the assembly constraint satisfaction process (Liu & Popplestone 1990) and the
answer.

``mate(problem)`` sets up the two-layer graph (step one), applies the laws (step two:
mandatory request, equivalent features, arc and path consistency), enumerates every
consistent assignment of candidate pairs to goals with a CSP library (python-constraint2
for small problems, OR-Tools CP-SAT from the ``csp`` extra for large ones), then places
the bodies globally and checks the spatial constraint:

* **global positions**: one body is fixed and the relative cosets are chained around the
  goal graph; a body reached twice gets the intersection of the two world cosets (Liu &
  Popplestone 1990 eq. (3)); a body rigidly attached to a moving body moves with it; a loop that
  chaining leaves open is closed by the representative-point loci of Liu & Popplestone 1990 Figs 4-5
  or, without a closed form, numerically (:mod:`assemblykit.mating.loci`), each
  solution a configuration;
* **interference** between every two placed bodies over their joint parameter ranges
  (:mod:`assemblykit.mating.clearance`): a pair proved to interfere in every position
  rejects the configuration with the reason; otherwise a joint free pose is found by
  exact checks (the representative when it is free, else the nearest free pose along
  the freedom) and reported;
* **sweeping** (Liu & Popplestone 1990 Discussion): a body left with a one-parameter group is swept
  with the others at their chosen poses, sampled finely, the collision-free intervals
  refined by bisection and reported as its range of motion.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import constraint
import numpy as np

from assemblykit import formatting as fmt
from assemblykit.algebra import Coset, EmptySet, Kind, SymmetryGroup
from assemblykit.errors import MissingExtraError
from assemblykit.geometry.interference import interference_threshold, solids_interfere
from assemblykit.mating.clearance import (
    Mover,
    Verdict,
    judge_pair,
    mover,
    overlaps,
    sweepable,
)
from assemblykit.mating.graph import Candidate, Domains, build_graph
from assemblykit.mating.laws import (
    Clashes,
    arc_consistency,
    compatible,
    equivalent_features,
    mandatory_request,
    path_consistency,
)
from assemblykit.mating.loci import World, loci_branches, numeric_closure
from assemblykit.mating.problem import MatingProblem
from assemblykit.tolerance import ModelTolerance

LAWS = (
    "candidates",
    "node consistency",
    "mandatory request",
    "equivalent feature",
    "arc consistency",
    "path consistency",
)
"""The stages whose domain sizes are reported, in order."""

#: Above this many assignments (product of the reduced domain sizes) CP-SAT is used.
SMALL_SEARCH = 10**6
#: Samples of a swept parameter (5 degrees for a full turn).
SWEEP_SAMPLES = 72
#: Bisection steps refining each end of a collision-free interval.
BISECTION_STEPS = 12
#: Steps per parameter of the grid searched for a joint free pose.
WITNESS_STEPS = 64
#: Most exact checks spent searching for a joint free pose of one configuration.
WITNESS_CHECKS = 4000
#: Bisection steps pulling a free pose back towards the representative.
REFINE_STEPS = 24


@dataclass(frozen=True)
class Motion:
    """The range of motion of an articulated body: its remaining ``group`` kind, the
    ``parameter`` swept (``angle`` in radians or ``travel`` in model units) and the
    collision-free ``intervals``."""

    kind: str
    parameter: str
    intervals: tuple[tuple[float, float], ...]

    def to_dict(self) -> dict[str, Any]:
        return {
            "motion": self.kind,
            "parameter": self.parameter,
            "intervals": [list(i) for i in self.intervals],
        }


@dataclass(frozen=True, eq=False)
class Configuration:
    """One assembly configuration: the candidate pair of every goal, the world pose of
    every body (the fixed one is the identity), the ranges of motion of articulated
    bodies, and the number of equivalent ``copies`` it stands for."""

    pairs: tuple[Candidate, ...]
    poses: Mapping[str, np.ndarray]
    motions: Mapping[str, Motion] = field(default_factory=dict)

    @property
    def copies(self) -> int:
        """The product of the pairs' orbit copies (equivalent feature law)."""
        return math.prod(c.copies for c in self.pairs)

    def to_dict(self) -> dict[str, Any]:
        return {
            "pairs": [
                {
                    "goal": c.goal.number,
                    "first": [c.goal.first, c.first],
                    "second": [c.goal.second, c.second],
                }
                for c in self.pairs
            ],
            "poses": {name: np.round(p, 12).tolist() for name, p in self.poses.items()},
            "copies": self.copies,
            "motions": {name: m.to_dict() for name, m in self.motions.items()},
        }


@dataclass(frozen=True)
class Emptied:
    """Which goal's domain emptied, and by which law."""

    goal: int
    law: str
    reason: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """``goal`` and ``law``, and the ``reason`` when arc consistency found bodies
        interfering in every position."""
        found: dict[str, Any] = {"goal": self.goal, "law": self.law}
        if self.reason is not None:
            found["reason"] = self.reason
        return found


@dataclass(frozen=True, eq=False)
class MatingResult:
    """The answer of :func:`mate`: the configurations (representatives), the ``count``
    including equivalent copies, the domain sizes after each law, the goal whose domain
    emptied (if any), how many assignments step three rejected, how many candidate
    pairs path consistency deleted, and the domains themselves after each law
    (``stages``, one per entry of :data:`LAWS`)."""

    configurations: tuple[Configuration, ...]
    statistics: Mapping[int, tuple[int, ...]]
    emptied: Emptied | None
    assignments: int
    rejected: int
    pairs_removed: int = 0
    rejections: tuple[Rejection, ...] = ()
    stages: tuple[Domains, ...] = ()

    @property
    def count(self) -> int:
        """Configurations including symmetric (orbit) copies."""
        return sum(c.copies for c in self.configurations)

    def __repr__(self) -> str:
        """``MatingResult(solved, 8 configurations, 2 found)``, or why there is none."""
        if self.configurations:
            facts = [
                "solved",
                fmt.count(self.count, "configuration"),
                f"{len(self.configurations)} found",
            ]
        elif self.emptied is not None:
            goal, law = self.emptied.goal, self.emptied.law
            facts = ["no solution", f"goal {goal} emptied by the {law} law"]
        else:
            facts = ["no solution", f"{fmt.count(self.rejected, 'assignment')} rejected"]
        return fmt.summary("MatingResult", *facts)

    def to_dict(self) -> dict[str, Any]:
        return {
            "status": "solved" if self.configurations else "no solution",
            "count": self.count,
            "representatives": len(self.configurations),
            "configurations": [c.to_dict() for c in self.configurations],
            "statistics": {
                "laws": list(LAWS),
                "domains": {str(g): list(sizes) for g, sizes in self.statistics.items()},
                "assignments": self.assignments,
                "rejected": self.rejected,
                "path_pairs_removed": self.pairs_removed,
            },
            "emptied": None if self.emptied is None else self.emptied.to_dict(),
            "rejections": [r.to_dict() for r in self.rejections],
        }

    def or_and(self) -> str:
        """``** [Or [And [fit [b1 comp1] [b4 comp13]] ...] ...]`` (Liu & Popplestone 1990
        Examples)."""
        if not self.configurations:
            return "** [Or]"
        ands = [
            "[And " + "\n       ".join(c.describe() for c in config.pairs) + "]"
            for config in self.configurations
        ]
        return "** [Or " + "\n    ".join(ands) + "]"


def mate(problem: MatingProblem) -> MatingResult:
    """All assembly configurations satisfying the goals (Liu & Popplestone 1990, steps one to
    three; docs/mating.md): candidate feature pairs, pruned by the mandatory request and
    equivalent feature laws and arc consistency, then searched, placed and checked for
    interference.

    Parameters
    ----------
    problem : MatingProblem
        The bodies and goals (:func:`assemblykit.load_problem`).

    Returns
    -------
    MatingResult
        The configurations found (feature pairs, each body's pose and remaining motion),
        the domain sizes after each law, and, when there is none, the goal emptied and the
        law that emptied it.

    Raises
    ------
    MissingExtraError
        A search too large for the built-in solver without the ``csp`` extra (OR-Tools).

    Examples
    --------
    >>> from pathlib import Path
    >>> import assemblykit
    >>> mating = Path(assemblykit.__file__).parent / "examples" / "mating"
    >>> assemblykit.mate(assemblykit.load_problem(mating / "one_socket.yaml"))
    MatingResult(no solution, goal 2 emptied by the mandatory request law)
    """
    graph = build_graph(problem)
    stages: list[Domains] = [graph.initial, graph.domains]
    stages.append(mandatory_request(stages[-1]))
    stages.append(equivalent_features(problem, stages[-1]))
    clashes = Clashes(problem)
    stages.append(arc_consistency(stages[-1], clashes))
    path = path_consistency(stages[-1], problem.goals)
    stages.append(path.domains)
    statistics = {g.number: tuple(len(s[g.number]) for s in stages) for g in problem.goals}
    emptied = _emptied(stages, problem, clashes)
    domains = stages[-1]
    if emptied is not None:
        return MatingResult((), statistics, emptied, 0, 0, path.pairs_removed, stages=tuple(stages))
    assignments = solve_csp(domains)
    placements = [
        place(problem, tuple(assignment[g.number] for g in problem.goals))
        for assignment in assignments
    ]
    configurations = [c for p in placements for c in p.configurations]
    rejected = sum(1 for p in placements if not p.configurations)
    return MatingResult(
        tuple(configurations),
        statistics,
        None,
        len(assignments),
        rejected,
        path.pairs_removed,
        tuple(r for p in placements for r in p.rejections),
        tuple(stages),
    )


def _emptied(stages: Sequence[Domains], problem: MatingProblem, clashes: Clashes) -> Emptied | None:
    for stage, law in zip(stages, LAWS, strict=True):
        for goal in problem.goals:
            if not stage[goal.number]:
                reason = clashes.reasons.get(goal.number) if law == "arc consistency" else None
                return Emptied(goal.number, law, reason)
    return None


# ----------------------------------------------------------------------------- the CSP


def solve_csp(domains: Domains) -> list[dict[int, Candidate]]:
    """Every assignment of one candidate per goal with pairwise compatible candidates:
    python-constraint2 for small search spaces, OR-Tools CP-SAT for large ones."""
    if math.prod(len(d) for d in domains.values()) <= SMALL_SEARCH:
        return _solve_small(domains)
    return _solve_cp_sat(domains)


def _solve_small(domains: Domains) -> list[dict[int, Candidate]]:
    problem = constraint.Problem()
    goals = list(domains)
    for g in goals:
        problem.addVariable(g, list(range(len(domains[g]))))
    for i, g in enumerate(goals):
        for h in goals[i + 1 :]:
            if any(not compatible(a, b) for a in domains[g] for b in domains[h]):
                problem.addConstraint(_pair_test(domains[g], domains[h]), (g, h))
    found = [tuple(solution[g] for g in goals) for solution in problem.getSolutions()]
    return [{g: domains[g][i] for g, i in zip(goals, row, strict=True)} for row in sorted(found)]


def _pair_test(a: tuple[Candidate, ...], b: tuple[Candidate, ...]) -> constraint.Constraint:
    return constraint.FunctionConstraint(lambda i, j: compatible(a[i], b[j]))


def _solve_cp_sat(domains: Domains) -> list[dict[int, Candidate]]:
    try:
        from ortools.sat.python import cp_model
    except ImportError:
        raise MissingExtraError("ortools", "csp", "a large mating search") from None
    model = cp_model.CpModel()
    choice = {
        (g, i): model.new_bool_var(f"g{g}_{i}") for g, d in domains.items() for i in range(len(d))
    }
    users: dict[tuple[str, str], list[Any]] = {}
    for g, d in domains.items():
        model.add_exactly_one(choice[(g, i)] for i in range(len(d)))
        for i, c in enumerate(d):
            for feature in c.uses:
                users.setdefault(feature, []).append(choice[(g, i)])
    for variables in users.values():
        if len(variables) > 1:
            model.add_at_most_one(variables)

    class _Collect(cp_model.CpSolverSolutionCallback):
        def __init__(self) -> None:
            super().__init__()
            self.rows: list[tuple[int, ...]] = []

        def on_solution_callback(self) -> None:
            self.rows.append(
                tuple(
                    next(i for i in range(len(d)) if self.value(choice[(g, i)]))
                    for g, d in domains.items()
                )
            )

    solver = cp_model.CpSolver()
    solver.parameters.enumerate_all_solutions = True
    solver.parameters.num_workers = 1
    collect = _Collect()
    solver.solve(model, collect)
    goals = list(domains)
    return [
        {g: domains[g][i] for g, i in zip(goals, row, strict=True)} for row in sorted(collect.rows)
    ]


# ----------------------------------------------------------------------------- placement


@dataclass(frozen=True)
class Rejection:
    """Why step three rejected a configuration of an assignment: the ``bodies`` that
    interfere (or have no free position), the ``reason``, and whether it is ``proven``
    (every pose shown to interfere) or only no free pose was found."""

    pairs: tuple[Candidate, ...]
    bodies: tuple[str, ...]
    reason: str
    proven: bool

    def to_dict(self) -> dict[str, Any]:
        return {
            "pairs": [c.describe() for c in self.pairs],
            "bodies": list(self.bodies),
            "reason": self.reason,
            "proven": self.proven,
        }


@dataclass(frozen=True, eq=False)
class Placement:
    """The configurations of one assignment and the rejections of its other branches."""

    configurations: tuple[Configuration, ...]
    rejections: tuple[Rejection, ...]


def place(problem: MatingProblem, pairs: tuple[Candidate, ...]) -> Placement:
    """The configurations of one assignment (Liu & Popplestone 1990 step three): global positions by
    coset chaining and representative-point loci, then the no-pairwise-interference
    constraint over the bodies' remaining freedoms (:mod:`assemblykit.mating.clearance`)."""
    tol = problem.tolerance
    root = _root(pairs, list(problem.bodies))
    configurations: list[Configuration] = []
    rejections: list[Rejection] = []
    for world in _positions({root: Coset(SymmetryGroup.identity(), np.eye(4))}, pairs, tol):
        outcome = _spatial(problem, pairs, world)
        if isinstance(outcome, Rejection):
            rejections.append(outcome)
        else:
            configurations.append(outcome)
    return Placement(tuple(configurations), tuple(rejections))


def _units(pairs: Sequence[Candidate], world: World, tol: ModelTolerance) -> list[list[str]]:
    """Bodies that move together: a goal with a determined relative position between two
    bodies with the same world group attaches them rigidly (one set of parameters)."""
    unit = {name: name for name in world}

    def top(name: str) -> str:
        while unit[name] != name:
            name = unit[name]
        return name

    for c in pairs:
        a, b = c.goal.first, c.goal.second
        if (
            c.coset.is_point
            and a in world
            and b in world
            and not world[a].is_point
            and world[a].group.equals(world[b].group, tol)
        ):
            unit[top(a)] = top(b)
    groups: dict[str, list[str]] = {}
    for name in world:
        groups.setdefault(top(name), []).append(name)
    return list(groups.values())


def _root(pairs: Sequence[Candidate], names: Sequence[str]) -> str:
    """The fixed body: the one in most goals (first in the file on ties)."""
    degree = dict.fromkeys(names, 0)
    for c in pairs:
        for name in (c.goal.first, c.goal.second):
            degree[name] += 1
    return max(names, key=lambda name: degree[name])


def _positions(world: World, pairs: Sequence[Candidate], tol: ModelTolerance) -> list[World]:
    """Every consistent set of world cosets reachable from ``world``: chain and intersect
    until quiescent, then branch on a loop that is not closed yet: representative-point
    loci (Liu & Popplestone 1990 Figs 4-5), else the numeric closure. A closed form with no meeting
    point rejects the assignment; the numeric path never does (module docstring of
    :mod:`assemblykit.mating.loci`)."""
    settled = _propagate(dict(world), pairs, tol)
    if settled is None:
        return []
    for c in pairs:
        u, v = c.goal.second, c.goal.first
        if u not in settled or v not in settled or _implied(settled[u], settled[v], c.coset, tol):
            continue
        branches = loci_branches(settled, u, v, c.coset, tol)
        if branches is None:
            branches = numeric_closure(settled, u, v, c.coset, tol) or None
        if branches is not None:
            return [w for b in branches for w in _positions(b, pairs, tol)]
    return [settled]


def _implied(second: Coset, first: Coset, relative: Coset, tol: ModelTolerance) -> bool:
    """Whether a goal X = L_second⁻¹·L_first ∈ ``relative`` holds for every pose left:
    both poses fixed (propagation checked it), or one world coset exactly the goal's
    image of the other (the goal is how that body was reached)."""
    if second.is_point and first.is_point:
        return True
    if second.is_point:
        reach = relative.left(second.rep)
        return reach.group.equals(first.group, tol) and reach.contains(first.rep, tol)
    if first.is_point:
        reach = relative.inverse().left(first.rep)
        return reach.group.equals(second.group, tol) and reach.contains(second.rep, tol)
    if relative.is_point:
        carried = second.right(relative.rep)
        return carried.group.equals(first.group, tol) and carried.contains(first.rep, tol)
    return False


def _propagate(world: World, pairs: Sequence[Candidate], tol: ModelTolerance) -> World | None:
    """Chain point positions through the goals' relative cosets (X = L_second⁻¹·L_first),
    carry bodies rigidly attached to a moving body along with it, and intersect with
    what is known; ``None`` when an intersection is empty."""
    changed = True
    while changed:
        changed = False
        for c in pairs:
            u, v = c.goal.second, c.goal.first
            for known, other, relative in ((u, v, c.coset), (v, u, c.coset.inverse())):
                if known not in world:
                    continue
                if world[known].is_point:
                    reach = relative.left(world[known].rep)
                elif relative.is_point and other not in world:
                    # Rigidly attached to a moving body: it moves with it (L_other = L·X).
                    reach = world[known].right(relative.rep)
                else:
                    continue
                if other not in world:
                    world[other] = reach
                    changed = True
                    continue
                if world[other].is_point and world[known].is_point:
                    if not reach.contains(world[other].rep, tol):
                        return None
                    continue
                met = world[other].intersect(reach, tol)
                if isinstance(met, EmptySet):
                    return None
                if met.dof < world[other].dof or met.is_point:
                    world[other] = met
                    changed = True
    return world


# ----------------------------------------------------------------------------- space


def _spatial(
    problem: MatingProblem, pairs: tuple[Candidate, ...], world: World
) -> Configuration | Rejection:
    """The no-pairwise-interference constraint (Liu & Popplestone 1990 step three) on one set of
    world cosets: every two bodies are judged over their joint parameter ranges (fixed ones at
    their pose, moving ones over their whole freedom, :func:`judge_pair`); a pair proved
    to interfere everywhere rejects the configuration; otherwise a joint free pose is
    searched for the pairs not proved clear, and each moving body's range of motion is
    swept with the others at their chosen poses (Liu & Popplestone 1990 Discussion)."""
    tol = problem.tolerance
    units = _units(pairs, world, tol)
    movers: dict[str, Mover] = {}
    for name, coset in world.items():
        mesh = problem.bodies[name].mesh
        if mesh is not None:
            # A freedom the cylindrical bounds do not cover stays at its representative.
            placed_at = coset if sweepable(coset) else Coset(SymmetryGroup.identity(), coset.rep)
            movers[name] = mover(name, mesh, placed_at, tol)
    owner = {name: i for i, members in enumerate(units) for name in members}
    names = sorted(movers)
    open_pairs: list[tuple[str, str]] = []
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            first, second = movers[a], movers[b]
            if owner[a] == owner[b] and first.span:
                # Rigidly attached: one relative pose, checked once.
                if overlaps(first, [0.0] * first.dof, second, [0.0] * second.dof, tol):
                    return Rejection(pairs, (a, b), f"{a} and {b} interfere", True)
                continue
            verdict = judge_pair(first, second, tol).verdict
            if verdict is Verdict.BLOCKED:
                where = " in every position" if first.span or second.span else ""
                return Rejection(pairs, (a, b), f"{a} and {b} interfere{where}", True)
            if verdict is not Verdict.CLEAR:
                open_pairs.append((a, b))
    moving = [u for u in units if any(movers.get(n) and movers[n].span for n in u)]
    chosen, exhausted = _joint_witness(movers, moving, open_pairs, tol)
    if chosen is None:
        bodies = tuple(sorted({n for pair in open_pairs for n in pair}))
        # a search cut short says so: the configuration may still have a free position
        cut = f" within {WITNESS_CHECKS} checks (search cut short)" if exhausted else ""
        return Rejection(
            pairs,
            bodies,
            "no collision-free position found for " + ", ".join(bodies) + cut,
            False,
        )
    poses = {name: coset.rep for name, coset in world.items()}
    motions: dict[str, Motion] = {}
    for index, unit in enumerate(moving):
        params = chosen[index]
        lead = next(movers[n] for n in unit if n in movers and movers[n].span)
        for name in unit:
            poses[name] = world[name].group.element(list(params)) @ world[name].rep
        motions.update(_ranges(movers, unit, lead, params, poses, open_pairs, tol))
    for name, coset in world.items():
        if not coset.is_point and name not in motions:
            motions[name] = Motion(coset.kind.value, "none", ())
    return Configuration(pairs, poses, motions)


def _candidates(body: Mover) -> list[tuple[float, ...]]:
    """Parameter values tried for a free pose, nearest the representative first."""
    axes = []
    for (lo, hi), weight in zip(body.span, body.weights(), strict=True):
        steps = np.linspace(lo, hi, WITNESS_STEPS + 1)
        axes.append(sorted({0.0, *map(float, steps)}, key=lambda t: abs(t) * weight))
    grid = [tuple(p) for p in itertools.product(*axes)]
    weights = body.weights()
    grid.sort(key=lambda p: math.hypot(*(t * w for t, w in zip(p, weights, strict=True))))
    return grid


def _joint_witness(
    movers: Mapping[str, Mover],
    units: Sequence[list[str]],
    open_pairs: Sequence[tuple[str, str]],
    tol: ModelTolerance,
) -> tuple[list[tuple[float, ...]] | None, bool]:
    """Parameters of every moving unit such that no open pair interferes (exact checks),
    by backtracking over candidate values; each unit's value is then pulled back towards
    its representative by bisection along the segment, staying free. With them, whether
    the :data:`WITNESS_CHECKS` budget ran out (``None`` then does not prove that no
    free position exists)."""
    owner = {name: i for i, unit in enumerate(units) for name in unit}
    leads = [next(movers[n] for n in unit if n in movers and movers[n].span) for unit in units]
    budget = [WITNESS_CHECKS]

    def params_of(name: str, chosen: Mapping[int, tuple[float, ...]]) -> tuple[float, ...]:
        unit = owner.get(name)
        if unit is None:
            return ()
        return chosen[unit]

    def free(index: int, value: tuple[float, ...], chosen: Mapping[int, tuple[float, ...]]) -> bool:
        trial = {**chosen, index: value}
        for a, b in open_pairs:
            involved = {owner.get(a), owner.get(b)}
            if index not in involved or any(u is not None and u not in trial for u in involved):
                continue
            budget[0] -= 1
            first, second = movers[a], movers[b]
            pa = params_of(a, trial) if first.span else ()
            pb = params_of(b, trial) if second.span else ()
            if overlaps(first, pa, second, pb, tol):
                return False
        return True

    Chosen = dict[int, tuple[float, ...]]

    def search(index: int, chosen: Chosen) -> Chosen | None:
        if index == len(units):
            return chosen
        for value in _candidates(leads[index]):
            if budget[0] <= 0:
                return None
            if free(index, value, chosen):
                found = search(index + 1, {**chosen, index: value})
                if found is not None:
                    return found
        return None

    found = search(0, {})
    if found is None:
        return None, budget[0] <= 0
    for index in range(len(units)):
        value = np.asarray(found[index])
        others = {k: v for k, v in found.items() if k != index}
        if not value.any() or free(index, tuple(0.0 * value), others):
            found[index] = tuple(0.0 * value) if value.any() else found[index]
            continue
        near, far = 0.0, 1.0
        for _ in range(REFINE_STEPS):
            middle = 0.5 * (near + far)
            if free(index, tuple(middle * value), others):
                far = middle
            else:
                near = middle
        found[index] = tuple(float(x) for x in far * value)
    return [found[i] for i in range(len(units))], False


def _ranges(
    movers: Mapping[str, Mover],
    unit: Sequence[str],
    lead: Mover,
    params: tuple[float, ...],
    poses: Mapping[str, np.ndarray],
    open_pairs: Sequence[tuple[str, str]],
    tol: ModelTolerance,
) -> dict[str, Motion]:
    """The range of motion of a one-parameter unit with every other body at its chosen
    pose: the whole turn or travel when no pair of it is open (its sweeps clear them,
    certified); else sampled and refined by bisection (Liu & Popplestone 1990 Discussion). Units
    with more freedom report their kind only; their pose was checked."""
    kind = lead.coset.kind
    if lead.dof != 1:
        return {name: Motion(kind.value, "none", ()) for name in unit}
    angle = kind is not Kind.PRISMATIC
    parameter = "angle" if angle else "travel"
    span = lead.span[0]
    inside = set(unit)
    watched = [(a, b) for a, b in open_pairs if (a in inside) != (b in inside)]
    if not watched:
        return {name: Motion(kind.value, parameter, (span,)) for name in unit}

    def free(t: float) -> bool:
        for a, b in watched:
            mine, other = (a, b) if a in inside else (b, a)
            pose = movers[mine].coset.group.element([t]) @ movers[mine].coset.rep
            if interfering_movers(movers[mine], pose, movers[other], poses[other], tol):
                return False
        return True

    intervals = _free_intervals(free, span, angle)
    return {name: Motion(kind.value, parameter, intervals) for name in unit}


def interfering_movers(
    first: Mover, pose_a: np.ndarray, second: Mover, pose_b: np.ndarray, tol: ModelTolerance
) -> bool:
    """Whether two bodies at world poses share more than a touching volume (their
    solids built once, moved to the poses)."""
    threshold = interference_threshold(first.mesh, second.mesh, tol.for_mesh())
    return solids_interfere(
        first.own_solid.transform(pose_a[:3, :]),
        second.own_solid.transform(pose_b[:3, :]),
        threshold,
    )


def _free_intervals(
    free: Callable[[float], bool], span: tuple[float, float], angle: bool
) -> tuple[tuple[float, float], ...]:
    """The free intervals of a sampled parameter, ends refined by bisection."""
    samples = np.linspace(span[0], span[1], SWEEP_SAMPLES + 1)
    flags = [free(float(t)) for t in samples]
    intervals = []
    start: float | None = None
    for k, (t, ok) in enumerate(zip(samples, flags, strict=True)):
        if ok and start is None:
            start = span[0] if k == 0 else _edge(free, float(samples[k - 1]), float(t))
        if not ok and start is not None:
            intervals.append((start, _edge(free, float(t), float(samples[k - 1]))))
            start = None
    if start is not None:
        intervals.append((start, span[1]))
    if angle and len(intervals) > 1 and intervals[0][0] == span[0] and intervals[-1][1] == span[1]:
        # A full turn is periodic: the pieces at -pi and +pi are one interval.
        intervals = [*intervals[1:-1], (intervals[-1][0], intervals[0][1] + 2 * math.pi)]
    return tuple(intervals)


def _edge(free: Callable[[float], bool], blocked: float, clear: float) -> float:
    """The boundary between a blocked and a free parameter value, by bisection."""
    for _ in range(BISECTION_STEPS):
        middle = 0.5 * (blocked + clear)
        if free(middle):
            clear = middle
        else:
            blocked = middle
    return clear
