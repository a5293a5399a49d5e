"""RAPT network reduction: solve times for stacks, trees and grids of N bodies.

Prints, per shape and N, the median solve time; the growth ratio t(10,000)/t(1,000);
and at N = 100 the ratio of the numeric-only path (the whole network handed to the
residue solver, the "equation solving" system of Corner et al. 1983 §III G) to reduction.

Shapes: ``stack`` (equal cubes, so reduction reuses the intersections of repeated
geometry), ``stack~`` (every cube a different size: no reuse), ``tree`` and ``grid``.

Then a task file of 1,000 stacked bodies (YAML, docs/tutorial.md §1) read and solved in one
process: load time (YAML parsing, by yaml-rs, and validation),
solve time and their sum.

Then a chain of 40 bodies, each seated on the one below, against CadQuery's assembly
solver on the same chain (41 unit boxes, each ``Plane``-constrained onto the one below
and ``Axis``-aligned with it), both with load included: for us reading the task file
and solving; for CadQuery building the assembly (its boxes and constraints) and solving.
Both are timed in a warm process (the best of repeats, as timeit advises on a shared
machine) and cold (a fresh interpreter,
imports included). CadQuery runs in this interpreter when it imports here, else in the
interpreter named by ``--cadquery-python PATH`` (or ``$CADQUERY_PYTHON``); without
either only our figure is printed.

Run: python benchmarks/bench_rapt.py [--quick] [--one-start] [--chain-only]
[--cadquery-python PATH]

``--quick`` stops at N = 1,000. The numeric-only path runs with the residue solver's
default settings (its deterministic multi-start; several minutes at N = 100 on a busy
machine) and must agree with reduction; ``--one-start`` runs a single start instead,
a lower bound of its cost.
"""

from __future__ import annotations

import importlib.util
import os
import statistics
import subprocess
import sys
import tempfile
import time
import timeit
from collections.abc import Callable
from pathlib import Path

import yaml

from assemblykit.features.primitives import Plane
from assemblykit.inference.reduction import solve_numeric_only, solve_task
from assemblykit.io.tasks import load_task
from assemblykit.model.body import Body
from assemblykit.model.relations import FeatureRef, Relation
from assemblykit.model.task import Situation, Task

Z, X, Y = (0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)
CHAIN_RATIO_TARGET = 100
"""How many times CadQuery's time for the chain ours should be at least, warm, loading
included."""
LOAD_SOLVE_TARGET = 0.3
"""Seconds to read and solve the task file of 1,000 stacked bodies (median)."""


def _cube(
    name: str, at: tuple[float, float, float] = (0, 0, 0), fixed: bool = False, size: float = 1.0
) -> Body:
    """A cube of edge ``size`` with its corner at ``at`` in its body frame, its six faces
    as planes.

    Movable cubes are modelled about their own origin, so their solved poses are
    translations away from the identity (the numeric path starts at the identity)."""
    x, y, z = at
    faces = {
        "bottom": Plane((x, y, z), (0, 0, -1)),
        "top": Plane((x, y, z + size), Z),
        "left": Plane((x, y, z), (-1, 0, 0)),
        "right": Plane((x + size, y, z), X),
        "front": Plane((x, y, z), (0, -1, 0)),
        "back": Plane((x, y + size, z), Y),
    }
    return Body(name, faces, fixed)


def _rel(kind: str, first: str, second: str) -> Relation:
    return Relation(kind, (FeatureRef.parse(first), FeatureRef.parse(second)))


def _seat_on(child: str, parent: str) -> list[Relation]:
    """Child on top of parent, flush on the left and front: a fixed relation (3 planes)."""
    return [
        _rel("against", f"{child}.bottom", f"{parent}.top"),
        _rel("coplanar", f"{child}.left", f"{parent}.left"),
        _rel("coplanar", f"{child}.front", f"{parent}.front"),
    ]


def _beside(child: str, parent: str) -> list[Relation]:
    """Child right of parent, flush at the bottom and front."""
    return [
        _rel("against", f"{child}.left", f"{parent}.right"),
        _rel("coplanar", f"{child}.bottom", f"{parent}.bottom"),
        _rel("coplanar", f"{child}.front", f"{parent}.front"),
    ]


def stack(n: int, distinct: bool = False) -> Task:
    """N cubes stacked on a fixed base; ``distinct``: of N different sizes, so that no two
    relations repeat."""
    bodies = [_cube("b0", (0, 0, 0), fixed=True)]
    relations: list[Relation] = []
    for i in range(1, n + 1):
        bodies.append(_cube(f"b{i}", size=1.0 + i / n if distinct else 1.0))
        relations += _seat_on(f"b{i}", f"b{i - 1}")
    return Task("mm", {b.name: b for b in bodies}, (Situation("s1", tuple(relations)),))


def distinct_stack(n: int) -> Task:
    """N cubes of N different sizes stacked on a fixed base: no two relations repeat."""
    return stack(n, distinct=True)


def tree(n: int) -> Task:
    """A binary tree of N cubes: each sits on its parent (left child) or beside it (right)."""
    bodies = [_cube("b0", (0, 0, 0), fixed=True)]
    relations: list[Relation] = []
    for i in range(1, n + 1):
        parent = (i - 1) // 2
        attach = _seat_on if i % 2 else _beside
        relations += attach(f"b{i}", f"b{parent}")
        bodies.append(_cube(f"b{i}"))
    return Task("mm", {b.name: b for b in bodies}, (Situation("s1", tuple(relations)),))


def grid(n: int) -> Task:
    """A wall of about N cubes in columns: each on the one below and beside the one left
    of it (redundant relations that reduction intersects)."""
    width = max(2, int(n**0.5))
    bodies = {"base": _cube("base", (0, 0, -1), fixed=True)}
    relations: list[Relation] = []
    for k in range(n):
        row, col = divmod(k, width)
        name = f"g{row}_{col}"
        bodies[name] = _cube(name)
        if row == 0:
            relations += [
                _rel("against", f"{name}.bottom", "base.top"),
                _rel("coplanar", f"{name}.front", "base.front"),
            ]
            if col == 0:
                relations.append(_rel("coplanar", f"{name}.left", "base.left"))
        else:
            relations += _seat_on(name, f"g{row - 1}_{col}")
        if col > 0:
            relations += _beside(name, f"g{row}_{col - 1}")
    return Task("mm", bodies, (Situation("s1", tuple(relations)),))


def stack_file(n: int) -> dict[str, object]:
    """The task file of N unit cubes stacked on a fixed base, as written by a user."""

    def cube(fixed: bool) -> dict[str, object]:
        planes = {
            "bottom": ([0, 0, 0], [0, 0, -1]),
            "top": ([0, 0, 1], [0, 0, 1]),
            "left": ([0, 0, 0], [-1, 0, 0]),
            "front": ([0, 0, 0], [0, -1, 0]),
        }
        features = {k: {"type": "plane", "point": p, "normal": v} for k, (p, v) in planes.items()}
        return {"fixed": fixed, "features": features}

    relations = []
    for i in range(1, n + 1):
        relations += [
            ["against", f"b{i}.bottom", f"b{i - 1}.top"],
            ["coplanar", f"b{i}.left", f"b{i - 1}.left"],
            ["coplanar", f"b{i}.front", f"b{i - 1}.front"],
        ]
    bodies = {f"b{i}": cube(i == 0) for i in range(n + 1)}
    return {"units": "mm", "bodies": bodies, "situations": [{"name": "s1", "relations": relations}]}


def load_and_solve(n: int, repeats: int = 5) -> None:
    """Median load, solve and total time of a task file of N stacked bodies."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"stack{n}.yaml"
        path.write_text(yaml.safe_dump(stack_file(n), sort_keys=False))
        size = path.stat().st_size
        loads, solves = [], []
        for _ in range(repeats):
            start = time.perf_counter()
            task = load_task(path)
            middle = time.perf_counter()
            solution = solve_task(task)
            loads.append(middle - start)
            solves.append(time.perf_counter() - middle)
            assert solution.status == "solved", solution.status
    load, solve = statistics.median(loads), statistics.median(solves)
    verdict = "met" if load + solve <= LOAD_SOLVE_TARGET else "NOT MET"
    print(
        f"task file of {n} bodies ({size / 1e6:.2f} MB): "
        f"load {load:.3f} s, solve {solve:.3f} s, load + solve {load + solve:.3f} s (median; "
        f"target <= {LOAD_SOLVE_TARGET:g} s: {verdict})"
    )


CHAIN = 40

_OURS_COLD = """
import sys, time
start = time.perf_counter()
from assemblykit.inference import solve_task
from assemblykit.io.tasks import load_task
solution = solve_task(load_task(sys.argv[1]))
assert solution.status == "solved", solution.status
print(time.perf_counter() - start)
"""

_CADQUERY = """
import sys, time
start = time.perf_counter()
import cadquery as cq
imported = time.perf_counter()
n, repeats = int(sys.argv[1]), int(sys.argv[2])


def chain():
    assy = cq.Assembly()
    assy.add(cq.Workplane().box(1, 1, 1), name="b0")
    for i in range(1, n + 1):
        # written away from the answer, as our chain's bodies are
        away = cq.Location((0.3 * i, 0.2, 2.0 * i))
        assy.add(cq.Workplane().box(1, 1, 1), name=f"b{i}", loc=away)
    assy.constrain("b0", "Fixed")
    for i in range(1, n + 1):
        assy.constrain(f"b{i - 1}@faces@>Z", f"b{i}@faces@<Z", "Plane")
        assy.constrain(f"b{i - 1}@faces@>X", f"b{i}@faces@>X", "Axis", param=0)
    assy.solve()
    return assy


top = chain().children[-1].loc.toTuple()[0]
cold = time.perf_counter() - start
assert abs(top[2] - n) < 1e-6 and abs(top[0]) < 1e-6, top
warm = []
for _ in range(repeats):
    begin = time.perf_counter()
    chain()
    warm.append(time.perf_counter() - begin)
print(cold, min(warm), imported - start)
"""


def _cadquery_python() -> str | None:
    """The interpreter that runs CadQuery: this one when it imports cadquery, else the
    one named on the command line or in ``$CADQUERY_PYTHON``."""
    if "--cadquery-python" in sys.argv:
        return sys.argv[sys.argv.index("--cadquery-python") + 1]
    if importlib.util.find_spec("cadquery") is not None:
        return sys.executable
    return os.environ.get("CADQUERY_PYTHON")


def chain_against_cadquery(n: int = CHAIN, repeats: int = 20) -> None:
    """Load + solve a chain of ``n`` bodies, ours against CadQuery's assembly solver."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"chain{n}.yaml"
        path.write_text(yaml.safe_dump(stack_file(n), sort_keys=False))
        runs = []
        for _ in range(repeats + 1):  # the first run also imports what solving needs
            start = time.perf_counter()
            solution = solve_task(load_task(path))
            runs.append(time.perf_counter() - start)
            assert solution.status == "solved", solution.status
        ours = min(runs[1:])
        cold = float(
            subprocess.run(
                [sys.executable, "-c", _OURS_COLD, str(path)],
                capture_output=True,
                text=True,
                check=True,
            ).stdout
        )
    print(
        f"chain of {n} bodies, load + solve: ours {ours * 1e3:.2f} ms warm (best of {repeats}),"
        f" {cold:.3f} s cold (imports included)"
    )
    python = _cadquery_python()
    if python is None:
        print("CadQuery not installed: give --cadquery-python PATH to compare")
        return
    run = subprocess.run(
        [python, "-c", _CADQUERY, str(n), str(max(3, repeats // 4))],
        capture_output=True,
        text=True,
    )
    if run.returncode != 0:
        print(f"CadQuery failed: {run.stderr.strip().splitlines()[-1:]}")
        return
    cq_cold, cq_warm, cq_import = (float(v) for v in run.stdout.split()[-3:])
    best = f"best of {max(3, repeats // 4)}"
    print(
        f"chain of {n} bodies, CadQuery build + solve: {cq_warm * 1e3:.1f} ms warm ({best}),"
        f" {cq_cold:.3f} s cold (import {cq_import:.3f} s)"
    )
    ratio = cq_warm / ours
    print(
        f"chain of {n} bodies: ours {ratio:.0f}x faster warm (target >= {CHAIN_RATIO_TARGET}x: "
        f"{'met' if ratio >= CHAIN_RATIO_TARGET else 'NOT MET'}), {cq_cold / cold:.1f}x cold"
    )


def timed(fn: Callable[[], object], repeats: int) -> float:
    """Median wall time of ``repeats`` calls (garbage collection left on, as in use)."""
    return statistics.median(timeit.repeat(fn, "gc.enable()", number=1, repeat=repeats))


def main() -> None:
    quick = "--quick" in sys.argv
    chain_against_cadquery()
    if "--chain-only" in sys.argv:
        return
    load_and_solve(1000)
    sizes = (10, 100, 1000) if quick else (10, 100, 1000, 10000)
    print(f"{'shape':8} {'N':>7} {'median s':>10} {'bodies/s':>10}")
    shapes = (("stack", stack), ("stack~", distinct_stack), ("tree", tree), ("grid", grid))
    for name, build in shapes:
        medians = {}
        for n in sizes:
            task = build(n)
            solution = solve_task(task)
            assert solution.status == "solved", (name, n, solution.status)
            medians[n] = timed(lambda task=task: solve_task(task), 3 if n <= 1000 else 1)
            print(f"{name:8} {n:>7} {medians[n]:>10.4f} {n / medians[n]:>10.0f}")
        if 10000 in medians:
            print(f"{name:8} growth t(10000)/t(1000) = {medians[10000] / medians[1000]:.1f}")
    task = stack(100)
    reduced = timed(lambda: solve_task(task), 5)
    options = {"starts": 1} if "--one-start" in sys.argv else {}
    start = time.perf_counter()
    numeric_solution = solve_numeric_only(task, **options)
    numeric = time.perf_counter() - start
    assert numeric_solution.status == "solved", numeric_solution.status
    top = numeric_solution.bodies["b100@s1"].pose[:3, 3]
    label = "one start" if options else "default settings"
    print(
        f"stack N=100: reduction {reduced:.4f} s, numeric only ({label}) {numeric:.1f} s"
        f" (top cube at {top.round(4).tolist()}), ratio {numeric / reduced:.0f}x"
    )


if __name__ == "__main__":
    main()
