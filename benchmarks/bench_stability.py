"""Static equilibrium under gravity and stability-aware planning, against the targets:
equilibrium of the dome (527 blocks) <= 1 s, the cross vault planned with gravity
<= 20 s and the dome <= 120 s CPU, the ASAP beam planned with gravity <= 1 s.

Run ``python benchmarks/bench_stability.py [--crossvault-plan] [--dome-plan | --dome-whole]``.
Figures (wall time, one run each, loading and contacts excluded unless said; the machine
is named first):

* equilibrium of the whole arch, dome and cross vault: assembling the sparse equations,
  then the equilibrium program (Clarabel, interior point, in Farkas form over the
  generators at the polygons' corners), and the slack program (Clarabel, interior point,
  on the corners too) when the assembly does not stand; the cross vault also at the
  tolerance that makes its crown joints contacts (``CROWN_JOINTS``), where it stands;
* one state of the cross vault that stands and one that does not, the programs each
  candidate step of a plan runs, solved whole (a plan decides many states from the
  balance it last found instead); four slack programs of the dome solved one after
  another and together on threads;
* plans with gravity: the ASAP beam (also without gravity) and the COMPAS arch with three
  holds, each followed by the time of the stability work alone: assembling the
  equations and checking every state of the plan once, the programs the plan solved,
  and every state's verdict decided again by a fresh model's whole program on every
  polygon vertex (an independent check); the cross vault's first 20
  steps with three holds, with the programs they ran; its whole plan with one hold only
  with ``--crossvault-plan`` (minutes: from step 78 on no single block's removal
  stands, and each step then asks which parts would fall); the dome's first 20 steps
  under gravity with ``--dome-plan``, its whole plan with ``--dome-whole`` (an hour), in
  CPU seconds next to the whole plan's target.

The dome is skipped unless ``$ASSEMBLYKIT_DATA`` holds
``compas_assembly/dome_assembly.json``.
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
import platform
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import clarabel
import numpy as np
import scipy

from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.io.assembly import load_assembly
from assemblykit.model.assembly import Assembly
from assemblykit.planning.equilibrium_programs import PROGRAM_THREADS_VARIABLE, program_threads
from assemblykit.planning.planner import plan
from assemblykit.planning.sequence import Plan
from assemblykit.planning.stability import (
    CONE_SIDES,
    EquilibriumMemory,
    EquilibriumModel,
    Gravity,
    equilibrium_model,
)
from assemblykit.tolerance import Tolerance
from datasets import dataset

CROWN_JOINTS = Tolerance.relative(5e-5)
"""The cross vault's tolerance with its crown joints as contacts (they are sunk up to
4.3e-5 of its size into each other: tests/geometry/test_contacts.py)."""


def machine() -> str:
    """CPU, cores, Python and library versions."""
    return (
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
        f"Python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}, "
        f"clarabel {clarabel.__version__}"
    )


def whole(name: str, path: Path | None, tol: Tolerance | None = None) -> bool | None:
    """Time the equilibrium of a whole assembly; whether it stands (None if absent)."""
    if path is None:
        print(f"{name:<24} skipped (not bundled; set ASSEMBLYKIT_DATA)")
        return None
    assembly = load_assembly(path)
    assembly_contacts(assembly, tol)
    start = time.perf_counter()
    model = equilibrium_model(assembly, tol=tol)
    built = time.perf_counter() - start
    found = model.check()
    solved = time.perf_counter() - start - built
    columns = model.normal_part.shape[1]
    corners = int(model.corners.sum()) * CONE_SIDES
    print(
        f"{name:<24} {len(assembly.names):>4} parts {columns:>7} generators "
        f"({corners:>6} at corners)  "
        f"equations {built:7.3f} s  program {solved:8.3f} s  "
        f"{'stands' if found.stands else f'{len(found.would_fall)} parts would fall'}"
    )
    return found.stands


@contextlib.contextmanager
def counting_programs() -> Iterator[dict[str, int]]:
    """Count the first programs (``stands``) and slack programs a model solves inside
    the block."""
    counts = {"stands": 0, "slack": 0}
    originals = {name: getattr(EquilibriumModel, name) for name in counts}

    def counted(name: str) -> Callable[..., object]:
        def call(self: EquilibriumModel, *args: object, **kwargs: object) -> object:
            counts[name] += 1
            return originals[name](self, *args, **kwargs)

        return call

    for name in counts:
        setattr(EquilibriumModel, name, counted(name))
    try:
        yield counts
    finally:
        for name, method in originals.items():
            setattr(EquilibriumModel, name, method)


def checked_verdicts(assembly: Assembly, result: Plan, tol: Tolerance | None) -> str:
    """Each state of a plan under gravity decided again by a fresh model's whole program
    on every polygon vertex (none of the plan's shortcuts), with the parts it holds: how
    many verdicts agree, and the steps that do not."""
    model = equilibrium_model(assembly, tol=tol)
    every = dataclasses.replace(model, corners=np.ones_like(model.corners))
    fixed = every.mask(every.fixed)
    wrong = []
    for number, step in enumerate(result.steps, start=1):
        assert step.stability is not None
        rest = every.mask(step.rest)
        held = rest & (fixed | every.mask(step.stability.held))
        if every.stands(rest, held, local=False) is not step.stability.stands:
            wrong.append(number)
    agree = len(result.steps) - len(wrong)
    return f"{agree} of {len(result.steps)} verdicts agree" + (f" (not: {wrong})" if wrong else "")


def planned(
    name: str,
    path: Path | None,
    gravity: Gravity | None,
    tol: Tolerance | None = None,
    target: float | None = None,
) -> None:
    """Time a plan (contacts included) with or without gravity, count the programs it
    solved, and under gravity check every state's verdict independently; ``target``:
    the seconds it should take, printed next to them."""
    if path is None:
        print(f"{name:<24} skipped (not bundled; set ASSEMBLYKIT_DATA)")
        return
    assembly = load_assembly(path)
    start = time.perf_counter()
    with counting_programs() as counts:
        result = plan(assembly, tol, gravity=gravity, max_and_or_parts=0)
    seconds = time.perf_counter() - start
    verdict = "no gravity"
    if result.gravity is not None:
        holds = max((len(s.stability.held) for s in result.steps if s.stability), default=0)
        standing = sum(bool(s.stability and s.stability.stands) for s in result.steps)
        stable = "every state stands" if result.gravity.stable else "some states fall"
        verdict = (
            f"{stable} ({standing} steps stand), at most {holds} held; "
            f"{counts['stands']} first programs, {counts['slack']} slack programs"
        )
    steps = len(result.steps)
    versus = ""
    if target is not None:
        versus = f" (target <= {target:g} s: {'met' if seconds <= target else 'NOT MET'})"
    print(
        f"{name:<24} {len(result.parts):>4} parts {seconds:8.3f} s{versus}  {steps} steps, "
        f"{verdict}"
    )
    if result.gravity is not None:
        start = time.perf_counter()
        model, memory = equilibrium_model(assembly, tol=tol), EquilibriumMemory()
        for step in result.steps:
            assert step.stability is not None
            model.check(step.rest, set(step.stability.held) & set(step.rest), memory=memory)
        seconds = time.perf_counter() - start
        print(f"{'':<24} equations and one program per state: {seconds:.3f} s")
        # what any search reporting these states pays: each decided once, whole
        fixed = model.mask(model.fixed)
        start = time.perf_counter()
        for step in result.steps:
            assert step.stability is not None
            rest = model.mask(step.rest)
            model.stands(rest, rest & (fixed | model.mask(step.stability.held)), local=False)
        seconds = time.perf_counter() - start
        print(f"{'':<24} one first program per state, solved whole: {seconds:.3f} s")
        print(f"{'':<24} independent check: {checked_verdicts(assembly, result, tol)}")


def first_steps(path: Path | None, steps: int, tol: Tolerance) -> None:
    """Time the first ``steps`` steps of the cross vault's plan with gravity and three
    holds (contacts included; ``max_steps``), and count the programs they ran."""
    if path is None:
        print(f"{'crossvault states':<24} skipped (not bundled; set ASSEMBLYKIT_DATA)")
        return
    assembly = load_assembly(path)
    start = time.perf_counter()
    with counting_programs() as counts:
        plan(assembly, tol, 0, gravity=Gravity(holds=3), max_steps=steps)
    seconds = time.perf_counter() - start
    label = f"crossvault, first {steps}"
    print(
        f"{label:<24} {seconds:8.3f} s  {counts['stands']} first programs, "
        f"{counts['slack']} slack programs (3 holds)"
    )


CROSSVAULT_PLAN_TARGET = 20.0
"""Seconds the cross vault's whole plan under gravity (one hold) should take."""

DOME_PLAN_TARGET = 120.0
"""CPU seconds the dome's whole plan under gravity should take."""

DOME_STEPS = 20
"""How many steps of the dome's plan ``--dome-plan`` times (``--dome-whole``: all of
them, an hour)."""


def dome_steps(path: Path | None, steps: int | None) -> None:
    """CPU time of the first ``steps`` steps of the dome's plan under gravity with one
    hold (``None``: the whole plan; contacts included), and how many of them stand,
    next to the whole plan's target :data:`DOME_PLAN_TARGET`."""
    if path is None:
        print(f"{'dome plan':<24} skipped (not found; set ASSEMBLYKIT_DATA)")
        return
    assembly = load_assembly(path)
    start = time.process_time()
    found = plan(assembly, max_and_or_parts=0, gravity=Gravity(), max_steps=steps)
    seconds = time.process_time() - start
    standing = sum(step.stability is not None and step.stability.stands for step in found.steps)
    label = "dome, whole plan" if steps is None else f"dome, first {steps}"
    print(
        f"{label:<24} {seconds:8.1f} CPU s, {seconds / max(len(found.steps), 1):.1f} s a step, "
        f"{standing} of {len(found.steps)} standing; {len(assembly.names)} blocks "
        f"(whole plan target <= {DOME_PLAN_TARGET:g} s)"
    )


def slack_together(path: Path | None, count: int = 4) -> None:
    """Time the slack programs of ``count`` states of the dome that fall (its 40 highest
    blocks taken away, then one more each time), solved one after another and together
    on the threads the process may use (:meth:`EquilibriumModel.solve_slack`), and check
    that both keep the same residuals."""
    if path is None:
        print(f"{'dome slack programs':<24} skipped (not found; set ASSEMBLYKIT_DATA)")
        return
    model = equilibrium_model(load_assembly(path))
    present = model.mask(None)
    fixed = present & model.mask(model.fixed)
    highest = np.argsort(model.levels)
    states = []
    for k in range(count):
        state = present.copy()
        state[highest[: 40 + k]] = False
        states.append((state, fixed))
    found = []
    before = os.environ.get(PROGRAM_THREADS_VARIABLE)
    for threads in ("1", str(program_threads())):
        os.environ[PROGRAM_THREADS_VARIABLE] = threads
        memory = EquilibriumMemory()
        start = time.perf_counter()
        model.solve_slack(states, memory=memory)
        found.append((time.perf_counter() - start, list(memory.residuals.items())))
    if before is None:
        os.environ.pop(PROGRAM_THREADS_VARIABLE)
    else:
        os.environ[PROGRAM_THREADS_VARIABLE] = before
    (alone, first), (together, second) = found
    assert [k for k, _ in first] == [k for k, _ in second]
    assert all(np.array_equal(a, b) for (_, a), (_, b) in zip(first, second, strict=True))
    print(
        f"{'dome slack programs':<24} {len(first)} programs: {alone:.2f} s one after another, "
        f"{together:.2f} s on {program_threads()} threads ({alone / together:.2f}x), "
        "the same residuals"
    )


def state_programs(path: Path | None, tol: Tolerance) -> None:
    """Time one state of the cross vault that stands (the whole vault) and one that does
    not (its three highest blocks taken away), each solved whole, then the second decided
    from the whole vault's balance (a Farkas certificate on the parts around the gap,
    then the slack program), as a plan decides it."""
    if path is None:
        print(f"{'crossvault states':<24} skipped (not bundled; set ASSEMBLYKIT_DATA)")
        return
    assembly = load_assembly(path)
    assembly_contacts(assembly, tol)
    highest = sorted(assembly.names, key=lambda n: -float(assembly.parts[n].mesh.center_mass[2]))
    rest = set(assembly.names) - set(highest[:3])
    states = (("whole", None), (f"without {', '.join(highest[:3])}", rest))
    for label, parts in states:
        model = equilibrium_model(assembly, tol=tol)
        start = time.perf_counter()
        found = model.check(parts)
        seconds = time.perf_counter() - start
        verdict = "stands" if found.stands else f"{len(found.would_fall)} parts would fall"
        print(f"{'crossvault ' + label:<24} {seconds:8.3f} s  {verdict}")
    memory = EquilibriumMemory()
    model.check(memory=memory)
    start = time.perf_counter()
    found = model.check(rest, memory=memory)
    seconds = time.perf_counter() - start
    print(f"{'  the same, after whole':<24} {seconds:8.3f} s  {len(found.would_fall)} would fall")


def main() -> None:
    full = "--crossvault-plan" in sys.argv
    print(f"machine: {machine()}")
    print(
        f"targets: dome equilibrium <= 1 s, crossvault plan with gravity "
        f"<= {CROSSVAULT_PLAN_TARGET:g} s, dome's <= {DOME_PLAN_TARGET:g} s,"
    )
    print("         ASAP beam plan with gravity <= 1 s")
    print("equilibrium of whole assemblies (one run; contacts excluded)")
    whole("compas arch", dataset("compas_assembly/arch_assembly.json"))
    whole("compas dome", dataset("compas_assembly/dome_assembly.json"))
    vault = dataset("compas_assembly/crossvault_assembly.json")
    whole("compas crossvault", vault)
    whole("crossvault, tol 5e-5", vault, CROWN_JOINTS)
    print("one state of a plan (equilibrium program, and the slack program when it falls)")
    state_programs(vault, CROWN_JOINTS)
    slack_together(dataset("compas_assembly/dome_assembly.json"))
    print("plans (one run; contacts and blocking included)")
    beam = dataset("asap_beam_assembly")
    planned("asap beam", beam, None)
    planned("asap beam, gravity", beam, Gravity())
    planned("compas arch, 3 holds", dataset("compas_assembly/arch_assembly.json"), Gravity(holds=3))
    first_steps(vault, 20, CROWN_JOINTS)
    if full:
        planned("crossvault, 1 hold", vault, Gravity(), CROWN_JOINTS, CROSSVAULT_PLAN_TARGET)
    else:
        print("crossvault, 1 hold        skipped: minutes; run with --crossvault-plan")
    dome = dataset("compas_assembly/dome_assembly.json")
    if "--dome-whole" in sys.argv:
        dome_steps(dome, None)
    elif "--dome-plan" in sys.argv:
        dome_steps(dome, DOME_STEPS)
    else:
        print(f"dome, first {DOME_STEPS:<12} skipped: minutes; run with --dome-plan")


if __name__ == "__main__":
    main()
