"""Contacts between parts: planar patches (exact polygons and areas on hand-made boxes),
curved contacts (a shaft in a hole), and agreement with compas_assembly's interfaces."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import shapely
import trimesh

from assemblykit.geometry.contacts import (
    assembly_contacts,
    assembly_curved_surfaces,
    assembly_surfaces,
    find_contacts,
    near_curved_surfaces,
)
from assemblykit.io.compas import load_compas
from assemblykit.model.assembly import Assembly, Part
from assemblykit.tolerance import Tolerance
from datasets import dataset


def box(lo, hi) -> trimesh.Trimesh:
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return trimesh.creation.box(
        extents=hi - lo, transform=trimesh.transformations.translation_matrix((lo + hi) / 2)
    )


def assembly(**meshes: trimesh.Trimesh) -> Assembly:
    return Assembly([Part(name, mesh) for name, mesh in meshes.items()])


def test_box_on_box_gives_the_full_square_with_normal_from_a_into_b():
    found = find_contacts(assembly(a=box([0, 0, 0], [1, 1, 1]), b=box([0, 0, 1], [1, 1, 2])))
    assert [c.pair for c in found] == [("a", "b")]
    (patch,) = found[0].planar
    assert patch.area == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(patch.normal, [0, 0, 1], atol=1e-12)
    corners = {tuple(np.round(p, 12)) for p in patch.polygon}
    assert corners == {(0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)}
    # counter-clockwise seen from the tip of the normal
    xy = patch.polygon[:, :2]
    signed = 0.5 * np.sum(xy[:, 0] * np.roll(xy[:, 1], -1) - np.roll(xy[:, 0], -1) * xy[:, 1])
    assert signed == pytest.approx(1.0)


def test_box_offset_by_half_touches_on_half_the_face():
    found = find_contacts(assembly(a=box([0, 0, 0], [1, 1, 1]), b=box([0.5, 0, 1], [1.5, 1, 2])))
    (patch,) = found[0].planar
    assert patch.area == pytest.approx(0.5, abs=1e-12)
    assert shapely.Polygon(patch.polygon[:, :2]).equals(shapely.box(0.5, 0, 1, 1))


def test_normal_points_from_the_first_part_into_the_second():
    found = find_contacts(assembly(top=box([0, 0, 1], [1, 1, 2]), bottom=box([0, 0, 0], [1, 1, 1])))
    np.testing.assert_allclose(found[0].planar[0].normal, [0, 0, -1], atol=1e-12)
    assert found[0].pair == ("top", "bottom")


def test_edge_contact_gap_and_same_side_faces_are_not_contacts():
    parts = assembly(
        a=box([0, 0, 0], [1, 1, 1]),
        edge=box([1, 1, 0], [2, 2, 1]),  # shares only an edge line with a
        gap=box([0, 0, 1.001], [1, 1, 2]),  # a thousandth above a
        side=box([3, 0, 0], [4, 1, 1]),
    )
    assert find_contacts(parts) == []


def test_side_by_side_boxes_and_a_t_junction():
    found = find_contacts(
        assembly(
            a=box([0, 0, 0], [2, 1, 1]),
            b=box([2, 0, 0], [3, 1, 1]),
            c=box([0.5, 0, 1], [1.5, 1, 2]),
        )
    )
    areas = {c.pair: c.area for c in found}
    assert areas == pytest.approx({("a", "b"): 1.0, ("a", "c"): 1.0})
    np.testing.assert_allclose(found[0].planar[0].normal, [1, 0, 0], atol=1e-12)


def test_only_restricts_to_the_contacts_of_one_part():
    parts = assembly(
        a=box([0, 0, 0], [1, 1, 1]), b=box([0, 0, 1], [1, 1, 2]), c=box([0, 0, 2], [1, 1, 3])
    )
    assert [c.pair for c in find_contacts(parts)] == [("a", "b"), ("b", "c")]
    assert [c.pair for c in find_contacts(parts, only="c")] == [("b", "c")]


def test_shaft_in_a_hole_from_meshes_is_a_cylindrical_contact():
    radius, sections = 1.0, 48
    shaft = trimesh.creation.cylinder(radius=radius, height=6.0, sections=sections)
    cutter = trimesh.creation.cylinder(radius=radius, height=10.0, sections=sections)
    plate = box([-3, -3, -1], [3, 3, 1]).difference(cutter, engine="manifold")
    found = find_contacts(assembly(plate=plate, shaft=shaft))
    assert [c.pair for c in found] == [("plate", "shaft")]
    (curved,) = found[0].curved
    assert curved.kind == "cylindrical"
    assert curved.inner == "shaft"
    assert curved.radius == pytest.approx(radius, abs=1e-6)  # boolean output is float32
    assert abs(curved.axis @ [0, 0, 1]) == pytest.approx(1.0, abs=1e-9)
    assert curved.extent[1] - curved.extent[0] == pytest.approx(2.0, abs=1e-6)
    assert found[0].planar == ()


def _ringed_shaft(radius: float, length: float, rings: int) -> trimesh.Trimesh:
    """A closed shaft along z centred on the origin, its side cut into ``rings`` rings."""
    z = np.linspace(-length / 2, length / 2, rings + 1)
    side = np.column_stack([np.full_like(z, radius), z])
    profile = np.vstack([[0.0, -length / 2], side, [0.0, length / 2]])
    return trimesh.creation.revolve(profile, sections=48)


def test_a_long_shaft_is_recognised_only_where_the_plate_around_it_reaches():
    """A shaft 20 long in rings of 0.5 through a plate 2 thick: the curved surface that
    contacts need is the shaft's cylinder on the rings reaching the plate's box (z in
    [-1.5, 1.5]: 6 of 40 rings), and the contact is the same whole turn of height 2;
    a collar touching the shaft elsewhere changes nothing of the plate's contact. The
    plate's hole fills the shaft's box, more than a quarter of the plate's triangles:
    the plate's whole surfaces serve (recognised once for all its pairs)."""
    shaft = _ringed_shaft(1.0, 20.0, 40)
    cutter = trimesh.creation.cylinder(radius=1.0, height=30.0, sections=48)
    plate = box([-3, -3, -1], [3, 3, 1]).difference(cutter, engine="manifold")
    pair = assembly(plate=plate, shaft=shaft)
    (near,) = near_curved_surfaces(pair, "shaft", "plate")
    (whole,) = (s for s in assembly_surfaces(pair, "shaft") if s.kind != "plane")
    assert (near.kind, whole.kind) == ("cylinder", "cylinder")
    assert near.radius == pytest.approx(1.0, abs=1e-12)
    assert len(near.faces) == len(whole.faces) * 6 // 40
    assert set(near.faces.tolist()) < set(whole.faces.tolist())
    assert near_curved_surfaces(pair, "plate", "shaft") is assembly_curved_surfaces(pair, "plate")
    heights = shaft.triangles[near.faces][:, :, 2]
    assert (heights.min(), heights.max()) == pytest.approx((-1.5, 1.5), abs=1e-12)
    (found,) = find_contacts(pair)
    (curved,) = found.curved
    assert curved.kind == "cylindrical" and curved.inner == "shaft"
    assert curved.extent[1] - curved.extent[0] == pytest.approx(2.0, abs=1e-6)

    collar = box([-2, -2, 5], [2, 2, 6]).difference(cutter, engine="manifold")
    found_with_collar = find_contacts(assembly(plate=plate, shaft=shaft, collar=collar))
    assert [c.pair for c in found_with_collar] == [("plate", "shaft"), ("shaft", "collar")]
    assert repr(found_with_collar[0]) == repr(found)


def _reference(path: Path) -> dict[frozenset[str], float]:
    edges = json.loads(path.read_text())["data"]["graph"]["data"]["edge"]
    ref = {}
    for i, row in edges.items():
        for j, edge in row.items():
            area = 0.0
            for interface in edge["interfaces"]:
                pts = np.array([p["data"] for p in interface["data"]["points"]])
                centred = pts - pts.mean(axis=0)
                area += (
                    np.linalg.norm(np.cross(centred, np.roll(centred, -1, axis=0)).sum(axis=0)) / 2
                )
            ref[frozenset((i, j))] = area
    return ref


# At the default policy (the command line without --tolerance) the loader measures each
# file's joint mismatch and compares with it: exact joints for stack and arch, 1.8e-4 for
# the cross vault, 0.029 (faces tilted up to 5.6 deg) for the dome. The cross vault holds
# 3 touching pairs compas_assembly did not list and misses none of it by more than 2%.
@pytest.mark.parametrize(
    "name, measured, jaccard",
    [
        ("stack_assembly.json", 0.0, 1.0),
        ("arch_assembly.json", 7e-16, 1.0),
        ("crossvault_assembly.json", 1.8e-4, 0.9717),
        ("dome_assembly.json", 0.029, 1.0),
    ],
)
def test_touching_pairs_and_areas_agree_with_compas_assembly(name, measured, jaccard):
    path = dataset(f"compas_assembly/{name}")
    asm = load_compas(path)
    assert asm.precision.length == pytest.approx(measured, rel=1e-9)
    found = {frozenset(c.pair): c.area for c in assembly_contacts(asm)}
    ref = _reference(path)
    assert len(found.keys() & ref.keys()) / len(found.keys() | ref.keys()) >= jaccard
    for pair in found.keys() & ref.keys():
        assert found[pair] == pytest.approx(ref[pair], rel=1e-6)


# The cross vault's two halves meet on a crown line where compas_assembly lists five
# joints (5-6, 7-8, 9-14, 10-13, 11-12). In the file those blocks are sunk into each
# other: the faces overlap fully, parallel within 1.3e-4 rad, 5.0e-4 to 6.7e-4 (up to
# 4.3e-5 of the vault's size) apart on the wrong side, more than the measured precision
# 1.8e-4 (precision.py does not count faces sunk into each other as joints). At that
# precision they are not faces in contact; what touches there are slivers as wide as the
# sinking, where the neighbours' side faces coincide. A tolerance beyond the sinking
# (--tolerance 5e-5) finds exactly compas_assembly's 452 pairs and their areas.
CROWN = {frozenset(p) for p in [("5", "6"), ("7", "8"), ("9", "14"), ("10", "13"), ("11", "12")]}


def test_the_cross_vaults_crown_joints_are_sunk_beyond_its_precision():
    from assemblykit.geometry.interference import overlap_volume

    path = dataset("compas_assembly/crossvault_assembly.json")
    asm = load_compas(path)
    ref = _reference(path)
    found = {frozenset(c.pair): c for c in assembly_contacts(asm)}
    assert ref.keys() - found.keys() == CROWN
    slivers = found.keys() - ref.keys()
    assert len(slivers) == 8
    assert all(0 < found[pair].area < 5e-4 for pair in slivers)
    length = asm.tolerance().length
    for pair in CROWN:
        a, b = sorted(pair)
        # shared volume over the joint's area: how deep the faces are sunk on average
        depth = overlap_volume(asm[a].mesh, asm[b].mesh) / ref[pair]
        assert length < depth < 4.3e-5 * asm.scale
    loose = Tolerance.relative(5e-5)
    found = {frozenset(c.pair): c.area for c in assembly_contacts(asm, loose)}
    assert found.keys() == ref.keys()
    for pair in ref:
        assert found[pair] == pytest.approx(ref[pair], rel=1e-6)


def test_the_pieces_of_one_face_make_one_patch():
    # part a is two boxes side by side with a crack of 1e-9 (far below the tolerance,
    # 1e-6 x 2.45) between them: two coplanar faces under box c, joined into one patch,
    # the unit square (the crack closed)
    halves = trimesh.util.concatenate(
        [box([0, 0, 0], [0.5 - 1e-9, 1, 1]), box([0.5, 0, 0], [1, 1, 1])]
    )
    (contact,) = find_contacts(assembly(a=halves, c=box([0, 0, 1], [1, 1, 2])))
    (patch,) = contact.planar
    assert patch.area == pytest.approx(1.0, abs=1e-8)
    np.testing.assert_allclose(patch.normal, [0, 0, 1], atol=1e-12)


def _fine_box(extents, corner, size: float) -> trimesh.Trimesh:
    """A box tessellated into triangles no longer than ``size`` (a CAD face's mesh)."""
    box = trimesh.creation.box(extents=extents)
    box.apply_translation(np.asarray(corner) + np.asarray(extents) / 2)
    vertices, faces = trimesh.remesh.subdivide_to_size(box.vertices, box.faces, size)
    return trimesh.Trimesh(vertices, faces)


@pytest.mark.parametrize("size", [0.4, 3.0])
def test_a_plate_on_a_finely_meshed_plate_touches_on_their_common_square(size):
    # 6 x 6 on 10 x 10, a corner 3 in along x and 2 along y: the contact is the square
    # [3, 9] x [2, 8] at z = 1, area 36, whether its faces hold thousands of triangles
    # (intersected outline to outline, OUTLINE_PAIRS) or a few (triangle by triangle)
    base = _fine_box((10, 10, 1), (0, 0, 0), size)
    top = _fine_box((6, 6, 1), (3, 2, 1), size)
    assert (len(base.faces) > 1000) is (size < 1)
    (contact,) = assembly_contacts(Assembly([Part("base", base), Part("top", top)]))
    (patch,) = contact.planar
    assert patch.area == pytest.approx(36.0, rel=1e-9)
    np.testing.assert_allclose(np.abs(patch.normal), [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(patch.polygon.min(axis=0), [3, 2, 1], atol=1e-9)
    np.testing.assert_allclose(patch.polygon.max(axis=0), [9, 8, 1], atol=1e-9)
    square = shapely.Polygon(patch.polygon[:, :2])
    assert square.symmetric_difference(shapely.box(3, 2, 9, 8)).area < 1e-9
