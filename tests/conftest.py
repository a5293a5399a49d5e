"""Shared fixtures; puts this folder on ``sys.path`` so that test modules import
``datasets`` (importlib import mode adds no test directory itself)."""

from __future__ import annotations

import os
import sys
from collections.abc import Generator
from pathlib import Path

# One thread per process for the linear algebra libraries: the suite runs one process
# per core (pytest-xdist), and more threads than cores only wait on each other. Set
# before numpy is first imported (the test modules import it after this file).
for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import pytest  # noqa: E402
from hypothesis import settings  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

# The same examples on every machine and run: a failure seen once is seen again, and a
# clean checkout passes or fails as a whole (the example database is not kept).
settings.register_profile("repeatable", derandomize=True, database=None)
settings.load_profile("repeatable")


@pytest.hookimpl(wrapper=True)
def pytest_make_collect_report(collector: pytest.Collector) -> Generator[None]:
    """Test modules imported with their rewritten asserts cached beside them (pytest's
    ``__pycache__`` files), even where ``PYTHONDONTWRITEBYTECODE`` is set: without the
    cache each worker rewrites every module's asserts again, about 10 s of every run."""
    if not (isinstance(collector, pytest.Module) and sys.dont_write_bytecode):
        return (yield)
    sys.dont_write_bytecode = False
    try:
        return (yield)
    finally:
        sys.dont_write_bytecode = True


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The tests marked ``early`` first, the others in their order: a long test started
    last would keep one worker busy after the others have run out of tests."""
    items.sort(key=lambda item: item.get_closest_marker("early") is None)


@pytest.fixture(scope="session")
def mating_examples() -> Path:
    """The folder of bundled mating problems (Liu & Popplestone 1990 Examples 1-2, no-solution
    case)."""
    return Path(__file__).resolve().parents[1] / "src" / "assemblykit" / "examples" / "mating"
