"""The JSON answers of every bundled example, one file each, for comparing installs.

Run ``python benchmarks/answers.py OUT`` with one install, again with another, then
``diff -r OUT1 OUT2``: plans, verdicts and poses must be identical (the deterministic
ordering rule and the signs of docs/architecture.md, "Tolerances"). Keys that measure
the run rather than the answer (times, versions) are left out. The commands run in this
process, one after the other (the imports are paid once); ``--jobs 2`` shares them
between two processes, with the same files written.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

from assemblykit.cli import main

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "src" / "assemblykit" / "examples"
DATA = ROOT / "tests" / "data"
"""The files of this checkout, whichever install runs them (their paths are in answers)."""

VOLATILE = {"seconds", "elapsed", "time", "times", "version", "timings"}
"""Keys about the run, not the answer."""


def jobs() -> list[tuple[str, list[str]]]:
    """(output name, command arguments) for every bundled example."""
    # the longest first, so that --jobs shares out the others: the first 20 steps of the
    # cross vault under gravity (its whole plan, 183 steps and minutes long, is compared
    # the same way by hand: docs/planning.md, "Under gravity")
    vault = DATA / "compas_assembly" / "crossvault_assembly.json"
    found: list[tuple[str, list[str]]] = [
        (
            "plan_crossvault_gravity_20",
            ["plan", str(vault), "--gravity", "--tolerance", "5e-5", "--max-steps", "20"],
        )
    ]
    for task in sorted((EXAMPLES / "tasks").glob("*.*")):
        found.append((f"solve_{task.name}", ["solve", str(task)]))
    for problem in sorted((EXAMPLES / "mating").glob("*.yaml")):
        found.append((f"mate_{problem.name}", ["mate", str(problem)]))
    for folder in sorted(p for p in (EXAMPLES / "motion").iterdir() if p.is_dir()):
        for spec in sorted(folder.glob("*.yaml")):
            found.append((f"motion_{folder.name}_{spec.name}", ["motion", str(spec)]))
    for shape in sorted((EXAMPLES / "planar").glob("*.yaml")):
        found.append((f"plan_{shape.name}", ["plan", str(shape)]))
    gearbox = str(EXAMPLES / "gearbox_demo" / "gearbox.yaml")
    found.append(("plan_gearbox", ["plan", gearbox]))
    found.append(("contacts_gearbox", ["contacts", gearbox]))
    for puzzle in sorted((EXAMPLES / "puzzles").iterdir()):
        found.append((f"plan_{puzzle.name}", ["plan", str(puzzle), "--moves", "multi"]))
    arch = DATA / "compas_assembly" / "arch_assembly.json"
    stack = DATA / "compas_assembly" / "stack_assembly.json"
    found.append(("plan_arch", ["plan", str(arch)]))
    found.append(("plan_arch_gravity_3", ["plan", str(arch), "--gravity", "--extra-holds", "2"]))
    found.append(("plan_stack_gravity", ["plan", str(stack), "--gravity"]))
    found.append(("plan_beam", ["plan", str(DATA / "asap_beam_assembly")]))
    return found


DIGITS = 6
"""Decimals kept of every number: the precision real data is written to (a pose computed
in another order of summation differs in its last bits, not in these)."""


def stripped(value: Any) -> Any:
    """``value`` without the :data:`VOLATILE` keys, at any depth, its numbers rounded to
    :data:`DIGITS` decimals (and -0 written 0)."""
    if isinstance(value, dict):
        return {k: stripped(v) for k, v in value.items() if k not in VOLATILE}
    if isinstance(value, list):
        return [stripped(v) for v in value]
    if isinstance(value, float):
        return round(value, DIGITS) + 0.0
    return value


def answer(argv: list[str]) -> tuple[int, str]:
    """The exit code of ``assemblykit ARGV --json``, run in this process, and its answer
    as stable JSON text (:func:`stripped`), or its last line on stderr when it printed no
    JSON."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            main([*argv, "--json"])
            code = 0
        except SystemExit as done:
            code = int(done.code or 0)
    try:
        found = stripped(json.loads(out.getvalue()))
    except json.JSONDecodeError:
        found = {"exit": code, "stderr": err.getvalue().strip().splitlines()[-1:]}
    return code, json.dumps(found, indent=1, sort_keys=True)


def main_answers() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="folder for one JSON file per example")
    parser.add_argument("--jobs", type=int, default=1, help="processes sharing the examples")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    names, argvs = zip(*jobs(), strict=True)
    with ProcessPoolExecutor(max_workers=args.jobs) as pool:
        for name, (code, text) in zip(names, pool.map(answer, argvs), strict=True):
            (args.out / f"{name}.json").write_text(text + "\n", encoding="utf-8")
            print(f"{name:<40} exit {code}")


if __name__ == "__main__":
    main_answers()
