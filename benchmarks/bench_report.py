"""Benchmark: writing the HTML report, the storyboard PNG and the exports of a plan.

Run ``python benchmarks/bench_report.py``. For the bundled gearbox (14 parts), the
crossvault (184 blocks, bundled under tests/data) and the dome (527 blocks, under
``$ASSEMBLYKIT_DATA`` when present) it plans the disassembly, then prints the time and
size of the report with plotly.js embedded (``inline``) and linked (``cdn``), of the
storyboard PNG, of the CSV step table and of the glTF exploded view. The requirement is
a dome report in under 5 s and 25 MB.
"""

from __future__ import annotations

import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from assemblykit.io.assembly import load_assembly
from assemblykit.io.exports import write_gltf, write_plan
from assemblykit.model.assembly import Assembly
from assemblykit.planning.planner import plan
from assemblykit.planning.sequence import Plan
from assemblykit.viz.plots import exploded_view_png
from assemblykit.viz.viewer import write_report
from datasets import dataset

ROOT = Path(__file__).resolve().parents[1]
ASSEMBLIES = {
    "gearbox": ROOT / "src" / "assemblykit" / "examples" / "gearbox_demo" / "gearbox.yaml",
    "crossvault": dataset("compas_assembly/crossvault_assembly.json"),
    "dome": dataset("compas_assembly/dome_assembly.json"),
}
LIMIT_S, LIMIT_MB = 5.0, 25.0


def timed(write: Callable[[], Path]) -> tuple[float, float]:
    """Seconds taken by ``write`` and the size of the file it wrote, in MB."""
    start = time.perf_counter()
    path = write()
    return time.perf_counter() - start, path.stat().st_size / 1e6


def writers(assembly: Assembly, found: Plan, out: Path) -> dict[str, Callable[[], Path]]:
    """What is timed: each output of one plan, by label."""
    return {
        "report inline": lambda: write_report(assembly, found, out / "r.html"),
        "report cdn": lambda: write_report(assembly, found, out / "c.html", plotlyjs="cdn"),
        "storyboard png": lambda: exploded_view_png(assembly, found, out / "s.png"),
        "steps csv": lambda: write_plan(found, out / "p.csv", assembly.tolerance()),
        "exploded glb": lambda: write_gltf(assembly, found, out / "e.glb"),
    }


def main() -> None:
    print(f"{'assembly':<11} {'parts':>5} {'steps':>5}  {'output':<14} {'s':>6} {'MB':>7}")
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder)
        for name, source in ASSEMBLIES.items():
            if source is None:
                print(f"{name:<11} (not found: set ASSEMBLYKIT_DATA)")
                continue
            assembly = load_assembly(source)
            found = plan(assembly)
            outputs = writers(assembly, found, out)
            for label, write in outputs.items():
                seconds, size = timed(write)
                print(
                    f"{name:<11} {len(assembly):>5} {len(found.steps):>5}  {label:<14} "
                    f"{seconds:>6.2f} {size:>7.2f}"
                )
            if name == "dome":
                seconds, size = timed(outputs["report inline"])
                verdict = "ok" if seconds < LIMIT_S and size < LIMIT_MB else "TOO SLOW OR LARGE"
                print(f"dome report: {seconds:.2f} s, {size:.2f} MB ({verdict})")


if __name__ == "__main__":
    main()
