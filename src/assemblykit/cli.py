"""The ``assemblykit`` command (DESIGN.md §5.3).

Every command takes ``INPUT``, ``--json`` (the documented JSON on stdout), ``--tolerance``
(relative length tolerance) and ``--debug`` (tracebacks). Exit codes: 0 for every answer
(including *inconsistent* or *infeasible*), 2 for bad input (one line on stderr naming the
file and the fault), 1 for an internal error.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from typing import Annotated, Any, Protocol

import click
import typer
from rich.console import Console

from assemblykit.errors import AssemblyKitError, InputError, MissingExtraError
from assemblykit.tolerance import Tolerance

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


class Result(Protocol):
    """What every command returns: JSON via ``to_dict`` and a readable rendering."""

    def to_dict(self) -> dict[str, Any]: ...

    def render(self) -> Any: ...


def tolerance_from(option: float | None) -> Tolerance:
    """The tolerance policy with the command line's ``--tolerance`` applied."""
    return Tolerance() if option is None else Tolerance(rel_length=option)


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
