"""Mating inference on a generated problem: 50 goals with domains of 10 (Liu & Popplestone 1990).

A base carries 50 seats, seat j a plane with a hole of radius r_j = 1 + 0.05 j and a key
hole of radius 0.5 beside it. Peg i carries ten compound features, one for each radius
r_i .. r_{i+9} that exists (a shared face and key, a stem of that radius). So goal i may
use seats i .. i+9: the last goal has one candidate and the mandatory request law
propagates back to a single configuration. Prints load and solve times (median of 3,
wall clock and this process's CPU time, since the machine may be shared), the domain
sizes after each law and the candidate pairs path consistency deleted. Then the
interference checks over remaining freedoms (Liu & Popplestone 1990 step three) on the bundled
``two_arms.yaml`` and ``shaft_fit.yaml``: the time spent judging pairs of bodies over their
joint parameter ranges, and the whole solve.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from importlib import resources
from typing import Any

from assemblykit.io.problem import load_problem, parse_problem
from assemblykit.mating import clearance, laws, search
from assemblykit.mating.search import LAWS, mate

GOALS = 50
DOMAIN = 10
REPEATS = 3


def _radius(j: int) -> float:
    return 1.0 + 0.05 * j


def generated(goals: int = GOALS, domain: int = DOMAIN) -> dict:
    """The problem mapping (no meshes, explicit trivial symmetry)."""
    base_features = {"top": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]}}
    seats = {}
    for j in range(goals):
        x = 10.0 * j
        base_features[f"h{j}"] = {
            "type": "hole",
            "point": [x, 0, 0],
            "axis": [0, 0, -1],
            "radius": _radius(j),
        }
        base_features[f"k{j}"] = {
            "type": "hole",
            "point": [x + 3, 0, 0],
            "axis": [0, 0, -1],
            "radius": 0.5,
        }
        seats[f"seat{j}"] = ["top", f"h{j}", f"k{j}"]
    bodies = {"base": {"features": base_features, "compound": seats, "symmetry": "none"}}
    for i in range(goals):
        features = {
            "face": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, -1]},
            "key": {"type": "shaft", "point": [3, 0, 0], "axis": [0, 0, -1], "radius": 0.5},
        }
        compound = {}
        for j in range(i, min(i + domain, goals)):
            features[f"s{j}"] = {
                "type": "shaft",
                "point": [0, 0, 0],
                "axis": [0, 0, -1],
                "radius": _radius(j),
            }
            compound[f"c{j}"] = ["face", f"s{j}", "key"]
        bodies[f"p{i}"] = {"features": features, "compound": compound, "symmetry": "none"}
    return {"bodies": bodies, "goals": [["fit", f"p{i}", "base"] for i in range(goals)]}


def main() -> None:
    data = generated()
    loads, solves, cpu = [], [], []
    for _ in range(REPEATS):
        start = time.perf_counter()
        problem = parse_problem(data)
        loaded = time.perf_counter()
        before = time.process_time()
        result = mate(problem)
        cpu.append(time.process_time() - before)
        loads.append(loaded - start)
        solves.append(time.perf_counter() - loaded)
    sizes = list(zip(*result.statistics.values(), strict=True))
    print(f"goals {GOALS}, compound features per peg <= {DOMAIN}, seats {GOALS}")
    print(f"load  median {statistics.median(loads):.3f} s")
    print(f"solve median {statistics.median(solves):.3f} s (limit 5 s)")
    print(f"solve CPU median {statistics.median(cpu):.3f} s")
    print(f"configurations {result.count}, assignments {result.assignments}")
    for law, column in zip(LAWS, sizes, strict=True):
        print(f"  {law:20s} total {sum(column):4d}  max {max(column):3d}  min {min(column):3d}")
    print(f"candidate pairs deleted by path consistency {result.pairs_removed}")


def _timed(spent: list[float], judge: Callable[..., Any]) -> Callable[..., Any]:
    def wrapped(*args: Any, **kwargs: Any) -> Any:
        start = time.perf_counter()
        try:
            return judge(*args, **kwargs)
        finally:
            spent.append(time.perf_counter() - start)

    return wrapped


def interference() -> None:
    """Time the pair verdicts (sweeps, kernels, exact checks) on the bundled examples."""
    folder = resources.files("assemblykit") / "examples" / "mating"
    original = clearance.judge_pair
    for name in ("two_arms.yaml", "shaft_fit.yaml"):
        spent: list[float] = []
        judge = _timed(spent, original)
        search.judge_pair = laws.judge_pair = judge  # type: ignore[attr-defined]
        try:
            start = time.perf_counter()
            result = mate(load_problem(str(folder / name)))
            total = time.perf_counter() - start
        finally:
            search.judge_pair = laws.judge_pair = original  # type: ignore[attr-defined]
        print(
            f"{name}: {result.count} configurations, {len(spent)} pair verdicts, "
            f"interference checks {sum(spent):.3f} s of {total:.3f} s"
        )


if __name__ == "__main__":
    main()
    interference()
