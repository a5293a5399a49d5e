"""Where the benchmarks find real assemblies: those shipped under ``tests/data`` first,
then the larger optional ones under ``$ASSEMBLYKIT_DATA`` (e.g. the 527-block dome) or in
the ``shared/data`` folder next to the checkout."""

from __future__ import annotations

import os
from pathlib import Path

BUNDLED = Path(__file__).resolve().parents[1] / "tests" / "data"
BESIDE = Path(__file__).resolve().parents[2] / "shared" / "data"


def dataset(relative: str) -> Path | None:
    """The data file or folder ``relative`` (``compas_assembly/dome_assembly.json``), or
    None when it is neither bundled, nor under ``$ASSEMBLYKIT_DATA``, nor beside the
    checkout."""
    for root in (BUNDLED, os.environ.get("ASSEMBLYKIT_DATA"), BESIDE):
        if root and (Path(root) / relative).exists():
            return Path(root) / relative
    return None
