"""Every ``assemblykit`` command shown in the README and the guides runs as written from
a clone of the repository: the lines of ```bash blocks that start with ``assemblykit``
and the ``$ assemblykit`` lines of ```console blocks (which exit 2, printing the error
line the transcript shows, when it shows one). The tutorial's Python blocks run in
order, as one session, and print what they show. Each runs in a fresh folder that sees
the repository's ``src``, ``tests`` and ``examples``, so written files land there.

The commands run in the slow tier: the work of each is tested, with checks, in the
default tier by the tests of its module and of the command line (``assemblykit demo``
by tests/test_cli_plan.py); the tutorial's Python blocks in the default tier."""

from __future__ import annotations

import contextlib
import doctest
import io
import itertools
import re
import shlex
from pathlib import Path

import pytest

from assemblykit.cli import main

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^```(\w*)\s*$")


def documented_commands() -> list[tuple[str, int, str, int]]:
    """``(document, line, command, exit code)`` for each runnable command."""
    found = []
    for document in DOCUMENTS:
        language = None
        lines = document.read_text().splitlines()
        for number, line in enumerate(lines, start=1):
            fence = FENCE.match(line)
            if fence:
                language = fence.group(1) if language is None else None
                continue
            text = line.strip()
            if language == "bash" and text.startswith("assemblykit "):
                found.append((document.name, number, text, 0))
            elif language == "console" and text.startswith("$ assemblykit "):
                error = number < len(lines) and lines[number].startswith("assemblykit: ")
                found.append((document.name, number, text.removeprefix("$ "), 2 if error else 0))
    return found


COMMANDS = documented_commands()


def words(command: str) -> list[str]:
    """The words of a command line, without its comment."""
    return shlex.split(command, comments=True)


def first_showings(commands: list[tuple[str, int, str, int]]) -> list[tuple[str, int, str, int]]:
    """The commands shown in two places (comments aside) once, under the first."""
    seen: set[tuple[str, ...]] = set()
    kept = []
    for found in commands:
        key = tuple(words(found[2]))
        if key not in seen:
            seen.add(key)
            kept.append(found)
    return kept


RUN = first_showings(COMMANDS)


def documented_errors() -> dict[str, str]:
    """The error line each ```console transcript shows under its command, by command."""
    errors = {}
    for document in DOCUMENTS:
        lines = document.read_text().splitlines()
        for line, after in itertools.pairwise(lines):
            if line.startswith("$ assemblykit ") and after.startswith("assemblykit: "):
                errors[line.removeprefix("$ ")] = after
    return errors


ERRORS = documented_errors()


# commands that need an optional extra: the module it installs
EXTRAS = {"--engine dask": "dask.distributed", ".step": "OCP"}


def test_the_documents_show_commands():
    assert len(COMMANDS) >= 20
    # the README's first command is the main job on the bundled example
    readme = [command for source, _, command, _ in COMMANDS if source == "README.md"]
    assert readme[0] == "assemblykit demo"


@pytest.mark.slow
@pytest.mark.parametrize(
    "command, expected",
    [(c, e) for _, _, c, e in RUN],
    ids=[f"{d}:{n}" for d, n, _, _ in RUN],
)
def test_documented_command_runs(command, expected, tmp_path, monkeypatch, capsys):
    for marker, module in EXTRAS.items():
        if marker in command:
            pytest.importorskip(module)
    for folder in ("src", "tests", "examples"):
        (tmp_path / folder).symlink_to(ROOT / folder)
    monkeypatch.chdir(tmp_path)
    args = words(command)[1:]
    try:
        main(args)
        code = 0
    except SystemExit as done:
        code = int(done.code or 0)
    assert code == expected, command
    if command in ERRORS:
        assert capsys.readouterr().err.strip() == ERRORS[command]


def python_blocks(document: Path) -> list[str]:
    """The text of each ```python block of ``document``, in order."""
    return re.findall(r"^```python\n(.*?)^```", document.read_text(), re.DOTALL | re.MULTILINE)


def test_the_tutorial_python_blocks_run_from_the_repository_root(tmp_path, monkeypatch):
    blocks = python_blocks(ROOT / "docs" / "tutorial.md")
    assert len(blocks) >= 2
    for folder in ("src", "tests", "examples"):
        (tmp_path / folder).symlink_to(ROOT / folder)
    monkeypatch.chdir(tmp_path)
    session: dict[str, object] = {}
    parser = doctest.DocTestParser()
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    for number, block in enumerate(blocks, start=1):
        if ">>> " in block:
            test = parser.get_doctest(block, session, f"tutorial block {number}", None, 0)
            test.globs = session  # one session: the names of the blocks before
            report: list[str] = []
            result = runner.run(test, out=report.append, clear_globs=False)
            assert result.failed == 0, "".join(report)
            continue
        printed = io.StringIO()
        with contextlib.redirect_stdout(printed):
            exec(compile(block, f"tutorial block {number}", "exec"), session)
        shown = re.findall(r"^print\(.*#\s*(.+)$", block, re.MULTILINE)
        assert printed.getvalue().split() == shown, block
