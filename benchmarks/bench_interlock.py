"""Interlocking tests (docs/interlocking.md): run ``python benchmarks/bench_interlock.py``.

Prints the median wall and CPU time of ``interlocking(assembly)`` over ``REPEATS`` runs,
each on a freshly built assembly (contacts and blocking graphs included):

* a 100-part voxel chain, generated here: 99 links of 5 x 3 cells with two one-cell
  holes, each through a hole of the next and holding that link's end in its own, so
  that two linked links block each other along every direction, and a hook hanging in
  the first link's free hole, which only lifts out (+z). It is interlocking with the
  hook as key (after it the links are deadlocked), decided next to its target of 5 s;
* the bundled examples (examples/interlocking), each with its verdict.

``--all`` also times the chain with extended translations and rigid motions (no target).
The machine the figures come from is printed first.
"""

from __future__ import annotations

import os
import platform
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from assemblykit.io.assembly import load_assembly
from assemblykit.io.burrtools import voxel_mesh
from assemblykit.io.polygons import load_polygons
from assemblykit.model.assembly import Assembly, Part
from assemblykit.planning.interlocking import Interlocking, interlocking

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "src" / "assemblykit" / "examples" / "interlocking"
REPEATS = 3
LINKS = 99
TARGET = 5.0
"""Seconds to decide the 100-part chain (median wall time)."""


def link_cells(start: int, flat: bool) -> np.ndarray:
    """The cells of a link starting at x = ``start``: 5 long, 3 wide, holes at its
    second and fourth cells, lying in the plane z = 0 (``flat``) or y = 0."""
    cells = [
        (start + a, b, 0) if flat else (start + a, 0, b)
        for a in range(5)
        for b in (-1, 0, 1)
        if not (b == 0 and a in (1, 3))
    ]
    return np.array(cells, dtype=np.int64)


def chain(links: int = LINKS) -> Assembly:
    """``links`` links, each 3 cells further along x and turned a quarter about x from
    the one before, and a hook in the first link's free hole (module docstring)."""
    parts = [
        Part(f"link_{k + 1:02d}", voxel_mesh(link_cells(3 * k, k % 2 == 0))) for k in range(links)
    ]
    hook = np.array([(1, 0, 0), (1, 0, 1), (2, 0, 1)], dtype=np.int64)
    parts.append(Part("hook", voxel_mesh(hook)))
    return Assembly(parts, units="unit")


def timed(
    make: Callable[[], object], motion: str, repeats: int = REPEATS
) -> tuple[float, float, Interlocking]:
    """Median wall and CPU seconds of ``interlocking(make(), motion=motion)``, and the
    last result."""
    walls, cpus, result = [], [], None
    for _ in range(repeats):
        assembly = make()
        wall, cpu = time.perf_counter(), time.process_time()
        result = interlocking(assembly, motion=motion)  # type: ignore[arg-type]
        walls.append(time.perf_counter() - wall)
        cpus.append(time.process_time() - cpu)
    assert result is not None
    return statistics.median(walls), statistics.median(cpus), result


def row(
    name: str, parts: int, wall: float, cpu: float, result: Interlocking, target: float | None
) -> None:
    keys = f"key {', '.join(result.keys)}" if result.interlocking else "no key"
    versus = (
        ""
        if target is None
        else f"  (target <= {target:g} s: {'met' if wall <= target else 'NOT MET'})"
    )
    print(
        f"{name:<36} {parts:>4} parts {wall:>7.3f} s wall {cpu:>7.3f} s CPU  "
        f"{result.verdict} ({keys}){versus}"
    )


def main() -> None:
    print(
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
        f"Python {platform.python_version()}, numpy {np.__version__}; shared, wall times are noisy"
    )
    wall, cpu, result = timed(chain, "infinitesimal")
    row("voxel chain, infinitesimal", LINKS + 1, wall, cpu, result, TARGET)
    examples: list[tuple[str, Callable[[], object]]] = [
        ("nested_locks.xmpuzzle", lambda: load_assembly(EXAMPLES / "nested_locks.xmpuzzle")),
        ("lipped_joint.yaml", lambda: load_polygons(EXAMPLES / "lipped_joint.yaml")),
        ("diagonal_tunnel", lambda: load_assembly(EXAMPLES / "diagonal_tunnel")),
    ]
    for name, make in examples:
        for motion in ("infinitesimal", "extended"):
            wall, cpu, result = timed(make, motion)
            row(f"{name}, {motion}", len(result.parts), wall, cpu, result, None)
    if "--all" in sys.argv[1:]:
        for motion in ("extended", "rigid"):
            wall, cpu, result = timed(chain, motion, repeats=1)
            row(f"voxel chain, {motion}", LINKS + 1, wall, cpu, result, None)


if __name__ == "__main__":
    main()
