"""Real CAD from STEP: the 144-part laser-cut gripper (``step_gripper/gripper.step``,
beside the checkout or under ``$ASSEMBLYKIT_DATA``) and the bundled STEP examples, each
loaded, its interfering parts resolved as ``plan`` does (docs/planning.md, "Interfering
parts"), the contacts of the parts so prepared found, and planned by extended
translations: the stages of the ``plan`` command, each timed once.

Printed per file: parts, the loader's warnings and skipped items, the interfering pairs
and what was done about them, the plan (feasible or the stuck parts, steps), the CPU
seconds of each stage (of every thread of the process: manifold3d's booleans run on one
thread unless ``ASSEMBLYKIT_BOOLEAN_THREADS=all``, docs/geometry.md, "The threads of
the booleans"), the wall clock seconds of all of them and the peak resident memory of
the process so far, next to the targets: a file of up to 34 parts loaded, contacts and
plan in <= 10 CPU s and <= 1 GB, 144 parts in <= 30 CPU s. The gripper is planned to the
end, or for its first ``--gripper-steps`` steps, the parts not yet taken apart counted
as unfinished.

Two irises are drawn here as a CAD user draws one (:func:`iris`): a base ring, a pivot
pin per blade at its hole's diameter, flat blades in one layer each drawn over its
neighbours (interference left as it is: the blades leave as one, the plan names an
interfering pair), and a cover ring; 12 blades (26 parts) and 16 blades (34 parts).

Run: python benchmarks/bench_step.py [--gripper-steps N]
"""

from __future__ import annotations

import argparse
import math
import resource
import tempfile
import time
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

import assemblykit
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.geometry.overlaps import resolve_overlaps
from assemblykit.io.assembly import load_assembly
from assemblykit.planning.planner import plan
from datasets import dataset

EXAMPLES = Path(assemblykit.__file__).parent / "examples"
T = TypeVar("T")


def peak_mb() -> float:
    """Peak resident memory of this process so far, in MB (Linux reports kB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def timed_stage(
    stage: str, run: Callable[[], T], times: dict[str, float], walls: dict[str, float]
) -> T:
    """Run ``run()``, recording its CPU seconds under ``stage`` in ``times`` and its wall
    clock seconds in ``walls`` (the CPU time is the sum over the process's threads)."""
    start, wall = time.process_time(), time.perf_counter()
    result = run()
    times[stage] = time.process_time() - start
    walls[stage] = time.perf_counter() - wall
    return result


def bench(path: Path, max_steps: int | None = None) -> None:
    """Load, resolve, plan ``path`` (its first ``max_steps`` steps) and print the
    figures."""
    times: dict[str, float] = {}
    walls: dict[str, float] = {}
    loaded = timed_stage("load", lambda: load_assembly(path), times, walls)
    prepared = timed_stage("overlaps", lambda: resolve_overlaps(loaded), times, walls)
    # the contacts of the parts as planned (cut, joined), which the plan then reads
    timed_stage("contacts", lambda: assembly_contacts(prepared), times, walls)
    result = timed_stage(
        "plan", lambda: plan(prepared, max_and_or_parts=0, max_steps=max_steps), times, walls
    )
    total = sum(times.values())
    target = 10.0 if len(loaded.parts) <= 34 else 30.0
    resolutions = Counter(o.resolution.split(" ")[0] or "left" for o in prepared.overlaps)
    verdict = "feasible" if result.feasible else f"{len(result.stuck)} parts stuck"
    if result.unfinished:
        verdict = (
            f"stopped after {max_steps} steps, {len(result.unfinished)} parts not yet taken apart"
        )
    print(
        f"{path.name}: {len(loaded.parts)} parts, {len(loaded.warnings)} warnings, "
        f"{len(loaded.skipped)} skipped"
    )
    print(f"  interfering pairs: {len(prepared.overlaps)} {dict(resolutions)}")
    print(f"  plan: {verdict}, {len(result.steps)} steps")
    for lock in result.interlocked:
        print(f"    {', '.join(lock.parts)}: {lock.reason}; holding {', '.join(lock.held) or '-'}")
    stages = ", ".join(f"{k} {v:.1f}" for k, v in times.items())
    print(
        f"  CPU s: {stages}; total {total:.1f} (target <= {target:.0f}); "
        f"wall s {sum(walls.values()):.1f}; peak memory {peak_mb():.0f} MB (target <= 1024)"
    )


def iris(path: Path, blades: int) -> Path:
    """An iris aperture written to ``path`` as STEP (module docstring): a base ring (radii
    20 and 40, 3 thick), on a circle of radius 30 a pin of radius 1 per blade through
    holes of its diameter in the base and the cover ring, and blades 0.5 thick between
    radii 22 and 36, each a 60 degree sector from 15 degrees before its pin, with a hole
    of the pin's diameter at its own pin and of radius 1.5 at the others."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
    from OCP.TopoDS import TopoDS_Compound

    def cylinder(x: float, y: float, z: float, radius: float, height: float, turn: float = 0.0):
        seam = gp_Dir(math.cos(turn), math.sin(turn), 0.0)
        frame = gp_Ax2(gp_Pnt(x, y, z), gp_Dir(0.0, 0.0, 1.0), seam)
        return BRepPrimAPI_MakeCylinder(frame, radius, height).Shape()

    def sector(start: float) -> object:
        span = math.radians(60.0)
        frame = gp_Ax2(
            gp_Pnt(0, 0, 3.0), gp_Dir(0, 0, 1), gp_Dir(math.cos(start), math.sin(start), 0)
        )
        low = gp_Ax2(
            gp_Pnt(0, 0, 2.0), gp_Dir(0, 0, 1), gp_Dir(math.cos(start), math.sin(start), 0)
        )
        outer = BRepPrimAPI_MakeCylinder(frame, 36.0, 0.5, span).Shape()
        return BRepAlgoAPI_Cut(
            outer, BRepPrimAPI_MakeCylinder(low, 22.0, 2.5, span).Shape()
        ).Shape()

    def cut(a, b):
        return BRepAlgoAPI_Cut(a, b).Shape()

    angles = [2 * math.pi * k / blades for k in range(blades)]
    pins = [(30 * math.cos(a), 30 * math.sin(a)) for a in angles]
    base = cut(cylinder(0, 0, 0, 40, 3), cylinder(0, 0, -1, 20, 5))
    cover = cut(cylinder(0, 0, 3.5, 40, 3), cylinder(0, 0, 2, 20, 8))
    shafts, leaves = [], []
    for k, (a, (x, y)) in enumerate(zip(angles, pins, strict=True)):
        base = cut(base, cylinder(x, y, -1, 1.0, 5))
        cover = cut(cover, cylinder(x, y, 2, 1.0, 8))
        shafts.append(cylinder(x, y, 0.5, 1.0, 5.5, turn=0.1 * k))
        leaf = sector(a - math.radians(15.0))
        for j, (u, v) in enumerate(pins):
            leaf = cut(leaf, cylinder(u, v, 2, 1.0 if j == k else 1.5, 3, turn=0.05 * k))
        leaves.append(leaf)
    compound, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(compound)
    for shape in (base, *shafts, *leaves, cover):
        builder.Add(compound, shape)
    from OCP.Message import Message, Message_Gravity

    # the writer's statistics (its trace) would fill the figures' lines: failures only
    for printer in Message.DefaultMessenger_s().Printers():
        printer.SetTraceLevel(Message_Gravity.Message_Fail)
    writer = STEPControl_Writer()
    writer.Transfer(compound, STEPControl_AsIs)
    writer.Write(str(path))
    return path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--gripper-steps", type=int, default=0)
    steps = parser.parse_args().gripper_steps
    for path in sorted(EXAMPLES.rglob("*.step")):
        bench(path)
    with tempfile.TemporaryDirectory() as folder:
        for blades in (12, 16):
            bench(iris(Path(folder) / f"iris_{blades}_blades.step", blades))
    gripper = dataset("step_gripper/gripper.step")
    if gripper is None:
        print("gripper.step: skipped (not beside the checkout; set ASSEMBLYKIT_DATA)")
    else:
        bench(gripper, steps or None)


if __name__ == "__main__":
    main()
