"""Mating inference on a generated problem: 50 goals with domains of 10 (seed 002).

A base carries 50 seats, seat j a plane with a hole of radius r_j = 1 + 0.05 j and a key
hole of radius 0.5 beside it. Peg i carries ten compound features, one for each radius
r_i .. r_{i+9} that exists (a shared face and key, a stem of that radius). So goal i may
use seats i .. i+9: the last goal has one candidate and the mandatory request law
propagates back to a single configuration. Prints load and solve times (median of 3,
wall clock and this process's CPU time, since the machine may be shared), the domain
sizes after each law and the candidate pairs path consistency deleted.
"""

from __future__ import annotations

import statistics
import time

from assemblykit.io.problem import parse_problem
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


if __name__ == "__main__":
    main()
