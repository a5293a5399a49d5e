"""Robustness benchmark: mesh answers under vertex noise.

Every vertex of the bundled mesh assemblies is moved by seeded uniform noise of
amplitude ``level`` x the model's size per axis: 1e-8 with the default tolerance, 1e-6
with ``--tolerance 5e-6`` (five times the noise, docs/geometry.md). Printed per
assembly: flat coplanar groups (planar faces), contact pairs and planar patches, whether
the motion kinds are those of the exact meshes, and the ``plan`` time (median of three,
contacts included) next to the exact meshes' time.

Run: python benchmarks/bench_robustness.py
"""

from __future__ import annotations

import statistics
import timeit
from pathlib import Path

import numpy as np

import assemblykit
from assemblykit.geometry.contacts import assembly_contacts, stack_parts
from assemblykit.geometry.precision import combined, coordinate_precision
from assemblykit.geometry.recognition import segment
from assemblykit.io.assembly import load_assembly
from assemblykit.model.assembly import Assembly, Part
from assemblykit.tolerance import Tolerance
from datasets import dataset

EXAMPLES = Path(assemblykit.__file__).parent / "examples"
CASES = (
    ("gearbox demo", EXAMPLES / "gearbox_demo" / "gearbox.yaml"),
    ("hinge", EXAMPLES / "motion" / "hinge" / "hinge.yaml"),
    ("gearbox (Liu 1997)", EXAMPLES / "motion" / "gearbox" / "gearbox.yaml"),
    ("interlock", EXAMPLES / "motion" / "interlock" / "interlock.yaml"),
    ("compas stack", dataset("compas_assembly/stack_assembly.json")),
    ("compas arch", dataset("compas_assembly/arch_assembly.json")),
)
LEVELS = ((1e-8, None), (1e-6, Tolerance.relative(5e-6)))


def noisy(asm: Assembly, level: float, seed: int = 7) -> Assembly:
    """``asm`` with seeded uniform vertex noise of amplitude ``level`` x its size."""
    rng = np.random.default_rng(seed)
    parts = []
    for part in asm.parts.values():
        mesh = part.mesh.copy()
        vertices = np.asarray(mesh.vertices, dtype=np.float64)
        mesh.vertices = vertices + rng.uniform(-1.0, 1.0, vertices.shape) * level * asm.scale
        parts.append(Part(part.name, mesh, part.pose, source=part.source))
    measured = [coordinate_precision(p.mesh.vertices) for p in parts]
    if asm.precision is not None:
        measured.append(asm.precision)
    return Assembly(parts, units=asm.units, source=asm.source, precision=combined(measured))


def figures(asm: Assembly, tol: Tolerance | None) -> tuple[int, int, int, dict[str, str], float]:
    """Flat groups, contact pairs, planar patches, motion kinds and the plan time."""
    stack = stack_parts(p.mesh for p in asm)
    groups = int(segment(stack.vertices, stack.faces, asm.tolerance(tol)).flat.sum())
    contacts = assembly_contacts(asm, tol)
    patches = sum(len(c.planar) for c in contacts)
    parts = assemblykit.motion(asm, tol=tol).to_dict()["parts"]
    kinds = {name: entry["motion"] for name, entry in parts.items()}

    def planned() -> object:
        fresh = Assembly(
            list(asm.parts.values()), units=asm.units, source=asm.source, precision=asm.precision
        )
        return assemblykit.plan(fresh, tol=tol)

    seconds = statistics.median(timeit.repeat(planned, number=1, repeat=3))
    return groups, len(contacts), patches, kinds, seconds


def main() -> None:
    for name, path in CASES:
        if path is None:
            print(f"{name}: data not present, skipped")
            continue
        exact = load_assembly(path)
        groups, pairs, patches, kinds, seconds = figures(exact, None)
        print(
            f"{name}: exact: {groups} planar groups, {pairs} contact pairs, "
            f"{patches} planar patches, plan {seconds:.2f} s"
        )
        for level, tol in LEVELS:
            n_groups, n_pairs, n_patches, n_kinds, n_seconds = figures(noisy(exact, level), tol)
            given = "default tolerance" if tol is None else f"--tolerance {tol.rel_length:g}"
            print(
                f"  noise {level:g} ({given}): {n_groups} planar groups, {n_pairs} contact "
                f"pairs, {n_patches} planar patches, motion kinds "
                f"{'as exact' if n_kinds == kinds else 'CHANGED'}, plan {n_seconds:.2f} s "
                f"({n_seconds / seconds:.1f}x exact)"
            )


if __name__ == "__main__":
    main()
