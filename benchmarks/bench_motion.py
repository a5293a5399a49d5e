"""Benchmark: the motion of every part of a 500-part assembly (Liu 1997).

Run ``python benchmarks/bench_motion.py``. The assembly is a floor slab carrying a wall
of 2 x 1 x 1 blocks, 5 courses of 10 rows of 10, in running bond (every other course
shifted by half a block along x, so that a block touches two blocks above and two
below), cut to 500 parts. It prints the time to find the contacts (cached on the
assembly), the median time of :func:`assemblykit.motion` over the repeats, the rate in
parts per second, and how many parts got each motion kind. The requirement is at most
5 s for all 500 parts.

It then times the compound-feature group of single parts touching many planes (the
slow case of the permutation method, Liu 1997 Props 3.2.6-5.0.9): a block boxed in on
all six sides (24 components), and the same with two or three stepped faces more.
"""

from __future__ import annotations

import statistics
import time
from collections import Counter

import numpy as np
import trimesh

from assemblykit.features import compound_group
from assemblykit.features.primitives import Plane
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.model.assembly import Assembly, Part
from assemblykit.motion.freedom import motion
from assemblykit.tolerance import Tolerance

COURSES, ROWS, BLOCKS = 5, 10, 10
REPEATS = 3
LIMIT_S = 5.0


def _box(name: str, lo: tuple[float, float, float], hi: tuple[float, float, float]) -> Part:
    mesh = trimesh.creation.box(extents=np.subtract(hi, lo))
    mesh.apply_translation(np.add(lo, hi) / 2.0)
    return Part(name, mesh)


def wall() -> Assembly:
    """The floor slab and 499 blocks: 5 courses of 10 rows of 10 blocks (2 x 1 x 1)
    in running bond, minus one block so that the total is 500 parts."""
    parts = [_box("floor", (-2.0, -1.0, -1.0), (2.0 * BLOCKS + 2.0, ROWS + 1.0, 0.0))]
    for course in range(COURSES):
        shift = 1.0 if course % 2 else 0.0
        for row in range(ROWS):
            for block in range(BLOCKS):
                x0 = 2.0 * block + shift
                lo = (x0, float(row), float(course))
                parts.append(
                    _box(f"b{course}_{row}_{block}", lo, (x0 + 2.0, row + 1.0, course + 1.0))
                )
    return Assembly(parts[:500])


def boxed_planes(steps: int) -> list[Plane]:
    """The six faces of a 2 x 2 x 2 cube about the origin (outward normals), plus
    ``steps`` (0 to 3) parallel faces 3 away along +x, +z, +y."""
    planes = [Plane(point=s * axis, normal=s * axis) for axis in np.eye(3) for s in (1.0, -1.0)]
    extra = [np.eye(3)[0], np.eye(3)[2], np.eye(3)[1]][:steps]
    return planes + [Plane(point=3.0 * axis, normal=axis) for axis in extra]


def many_planes() -> None:
    """Median time of the compound-feature group of parts touching 6 to 9 planes."""
    tol = Tolerance().with_scale(20.0)
    for steps in (0, 2, 3):
        planes = boxed_planes(steps)
        times = []
        for _ in range(REPEATS):
            start = time.perf_counter()
            group = compound_group(planes, tol)
            times.append(time.perf_counter() - start)
        print(
            f"{len(planes)} planes: median {statistics.median(times) * 1e3:.0f} ms "
            f"({group.describe()}, {group.n_components} components)"
        )


def main() -> None:
    """Time contacts and motions; print medians, rate and the kinds found."""
    assembly = wall()
    start = time.perf_counter()
    contacts = assembly_contacts(assembly)
    contact_s = time.perf_counter() - start
    times = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        report = motion(assembly)
        times.append(time.perf_counter() - start)
    median = statistics.median(times)
    kinds = Counter(m.kind for m in report.motions.values())
    print(f"parts: {len(assembly)}, contacts: {len(contacts)} (found in {contact_s:.2f} s)")
    print(f"motion of every part: median {median:.2f} s over {REPEATS} runs")
    print(f"rate: {len(assembly) / median:.0f} parts/s")
    print(f"kinds: {dict(kinds)}")
    print(f"within {LIMIT_S:.0f} s: {'yes' if median + contact_s <= LIMIT_S else 'no'}")
    many_planes()


if __name__ == "__main__":
    main()
