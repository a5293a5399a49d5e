"""Static equilibrium under gravity and stability-aware planning.

Run ``python benchmarks/bench_stability.py``. Figures (wall time, one run each, loading
and contacts excluded unless said):

* equilibrium of the whole dome (527 blocks) and crossvault (184 blocks): assembling the
  sparse equations, then one slack program (HiGHS);
* plans with gravity: the ASAP beam (also without gravity) and the COMPAS arch with three
  holds, each followed by the time of the stability work alone: assembling the
  equations and checking every state of the plan once;
* the crossvault plan with gravity runs only when its whole assembly stands.

The dome is skipped unless ``$ASSEMBLYKIT_DATA`` holds
``compas_assembly/dome_assembly.json``.
"""

from __future__ import annotations

import os
import platform
import time
from pathlib import Path

import numpy as np
import scipy

from assemblykit.io.assembly import load_assembly
from assemblykit.planning.sequence import plan
from assemblykit.planning.stability import Gravity, equilibrium_model
from datasets import dataset


def machine() -> str:
    """CPU, cores, Python and library versions."""
    return (
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
        f"Python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}"
    )


def whole(name: str, path: Path | None) -> bool | None:
    """Time the equilibrium of a whole assembly; whether it stands (None if absent)."""
    if path is None:
        print(f"{name:<24} skipped (not bundled; set ASSEMBLYKIT_DATA)")
        return None
    assembly = load_assembly(path)
    assembly.contacts()
    start = time.perf_counter()
    model = equilibrium_model(assembly)
    built = time.perf_counter() - start
    found = model.check()
    solved = time.perf_counter() - start - built
    columns = model.normal_part.shape[1]
    print(
        f"{name:<24} {len(assembly.names):>4} parts {columns:>7} generators  "
        f"equations {built:7.3f} s  program {solved:8.3f} s  "
        f"{'stands' if found.stands else f'{len(found.would_fall)} parts would fall'}"
    )
    return found.stands


def planned(name: str, path: Path | None, gravity: Gravity | None) -> None:
    """Time a plan (contacts included) with or without gravity."""
    if path is None:
        print(f"{name:<24} skipped (not bundled; set ASSEMBLYKIT_DATA)")
        return
    assembly = load_assembly(path)
    start = time.perf_counter()
    result = plan(assembly, gravity=gravity, max_and_or_parts=0)
    seconds = time.perf_counter() - start
    verdict = "no gravity"
    if result.gravity is not None:
        holds = max((len(s.stability.held) for s in result.steps if s.stability), default=0)
        stable = "every state stands" if result.gravity.stable else "some states fall"
        verdict = f"{stable}, at most {holds} held"
    steps = len(result.steps)
    print(f"{name:<24} {len(result.parts):>4} parts {seconds:8.3f} s  {steps} steps, {verdict}")
    if result.gravity is not None:
        start = time.perf_counter()
        model = equilibrium_model(assembly)
        for step in result.steps:
            assert step.stability is not None
            model.check(step.rest, set(step.stability.held) & set(step.rest))
        seconds = time.perf_counter() - start
        print(f"{'':<24} equations and one program per state: {seconds:.3f} s")


def main() -> None:
    print(f"machine: {machine()}")
    print("equilibrium of whole assemblies (one run; contacts excluded)")
    whole("compas arch", dataset("compas_assembly/arch_assembly.json"))
    whole("compas dome", dataset("compas_assembly/dome_assembly.json"))
    vault_stands = whole("compas crossvault", dataset("compas_assembly/crossvault_assembly.json"))
    print("plans (one run; contacts and blocking included)")
    beam = dataset("asap_beam_assembly")
    planned("asap beam", beam, None)
    planned("asap beam, gravity", beam, Gravity())
    planned("compas arch, 3 holds", dataset("compas_assembly/arch_assembly.json"), Gravity(holds=3))
    if vault_stands:
        planned(
            "crossvault, 3 holds",
            dataset("compas_assembly/crossvault_assembly.json"),
            Gravity(holds=3),
        )
    else:
        print("crossvault with gravity   skipped: the whole vault does not stand in the model")


if __name__ == "__main__":
    main()
