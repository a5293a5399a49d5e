"""``assemblykit mate``: the answers of Liu & Popplestone 1990 on the bundled problems; exit 2
on bad input."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from assemblykit.cli import main


def _run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    with pytest.raises(SystemExit) as done:
        main(["mate", *args])
        raise SystemExit(0)
    out, err = capsys.readouterr()
    return int(done.value.code or 0), out, err


def test_example1_json(mating_examples: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = _run(capsys, str(mating_examples / "example1.yaml"), "--json")
    data = json.loads(out)
    assert code == 0
    assert (data["count"], data["representatives"]) == (8, 2)
    seats = sorted(
        tuple(p["second"][1] for p in config["pairs"]) for config in data["configurations"]
    )
    assert seats == [("comp1", "comp13", "comp12"), ("comp13", "comp1", "comp12")]


def test_no_solution_is_an_answer(
    mating_examples: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, _ = _run(capsys, str(mating_examples / "one_socket.yaml"))
    assert code == 0
    assert "no configuration found" in out
    assert "goal 2: no candidate left after the mandatory request law" in out


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("bodies: {}\n", "p.yaml: missing field 'goals'"),
        ("bodies: {a: {features: {}}}\ngoals: [[fit, a, b]]\n", "p.yaml: goals[0][2]: no body"),
        ("goals: [\n", "p.yaml: line"),
    ],
)
def test_bad_input_exits_2_with_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, message: str
) -> None:
    path = tmp_path / "p.yaml"
    path.write_text(text)
    code, out, err = _run(capsys, str(path))
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1
    assert message in err


def test_missing_file_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = _run(capsys, str(tmp_path / "none.yaml"))
    assert code == 2 and "cannot read the problem" in err


def test_example3_position_up_to_the_peg_symmetry(
    mating_examples: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, _ = _run(capsys, str(mating_examples / "example3.yaml"), "--json")
    data = json.loads(out)
    # The three third-turns of the key are one position of the C3-symmetric peg.
    assert code == 0 and data["count"] == 1
    assert data["statistics"]["domains"]["1"] == [1, 1, 1, 1, 1, 1]
    assert data["configurations"][0]["poses"]["peg"] == [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]


def test_png_draws_the_two_layer_graph(
    mating_examples: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    png = tmp_path / "graph.png"
    code, out, err = _run(capsys, str(mating_examples / "example1.yaml"), "--png", str(png))
    assert code == 0 and "8 configurations" in out
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert err.strip() == f"wrote {png}"


@pytest.mark.parametrize("name", ["missing/graph.png", "graph.svg", ""])
def test_a_bad_png_path_exits_2_before_reading_the_problem(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _, err = _run(capsys, str(tmp_path / "nosuch.yaml"), "--png", str(tmp_path / name))
    assert code == 2 and "--png" in err and len(err.strip().splitlines()) == 1
    assert not list(tmp_path.iterdir())
