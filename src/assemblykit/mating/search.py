"""Step three of the assembly constraint satisfaction process (seed 002) and the answer.

``mate(problem)`` sets up the two-layer graph (step one), applies the laws (step two:
mandatory request, equivalent features, arc and path consistency), enumerates every
consistent assignment of candidate pairs to goals with a CSP library (python-constraint2
for small problems, OR-Tools CP-SAT from the ``csp`` extra for large ones), then places
the bodies globally and checks the spatial constraint:

* **global positions**: one body is fixed and the relative cosets are chained around the
  goal graph; a body reached twice gets the intersection of the two world cosets (seed
  002 eq. (3)); a body rigidly attached to a moving body moves with it; a loop that
  chaining leaves open is closed by the representative-point loci of seed 002 Figs 4-5
  or, without a closed form, numerically (:mod:`assemblykit.mating.loci`), each
  solution a configuration;
* **interference** between every two placed bodies (manifold3d volumes);
* **sweeping** (beyond the seed; its Discussion): a body left with a one-parameter group
  is swept over it, sampled finely, the collision-free intervals refined by bisection and
  reported as its range of motion; a configuration with no free position is rejected.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import constraint
import numpy as np
from rich.console import Group
from rich.text import Text

from assemblykit.algebra import Coset, EmptySet, Kind, SymmetryGroup, se3
from assemblykit.errors import MissingExtraError
from assemblykit.mating.graph import Candidate, Domains, build_graph, interfering
from assemblykit.mating.laws import (
    arc_consistency,
    compatible,
    equivalent_features,
    mandatory_request,
    path_consistency,
)
from assemblykit.mating.loci import World, loci_branches, numeric_closure
from assemblykit.mating.problem import MatingProblem
from assemblykit.tolerance import Tolerance

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

_ONE_PARAMETER = frozenset({Kind.REVOLUTE, Kind.PRISMATIC, Kind.HELICAL})


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


@dataclass(frozen=True, eq=False)
class MatingResult:
    """The answer of :func:`mate`: the configurations (representatives), the ``count``
    including equivalent copies, the domain sizes after each law, the goal whose domain
    emptied (if any), how many assignments step three rejected, and how many candidate
    pairs path consistency deleted."""

    configurations: tuple[Configuration, ...]
    statistics: Mapping[int, tuple[int, ...]]
    emptied: Emptied | None
    assignments: int
    rejected: int
    pairs_removed: int = 0

    @property
    def count(self) -> int:
        """Configurations including symmetric (orbit) copies."""
        return sum(c.copies for c in self.configurations)

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
            "emptied": None
            if self.emptied is None
            else {"goal": self.emptied.goal, "law": self.emptied.law},
        }

    def render(self) -> Group:
        """Seed 002's Or/And form, then the pruning statistics."""
        lines = [Text(self.or_and())]
        if self.emptied is not None:
            lines.append(
                Text(f"goal {self.emptied.goal}: domain emptied by the {self.emptied.law} law")
            )
        lines.append(Text(f"{self.count} configurations ({len(self.configurations)} found)"))
        for config in self.configurations:
            for name, motion in config.motions.items():
                spans = ", ".join(f"[{lo:.6g}, {hi:.6g}]" for lo, hi in motion.intervals)
                lines.append(Text(f"  {name}: {motion.kind} {motion.parameter} {spans}"))
        header = " -> ".join(LAWS)
        lines.append(Text(f"domain sizes ({header}):"))
        lines.extend(
            Text(f"  goal {g}: {' -> '.join(map(str, s))}") for g, s in self.statistics.items()
        )
        lines.append(Text(f"candidate pairs deleted by path consistency: {self.pairs_removed}"))
        return Group(*lines)

    def or_and(self) -> str:
        """``** [Or [And [fit [b1 comp1] [b4 comp13]] ...] ...]`` (seed 002 Examples)."""
        if not self.configurations:
            return "** [Or]"
        ands = [
            "[And " + "\n       ".join(c.describe() for c in config.pairs) + "]"
            for config in self.configurations
        ]
        return "** [Or " + "\n    ".join(ands) + "]"


def mate(problem: MatingProblem) -> MatingResult:
    """All assembly configurations satisfying the goals (seed 002, steps one to three)."""
    graph = build_graph(problem)
    stages: list[Domains] = [graph.initial, graph.domains]
    stages.append(mandatory_request(stages[-1]))
    stages.append(equivalent_features(problem, stages[-1]))
    stages.append(arc_consistency(stages[-1]))
    path = path_consistency(stages[-1], problem.goals)
    stages.append(path.domains)
    statistics = {g.number: tuple(len(s[g.number]) for s in stages) for g in problem.goals}
    emptied = _emptied(stages, problem)
    domains = stages[-1]
    if emptied is not None:
        return MatingResult((), statistics, emptied, 0, 0, path.pairs_removed)
    assignments = solve_csp(domains)
    configurations = [
        config
        for assignment in assignments
        for config in place(problem, tuple(assignment[g.number] for g in problem.goals))
    ]
    rejected = len(assignments) - len({tuple(map(id, c.pairs)) for c in configurations})
    return MatingResult(
        tuple(configurations), statistics, None, len(assignments), rejected, path.pairs_removed
    )


def _emptied(stages: Sequence[Domains], problem: MatingProblem) -> Emptied | None:
    for stage, law in zip(stages, LAWS, strict=True):
        for goal in problem.goals:
            if not stage[goal.number]:
                return Emptied(goal.number, law)
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
        (g, i): model.NewBoolVar(f"g{g}_{i}") for g, d in domains.items() for i in range(len(d))
    }
    users: dict[tuple[str, str], list[Any]] = {}
    for g, d in domains.items():
        model.AddExactlyOne(choice[(g, i)] for i in range(len(d)))
        for i, c in enumerate(d):
            for feature in c.uses:
                users.setdefault(feature, []).append(choice[(g, i)])
    for variables in users.values():
        if len(variables) > 1:
            model.AddAtMostOne(variables)

    class _Collect(cp_model.CpSolverSolutionCallback):
        def __init__(self) -> None:
            super().__init__()
            self.rows: list[tuple[int, ...]] = []

        def on_solution_callback(self) -> None:
            self.rows.append(
                tuple(
                    next(i for i in range(len(d)) if self.Value(choice[(g, i)]))
                    for g, d in domains.items()
                )
            )

    solver = cp_model.CpSolver()
    solver.parameters.enumerate_all_solutions = True
    solver.parameters.num_workers = 1
    collect = _Collect()
    solver.Solve(model, collect)
    goals = list(domains)
    return [
        {g: domains[g][i] for g, i in zip(goals, row, strict=True)} for row in sorted(collect.rows)
    ]


# ----------------------------------------------------------------------------- placement


def place(problem: MatingProblem, pairs: tuple[Candidate, ...]) -> list[Configuration]:
    """The configurations of one assignment (seed 002 step three): global positions by
    coset chaining and representative-point loci, then interference and sweeping."""
    tol = problem.tolerance
    root = _root(pairs, list(problem.bodies))
    configurations = []
    for world in _positions({root: Coset(SymmetryGroup.identity(), np.eye(4))}, pairs, tol):
        fixed = {b: w.rep for b, w in world.items() if w.is_point}
        moving = {b: w for b, w in world.items() if not w.is_point}
        if not _clear(problem, fixed, tol):
            continue
        motions: dict[str, Motion] = {}
        poses = dict(fixed)
        for name, coset in moving.items():
            swept = _sweep(problem, name, coset, fixed, tol)
            if swept is None:
                break
            poses[name], motions[name] = swept
        else:
            configurations.append(Configuration(pairs, poses, motions))
    return configurations


def _root(pairs: Sequence[Candidate], names: Sequence[str]) -> str:
    """The fixed body: the one in most goals (first in the file on ties)."""
    degree = dict.fromkeys(names, 0)
    for c in pairs:
        for name in (c.goal.first, c.goal.second):
            degree[name] += 1
    return max(names, key=lambda name: degree[name])


def _positions(world: World, pairs: Sequence[Candidate], tol: Tolerance) -> list[World]:
    """Every consistent set of world cosets reachable from ``world``: chain and intersect
    until quiescent, then branch on a loop that is not closed yet: representative-point
    loci (seed 002 Figs 4-5), else the numeric closure. A closed form with no meeting
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


def _implied(second: Coset, first: Coset, relative: Coset, tol: Tolerance) -> bool:
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


def _propagate(world: World, pairs: Sequence[Candidate], tol: Tolerance) -> World | None:
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


def _clear(problem: MatingProblem, poses: Mapping[str, np.ndarray], tol: Tolerance) -> bool:
    """No two placed bodies interfere (seed 002 step three, spatial constraint)."""
    names = sorted(poses)
    return not any(
        interfering(
            problem.bodies[a],
            problem.bodies[b],
            se3.inverse(poses[b]) @ poses[a],
            tol,
        )
        for i, a in enumerate(names)
        for b in names[i + 1 :]
    )


def _sweep(
    problem: MatingProblem,
    name: str,
    coset: Coset,
    fixed: Mapping[str, np.ndarray],
    tol: Tolerance,
) -> tuple[np.ndarray, Motion] | None:
    """Sweep body ``name`` over its one-parameter world coset against the placed bodies
    (seed 002 Discussion): sample, keep the collision-free intervals, refine their ends by
    bisection. Returns a free pose and the range of motion, or ``None`` if none is free.
    Bodies with more freedom are reported without a sweep (their representative pose)."""
    if coset.kind not in _ONE_PARAMETER:
        return coset.rep, Motion(coset.kind.value, "none", ())
    angle = coset.kind is not Kind.PRISMATIC
    span = (-math.pi, math.pi) if angle else (-tol.scale, tol.scale)

    def free(t: float) -> bool:
        pose = coset.group.element([t]) @ coset.rep
        return _clear(problem, {**fixed, name: pose}, tol)

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
    if not intervals:
        return None
    if angle and len(intervals) > 1 and intervals[0][0] == span[0] and intervals[-1][1] == span[1]:
        # A full turn is periodic: the pieces at -pi and +pi are one interval.
        intervals = [*intervals[1:-1], (intervals[-1][0], intervals[0][1] + 2 * math.pi)]
    kept = _inside(0.0, intervals)
    parameter = 0.0 if kept else 0.5 * sum(max(intervals, key=lambda i: i[1] - i[0]))
    pose = coset.group.element([parameter]) @ coset.rep
    return pose, Motion(coset.kind.value, "angle" if angle else "travel", tuple(intervals))


def _inside(value: float, intervals: Sequence[tuple[float, float]]) -> bool:
    return any(lo <= value <= hi for lo, hi in intervals)


def _edge(free: Any, blocked: float, clear: float) -> float:
    """The boundary between a blocked and a free parameter value, by bisection."""
    for _ in range(BISECTION_STEPS):
        middle = 0.5 * (blocked + clear)
        if free(middle):
            clear = middle
        else:
            blocked = middle
    return clear
