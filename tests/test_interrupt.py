"""The command as a process: Ctrl-C (SIGINT) ends every command at once with one line
"assemblykit: interrupted" on stderr and exit code 130, a batch keeps the lines it has
written and starts no more work, and numerical warnings stay off stderr unless
``--debug``.

Each test starts ``assemblykit`` with :mod:`subprocess` through a tiny launcher that
says "ready" on stdout right before calling :func:`assemblykit.cli.main`, so that the
signal is sent once the command runs (a signal during Python's own start-up is not ours
to handle). The launcher gives Ctrl-C Python's usual handler, as a terminal does: a
process started in the background by a non-interactive shell inherits SIGINT ignored.
The plan test sends the signal once the planner is at work on its blocking graph, which
the launcher marks with a file. The batch tests replace the Python of the batch's
children by a shell script (``sys.executable``), so that which child starts, answers or
hangs is set by the test.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from assemblykit.cli import INTERRUPTED

LIMIT = 30.0
"""Seconds allowed from the signal to the end of the process: generous, since a loaded
machine is slow, not wrong; the plan interrupted would run for minutes."""

LAUNCHER = """
import signal
import sys
from assemblykit.cli import main
signal.signal(signal.SIGINT, signal.default_int_handler)
{setup}
print("ready", flush=True)
main(sys.argv[1:])
"""

FAKE_PYTHON = """#!/bin/sh
# the Python of a batch's workers ("-m assemblykit.batch --serve"): one request per line
# on stdin ({"command": ..., "path": ...}), one answer per line on stdout
while IFS= read -r line; do
  path=$(printf '%s\\n' "$line" | sed -n 's/.*"path": "\\([^"]*\\)".*/\\1/p')
  echo "$path" >> "$(dirname "$0")/started.txt"
  case "$path" in
    *slow*) echo $$ > "$(dirname "$0")/slow.pid"; exec sleep 600 ;;
  esac
  echo '{"status": "ok", "result": {"ran": "'"$path"'"}}'
done
"""


def start(argv: list[str], cwd: Path, setup: str = "") -> subprocess.Popen[str]:
    """``assemblykit argv`` running in ``cwd``, once it has said "ready"."""
    child = subprocess.Popen(
        [sys.executable, "-c", LAUNCHER.format(setup=setup), *argv],
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert child.stdout is not None and child.stdout.readline() == "ready\n"
    return child


def interrupt(child: subprocess.Popen[str]) -> tuple[int, str, float]:
    """Send SIGINT to ``child``: its exit code, its stderr and the seconds it took to end."""
    assert child.poll() is None, "the command ended before it was interrupted"
    sent = time.monotonic()
    child.send_signal(signal.SIGINT)
    try:
        _, err = child.communicate(timeout=LIMIT)
    except subprocess.TimeoutExpired:
        child.kill()
        child.communicate()
        pytest.fail(f"still running {LIMIT} s after SIGINT")
    return child.returncode, err, time.monotonic() - sent


def wait_for(condition: Callable[[], object], what: str) -> None:
    """Poll ``condition`` (generously: slow machines are slow, not wrong)."""
    deadline = time.monotonic() + 120
    while not condition():
        assert time.monotonic() < deadline, f"never saw {what}"
        time.sleep(0.05)


def brick_wall(path: Path, rows: int) -> Path:
    """A running-bond wall of rows x rows unit bricks as a 2D polygon file: its plan takes
    minutes, so it is still running when interrupted."""
    lines = ["parts:"]
    for y in range(rows):
        shift = 0.5 * (y % 2)
        for x in range(rows):
            a, b = x + shift, x + shift + 1
            lines.append(f"  p{x}_{y}: [[{a}, {y}], [{b}, {y}], [{b}, {y + 1}], [{a}, {y + 1}]]")
    path.write_text("\n".join(lines) + "\n")
    return path


WORKING = """
from pathlib import Path
import assemblykit.blocking.tables as tables
computed = tables.blocking_graph
def marked(*args, **kwargs):
    Path({marker!r}).touch()
    return computed(*args, **kwargs)
tables.blocking_graph = marked
"""
"""Launcher setup: the file ``marker`` appears as the planner starts a blocking graph."""


def test_ctrl_c_ends_plan_with_130_and_one_line(tmp_path: Path) -> None:
    wall = brick_wall(tmp_path / "wall.yaml", 20)
    marker = tmp_path / "working"
    setup = WORKING.format(marker=str(marker))
    child = start(["plan", str(wall), "--json"], tmp_path, setup=setup)
    wait_for(lambda: marker.exists() or child.poll() is not None, "the planner at work")
    code, err, seconds = interrupt(child)
    assert code == INTERRUPTED == 130
    assert err.strip() == "assemblykit: interrupted"
    assert seconds < LIMIT


@pytest.fixture
def fake_python(tmp_path: Path) -> Path:
    script = tmp_path / "bin" / "python"
    script.parent.mkdir()
    script.write_text(FAKE_PYTHON)
    script.chmod(0o755)
    return script


def started(fake_python: Path) -> list[str]:
    log = fake_python.parent / "started.txt"
    return log.read_text().splitlines() if log.exists() else []


@pytest.mark.parametrize("engine", ["local", pytest.param("dask", marks=pytest.mark.slow)])
def test_ctrl_c_stops_a_batch_and_keeps_its_finished_lines(
    tmp_path: Path, fake_python: Path, engine: str
) -> None:
    if engine == "dask":
        pytest.importorskip("dask.distributed")
    inputs = [tmp_path / name for name in ("a.yaml", "slow.yaml", "c.yaml")]
    for path in inputs:
        path.write_text(f"parts: []  # {path.name}\n")
    out = tmp_path / "results.jsonl"
    argv = ["batch", *map(str, inputs), "--out", str(out), "--workers", "1", "--engine", engine]
    child = start(argv, tmp_path, setup=f"sys.executable = {str(fake_python)!r}")
    wait_for(lambda: str(inputs[1]) in started(fake_python), "the slow job start")
    pid = fake_python.parent / "slow.pid"
    wait_for(lambda: pid.exists() and pid.read_text().strip(), "the slow job's pid")
    code, err, seconds = interrupt(child)
    assert code == 130
    assert err.strip() == "assemblykit: interrupted"
    assert seconds < LIMIT
    # the finished line is kept whole; the interrupted job is not recorded
    records = [json.loads(line) for line in out.read_text().splitlines()]
    assert [(r["input"], r["status"], r["result"]) for r in records] == [
        (str(inputs[0]), "ok", {"ran": str(inputs[0])})
    ]
    assert out.read_text().endswith("\n")
    # no job started after the signal, and the running one was ended
    assert started(fake_python) == [str(inputs[0]), str(inputs[1])]
    with pytest.raises(ProcessLookupError):
        os.kill(int(pid.read_text()), 0)


LOUD_LOAD = """
import numpy as np
import assemblykit.io.tasks as tasks
quiet = tasks.load_task
def loud(path):
    np.array([0.0]) / 0.0  # numpy: RuntimeWarning: invalid value encountered in divide
    return quiet(path)
tasks.load_task = loud
"""


def test_runtime_warnings_reach_stderr_only_with_debug(tmp_path: Path) -> None:
    task = (
        Path(__file__).resolve().parents[1] / "src/assemblykit/examples/tasks/point_in_planes.yaml"
    )
    runs: dict[bool, str] = {}
    for extra in ([], ["--debug"]):
        child = start(["solve", str(task), "--json", *extra], tmp_path, setup=LOUD_LOAD)
        out, err = child.communicate(timeout=120)
        assert child.returncode == 0
        assert json.loads(out)["status"] in ("solved", "underconstrained")
        runs[bool(extra)] = err
    assert runs[False] == ""
    assert "RuntimeWarning" in runs[True]
