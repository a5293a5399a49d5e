"""The ``assemblykit`` command (DESIGN.md §5.3).

Every command takes ``INPUT``, ``--json`` (the documented JSON on stdout), ``--tolerance``
(relative length tolerance) and ``--debug`` (tracebacks); the commands that load an
assembly take ``--as-written`` (keep rounded mesh-folder poses unsettled). Exit codes: 0
for every answer (including *inconsistent* or *infeasible*), 2 for bad input (one line on
stderr naming the file and the fault), 1 for an internal error.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING, Annotated, Any, Protocol

import click
import typer
from rich.console import Console

from assemblykit.errors import AssemblyKitError, InputError, MissingExtraError
from assemblykit.tolerance import Tolerance

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly

app = typer.Typer(
    name="assemblykit",
    help="Geometric reasoning about mechanical assemblies.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)

console = Console()
err_console = Console(stderr=True)

JsonOption = Annotated[bool, typer.Option("--json", help="Print the result as JSON on stdout.")]
ToleranceOption = Annotated[
    float | None,
    typer.Option(
        "--tolerance",
        help="Relative length tolerance (fraction of the model's bounding-box diagonal).",
    ),
]
DebugOption = Annotated[bool, typer.Option("--debug", help="Show tracebacks on errors.")]
AssemblyArgument = Annotated[
    str, typer.Argument(help="Assembly: mesh folder, .yaml manifest, .step or COMPAS .json.")
]
AsWrittenOption = Annotated[
    bool,
    typer.Option(
        "--as-written",
        help="Keep rounded mesh-folder poses as written (do not settle thin overlaps).",
    ),
]


class Result(Protocol):
    """What every command returns: JSON via ``to_dict`` and a readable rendering."""

    def to_dict(self) -> dict[str, Any]: ...

    def render(self) -> Any: ...


def tolerance_from(option: float | None) -> Tolerance:
    """The tolerance policy with the command line's ``--tolerance`` applied."""
    return Tolerance() if option is None else Tolerance(rel_length=option)


def loaded_assembly(path: str, tol: Tolerance, as_written: bool) -> Assembly:
    """The assembly at ``path`` with the command line's tolerance, settled unless
    ``--as-written``."""
    from assemblykit.io.assembly import load_assembly

    return load_assembly(path, tol, settle=not as_written)


def emit(result: Result, as_json: bool) -> None:
    """Print a result: JSON on stdout, or its rich rendering."""
    if as_json:
        sys.stdout.write(json.dumps(result.to_dict(), indent=2) + "\n")
    else:
        console.print(result.render())


def _fail(message: str, code: int) -> None:
    err_console.print(f"assemblykit: {message}", markup=False, highlight=False, soft_wrap=True)
    raise SystemExit(code)


def main(argv: list[str] | None = None) -> None:
    """Entry point of the console script: maps errors to one line and an exit code."""
    args = sys.argv[1:] if argv is None else argv
    debug = "--debug" in args
    try:
        app(args=args, prog_name="assemblykit", standalone_mode=False)
    except click.exceptions.Exit as done:
        raise SystemExit(done.exit_code) from None
    except click.ClickException as usage:
        if debug:
            raise
        _fail(usage.format_message(), 2)
    except (click.exceptions.Abort, KeyboardInterrupt):
        _fail("interrupted", 1)
    except (InputError, MissingExtraError) as bad:
        if debug:
            raise
        _fail(str(bad), 2)
    except AssemblyKitError as failure:
        if debug:
            raise
        _fail(str(failure), 1)
    except Exception as bug:  # an internal error still gets one line unless --debug
        if debug:
            raise
        _fail(f"internal error: {type(bug).__name__}: {bug} (rerun with --debug)", 1)


def command(fn: Callable[..., None]) -> Callable[..., None]:
    """Register ``fn`` as a sub-command named after it (underscores become dashes)."""
    return app.command(name=fn.__name__.removesuffix("_cmd").replace("_", "-"))(fn)


# Commands follow; each one is a thin layer over the library's public API.


ExplainOption = Annotated[
    bool, typer.Option("--explain", help="Also print the reduction steps (the trace).")
]


@command
def solve_cmd(
    task: Annotated[str, typer.Argument(help="Task file: .yaml, .yml, .json or .rapt.")],
    as_json: JsonOption = False,
    tolerance: ToleranceOption = None,
    explain: ExplainOption = False,
    debug: DebugOption = False,
) -> None:
    """Pose of every body in every situation of a task (RAPT network reduction, seed 000)."""
    from assemblykit.io.spec import load_task
    from assemblykit.tolerance import using

    # The engine scales the policy to the model's size; only the relative part comes from here.
    with using(tolerance_from(tolerance)):
        emit(load_task(task).solve(explain=explain), as_json)


def _progress_bar() -> Any:
    """A rich progress bar on stderr (shown when stderr is a terminal)."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    return Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=err_console,
        transient=True,
        disable=not err_console.is_terminal,
    )


def _updater(bar: Any) -> Callable[[str, int, int], None]:
    task = bar.add_task("loading", total=None)

    def update(stage: str, done: int, total: int) -> None:
        bar.update(task, description=stage, completed=done, total=total)

    return update


@command
def plan_cmd(
    assembly: AssemblyArgument,
    html: Annotated[
        str | None, typer.Option("--html", help="Write a self-contained HTML report here.")
    ] = None,
    png: Annotated[
        str | None, typer.Option("--png", help="Write a static exploded view (PNG) here.")
    ] = None,
    as_json: JsonOption = False,
    tolerance: ToleranceOption = None,
    as_written: AsWrittenOption = False,
    debug: DebugOption = False,
) -> None:
    """Disassembly (and assembly) sequence by extended translations (seed 004)."""
    from assemblykit.planning.sequence import plan

    tol = tolerance_from(tolerance)
    with _progress_bar() as bar:
        update = _updater(bar)
        loaded = loaded_assembly(assembly, tol, as_written)
        result = plan(loaded, tol=tol, progress=update)
        if html is not None:
            from assemblykit.viz.viewer import write_report

            update("writing the report", 0, 1)
            write_report(loaded, result, html)
        if png is not None:
            from assemblykit.viz.plots import exploded_view_png

            update("drawing the exploded view", 0, 1)
            exploded_view_png(loaded, result, png)
    for written in (html, png):
        if written is not None:
            err_console.print(f"wrote {written}", markup=False, highlight=False)
    emit(result, as_json)


@command
def demo_cmd(
    out: Annotated[
        str, typer.Option("--out", help="Folder for the report (created if missing).")
    ] = ".",
    as_json: JsonOption = False,
    tolerance: ToleranceOption = None,
    debug: DebugOption = False,
) -> None:
    """Plan the bundled 14-part gearbox and write its HTML report (start here)."""
    from assemblykit.demo import run_demo

    with _progress_bar() as bar:
        result = run_demo(out, tol=tolerance_from(tolerance), progress=_updater(bar))
    if as_json:
        emit(result, as_json)
    else:
        # soft wrap: the report's path must stay whole to be copied
        console.print(result.render(), soft_wrap=True)


@command
def batch_cmd(
    inputs: Annotated[list[str], typer.Argument(help="Assemblies (files or mesh folders).")],
    out: Annotated[str, typer.Option("--out", help="JSON Lines file (appended to).")] = (
        "results.jsonl"
    ),
    engine: Annotated[
        str, typer.Option("--engine", help="local (processes here) or dask.")
    ] = "local",
    scheduler: Annotated[
        str | None, typer.Option("--scheduler", help="Dask scheduler address (else a local one).")
    ] = None,
    run: Annotated[str, typer.Option("--command", help="plan or motion.")] = "plan",
    timeout: Annotated[
        float | None, typer.Option("--timeout", help="Seconds allowed per assembly.")
    ] = None,
    workers: Annotated[int, typer.Option("--workers", help="Assemblies run at once.")] = 2,
    as_json: JsonOption = False,
    tolerance: ToleranceOption = None,
    debug: DebugOption = False,
) -> None:
    """Run plan or motion over many assemblies: one JSON line each; reruns skip done ones."""
    from assemblykit.batch import run_batch

    if run not in ("plan", "motion"):
        raise InputError(f"unknown command {run!r} (use plan or motion)", where="--command")
    with _progress_bar() as bar:
        task = bar.add_task("assemblies", total=len(inputs))
        summary = run_batch(
            inputs,
            out,
            engine=engine,  # type: ignore[arg-type]
            command=run,  # type: ignore[arg-type]
            timeout=timeout,
            workers=workers,
            scheduler=scheduler,
            rel_tolerance=tolerance,
            progress=lambda done, total: bar.update(task, completed=done, total=total),
        )
    emit(summary, as_json)


SubassemblyOption = Annotated[
    list[str] | None,
    typer.Option(
        "--subassembly",
        help="Comma-separated parts that move together (e.g. a,b); repeat for several.",
    ),
]
HtmlOption = Annotated[
    str | None, typer.Option("--html", help="Also write a self-contained HTML view to FILE.")
]


def _is_task_file(path: str) -> bool:
    """Whether ``path`` is a task: ``.rapt``, or YAML/JSON whose top level has
    ``situations`` (DESIGN.md §5.1); anything else is read as an assembly."""
    from pathlib import Path

    import yaml

    file = Path(path)
    suffix = file.suffix.lower()
    if suffix == ".rapt":
        return True
    if suffix not in (".yaml", ".yml", ".json") or not file.is_file():
        return False
    try:
        data = yaml.safe_load(file.read_text())
    except (yaml.YAMLError, UnicodeDecodeError):
        return False
    return isinstance(data, dict) and "situations" in data


def _task_motion(path: str, tol: Tolerance, as_json: bool) -> None:
    """Emit the motion of every body of the task at ``path`` from its relations."""
    from assemblykit.inference.reduction import model_scale
    from assemblykit.io.spec import load_task
    from assemblykit.motion.relational import task_motion

    task = load_task(path)
    emit(_RoundedResult(task_motion(task, tol), tol.with_scale(model_scale(task))), as_json)


@command
def motion_cmd(
    assembly: Annotated[
        str,
        typer.Argument(
            help="Assembly (mesh folder, .yaml manifest, .step or COMPAS .json) "
            "or task (.yaml/.json with situations, or .rapt)."
        ),
    ],
    subassembly: SubassemblyOption = None,
    html: HtmlOption = None,
    as_json: JsonOption = False,
    tolerance: ToleranceOption = None,
    as_written: AsWrittenOption = False,
    debug: DebugOption = False,
) -> None:
    """Motion of each part and subassembly relative to the rest, gear trains (seed 003);
    on a task, of each body in each situation from the relations it takes part in."""
    from assemblykit.motion.articulation import articulation

    tol = tolerance_from(tolerance)
    if _is_task_file(assembly):
        if subassembly or html is not None:
            raise InputError("--subassembly and --html apply to assemblies, not tasks")
        _task_motion(assembly, tol, as_json)
        return
    loaded = loaded_assembly(assembly, tol, as_written)
    sets = [[n.strip() for n in spec.split(",") if n.strip()] for spec in subassembly or ()]
    if any(not names for names in sets):
        raise InputError("--subassembly needs comma-separated part names", source=assembly)
    result = articulation(loaded, sets, tol)
    if html is not None:
        from assemblykit.viz.motion_view import write_motion_html

        write_motion_html(loaded, result.report, html)
    emit(_RoundedResult(result, loaded.tolerance(tol)), as_json)


class _RoundedResult:
    """A result whose JSON numbers are rounded by the model's tolerance (io.report)."""

    def __init__(self, result: Result, tol: Tolerance) -> None:
        self.result = result
        self.tol = tol

    def to_dict(self) -> dict[str, Any]:
        from assemblykit.io.report import jsonable

        return jsonable(self.result.to_dict(), self.tol)  # type: ignore[return-value]

    def render(self) -> Any:
        return self.result.render()


PngOption = Annotated[
    str | None, typer.Option("--png", help="Also write a PNG of the parts and contacts to FILE.")
]


@command
def contacts_cmd(
    assembly: AssemblyArgument,
    png: PngOption = None,
    as_json: JsonOption = False,
    tolerance: ToleranceOption = None,
    as_written: AsWrittenOption = False,
    debug: DebugOption = False,
) -> None:
    """Parts, contact patches (areas, normals), surface features and interferences."""
    from assemblykit.io.assembly import contact_report

    tol = tolerance_from(tolerance)
    result = contact_report(loaded_assembly(assembly, tol, as_written), tol)
    if png is not None:
        from assemblykit.viz.plots import plot_contacts

        plot_contacts(result.assembly, result.contacts, png)
    emit(result, as_json)


BLOCKING_MOTIONS = ("infinitesimal", "extended", "rigid")


@command
def blocking_cmd(
    assembly: Annotated[
        str,
        typer.Argument(
            help="Assembly (mesh folder, .yaml manifest, .step, COMPAS .json) or a YAML "
            "file of 2D polygons 'parts: {name: [[x, y], ...]}'."
        ),
    ],
    motion: Annotated[
        str, typer.Option("--motion", help="infinitesimal, extended or rigid.")
    ] = "infinitesimal",
    png: Annotated[
        str | None,
        typer.Option("--png", help="Also write a PNG of the arrangement and a DBG to FILE."),
    ] = None,
    as_json: JsonOption = False,
    tolerance: ToleranceOption = None,
    as_written: AsWrittenOption = False,
    debug: DebugOption = False,
) -> None:
    """Non-directional blocking graph: regions of directions, removable subassemblies."""
    from assemblykit.blocking.ndbg import blocking_graph
    from assemblykit.blocking.polygons import is_polygon_file, load_polygons

    if motion not in BLOCKING_MOTIONS:
        raise InputError(
            f"unknown motion {motion!r} (choose {', '.join(BLOCKING_MOTIONS)})", where="--motion"
        )
    tol = tolerance_from(tolerance)
    if is_polygon_file(assembly):
        model: Any = load_polygons(assembly)
    else:
        model = loaded_assembly(assembly, tol, as_written)
    result = blocking_graph(model, motion, tol=tol)  # type: ignore[arg-type]
    if png is not None:
        if motion == "rigid":
            raise InputError("--png draws the direction sphere: not for --motion rigid")
        from assemblykit.viz.plots import plot_ndbg

        plot_ndbg(result, png)
    emit(result, as_json)


@command
def mate_cmd(
    problem: Annotated[str, typer.Argument(help="Mating problem: .yaml, .yml or .json.")],
    as_json: JsonOption = False,
    tolerance: ToleranceOption = None,
    debug: DebugOption = False,
) -> None:
    """Mating inference (seed 002): which compound features mate to satisfy the goals."""
    from assemblykit.io.problem import load_problem
    from assemblykit.mating.search import mate

    emit(mate(load_problem(problem, tolerance_from(tolerance))), as_json)
