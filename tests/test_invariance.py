"""The bundled examples keep their answers when their numbers are disturbed as real input
is: every position and axis moved by 1e-12 .. 1e-7 of the model's size, or the whole model
scaled by 1e-3 and 1e3 (positions and lengths scaled, directions kept)."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from cli_runs import run as cli_run

EXAMPLES = Path(__file__).resolve().parents[1] / "src" / "assemblykit" / "examples"
LENGTHS = frozenset({"radius", "height", "size"})
"""Keys whose numbers are lengths, scaled with the model but not moved by a jitter."""
DIRECTIONS = frozenset({"axis", "normal"})
JITTERS = (1e-12, 1e-9, 1e-7)
SCALES = (1e-3, 1e3)


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> dict[str, Any]:
    code, out, err = cli_run(capsys, *argv)
    assert code == 0, err
    return json.loads(out)


Map = Callable[[np.ndarray], np.ndarray]


def transformed(
    document: Any, positions: Map, directions: Map, factor: float = 1.0, key: str | None = None
) -> Any:
    """``document`` with every point (list of numbers) mapped by ``positions``, every
    direction (under axis/normal keys) by ``directions``, and the lengths under length
    keys (radius, height, size) multiplied by ``factor``."""
    if isinstance(document, dict):
        return {k: transformed(v, positions, directions, factor, k) for k, v in document.items()}
    if isinstance(document, list) and not all(isinstance(v, (int, float)) for v in document):
        return [transformed(v, positions, directions, factor, key) for v in document]
    if isinstance(document, list):
        vector = np.asarray(document, dtype=np.float64)
        if key in DIRECTIONS:
            return directions(vector).tolist()
        return positions(vector).tolist()
    if isinstance(document, (int, float)) and not isinstance(document, bool) and key in LENGTHS:
        return float(document) * factor
    return document


def jittered(document: Any, size: float, relative: float, seed: int) -> Any:
    """``document`` with each point moved independently by up to ``relative`` of the
    model's ``size`` and each direction turned by up to about ``relative`` radians."""
    rng = np.random.default_rng(seed)

    def point(p: np.ndarray) -> np.ndarray:
        return p + rng.uniform(-1, 1, p.shape) * relative * size

    def direction(d: np.ndarray) -> np.ndarray:
        turned = d + rng.uniform(-1, 1, d.shape) * relative * np.linalg.norm(d)
        return turned / np.linalg.norm(turned) * np.linalg.norm(d)

    return transformed(document, point, direction)


def matching(relative: float) -> str:
    """The ``--tolerance`` for input moved by ``relative``: the default, or 100 times the
    disturbance when that is larger (docs/architecture.md, "Tolerances")."""
    return str(max(1e-9, 100 * relative))


def scaled(document: Any, factor: float) -> Any:
    """``document`` scaled by ``factor`` about the origin (directions kept)."""
    return transformed(document, lambda p: p * factor, lambda d: d, factor)


def written(tmp_path: Path, source: Path, document: Any) -> Path:
    target = tmp_path / source.name
    target.write_text(yaml.safe_dump(document), encoding="utf-8")
    return target


PLANAR = sorted((EXAMPLES / "planar").glob("*.yaml"))


def planar_answer(data: dict[str, Any]) -> tuple[Any, ...]:
    return (
        data["feasible"],
        [sorted(step["parts"]) for step in data["steps"]],
        [step["motion"] for step in data["steps"]],
        sorted(data["stuck"]),
        sorted(sorted(s["parts"]) for s in data["interlocked"]),
    )


def planar_size(document: dict[str, Any]) -> float:
    points = np.concatenate([np.asarray(p, dtype=np.float64) for p in document["parts"].values()])
    return float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))


@pytest.mark.parametrize("source", PLANAR, ids=lambda p: p.stem)
def test_planar_plans_survive_jitter_and_scaling(capsys, tmp_path, source):
    document = yaml.safe_load(source.read_text(encoding="utf-8"))
    expected = planar_answer(run(capsys, "plan", str(source), "--json"))
    size = planar_size(document)
    for number, relative in enumerate(JITTERS):
        moved = jittered(document, size, relative, number)
        target = written(tmp_path, source, moved)
        got = run(capsys, "plan", str(target), "--json", "--tolerance", matching(relative))
        assert planar_answer(got) == expected, f"jitter {relative}"
    for factor in SCALES:
        moved = scaled(document, factor)
        got = run(capsys, "plan", str(written(tmp_path, source, moved)), "--json")
        assert planar_answer(got) == expected, f"scale {factor}"


MATING = sorted((EXAMPLES / "mating").glob("*.yaml"))


def mating_answer(data: dict[str, Any]) -> tuple[Any, ...]:
    return data["status"], data["count"], data["representatives"]


def mating_size(document: dict[str, Any]) -> float:
    points: list[list[float]] = []

    def collect(node: Any, key: str | None = None) -> None:
        if isinstance(node, dict):
            for k, v in node.items():
                collect(v, k)
        elif isinstance(node, list) and key in {"point", "min", "max"}:
            points.append([float(v) for v in node])
        elif isinstance(node, list):
            for v in node:
                collect(v, key)

    collect(document)
    cloud = np.asarray(points)
    return float(np.linalg.norm(cloud.max(axis=0) - cloud.min(axis=0)))


@pytest.mark.slow
@pytest.mark.parametrize("source", MATING, ids=lambda p: p.stem)
def test_mating_answers_survive_jitter_and_scaling(capsys, tmp_path, source):
    document = yaml.safe_load(source.read_text(encoding="utf-8"))
    expected = mating_answer(run(capsys, "mate", str(source), "--json"))
    size = mating_size(document)
    for number, relative in enumerate(JITTERS):
        moved = jittered(document, size, relative, number)
        target = written(tmp_path, source, moved)
        got = run(capsys, "mate", str(target), "--json", "--tolerance", matching(relative))
        assert mating_answer(got) == expected, f"jitter {relative}"
    for factor in SCALES:
        moved = scaled(document, factor)
        got = run(capsys, "mate", str(written(tmp_path, source, moved)), "--json")
        assert mating_answer(got) == expected, f"scale {factor}"
