"""The ``assemblykit`` command (docs/architecture.md, "Results and errors").

Every command takes ``INPUT``, ``--json`` (the documented JSON on stdout), ``--tolerance``
(relative length tolerance; ``solve`` and ``motion`` also take ``--angle-tolerance``, which
otherwise follows it) and ``--debug`` (tracebacks); the commands that load an
assembly take ``--as-written`` (keep rounded mesh-folder poses unsettled). Exit codes: 0
for every answer (including *inconsistent* or *infeasible*), 2 for bad input (one line on
stderr naming the file and the fault), 1 for an internal error, 130 after Ctrl-C (one
line, "assemblykit: interrupted").
"""

from __future__ import annotations

import contextlib
import functools
import json
import re
import sys
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal, NoReturn, Protocol

import click

from assemblykit import __version__
from assemblykit.errors import AssemblyKitError, InputError, MissingExtraError
from assemblykit.outputs import HTML_SUFFIXES, PNG_SUFFIXES, checked_output
from assemblykit.tolerance import MAX_ANGLE, MAX_REL_LENGTH, MIN_ANGLE, MIN_REL_LENGTH, Tolerance

if TYPE_CHECKING:
    from rich.console import Console

    from assemblykit.blocking.ndbg import Motion
    from assemblykit.model.assembly import Assembly
    from assemblykit.planning.stability import Gravity

# Output captured by a program (a pipe, a file, a test) is laid out at this width whatever
# the terminal says, so that what machines read never depends on COLUMNS.
PLAIN_WIDTH = 120

INTERRUPTED = 130
"""Exit code after Ctrl-C (SIGINT): 128 + the signal's number, as shells report it."""


class Interrupted(BaseException):
    """Ctrl-C during a command. A :class:`BaseException` like :class:`KeyboardInterrupt`,
    so that no ``except Exception`` stops it; click turns only the latter into its own
    message."""


class _Commands(click.Group):
    """The command group, passing an interruption on as :class:`Interrupted`."""

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt:
            raise Interrupted from None


@click.group(
    cls=_Commands,
    name="assemblykit",
    context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100},
    no_args_is_help=True,
)
@click.version_option(__version__, "--version", "-V", prog_name="assemblykit")
def app() -> None:
    """Geometric reasoning about mechanical assemblies."""


@functools.cache
def console(stderr: bool = False) -> Console:
    """The rich console of stdout (or stderr): the terminal's width when it is one,
    ``PLAIN_WIDTH`` otherwise."""
    from rich.console import Console

    stream = sys.stderr if stderr else sys.stdout
    width = None if stream.isatty() else PLAIN_WIDTH
    return Console(stderr=stderr, width=width)


def _option_fault(message: str, param: click.Parameter | None) -> NoReturn:
    """A bad option value as bad input: one line naming the option and exit 2, like a
    bad file (click's own faults print the whole usage)."""
    option = param.opts[0] if param is not None and param.opts else None
    raise InputError(message, where=option)


class _BadInput:
    """What a range of :func:`_option_fault` faults shares: a value typed on the command
    line is first read as a number (``parse``: it is ``what``, else one line says it is
    not) and checked against the range in words (:meth:`outside`), before click's own
    conversion, whose words name its types ("not a valid float range", "x>=0")."""

    parse: Callable[[str], float]
    what: str
    min: Any
    max: Any
    min_open: bool
    max_open: bool

    def fail(
        self, message: str, param: click.Parameter | None = None, ctx: click.Context | None = None
    ) -> NoReturn:
        _option_fault(message, param)

    def outside(self, number: float) -> str | None:
        """What ``number`` misses of the range, in words ("must be at least 1"), or
        ``None`` when it is inside."""
        low, high = self.min, self.max
        if low is not None and (number <= low if self.min_open else number < low):
            return f"must be {'more than' if self.min_open else 'at least'} {low:g}"
        if high is not None and (number >= high if self.max_open else number > high):
            return f"must be {'less than' if self.max_open else 'at most'} {high:g}"
        return None

    def checked(self, value: Any, param: click.Parameter | None) -> None:
        """Fail on a typed ``value`` that is not a number or lies outside the range."""
        if not isinstance(value, str):
            return
        try:
            number = self.parse(value)
        except ValueError:
            self.fail(f"{value!r} is not {self.what}", param)
        missed = self.outside(number)
        if missed is not None:
            self.fail(f"{value} {missed}", param)


class _OptionRange(_BadInput, click.FloatRange):
    """A number in a range whose faults are bad input (:class:`_BadInput`)."""

    parse = float
    what = "a number"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        self.checked(value, param)
        number = super().convert(value, param, ctx)
        if number != number:  # NaN passes every range comparison
            self.fail(f"{value!r} is not a number", param, ctx)
        if abs(number) == float("inf"):
            self.fail(f"{value!r} is not a finite number", param, ctx)
        return number


class _CountRange(_BadInput, click.IntRange):
    """A whole number in a range whose faults are bad input (:class:`_BadInput`)."""

    parse = int
    what = "a whole number"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        self.checked(value, param)
        return super().convert(value, param, ctx)


json_option = click.option(
    "--json", "as_json", is_flag=True, help="Print the result as JSON on stdout."
)
tolerance_option = click.option(
    "--tolerance",
    type=_OptionRange(MIN_REL_LENGTH, MAX_REL_LENGTH),
    default=None,
    help="Relative length tolerance (fraction of the model's bounding-box diagonal);"
    " the angle tolerance follows it unless --angle-tolerance is given.",
)
angle_tolerance_option = click.option(
    "--angle-tolerance",
    type=_OptionRange(MIN_ANGLE, MAX_ANGLE),
    default=None,
    help="Angle tolerance in radians (default: the --tolerance value, else 1e-9).",
)
debug_option = click.option("--debug", is_flag=True, help="Show tracebacks on errors.")
as_written_option = click.option(
    "--as-written",
    is_flag=True,
    help="Keep rounded mesh-folder poses as written (do not settle thin overlaps).",
)
partial_option = click.option(
    "--partial",
    is_flag=True,
    help="Work on the parts of a damaged STEP file that could be read (they are listed).",
)
assembly_argument = click.argument("assembly", metavar="ASSEMBLY")
ASSEMBLY_HELP = "ASSEMBLY: mesh folder, .yaml manifest, .step or COMPAS .json."


class Result(Protocol):
    """What every command returns: JSON via ``to_dict``; :func:`assemblykit.render.render`
    gives its readable form."""

    def to_dict(self) -> dict[str, Any]: ...


def tolerance_from(option: float | None, angle: float | None = None) -> Tolerance:
    """The tolerance policy with the command line's ``--tolerance`` and
    ``--angle-tolerance`` applied (the angle follows ``--tolerance`` unless given)."""
    return Tolerance.relative(option, angle)


def loaded_assembly(path: str, tol: Tolerance, as_written: bool, partial: bool = False) -> Assembly:
    """The assembly at ``path`` with the command line's tolerance, settled unless
    ``--as-written``; what the loader skipped is said on stderr. A file damaged where
    solids should be (:attr:`Skipped.unreadable`) is bad input unless ``--partial``."""
    from assemblykit.io.assembly import load_assembly

    loaded = load_assembly(path, tol, settle=not as_written)
    damaged = [item for item in loaded.skipped if item.unreadable]
    if damaged and not partial:
        first = damaged[0]
        raise InputError(
            f"damaged: {first.item}: {first.reason}"
            + (f" (and {len(damaged) - 1} more)" if len(damaged) > 1 else "")
            + f"; --partial works on the {len(loaded.parts)} parts read",
            source=path,
        )
    for item in loaded.skipped:
        note(f"{path}: skipped {item.item}: {item.reason}")
    return loaded


def assembly_or_polygons(path: str, tol: Tolerance, as_written: bool, partial: bool = False) -> Any:
    """A YAML file of 2D polygons (``parts: {name: [[x, y], ...]}``) as a polygon
    assembly, anything else as :func:`loaded_assembly`."""
    from assemblykit.io.polygons import is_polygon_file, load_polygons

    if is_polygon_file(path):
        return load_polygons(path)
    return loaded_assembly(path, tol, as_written, partial)


def emit(
    result: Result, as_json: bool, rounding: Tolerance | None = None, shown: Tolerance | None = None
) -> None:
    """Print a result: JSON on stdout, its numbers rounded by the model's tolerance
    ``rounding`` when given (io.report), or its rich rendering written with the model's
    tolerance ``shown`` (else ``rounding``) in force: directions within its angle of an
    axis print as ``+X``, numbers within its length as 0 (docs/architecture.md, "Numbers
    for people")."""
    if as_json:
        data: Any = result.to_dict()
        if rounding is not None:
            from assemblykit.io.report import jsonable

            data = jsonable(data, rounding)
        sys.stdout.write(json.dumps(data, indent=2) + "\n")
    else:
        from assemblykit.render import render
        from assemblykit.tolerance import current, using

        with using(shown or rounding or current()):
            # lines longer than the width (a trace, a path) are wrapped or kept, never cut
            console().print(render(result), crop=False)


def note(message: str) -> None:
    """One line on stderr, printed as written (no markup, no wrapping)."""
    console(stderr=True).print(message, markup=False, highlight=False, soft_wrap=True)


def _fail(message: str, code: int) -> None:
    # one line whatever the message holds (parsers' messages may span lines)
    note(f"assemblykit: {' '.join(message.split())}")
    raise SystemExit(code)


DIRECTION_OPTIONS = ("--gravity",)
"""Options whose optional value is a direction, which may start with a minus (``-z``)."""
_DIRECTION = re.compile(r"^[+-]?[xyzXYZ]$|^[+-]?[\d.eE+-]+(,[+-]?[\d.eE+-]+){2}$")


def _direction_values(args: list[str]) -> list[str]:
    """``args`` with a direction given to a :data:`DIRECTION_OPTIONS` option (``--gravity
    -z``, ``--gravity=-z``) protected by a leading space: click takes a word starting
    with a minus after an option with an optional value for the next option."""
    result: list[str] = []
    for k, arg in enumerate(args):
        name, equals, value = arg.partition("=")
        if equals and name in DIRECTION_OPTIONS and _DIRECTION.match(value):
            result.append(f"{name}= {value}")
        elif k > 0 and args[k - 1] in DIRECTION_OPTIONS and _DIRECTION.match(arg):
            result.append(f" {arg}")
        else:
            result.append(arg)
    return result


def main(argv: list[str] | None = None) -> None:
    """Entry point of the console script: maps errors to one line and an exit code
    (a usage error is one line naming the help to read and exits 2, like bad input;
    Ctrl-C prints
    "assemblykit: interrupted" and exits ``INTERRUPTED``). Without ``--debug``,
    RuntimeWarnings are not shown."""
    args = _direction_values(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in args
    try:
        with warnings.catch_warnings():
            if not debug:
                # numpy and trimesh report floating-point edge cases (0/0 on a degenerate
                # facet, ...) that the algorithms handle; to a user they are noise
                warnings.simplefilter("ignore", RuntimeWarning)
            app.main(args=args, prog_name="assemblykit", standalone_mode=False)
    except click.exceptions.Exit as done:
        raise SystemExit(done.exit_code) from None
    except click.UsageError as usage:
        if debug:
            raise
        path = usage.ctx.command_path if usage.ctx is not None else "assemblykit"
        _fail(f"{usage.format_message()} (see '{path} --help')", 2)
    except click.ClickException as bad:
        if debug:
            raise
        _fail(bad.format_message(), 2)
    except (Interrupted, click.exceptions.Abort, KeyboardInterrupt):
        _fail("interrupted", INTERRUPTED)
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


def command(fn: Callable[..., None]) -> click.Command:
    """Register ``fn`` as a sub-command named after it (underscores become dashes)."""
    return app.command(name=fn.__name__.removesuffix("_cmd").replace("_", "-"))(fn)


# Commands follow; each one is a thin layer over the library's public API.


@command
@click.argument("task")
@json_option
@tolerance_option
@angle_tolerance_option
@click.option("--explain", is_flag=True, help="Also print the reduction steps (the trace).")
@click.option(
    "--max-branches",
    type=_CountRange(min=1, max=100_000),
    default=None,
    help="Most finite alternatives (discrete poses, assembly modes) followed to the end "
    "(default 64).",
)
@click.option("--png", default=None, help="Also write a PNG of the bodies and their freedom here.")
@debug_option
def solve_cmd(
    task: str,
    as_json: bool,
    tolerance: float | None,
    angle_tolerance: float | None,
    explain: bool,
    max_branches: int | None,
    png: str | None,
    debug: bool,
) -> None:
    """Pose of every body in every situation of a task (RAPT network reduction,
    Corner, Ambler & Popplestone 1983).

    TASK: task file, .yaml, .yml, .json or .rapt.
    """
    from assemblykit.inference import solve_task
    from assemblykit.io.tasks import load_task
    from assemblykit.tolerance import using

    if png is not None:
        checked_output(png, "--png", PNG_SUFFIXES)
    # The engine scales the policy to the model's size; only the relative part comes from here.
    with using(tolerance_from(tolerance, angle_tolerance)):
        loaded = load_task(task)
        result = solve_task(loaded, explain=explain, max_branches=max_branches)
        if png is not None:
            from assemblykit.viz.task_view import write_task_png

            note(f"wrote {write_task_png(loaded, result, png)}")
        emit(result, as_json)


def _progress_bar() -> Any:
    """A rich progress bar on stderr (shown when stderr is a terminal)."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    err = console(stderr=True)
    bar = Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=err,
        transient=True,
        disable=not err.is_terminal,
    )
    if bar.disable:
        # never started nor stopped: rich before 14.3 ends even a disabled bar with a
        # blank line on a stream that is not a terminal
        return contextlib.nullcontext(bar)
    return bar


def _updater(bar: Any) -> Callable[[str, int, int], None]:
    task = bar.add_task("loading", total=None)

    def update(stage: str, done: int, total: int) -> None:
        bar.update(task, description=stage, completed=done, total=total)

    return update


def _plan_input(
    path: str, tol: Tolerance, as_written: bool, problem: int, solution: int, partial: bool
) -> Any:
    """What ``plan`` reads: a BurrTools puzzle placed as ``solution`` of ``problem``, or
    :func:`assembly_or_polygons`."""
    if path.lower().endswith(".xmpuzzle"):
        from assemblykit.io.burrtools import load_burrtools

        return load_burrtools(path, tol, problem, solution)
    return assembly_or_polygons(path, tol, as_written, partial)


@dataclass(frozen=True)
class PlanRequest:
    """What ``plan`` is asked besides the assembly: the options its modes read."""

    tol: Tolerance | None
    progress: Callable[[str, int, int], None]
    fixed: tuple[str, ...] = ()
    max_hands: int = 4
    gravity: Gravity | None = None
    one_at_a_time: bool = False
    max_steps: int | None = None
    ground: bool = True
    max_states: int | None = None


@dataclass(frozen=True)
class PlanMode:
    """A way the ``plan`` command plans (``--moves``): its planner (``run``) and the
    options it takes. Only plans of single translations (``monotone``) take the options
    of that search (:data:`TRANSLATION_OPTIONS`) and plan polygons in the plane; the
    others move 3D parts, and what it moves them by is its ``motion`` (said when it is
    given polygons)."""

    name: str
    translations: bool
    run: Callable[[Any, PlanRequest], Result]
    motion: str = "moves"

    def check_options(self, given: set[str]) -> None:
        """:class:`InputError` naming the first group of ``given`` options this mode does
        not take."""
        if self.translations:
            return
        for options, use in TRANSLATION_OPTIONS:
            if given & set(options):
                raise InputError(f"{_listed(options)} {use}: not with --moves {self.name}")

    def check_plane(self, given: set[str], source: str) -> None:
        """:class:`InputError` naming ``source`` when this mode, with the ``given``
        options, cannot plan it, an assembly of polygons in the plane."""
        said = "not for a 2D polygon assembly"
        if not self.translations:
            raise InputError(f"--moves {self.name} {self.motion} 3D parts: {said}", source=source)
        for options in PLANE_REFUSED:
            if given & set(options):
                verb = "draws" if len(options) == 1 else "draw"
                raise InputError(f"{_listed(options)} {verb} meshes: {said}", source=source)


TRANSLATION_OPTIONS = (
    (("--html", "--png"), "draw translation plans"),
    (("--gravity", "--one-at-a-time", "--max-steps"), "plan translations"),
    (("--out", "--gltf"), "export translation plans"),
)
"""The options of ``plan`` that only plans of single translations take, and what they do."""

PLANE_REFUSED = (("--gltf",), ("--html", "--png"))
"""The options of ``plan`` that draw meshes, which an assembly of polygons has not."""


def _listed(options: tuple[str, ...]) -> str:
    """``a``, ``a and b``, ``a, b and c``."""
    return options[0] if len(options) == 1 else f"{', '.join(options[:-1])} and {options[-1]}"


def _monotone_plan(loaded: Any, request: PlanRequest) -> Result:
    """The plan of single translations (Wilson & Latombe 1992), under gravity when asked."""
    from assemblykit.planning.planner import plan

    return plan(
        loaded,
        tol=request.tol,
        progress=request.progress,
        max_hands=request.max_hands,
        gravity=request.gravity,
        one_at_a_time=request.one_at_a_time,
        max_steps=request.max_steps,
        fixed=request.fixed,
        ground=request.ground,
    )


def _multi_move_plan(loaded: Any, request: PlanRequest) -> Result:
    """The multi-move plan of a loaded voxel puzzle, compared with its stored level, or
    of a mesh assembly, never moving the ``fixed`` parts (docs/planning.md, "Fixed
    parts")."""
    from assemblykit.planning.multimove import MAX_STATES, plan_voxels
    from assemblykit.planning.multimove_mesh import plan_meshes

    limit = MAX_STATES if request.max_states is None else request.max_states
    progress, fixed = request.progress, request.fixed
    if loaded.kind != "voxels":
        return plan_meshes(loaded, request.tol, max_states=limit, progress=progress, fixed=fixed)
    puzzle = loaded.puzzle
    return plan_voxels(
        puzzle.names,
        [p.voxels for p in puzzle.pieces],
        [p.group for p in puzzle.pieces],
        max_states=limit,
        reference_level=puzzle.level,
        progress=progress,
        fixed=fixed,
    )


def _screw_plan(loaded: Any, request: PlanRequest) -> Result:
    """The plan of rigid motions: translations, turns and screws (docs/planning.md)."""
    from assemblykit.planning.screw import plan_with_screws

    return plan_with_screws(loaded, request.tol, fixed=request.fixed)


PLAN_MODES = {
    "monotone": PlanMode("monotone", translations=True, run=_monotone_plan),
    "multi": PlanMode("multi", translations=False, run=_multi_move_plan),
    "rigid": PlanMode("rigid", translations=False, run=_screw_plan, motion="turns"),
}
"""The ways of ``plan --moves``."""


@dataclass(frozen=True)
class PlanFiles:
    """The files ``plan`` writes for a plan of translations (``None``: not asked)."""

    html: str | None
    png: str | None
    out: str | None
    gltf: str | None
    plotly: Literal["inline", "cdn"] = "inline"


def _write_plan(
    loaded: Any, result: Any, files: PlanFiles, update: Callable[[str, int, int], None]
) -> None:
    """Write the report, the exploded view, the step table and the glTF scene asked for."""
    if files.html is not None:
        from assemblykit.viz.viewer import write_report

        update("writing the report", 0, 1)
        write_report(loaded, result, files.html, plotlyjs=files.plotly)
    if files.png is not None:
        from assemblykit.viz.plots import exploded_view_png

        update("drawing the exploded view", 0, 1)
        exploded_view_png(loaded, result, files.png)
    if files.out is not None:
        from assemblykit.io.exports import write_plan

        write_plan(result, files.out, loaded.tolerance())
    if files.gltf is not None:
        from assemblykit.io.exports import write_gltf

        update("writing the glTF scene", 0, 1)
        write_gltf(loaded, result, files.gltf, loaded.tolerance())


def _holds(extra: int | None, holds: int | None) -> int:
    """The holds of a step under gravity, the grip of the moved part included, from
    ``--extra-holds`` (the others) or the deprecated ``--holds`` (all of them), which
    says what to write instead."""
    if holds is None:
        return 1 + (extra or 0)
    if extra is not None:
        raise InputError("--holds and --extra-holds say the same: give --extra-holds alone")
    note(f"assemblykit: --holds is deprecated; --holds {holds} is --extra-holds {holds - 1}")
    return holds


def _gravity(
    direction: str | None, friction: float, holds: int, fixed: tuple[str, ...]
) -> Gravity | None:
    """The settings of ``plan --gravity`` (``None`` without it)."""
    if direction is None:
        return None
    from assemblykit.planning.stability import Gravity, gravity_direction

    down = gravity_direction(direction)
    return Gravity((float(down[0]), float(down[1]), float(down[2])), friction, holds, fixed or None)


@command
@assembly_argument
@click.option("--html", default=None, help="Write a self-contained HTML report here.")
@click.option("--png", default=None, help="Write a static exploded view (PNG) here.")
@click.option("--out", default=None, help="Write the step table here (.json or .csv).")
@click.option("--gltf", default=None, help="Write the exploded view as glTF here (.glb or .gltf).")
@click.option(
    "--plotly",
    type=click.Choice(["inline", "cdn"]),
    default="inline",
    show_default=True,
    help="--html: embed plotly.js (opens offline) or link it from its CDN (a small file).",
)
@click.option(
    "--max-hands",
    type=_CountRange(min=2),
    default=4,
    show_default=True,
    help="For parts no two-handed move separates: try up to this many hands.",
)
@click.option(
    "--moves",
    type=click.Choice(["monotone", "multi", "rigid"]),
    default="monotone",
    show_default=True,
    help="monotone: one translation per separation (NDBG); multi: sequences of "
    "translations (lattice moves for .xmpuzzle voxel puzzles, contact-change distances "
    "for meshes); rigid: monotone, then turns (screw motions) "
    "for what translations leave stuck.",
)
@click.option(
    "--max-states",
    type=_CountRange(min=1),
    default=None,
    help="--moves multi: states per separation before the search is cut [default: 250000].",
)
@click.option(
    "--problem", type=_CountRange(min=0), default=0, help=".xmpuzzle: the problem (from 0)."
)
@click.option(
    "--solution",
    type=_CountRange(min=0),
    default=0,
    help=".xmpuzzle: the stored solution giving the assembled position (from 0).",
)
@click.option(
    "--gravity",
    is_flag=False,
    flag_value="-z",
    default=None,
    metavar="[DIR]",
    help="Plan under gravity along DIR (-z when bare; +y, x, or a vector such as 0,-1,0): "
    "every state must stand (static equilibrium with friction).",
)
@click.option(
    "--friction",
    type=_OptionRange(min=0.0),
    default=0.5,
    show_default=True,
    help="--gravity: Coulomb friction coefficient of every contact.",
)
@click.option(
    "--extra-holds",
    type=_CountRange(min=0),
    default=None,
    help="--gravity: parts that may be held during a step besides the moved one, which "
    "its grip holds [default: 0, what remains stands alone].",
)
@click.option(
    "--holds",
    type=_CountRange(min=1),
    default=None,
    help="Deprecated: the holds counting the grip, --extra-holds K-1.",
)
@click.option(
    "--fixed",
    multiple=True,
    help="A part that never moves (ground, fixture), in every mode; repeatable "
    "[default under --gravity: the parts touching the lowest plane, taken off last].",
)
@click.option("--one-at-a-time", is_flag=True, help="Move one free set (a part) per step.")
@click.option(
    "--floating",
    is_flag=True,
    help="Plan free-floating: no ground under an input that stands on one [default: blocks "
    "declared supports, or resting on the lowest plane of a block assembly, are fixed and "
    "no part moves down through the plane under them].",
)
@click.option(
    "--join",
    nargs=2,
    multiple=True,
    metavar="A B",
    help="Treat parts A and B as one rigid part (glued, welded, riveted); repeatable.",
)
@click.option(
    "--join-interfering",
    is_flag=True,
    help="Treat every set of parts that share a volume as one rigid part.",
)
@click.option(
    "--split-products",
    is_flag=True,
    help="Plan the solids of a product of several solids (a STEP multi-body part) as "
    "separate parts [default: one part named after the product].",
)
@click.option(
    "--ignore-overlap",
    type=_OptionRange(min=0.0),
    default=None,
    metavar="V",
    help="Parts sharing at most this volume (model units cubed) are designed "
    "interference: it is cut from the smaller one [default: 25% of the smaller "
    "part's volume; 0 cuts nothing].",
)
@click.option(
    "--max-steps",
    type=_CountRange(min=0),
    default=None,
    help="Stop after this many steps; the parts not yet taken apart are listed as unfinished.",
)
@json_option
@tolerance_option
@as_written_option
@partial_option
@debug_option
def plan_cmd(
    assembly: str,
    html: str | None,
    png: str | None,
    out: str | None,
    gltf: str | None,
    plotly: Literal["inline", "cdn"],
    max_hands: int,
    moves: str,
    max_states: int | None,
    problem: int,
    solution: int,
    gravity: str | None,
    friction: float,
    extra_holds: int | None,
    holds: int | None,
    fixed: tuple[str, ...],
    one_at_a_time: bool,
    floating: bool,
    join: tuple[tuple[str, str], ...],
    join_interfering: bool,
    split_products: bool,
    ignore_overlap: float | None,
    max_steps: int | None,
    as_json: bool,
    tolerance: float | None,
    as_written: bool,
    partial: bool,
    debug: bool,
) -> None:
    """Disassembly (and assembly) sequence by extended translations (Wilson & Latombe
    1992), or by sequences of translations for interlocking parts (--moves multi).

    ASSEMBLY: mesh folder, .yaml manifest, .step, COMPAS .json, or a YAML file of 2D
    polygons 'parts: {name: [[x, y], ...]}' (planned in the plane), or a BurrTools
    .xmpuzzle (placed as its stored --solution of --problem).
    """
    mode = PLAN_MODES[moves]
    given = {
        "--html": html is not None,
        "--png": png is not None,
        "--out": out is not None,
        "--gltf": gltf is not None,
        "--gravity": gravity is not None,
        "--one-at-a-time": one_at_a_time,
        "--max-steps": max_steps is not None,
    }
    mode.check_options({option for option, on in given.items() if on})
    if html is not None:
        checked_output(html, "--html", HTML_SUFFIXES)
    if png is not None:
        checked_output(png, "--png", PNG_SUFFIXES)
    from assemblykit.io.exports import GLTF_SUFFIXES, PLAN_SUFFIXES

    if out is not None:
        checked_output(out, "--out", PLAN_SUFFIXES)
    if gltf is not None:
        checked_output(gltf, "--gltf", GLTF_SUFFIXES)
    tol = tolerance_from(tolerance)
    with _progress_bar() as bar:
        update = _updater(bar)
        loaded = _plan_input(assembly, tol, as_written, problem, solution, partial)
        if loaded.kind == "meshes":
            from assemblykit.geometry.overlaps import resolve_overlaps

            update("interfering parts", 0, 1)
            loaded = resolve_overlaps(
                loaded,
                join,
                join_interfering,
                ignore_overlap,
                join_products=not split_products,
            )
        elif join or join_interfering:
            raise InputError("--join and --join-interfering need 3D parts")
        if loaded.dimension == 2:
            mode.check_plane({option for option, on in given.items() if on}, assembly)
        request = PlanRequest(
            tol,
            update,
            fixed,
            max_hands=max_hands,
            gravity=_gravity(gravity, friction, _holds(extra_holds, holds), fixed),
            one_at_a_time=one_at_a_time,
            max_steps=max_steps,
            ground=not floating,
            max_states=max_states,
        )
        result = mode.run(loaded, request)
        if mode.translations:
            _write_plan(loaded, result, PlanFiles(html, png, out, gltf, plotly), update)
    for written in (html, png, out, gltf):
        if written is not None:
            note(f"wrote {written}")
    emit(result, as_json, shown=loaded.tolerance())


@command
@click.option("--out", default=".", help="Folder for the report (created if missing).")
@json_option
@tolerance_option
@debug_option
def demo_cmd(out: str, as_json: bool, tolerance: float | None, debug: bool) -> None:
    """Plan the bundled 14-part gearbox and write its HTML report (start here)."""
    from pathlib import Path

    from assemblykit.demo import REPORT_NAME, run_demo

    folder = Path(out)
    if folder.exists() and not folder.is_dir():
        raise InputError(
            "is a file; --out names the folder of the report", source=out, where="--out"
        )
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise InputError(
            f"cannot make the folder ({error.strerror or type(error).__name__})",
            source=out,
            where="--out",
        ) from None
    checked_output(folder / REPORT_NAME, "--out")
    with _progress_bar() as bar:
        result = run_demo(out, tol=tolerance_from(tolerance), progress=_updater(bar))
    if as_json:
        emit(result, as_json)
    else:
        from assemblykit.render import render

        # soft wrap: the report's path must stay whole to be copied
        console().print(render(result), soft_wrap=True)


@command
@click.argument("inputs", nargs=-1, required=True)
@click.option("--out", default="results.jsonl", help="JSON Lines file (appended to).")
@click.option(
    "--engine",
    type=click.Choice(["local", "dask"]),
    default="local",
    help="local (processes here) or dask.",
)
@click.option("--scheduler", default=None, help="Dask scheduler address (else a local one).")
@click.option(
    "--command",
    "run",
    type=click.Choice(["plan", "motion"]),
    default="plan",
    help="plan or motion.",
)
@click.option(
    "--timeout",
    type=_OptionRange(min=0.0, min_open=True),
    default=None,
    help="Seconds allowed per assembly (more than 0).",
)
@click.option("--workers", type=_CountRange(min=1), default=2, help="Assemblies run at once.")
@json_option
@tolerance_option
@debug_option
def batch_cmd(
    inputs: tuple[str, ...],
    out: str,
    engine: str,
    scheduler: str | None,
    run: str,
    timeout: float | None,
    workers: int,
    as_json: bool,
    tolerance: float | None,
    debug: bool,
) -> None:
    """Run plan or motion over many assemblies: one JSON line each; reruns skip done ones.

    INPUTS: assemblies (files or mesh folders).
    """
    from assemblykit.batch import run_batch

    checked_output(out, "--out")
    with _progress_bar() as bar:
        task = bar.add_task("assemblies", total=len(inputs))
        summary = run_batch(
            list(inputs),
            out,
            engine=engine,  # type: ignore[arg-type]
            command=run,  # type: ignore[arg-type]
            timeout=timeout,
            workers=workers,
            scheduler=scheduler,
            rel_tolerance=tolerance,
            progress=lambda done, total: bar.update(task, completed=done, total=total),
            notice=note,
        )
    emit(summary, as_json)
    if summary.missing:
        raise InputError(f"not found: {', '.join(summary.missing)} (tried again on the next run)")


def _is_task_file(path: str) -> bool:
    """Whether ``path`` is a task: ``.rapt``, or YAML/JSON whose top level has
    ``situations`` (docs/tutorial.md §1); anything else is read as an assembly."""
    from pathlib import Path

    from assemblykit.io.documents import read_text, read_yaml

    file = Path(path)
    suffix = file.suffix.lower()
    if suffix == ".rapt":
        return True
    if suffix not in (".yaml", ".yml", ".json") or not file.is_file():
        return False
    try:
        data = read_yaml(read_text(file))
    except InputError:
        return False  # the assembly loaders name the fault
    return isinstance(data, dict) and "situations" in data


def _task_motion(path: str, tol: Tolerance, as_json: bool) -> None:
    """Emit the motion of every body of the task at ``path`` from its relations."""
    from assemblykit.inference.reduction import task_tolerance
    from assemblykit.io.tasks import load_task
    from assemblykit.motion.relational import task_motion

    task = load_task(path)
    emit(task_motion(task, tol), as_json, task_tolerance(task, tol))


@command
@click.argument("assembly")
@click.option(
    "--subassembly",
    multiple=True,
    help="Comma-separated parts that move together (e.g. a,b), or the name of a "
    "subassembly of a STEP file; repeat for several.",
)
@click.option("--html", default=None, help="Also write a self-contained HTML view to FILE.")
@click.option(
    "--split-products",
    is_flag=True,
    help="Take the solids of a product of several solids (a STEP multi-body part) as "
    "separate parts [default: one rigid part named after the product].",
)
@json_option
@tolerance_option
@angle_tolerance_option
@as_written_option
@partial_option
@debug_option
def motion_cmd(
    assembly: str,
    subassembly: tuple[str, ...],
    html: str | None,
    split_products: bool,
    as_json: bool,
    tolerance: float | None,
    angle_tolerance: float | None,
    as_written: bool,
    partial: bool,
    debug: bool,
) -> None:
    """Motion of each part and subassembly relative to the rest, gear trains (Liu 1997);
    on a task, of each body in each situation from the relations it takes part in.

    ASSEMBLY: mesh folder, .yaml manifest, .step or COMPAS .json, or a task (.yaml/.json
    with situations, or .rapt).
    """
    from assemblykit.motion.articulation import articulation

    if html is not None:
        checked_output(html, "--html", HTML_SUFFIXES)
    tol = tolerance_from(tolerance, angle_tolerance)
    if _is_task_file(assembly):
        if subassembly or html is not None:
            raise InputError("--subassembly and --html apply to assemblies, not tasks")
        _task_motion(assembly, tol, as_json)
        return
    loaded = loaded_assembly(assembly, tol, as_written, partial)
    if not split_products:
        from assemblykit.geometry.overlaps import join_products

        loaded = join_products(loaded)
    sets = [
        loaded.groups.get(spec.strip()) or [n.strip() for n in spec.split(",") if n.strip()]
        for spec in subassembly
    ]
    if any(not names for names in sets):
        raise InputError("--subassembly needs comma-separated part names", source=assembly)
    result = articulation(loaded, sets, tol)
    if html is not None:
        from assemblykit.viz.motion_view import write_motion_html

        write_motion_html(loaded, result.report, html)
    emit(result, as_json, loaded.tolerance(tol))


@command
@assembly_argument
@click.option("--png", default=None, help="Also write a PNG of the parts and contacts to FILE.")
@json_option
@tolerance_option
@as_written_option
@partial_option
@debug_option
def contacts_cmd(
    assembly: str,
    png: str | None,
    as_json: bool,
    tolerance: float | None,
    as_written: bool,
    partial: bool,
    debug: bool,
) -> None:
    """Parts, contact patches (areas, normals), surface features and interferences.

    ASSEMBLY: mesh folder, .yaml manifest, .step or COMPAS .json.
    """
    from assemblykit.io.assembly import contact_report

    if png is not None:
        checked_output(png, "--png", PNG_SUFFIXES)
    tol = tolerance_from(tolerance)
    result = contact_report(loaded_assembly(assembly, tol, as_written, partial), tol)
    if png is not None:
        from assemblykit.viz.plots import plot_contacts

        plot_contacts(result.assembly, result.contacts, png)
    emit(result, as_json, shown=result.assembly.tolerance(tol))


BLOCKING_MOTIONS = ("infinitesimal", "extended", "rigid")


@command
@assembly_argument
@click.option(
    "--motion",
    type=click.Choice(BLOCKING_MOTIONS),
    default="infinitesimal",
    help="infinitesimal, extended or rigid.",
)
@click.option("--png", default=None, help="Also write a PNG of the arrangement and a DBG to FILE.")
@json_option
@tolerance_option
@as_written_option
@partial_option
@debug_option
def blocking_cmd(
    assembly: str,
    motion: Motion,
    png: str | None,
    as_json: bool,
    tolerance: float | None,
    as_written: bool,
    partial: bool,
    debug: bool,
) -> None:
    """Non-directional blocking graph: regions of directions, removable subassemblies.

    ASSEMBLY: mesh folder, .yaml manifest, .step, COMPAS .json, or a YAML file of 2D
    polygons 'parts: {name: [[x, y], ...]}'.
    """
    from assemblykit.blocking.graphs import blocking_graph
    from assemblykit.blocking.ndbg import NonDirectionalBlockingGraph

    if png is not None:
        if motion == "rigid":
            raise InputError("--png draws the direction sphere: not for --motion rigid")
        checked_output(png, "--png", PNG_SUFFIXES)
    tol = tolerance_from(tolerance)
    model = assembly_or_polygons(assembly, tol, as_written, partial)
    result = blocking_graph(model, motion, tol=tol)
    if png is not None and isinstance(result, NonDirectionalBlockingGraph):
        from assemblykit.viz.plots import plot_ndbg

        plot_ndbg(result, png)
    emit(result, as_json, shown=getattr(model, "tolerance", lambda: tol)())


@command
@click.argument("problem")
@click.option("--png", default=None, help="Also write a PNG of the two-layer graph here.")
@json_option
@tolerance_option
@debug_option
def mate_cmd(
    problem: str, png: str | None, as_json: bool, tolerance: float | None, debug: bool
) -> None:
    """Mating inference (Liu & Popplestone 1990): which compound features mate to satisfy the goals.

    PROBLEM: mating problem, .yaml, .yml or .json.
    """
    from assemblykit.io.problem import load_problem
    from assemblykit.mating.search import mate

    if png is not None:
        checked_output(png, "--png", PNG_SUFFIXES)
    loaded = load_problem(problem, tolerance_from(tolerance))
    result = mate(loaded)
    if png is not None:
        from assemblykit.viz.mating_view import write_mating_png

        note(f"wrote {write_mating_png(loaded, result, png)}")
    emit(result, as_json)


@command
@assembly_argument
@click.option(
    "--key",
    "keys",
    multiple=True,
    metavar="PART",
    help="A key part; repeat for a set of keys [default: find the key].",
)
@click.option(
    "--motion",
    type=click.Choice(BLOCKING_MOTIONS),
    default="infinitesimal",
    show_default=True,
    help="infinitesimal, extended or rigid.",
)
@click.option(
    "--html", default=None, help="Also write a self-contained HTML page (verdict, 3D view) here."
)
@json_option
@tolerance_option
@as_written_option
@partial_option
@debug_option
def interlock_cmd(
    assembly: str,
    keys: tuple[str, ...],
    motion: Motion,
    html: str | None,
    as_json: bool,
    tolerance: float | None,
    as_written: bool,
    partial: bool,
    debug: bool,
) -> None:
    """Is the assembly interlocking, and with which key? Every direction of the blocking
    graphs (Wilson & Latombe 1992), not only the six axes.

    ASSEMBLY: mesh folder, .yaml manifest, .step, COMPAS .json, BurrTools .xmpuzzle, or a
    YAML file of 2D polygons 'parts: {name: [[x, y], ...]}'.
    """
    from assemblykit.outputs import atomic_output
    from assemblykit.planning.interlocking import interlocking
    from assemblykit.viz.interlock_view import interlock_page

    if html is not None:
        checked_output(html, "--html", HTML_SUFFIXES)
    tol = tolerance_from(tolerance)
    loaded = _plan_input(assembly, tol, as_written, 0, 0, partial)
    if html is not None and loaded.dimension == 2:
        raise InputError("--html draws meshes: not for a 2D polygon assembly")
    result = interlocking(loaded, keys or None, motion, tol)
    if html is not None:
        page = interlock_page(loaded, result)
        with atomic_output(html) as temporary:
            temporary.write_text(page, encoding="utf-8")
        note(f"wrote {html}")
    emit(result, as_json, loaded.tolerance(tol))
