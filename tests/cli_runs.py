"""Running the command line inside the test process."""

from __future__ import annotations

import pytest

from assemblykit.cli import main


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    """``assemblykit ARGV...``: its exit code, standard output and standard error."""
    try:
        main(list(argv))
        code = 0
    except SystemExit as done:
        code = int(done.code or 0)
    captured = capsys.readouterr()
    return code, captured.out, captured.err
