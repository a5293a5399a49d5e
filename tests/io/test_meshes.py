"""Mesh folders and manifests: poses (ASAP final_state, 4x4, translation + Euler degrees),
units, repairs and rejection of bad meshes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import trimesh

from assemblykit.errors import GeometryError, SchemaError
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.geometry.interference import (
    interferences,
    overlap_volume,
    part_solid,
    shared_volume,
    solid,
)
from assemblykit.io.assembly import load_assembly
from assemblykit.io.meshes import load_manifest, pose_from_spec, pose_from_state, read_mesh
from assemblykit.tolerance import DEFAULT
from datasets import BUNDLED, dataset, shared_assembly

ASAP = BUNDLED / "asap_beam_assembly"
STATES = {k: v["final_state"] for k, v in json.loads((ASAP / "config.json").read_text()).items()}


def unit_box(folder: Path, name: str) -> Path:
    path = folder / name
    trimesh.creation.box(extents=[1, 1, 1]).export(path)
    return path


def test_pose_from_state_is_translation_after_xyz_euler_radians():
    pose = pose_from_state([1, 2, 3, 0, 0, np.pi / 2])
    np.testing.assert_allclose(pose @ [1, 0, 0, 1], [1, 3, 3, 1], atol=1e-12)


def test_folder_applies_config_final_state(tmp_path):
    unit_box(tmp_path, "a.stl")
    unit_box(tmp_path, "b.obj")
    (tmp_path / "config.json").write_text(json.dumps({"b": {"final_state": [0, 0, 1, 0, 0, 0.5]}}))
    asm = load_assembly(tmp_path)
    assert asm.names == ["a", "b"]
    np.testing.assert_allclose(asm["a"].pose, np.eye(4))
    assert asm["b"].mesh.bounds[0][2] == pytest.approx(0.5)
    assert asm["b"].mesh.volume == pytest.approx(1.0)
    assert (asm.units, asm.units_source) == ("mm", "default")
    assert [c.pair for c in assembly_contacts(asm)] == [("a", "b")]


def test_manifest_poses_units_and_relative_paths(tmp_path):
    (tmp_path / "meshes").mkdir()
    unit_box(tmp_path / "meshes", "cube.ply")
    (tmp_path / "asm.yaml").write_text(
        "units: in\n"
        "parts:\n"
        "  - {name: base, mesh: meshes/cube.ply}\n"
        "  - name: lid\n    mesh: meshes/cube.ply\n"
        "    pose: {translation: [0, 0, 1], rotation_xyz_deg: [0, 0, 90]}\n"
        "  - name: side\n    mesh: meshes/cube.ply\n"
        "    pose: [[1, 0, 0, 1], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n"
    )
    asm = load_manifest(tmp_path / "asm.yaml")
    assert (asm.units, asm.units_source) == ("in", "declared")
    np.testing.assert_allclose(
        asm["lid"].pose[:3, :3], [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-12
    )
    assert asm["side"].mesh.bounds[0][0] == pytest.approx(0.5)
    assert {c.pair for c in assembly_contacts(asm)} == {("base", "lid"), ("base", "side")}


def test_pose_spec_rejects_non_rigid_matrix():
    with pytest.raises(SchemaError, match=r"parts\[0\]\.pose"):
        pose_from_spec(
            [[2, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]],
            where="parts[0].pose",
            tol=DEFAULT,
        )


def test_manifest_with_missing_mesh_names_the_file(tmp_path):
    (tmp_path / "m.yaml").write_text("parts:\n  - {name: a, mesh: nowhere.stl}\n")
    with pytest.raises(GeometryError, match=r"nowhere\.stl"):
        load_assembly(tmp_path / "m.yaml")


def test_empty_folder_is_rejected(tmp_path):
    with pytest.raises(GeometryError, match="no mesh files"):
        load_assembly(tmp_path)


def test_nan_vertices_are_rejected_naming_the_file(tmp_path):
    path = tmp_path / "bad.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv nan 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n")
    with pytest.raises(GeometryError, match=r"bad\.obj.*NaN"):
        read_mesh(path)


def test_duplicate_and_degenerate_faces_are_repaired(tmp_path):
    cube = trimesh.creation.box(extents=[1, 1, 1])
    faces = np.vstack([cube.faces, cube.faces[:1], [[0, 0, 1]]])
    path = tmp_path / "messy.ply"
    trimesh.Trimesh(cube.vertices, faces, process=False).export(path)
    mesh = read_mesh(path)
    assert len(mesh.faces) == 12 and mesh.is_watertight
    assert mesh.volume == pytest.approx(1.0)


def test_open_mesh_that_cannot_be_closed_is_rejected(tmp_path):
    cube = trimesh.creation.box(extents=[1, 1, 1])
    path = tmp_path / "open.stl"
    trimesh.Trimesh(cube.vertices, cube.faces[:6], process=False).export(path)  # half a box
    with pytest.raises(GeometryError, match=r"open\.stl"):
        read_mesh(path)


def _open_box(folder: Path, name: str, missing: list[int]) -> Path:
    """A unit box (corner at the origin) with the faces ``missing`` left out."""
    cube = trimesh.creation.box(bounds=[[0, 0, 0], [1, 1, 1]])
    kept = np.delete(cube.faces, missing, axis=0)
    path = folder / name
    trimesh.Trimesh(cube.vertices, kept, process=False).export(path)
    return path


def test_a_box_missing_one_side_is_closed_and_the_repair_said(tmp_path):
    # the two triangles of one side gone: a quad hole, which fill_holes closes exactly
    cube = trimesh.creation.box(bounds=[[0, 0, 0], [1, 1, 1]])
    side = np.flatnonzero(np.isclose(cube.triangles_center[:, 0], 1.0))
    assert len(side) == 2
    path = _open_box(tmp_path, "lid.stl", side.tolist())
    asm = load_assembly(path)
    assert asm["lid"].mesh.is_watertight and asm["lid"].volume == pytest.approx(1.0, abs=1e-12)
    (note,) = asm.warnings
    assert "lid.stl" in note and "4 edges bordered holes" in note and "filled" in note
    # the same file in a folder and in a manifest says so too
    (tmp_path / "parts.yaml").write_text("parts:\n  - {name: lid, mesh: lid.stl}\n")
    assert load_assembly(tmp_path / "parts.yaml").warnings == (note,)
    assert load_assembly(tmp_path).warnings == (note,)


def test_a_box_missing_a_side_and_a_half_is_refused_with_its_holes(tmp_path):
    # three triangles gone from two sides: a hole bent over the box's edge, which no
    # exact repair closes
    cube = trimesh.creation.box(bounds=[[0, 0, 0], [1, 1, 1]])
    side = np.flatnonzero(np.isclose(cube.triangles_center[:, 0], 1.0)).tolist()
    top = np.flatnonzero(np.isclose(cube.triangles_center[:, 2], 1.0)).tolist()
    path = _open_box(tmp_path, "broken.stl", [*side, top[0]])
    with pytest.raises(GeometryError, match=r"broken\.stl.*edges border holes that are not flat"):
        read_mesh(path)


def edge_piece(path: Path) -> Path:
    """Two unit cubes sharing only the edge x = y = 1, written as one mesh (its vertices
    on that edge shared: four faces meet there)."""
    first = trimesh.creation.box(bounds=[[0, 0, 0], [1, 1, 1]])
    second = trimesh.creation.box(bounds=[[1, 1, 0], [2, 2, 1]])
    trimesh.util.concatenate([first, second]).export(path)
    merged = trimesh.load(path, force="mesh")
    assert not merged.is_watertight  # as trimesh reads it: a non-manifold edge
    return path


def test_solids_meeting_along_an_edge_load_as_one_piece(tmp_path):
    piece = read_mesh(edge_piece(tmp_path / "piece.obj"))
    assert piece.is_watertight
    assert piece.volume == pytest.approx(2.0, abs=1e-12)
    assert piece.body_count == 2


def test_contacts_and_blocking_of_a_piece_with_cubes_meeting_along_an_edge(tmp_path):
    from assemblykit.blocking.graphs import blocking_graph

    edge_piece(tmp_path / "piece.obj")
    trimesh.creation.box(bounds=[[0, 0, 1], [1, 1, 2]]).export(tmp_path / "lid.stl")
    asm = load_assembly(tmp_path)
    assert asm.parts["piece"].volume == pytest.approx(2.0, abs=1e-12)
    # the lid lies on the first cube: one unit square of contact, normal +z
    (contact,) = assembly_contacts(asm)
    assert contact.pair == ("lid", "piece")
    assert sum(p.area for p in contact.planar) == pytest.approx(1.0)
    ndbg = blocking_graph(asm, "extended")
    assert ndbg.dbg([0, 0, 1]).arcs == {("piece", "lid")}
    assert ndbg.dbg([0, 0, -1]).arcs == {("lid", "piece")}
    # sliding along +x the lid passes over the second cube (touching, not blocked)
    assert ndbg.dbg([1, 0, 0]).arcs == set()


def test_open_sheets_meeting_along_an_edge_are_still_rejected(tmp_path):
    # the two cubes of the edge piece, each cut in half: open, and the file is named
    first = trimesh.creation.box(bounds=[[0, 0, 0], [1, 1, 1]])
    second = trimesh.creation.box(bounds=[[1, 1, 0], [2, 2, 1]])
    both = trimesh.util.concatenate([first, second])
    path = tmp_path / "holed.stl"
    # half of each box, as in the half box above: holes too big to fill
    keep = [*range(6), *range(12, 18)]
    trimesh.Trimesh(both.vertices, both.faces[keep], process=False).export(path)
    with pytest.raises(GeometryError, match=r"holed\.stl"):
        read_mesh(path)


def test_asap_beam_touches_without_interfering_with_final_state_poses():
    asm = shared_assembly("asap_beam_assembly")
    assert asm.names == ["0", "1", "2", "3", "6"]
    # translation after Rotation.from_euler('xyz') of the mesh as read: beams on posts
    assert {c.pair for c in assembly_contacts(asm)} == {
        ("0", "2"),
        ("1", "3"),
        ("2", "6"),
        ("3", "6"),
    }
    assert interferences(asm) == []
    # final_state is rounded to 4 decimals (translations) and 6 (angles): a vertex may be
    # misplaced by sqrt(3) (5e-5 + r 5e-7), r up to 7.76 (part 6): 9.3e-5
    assert asm.precision.length == pytest.approx(9.3257e-5, rel=1e-4)
    assert asm.tolerance_summary()["from"] == "measured"
    # settled within that rounding, the parts share at most 1e-6 of a part's volume
    for (a, b), area in {c.pair: c.area for c in assembly_contacts(asm)}.items():
        assert overlap_volume(asm[a].mesh, asm[b].mesh) <= 1e-6 * min(asm[a].volume, asm[b].volume)
        # still touching: the same 3.82 of seat and tenon area as the poses as written
        assert area == pytest.approx(3.8233, abs=1e-4)
    for part in asm:
        assert part.settled is not None
        assert 0 < np.linalg.norm(part.settled) <= asm.precision.length
        assert part.pose[:3, 3] - pose_from_state(STATES[part.name])[:3, 3] == pytest.approx(
            part.settled, abs=1e-12
        )
    assert asm.to_dict()["parts"]["2"]["settled"] == list(asm["2"].settled)


def test_the_solids_kept_by_the_loader_are_the_settled_parts():
    # the loader settles with manifold3d solids and keeps them, moved as the parts were:
    # each is the solid of its part's mesh as the assembly holds it, in a sub-assembly too
    asm = shared_assembly("asap_beam_assembly")
    for sub in (asm, asm.subset(["0", "2"])):
        for name in sub.names:
            kept = part_solid(sub, name)
            made = solid(sub[name].mesh)
            assert kept.volume() == pytest.approx(made.volume(), rel=1e-12)
            np.testing.assert_allclose(kept.bounding_box(), made.bounding_box(), atol=1e-12)
            assert shared_volume(kept, made) == pytest.approx(made.volume(), rel=1e-9)


def test_asap_beam_as_written_shares_thin_layers():
    asm = load_assembly(dataset("asap_beam_assembly"), settle=False)
    assert all(part.settled is None for part in asm)
    assert interferences(asm) == []
    # The poses as written leave layers thinner than their rounding (docs/geometry.md):
    # 2.5e-6 to 4.3e-6 of the smaller part's volume
    areas = {c.pair: c.area for c in assembly_contacts(asm)}
    shares = []
    for (a, b), area in areas.items():
        volume = overlap_volume(asm[a].mesh, asm[b].mesh)
        shares.append(volume / min(asm[a].volume, asm[b].volume))
        assert volume / area <= asm.precision.length
    assert min(shares) == pytest.approx(2.47e-6, rel=0.01)
    assert max(shares) == pytest.approx(4.30e-6, rel=0.01)
