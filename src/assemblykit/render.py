"""The readable form of every result: the rich tables and lines of text the commands print
without ``--json``.

The algorithms return data (``to_dict()`` gives the JSON of docs/architecture.md,
"Results and errors"); :func:`render` turns any of their results into a rich renderable,
dispatched on the result's type (:func:`functools.singledispatch`). The renderers of a
package's results are registered the first time one of its results is rendered, so that
printing a solution does not import the planners.

>>> from pathlib import Path
>>> import assemblykit
>>> from rich.console import Console
>>> examples = Path(assemblykit.__file__).parent / "examples"
>>> task = assemblykit.load_task(examples / "tasks" / "peg_in_block.rapt")
>>> console = Console(width=100, color_system=None)
>>> with console.capture() as captured:
...     console.print(render(task.solve()))
>>> print(captured.get().splitlines()[0].strip())
RAPT inference: underconstrained
"""

from __future__ import annotations

import functools
import math
from collections import Counter
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from rich.console import Group, RenderableType
from rich.table import Table
from rich.text import Text

from assemblykit import formatting as fmt

if TYPE_CHECKING:
    from numpy.typing import NDArray

    from assemblykit.batch import BatchSummary
    from assemblykit.blocking.dbg import Removal
    from assemblykit.blocking.ndbg import NonDirectionalBlockingGraph
    from assemblykit.blocking.rigid import RigidBlockingGraph
    from assemblykit.demo import DemoResult
    from assemblykit.inference.solution import Solution
    from assemblykit.io.assembly import ContactReport
    from assemblykit.mating.search import MatingResult
    from assemblykit.motion.articulation import Articulation
    from assemblykit.motion.freedom import MotionReport
    from assemblykit.motion.relational import TaskMotionReport
    from assemblykit.planning.interlocking import Interlocking
    from assemblykit.planning.multimove import MultiMovePlan, Separation
    from assemblykit.planning.plan_values import Hands, Plan
    from assemblykit.planning.screw import ScrewPlan


@functools.singledispatch
def render(result: object) -> RenderableType:
    """``result`` as rich tables and text (module docstring); a :class:`TypeError` for
    an object that is no result of assemblykit."""
    kind = type(result)
    register = _REGISTRARS.get(".".join(kind.__module__.split(".")[:2]))
    if register is not None:
        register()
        renderer = render.dispatch(kind)
        if renderer is not render.registry[object]:
            return renderer(result)
    raise TypeError(f"no rendering of {kind.__name__}")


def _solution(result: Solution) -> Group:
    """RAPT inference (Corner et al. 1983): a table of the body instances, then the
    freedoms, the conflicts and (when explaining) the trace."""
    from assemblykit.inference.solution import INVARIANT_KEYS, invariant_text

    table = Table(title=f"RAPT inference: {result.status}")
    for column in ("instance", "dof", "motion", "solutions"):
        table.add_column(column)
    table.add_column(fmt.header("position", result.units))
    table.add_column("invariants")
    for key, b in result.bodies.items():
        table.add_row(
            key,
            str(b.dof),
            b.mechanism or b.motion,
            "infinite" if b.solutions is None else str(b.solutions),
            fmt.vector(np.asarray(b.pose)[:3, 3]),
            ", ".join(
                f"{k} {invariant_text(k, v)}"
                for k, v in b.invariants.items()
                if k in INVARIANT_KEYS
            ),
        )
    parts: list[RenderableType] = [table]
    if result.valid_without:
        without = ", ".join(result.valid_without)
        parts.append(Text(f"poses and freedoms hold only without: {without}"))
    if result.cut is not None:
        parts.append(Text(result.cut.message))
    parts.extend(Text(b.freedom) for b in result.bodies.values() if b.freedom)
    for c in result.conflicts:
        parts.append(Text(f"conflict ({c.kind} {c.value:.6g}): {', '.join(c.relations)}"))
        parts.append(Text(f"  {c.message}"))
        if c.advice is not None:
            parts.append(Text(f"  {c.advice}"))
    if result.explain:
        # one line per step whatever the width: the trace is read by people and programs
        for step in result.trace:
            parts.append(
                Text(
                    f"{step.rule}: {step.link} dof {step.dof_before} -> {step.dof_after}"
                    + (f" ({step.detail})" if step.detail else ""),
                    no_wrap=True,
                    overflow="ignore",
                )
            )
    return Group(*parts)


def _motion_report(result: MotionReport) -> Table:
    """Liu 1997 eq. (2): per moving set, the motion with its invariants, dof, components
    and the unilateral reading."""
    from assemblykit.motion.freedom import motion_summary

    table = Table(title=f"Motion of each part{f' of {result.source}' if result.source else ''}")
    for column in ("part", "motion", "dof", "components", "unilateral"):
        table.add_column(column)
    for key, moved in result.motions.items():
        data = motion_summary(moved.group)
        reading = moved.unilateral
        if reading.lift_off:
            rays = ", ".join(fmt.direction(r) for r in reading.lift_off)
            unilateral = f"lifts off along {rays}"
        elif reading.can_lift_off:
            unilateral = "lifts off by turning"
        else:
            unilateral = "keeps every contact" if reading.free else "held"
        table.add_row(
            key, data["description"], str(data["dof"]), str(data["components"]), unilateral
        )
    return table


def _articulation(result: Articulation) -> Group:
    """The motion table followed by one table of gear ratios per train (Liu 1997 Fig. 9)."""
    tables: list[RenderableType] = [render(result.report)]
    for number, train in enumerate(result.trains, start=1):
        table = Table(title=f"Gear train {number}: {train.dof} dof")
        table.add_column("gear")
        table.add_column(f"speed / speed of {train.gears[0]}")
        for gear in train.gears:
            ratio = train.ratios.get(gear)
            table.add_row(gear, "locked" if ratio is None else f"{ratio:.6g}")
        tables.append(table)
    return Group(*tables)


def _task_motion(result: TaskMotionReport) -> Table:
    """Per body instance of a task: the motion its relations leave (Liu 1997 eq. (2)) with
    its invariants, dof, components, the bodies it meets and the ignored relations."""
    from assemblykit.motion.freedom import motion_summary

    title = f"Motion of each body{f' of {result.source}' if result.source else ''}"
    table = Table(title=f"{title} (inference: {result.status})")
    for column in ("body", "motion", "dof", "components", "touching", "ignored"):
        table.add_column(column)
    for key, moved in result.motions.items():
        data = motion_summary(moved.group)
        table.add_row(
            key,
            data["description"],
            str(data["dof"]),
            str(data["components"]),
            ", ".join(moved.touching),
            "; ".join(moved.ignored),
        )
    return table


def _mating(result: MatingResult) -> Group:
    """The configurations found, each as its mating pairs in words and the ranges of
    motion left, then the pruning statistics of each law (docs/mating.md, "Walk-through:
    Example 1 of Liu & Popplestone 1990"; ``MatingResult.or_and`` gives the paper's
    Or/And form)."""
    from assemblykit.mating.search import LAWS

    found = len(result.configurations)
    if not found:
        lines = [Text("no configuration found")]
    elif result.count == found:
        lines = [Text(fmt.count(found, "configuration"))]
    else:
        lines = [Text(f"{fmt.count(result.count, 'configuration')} ({found} up to symmetry)")]
    for number, config in enumerate(result.configurations, start=1):
        lines.append(Text(f"configuration {number}:"))
        lines.extend(Text(f"  {c.words()} (goal {c.goal.number})") for c in config.pairs)
        for name, motion in config.motions.items():
            unit = " rad" if motion.parameter == "angle" else ""
            spans = ", ".join(f"[{lo:.6g}, {hi:.6g}]{unit}" for lo, hi in motion.intervals)
            free = f", {motion.parameter} free in {spans}" if motion.intervals else ""
            lines.append(Text(f"  {name} moves: {motion.kind}{free}"))
    if result.emptied is not None:
        goal, law = result.emptied.goal, result.emptied.law
        lines.append(Text(f"goal {goal}: no candidate left after the {law} law"))
        if result.emptied.reason:
            lines.append(Text(f"  {result.emptied.reason}"))
    for rejection in result.rejections:
        lines.append(Text(f"rejected: {rejection.reason}"))
    header = " -> ".join(LAWS)
    lines.append(Text(f"candidates per goal after each law ({header}):"))
    lines.extend(
        Text(f"  goal {g}: {' -> '.join(map(str, s))}") for g, s in result.statistics.items()
    )
    lines.append(Text(f"candidate pairs deleted by path consistency: {result.pairs_removed}"))
    return Group(*lines)


def _removals(
    title: str,
    kind: str,
    example: str,
    removals: list[Removal],
    shown: Callable[[NDArray[np.float64]], str],
) -> Table:
    """The removable subassemblies (Wilson & Latombe 1992): parts, how many ``kind`` free
    them, and the first one as an ``example``, written by ``shown``."""
    table = Table(title=title)
    table.add_column("removable parts")
    table.add_column(kind)
    table.add_column(example)
    for r in removals:
        table.add_row(", ".join(sorted(r.parts)), str(len(r.directions)), shown(r.directions[0]))
    return table


MOTION_WORDS = {
    "infinitesimal": "a small straight move",
    "extended": "a straight move all the way out",
    "rigid": "a small move that may turn",
}
"""How each kind of motion of the blocking graphs reads in a title: infinitesimal and
extended translations, infinitesimal rigid motions (docs/blocking.md, "Three kinds of
motion")."""


def _ndbg(result: NonDirectionalBlockingGraph) -> Table:
    """The NDBG's removable subassemblies with their first direction (Wilson & Latombe
    1992), titled in words (docs/blocking.md, "Output"): the regions of directions are the
    vertices, edges and faces of its arrangement, counted together."""
    regions = sum(result.arrangement.counts.values())
    return _removals(
        f"Parts removable by {MOTION_WORDS.get(result.motion, result.motion)}: "
        f"{fmt.count(len(result.parts), 'part')}, {fmt.count(result.contacts, 'contact')}, "
        f"{fmt.count(regions, 'region')} of directions",
        "directions",
        "e.g.",
        result.removable(),
        lambda d: fmt.direction(d, result.tol),
    )


def _rigid(result: RigidBlockingGraph) -> Table:
    """The subassemblies some rigid twist frees, with their first twist (Wilson & Latombe
    1992)."""
    arrangement = result.arrangement
    mapped = (
        f"{fmt.count(len(arrangement.signs), 'region')} of motions"
        if arrangement.signs is not None
        else f"motions not mapped ({fmt.count(len(arrangement.normals), 'contact constraint')})"
    )
    return _removals(
        f"Parts removable by {MOTION_WORDS['rigid']}: {fmt.count(len(result.parts), 'part')}, "
        f"{fmt.count(len(result.contacts), 'contact')}, {mapped}",
        "twists",
        "e.g. (omega; v)",
        result.removable(),
        fmt.twist,
    )


def _plan(result: Plan) -> Group:
    """The disassembly steps (and the interlocked sets when infeasible) and the assembly
    order (Wilson & Latombe 1992)."""
    tables = [_disassembly_table(result), _assembly_table(result)]
    if result.overlaps:
        tables.append(_overlap_table(result))
    if result.joined:
        tables.append(_joined_table(result))
    return Group(*tables)


def _interlocking(result: Interlocking) -> Group:
    """The verdict in words, then each subset that moves: one direction that frees it,
    where it is free and the contacts that would block it (docs/interlocking.md)."""
    lines = result.summary().splitlines()
    if result.freedoms:
        # the table says per subset what the summary's list says
        lines = [line for line in lines if not line.startswith("- ")]
    parts: list[RenderableType] = [Text("\n".join(lines))]
    if result.freedoms:
        table = Table(title="What moves", title_justify="left")
        for header in ("moves", "e.g. along", "free along", "to block it"):
            table.add_column(header, overflow="fold")
        for freedom in result.freedoms:
            table.add_row(
                fmt.name_list(freedom.parts, 8),
                fmt.direction(freedom.direction, result.tol),
                "; ".join(d.words(result.tol) for d in freedom.free_along) or "-",
                freedom.advice(result.tol),
            )
        parts.append(table)
    return Group(*parts)


def _joined_table(plan: Plan) -> Table:
    table = Table(title="Parts planned as one")
    for column in ("part", "made of"):
        table.add_column(column)
    for name, members in plan.joined.items():
        table.add_row(name, ", ".join(members))
    return table


def _overlap_table(plan: Plan) -> Table:
    units = next((o.units for o in plan.overlaps if o.units), None)
    table = Table(title="Interfering parts (shared volume, what was done)")
    for column in ("parts", fmt.header("volume", f"{units}³" if units else None), "resolution"):
        table.add_column(column)
    for overlap in plan.overlaps:
        table.add_row(
            f"{overlap.a} / {overlap.b}",
            f"{overlap.volume:.4g}",
            overlap.resolution or "left as it is: an obstacle in every direction",
        )
    return table


def _assembly_table(plan: Plan) -> Table:
    table = Table(title="Assembly order")
    columns = ["step", "insert", "direction", "held"]
    if plan.gravity is not None:
        columns.append("stands")
    for column in columns:
        table.add_column(column)
    for number, step in enumerate(plan.assembly_steps, start=1):
        cells = [
            str(number),
            ", ".join(step.parts),
            fmt.direction(step.direction),
            fmt.name_list(step.held),
        ]
        if step.stands is not None:
            cells.append("yes" if step.stands else "no")
        table.add_row(*cells)
    return table


def _disassembly_table(plan: Plan) -> Table:
    title = "feasible" if plan.feasible else "infeasible"
    if plan.unfinished:
        title = f"stopped at its step limit, {fmt.count(len(plan.unfinished), 'part')} left"
    if plan.and_or is not None:
        # the plans of the AND/OR graph (docs/planning.md): the orders it takes apart in
        title += f", {fmt.count(plan.and_or.plans, 'possible order')}"
    if plan.gravity is not None:
        title += ", " + plan.gravity.summary()
    if plan.ground:
        title += f", on the ground under {fmt.name_list(plan.ground)}"
    table = Table(title=f"Disassembly plan ({title})")
    columns = ["step", "move", "direction", "motion", "away from"]
    if plan.gravity is not None:
        columns += ["held", "would fall unheld", "friction needed"]
    for column in columns:
        table.add_column(column)
    if plan.gravity is not None and not plan.gravity.whole.stands:
        # the assembly as given does not stand: step 0 says what falls before any move
        table.add_row("0", "-", "-", "as given", "-", *plan.gravity.cells())
    for number, step in enumerate(plan.steps, start=1):
        cells = [
            str(number),
            ", ".join(step.parts),
            fmt.direction(step.direction),
            step.summary(),
            fmt.name_list(step.rest),
        ]
        if step.stability is not None:
            cells += step.stability.cells()
        table.add_row(*cells)
    if plan.unfinished:
        table.add_row("-", fmt.name_list(plan.unfinished), "-", "not yet taken apart", "-")
    for lock in plan.interlocked:
        table.add_row("-", ", ".join(lock.parts), "-", lock.reason, "-")
        if lock.held:
            table.add_row("-", ", ".join(lock.held), "-", "held by the interlock", "-")
    if plan.hands is not None:
        # the groups of the operations two hands cannot do, one row per group
        for move in plan.hands.moves:
            for group, direction in zip(move.groups[1:], move.directions[1:], strict=True):
                table.add_row(
                    f"{move.hands} hands",
                    ", ".join(group),
                    fmt.direction(direction),
                    "translation, together",
                    fmt.name_list(move.groups[0]),
                )
        if plan.hands.moves or plan.hands.needed is None:
            table.caption = plan.hands.summary()
    if any(
        lock.rigid_may_free and not lock.interfering and not lock.enclosed
        for lock in plan.interlocked
    ):
        hint = "turns and drawn threads: plan --moves rigid"
        table.caption = f"{table.caption}; {hint}" if table.caption else hint
    return table


def _hands(result: Hands) -> Table:
    """The operations with more than two hands (Wilson & Latombe 1992): per group its
    parts, direction and speed, the first group held fixed."""
    table = Table(title=result.summary().capitalize())
    for column in ("operation", "group", "parts", "direction", "speed"):
        table.add_column(column)
    for number, move in enumerate(result.moves, start=1):
        for g, (group, direction, speed) in enumerate(
            zip(move.groups, move.directions, move.speeds, strict=True)
        ):
            table.add_row(
                str(number) if g == 0 else "",
                "fixed" if g == 0 else str(g),
                ", ".join(group),
                "-" if g == 0 else fmt.direction(direction),
                "-" if g == 0 else f"{speed:.3g}",
            )
    return table


def _multi_move(result: MultiMovePlan) -> Table:
    """A multi-move plan: one row per move, grouped by separation (``1``, then ``1.r``
    for the removed side and ``1.l`` for the side left)."""
    verdict = "feasible" if result.feasible else "infeasible"
    if result.cut:
        verdict += f", search cut at {result.max_states} states"
    table = Table(title=f"Multi-move disassembly ({verdict}), level {result.level or '-'}")
    for column in ("separation", "move", "parts", "direction", "distance"):
        table.add_column(column)

    def rows(node: Separation | None, label: str) -> None:
        if node is None:
            return
        if node.status != "separated":
            table.add_row(label, "-", ", ".join(node.parts), node.status, "-")
            return
        for number, move in enumerate(node.moves, start=1):
            distance = "inf" if move.distance is None else f"{move.distance:.6g}"
            table.add_row(label, str(number), ", ".join(move.parts), move.label, distance)
        rows(node.removed, f"{label}.r")
        rows(node.left, f"{label}.l")

    rows(result.root, "1")
    first = "-" if result.first_moves is None else fmt.count(result.first_moves, "move")
    caption = f"first separation: {first}"
    if result.reference_level is not None:
        caption += f" (stored level {result.reference_level})"
    table.caption = caption
    return table


def _screw(result: ScrewPlan) -> Table:
    """A plan with turns: one row per step, turns with their axis and angle."""
    verdict = "feasible" if result.feasible else "infeasible"
    table = Table(title=f"Disassembly plan with turns ({verdict})")
    for column in ("step", "move", "motion", "axis (point; direction)", "then along"):
        table.add_column(column)
    number = 0
    for k, stage in enumerate(result.stages):
        for step in stage.steps:
            number += 1
            direction = fmt.direction(step.direction)
            table.add_row(str(number), ", ".join(step.parts), step.motion, "-", direction)
        if k < len(result.screws):
            turn = result.screws[k]
            number += 1
            axis = f"({fmt.vector(turn.point)[1:-1]}; {fmt.direction(turn.axis)})"
            table.add_row(
                str(number),
                ", ".join(turn.parts),
                _turned(turn.angle, turn.pitch),
                axis,
                fmt.direction(turn.exit),
            )
    if not result.feasible:
        table.caption = "stuck: " + ", ".join(result.stages[-1].stuck)
    return table


def _turned(angle: float, pitch: float) -> str:
    """A turn in words: degrees and the pitch per radian, or, past a whole turn (a
    thread followed out), the turns and the advance per turn."""
    if angle <= 2 * math.pi:
        return f"turn {math.degrees(angle):.1f} deg" + (
            f", pitch {pitch:.4g} per rad" if pitch else ""
        )
    hand = "" if pitch >= 0 else ", left-handed"
    return (
        f"unscrew {angle / (2 * math.pi):.4g} turns, {abs(pitch) * 2 * math.pi:.4g} per turn{hand}"
    )


def _contacts(result: ContactReport) -> Group:
    """The tolerance used, a table of parts, one of contacts, then the interferences."""
    asm = result.assembly
    parts = Table(
        title=f"{asm.source}: {fmt.count(len(asm), 'part')} ({asm.units}, {asm.units_source})"
    )
    for column in ("part", "triangles", fmt.header("volume", f"{asm.units}³"), "features"):
        parts.add_column(column)
    for name, part in asm.parts.items():
        kinds = Counter(s.feature().type_name for s in result.surfaces[name])
        listing = ", ".join(f"{n} {k}" for k, n in sorted(kinds.items()))
        parts.add_row(name, str(len(part.mesh.faces)), f"{part.volume:.6g}", listing)
    contacts = Table(title=fmt.count(len(result.contacts), "contact"))
    for column in ("a", "b", "planar area", "normals", "curved"):
        contacts.add_column(column)
    working = asm.tolerance(result.policy)
    for c in result.contacts:
        normals = "; ".join(fmt.direction(p.normal, working) for p in c.planar)
        curved = ", ".join(f"{p.kind} r={p.radius:.6g} inner={p.inner}" for p in c.curved)
        contacts.add_row(c.a, c.b, f"{c.area:.6g}", normals, curved)
    clashes = (
        "\n".join(
            f"interference {a} / {b}: volume {v:.6g} {asm.units}³"
            for a, b, v in result.interferences
        )
        or "no interferences"
    )
    used = asm.tolerance_summary(result.policy)
    measured = f"{used['measured_from'] or 'nothing measured'}: {used['measured'] or 0:.2g}"
    why = f"input ({measured})" if used["from"] == "measured" else f"policy ({measured})"
    tolerance = f"length tolerance {used['length']:.3g} {asm.units} from the {why}"
    return Group(tolerance, parts, contacts, clashes)


def _batch(result: BatchSummary) -> Group:
    """A one-row table of the counts, then one line per failed input."""
    data = result.to_dict()
    keys = ("total", "skipped", "ok", "error", "timeout", "missing")
    table = Table(title=f"batch -> {result.out}")
    for key in keys:
        table.add_column(key)
    table.add_row(*(str(data[key]) for key in keys))
    lines = [
        Text(f"{f.status}: {f.input}: {f.error}", no_wrap=True, overflow="ignore")
        for f in result.failed
    ]
    return Group(table, *lines)


def _demo(result: DemoResult) -> Group:
    """The plan's tables, then one line saying where the report is to open
    (docs/planning.md, "The HTML report")."""
    return Group(_plan(result.plan), Text(f"Open {result.report} in a browser."))


def _register_inference() -> None:
    from assemblykit.inference.solution import Solution

    render.register(Solution, _solution)


def _register_motion() -> None:
    from assemblykit.motion.articulation import Articulation
    from assemblykit.motion.freedom import MotionReport
    from assemblykit.motion.relational import TaskMotionReport

    render.register(MotionReport, _motion_report)
    render.register(Articulation, _articulation)
    render.register(TaskMotionReport, _task_motion)


def _register_mating() -> None:
    from assemblykit.mating.search import MatingResult

    render.register(MatingResult, _mating)


def _register_blocking() -> None:
    from assemblykit.blocking.ndbg import NonDirectionalBlockingGraph
    from assemblykit.blocking.rigid import RigidBlockingGraph

    render.register(NonDirectionalBlockingGraph, _ndbg)
    render.register(RigidBlockingGraph, _rigid)


def _register_planning() -> None:
    from assemblykit.planning.interlocking import Interlocking
    from assemblykit.planning.multimove import MultiMovePlan
    from assemblykit.planning.plan_values import Hands, Plan
    from assemblykit.planning.screw import ScrewPlan

    render.register(Plan, _plan)
    render.register(Interlocking, _interlocking)
    render.register(Hands, _hands)
    render.register(MultiMovePlan, _multi_move)
    render.register(ScrewPlan, _screw)


def _register_io() -> None:
    from assemblykit.io.assembly import ContactReport

    render.register(ContactReport, _contacts)


def _register_batch() -> None:
    from assemblykit.batch import BatchSummary

    render.register(BatchSummary, _batch)


def _register_demo() -> None:
    from assemblykit.demo import DemoResult

    render.register(DemoResult, _demo)


_REGISTRARS: dict[str, Callable[[], None]] = {
    "assemblykit.inference": _register_inference,
    "assemblykit.motion": _register_motion,
    "assemblykit.mating": _register_mating,
    "assemblykit.blocking": _register_blocking,
    "assemblykit.planning": _register_planning,
    "assemblykit.io": _register_io,
    "assemblykit.batch": _register_batch,
    "assemblykit.demo": _register_demo,
}
"""The package of a result's module -> the function registering the renderers of that
package's results."""
