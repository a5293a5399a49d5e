"""The import contracts of ``pyproject.toml`` (docs/architecture.md, "Layers") name every
module of the packages they layer, so that a new module cannot escape them unseen."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[1]
CONTRACTS = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"][
    "importlinter"
]["contracts"]
LAYERED = [c for c in CONTRACTS if c["type"] == "layers" and "containers" in c]


def test_every_subpackage_is_layered() -> None:
    packages = {p.parent.name for p in (ROOT / "src" / "assemblykit").glob("*/__init__.py")}
    layered = {c["containers"][0].removeprefix("assemblykit.") for c in LAYERED}
    # the facades are kept apart by an independence contract instead
    assert packages - layered == {"api"}


@pytest.mark.parametrize("contract", LAYERED, ids=lambda c: c["name"])
def test_each_module_is_in_a_layer(contract: dict[str, Any]) -> None:
    package = ROOT / "src" / Path(*contract["containers"][0].split("."))
    named = {name.strip() for layer in contract["layers"] for name in layer.split("|")}
    modules = {p.stem for p in package.glob("*.py")} - {"__init__"}
    assert modules == named
