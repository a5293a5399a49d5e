"""The one process-wide setting the library changes, and only for the duration of a call:
the cyclic garbage collector's pause (docs/architecture.md, "Caching").

Reading a large task file and building and reducing its network allocate many small
objects that all stay alive until the answer is built; every collection those
allocations trigger rescans all of them, which makes a large task cost quadratic time.
None of them is cyclic garbage, so nothing is lost by collecting once afterwards.
"""

from __future__ import annotations

import gc
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def collector_paused() -> Iterator[None]:
    """Pause the cyclic garbage collector for the duration, restoring its state after
    (a pause inside another leaves it paused)."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()
