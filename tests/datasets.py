"""Where the tests find real assemblies: the ones shipped under ``tests/data`` first,
then the optional larger ones under ``$ASSEMBLYKIT_DATA`` (skipped when absent)."""

from __future__ import annotations

import functools
import os
from pathlib import Path

import pytest

from assemblykit.io.assembly import load_assembly
from assemblykit.model.assembly import Assembly

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


def shared_assembly(source: str | Path) -> Assembly:
    """The assembly read from ``source`` as :func:`load_assembly` reads it by default: a
    path, or a name for :func:`dataset`. Read once per test process and shared by the
    tests that only read it, so what one of them computes from it (contacts, blocking
    graphs: the assembly's memo) serves the next. A test that changes a part, or that
    replaces a function the computation calls, reads its own copy."""
    return _read(dataset(source) if isinstance(source, str) else Path(source))


@functools.cache
def _read(path: Path) -> Assembly:
    return load_assembly(path)
