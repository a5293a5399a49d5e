"""Run benchmark scripts against two source trees and print their figures side by side.

    python benchmarks/compare.py --before /path/to/other/checkout bench_algebra.py ...

Each script runs as a fresh process, once as the ``--before`` checkout has it (its
``benchmarks/`` script on its ``src/``) and once as this checkout has it, alternating
``--rounds`` times so that both see the same machine load; the scripts' own arguments
follow ``--``. Lines of the two
outputs are matched by their text with the numbers taken out; for each figure the
medians over the rounds are printed before and after with their ratio, and a figure that
moved by more than ``--threshold`` (10 % by default) is marked ``*``. Figures that are
not times (counts, sizes) are compared the same way: they should not move at all.
"""

from __future__ import annotations

import argparse
import os
import platform
import re
import statistics
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

HERE = Path(__file__).resolve().parent
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")


def run(script: str, root: Path, args: Sequence[str]) -> list[str]:
    """The output lines of one run of the checkout ``root``'s ``script`` on its ``src/``."""
    env = {**os.environ, "PYTHONPATH": str(root / "src")}
    done = subprocess.run(
        [sys.executable, str(root / "benchmarks" / script), *args],
        env=env,
        capture_output=True,
        text=True,
        check=False,
        cwd=root,
    )
    lines = [line for line in done.stdout.splitlines() if line.strip()]
    if done.returncode != 0:
        # what the script printed before it failed still compares
        tail = (done.stderr.strip().splitlines() or ["no output"])[-1]
        lines.append(f"FAILED ({done.returncode}): {tail}")
    return lines


def figures(runs: list[list[str]]) -> dict[str, list[list[float]]]:
    """For each line shape (text without numbers), the numbers of that line in each run."""
    table: dict[str, list[list[float]]] = {}
    for lines in runs:
        seen: dict[str, int] = {}
        for line in lines:
            shape = NUMBER.sub("#", line)
            seen[shape] = seen.get(shape, 0) + 1
            key = f"{shape}\x00{seen[shape]}"
            table.setdefault(key, []).append([float(x) for x in NUMBER.findall(line)])
    return table


def medians(rows: list[list[float]]) -> list[float]:
    """Column medians of rows of equal length (the shortest row decides)."""
    width = min(len(row) for row in rows)
    return [statistics.median(row[i] for row in rows) for i in range(width)]


def compare(script: str, before: Path, args: Sequence[str], rounds: int, threshold: float) -> int:
    """Print one script's figures before and after; the number of figures that moved."""
    after = HERE.parent
    old_runs: list[list[str]] = []
    new_runs: list[list[str]] = []
    for _ in range(rounds):
        old_runs.append(run(script, before, args))
        new_runs.append(run(script, after, args))
    old, new = figures(old_runs), figures(new_runs)
    moved = 0
    print(f"== {script} {' '.join(args)} ({rounds} rounds, medians)")
    for key in dict.fromkeys([*old, *new]):
        shape = key.split("\x00")[0]
        if key not in old or key not in new:
            side = "before only" if key in old else "after only"
            print(f"   {side}: {shape}")
            continue
        a, b = medians(old[key]), medians(new[key])
        if not a:
            print(f"   {shape}")
            continue
        cells = []
        for x, y in zip(a, b, strict=False):
            ratio = y / x if x else (1.0 if y == 0 else float("inf"))
            mark = "*" if abs(ratio - 1) > threshold else ""
            moved += bool(mark)
            cells.append(f"{x:g} -> {y:g} ({ratio:.2f}x){mark}")
        label = shape.replace("#", "{}").strip()
        print(f"   {label[:70]}\n      " + "; ".join(cells))
    return moved


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=Path, required=True, help="the other checkout's root")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--threshold", type=float, default=0.10)
    parser.add_argument("scripts", nargs="+", help="benchmark scripts, then -- and their args")
    argv = sys.argv[1:]
    extra: list[str] = []
    if "--" in argv:
        cut = argv.index("--")
        argv, extra = argv[:cut], argv[cut + 1 :]
    options = parser.parse_args(argv)
    print(f"machine: {platform.node()}, {os.cpu_count()} cores, Python {platform.python_version()}")
    moved = sum(
        compare(script, options.before, extra, options.rounds, options.threshold)
        for script in options.scripts
    )
    print(f"figures moved by more than {options.threshold:.0%}: {moved}")


if __name__ == "__main__":
    main()
