"""assemblykit: geometric reasoning about mechanical assemblies.

The public API (DESIGN.md §5.4) is imported lazily so that ``import assemblykit`` stays
cheap and optional extras are only needed by the functions that use them.
"""

from __future__ import annotations

import importlib
from typing import Any

from assemblykit.errors import AssemblyKitError

__version__ = "0.1.0"

_PUBLIC = {
    "load_task": "assemblykit.io.spec",
    "load_assembly": "assemblykit.io.assembly",
    "motion": "assemblykit.motion.freedom",
    "blocking_graph": "assemblykit.blocking.ndbg",
    "plan": "assemblykit.planning.sequence",
    "load_problem": "assemblykit.io.problem",
    "mate": "assemblykit.mating.search",
    "Tolerance": "assemblykit.tolerance",
}

__all__ = ["AssemblyKitError", "__version__", *_PUBLIC]


def __getattr__(name: str) -> Any:
    module = _PUBLIC.get(name)
    if module is None:
        raise AttributeError(f"module 'assemblykit' has no attribute {name!r}")
    return getattr(importlib.import_module(module), name)
