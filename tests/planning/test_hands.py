"""Tests of the hands analysis (Wilson & Latombe 1992, "Conclusion": how many hands an assembly
needs) on the bundled planar assemblies, with an independent check of the sweeps by
manifold3d (prisms over the polygons)."""

from __future__ import annotations

from pathlib import Path

import manifold3d as m3
import numpy as np
import pytest
import trimesh

from assemblykit.blocking.planar import convex_pieces
from assemblykit.io.polygons import load_polygons
from assemblykit.model.assembly import Assembly, Part
from assemblykit.model.polygons import PolygonAssembly
from assemblykit.planning.hands import hands_needed, partitions
from assemblykit.planning.planner import plan

PLANAR = Path(__file__).resolve().parents[2] / "src" / "assemblykit" / "examples" / "planar"
FAR = 100.0


def prism(points: np.ndarray) -> m3.Manifold:
    """The polygon extruded from z = 0 to z = 1."""
    return m3.CrossSection([points.tolist()]).extrude(1.0)


def swept_overlap(model: PolygonAssembly, moving: str, still: str, relative: np.ndarray) -> float:
    """Volume shared by ``still`` and the prism of ``moving`` swept along ``relative``
    (2-vector) far beyond the drawing: the union of the hulls of each convex piece with
    its translate (manifold3d)."""
    tol = model.tolerance()
    step = FAR * np.r_[relative / np.linalg.norm(relative), 0.0]
    obstacle = prism(model.polygons[still])
    total = 0.0
    for piece in convex_pieces(model.polygons[moving], tol):
        corners = np.vstack([np.c_[piece, np.zeros(len(piece))], np.c_[piece, np.ones(len(piece))]])
        sweep = m3.Manifold.hull_points(np.vstack([corners, corners + step]).tolist())
        total += (sweep ^ obstacle).volume()
    return total


def test_partitions_into_k_groups_are_counted_by_stirling_numbers():
    # S(4, 2) = 7, S(4, 3) = 6, S(5, 3) = 25; the first item's group comes first
    assert len(list(partitions([0, 1, 2, 3], 2))) == 7
    assert len(list(partitions([0, 1, 2, 3], 3))) == 6
    assert len(list(partitions(list(range(5)), 3))) == 25
    assert all(split[0][0] == 0 for split in partitions([0, 1, 2, 3], 3))
    assert list(partitions([0, 1], 3)) == []


def test_three_tongues_need_three_hands():
    model = load_polygons(PLANAR / "three_hands.yaml")
    result = plan(model)
    # two hands: no part leaves the two others (each joint slides one way only)
    assert not result.feasible
    assert result.stuck == ("bar", "base", "block")
    hands = result.hands
    assert hands is not None and hands.needed == 3
    (move,) = hands.moves
    assert move.groups == (("base",), ("bar",), ("block",))
    # by hand: base still, bar up, block along (1, 1) at sqrt(2) times the bar's speed
    v_base, v_bar, v_block = move.velocities
    assert np.allclose(v_base, 0)
    assert np.allclose(v_bar / np.linalg.norm(v_bar), [0, 1, 0])
    assert np.allclose(v_block / np.linalg.norm(v_block), [np.sqrt(0.5), np.sqrt(0.5), 0])
    assert np.isclose(np.linalg.norm(v_block) / np.linalg.norm(v_bar), np.sqrt(2))
    # the bar moves along -x relative to the block
    relative = v_bar - v_block
    assert np.allclose(relative / np.linalg.norm(relative), [-1, 0, 0])
    data = result.to_dict()["hands"]
    assert data["needed"] == 3
    assert data["groups"] == [["base"], ["bar"], ["block"]]
    assert np.allclose(data["directions"][1], [0, 1, 0])


def test_three_handed_move_is_free_by_independent_sweeps():
    model = load_polygons(PLANAR / "three_hands.yaml")
    (move,) = hands_needed(model).moves
    velocity = {group[0]: v[:2] for group, v in zip(move.groups, move.velocities, strict=True)}
    # every two groups, the moving ones against each other included, miss each other
    for moving in ("bar", "block"):
        for still in ("base", "bar", "block"):
            if still != moving:
                relative = velocity[moving] - velocity[still]
                assert swept_overlap(model, moving, still, relative) == pytest.approx(0, abs=1e-9)
    # two hands fail: each part alone, along its own joint's direction, hits another
    assert swept_overlap(model, "bar", "block", np.array([0.0, 1.0])) > 0.1
    assert swept_overlap(model, "block", "bar", np.array([1.0, 1.0])) > 0.1
    assert swept_overlap(model, "bar", "base", np.array([-1.0, 0.0])) > 0.1


def test_trapped_parts_need_more_than_four_hands():
    # the plug's foot is wider than the neck: no simultaneous translations free it
    result = plan(load_polygons(PLANAR / "bottle.yaml"))
    assert result.hands is not None
    assert result.hands.needed is None
    assert result.to_dict()["hands"]["moves"] == []


def test_a_plan_two_hands_finish_needs_two_hands():
    result = plan(load_polygons(PLANAR / "hook.yaml"))
    assert result.feasible
    assert result.hands is not None and result.hands.needed == 2
    assert result.hands.moves == ()
    assert hands_needed(load_polygons(PLANAR / "hook.yaml")).needed == 2


def test_three_handed_move_of_meshes_between_a_floor_and_a_ceiling():
    # the planar three-hands joint as prisms, the base's floor and ceiling holding the
    # bar and block in their plane: the base is not convex, so Γ_e is sampled and
    # computed by projection, and the same three-handed move separates the parts
    model = load_polygons(PLANAR / "three_hands.yaml")
    slab = m3.Manifold.cube([10.0, 7.0, 1.0]).translate([0.0, -1.0, 0.0])
    base = prism(model.polygons["base"]) + slab.translate([0, 0, -1]) + slab.translate([0, 0, 1])

    def mesh(body: m3.Manifold) -> trimesh.Trimesh:
        out = body.to_mesh()
        return trimesh.Trimesh(np.asarray(out.vert_properties)[:, :3], np.asarray(out.tri_verts))

    bodies = {"base": base, **{n: prism(model.polygons[n]) for n in ("bar", "block")}}
    assembly = Assembly([Part(name, mesh(body)) for name, body in bodies.items()])
    hands = hands_needed(assembly)
    assert hands.needed == 3
    (move,) = hands.moves
    assert move.groups == (("base",), ("bar",), ("block",))
    velocity = {group[0]: v for group, v in zip(move.groups, move.velocities, strict=True)}
    # in the plane of the joint: the floor and ceiling are never crossed
    assert np.allclose([v[2] for v in velocity.values()], 0.0)
    for moving in ("bar", "block"):
        for still in ("base", "bar", "block"):
            if still != moving:
                relative = (velocity[moving] - velocity[still])[:2]
                assert swept_overlap(model, moving, still, relative) == pytest.approx(0, abs=1e-9)


def test_two_linked_rings_come_apart_with_no_number_of_hands():
    """Two links of a chain (tori of radius 10 and tube 2, each through the other): no
    translation separates them, and with a hand for each link there is no other way to
    hold them, so more hands would not do either."""
    first = trimesh.creation.torus(10.0, 2.0, major_sections=48, minor_sections=12)
    second = first.copy()
    second.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [1, 0, 0]))
    second.apply_translation([10.0, 0.0, 0.0])
    solids = [
        m3.Manifold(m3.Mesh(np.asarray(m.vertices, np.float32), np.asarray(m.faces, np.uint32)))
        for m in (first, second)
    ]
    assert (solids[0] ^ solids[1]).volume() == 0.0  # linked, not overlapping
    links = Assembly([Part("a", first), Part("b", second)])
    result = plan(links)
    assert sorted(result.stuck) == ["a", "b"]
    hands = result.hands
    assert hands is not None and hands.needed is None and hands.more_may_free is False
    assert hands.summary() == "no number of hands takes it apart by translations"
    assert result.to_dict()["hands"]["more_may_free"] is False
