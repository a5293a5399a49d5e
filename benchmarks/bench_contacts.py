"""Contacts benchmark: the 527-block dome of compas_assembly, grids of unit boxes
showing how the cost grows with the number of parts (near-linear: the broad phase keeps
only touching pairs, the narrow phase is vectorised over all of them), and the ASAP beam
loaded with and without settling its rounded poses (largest shared volume per pair).

Run: python benchmarks/bench_contacts.py
"""

from __future__ import annotations

import statistics
import time
import timeit
from collections.abc import Callable
from pathlib import Path

import numpy as np
import trimesh

from assemblykit.geometry.contacts import assembly_contacts, find_contacts
from assemblykit.geometry.interference import overlap_volume
from assemblykit.io.assembly import load_assembly
from assemblykit.io.compas import load_compas
from assemblykit.model.assembly import Assembly, Part
from datasets import dataset

DOME = dataset("compas_assembly/dome_assembly.json")
ASAP = dataset("asap_beam_assembly")
ASAP_CONTACTS_TARGET = 0.2
"""Contacts of the freshly loaded ASAP beam (surfaces recognised included), seconds."""
GRID_SIZES = (1000, 2500, 5000, 10000)


def median_time(fn: Callable[[], object], repeats: int) -> float:
    """Median wall time of ``repeats`` calls (garbage collection left on, as in use)."""
    return statistics.median(timeit.repeat(fn, "gc.enable()", number=1, repeat=repeats))


def grid(n: int) -> Assembly:
    """``n`` unit boxes packed face to face in a near-cubic grid."""
    side = int(np.ceil(n ** (1 / 3)))
    unit = trimesh.creation.box(extents=[1, 1, 1])
    parts = []
    for k, cell in enumerate(np.ndindex(side, side, side)):
        if k == n:
            break
        mesh = trimesh.Trimesh(unit.vertices + np.array(cell), unit.faces, process=False)
        parts.append(Part(f"b{k}", mesh))
    return Assembly(parts)


def largest_share(assembly: Assembly) -> float:
    """The largest volume a touching pair shares, over the smaller part's volume."""
    return max(
        overlap_volume(assembly[c.a].mesh, assembly[c.b].mesh)
        / min(assembly[c.a].volume, assembly[c.b].volume)
        for c in assembly_contacts(assembly)
    )


def fresh_contacts(path: Path) -> float:
    """Seconds of :func:`find_contacts` on a freshly loaded assembly (no kept surfaces)."""
    assembly = load_assembly(path)
    start = time.perf_counter()
    find_contacts(assembly)
    return time.perf_counter() - start


def asap() -> None:
    if ASAP is None:
        print("asap beam: data not present, skipped")
        return
    seconds = statistics.median(fresh_contacts(ASAP) for _ in range(5))
    print(
        f"asap beam contacts (surfaces recognised included): {seconds:.3f} s median "
        f"(target <= {ASAP_CONTACTS_TARGET:g} s: "
        f"{'met' if seconds <= ASAP_CONTACTS_TARGET else 'NOT MET'})"
    )
    for settle in (False, True):
        seconds = median_time(lambda settle=settle: load_assembly(ASAP, settle=settle), 3)
        beam = load_assembly(ASAP, settle=settle)
        print(
            f"asap beam {'settled' if settle else 'as written'}: load {seconds:.2f} s, "
            f"largest shared volume {largest_share(beam):.2g} of the smaller part"
        )


def main() -> None:
    if DOME is not None:
        load = median_time(lambda: load_compas(DOME), 3)
        dome = load_compas(DOME)
        found = find_contacts(dome)
        seconds = median_time(lambda: find_contacts(dome), 3)
        print(
            f"dome: {len(dome)} blocks, {len(found)} contacts: contacts {seconds:.2f} s "
            f"(load, measuring the joints' precision {dome.precision.length:.2g}: {load:.2f} s)"
        )
    else:
        print(
            "dome: not bundled, skipped (set ASSEMBLYKIT_DATA to a folder holding compas_assembly/)"
        )
    rates = []
    for n in GRID_SIZES:
        boxes = grid(n)
        count = len(find_contacts(boxes))
        cpu = time.process_time()
        seconds = median_time(lambda boxes=boxes: find_contacts(boxes), 3 if n <= 2500 else 1)
        cpu = (time.process_time() - cpu) / (3 if n <= 2500 else 1)
        rates.append(cpu / n)
        print(
            f"grid: {n:6d} boxes, {count:6d} contacts: {seconds:6.2f} s wall, "
            f"{cpu:6.2f} s CPU ({1e3 * cpu / n:.3f} ms CPU per box; the machine is shared)"
        )
    print(
        f"CPU time per box, {GRID_SIZES[-1]} vs {GRID_SIZES[0]} boxes: "
        f"ratio {rates[-1] / rates[0]:.2f} (1.0 = linear)"
    )
    asap()


if __name__ == "__main__":
    main()
