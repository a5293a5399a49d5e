"""The ``assemblykit contacts`` command: JSON, PNG, and one-line errors (exit 2)."""

from __future__ import annotations

import json
import re

import pytest
import trimesh

from assemblykit.cli import main


def run(args, capsys):
    with pytest.raises(SystemExit) as done:
        main(args)
    out, err = capsys.readouterr()
    return done.value.code, out, err


@pytest.fixture
def tower(tmp_path):
    for i in range(2):
        mesh = trimesh.creation.box(extents=[1, 1, 1])
        mesh.apply_translation([0, 0, i])
        mesh.export(tmp_path / f"block{i}.stl")
    return tmp_path


def test_json_lists_parts_contacts_features_and_interferences(tower, capsys, tmp_path):
    png = tmp_path / "view.png"
    main(["contacts", str(tower), "--json", "--png", str(png)])
    data = json.loads(capsys.readouterr().out)
    assert list(data["parts"]) == ["block0", "block1"]
    assert [f["type"] for f in data["parts"]["block0"]["features"]] == ["plane"] * 6
    (contact,) = data["contacts"]
    assert (contact["a"], contact["b"]) == ("block0", "block1")
    assert contact["area"] == pytest.approx(1.0)
    assert contact["planar"][0]["normal"] == pytest.approx([0, 0, 1])
    assert data["interferences"] == []
    tolerance = data["tolerance"]
    assert tolerance["from"] == "policy" and tolerance["relative"] == pytest.approx(1e-6)
    assert tolerance["length"] == pytest.approx(1e-6 * 6**0.5)  # diagonal of 1 x 1 x 2
    assert tolerance["measured_from"] == "float32 coordinates"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_text_output_names_the_contact(tower, capsys):
    main(["contacts", str(tower)])
    out = capsys.readouterr().out
    assert re.search(r"\b1 contact\b", out) and "block1" in out


def test_interference_is_reported_with_its_volume(tmp_path, capsys):
    trimesh.creation.box(extents=[1, 1, 1]).export(tmp_path / "a.stl")
    sunk = trimesh.creation.box(extents=[1, 1, 1])
    sunk.apply_translation([0, 0, 0.5])
    sunk.export(tmp_path / "b.stl")
    main(["contacts", str(tmp_path), "--json"])
    (clash,) = json.loads(capsys.readouterr().out)["interferences"]
    assert (clash["a"], clash["b"]) == ("a", "b")
    assert clash["volume"] == pytest.approx(0.5)


@pytest.mark.parametrize("kind", ["missing", "step", "empty", "nan"])
def test_bad_input_exits_2_with_one_line_naming_the_file(kind, tmp_path, capsys):
    if kind == "missing":
        (tmp_path / "m.yaml").write_text("parts:\n  - {name: a, mesh: gone.obj}\n")
        target, named = tmp_path / "m.yaml", "gone.obj"
    elif kind == "step":
        target = named = tmp_path / "broken.step"
        target.write_text("garbage")
    elif kind == "empty":
        target = named = tmp_path / "nothing"
        target.mkdir()
    else:
        target = tmp_path / "asm"
        target.mkdir()
        (target / "nan.obj").write_text(
            "v 0 0 0\nv 1 0 0\nv 0 nan 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n"
        )
        named = "nan.obj"
    code, out, err = run(["contacts", str(target)], capsys)
    assert code == 2
    assert out == ""
    assert len(err.strip().splitlines()) == 1 and str(named) in err.replace("\n", "")


def test_rounded_poses_are_settled_unless_kept_as_written(tmp_path, capsys):
    # block b was meant to sit on a at z = 1; its pose, written to 4 decimals, sinks it
    # 1e-4 into a: deeper than the tolerance (the 8.7e-5 the rounding allows)
    trimesh.creation.box(extents=[1, 1, 1]).export(tmp_path / "a.stl")
    trimesh.creation.box(extents=[1, 1, 1]).export(tmp_path / "b.stl")
    states = {"a": [0, 0, 0, 0, 0, 0], "b": [0, 0, 0.9999, 0, 0, 0]}
    (tmp_path / "config.json").write_text(
        json.dumps({k: {"final_state": v} for k, v in states.items()})
    )
    main(["contacts", str(tmp_path), "--json"])
    out = capsys.readouterr().out
    parts = json.loads(out)["parts"]
    # each moves half the layer, a down and b up, and they touch
    assert parts["a"]["settled"] == pytest.approx([0, 0, -5e-5], abs=1e-9)
    assert parts["b"]["settled"] == pytest.approx([0, 0, 5e-5], abs=1e-9)
    assert [(c["a"], c["b"]) for c in json.loads(out)["contacts"]] == [("a", "b")]
    main(["contacts", str(tmp_path), "--json", "--as-written"])
    data = json.loads(capsys.readouterr().out)
    assert [p["settled"] for p in data["parts"].values()] == [None, None]
    # as written they neither touch within the tolerance nor interfere
    assert data["contacts"] == []
    assert data["interferences"] == []
