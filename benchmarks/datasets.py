"""Where the benchmarks find real assemblies: those shipped under ``tests/data`` first,
then the larger optional ones under ``$ASSEMBLYKIT_DATA`` (e.g. the 527-block dome)."""

from __future__ import annotations

import os
from pathlib import Path

BUNDLED = Path(__file__).resolve().parents[1] / "tests" / "data"


def dataset(relative: str) -> Path | None:
    """The data file or folder ``relative`` (``compas_assembly/dome_assembly.json``), or
    None when it is neither bundled nor under ``$ASSEMBLYKIT_DATA``."""
    for root in (BUNDLED, os.environ.get("ASSEMBLYKIT_DATA")):
        if root and (Path(root) / relative).exists():
            return Path(root) / relative
    return None
