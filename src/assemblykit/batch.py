"""Many assemblies in parallel: ``assemblykit batch`` (docs/planning.md, "Many assemblies").

The assemblies run in worker processes (``python -m assemblykit.batch --serve``), each
answering one assembly after another, so that a batch pays for importing assemblykit and
its dependencies once per worker, not once per assembly. A worker is a child process, so
a per-assembly timeout really stops the work (the worker is killed, and the next
assembly starts a new one) and a crash is recorded instead of ending the batch. The
workers are driven either locally (a pool of ``workers`` threads, each with its own
worker) or by Dask (``dask.distributed``; a local cluster when no scheduler address is
given), whose tasks ask the same workers. Both engines therefore give the same answers.
With a remote scheduler each assembly runs in a new child on the remote worker
(``python -m assemblykit.batch COMMAND INPUT``), which leaves no process behind there.

The output is JSON Lines, one line per assembly, appended as soon as it is known:
``input`` (as given), ``status`` (``ok``, ``error`` or ``timeout``), ``result`` (the
command's JSON) or ``error`` (one line), ``seconds``, and what identifies the work done:
``command``, ``path`` (absolute) and ``sha256`` (of the file, or of every file in a
folder). An error that is a fault of assemblykit rather than of the input (the command
would exit 1) says ``internal error: ...`` and carries ``"internal": true``. A line is
written whole, by one write followed by ``fsync``, so a run that is
killed leaves at most its last line cut short; the next run drops that line (saying so)
before appending.

A rerun skips an input when the file holds an answer for the same command, absolute path
and content: ``ok`` (including answers such as *infeasible*) or an ``error`` the child
reported (bad input, or a fault of assemblykit on that input). Outcomes that are not
answers carry ``"retry": true`` and are tried again: a worker that died (out of memory,
killed) and a timeout. An input that does not exist (or cannot be read) is not run and
not written: the summary lists it with the other failures, and the next run tries it
again.

Ctrl-C stops a run at once: no new child is started, the running ones are killed and
their (missing) answers are not recorded, the lines already written stay, and
:class:`KeyboardInterrupt` propagates to the caller. With a remote Dask scheduler the
assemblies already running finish on their workers, unrecorded.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import logging
import os
import queue
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any, Literal, cast

from assemblykit.errors import AssemblyKitError, InputError, MissingExtraError

Engine = Literal["local", "dask"]
Command = Literal["plan", "motion"]
Status = Literal["ok", "error", "timeout"]
FINISHED: frozenset[str] = frozenset({"ok", "error"})

Key = tuple[str, str, str]
"""What a result answers: the command, the input's absolute path and its ``sha256``."""

INTERRUPTED_CODES = (130, -signal.SIGINT)
"""Exit codes of a child ended by Ctrl-C (it exits 130; killed by SIGINT, -2)."""

ONE_THREAD: dict[str, str] = {
    "OMP_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "ASSEMBLYKIT_PROGRAM_THREADS": "1",
}
"""The environment a worker's numerical libraries start with, unless the batch's own
environment sets these variables: one thread each, as Dask starts the worker processes
of its nannies (``distributed.nanny.pre-spawn-environ``), and the equilibrium programs
of a plan under gravity one at a time
(:data:`~assemblykit.planning.equilibrium_programs.PROGRAM_THREADS_VARIABLE`). The
workers are the batch's parallelism, one per core asked for; a library's own threads,
one per core in each worker, would compete with the other workers for the same cores."""


@dataclass(frozen=True)
class Job:
    """One assembly to process: its path (as given), the command, the timeout, the
    relative tolerance, and its absolute path and content digest (:func:`input_key`)."""

    input: str
    command: Command
    timeout: float | None = None
    rel_tolerance: float | None = None
    path: str = ""
    sha256: str = ""

    @property
    def key(self) -> Key:
        """The key of this job's result."""
        return (self.command, self.path, self.sha256)


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


def compute(command: Command, path: str, rel_tolerance: float | None = None) -> dict[str, Any]:
    """The JSON result of ``command`` (``plan`` or ``motion``) on the assembly at ``path``."""
    from assemblykit.io.assembly import load_assembly
    from assemblykit.io.report import jsonable
    from assemblykit.tolerance import Tolerance

    tol = None if rel_tolerance is None else Tolerance(rel_length=rel_tolerance)
    assembly = load_assembly(path, tol=tol)
    if command == "plan":
        from assemblykit.planning.planner import plan

        data = plan(assembly, tol=tol).to_dict()
    else:
        from assemblykit.motion.freedom import motion

        data = motion(assembly).to_dict()
    return cast(dict[str, Any], jsonable(data, assembly.tolerance(tol)))


class _Stopped(Exception):
    """A job whose child was ended by an interruption: it has no outcome to record."""


class _Children:
    """The child processes of the jobs running in this process, so that an interruption
    ends them at once instead of waiting for work that would not be recorded."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._running: set[subprocess.Popen[str]] = set()
        self._stopping = False

    def start(self, command: list[str], **streams: Any) -> subprocess.Popen[str]:
        """A child running ``command`` (stdout and stderr piped unless ``streams`` say
        otherwise); :class:`_Stopped` while stopping."""
        with self._lock:
            if self._stopping:
                raise _Stopped(command[-1])
            pipes: dict[str, Any] = {"stdout": subprocess.PIPE, "stderr": subprocess.PIPE}
            env = {**ONE_THREAD, **os.environ}
            child = subprocess.Popen(command, text=True, env=env, **{**pipes, **streams})
            self._running.add(child)
            return child

    def finish(self, child: subprocess.Popen[str]) -> bool:
        """Forget ``child``; whether it ended while stopping (its outcome is void)."""
        with self._lock:
            self._running.discard(child)
            return self._stopping

    @property
    def is_stopping(self) -> bool:
        """Whether the running children are being ended (an interruption)."""
        with self._lock:
            return self._stopping

    @contextlib.contextmanager
    def stopping(self) -> Iterator[None]:
        """Kill the running children, and start none until the block ends."""
        with self._lock:
            self._stopping = True
            for child in self._running:
                child.kill()
        try:
            yield
        finally:
            with self._lock:
                self._stopping = False


_CHILDREN = _Children()


def run_job(job: Job, keep: bool = True) -> dict[str, Any]:
    """Run one job and return its JSON line (as a dict): in this thread's worker
    (:class:`_Worker`) with ``keep``, else in a child of its own.

    A worker answers ``{"status": ..., "result"|"error": ...}``; one that exceeds
    ``job.timeout`` seconds is killed (status ``timeout``); one that dies without an
    answer is an ``error`` carrying the last line of its stderr or the signal that killed
    it; both carry ``"retry": true``. A job ended by an interruption (Ctrl-C, or the
    batch stopping) raises :class:`_Stopped`.
    """
    start = time.perf_counter()
    if keep:
        outcome = _worker().ask(job)
        if _CHILDREN.is_stopping:
            raise _Stopped(job.input)
        return _line(job, outcome, start)
    command = [sys.executable, "-m", "assemblykit.batch", job.command, job.path or job.input]
    if job.rel_tolerance is not None:
        command.append(repr(job.rel_tolerance))
    child = _CHILDREN.start(command)
    try:
        outcome = _outcome(child, job.timeout)
    finally:
        stopped = _CHILDREN.finish(child)
    if stopped or child.returncode in INTERRUPTED_CODES:
        raise _Stopped(job.input)
    return _line(job, outcome, start)


class _Worker:
    """A worker process (``python -m assemblykit.batch --serve``) that answers jobs one
    after another, one JSON line each (module docstring). It is started by the first job
    it is asked, killed by a timeout, and started again by the job after one that killed
    it; its stderr goes to a temporary file, whose last line says why it died."""

    def __init__(self) -> None:
        self._child: subprocess.Popen[str] | None = None
        self._answers: queue.Queue[str | None] = queue.Queue()
        self._errors: IO[str] | None = None

    def ask(self, job: Job) -> dict[str, Any]:
        """The outcome of ``job``: the worker's answer, a timeout or its death."""
        child = self._child if self._child is not None else self._start()
        request: dict[str, Any] = {"command": job.command, "path": job.path or job.input}
        if job.rel_tolerance is not None:
            request["rel_tolerance"] = job.rel_tolerance
        try:
            assert child.stdin is not None
            child.stdin.write(json.dumps(request) + "\n")
            child.stdin.flush()
            answer = self._answers.get(timeout=job.timeout)
        except queue.Empty:
            self.close(kill=True)
            return {"status": "timeout", "error": f"over {job.timeout} s", "retry": True}
        except (BrokenPipeError, OSError):
            answer = None
        if answer is not None:
            return cast(dict[str, Any], json.loads(answer))
        return {"status": "error", "error": f"worker died: {self._death()}", "retry": True}

    def _start(self) -> subprocess.Popen[str]:
        # kept open for the worker's life, closed by _death or close
        self._errors = tempfile.TemporaryFile("w+", encoding="utf-8")  # noqa: SIM115
        command = [sys.executable, "-m", "assemblykit.batch", "--serve"]
        child = _CHILDREN.start(command, stdin=subprocess.PIPE, stderr=self._errors)
        self._child, self._answers = child, queue.Queue()
        threading.Thread(target=_read_lines, args=(child, self._answers), daemon=True).start()
        return child

    def _death(self) -> str:
        """Why the worker ended (the last line of its stderr, or its signal or exit
        code), once it has; it is forgotten."""
        child, errors = self._child, self._errors
        assert child is not None and errors is not None
        code = child.wait()
        _CHILDREN.finish(child)
        errors.seek(0)
        last = errors.read().strip().splitlines()
        errors.close()
        self._child = self._errors = None
        if code in INTERRUPTED_CODES:
            raise _Stopped("interrupted")
        if last:
            return last[-1]
        if code < 0:
            return f"killed by {signal.Signals(-code).name}"
        return f"exit code {code}"

    def close(self, kill: bool = False) -> None:
        """End the worker: at once with ``kill``, else once it has read the end of its
        input (it finishes no job then: it has none)."""
        child = self._child
        if child is None:
            return
        if kill:
            child.kill()
        elif child.stdin is not None:
            with contextlib.suppress(OSError):
                child.stdin.close()
        try:
            child.wait(timeout=WORKER_EXIT)
        except subprocess.TimeoutExpired:
            child.kill()
            child.wait()
        _CHILDREN.finish(child)
        if self._errors is not None:
            self._errors.close()
        self._child = self._errors = None


WORKER_EXIT = 10.0
"""Seconds a worker is given to end once its input is closed, before it is killed."""


def _read_lines(child: subprocess.Popen[str], answers: queue.Queue[str | None]) -> None:
    """Put each line ``child`` prints into ``answers``, then ``None`` at its end."""
    assert child.stdout is not None
    for line in child.stdout:
        answers.put(line)
    answers.put(None)


_WORKERS = threading.local()
_ALL_WORKERS: list[_Worker] = []
_WORKERS_LOCK = threading.Lock()


def _worker() -> _Worker:
    """This thread's worker (each thread of a pool drives its own; a new one after
    :func:`close_workers`)."""
    found = getattr(_WORKERS, "worker", None)
    if found is None or found not in _ALL_WORKERS:
        found = _WORKERS.worker = _Worker()
        with _WORKERS_LOCK:
            _ALL_WORKERS.append(found)
    return cast(_Worker, found)


def close_workers() -> None:
    """End every worker this process started (a batch's end)."""
    with _WORKERS_LOCK:
        workers = list(_ALL_WORKERS)
        _ALL_WORKERS.clear()
    for worker in workers:
        worker.close()


def _outcome(child: subprocess.Popen[str], timeout: float | None) -> dict[str, Any]:
    """What ``child`` printed, or why it printed nothing (run again: ``retry``)."""
    try:
        stdout, stderr = child.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        child.kill()
        child.communicate()
        return {"status": "timeout", "error": f"over {timeout} s", "retry": True}
    lines = stdout.strip().splitlines()
    if child.returncode == 0 and lines:
        return cast(dict[str, Any], json.loads(lines[-1]))
    code = child.returncode
    last = stderr.strip().splitlines()
    if last:
        reason = last[-1]
    elif code < 0:
        reason = f"killed by {signal.Signals(-code).name}"
    else:
        reason = f"exit code {code}"
    return {"status": "error", "error": f"worker died: {reason}", "retry": True}


def _line(job: Job, outcome: dict[str, Any], start: float) -> dict[str, Any]:
    return {
        "input": job.input,
        **outcome,
        "seconds": round(time.perf_counter() - start, 3),
        "command": job.command,
        "path": job.path,
        "sha256": job.sha256,
    }


def content_digest(path: Path) -> str:
    """SHA-256 (hex) of a file's bytes, or of a folder's files (each one's name relative
    to the folder, then its digest, in sorted order): an edited input is run again."""
    if not path.is_dir():
        return _file_sha256(path).hex()
    digest = hashlib.sha256()
    for file in sorted(p for p in path.rglob("*") if p.is_file()):
        digest.update(file.relative_to(path).as_posix().encode() + b"\0")
        digest.update(_file_sha256(file))
    return digest.hexdigest()


def _file_sha256(path: Path) -> bytes:
    with path.open("rb") as handle:
        return hashlib.file_digest(handle, "sha256").digest()


@dataclass(frozen=True)
class ResultsFile:
    """What an existing results file holds: the keys of its answers (``ok`` or ``error``
    lines without ``retry``), the length in bytes of its whole lines, and the number of
    its last line when that one was cut short (0 when it was not)."""

    finished: frozenset[Key]
    whole: int
    torn_line: int = 0


def read_results(out: Path) -> ResultsFile:
    """The results file ``out`` (empty when missing). :class:`InputError` naming the line
    when a whole line is not a JSON object with ``input``. Lines without ``command``,
    ``path`` and ``sha256`` answer nothing (their inputs run again)."""
    if not out.exists():
        return ResultsFile(frozenset(), 0)
    try:
        data = out.read_bytes()
    except OSError as error:
        reason = error.strerror or type(error).__name__
        raise InputError(f"cannot read the results file: {reason}", source=str(out)) from None
    whole = data.rfind(b"\n") + 1
    lines = data[:whole].split(b"\n")[:-1]
    finished = set()
    for number, raw in enumerate(lines, start=1):
        record = _record(raw, out, number)
        if record is None or record.get("status") not in FINISHED or record.get("retry"):
            continue
        key = (record.get("command"), record.get("path"), record.get("sha256"))
        if all(isinstance(part, str) for part in key):
            finished.add(cast(Key, key))
    return ResultsFile(frozenset(finished), whole, len(lines) + 1 if whole < len(data) else 0)


def _record(raw: bytes, out: Path, number: int) -> dict[str, Any] | None:
    """Line ``number`` of ``out`` as a record, None when blank."""
    try:
        text = raw.decode("utf-8")
        if not text.strip():
            return None
        record = json.loads(text)
    except (UnicodeDecodeError, json.JSONDecodeError):
        raise InputError("not a JSON line", source=str(out), where=f"line {number}") from None
    if not (isinstance(record, dict) and isinstance(record.get("input"), str)):
        raise InputError(
            "not a result line (an object with 'input')", source=str(out), where=f"line {number}"
        )
    return record


def finished_inputs(out: Path) -> set[Key]:
    """The keys (:data:`Key`) of the answers already in the results file ``out``."""
    return set(read_results(out).finished)


def _answers(futures: Iterable[Any]) -> Iterator[dict[str, Any]]:
    """The lines of futures as they finish; a job ended by an interruption has none."""
    for future in futures:
        try:
            yield future.result()
        except _Stopped:
            continue


@contextlib.contextmanager
def _local(jobs: Sequence[Job], workers: int) -> Iterator[Iterator[dict[str, Any]]]:
    """Lines of ``jobs`` as they finish, from ``workers`` threads each waiting on one
    child; leaving the block early kills the children still running."""
    pool = ThreadPoolExecutor(max_workers=workers)
    futures = [pool.submit(run_job, job) for job in jobs]
    try:
        yield _answers(as_completed(futures))
    finally:
        with _CHILDREN.stopping():
            pool.shutdown(cancel_futures=True)
        close_workers()


SCHEDULER_TIMEOUT = 10
"""Seconds to wait for a remote Dask scheduler to answer before saying it is not there."""


@contextlib.contextmanager
def _dask(
    jobs: Sequence[Job], workers: int, scheduler: str | None
) -> Iterator[Iterator[dict[str, Any]]]:
    """As :func:`_local`, with the jobs run as Dask tasks."""
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
        try:
            client = Client(scheduler, timeout=SCHEDULER_TIMEOUT)
        except (OSError, ValueError, TypeError) as error:  # unreachable, or no address
            raise InputError(
                f"no Dask scheduler there ({' '.join(str(error).split()) or type(error).__name__})",
                source=scheduler,
                where="--scheduler",
            ) from None
    # the workers of a local cluster are threads of this process: each keeps a worker
    # process; a remote one's jobs each run in a child of their own
    keep = cluster is not None
    try:
        futures = [client.submit(run_job, j, keep, pure=False) for j in jobs]
        yield _answers(dask_completed(futures))
    finally:
        with _CHILDREN.stopping(), _quiet_logger("distributed"):
            client.close()
            if cluster is not None:
                cluster.close()
        close_workers()


@contextlib.contextmanager
def _quiet_logger(name: str) -> Iterator[None]:
    """Only errors from logger ``name`` in the block: Dask warns about each running task
    that closing cancels, and an interrupted run closes with tasks running."""
    logger = logging.getLogger(name)
    level = logger.level
    logger.setLevel(logging.ERROR)
    try:
        yield
    finally:
        logger.setLevel(level)


def _append(sink: io.FileIO, record: dict[str, Any]) -> None:
    """Append ``record`` as one whole line: a single write, then ``fsync``."""
    line = (json.dumps(record) + "\n").encode("utf-8")
    if sink.write(line) != len(line):
        raise InputError("cannot write a whole line (is the disk full?)", source=str(sink.name))
    os.fsync(sink.fileno())


def _stderr_line(message: str) -> None:
    sys.stderr.write(message + "\n")


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
    notice: Callable[[str], None] = _stderr_line,
) -> BatchSummary:
    """Run ``command`` over ``inputs`` and append one JSON line per assembly to ``out``.

    Inputs already answered in ``out`` are skipped (module docstring); a last line cut
    short is dropped first and ``notice`` is told so; ``progress(done, total)`` is called
    after each assembly. Ctrl-C ends the run with :class:`KeyboardInterrupt`, keeping the
    lines written.
    """
    if engine not in ("local", "dask"):
        raise InputError(f"unknown engine {engine!r} (use local or dask)", where="--engine")
    if workers < 1:
        raise InputError(f"workers must be at least 1, got {workers}", where="--workers")
    target = Path(out)
    names = [str(path) for path in inputs]
    results = read_results(target)
    failed: list[Failure] = []
    todo: list[Job] = []
    for name in names:
        try:
            path = Path(name).resolve(strict=True)
            job = Job(name, command, timeout, rel_tolerance, str(path), content_digest(path))
        except FileNotFoundError:
            failed.append(Failure(name, "missing", "no such file or folder"))
        except OSError as error:
            failed.append(Failure(name, "missing", f"cannot read: {error.strerror}"))
        else:
            if job.key not in results.finished:
                todo.append(job)
    target.parent.mkdir(parents=True, exist_ok=True)
    if results.torn_line:
        os.truncate(target, results.whole)
        notice(f"{target}: dropped line {results.torn_line}, cut short by an interrupted run")
    statuses: Counter[str] = Counter()
    runs = _local(todo, workers) if engine == "local" else _dask(todo, workers, scheduler)
    with target.open("ab", buffering=0) as sink, runs as lines:
        for record in lines:
            _append(sink, record)
            statuses[record["status"]] += 1
            if record["status"] != "ok":
                failed.append(Failure(record["input"], record["status"], record["error"]))
            if progress is not None:
                progress(sum(statuses.values()), len(todo))
    order = {name: i for i, name in enumerate(names)}
    failed.sort(key=lambda f: order[f.input])
    skipped = len(names) - len(todo) - sum(f.status == "missing" for f in failed)
    return BatchSummary(str(target), len(names), skipped, dict(statuses), tuple(failed))


def answer(command: str, path: str, rel_tolerance: float | None = None) -> dict[str, Any]:
    """One job's outcome as a worker prints it: ``status`` and ``result`` or ``error``
    (``internal`` for a fault of assemblykit rather than of the input)."""
    try:
        return {
            "status": "ok",
            "result": compute(command, path, rel_tolerance),  # type: ignore[arg-type]
        }
    except (InputError, MissingExtraError) as bad:
        return {"status": "error", "error": str(bad)}
    except AssemblyKitError as failure:  # a fault of the computation, not of the input
        return {"status": "error", "error": f"internal error: {failure}", "internal": True}
    except Exception as bug:  # recorded, never fatal to the batch
        return {
            "status": "error",
            "error": f"internal error: {type(bug).__name__}: {bug}",
            "internal": True,
        }


def _child(argv: Sequence[str]) -> int:
    """A child of one job: print one JSON object (:func:`answer`)."""
    command, path, *rest = argv
    rel_tolerance = float(rest[0]) if rest else None
    try:
        outcome = answer(command, path, rel_tolerance)
    except KeyboardInterrupt:  # Ctrl-C reaches the whole process group; the batch stops
        return INTERRUPTED_CODES[0]
    sys.stdout.write(json.dumps(outcome) + "\n")
    return 0


def _serve(requests: IO[str], answers: IO[str]) -> int:
    """A worker: for each request line (``{"command", "path", "rel_tolerance"}``), one
    answer line (:func:`answer`), flushed at once; it ends with its input."""
    from assemblykit.io.assembly import load_assembly  # noqa: F401  (imported once, here)
    from assemblykit.planning.planner import plan  # noqa: F401

    try:
        for line in requests:
            request = json.loads(line)
            outcome = answer(request["command"], request["path"], request.get("rel_tolerance"))
            answers.write(json.dumps(outcome) + "\n")
            answers.flush()
    except KeyboardInterrupt:
        return INTERRUPTED_CODES[0]
    return 0


if __name__ == "__main__":
    if sys.argv[1:] == ["--serve"]:
        raise SystemExit(_serve(sys.stdin, sys.stdout))
    raise SystemExit(_child(sys.argv[1:]))
