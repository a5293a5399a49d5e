"""Interfering parts read as a fitter reads them (geometry/overlaps.py): designed
interference cut from the smaller part, joined parts, and pairs left as obstacles, each
reported with its volume; on hand-built parts whose shared volumes are known, with the
cut checked by manifold3d and the plans' directions known by hand."""

from __future__ import annotations

import json
from dataclasses import replace

import manifold3d
import numpy as np
import pytest
import shapely
import trimesh

from assemblykit.geometry import overlaps
from assemblykit.geometry.interference import interferences, overlap_volume, solid
from assemblykit.geometry.overlaps import DESIGNED_SHARE, joined, resolve_overlaps
from assemblykit.model.assembly import Assembly, Part
from assemblykit.planning.planner import plan
from cli_runs import run
from plan_checks import assert_steps_clear
from stability_blocks import box


def cup_and_peg() -> Assembly:
    """A cup (3 x 3 x 2, a 1 x 1 well from z = 1) and a peg 1.1 x 0.2 x 1 standing in the
    well, 0.1 of it pressed into the well's wall: they share 0.1 x 0.2 x 1 = 0.02, 9% of
    the peg."""
    cup = trimesh.boolean.difference(
        [box((3, 3, 2), (0, 0, 0)), box((1, 1, 2), (1, 1, 1))], engine="manifold"
    )
    return Assembly([Part("cup", cup), Part("peg", box((1.1, 0.2, 1), (1, 1.4, 1)))])


def winding_numbers(mesh: trimesh.Trimesh, points: np.ndarray) -> np.ndarray:
    """How many times the closed surfaces of ``mesh`` wind round each point: the solid
    angles its triangles subtend there (Van Oosterom and Strackee, 1983) over 4 pi. Meshes
    side by side add up, faces they share or not, which a ray count does not promise."""
    corners = mesh.triangles[None, :, :, :] - points[:, None, None, :]
    a, b, c = corners[..., 0, :], corners[..., 1, :], corners[..., 2, :]
    la, lb, lc = (np.linalg.norm(v, axis=-1) for v in (a, b, c))
    numerator = np.einsum("ijk,ijk->ij", a, np.cross(b, c))
    denominator = (
        la * lb * lc
        + np.einsum("ijk,ijk->ij", a, b) * lc
        + np.einsum("ijk,ijk->ij", b, c) * la
        + np.einsum("ijk,ijk->ij", c, a) * lb
    )
    return 2 * np.arctan2(numerator, denominator).sum(axis=1) / (4 * np.pi)


def screw_in_plate(thread: float = 1.5, hole: float = 1.45) -> Assembly:
    """A plate 10 x 10 x 4 with a hole of radius ``hole`` along z, and a screw of radius
    ``thread`` through it with a head (radius 2.5, 1.5 high) resting on the plate."""
    plate = trimesh.boolean.difference(
        [
            box((10, 10, 4), (-5, -5, 0)),
            trimesh.creation.cylinder(hole, 10, sections=64),
        ],
        engine="manifold",
    )
    shank = trimesh.creation.cylinder(thread, 6, sections=64)
    shank.apply_translation([0, 0, 1])
    head = trimesh.creation.cylinder(2.5, 1.5, sections=64)
    head.apply_translation([0, 0, 4.75])
    screw = trimesh.boolean.union([shank, head], engine="manifold")
    return Assembly([Part("plate", plate), Part("screw", screw)])


def test_designed_interference_is_cut_from_the_smaller_part_and_reported():
    prepared = resolve_overlaps(cup_and_peg())
    ((a, b, volume, resolution),) = [(o.a, o.b, o.volume, o.resolution) for o in prepared.overlaps]
    assert {a, b} == {"cup", "peg"} and volume == pytest.approx(0.02, rel=1e-9)
    assert resolution == "trimmed from peg"
    peg, cup = prepared.parts["peg"].mesh, prepared.parts["cup"].mesh
    assert peg.volume == pytest.approx(0.22 - 0.02, rel=1e-9) and cup.volume == pytest.approx(17.0)
    assert overlap_volume(peg, cup) == pytest.approx(0.0, abs=1e-12)
    result = plan(prepared, max_and_or_parts=0)
    assert result.feasible and result.overlaps == prepared.overlaps
    np.testing.assert_allclose(result.steps[0].direction, [0, 0, 1], atol=1e-9)


@pytest.mark.parametrize("limit", [0.0, 0.019])
def test_a_shared_volume_beyond_the_limit_is_an_obstacle_named_in_the_plan(limit):
    prepared = resolve_overlaps(cup_and_peg(), ignore_overlap=limit)
    (overlap,) = prepared.overlaps
    assert overlap.resolution == "" and prepared.parts["peg"].volume == pytest.approx(0.22)
    result = plan(prepared, max_and_or_parts=0, max_hands=2)
    assert not result.feasible
    assert result.interlocked[0].interfering[0][2] == pytest.approx(0.02)
    assert result.to_dict()["overlaps"] == [overlap.to_dict()]


def test_a_share_beyond_the_default_is_left_as_it_is():
    # the peg 0.4 long pressed 0.2 into the wall shares 0.04 of its 0.08: beyond
    # DESIGNED_SHARE
    parts = cup_and_peg()
    pressed = Assembly([parts.parts["cup"], Part("peg", box((0.4, 0.2, 1), (1.8, 1.4, 1)))])
    (overlap,) = resolve_overlaps(pressed).overlaps
    assert overlap.volume / 0.08 > DESIGNED_SHARE and overlap.resolution == ""


@pytest.mark.parametrize("how", ["join", "join_interfering"])
def test_joined_parts_move_as_one(how):
    options = {"join": [["peg", "cup"]]} if how == "join" else {"join_interfering": True}
    prepared = resolve_overlaps(cup_and_peg(), **options)
    assert list(prepared.parts) == ["cup+peg"]
    assert prepared.parts["cup+peg"].volume == pytest.approx(17.0 + 0.22 - 0.02, rel=1e-9)
    assert [o.resolution for o in prepared.overlaps] == ["joined"]


def test_parts_that_only_touch_are_joined_side_by_side_and_keep_their_solid():
    # a lid resting on the cup and a peg standing in its well, apart from its walls:
    # the three share no volume, so the joined part is their meshes side by side (no
    # boolean, whose mesh keeps the touching faces as sheets: made into a solid again it
    # is not their union), its solid exactly theirs; a ball of radius 0.2 just clear of
    # the cup, the lid and the peg shares nothing with it, by the solid and by counting
    # sample points (independently of manifold3d)
    peg = box((0.4, 0.4, 1), (1.5, 1.3, 1))
    lid = box((3, 3, 1), (0, 0, 2))
    parts = [cup_and_peg().parts["cup"], Part("peg", peg), Part("lid", lid)]
    together = joined(Assembly(parts), [["cup", "peg", "lid"]])
    part = together.parts["cup+peg+lid"]
    assert len(part.mesh.faces) == sum(len(p.mesh.faces) for p in parts)
    volume = sum(p.mesh.volume for p in parts)
    assert solid(part.mesh).volume() == pytest.approx(volume, rel=1e-12)
    ball = trimesh.creation.icosphere(subdivisions=3, radius=0.2)
    ball.apply_translation([1.25, 1.5, 1.5])  # in the well, 0.05 from its wall and the peg
    assert overlap_volume(ball, part.mesh) == pytest.approx(0.0, abs=1e-12)
    grid = np.stack(np.meshgrid(*[np.linspace(-0.19, 0.19, 9)] * 3), axis=-1).reshape(-1, 3)
    points = grid[np.linalg.norm(grid, axis=1) < 0.19] + [1.25, 1.5, 1.5]
    assert np.abs(winding_numbers(part.mesh, points)).max() < 1e-9
    # parts that overlap are their boolean union: the cup and the peg pressed into it
    pressed = joined(cup_and_peg(), [["cup", "peg"]]).parts["cup+peg"]
    assert pressed.volume == pytest.approx(17.0 + 0.22 - 0.02, rel=1e-9)


def test_joining_chains_of_parts_and_unknown_names():
    three = Assembly([*cup_and_peg(), Part("lid", box((3, 3, 1), (0, 0, 2)))])
    together = joined(three, [["cup", "peg"], ["lid", "peg"]])
    assert list(together.parts) == ["cup+peg+lid"]
    with pytest.raises(Exception, match="no part named 'nut'"):
        joined(three, [["cup", "nut"]])


def test_a_screw_in_a_smaller_hole_leaves_along_its_axis():
    # a thread of radius 1.5 in a pilot hole of 1.45: the ring they share is cut from the
    # screw, which then unscrews up its axis (its head lies on the plate)
    prepared = resolve_overlaps(screw_in_plate())
    (overlap,) = prepared.overlaps
    assert overlap.resolution == "trimmed from screw" and overlap.volume > 0.1
    result = plan(prepared, max_and_or_parts=0)
    assert result.feasible
    (step,) = result.steps
    assert step.parts == ("screw",)
    np.testing.assert_allclose(step.direction, [0, 0, 1], atol=1e-9)
    assert not plan(screw_in_plate(), max_and_or_parts=0).feasible


def test_the_plan_command_cuts_designed_interference_and_says_so(capsys, tmp_path):
    folder = tmp_path / "screwed"
    folder.mkdir()
    for part in screw_in_plate():
        part.mesh.export(folder / f"{part.name}.stl")
    code, out, err = run(capsys, "plan", str(folder), "--json")
    assert code == 0, err
    found = json.loads(out)
    assert found["feasible"] and found["overlaps"][0]["resolution"] == "trimmed from screw"
    code, out, err = run(capsys, "plan", str(folder), "--json", "--ignore-overlap", "0")
    assert code == 0, err
    found = json.loads(out)
    assert not found["feasible"] and found["interlocked"][0]["interfering"]
    code, out, err = run(capsys, "plan", str(folder), "--join", "screw", "plate", "--json")
    assert code == 0, err
    found = json.loads(out)
    assert found["parts"] == ["plate+screw"] and found["overlaps"][0]["resolution"] == "joined"
    assert found["joined"] == {"plate+screw": ["plate", "screw"]}


def polygon_area(radius: float, sections: int = 64) -> float:
    """Area of the regular polygon trimesh makes for a cylinder of ``radius``."""
    return sections / 2 * radius**2 * np.sin(2 * np.pi / sections)


def test_a_screw_through_two_plates_is_cut_once_along_its_whole_shank():
    # plates 4 thick at z in [0, 4] and [4, 8], each with a pilot hole of radius 1.45;
    # the screw (radius 1.5 from z = -1 to 8, a head of radius 2.5 up to 9.5) loses the
    # ring between the two radii along its whole length, once: the second plate then
    # shares nothing with it and cuts nothing more
    def plate(z: float) -> trimesh.Trimesh:
        hole = trimesh.creation.cylinder(1.45, 20, sections=64)
        return trimesh.boolean.difference([box((10, 10, 4), (-5, -5, z)), hole], engine="manifold")

    shank = trimesh.creation.cylinder(1.5, 9, sections=64)
    shank.apply_translation([0, 0, 3.5])
    head = trimesh.creation.cylinder(2.5, 1.5, sections=64)
    head.apply_translation([0, 0, 8.75])
    screw = trimesh.boolean.union([shank, head], engine="manifold")
    parts = [Part("lower", plate(0.0)), Part("upper", plate(4.0)), Part("screw", screw)]
    prepared = resolve_overlaps(Assembly(parts))
    assert [o.resolution for o in prepared.overlaps] == ["trimmed from screw"] * 2
    ring = polygon_area(1.5) - polygon_area(1.45)
    expected = polygon_area(1.45) * 9 + (polygon_area(2.5) - ring) * 1.5
    trimmed = prepared.parts["screw"].mesh
    assert trimmed.is_watertight and trimmed.volume == pytest.approx(expected, rel=1e-7)
    result = plan(prepared, max_and_or_parts=0)
    assert result.feasible and result.steps[0].parts == ("screw",)
    np.testing.assert_allclose(result.steps[0].direction, [0, 0, 1], atol=1e-9)


def test_designed_interference_far_from_the_origin_is_cut():
    # the cup and peg 100 up the peg's insertion axis (z), 20 times the assemblies'
    # size away: the shadow of the 0.1 x 0.2 x 1 they share is cut all the same
    far = Assembly(
        [
            replace(part, mesh=part.mesh.copy().apply_translation([0, 0, 100]))
            for part in cup_and_peg()
        ]
    )
    prepared = resolve_overlaps(far)
    ((volume, resolution),) = [(o.volume, o.resolution) for o in prepared.overlaps]
    assert volume == pytest.approx(0.02, rel=1e-9) and resolution == "trimmed from peg"
    peg, cup = prepared.parts["peg"].mesh, prepared.parts["cup"].mesh
    assert peg.volume == pytest.approx(0.22 - 0.02, rel=1e-8)
    assert overlap_volume(peg, cup) == pytest.approx(0.0, abs=1e-9)
    assert interferences(prepared) == []


def test_a_cut_that_leaves_the_pair_interfering_leaves_it_as_it_is(monkeypatch):
    # a shadow that removes nothing leaves the peg sharing its 0.02 with the cup: the
    # pair is an obstacle, not "trimmed", and the peg is whole
    monkeypatch.setattr(overlaps, "_extruded_shadow", lambda *_: manifold3d.Manifold())
    prepared = resolve_overlaps(cup_and_peg())
    (overlap,) = prepared.overlaps
    assert overlap.resolution == "" and overlap.volume == pytest.approx(0.02, rel=1e-9)
    assert prepared.parts["peg"].mesh.volume == pytest.approx(0.22, rel=1e-9)
    ((_, _, left),) = interferences(prepared)
    assert left == pytest.approx(0.02, rel=1e-9)


def motor_through_mount() -> Assembly:
    """A motor 42 x 42 in y and z, from x = -40, drawn 1.5 into the 2-thick plate of
    the mount it should stand against, the mount's walls, floor and roof boxing it in
    from x = -30 to 40 (4 thick, 5 away from it): they share a slab 1.5 x 42 x 42, 9%
    of the mount, which is the smaller part."""
    mount = trimesh.boolean.union(
        [
            box((2, 60, 60), (0, -30, -30)),
            box((70, 4, 60), (-30, -30, -30)),
            box((70, 4, 60), (-30, 26, -30)),
            box((70, 52, 4), (-30, -26, -30)),
            box((70, 52, 4), (-30, -26, 26)),
        ],
        engine="manifold",
    )
    return Assembly([Part("mount", mount), Part("motor", box((41.5, 42, 42), (-40, -21, -21)))])


def test_a_motor_drawn_through_its_mounts_plate_leaves_along_its_axis():
    # the slab's smallest shadows are along y and z, but a cut along either leaves the
    # motor boxed in by the walls; along x the plate loses the 42 x 42 x 2 the motor
    # passes through, and nothing else, and the motor slides out along its axis
    assembly = motor_through_mount()
    mount_volume = assembly.parts["mount"].mesh.volume
    prepared = resolve_overlaps(assembly)
    (overlap,) = prepared.overlaps
    assert overlap.resolution == "trimmed from mount"
    assert overlap.volume == pytest.approx(1.5 * 42 * 42, rel=1e-9)
    mount = prepared.parts["mount"].mesh
    assert mount_volume - mount.volume == pytest.approx(2 * 42 * 42, rel=1e-9)
    result = plan(prepared, max_and_or_parts=0)
    assert result.feasible
    (step,) = result.steps
    assert abs(step.direction[0]) == pytest.approx(1.0, abs=1e-12)
    assert_steps_clear(prepared, result)


def test_the_axes_of_a_slab_lie_along_its_faces():
    # a slab 2 thick in z whose outline is a quadrilateral with no symmetry, one corner
    # of its top face moved sideways by 3 (a slab cut through tessellated faces, its
    # sides not square to it): its principal axes lean, and the one across it is taken
    # along its faces, square to z
    outline = np.array([[0.0, 0.0], [40.0, 3.0], [35.0, 30.0], [4.0, 22.0]])
    slab = trimesh.creation.extrude_polygon(shapely.Polygon(outline), 2.0)
    corner = np.flatnonzero((slab.vertices[:, 2] > 1) & (slab.vertices[:, 1] > 25))
    slab.vertices[corner] += [3.0, 0.0, 0.0]
    axes = overlaps.insertion_axes(slab)
    assert max(abs(axis[2]) for axis in np.asarray(slab.principal_inertia_vectors)) < 1 - 1e-7
    across = max(axes, key=lambda axis: abs(axis[2]))
    np.testing.assert_allclose(np.abs(across), [0, 0, 1], atol=1e-12)
