"""End-to-end tests of ``assemblykit plan``, ``demo`` and ``batch`` on the bundled gearbox."""

from __future__ import annotations

import contextlib
import io
import json
import math
from pathlib import Path

import numpy as np
import pytest

from cli_runs import run

ROOT = Path(__file__).resolve().parents[1]
DEMO = ROOT / "src" / "assemblykit" / "examples" / "gearbox_demo" / "gearbox.yaml"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def test_plan_json_html_and_png(capsys, tmp_path):
    html, png = tmp_path / "report.html", tmp_path / "exploded.png"
    code, out, err = run(
        capsys, "plan", str(DEMO), "--json", "--html", str(html), "--png", str(png)
    )
    assert code == 0, err
    data = json.loads(out)
    assert data["feasible"] is True
    assert data["stuck"] == []
    assert {"parts", "direction", "motion"} <= set(data["steps"][0])
    moved = {name for step in data["steps"] for name in step["parts"]}
    assert len(moved) == 13 and "base" not in moved  # the heaviest part stays
    assert html.stat().st_size > 3_000_000
    assert png.read_bytes()[:8] == PNG_SIGNATURE
    assert f"wrote {html}" in err and f"wrote {png}" in err


def test_plan_table_output(capsys):
    code, out, _ = run(capsys, "plan", str(DEMO))
    assert code == 0
    assert "Disassembly plan (feasible)" in out
    assert "pin_1" in out


def test_plan_of_a_missing_file_is_one_line_and_exit_2(capsys, tmp_path):
    code, out, err = run(capsys, "plan", str(tmp_path / "nothing.yaml"))
    assert code == 2
    assert out == ""
    assert err.count("\n") == 1 and "nothing.yaml" in err and "Traceback" not in err


def test_demo_writes_its_report(capsys, tmp_path):
    code, out, err = run(capsys, "demo", "--out", str(tmp_path / "demo"))
    assert code == 0, err
    report = tmp_path / "demo" / "gearbox_report.html"
    assert report.stat().st_size > 3_000_000
    assert "Disassembly plan (feasible)" in out
    assert "in a browser" in out and "gearbox_report.html" in out
    code, out, _ = run(capsys, "demo", "--out", str(tmp_path / "again"), "--json")
    data = json.loads(out)
    assert data["report"] == str((tmp_path / "again" / "gearbox_report.html").resolve())
    assert data["plan"]["feasible"] is True


def test_batch_command(capsys, tmp_path):
    out_file = tmp_path / "r.jsonl"
    code, out, err = run(capsys, "batch", str(DEMO), "--out", str(out_file), "--json")
    assert code == 0, err
    assert json.loads(out)["ok"] == 1
    record = json.loads(out_file.read_text())
    assert record["input"] == str(DEMO) and record["status"] == "ok"
    code, _, err = run(capsys, "batch", str(DEMO), "--command", "solve")
    assert code == 2 and "'solve' is not one of 'plan', 'motion'" in err


def test_batch_lists_a_missing_input_and_exits_2(capsys, tmp_path):
    out_file = tmp_path / "r.jsonl"
    missing = str(tmp_path / "nowhere.yaml")
    code, out, err = run(capsys, "batch", missing, "--out", str(out_file))
    assert code == 2
    assert "missing: " in out and "nowhere.yaml: no such file or folder" in out
    assert err.count("\n") == 1 and "not found" in err and "nowhere.yaml" in err
    assert not out_file.exists() or out_file.read_text() == ""


PLANAR = ROOT / "src" / "assemblykit" / "examples" / "planar"


def test_plan_of_a_polygon_file_is_planar(capsys):
    """The hook: the peg leaves along one direction of its free arc [atan(1/3), 45°]."""
    code, out, err = run(capsys, "plan", str(PLANAR / "hook.yaml"), "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["feasible"] is True
    (step,) = data["steps"]
    assert step["parts"] == ["peg"]
    x, y, z = step["direction"]
    assert z == 0.0 and math.atan(1 / 3) - 1e-9 <= math.atan2(y, x) <= math.pi / 4 + 1e-9
    code, _, err = run(capsys, "plan", str(PLANAR / "hook.yaml"), "--png", "x.png")
    assert code == 2 and "2D polygon" in err


@pytest.mark.parametrize("moves", ["multi", "rigid"])
@pytest.mark.parametrize(
    ("option", "said"),
    [
        (["--html", "r.html"], "--html and --png draw translation plans: not with --moves"),
        (["--png", "r.png"], "--html and --png draw translation plans: not with --moves"),
        (["--gravity", "-z"], "--max-steps plan translations: not with --moves"),
        (["--one-at-a-time"], "--max-steps plan translations: not with --moves"),
        (["--max-steps", "2"], "--max-steps plan translations: not with --moves"),
        (["--out", "p.json"], "--out and --gltf export translation plans: not with --moves"),
        (["--gltf", "p.glb"], "--out and --gltf export translation plans: not with --moves"),
    ],
)
def test_options_of_translation_plans_are_refused_by_the_other_modes(
    capsys, tmp_path, moves, option, said
):
    """Each option that only a plan of single translations takes is refused, in one
    line naming it and the mode, before anything is loaded or written."""
    args = [
        str(tmp_path / a) if a.endswith((".html", ".png", ".json", ".glb")) else a for a in option
    ]
    code, out, err = run(capsys, "plan", str(DEMO), "--moves", moves, *args)
    assert code == 2 and out == ""
    assert f"{said} {moves}" in err and len(err.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (["--moves", "multi"], "--moves multi moves 3D parts: not for a 2D polygon assembly"),
        (["--moves", "rigid"], "--moves rigid turns 3D parts: not for a 2D polygon assembly"),
        (["--gltf", "p.glb"], "--gltf draws meshes: not for a 2D polygon assembly"),
        (["--html", "r.html"], "--html and --png draw meshes: not for a 2D polygon assembly"),
    ],
)
def test_what_moves_or_draws_meshes_is_refused_for_polygons(capsys, tmp_path, args, said):
    args = [str(tmp_path / a) if "." in a else a for a in args]
    polygons = str(PLANAR / "hook.yaml")
    code, out, err = run(capsys, "plan", polygons, *args)
    assert code == 2 and out == ""
    assert said in err and "hook.yaml" in err and len(err.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def test_plan_reports_the_hands_a_planar_interlock_needs(capsys):
    code, out, err = run(capsys, "plan", str(PLANAR / "three_hands.yaml"), "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["feasible"] is False
    assert data["hands"]["needed"] == 3
    code, out, _ = run(
        capsys, "plan", str(PLANAR / "three_hands.yaml"), "--json", "--max-hands", "2"
    )
    two = json.loads(out)["hands"]
    # three parts in two hands: a third hand might take them apart
    assert two["needed"] is None and two["more_may_free"] is True
    code, _, err = run(capsys, "plan", str(PLANAR / "three_hands.yaml"), "--max-hands", "1")
    assert code == 2 and "--max-hands" in err


def _leaning_pair(folder: Path) -> Path:
    """A manifest of a ground slab, two pillars and two corbels leaning on each other
    (each alone would tip over its pillar's edge)."""
    import trimesh

    boxes = {
        "ground": ((6, 1, 1), (-3, 0, -1)),
        "pillar_l": ((1, 1, 1), (-2, 0, 0)),
        "pillar_r": ((1, 1, 1), (1, 0, 0)),
        "corbel_l": ((1.8, 1, 1), (-1.8, 0, 1)),
        "corbel_r": ((1.8, 1, 1), (0, 0, 1)),
    }
    entries = []
    for name, (extents, low) in boxes.items():
        mesh = trimesh.creation.box(extents=extents)
        mesh.apply_translation([lo + e / 2 for lo, e in zip(low, extents, strict=True)])
        mesh.export(folder / f"{name}.obj")
        entries.append(f"  - {{name: {name}, mesh: {name}.obj}}")
    manifest = folder / "pair.yaml"
    manifest.write_text("parts:\n" + "\n".join(entries) + "\n")
    return manifest


def test_plan_under_gravity_lists_holds_and_the_assembly_order(capsys, tmp_path):
    manifest = _leaning_pair(tmp_path)
    html = tmp_path / "pair.html"
    code, out, err = run(
        capsys,
        "plan",
        str(manifest),
        "--json",
        "--gravity",
        "--extra-holds",
        "1",
        "--html",
        str(html),
    )
    assert code == 0, err
    # the deprecated count of holds, the grip included, gives the same plan and says so
    code, again, said = run(capsys, "plan", str(manifest), "--json", "--gravity", "--holds", "2")
    assert code == 0 and json.loads(again) == json.loads(out)
    assert "--holds 2 is --extra-holds 1" in said
    page = html.read_text()
    assert "<h2>Assembly order</h2>" in page and "<th>stands</th>" in page
    data = json.loads(out)
    assert data["gravity"]["direction"] == [0.0, 0.0, -1.0]
    assert data["gravity"]["fixed"] == ["ground"] and data["gravity"]["stable"] is True
    first = data["steps"][0]
    assert {"parts", "direction", "motion", "held", "would_fall", "stability_margin"} <= set(first)
    assert set(first["held"]) == {"corbel_l", "corbel_r"}
    assert all(len(step["parts"]) == 1 for step in data["steps"])
    assert data["gravity"]["holds"] == 2 and data["gravity"]["extra_holds"] == 1
    last = data["assembly_steps"][-1]
    assert last["parts"] == first["parts"] and set(last["held"]) == set(first["held"])
    assert last["direction"] == [-x + 0.0 for x in first["direction"]]
    # each assembly step says whether it stands, as the step it reverses does
    stands = [step["stands"] for step in data["steps"]]
    assert [step["stands"] for step in data["assembly_steps"]] == stands[::-1]
    code, out, _ = run(capsys, "plan", str(manifest), "--gravity", "--extra-holds", "1")
    assert "no extra hold" not in out and "1 extra hold" in " ".join(out.split())
    assert "unheld" in out

    code, out, _ = run(capsys, "plan", str(manifest), "--gravity", "0,0,-1", "--friction", "0.05")
    assert code == 0
    assert "Assembly order" in out and "some states fall" in out
    code, out, _ = run(capsys, "plan", str(manifest), "--json", "--gravity=+x")
    assert json.loads(out)["gravity"]["direction"] == [1.0, 0.0, 0.0]
    # a direction starting with a minus is a value, not an option
    for given in (["--gravity", "-y"], ["--gravity=-y"], ["--gravity", "0,-1,0"]):
        code, out, err = run(capsys, "plan", str(manifest), "--json", *given)
        assert code == 0, err
        assert json.loads(out)["gravity"]["direction"] == [0.0, -1.0, 0.0]


@pytest.mark.parametrize(
    ("option", "named"),
    [
        (["--gravity=up"], "--gravity"),
        (["--gravity", "--fixed", "nothing"], "nothing"),
        (["--gravity", "--friction", "-1"], "--friction"),
    ],
)
def test_bad_gravity_options_are_one_line_and_exit_2(capsys, tmp_path, option, named):
    manifest = _leaning_pair(tmp_path)
    code, out, err = run(capsys, "plan", str(manifest), *option)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and named in err and "Traceback" not in err


def test_no_holds_at_all_is_bad_input(capsys, tmp_path):
    manifest = str(_leaning_pair(tmp_path))
    code, _, err = run(capsys, "plan", manifest, "--gravity", "--holds", "0")
    assert code == 2 and "--holds" in err
    code, _, err = run(capsys, "plan", manifest, "--gravity", "--extra-holds", "-1")
    assert code == 2 and "--extra-holds: -1 must be at least 0" in err
    code, _, err = run(capsys, "plan", manifest, "--gravity", "--extra-holds", "1", "--holds", "2")
    assert code == 2 and "give --extra-holds alone" in err


def test_a_step_along_an_axis_names_it_and_keeps_the_exact_vector(capsys):
    code, out, err = run(capsys, "plan", str(DEMO), "--json")
    assert code == 0, err
    data = json.loads(out)
    for step in data["steps"] + data["assembly_steps"]:
        direction = np.array(step["direction"])
        axis = np.argmax(np.abs(direction))
        along = np.abs(direction[axis]) > 1 - 1e-9
        expected = ("+" if direction[axis] > 0 else "-") + "XYZ"[axis] if along else None
        assert step["axis"] == expected
    assert data["steps"][0]["axis"] == "+Z"


@pytest.fixture(scope="module")
def demo_plan() -> dict:
    """The whole plan of the demo gearbox, as ``plan --json`` prints it."""
    from assemblykit.cli import main

    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        try:
            main(["plan", str(DEMO), "--json"])
        except SystemExit as done:
            assert not done.code
    return json.loads(printed.getvalue())


@pytest.mark.parametrize("limit", [0, 1, 2])
def test_a_plan_stopped_at_its_step_limit_is_the_whole_plans_prefix(capsys, demo_plan, limit):
    whole = demo_plan
    code, out, err = run(capsys, "plan", str(DEMO), "--max-steps", str(limit), "--json")
    assert code == 0, err
    prefix = json.loads(out)
    assert prefix["steps"] == whole["steps"][:limit]
    assert not prefix["feasible"] and prefix["stuck"] == [] and whole["unfinished"] == []
    left = whole["parts"] if limit == 0 else whole["steps"][limit - 1]["rest"]
    assert sorted(prefix["unfinished"]) == sorted(left)


def test_an_assembly_that_does_not_stand_as_given_is_step_0(capsys, tmp_path):
    # a unit cube on a unit cube, its centre 0.1 beyond the lower one's edge: it tips
    # over before anything is moved (no friction holds it)
    import trimesh

    folder = tmp_path / "tipping"
    folder.mkdir()
    for name, low in (("bottom", (0.0, 0.0, 0.0)), ("top", (0.6, 0.0, 1.0))):
        mesh = trimesh.creation.box(extents=(1, 1, 1))
        mesh.apply_translation([c + 0.5 for c in low])
        mesh.export(folder / f"{name}.obj")
    code, out, err = run(capsys, "plan", str(folder), "--gravity", "--json")
    assert code == 0, err
    gravity = json.loads(out)["gravity"]
    assert gravity["stands"] is False and gravity["would_fall"] == ["top"]
    assert gravity["tips"] is True and gravity["friction_needed"] is None
    page = tmp_path / "tipping.html"
    code, out, err = run(capsys, "plan", str(folder), "--gravity", "--html", str(page))
    assert code == 0, err
    first = next(line for line in out.splitlines() if line.startswith("│ 0 "))
    assert "as given" in first and "top" in first and "tips" in first
    shown = page.read_text()
    assert "<td>0</td><td>-</td><td>-</td><td>as given</td>" in shown
    assert "<th>would fall unheld</th>" in shown and "<td>tips</td>" in shown
