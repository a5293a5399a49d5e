"""Plan exports (io/exports.py): ``plan --out`` (CSV, JSON) and ``plan --gltf``, written
by the command line and read back (the glTF with trimesh)."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import trimesh

from assemblykit.io.exports import CSV_COLUMNS, write_gltf, write_plan
from assemblykit.planning.sequence import Plan, Step
from assemblykit.viz.viewer import part_colors
from cli_runs import run
from datasets import shared_assembly

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "src" / "assemblykit" / "examples" / "gearbox_demo" / "gearbox.yaml"
UP = np.array([0.0, 0.0, 1.0])


def test_plan_writes_the_step_table_and_the_exploded_gltf(capsys, tmp_path):
    table, scene = tmp_path / "plan.csv", tmp_path / "exploded.glb"
    code, out, err = run(
        capsys, "plan", str(DEMO), "--json", "--out", str(table), "--gltf", str(scene)
    )
    assert code == 0, err
    steps = json.loads(out)["steps"]
    with table.open(newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    assert tuple(rows[0]) == CSV_COLUMNS
    assert [r["parts"].split(";") for r in rows] == [s["parts"] for s in steps]
    assert [int(r["assembly_order"]) for r in rows] == list(range(len(steps), 0, -1))
    first = rows[0]
    assert first["parts"] == "cover;pin_1;pin_2;pin_3;pin_4" and first["direction"] == "+Z"
    assert (first["dx"], first["dy"], first["dz"]) == ("0.0", "0.0", "1.0")
    assert int(first["away_from_count"]) == len(first["away_from"].split(";")) == 9

    loaded = trimesh.load(scene)
    assert isinstance(loaded, trimesh.Scene)
    assert sorted(loaded.geometry) == sorted(shared_assembly(DEMO).names)
    assert loaded.metadata["plan"]["order"][0] == steps[-1]["parts"]
    # the base never moves; the cover, removed first along +z, carries every later
    # step's move: 1.25 x the extent of each step's parts along its direction
    assembly = shared_assembly(DEMO)
    travel = 0.0
    for step in steps:
        d = np.asarray(step["direction"])
        heights = np.concatenate([assembly[n].mesh.vertices @ d for n in step["parts"]])
        travel += max(1.25 * (heights.max() - heights.min()), 0.03 * assembly.scale)
    assert np.allclose(loaded.graph["base"][0][:3, 3], 0)
    assert np.allclose(loaded.graph["cover"][0][:3, 3], [0, 0, travel])


def test_bad_export_names_are_refused_before_planning(capsys, tmp_path):
    code, _, err = run(capsys, "plan", str(DEMO), "--out", str(tmp_path / "plan.txt"))
    assert code == 2 and "--out" in err and "'.txt'" in err
    code, _, err = run(capsys, "plan", str(DEMO), "--gltf", str(tmp_path / "x.obj"))
    assert code == 2 and "--gltf" in err


def test_json_export_is_the_plan_json_and_gltf_text_reads_back(tmp_path):
    assembly = shared_assembly(DEMO)
    step = Step(("plug",), np.array([1.0, 6e-17, 0.0]), ("base", "housing"), ())
    plan = Plan(tuple(assembly.names), (step,), (), None, 2)
    data = json.loads(write_plan(plan, tmp_path / "p.json").read_text(encoding="utf-8"))
    assert data["steps"][0]["direction"] == [1.0, 0.0, 0.0]
    assert data["steps"][0]["direction_label"] == "+X"  # beside the vector, in words
    assert data["assembly_steps"][0]["direction_label"] == "-X"
    assert data["order"] == [["plug"]] and data["feasible"] is True
    loaded = trimesh.load(write_gltf(assembly, plan, tmp_path / "x.gltf"))
    assert len(loaded.geometry) == 14
    # the plug leaves along +x by 1.25 x its length (x from 60 to 70)
    assert np.allclose(loaded.graph["plug"][0][:3, 3], [12.5, 0, 0])


def test_each_part_of_the_gltf_scene_has_the_colour_of_the_report_legend(tmp_path):
    assembly = shared_assembly(DEMO)
    step = Step(("cover",), UP, ("base", "housing"), ())
    plan = Plan(tuple(assembly.names), (step,), (), None, 2)
    legend = part_colors(assembly.names)
    assert (legend["cover"], legend["gear_a"], legend["housing"]) == (
        "#00CC96",  # green
        "#FECB52",  # yellow
        "#EF553B",  # red
    )
    for suffix in (".glb", ".gltf"):
        loaded = trimesh.load(write_gltf(assembly, plan, tmp_path / f"x{suffix}"))
        for name, color in legend.items():
            material = loaded.geometry[name].visual.material
            red, green, blue = (int(color[i : i + 2], 16) for i in (1, 3, 5))
            assert list(material.baseColorFactor) == [red, green, blue, 255], (suffix, name)
            assert material.metallicFactor == 0.0
