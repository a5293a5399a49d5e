"""Shared fixtures."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def mating_examples() -> Path:
    """The folder of bundled mating problems (seed 002 Examples 1-2, no-solution case)."""
    return Path(__file__).resolve().parents[1] / "src" / "assemblykit" / "examples" / "mating"
