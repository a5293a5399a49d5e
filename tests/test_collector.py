"""The garbage collector's pause: paused inside, restored after, whatever happens."""

from __future__ import annotations

import gc
from collections.abc import Iterator
from pathlib import Path

import pytest

from assemblykit.collector import collector_paused
from assemblykit.errors import InputError
from assemblykit.io.tasks import load_task


@pytest.fixture
def collecting() -> Iterator[None]:
    was = gc.isenabled()
    gc.enable()
    yield
    if not was:
        gc.disable()


def test_paused_inside_and_restored_after(collecting: None) -> None:
    with collector_paused():
        assert not gc.isenabled()
        with collector_paused():
            assert not gc.isenabled()
        assert not gc.isenabled()
    assert gc.isenabled()


def test_restored_after_an_error(collecting: None) -> None:
    with pytest.raises(ValueError), collector_paused():
        raise ValueError("inside")
    assert gc.isenabled()


def test_a_paused_collector_stays_paused() -> None:
    was = gc.isenabled()
    gc.disable()
    try:
        with collector_paused():
            pass
        assert not gc.isenabled()
    finally:
        if was:
            gc.enable()


def test_reading_a_task_file_restores_it(collecting: None, tmp_path: Path) -> None:
    good = tmp_path / "task.yaml"
    good.write_text(
        "bodies:\n  a: {fixed: true, features: {f: {type: plane, point: [0, 0, 0], "
        "normal: [0, 0, 1]}}}\n  b: {features: {g: {type: plane, point: [0, 0, 0], "
        "normal: [0, 0, -1]}}}\nsituations:\n  - {name: s, relations: [[against, b.g, a.f]]}\n"
    )
    assert set(load_task(good).bodies) == {"a", "b"}
    assert gc.isenabled()
    bad = tmp_path / "bad.yaml"
    bad.write_text("bodies: [1, 2\n")
    with pytest.raises(InputError):
        load_task(bad)
    assert gc.isenabled()
