"""Throughput on datasets: ``batch`` over 20 copies of the ASAP beam (a mesh folder of 5
parts, ``tests/data/asap_beam_assembly``), each under its own path so that none is
skipped, planned by the local engine with one and with two workers and by the Dask engine
with one and with two (docs/planning.md, "Many assemblies"), and the command line's own
start-up.

Printed next to the targets:

* seconds per beam in the batch (wall clock over 20), against 0.3 s, and the ratio to
  ASAP's 64 s per beam;
* the Dask engine's speed-up with two workers over one, against 1.7;
* one beam's CPU seconds in this process, warm, by stage (loading, contacts, planning):
  two workers reach 0.3 s a beam only below 0.6 s;
* the start-up of ``assemblykit --version`` beyond the imports it needs (the median of 5
  fresh processes, less that of a process importing the same modules), against 0.1 s.

Every batch's answers are compared with the first one's: the same JSON per beam.

Run: python benchmarks/bench_batch.py [--copies N]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from assemblykit.batch import run_batch
from datasets import dataset

ASAP_SECONDS = 64.0
"""ASAP's time for the beam (its paper's setting, measured once on this machine's class)."""


def copies(beam: Path, folder: Path, count: int) -> list[Path]:
    """``count`` copies of the beam's folder under ``folder``."""
    made = []
    for k in range(count):
        target = folder / f"beam_{k:02d}"
        shutil.copytree(beam, target)
        made.append(target)
    return made


def timed_batch(inputs: list[Path], out: Path, engine: str, workers: int) -> tuple[float, dict]:
    """Wall seconds of one batch run, and its results by input."""
    start = time.perf_counter()
    summary = run_batch(inputs, out, engine=engine, workers=workers)  # type: ignore[arg-type]
    seconds = time.perf_counter() - start
    assert summary.statuses == {"ok": len(inputs)}, summary.to_dict()
    results = {
        Path(r["input"]).name: r["result"] for r in map(json.loads, out.read_text().splitlines())
    }
    return seconds, results


def median_seconds(argv: list[str], runs: int = 5) -> float:
    """Median wall seconds of ``argv`` in a fresh process."""
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        subprocess.run(argv, check=True, capture_output=True)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def startup() -> tuple[float, float]:
    """Seconds of ``assemblykit --version`` and of importing what it imports."""
    script = "import assemblykit.cli"
    whole = median_seconds([sys.executable, "-m", "assemblykit", "--version"])
    imports = median_seconds([sys.executable, "-c", script])
    return whole, imports


def stages(beam: Path, runs: int = 8) -> tuple[float, float, float]:
    """Median CPU seconds of one beam's loading, contacts and planning in this process,
    warm (after one run), over ``runs`` runs: where a beam's time goes."""
    from assemblykit.geometry.contacts import assembly_contacts
    from assemblykit.io.assembly import load_assembly
    from assemblykit.planning.planner import plan

    found = []
    for k in range(runs + 1):
        start = time.process_time()
        assembly = load_assembly(beam)
        loaded = time.process_time()
        assembly_contacts(assembly)
        touched = time.process_time()
        plan(assembly).to_dict()
        planned = time.process_time()
        if k:
            found.append((loaded - start, touched - loaded, planned - touched))
    load, contacts, planning = (statistics.median(column) for column in zip(*found, strict=True))
    return load, contacts, planning


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--copies", type=int, default=20)
    count = parser.parse_args().copies
    beam = dataset("asap_beam_assembly")
    assert beam is not None
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory() as scratch:
        root = Path(scratch)
        inputs = copies(beam, root / "beams", count)
        runs: dict[tuple[str, int], float] = {}
        first: dict | None = None
        for engine, workers in (("local", 1), ("local", 2), ("dask", 1), ("dask", 2)):
            out = root / f"{engine}_{workers}.jsonl"
            seconds, results = timed_batch(inputs, out, engine, workers)
            runs[engine, workers] = seconds
            first = first or results
            assert results == first, f"{engine} with {workers} workers answered otherwise"
            per = seconds / count
            print(
                f"batch of {count} beams, {engine} engine, {workers} worker(s): "
                f"{seconds:.2f} s, {per:.3f} s per beam (target <= 0.3), "
                f"{ASAP_SECONDS / per:.0f}x ASAP (target >= 200)"
            )
        speedup = runs["dask", 1] / runs["dask", 2]
        print(f"dask, 2 workers over 1: {speedup:.2f}x (target >= 1.7)")
        print(f"local, 2 workers over 1: {runs['local', 1] / runs['local', 2]:.2f}x")
    load, contacts, planning = stages(beam)
    print(
        f"one beam, warm (median CPU s): {load + contacts + planning:.3f} s, loading {load:.3f}, "
        f"contacts {contacts:.3f}, planning {planning:.3f} (two workers at 0.3 s a beam need "
        "<= 0.6)"
    )
    whole, imports = startup()
    print(
        f"assemblykit --version {whole:.3f} s, its imports {imports:.3f} s: "
        f"{whole - imports:.3f} s of its own (target <= 0.1)"
    )


if __name__ == "__main__":
    main()
