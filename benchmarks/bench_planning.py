"""Planning times: the bundled gearbox, the ASAP beam, arch and crossvault (shipped with
the tests), the dome, and synthetic stacks of growing size.

Run ``python benchmarks/bench_planning.py``. Each figure is the median wall time of
``REPEATS`` runs on a freshly loaded assembly (contacts and blocking graphs included);
the beam runs once. The crossvault (184 blocks) and the dome (527 blocks, candidate
directions from each block's own arrangement) are printed next to their targets (2 s and
5 s), and the dome's peak memory (resident set of a process that loads and plans it
alone) next to its target of 2 GB, and the beam's ``assemblykit plan --json`` in a new
process, imports and loading included, next to its target of 0.64 s. The dome is
skipped unless ``$ASSEMBLYKIT_DATA`` holds ``compas_assembly/dome_assembly.json``.
Growth: plan times of guillotine box packings of 25 to 400 parts and the exponent of a
power law fitted to them (target: at most 1.5).
The machine the figures come from is printed first.

Puzzles: multi-move plans (``plan --moves multi``) of BurrTools' example puzzles, with the
level each stored and the ``time`` BurrTools recorded for the problem, and all 314 solid
six-piece burrs (bundled under ``tests/data/burrtools``); then multi-move plans of
meshes (contact-change distances from the Minkowski sums of convex pieces): the bundled
key in steps, guillotine packings and a key in a cage too long for it. ``--puzzles``
runs only these. Monotone plans of six-piece burrs (``assemblykit plan FILE --solution N
--max-hands 2``, processor time of ``plan`` after loading): one solvable (solution 0)
and one stuck (257), next to their targets (0.3 s and 1 s); ``--burrs`` adds all 314
next to theirs (60 s together). A stuck mesh assembly: 50 links of a chain, each locked
in the next, as meshes off the lattice, planned next to its target (5 s).
"""

from __future__ import annotations

import os
import platform
import resource
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import trimesh

from assemblykit.io.assembly import load_assembly
from assemblykit.io.burrtools import load_burrtools, load_puzzle, solution_count
from assemblykit.model.assembly import Assembly, Part
from assemblykit.model.packings import box_mesh, guillotine_packing
from assemblykit.planning.multimove import MultiMovePlan, plan_voxels
from assemblykit.planning.multimove_mesh import plan_meshes
from assemblykit.planning.planner import plan
from assemblykit.planning.sequence import Plan
from datasets import dataset

ROOT = Path(__file__).resolve().parents[1]
REPEATS = 3
STACK_SIZES = (5, 10, 20, 40, 80)
PACKING_SIZES = (25, 50, 100, 200, 400)
TARGETS = {"compas crossvault": 2.0, "compas dome": 5.0}
"""Plan time targets in seconds (median wall time)."""
MEMORY_TARGET = 2.0
"""Peak memory of the dome's plan, GB."""
GROWTH_TARGET = 1.5
"""Largest exponent of plan time in the number of parts of box packings."""
STUCK_LINKS = 50
STUCK_TARGET = 5.0
"""CPU seconds for ``plan`` to decide a stuck mesh assembly of :data:`STUCK_LINKS` parts."""
END_TO_END_TARGET = 0.64
"""``assemblykit plan`` of the ASAP beam from process start to its JSON, median seconds."""
DOME = "compas_assembly/dome_assembly.json"
BURR_TARGETS = {"solvable": 0.3, "stuck": 1.0, "all": 60.0}
"""Processor seconds of a six-piece burr's monotone plan (``max_hands=2``), and of all 314."""
PUZZLES = ("CubeInCage", "DraculasDentalDesaster", "PelikanBurr", "AlPackino")


def stack(n: int) -> Assembly:
    """``n`` unit cubes stacked along z, each resting on the one below."""
    parts = []
    for level in range(n):
        cube = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
        cube.apply_translation((0.0, 0.0, level + 0.5))
        parts.append(Part(f"block_{level}", cube))
    return Assembly(parts)


def timed(make: Callable[[], Assembly], repeats: int) -> tuple[float, Plan]:
    """Median seconds of ``plan(make())`` over ``repeats`` runs, and the last plan."""
    seconds, result = [], None
    for _ in range(repeats):
        assembly = make()
        start = time.perf_counter()
        result = plan(assembly)
        seconds.append(time.perf_counter() - start)
    assert result is not None
    return statistics.median(seconds), result


def row(name: str, parts: int, seconds: float, result: Plan) -> None:
    verdict = "feasible" if result.feasible else "infeasible"
    target = TARGETS.get(name)
    versus = "" if target is None else f"  (target <= {target:g} s: {meets(seconds <= target)})"
    print(
        f"{name:<28} {parts:>5} parts {seconds:>8.3f} s  {len(result.steps):>4} steps  "
        f"{result.directions:>6} directions  {verdict}  {parts / seconds:>8.1f} parts/s{versus}"
    )


def end_to_end(path: Path, repeats: int = 5) -> None:
    """Median wall time of ``python -m assemblykit plan <path> --json`` in a new process
    (imports and loading included), against its target, and that of importing trimesh
    alone, the mesh reader every such process needs. Both run with their bytecode
    cached, as an installed package runs (a first run writes it, whatever
    ``PYTHONDONTWRITEBYTECODE`` says)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}

    def median_run(command: list[str]) -> float:
        subprocess.run(command, capture_output=True, check=True, env=env)
        seconds = []
        for _ in range(repeats):
            start = time.perf_counter()
            subprocess.run(command, capture_output=True, check=True, env=env)
            seconds.append(time.perf_counter() - start)
        return statistics.median(seconds)

    median = median_run([sys.executable, "-m", "assemblykit", "plan", str(path), "--json"])
    floor = median_run([sys.executable, "-c", "import trimesh"])
    print(
        f"asap beam, 'assemblykit plan --json' end to end: {median:.2f} s median of {repeats} "
        f"(target <= {END_TO_END_TARGET:g} s: {meets(median <= END_TO_END_TARGET)}); "
        f"'python -c \"import trimesh\"' alone: {floor:.2f} s"
    )


def meets(ok: bool) -> str:
    return "met" if ok else "NOT MET"


def machine() -> str:
    """The machine the figures come from."""
    return (
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
        f"Python {platform.python_version()}, numpy {np.__version__}"
    )


def peak_memory_gb() -> float:
    """Peak resident set of this process, GB (``ru_maxrss`` is in kB on Linux)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2


def dome_memory() -> None:
    """Load and plan the dome alone and print the process's peak memory."""
    path = dataset(DOME)
    if path is None:
        return
    plan(load_assembly(path))
    print(f"{peak_memory_gb():.3f}")


def growth() -> None:
    """Plan times of guillotine packings (random boxes, ``seed = n``) and the fitted
    exponent of time in the number of parts."""
    print("growth (guillotine box packings, median wall time)")
    seconds = []
    for n in PACKING_SIZES:
        median, result = timed(lambda n=n: guillotine_packing(n, seed=n), REPEATS)
        seconds.append(median)
        row(f"box packing of {n}", n, median, result)
    exponent = float(np.polyfit(np.log(PACKING_SIZES), np.log(seconds), 1)[0])
    print(
        f"growth exponent {PACKING_SIZES[0]}-{PACKING_SIZES[-1]} parts: n^{exponent:.2f} "
        f"(target <= n^{GROWTH_TARGET:g}: {meets(exponent <= GROWTH_TARGET)})"
    )


def multi_move(path: Path, solution: int = 0) -> tuple[float, MultiMovePlan]:
    """Seconds of the multi-move plan of one stored solution (loading excluded)."""
    puzzle = load_puzzle(path, solution=solution)
    start = time.perf_counter()
    result = plan_voxels(
        puzzle.names,
        [p.voxels for p in puzzle.pieces],
        [p.group for p in puzzle.pieces],
        reference_level=puzzle.level,
    )
    return time.perf_counter() - start, result


def burrtools_time(seconds: float | None) -> str:
    """BurrTools' recorded time for a problem (whole seconds), or that it stores none."""
    return "not stored" if seconds is None else f"{seconds:g} s"


def puzzles() -> None:
    """Multi-move plans of the BurrTools puzzles, then of all 314 six-piece burrs."""
    print(
        "puzzles (--moves multi, one run each; BurrTools time: what the file records for "
        "solving the whole problem, assemblies and disassemblies)"
    )
    for name in PUZZLES:
        path = dataset(f"burrtools/{name}.xmpuzzle")
        if path is None:
            print(f"{name:<28} skipped (not found)")
            continue
        seconds, result = multi_move(path)
        stored = load_puzzle(path)
        same = "same" if result.level == stored.level else "DIFFERENT"
        print(
            f"{name:<28} {len(result.parts):>5} parts {seconds:>8.3f} s  "
            f"(BurrTools time {burrtools_time(stored.time)})  "
            f"first separation: {result.first_moves} moves, level {result.level} "
            f"({same} as stored {stored.level})  {result.states} states"
        )
    path = dataset("burrtools/SolidSixPieceBurrs.xmpuzzle")
    if path is None:
        print("six-piece burrs              skipped (not found)")
        return
    total, solved, multi, same = 0.0, 0, 0, 0
    count = solution_count(path)
    for solution in range(count):
        seconds, result = multi_move(path, solution)
        total += seconds
        solved += result.feasible
        multi += result.root is not None and max(result.root.levels()) > 1
        same += result.level == result.reference_level
    print(
        f"six-piece burrs: {solved} of {count} taken apart, {multi} need several moves for "
        f"a separation, {same} at the stored level, {total:.2f} s in all "
        f"({total / count * 1000:.1f} ms each; BurrTools time "
        f"{burrtools_time(load_puzzle(path).time)} to find and take apart all of them)"
    )


def monotone_burrs(every: bool) -> None:
    """Monotone plans (``plan(..., max_hands=2)``) of six-piece burrs, processor time
    after loading: solution 0 (solvable), 257 (stuck: no monotone plan), and with
    ``every`` all 314, each next to its target (:data:`BURR_TARGETS`)."""
    path = dataset("burrtools/SolidSixPieceBurrs.xmpuzzle")
    if path is None:
        print("six-piece burrs (monotone)   skipped (not found)")
        return

    def seconds(solution: int) -> tuple[float, bool]:
        assembly = load_burrtools(path, solution=solution)
        start = time.process_time()
        feasible = plan(assembly, max_hands=2).feasible
        return time.process_time() - start, feasible

    seconds(1)  # imports and first-use caches
    for kind, solution in (("solvable", 0), ("stuck", 257)):
        took, feasible = seconds(solution)
        target = BURR_TARGETS[kind]
        print(
            f"six-piece burr {solution:>3} monotone plan ({'feasible' if feasible else 'stuck'}): "
            f"{took:.3f} CPU s (target {target:g} s: {meets(took <= target)})"
        )
    if every:
        runs = [seconds(s) for s in range(solution_count(path))]
        total = sum(t for t, _ in runs)
        stuck = sum(not f for _, f in runs)
        slowest = max(t for t, _ in runs)
        target = BURR_TARGETS["all"]
        print(
            f"all {len(runs)} six-piece burrs, monotone plans: {stuck} stuck, {total:.1f} CPU s "
            f"(slowest {slowest:.2f} s; target {target:g} s: {meets(total <= target)})"
        )


def stuck_chain(links: int = STUCK_LINKS) -> None:
    """A stuck mesh assembly: ``links`` links of the voxel chain of
    ``bench_interlock.py`` and its hook, as meshes moved off the unit lattice; the
    processor time of ``plan`` (the hook lifts out, the links are stuck), next to its
    target (:data:`STUCK_TARGET`)."""
    from bench_interlock import chain

    cells = chain(links)
    shift = np.array([0.37, 0.21, 0.13])
    assembly = Assembly(
        [Part(p.name, p.mesh.copy().apply_translation(shift)) for p in cells.parts.values()]
    )
    start = time.process_time()
    result = plan(assembly)
    took = time.process_time() - start
    print(
        f"stuck mesh chain of {links} links and a hook: {len(result.stuck)} stuck, "
        f"{took:.2f} CPU s (target {STUCK_TARGET:g} s: {meets(took <= STUCK_TARGET)})"
    )


def caged_key() -> Assembly:
    """A 2 x 1 x 1 key in a closed cage whose cavity is one unit longer (stuck)."""
    cage = trimesh.boolean.difference(
        [box_mesh((-1, -1, -1), (4, 2, 2)), box_mesh((0, 0, 0), (3, 1, 1))], engine="manifold"
    )
    return Assembly([Part("cage", cage), Part("key", box_mesh((0, 0, 0), (2, 1, 1)))])


def mesh_puzzles() -> None:
    """Multi-move plans of mesh assemblies (``plan --moves multi`` on meshes)."""
    print("meshes (--moves multi; loading excluded, convex pieces and directions included)")
    steps = ROOT / "src" / "assemblykit" / "examples" / "puzzles" / "key_in_steps"
    cases: list[tuple[str, Callable[[], Assembly]]] = [
        ("key in steps", lambda: load_assembly(steps)),
        ("guillotine packing of 6", lambda: guillotine_packing(6, seed=2)),
        ("guillotine packing of 10", lambda: guillotine_packing(10, seed=2)),
        ("key in a long cage", caged_key),
    ]
    for name, make in cases:
        assembly = make()
        start = time.perf_counter()
        result = plan_meshes(assembly)
        seconds = time.perf_counter() - start
        verdict = "feasible" if result.feasible else "stuck"
        print(
            f"{name:<28} {len(result.parts):>5} parts {seconds:>8.3f} s  "
            f"level {result.level or '-'}  {result.states} states  {verdict}"
        )


def main() -> None:
    if "--dome-memory" in sys.argv:
        dome_memory()
        return
    print(f"machine: {machine()}; shared with other work, wall times are noisy")
    puzzles()
    monotone_burrs("--burrs" in sys.argv)
    stuck_chain()
    mesh_puzzles()
    if "--puzzles" in sys.argv:
        return
    print("planning (median wall time; loading excluded, contacts and blocking included)")
    demo = ROOT / "src" / "assemblykit" / "examples" / "gearbox_demo" / "gearbox.yaml"
    cases = [("gearbox demo", demo, REPEATS)]
    cases += [
        ("asap beam", dataset("asap_beam_assembly"), 1),
        ("compas stack", dataset("compas_assembly/stack_assembly.json"), REPEATS),
        ("compas arch", dataset("compas_assembly/arch_assembly.json"), REPEATS),
        ("compas crossvault", dataset("compas_assembly/crossvault_assembly.json"), REPEATS),
        ("compas dome", dataset(DOME), REPEATS),
    ]
    for name, path, repeats in cases:
        if path is None:
            print(f"{name:<28} skipped (not bundled; set ASSEMBLYKIT_DATA)")
            continue
        seconds, result = timed(lambda p=path: load_assembly(p), repeats)
        row(name, len(result.parts), seconds, result)
    beam = dataset("asap_beam_assembly")
    if beam is not None:
        end_to_end(beam)
    for n in STACK_SIZES:
        seconds, result = timed(lambda n=n: stack(n), REPEATS)
        row(f"synthetic stack of {n}", n, seconds, result)
    if dataset(DOME) is not None:
        alone = subprocess.run(
            [sys.executable, __file__, "--dome-memory"], capture_output=True, text=True, check=True
        )
        peak = float(alone.stdout.split()[-1])
        print(
            f"dome plan peak memory (load and plan alone): {peak:.2f} GB "
            f"(target < {MEMORY_TARGET:g} GB: {meets(peak < MEMORY_TARGET)})"
        )
    growth()


if __name__ == "__main__":
    main()
