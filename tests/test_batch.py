"""Tests of batch runs: one JSON line per assembly, errors and timeouts recorded, reruns
skip finished work, and the local and Dask engines agree."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

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
    assert "result" not in record
    assert finished_inputs(out) == set()  # timed-out inputs run again next time


def test_finished_inputs_tolerates_a_cut_last_line_only(tmp_path):
    out = tmp_path / "results.jsonl"
    out.write_text('{"input": "a.json", "status": "ok"}\n{"input": "b.js')
    assert finished_inputs(out) == {str(Path("a.json").resolve())}
    out.write_text('{"input": "a.json"\n{"input": "b.json", "status": "error"}\n')
    with pytest.raises(InputError, match="line 1"):
        finished_inputs(out)


def test_bad_engine_is_an_input_error(tmp_path):
    with pytest.raises(InputError, match="unknown engine"):
        run_batch([str(DEMO)], tmp_path / "r.jsonl", engine="spark")  # type: ignore[arg-type]


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
