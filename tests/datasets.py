"""Where the tests find real assemblies: the ones shipped under ``tests/data`` first,
then the optional larger ones under ``$ASSEMBLYKIT_DATA`` (skipped when absent)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

BUNDLED = Path(__file__).resolve().parent / "data"


def dataset(relative: str) -> Path:
    """The data file or folder ``relative`` (e.g. ``compas_assembly/arch_assembly.json``);
    skips the calling test when it is neither bundled nor in ``$ASSEMBLYKIT_DATA``."""
    bundled = BUNDLED / relative
    if bundled.exists():
        return bundled
    extra = os.environ.get("ASSEMBLYKIT_DATA")
    if extra and (Path(extra) / relative).exists():
        return Path(extra) / relative
    pytest.skip(f"{relative} is not bundled and ASSEMBLYKIT_DATA does not hold it")
