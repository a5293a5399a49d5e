"""manifold3d's thread pool as assemblykit starts it (geometry/booleans.py)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from assemblykit.geometry.booleans import BOOLEAN_THREADS_VARIABLE

pytestmark = pytest.mark.skipif(
    not hasattr(os, "sched_setaffinity") or not os.path.isdir("/proc/self/task"),
    reason="threads are chosen through the cores a thread may use (Linux)",
)

PROBE = """
import json, os
cores = sorted(os.sched_getaffinity(0))
import assemblykit.geometry.booleans as booleans
after_import = sorted(os.sched_getaffinity(0))
before = len(os.listdir("/proc/self/task"))
a = booleans.manifold3d.Manifold.sphere(1.0, 400)
volume = (a ^ a.translate((0.5, 0.0, 0.0))).volume()
print(json.dumps({
    "cores": cores, "after_import": after_import, "volume": volume,
    "added": len(os.listdir("/proc/self/task")) - before,
}))
"""


def probe(threads: str | None) -> dict[str, object]:
    """What a fresh process importing the module reports, with the variable set to
    ``threads`` (unset for ``None``)."""
    env = {k: v for k, v in os.environ.items() if k != BOOLEAN_THREADS_VARIABLE}
    if threads is not None:
        env[BOOLEAN_THREADS_VARIABLE] = threads
    out = subprocess.run(
        [sys.executable, "-c", PROBE], env=env, capture_output=True, text=True, check=True
    )
    return dict(json.loads(out.stdout))


def test_booleans_run_on_the_calling_thread_and_every_core_stays_allowed() -> None:
    report = probe(None)
    assert report["after_import"] == report["cores"]
    assert report["added"] == 0
    assert float(str(report["volume"])) > 1.0  # two unit spheres half a radius apart


def test_every_core_on_request() -> None:
    report = probe("all")
    assert report["after_import"] == report["cores"]
    cores = report["cores"]
    assert isinstance(cores, list)
    if len(cores) < 2:
        pytest.skip("one core: the pool has no thread to add")
    assert int(str(report["added"])) >= 1
