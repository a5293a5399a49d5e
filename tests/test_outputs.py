"""Outputs written atomically keep the permissions a user expects."""

from __future__ import annotations

import os
import stat
from pathlib import Path

from assemblykit.outputs import atomic_output


def _mode(path: Path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


def test_a_new_output_gets_the_mode_of_any_new_file(tmp_path: Path) -> None:
    old = os.umask(0o022)
    try:
        with atomic_output(tmp_path / "plan.csv") as temporary:
            temporary.write_text("step\n")
    finally:
        os.umask(old)
    assert _mode(tmp_path / "plan.csv") == 0o644
    assert (tmp_path / "plan.csv").read_text() == "step\n"


def test_a_replaced_output_keeps_its_mode(tmp_path: Path) -> None:
    target = tmp_path / "report.html"
    target.write_text("old")
    target.chmod(0o640)
    with atomic_output(target) as temporary:
        temporary.write_text("new")
    assert _mode(target) == 0o640 and target.read_text() == "new"
    assert [p.name for p in tmp_path.iterdir()] == ["report.html"]
