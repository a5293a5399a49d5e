"""Files of 2D polygons: ``parts: {name: [[x, y], ...]}`` read into counter-clockwise
polygons, every fault named by file and part, and told apart from assembly manifests."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from assemblykit.errors import GeometryError, InputError, SchemaError
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.io.polygons import is_polygon_file, load_polygons

PLANAR = Path(__file__).resolve().parents[2] / "src" / "assemblykit" / "examples" / "planar"


def write(folder: Path, text: str, name: str = "p.yaml") -> Path:
    path = folder / name
    path.write_text(text)
    return path


def test_polygons_are_read_counter_clockwise_in_file_order(tmp_path):
    # b is written clockwise; both come back counter-clockwise with the same vertices
    path = write(
        tmp_path,
        "parts:\n  b: [[0, 1], [0, 2], [2, 2], [2, 1]]\n  a: [[0, 0], [2, 0], [2, 1], [0, 1]]\n",
    )
    model = load_polygons(path)
    assert model.names == ["b", "a"] and model.source == str(path)
    for name, area in (("a", 2.0), ("b", 2.0)):
        x, y = model.polygons[name][:, 0], model.polygons[name][:, 1]
        assert 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) == area
    assert {tuple(p) for p in model.polygons["b"]} == {(0, 1), (0, 2), (2, 2), (2, 1)}
    # the two share the edge y = 1 from x = 0 to 2: one contact of length 2, its normal
    # from b (above) into a (below)
    (contact,) = assembly_contacts(model)
    assert (contact.a, contact.b) == ("b", "a")
    (patch,) = contact.planar
    assert patch.area == 2.0
    assert patch.normal.tolist() == [0.0, -1.0, 0.0]
    assert sorted(patch.polygon.tolist()) == [[0.0, 1.0, 0.0], [2.0, 1.0, 0.0]]


@pytest.mark.parametrize(
    ("text", "error", "where"),
    [
        ("parts: [a, b]\n", SchemaError, "parts"),
        ("parts:\n  a: [[0, 0], [1, 0]]\n", SchemaError, "parts.a"),
        ("parts:\n  a: [[0, 0], [1, true], [0, 1]]\n", SchemaError, "parts.a"),
        ("parts:\n  a: [[0, 0], [1, .inf], [0, 1]]\n", SchemaError, "parts.a"),
        ("parts:\n  a: [[0, 0], [1, 0, 3], [0, 1]]\n", SchemaError, "parts.a"),
        ("parts:\n  tie: [[0, 0], [1, 1], [1, 0], [0, 1]]\n", GeometryError, "parts.tie"),
    ],
)
def test_faults_name_the_file_and_the_part(tmp_path, text, error, where):
    path = write(tmp_path, text)
    with pytest.raises(error) as raised:
        load_polygons(path)
    assert str(path) in str(raised.value) and where in str(raised.value)


def test_a_file_that_is_not_utf8_is_refused_by_name(tmp_path):
    path = tmp_path / "p.yaml"
    path.write_bytes("parts: {} # caf\u00e9\n".encode("latin-1"))
    with pytest.raises(InputError, match="not UTF-8"):
        load_polygons(path)


def test_polygon_files_are_told_from_manifests(tmp_path):
    assert is_polygon_file(PLANAR / "hook.yaml")
    assert not is_polygon_file(write(tmp_path, "parts:\n  - {name: a, mesh: a.obj}\n", "m.yaml"))
    assert not is_polygon_file(write(tmp_path, "parts: {}\n", "p.json"))
    assert not is_polygon_file(tmp_path / "missing.yaml")
    assert not is_polygon_file(write(tmp_path, "parts: [", "broken.yaml"))
