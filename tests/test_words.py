"""The commands speak an engineer's words (docs/blocking.md, "Output"; docs/mating.md,
"The answer"; docs/planning.md, "Under gravity"): no graph jargon in titles, plurals by
count, volumes with their unit, the paper's Or/And tree kept for Python, and a number
that does not parse named as such on one line of stderr with exit 2. Each command runs
in-process on a small bundled example (tests/cli_runs.py); the checks are on words, not
on the layout, so the terminal's width does not matter."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import trimesh

import assemblykit
from cli_runs import run

EXAMPLES = Path(assemblykit.__file__).parent / "examples"
COMPAS = Path(__file__).parent / "data" / "compas_assembly"


def test_blocking_titles_say_what_moves_not_ndbg(capsys: pytest.CaptureFixture[str]) -> None:
    hook = str(EXAMPLES / "planar" / "hook.yaml")
    for motion in ("infinitesimal", "extended"):
        code, out, err = run(capsys, "blocking", hook, "--motion", motion)
        assert code == 0, err
        assert "Parts removable by" in out and "regions of directions" in out
        assert "NDBG" not in out and "vertices" not in out


def test_interlock_names_the_motion_in_words(capsys: pytest.CaptureFixture[str]) -> None:
    lipped = str(EXAMPLES / "interlocking" / "lipped_joint.yaml")
    code, out, err = run(capsys, "interlock", lipped, "--motion", "extended")
    assert code == 0, err
    assert "(straight moves all the way out, 3 parts)" in out
    assert "groups of directions checked" in out
    assert "extended translations" not in out and "blocking graph" not in out


def test_plan_counts_orders_in_words(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "plan", str(COMPAS / "two-blocks_assembly.json"), "--gravity")
    assert code == 0, err
    assert "1 possible order" in out
    assert "(s)" not in out and "AND/OR" not in out


def test_long_would_fall_cells_are_cut_like_away_from(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code, out, err = run(capsys, "plan", str(COMPAS / "stack_assembly.json"), "--gravity")
    assert code == 0, err
    # step 1 lifts the top block of ten: eight below it would fall, cut after four
    assert "1, 2, 3, 4 and 4 more" in out
    assert "1, 2, 3, 4, 5" not in out


def test_mate_lists_pairs_in_words(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "mate", str(EXAMPLES / "mating" / "example1.yaml"))
    assert code == 0, err
    assert "8 configurations (2 up to symmetry)" in out
    assert "b1 comp1 fits b4 comp1 (goal 1)" in out
    assert "[Or" not in out and "[And" not in out and "domain" not in out
    code, out, _ = run(capsys, "mate", str(EXAMPLES / "mating" / "example3.yaml"))
    assert "1 configuration\n" in out and "configurations" not in out


def test_volumes_carry_the_models_unit(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    trimesh.creation.box(extents=[1, 1, 1]).export(tmp_path / "a.stl")
    sunk = trimesh.creation.box(extents=[1, 1, 1])
    sunk.apply_translation([0, 0, 0.5])
    sunk.export(tmp_path / "b.stl")
    code, out, err = run(capsys, "contacts", str(tmp_path))
    assert code == 0, err
    assert "volume (mm³)" in out
    assert re.search(r"interference a / b: volume 0\.5 mm³", out)
    code, out, err = run(capsys, "plan", str(tmp_path), "--ignore-overlap", "0")
    assert code == 0, err
    assert "volume (mm³)" in out


def test_symmetric_positions_not_discrete_components(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code, out, err = run(capsys, "motion", str(EXAMPLES / "motion" / "drawer" / "drawer.yaml"))
    assert code == 0, err
    assert "2 symmetric positions" in out and "discrete" not in out


@pytest.mark.parametrize("option", ["--tolerance", "--friction"])
def test_a_number_that_does_not_parse_is_one_line(
    capsys: pytest.CaptureFixture[str], option: str
) -> None:
    code, out, err = run(capsys, "plan", str(COMPAS / "two-blocks_assembly.json"), option, "abc")
    assert code == 2 and out == ""
    assert err.count("\n") == 1
    assert f"{option}: 'abc' is not a number" in err
    assert "float range" not in err and "Usage" not in err


@pytest.mark.parametrize(
    ("option", "value", "said"),
    [
        ("--max-steps", "abc", "'abc' is not a whole number"),
        ("--max-steps", "2.5", "'2.5' is not a whole number"),
        ("--max-steps", "-3", "-3 must be at least 0"),
        ("--tolerance", "-1", "-1 must be at least"),
    ],
)
def test_an_option_value_out_of_its_range_is_one_line_in_words(
    capsys: pytest.CaptureFixture[str], option: str, value: str, said: str
) -> None:
    code, out, err = run(capsys, "plan", str(COMPAS / "two-blocks_assembly.json"), option, value)
    assert code == 2 and out == ""
    assert err.count("\n") == 1
    assert f"{option}: {said}" in err
    assert "range" not in err and "Usage" not in err
