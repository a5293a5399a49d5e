"""Interlocking assemblies (docs/interlocking.md): verdicts and keys derived by hand,
every "free" answer swept along its direction by manifold3d (tests/plan_checks.py), every
"blocked" answer checked against the planner."""

from __future__ import annotations

import json
from pathlib import Path

import manifold3d
import networkx as nx
import numpy as np
import pytest
import trimesh
from shapely.geometry import Polygon

import assemblykit
from assemblykit.blocking.graphs import blocking_graph
from assemblykit.blocking.queries import can_extract
from assemblykit.errors import InputError, UnknownNameError
from assemblykit.io.assembly import load_assembly
from assemblykit.io.burrtools import voxel_mesh
from assemblykit.io.polygons import load_polygons
from assemblykit.model.assembly import Assembly, Part
from assemblykit.model.packings import box_mesh
from assemblykit.planning.interlocking import Interlocking, interlocking
from assemblykit.planning.planner import plan, separable_by_translations
from assemblykit.planning.sequence import Step
from plan_checks import step_clashes

EXAMPLES = Path(assemblykit.__file__).parent / "examples" / "interlocking"
DIAGONAL = np.array([1.0, 1.0, 0.0]) / np.sqrt(2.0)


def swept_clear(assembly: Assembly, steps: list[tuple[tuple[str, ...], np.ndarray]]) -> bool:
    """Whether each set, in turn, leaves along its direction without entering a part
    still in place (manifold3d sweeps, independent of the blocking code)."""
    names = list(assembly.names)
    moved: list[Step] = []
    gone: set[str] = set()
    for parts, direction in steps:
        d = np.zeros(3)
        d[: len(direction)] = direction
        rest = tuple(n for n in names if n not in gone and n not in parts)
        moved.append(Step(tuple(parts), d, rest, ()))
        gone |= set(parts)
    return step_clashes(assembly, moved) == []


def extruded(path: Path) -> Assembly:
    """A polygon file's parts as unit-high prisms."""
    model = load_polygons(path)
    return Assembly(
        [
            Part(name, trimesh.creation.extrude_polygon(Polygon(points), 1.0))
            for name, points in model.polygons.items()
        ]
    )


def voxels(pieces: dict[str, list[tuple[int, int, int]]]) -> Assembly:
    """An assembly of voxel pieces (unit cubes at integer cells)."""
    return Assembly([Part(name, voxel_mesh(np.array(cells))) for name, cells in pieces.items()])


def box_cells(lo: tuple[int, int, int], hi: tuple[int, int, int]) -> list[tuple[int, int, int]]:
    """Every cell of the box from ``lo`` to ``hi`` (inclusive)."""
    return [
        (x, y, z)
        for x in range(lo[0], hi[0] + 1)
        for y in range(lo[1], hi[1] + 1)
        for z in range(lo[2], hi[2] + 1)
    ]


def pin_lock() -> Assembly:
    """A pin filling a straight tunnel along x through a frame (flush at both ends: it
    slides along +x or -x only) and a block in a pocket under the pin, whose way out
    (up a shaft) the pin covers."""
    pin = [(x, 0, 2) for x in range(5)]
    block = [(2, 0, 1)]
    shaft = [(2, 0, 3)]
    frame = [c for c in box_cells((0, -1, 0), (4, 1, 3)) if c not in {*pin, *block, *shaft}]
    return voxels({"frame": frame, "block": block, "pin": pin})


def stack() -> Assembly:
    """Three unit boxes stacked along z."""
    return Assembly(
        [
            Part("bottom", box_mesh([0, 0, 0], [1, 1, 1])),
            Part("middle", box_mesh([0, 0, 1], [1, 1, 2])),
            Part("top", box_mesh([0, 0, 2], [1, 1, 3])),
        ]
    )


def linked_links() -> Assembly:
    """Two chain links through each other's holes: neither comes out by translating."""
    first = [(a, b, 0) for a in range(5) for b in range(-1, 2) if not (b == 0 and a in (1, 3))]
    second = [(a + 3, 0, b) for a in range(5) for b in range(-1, 2) if not (b == 0 and a in (1, 3))]
    return voxels({"first": first, "second": second})


def six_axis_keys(assembly: Assembly) -> list[str]:
    """The single keys the six axis directions alone give: the classes of parts no
    axis DBG separates (strong components of the DBGs along +-X, +-Y, +-Z)."""
    graph = blocking_graph(assembly, "extended")
    signature: dict[str, list[int]] = {n: [] for n in assembly.names}
    for axis in np.concatenate([np.eye(3), -np.eye(3)]):
        dbg = graph.dbg(axis)
        for k, component in enumerate(nx.strongly_connected_components(dbg.graph)):
            for name in component:
                signature[name].append(k)
    classes: dict[tuple[int, ...], list[str]] = {}
    for name, sig in signature.items():
        classes.setdefault(tuple(sig), []).append(name)
    groups = sorted(classes.values(), key=len)
    if len(groups) == 2 and len(groups[0]) == 1:
        return groups[0]
    return []


def test_planar_three_piece_joint_is_recursively_interlocking() -> None:
    # the key stands on the base beside the tongue, its tooth in the floor's notch: it
    # lifts off (+y) only; the tongue, under the lip, then slides out along +x
    joint = load_polygons(EXAMPLES / "lipped_joint.yaml")
    for motion in ("infinitesimal", "extended"):
        result = interlocking(joint, motion=motion)
        assert result.verdict == "recursively interlocking"
        assert result.keys == ("key",) and not result.keys_given
        assert result.locked == (("base", "tongue"), ("key",))
        assert [r.keys for r in result.order] == [("key",), ("tongue",)]
        assert [tuple(r.direction) for r in result.order] == [(0.0, 1.0), (1.0, 0.0)]
        assert result.exact
    (key,) = result.freedoms
    assert key.parts == ("key",) and [f.kind for f in key.free_along] == ["direction"]
    assert np.allclose(key.block_with, [[0.0, 1.0]])
    # free: swept out, the key then the tongue, as prisms
    prisms = extruded(EXAMPLES / "lipped_joint.yaml")
    assert swept_clear(prisms, [(r.keys, r.direction) for r in result.order])
    # blocked: the planner's first step can only take the key
    steps = plan(joint).steps
    assert [s.parts for s in steps] == [("key",), ("tongue",)]


def test_voxel_puzzle_recursive_keys_and_certificate() -> None:
    puzzle = load_assembly(EXAMPLES / "nested_locks.xmpuzzle")
    result = interlocking(puzzle)
    assert result.verdict == "recursively interlocking"
    assert result.keys == ("key",) and result.smallest_keys == ("key",)
    assert [r.keys for r in result.order] == [("key",), ("slider",), ("pocket",)]
    assert [r.direction.tolist() for r in result.order] == [[0, 0, 1], [1, 0, 0], [0, 1, 0]]
    assert result.order[-1].rest == ("frame",) and result.stops == ()
    # the certificate: in every distinct DBG the parts other than the key are one strong
    # component, and only the key's component is ever free
    assert result.cells
    for cell in result.cells:
        holding = [c for c in cell.components if "frame" in c.parts]
        assert set(holding[0].parts) >= {"frame", "pocket", "slider"}
        assert all(
            c.parts == ("key",) for c in cell.components if c.free and "frame" not in c.parts
        )
        for component in cell.components:
            assert all(
                i in component.parts and j not in component.parts for i, j in component.stopped_by
            )
    # free: each key in turn leaves along its direction (swept)
    assert swept_clear(puzzle, [(r.keys, r.direction) for r in result.order])
    # blocked: no part but the key comes out first, by the planner's exact test
    assert can_extract(puzzle, ["slider"]) is None and can_extract(puzzle, ["pocket"]) is None
    assert [s.parts for s in plan(puzzle).steps] == [("key",), ("slider",), ("pocket",)]


def test_voxel_puzzle_with_extended_translations_agrees() -> None:
    result = interlocking(load_assembly(EXAMPLES / "nested_locks.xmpuzzle"), motion="extended")
    assert result.verdict == "recursively interlocking" and result.exact
    assert [r.keys for r in result.order] == [("key",), ("slider",), ("pocket",)]


def test_a_wrong_key_is_refused_with_the_part_that_moves() -> None:
    puzzle = load_assembly(EXAMPLES / "nested_locks.xmpuzzle")
    result = interlocking(puzzle, keys=["slider"])
    assert result.verdict == "not interlocking" and result.keys == ("slider",)
    assert result.keys_given and result.smallest_keys == ("key",)
    assert [f.parts for f in result.freedoms] == [("key",)]
    assert result.freedoms[0].direction.tolist() == [0, 0, 1]
    with pytest.raises(UnknownNameError, match="'lever'"):
        interlocking(puzzle, keys=["lever"])
    with pytest.raises(InputError, match="not none or all"):
        interlocking(puzzle, keys=puzzle.names)


def test_a_stack_is_not_interlocking() -> None:
    # the top lifts off alone and slides; the middle slides out between its neighbours:
    # two parts move, so no single key; with both as keys the bottom is all that is left
    boxes = stack()
    for motion in ("infinitesimal", "extended"):
        result = interlocking(boxes, motion=motion)
        assert result.verdict == "not interlocking" and not result.deadlocked
        assert result.keys == () and result.smallest_keys == ("middle", "top")
        assert result.locked == (("bottom",), ("middle",), ("top",))
        moving = {f.parts: f for f in result.freedoms}
        assert set(moving) == {("middle",), ("top",)}
        assert moving[("top",)].direction.tolist() == [0, 0, 1]
        assert moving[("middle",)].direction.tolist() == [1, 0, 0]
        assert [f.kind for f in moving[("middle",)].free_along] == ["circle"]
    assert [f.kind for f in moving[("top",)].free_along] == ["region"]
    for freedom in result.freedoms:
        assert swept_clear(boxes, [(freedom.parts, freedom.direction)])
    # the planner takes more than one part off alone as well
    assert can_extract(boxes, ["middle"]) is not None and can_extract(boxes, ["top"]) is not None
    assert interlocking(boxes, keys=["middle", "top"]).verdict == "interlocking"


def test_the_diagonal_tunnel_is_missed_by_the_six_axes() -> None:
    # along the axes only the lid moves (a key); the peg leaves its tunnel along
    # +-(1, 1, 0)/sqrt 2, which no axis direction sees
    tunnel = load_assembly(EXAMPLES / "diagonal_tunnel")
    assert six_axis_keys(tunnel) == ["lid"]
    result = interlocking(tunnel, motion="extended")
    assert result.verdict == "not interlocking" and result.keys == ()
    assert result.smallest_keys == ("lid", "peg")
    moving = {f.parts: f for f in result.freedoms}
    assert set(moving) == {("lid",), ("peg",)}
    peg = moving[("peg",)]
    assert np.allclose(np.abs(peg.direction), np.abs(DIAGONAL), atol=1e-9)
    # it can only slide: two isolated directions, blocked by a cap at each end
    assert [f.kind for f in peg.free_along] == ["direction", "direction"]
    ends = sorted(tuple(np.round(f.direction, 9)) for f in peg.free_along)
    assert np.allclose(ends, [-DIAGONAL, DIAGONAL])
    assert np.allclose(sorted(map(tuple, peg.block_with)), [-DIAGONAL, DIAGONAL])
    assert "block it with parts touching it on faces" in peg.explanation(result.tol)
    assert swept_clear(tunnel, [(peg.parts, peg.direction)])
    assert swept_clear(tunnel, [(peg.parts, -peg.direction)])
    assert swept_clear(tunnel, [(("lid",), moving[("lid",)].direction)])
    # the planner finds the tunnel too: the assembly comes apart
    assert separable_by_translations(tunnel)


def test_a_sliding_key() -> None:
    # the pin moves only along +x or -x (two isolated directions); once it is out the
    # block rises through the shaft
    lock = pin_lock()
    result = interlocking(lock, motion="extended")
    assert result.verdict == "recursively interlocking" and result.keys == ("pin",)
    (pin,) = result.freedoms
    assert sorted(tuple(f.direction) for f in pin.free_along) == [(-1, 0, 0), (1, 0, 0)]
    assert pin.direction.tolist() == [1, 0, 0]
    assert [(r.keys, r.direction.tolist()) for r in result.order] == [
        (("pin",), [1, 0, 0]),
        (("block",), [0, 0, 1]),
    ]
    assert swept_clear(
        lock, [(("pin",), np.array([-1.0, 0, 0])), (("block",), np.array([0, 0, 1.0]))]
    )
    assert can_extract(lock, ["block"]) is None


def closed_box() -> trimesh.Trimesh:
    """A hollow cube (side 4, cavity of side 2 at its centre), one non-convex part."""
    mesh = (
        manifold3d.Manifold.cube([4.0, 4.0, 4.0], True)
        - manifold3d.Manifold.cube([2.0, 2.0, 2.0], True)
    ).to_mesh()
    return trimesh.Trimesh(mesh.vert_properties[:, :3], mesh.tri_verts)


def test_a_cube_shut_in_a_box_moves_only_locally() -> None:
    # resting on the cavity's floor the cube may start to rise (Γ_t) but no straight
    # line takes it out (Γ_e): over every face of the blocked sets' overlay it is held
    shut = Assembly(
        [Part("box", closed_box()), Part("cube", box_mesh([-0.5, -0.5, -1], [0.5, 0.5, 0]))]
    )
    assert interlocking(shut).verdict == "interlocking"
    result = interlocking(shut, motion="extended")
    assert result.verdict == "not interlocking" and result.deadlocked and result.exact
    assert can_extract(shut, ["cube"]) is None


@pytest.mark.slow
def test_a_tunnel_between_the_regions_is_found() -> None:
    # a cube floating in a cage whose only way out is a 0.6-wide tunnel along the body
    # diagonal: it touches nothing, so Γ_t has one region, where Γ_e is blocked; its
    # exact free set finds the tunnel
    axis = np.ones(3) / np.sqrt(3.0)
    z = np.array([0.0, 0.0, 1.0])
    turn = trimesh.transformations.rotation_matrix(np.arccos(z @ axis), np.cross(z, axis))
    tunnel = manifold3d.Manifold.cube([0.6, 0.6, 5.0]).translate([-0.3, -0.3, 0.0])
    shell = manifold3d.Manifold.cube([4.0, 4.0, 4.0], True) - manifold3d.Manifold.cube(
        [2.0, 2.0, 2.0], True
    )
    mesh = (shell - tunnel.transform(turn[:3, :4])).to_mesh()
    cage = trimesh.Trimesh(mesh.vert_properties[:, :3], mesh.tri_verts)
    caged = Assembly([Part("cage", cage), Part("cube", box_mesh([-0.15] * 3, [0.15] * 3))])
    result = interlocking(caged, motion="extended")
    assert result.verdict == "interlocking" and result.exact
    (cube,) = result.freedoms
    assert cube.parts == ("cube",) and not cube.touching
    assert np.arccos(np.clip(cube.direction @ axis, -1, 1)) < 0.15
    assert swept_clear(caged, [(("cube",), cube.direction)])


def test_linked_links_are_deadlocked() -> None:
    links = linked_links()
    result = interlocking(links)
    assert result.verdict == "not interlocking" and result.deadlocked
    assert result.freedoms == () and result.smallest_keys == ()
    assert can_extract(links, ["first"]) is None and can_extract(links, ["second"]) is None
    assert "deadlocked" in result.summary()


def test_two_parts_that_separate_are_both_keys() -> None:
    pair = Assembly(
        [
            Part("plate", box_mesh([0, 0, 0], [4, 4, 1])),
            Part("cube", box_mesh([0, 0, 1], [1, 1, 2])),
        ]
    )
    result = interlocking(pair)
    assert result.verdict == "interlocking" and result.keys == ("cube", "plate")
    assert [(r.keys, r.rest) for r in result.order] == [(("cube",), ("plate",))]


def test_rigid_motion_counts_translations_and_turns() -> None:
    result = interlocking(stack(), motion="rigid")
    assert result.verdict == "not interlocking" and not result.exact
    assert {f.parts for f in result.freedoms} == {("middle",), ("top",)}
    assert len(result.freedoms[0].direction) == 6
    with pytest.raises(InputError, match="2D"):
        interlocking(load_polygons(EXAMPLES / "lipped_joint.yaml"), motion="rigid")


def test_result_presents_itself() -> None:
    result = assemblykit.interlocking(load_polygons(EXAMPLES / "lipped_joint.yaml"))
    assert isinstance(result, Interlocking) and assemblykit.Interlocking is Interlocking
    assert repr(result) == "Interlocking(recursively interlocking, key: key, 3 parts)"
    data = json.loads(json.dumps(result.to_dict()))
    assert data["verdict"] == "recursively interlocking" and data["keys"] == ["key"]
    assert data["free"][0]["direction"] == [0.0, 1.0]
    assert data["order"][1] == {"keys": ["tongue"], "direction": [1.0, 0.0], "rest": ["base"]}
    assert data["certificate"]["cells"][0]["components"]
    assert "Keys in order: key along +Y, then tongue along +X (base stays)." in result.summary()
    assert "<table>" in result._repr_html_()
