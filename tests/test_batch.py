"""Tests of batch runs: one JSON line per assembly, errors and timeouts recorded, reruns
skip answered work (by command, absolute path and content) and retry the rest, a line cut
short is dropped, and the local and Dask engines agree.

The resumption tests replace the Python of the batch's children by a shell script
(``sys.executable``) that answers at once, dies, or says which inputs it ran, so that
they test the bookkeeping without planning anything.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

import pytest

from assemblykit import batch
from assemblykit.batch import finished_inputs, run_batch
from assemblykit.errors import InputError
from datasets import dataset

ROOT = Path(__file__).resolve().parents[1]
DEMO = ROOT / "src" / "assemblykit" / "examples" / "gearbox_demo" / "gearbox.yaml"


def lines(path: Path) -> dict[str, dict]:
    return {r["input"]: r for r in map(json.loads, path.read_text().splitlines())}


def shared_inputs() -> list[str]:
    names = ("two-blocks_assembly.json", "stack_assembly.json")
    return [str(dataset(f"compas_assembly/{name}")) for name in names]


@pytest.mark.slow
def test_results_errors_and_rerun_skipping(tmp_path):
    out = tmp_path / "runs" / "results.jsonl"
    missing = str(tmp_path / "missing.yaml")
    broken = tmp_path / "broken.yaml"
    broken.write_text("parts: 3\n")
    inputs = [str(DEMO), missing, str(broken)]
    summary = run_batch(inputs, out, workers=2)
    data = summary.to_dict()
    assert {k: v for k, v in data.items() if k != "failed"} == {
        "out": str(out),
        "total": 3,
        "skipped": 0,
        "ran": 2,
        "ok": 1,
        "error": 1,
        "timeout": 0,
        "missing": 1,
    }
    # every input without an answer is listed, in the order given, with its message
    assert [(f["input"], f["status"]) for f in data["failed"]] == [
        (missing, "missing"),
        (str(broken), "error"),
    ]
    assert data["failed"][0]["error"] == "no such file or folder"
    assert "broken.yaml" in data["failed"][1]["error"]
    # the missing input is not recorded: only the two that ran are
    records = lines(out)
    assert set(records) == {str(DEMO), str(broken)}
    good = records[str(DEMO)]
    assert good["status"] == "ok"
    assert good["result"]["feasible"] is True
    assert good["seconds"] > 0
    assert records[str(broken)]["status"] == "error"
    # a rerun skips the two finished inputs and tries the missing one again
    again = run_batch(inputs, out)
    assert again.skipped == 2 and again.to_dict()["ran"] == 0
    assert again.missing == (missing,)
    assert len(out.read_text().splitlines()) == 2


def test_timeout_is_recorded_and_retried(tmp_path):
    out = tmp_path / "results.jsonl"
    summary = run_batch([str(DEMO)], out, timeout=0.05)
    assert summary.statuses == {"timeout": 1}
    record = lines(out)[str(DEMO)]
    assert record["status"] == "timeout"
    assert record["retry"] is True
    assert "result" not in record
    assert finished_inputs(out) == set()  # timed-out inputs run again next time


def sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def test_finished_inputs_are_answers_keyed_by_command_path_and_content(tmp_path):
    out = tmp_path / "results.jsonl"
    key = {"command": "plan", "path": "/data/a.json", "sha256": sha256(b"a")}
    records = [
        {"input": "a.json", "status": "ok", **key},
        {"input": "b.json", "status": "error", **key, "path": "/data/b.json"},
        {"input": "c.json", "status": "error", "retry": True, **key, "path": "/data/c.json"},
        {"input": "d.json", "status": "timeout", "retry": True, **key, "path": "/data/d.json"},
        {"input": "e.json", "status": "ok"},  # no path nor digest: answers nothing
    ]
    out.write_text("".join(json.dumps(r) + "\n" for r in records) + '{"input": "f.js')
    assert finished_inputs(out) == {
        ("plan", "/data/a.json", sha256(b"a")),
        ("plan", "/data/b.json", sha256(b"a")),
    }
    out.write_text('{"input": "a.json"\n{"input": "b.json", "status": "error"}\n')
    with pytest.raises(InputError, match="line 1"):
        finished_inputs(out)


FAKE_PYTHON = """#!/bin/sh
# the Python of a batch's workers ("-m assemblykit.batch --serve"): one request per line
# on stdin ({"command": ..., "path": ...}), one answer per line on stdout
while IFS= read -r line; do
  path=$(printf '%s\\n' "$line" | sed -n 's/.*"path": "\\([^"]*\\)".*/\\1/p')
  echo "$path" >> "$(dirname "$0")/ran.txt"
  case "$path" in
    *die*) kill -9 $$ ;;
    *bad*) echo '{"status": "error", "error": "'"$path"': not an assembly"}' ;;
    *) echo '{"status": "ok", "result": {"ran": "'"$path"'"}}' ;;
  esac
done
"""


@pytest.fixture
def fake_python(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """The children's Python replaced by :data:`FAKE_PYTHON`; returns its log of inputs."""
    script = tmp_path / "bin" / "python"
    script.parent.mkdir()
    script.write_text(FAKE_PYTHON)
    script.chmod(0o755)
    monkeypatch.setattr(sys, "executable", str(script))
    return script.parent / "ran.txt"


def ran(log: Path) -> list[str]:
    """The inputs the children were started on, and empties the log."""
    names = log.read_text().splitlines() if log.exists() else []
    log.unlink(missing_ok=True)
    return names


def whole_lines(out: Path) -> list[dict]:
    text = out.read_text()
    assert text.endswith("\n")
    return [json.loads(line) for line in text.splitlines()]


def test_a_cut_last_line_is_dropped_and_its_input_run_again(tmp_path, fake_python):
    a, b = tmp_path / "a.yaml", tmp_path / "b.yaml"
    a.write_text("a\n")
    b.write_text("b\n")
    out = tmp_path / "results.jsonl"
    run_batch([a], out)
    assert ran(fake_python) == [str(a)]
    with out.open("a") as sink:  # a run killed while writing b's line
        sink.write('{"input": "' + str(b) + '", "status": "ok", "res')
    notices = []
    summary = run_batch([a, b], out, notice=notices.append)
    assert notices == [f"{out}: dropped line 2, cut short by an interrupted run"]
    assert (summary.skipped, summary.statuses) == (1, {"ok": 1})
    assert ran(fake_python) == [str(b)]
    records = whole_lines(out)
    answered = [(r["input"], r["result"]["ran"]) for r in records]
    assert answered == [(str(a), str(a)), (str(b), str(b))]
    assert records[1]["path"] == str(b) and records[1]["sha256"] == sha256(b"b\n")
    assert run_batch([a, b], out, notice=notices.append).skipped == 2
    assert len(notices) == 1 and ran(fake_python) == []


def test_same_relative_path_in_two_folders_is_two_jobs(tmp_path, fake_python, monkeypatch):
    out = tmp_path / "results.jsonl"
    one, two = tmp_path / "one", tmp_path / "two"
    for folder in (one, two):
        folder.mkdir()
        (folder / "x.yaml").write_text("the same text\n")
    for folder in (one, two):
        monkeypatch.chdir(folder)
        assert run_batch(["x.yaml"], out).skipped == 0
        assert ran(fake_python) == [str(folder / "x.yaml")]
    assert [(r["input"], r["path"]) for r in whole_lines(out)] == [
        ("x.yaml", str(one / "x.yaml")),
        ("x.yaml", str(two / "x.yaml")),
    ]
    assert run_batch(["x.yaml"], out).skipped == 1  # answered for this folder already
    (two / "x.yaml").write_text("edited\n")
    assert run_batch(["x.yaml"], out).skipped == 0  # same path, new content: run again
    assert run_batch(["x.yaml"], out, command="motion").skipped == 0  # another command
    assert ran(fake_python) == [str(two / "x.yaml")] * 2


def test_a_folder_digest_covers_its_files(tmp_path, fake_python):
    out = tmp_path / "results.jsonl"
    folder = tmp_path / "meshes"
    folder.mkdir()
    (folder / "a.obj").write_text("v 0 0 0\n")
    run_batch([folder], out)
    assert run_batch([folder], out).skipped == 1
    (folder / "b.obj").write_text("v 1 0 0\n")
    assert run_batch([folder], out).skipped == 0
    assert ran(fake_python) == [str(folder)] * 2


def test_dead_workers_are_retried_and_answers_are_not(tmp_path, fake_python):
    out = tmp_path / "results.jsonl"
    inputs = [tmp_path / name for name in ("ok.yaml", "bad.yaml", "die.yaml")]
    for path in inputs:
        path.write_text(path.name)
    summary = run_batch(inputs, out)
    assert summary.statuses == {"ok": 1, "error": 2}
    records = {Path(r["input"]).name: r for r in whole_lines(out)}
    assert records["die.yaml"]["error"] == "worker died: killed by SIGKILL"
    assert records["die.yaml"]["retry"] is True
    assert "retry" not in records["bad.yaml"] and "retry" not in records["ok.yaml"]
    assert sorted(ran(fake_python)) == sorted(map(str, inputs))
    # the next run retries only the worker that died (it dies again here)
    again = run_batch(inputs, out)
    assert (again.skipped, again.statuses) == (2, {"error": 1})
    assert ran(fake_python) == [str(inputs[2])]


def test_bad_engine_is_an_input_error(tmp_path):
    with pytest.raises(InputError, match="unknown engine"):
        run_batch([str(DEMO)], tmp_path / "r.jsonl", engine="spark")  # type: ignore[arg-type]


def test_a_scheduler_address_that_is_none_is_an_input_error(tmp_path):
    pytest.importorskip("dask.distributed")
    with pytest.raises(InputError, match=r"notanaddress.*--scheduler.*no Dask scheduler"):
        run_batch([str(DEMO)], tmp_path / "r.jsonl", engine="dask", scheduler="notanaddress")


@pytest.mark.slow
def test_local_and_dask_engines_agree(tmp_path):
    pytest.importorskip("dask.distributed")
    inputs = [*shared_inputs(), str(DEMO)]
    local, dask = tmp_path / "local.jsonl", tmp_path / "dask.jsonl"
    run_batch(inputs, local, engine="local", workers=2)
    run_batch(inputs, dask, engine="dask", workers=2)
    by_local, by_dask = lines(local), lines(dask)
    assert set(by_local) == set(by_dask) == set(inputs)
    for name in inputs:
        assert by_local[name]["status"] == by_dask[name]["status"] == "ok"
        assert by_local[name]["result"] == by_dask[name]["result"]
    assert run_batch(inputs, dask, engine="dask", workers=2).skipped == len(inputs)


def test_a_fault_of_assemblykit_is_recorded_as_one_not_as_bad_input(tmp_path, monkeypatch, capsys):
    # bad input: the loader's message, as the command prints it
    assert batch._child(["plan", str(tmp_path / "none.yaml")]) == 0
    record = json.loads(capsys.readouterr().out)
    assert record["status"] == "error" and "none.yaml" in record["error"]
    assert "internal" not in record

    # a fault of the computation: said to be one
    def broken(*args, **kwargs):
        raise ZeroDivisionError("division by zero")

    monkeypatch.setattr(batch, "compute", broken)
    assert batch._child(["plan", str(DEMO)]) == 0
    record = json.loads(capsys.readouterr().out)
    assert record == {
        "status": "error",
        "error": "internal error: ZeroDivisionError: division by zero",
        "internal": True,
    }


THREADS_PYTHON = """#!/bin/sh
# a worker that answers each request with the thread counts its environment sets
while IFS= read -r line; do
  openblas=$OPENBLAS_NUM_THREADS omp=$OMP_NUM_THREADS
  echo '{"status": "ok", "result": {"openblas": "'"$openblas"'", "omp": "'"$omp"'"}}'
done
"""


@pytest.mark.parametrize("asked", [None, "2"])
def test_workers_run_their_numerical_libraries_on_one_thread_unless_told(
    tmp_path, monkeypatch, asked
):
    script = tmp_path / "bin" / "python"
    script.parent.mkdir()
    script.write_text(THREADS_PYTHON)
    script.chmod(0o755)
    monkeypatch.setattr(sys, "executable", str(script))
    for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"):
        monkeypatch.delenv(name, raising=False)
    if asked is not None:
        monkeypatch.setenv("OPENBLAS_NUM_THREADS", asked)
    (tmp_path / "a.yaml").write_text("a")
    out = tmp_path / "results.jsonl"
    run_batch([tmp_path / "a.yaml"], out, workers=2)
    [record] = whole_lines(out)
    assert record["result"] == {"openblas": asked or "1", "omp": "1"}
