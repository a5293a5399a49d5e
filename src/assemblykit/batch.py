"""Many assemblies in parallel: ``assemblykit batch`` (DESIGN.md §5.3).

Every assembly runs in its own child process (``python -m assemblykit.batch INPUT``), so
a per-assembly timeout really stops the work and a crash is recorded instead of ending
the batch. The children are driven either locally (a pool of ``workers`` threads, each
waiting on one child at a time) or by Dask (``dask.distributed``; a local cluster when no
scheduler address is given), whose tasks start the same child. Both engines therefore
give the same answers.

The output is JSON Lines, one line per assembly, appended as soon as it is known:
``input``, ``status`` (``ok``, ``error`` or ``timeout``), ``result`` (the command's JSON)
or ``error`` (one line), and ``seconds``. A rerun reads the file first and skips the
inputs already finished (``ok`` or ``error``); timed-out inputs are tried again. An input
that does not exist is not run and not written: the summary lists it with the other
failures, and the next run tries it again.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal, cast

from rich.console import Group
from rich.table import Table
from rich.text import Text

from assemblykit.errors import AssemblyKitError, InputError, MissingExtraError
from assemblykit.io.documents import read_text

Engine = Literal["local", "dask"]
Command = Literal["plan", "motion"]
Status = Literal["ok", "error", "timeout"]
FINISHED: frozenset[str] = frozenset({"ok", "error"})


@dataclass(frozen=True)
class Job:
    """One assembly to process: its path, the command, and the relative tolerance."""

    input: str
    command: Command
    timeout: float | None = None
    rel_tolerance: float | None = None


@dataclass(frozen=True)
class Failure:
    """An input that gave no answer: ``error``, ``timeout`` or ``missing`` (not found)."""

    input: str
    status: str
    error: str

    def to_dict(self) -> dict[str, str]:
        return {"input": self.input, "status": self.status, "error": self.error}


@dataclass(frozen=True)
class BatchSummary:
    """What a batch run did: the output file, how many inputs it skipped, the count of
    each status among the inputs it ran, and every input that gave no answer."""

    out: str
    total: int
    skipped: int
    statuses: dict[str, int]
    failed: tuple[Failure, ...] = ()

    @property
    def missing(self) -> tuple[str, ...]:
        """Inputs that do not exist (not run, not written, tried again next time)."""
        return tuple(f.input for f in self.failed if f.status == "missing")

    def to_dict(self) -> dict[str, Any]:
        """JSON form: ``out``, ``total``, ``skipped``, ``ran``, the status counts,
        ``missing`` and ``failed`` (each failed input with its status and message)."""
        return {
            "out": self.out,
            "total": self.total,
            "skipped": self.skipped,
            "ran": sum(self.statuses.values()),
            **{status: self.statuses.get(status, 0) for status in ("ok", "error", "timeout")},
            "missing": len(self.missing),
            "failed": [failure.to_dict() for failure in self.failed],
        }

    def render(self) -> Group:
        """A one-row rich table of the counts, then one line per failed input."""
        data = self.to_dict()
        keys = ("total", "skipped", "ok", "error", "timeout", "missing")
        table = Table(title=f"batch -> {self.out}")
        for key in keys:
            table.add_column(key)
        table.add_row(*(str(data[key]) for key in keys))
        lines = [
            Text(f"{f.status}: {f.input}: {f.error}", no_wrap=True, overflow="ignore")
            for f in self.failed
        ]
        return Group(table, *lines)


def compute(command: Command, path: str, rel_tolerance: float | None = None) -> dict[str, Any]:
    """The JSON result of ``command`` (``plan`` or ``motion``) on the assembly at ``path``."""
    from assemblykit.io.assembly import load_assembly
    from assemblykit.io.report import jsonable
    from assemblykit.tolerance import Tolerance

    tol = None if rel_tolerance is None else Tolerance(rel_length=rel_tolerance)
    assembly = load_assembly(path, tol=tol)
    if command == "plan":
        from assemblykit.planning.sequence import plan

        result = plan(assembly, tol=tol)
    else:
        from assemblykit.motion.freedom import motion

        result = motion(assembly)
    return cast(dict[str, Any], jsonable(result.to_dict(), assembly.tolerance(tol)))


def run_job(job: Job) -> dict[str, Any]:
    """Run one job in a child process and return its JSON line (as a dict).

    The child prints ``{"status": ..., "result"|"error": ...}``; a child that exceeds
    ``job.timeout`` seconds is killed (status ``timeout``); one that dies without an
    answer is an ``error`` carrying the last line of its stderr.
    """
    command = [sys.executable, "-m", "assemblykit.batch", job.command, job.input]
    if job.rel_tolerance is not None:
        command.append(repr(job.rel_tolerance))
    start = time.perf_counter()
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=job.timeout)
    except subprocess.TimeoutExpired:
        return _line(job, {"status": "timeout", "error": f"over {job.timeout} s"}, start)
    lines = done.stdout.strip().splitlines()
    if done.returncode == 0 and lines:
        return _line(job, json.loads(lines[-1]), start)
    reason = (done.stderr.strip().splitlines() or [f"exit code {done.returncode}"])[-1]
    return _line(job, {"status": "error", "error": f"worker died: {reason}"}, start)


def _line(job: Job, outcome: dict[str, Any], start: float) -> dict[str, Any]:
    return {"input": job.input, **outcome, "seconds": round(time.perf_counter() - start, 3)}


def finished_inputs(out: Path) -> set[str]:
    """Inputs already finished (``ok`` or ``error``) in an existing JSON Lines file, as
    resolved paths; a truncated last line (an interrupted run) is ignored."""
    if not out.exists():
        return set()
    done = set()
    lines = read_text(out, "results file").splitlines()
    for number, text in enumerate(lines, start=1):
        if not text.strip():
            continue
        try:
            record = json.loads(text)
        except json.JSONDecodeError:
            if number == len(lines):
                continue
            raise InputError("not a JSON line", source=str(out), where=f"line {number}") from None
        if not (isinstance(record, dict) and isinstance(record.get("input"), str)):
            raise InputError(
                "not a result line (an object with 'input')",
                source=str(out),
                where=f"line {number}",
            )
        if record.get("status") in FINISHED:
            done.add(_key(record["input"]))
    return done


def _key(path: str) -> str:
    return str(Path(path).resolve())


def _local(jobs: Sequence[Job], workers: int) -> Iterator[dict[str, Any]]:
    with ThreadPoolExecutor(max_workers=workers) as pool:
        futures = [pool.submit(run_job, job) for job in jobs]
        for future in as_completed(futures):
            yield future.result()


def _dask(jobs: Sequence[Job], workers: int, scheduler: str | None) -> Iterator[dict[str, Any]]:
    try:
        from dask.distributed import Client, LocalCluster
        from dask.distributed import as_completed as dask_completed
    except ImportError:
        raise MissingExtraError("dask[distributed]", "dist", "batch --engine dask") from None
    if scheduler is None:
        # the work happens in child processes, so thread workers are enough here
        cluster = LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=False, dashboard_address=None
        )
        client = Client(cluster)
    else:
        cluster = None
        client = Client(scheduler)
    try:
        futures = [client.submit(run_job, job, pure=False) for job in jobs]
        for future in dask_completed(futures):
            yield future.result()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def run_batch(
    inputs: Iterable[str | Path],
    out: str | Path,
    *,
    engine: Engine = "local",
    command: Command = "plan",
    timeout: float | None = None,
    workers: int = 2,
    scheduler: str | None = None,
    rel_tolerance: float | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> BatchSummary:
    """Run ``command`` over ``inputs`` and append one JSON line per assembly to ``out``.

    Inputs already finished in ``out`` are skipped; ``progress(done, total)`` is called
    after each assembly.
    """
    if engine not in ("local", "dask"):
        raise InputError(f"unknown engine {engine!r} (use local or dask)", where="--engine")
    if workers < 1:
        raise InputError(f"workers must be at least 1, got {workers}", where="--workers")
    target = Path(out)
    names = [str(path) for path in inputs]
    done = finished_inputs(target)
    pending = [name for name in names if _key(name) not in done]
    failed = [
        Failure(name, "missing", "no such file or folder")
        for name in pending
        if not Path(name).exists()
    ]
    todo = [Job(name, command, timeout, rel_tolerance) for name in pending if Path(name).exists()]
    target.parent.mkdir(parents=True, exist_ok=True)
    lines = _local(todo, workers) if engine == "local" else _dask(todo, workers, scheduler)
    statuses: Counter[str] = Counter()
    with target.open("a", encoding="utf-8") as sink:
        for record in lines:
            sink.write(json.dumps(record) + "\n")
            sink.flush()
            statuses[record["status"]] += 1
            if record["status"] != "ok":
                failed.append(Failure(record["input"], record["status"], record["error"]))
            if progress is not None:
                progress(sum(statuses.values()), len(todo))
    order = {name: i for i, name in enumerate(names)}
    failed.sort(key=lambda f: order[f.input])
    return BatchSummary(
        str(target), len(names), len(names) - len(pending), dict(statuses), tuple(failed)
    )


def _child(argv: Sequence[str]) -> int:
    """The child process: print one JSON object with ``status`` and ``result``/``error``."""
    command, path, *rest = argv
    rel_tolerance = float(rest[0]) if rest else None
    try:
        outcome: dict[str, Any] = {
            "status": "ok",
            "result": compute(command, path, rel_tolerance),  # type: ignore[arg-type]
        }
    except AssemblyKitError as failure:
        outcome = {"status": "error", "error": str(failure)}
    except Exception as bug:  # recorded, never fatal to the batch
        outcome = {"status": "error", "error": f"{type(bug).__name__}: {bug}"}
    sys.stdout.write(json.dumps(outcome) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(_child(sys.argv[1:]))
