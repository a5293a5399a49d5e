"""COMPAS JSON: assemblies (COMPAS 1 and 2 layouts) and plain lists of block meshes."""

from __future__ import annotations

import json

import pytest

from assemblykit.errors import SchemaError
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.io.assembly import load_assembly
from assemblykit.io.compas import load_compas
from compas_documents import box_mesh
from datasets import dataset

CUBE = box_mesh((0, 0, 0), (1, 1, 1))


def lifted(dz: float) -> dict:
    return {
        "vertex": {k: {**v, "z": v["z"] + dz} for k, v in CUBE["vertex"].items()},
        "face": CUBE["face"],
    }


def test_compas2_assembly_blocks_become_parts(tmp_path):
    doc = {
        "dtype": "compas_assembly.datastructures/Assembly",
        "data": {
            "graph": {
                "dtype": "compas.datastructures/Graph",
                "data": {
                    "node": {
                        "7": {
                            "block": {"dtype": "compas_assembly.datastructures/Block", "data": CUBE}
                        },
                        "9": {
                            "block": {
                                "dtype": "compas_assembly.datastructures/Block",
                                "data": lifted(1),
                            }
                        },
                    }
                },
            }
        },
    }
    path = tmp_path / "a.json"
    path.write_text(json.dumps(doc))
    asm = load_assembly(path)
    assert asm.names == ["7", "9"]
    assert asm["7"].volume == pytest.approx(1.0)
    assert [(c.pair, c.area) for c in assembly_contacts(asm)] == [(("7", "9"), pytest.approx(1.0))]


def test_compas1_list_of_meshes(tmp_path):
    doc = [
        {"dtype": "compas.datastructures/Mesh", "value": {"data": CUBE}},
        {"dtype": "compas.datastructures/Mesh", "value": lifted(2)},
    ]
    path = tmp_path / "list.json"
    path.write_text(json.dumps(doc))
    asm = load_compas(path)
    assert asm.names == ["0", "1"] and assembly_contacts(asm) == []


def test_malformed_block_names_the_field(tmp_path):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps([{"dtype": "compas.datastructures/Mesh", "value": {"vertex": {}}}]))
    with pytest.raises(SchemaError, match=r"bad\.json: \[0\]"):
        load_compas(path)


@pytest.mark.parametrize(
    "name, count",
    [
        ("stack_assembly.json", 10),
        ("crossvault.json", 184),
        ("armadillo.json", 399),
        ("armadillo_interfaces.json", 399),
    ],
)
def test_published_files_load(name, count):
    asm = load_compas(dataset(f"compas_assembly/{name}"))
    assert len(asm) == count
    assert all(p.mesh.is_watertight for p in asm)
