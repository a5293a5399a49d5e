"""Multi-move disassembly of meshes, every plan replayed by sweeping the parts' boxes."""

from __future__ import annotations

import itertools
import json

import manifold3d
import numpy as np
import pytest
import trimesh
from rich.console import Console

from assemblykit.blocking.extended import extended_free
from assemblykit.cli import main
from assemblykit.geometry.minkowski import convex_pieces
from assemblykit.model.assembly import Assembly, Part
from assemblykit.model.packings import guillotine_cells
from assemblykit.planning.multimove import MultiMovePlan, Separation
from assemblykit.planning.multimove_mesh import plan_meshes
from assemblykit.planning.planner import plan
from assemblykit.render import render
from assemblykit.tolerance import Tolerance

Box = tuple[tuple[float, float, float], tuple[float, float, float]]

# side view (x right, z up), extruded along y over [0, 1] between two plates: a channel
# z in [0, 1] over a floor between walls at x = 0 and 7, roofed by two blocks leaving a
# gap at x in [3, 5]; above it a second channel z in [2, 3] roofed over x in [0, 1] and
# [3, 7], open at x in [1, 3]. The key, a 2 x 1 x 1 box, starts at the left of the lower
# channel: by hand it must go +x 3 (under the gap; at 5 it is under the roof again), +z 2
# (into the upper channel), -x 2 (under the opening; 3 takes it under the roof) and +z.
STAIRCASE: dict[str, list[Box]] = {
    "base": [
        ((-1, -1, -1), (8, 2, 0)),
        ((-1, -1, 0), (0, 2, 4)),
        ((7, -1, 0), (8, 2, 4)),
        ((0, -1, 1), (3, 2, 2)),
        ((5, -1, 1), (7, 2, 2)),
        ((0, -1, 3), (1, 2, 4)),
        ((3, -1, 3), (7, 2, 4)),
        ((0, -1, 0), (7, 0, 4)),
        ((0, 1, 0), (7, 2, 4)),
    ],
    "key": [((0, 0, 0), (2, 1, 1))],
}
# overlaps below this are floating-point noise; a real one here is a whole unit cube
NOISE = 1e-9


def cube(lo, hi) -> manifold3d.Manifold:
    return manifold3d.Manifold.cube(np.subtract(hi, lo)).translate(lo)


def union(boxes: list[Box], offset=(0.0, 0.0, 0.0)) -> manifold3d.Manifold:
    """The solid of ``boxes`` moved by ``offset``, built straight from the boxes."""
    return manifold3d.Manifold.batch_boolean(
        [cube(np.add(lo, offset), np.add(hi, offset)) for lo, hi in boxes],
        manifold3d.OpType.Add,
    )


def mesh_of(body: manifold3d.Manifold) -> trimesh.Trimesh:
    out = body.to_mesh()
    return trimesh.Trimesh(np.asarray(out.vert_properties)[:, :3], np.asarray(out.tri_verts))


def assembly_of(parts: dict[str, list[Box]]) -> Assembly:
    return Assembly([Part(name, mesh_of(union(boxes))) for name, boxes in parts.items()])


def corners(box: Box, offset: np.ndarray) -> np.ndarray:
    lo, hi = np.add(box[0], offset), np.add(box[1], offset)
    return np.array(
        [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    )


def replay(result: MultiMovePlan, parts: dict[str, list[Box]]) -> None:
    """Sweep every box of the moved parts over each move of ``result`` (the hull of a
    box and its copy at the end of the move holds all it passes through) and assert it
    shares no volume with the other parts of the subassembly being taken apart; the
    move to infinity goes 100 units, after which the moved parts' bounding box must be
    clear of the others'. Every part must end alone."""
    alone: list[str] = []

    def sweep(move_parts, rest, offsets, step) -> None:
        others = manifold3d.Manifold.batch_boolean(
            [union(parts[n], offsets[n]) for n in rest], manifold3d.OpType.Add
        )
        for name in move_parts:
            for box in parts[name]:
                start = corners(box, offsets[name])
                hull = manifold3d.Manifold.hull_points(np.vstack([start, start + step]))
                assert (hull ^ others).volume() <= NOISE, (name, step)

    def bounds(names, offsets) -> np.ndarray:
        points = np.vstack([corners(b, offsets[n]) for n in names for b in parts[n]])
        return np.array([points.min(axis=0), points.max(axis=0)])

    def walk(node: Separation | None, names: tuple[str, ...], offsets) -> None:
        if node is None:
            alone.extend(names)
            return
        assert node.status == "separated" and set(node.parts) == set(names)
        for move in node.moves:
            rest = [n for n in names if n not in move.parts]
            far = move.distance is None
            step = np.array(move.direction) * (100.0 if far else move.distance)
            sweep(move.parts, rest, offsets, step)
            offsets = {n: offsets[n] + step if n in move.parts else offsets[n] for n in names}
        a, b = bounds(node.moves[-1].parts, offsets), bounds(rest, offsets)
        assert np.any(a[0] >= b[1]) or np.any(b[0] >= a[1])
        removed = tuple(node.removed_parts)
        walk(node.removed, removed, offsets)
        walk(node.left, tuple(n for n in names if n not in removed), offsets)

    walk(result.root, result.parts, {n: np.zeros(3) for n in result.parts})
    assert sorted(alone) == sorted(parts)


def test_the_key_goes_through_the_staircase_in_four_moves_of_hand_computed_lengths():
    assembly = assembly_of(STAIRCASE)
    result = plan_meshes(assembly)
    assert result.feasible and result.level == "4" and result.first_moves == 4
    moves = [(m.parts, m.direction, m.distance) for m in result.root.moves]
    assert moves == [
        (("key",), (1.0, 0.0, 0.0), pytest.approx(3.0)),
        (("key",), (0.0, 0.0, 1.0), pytest.approx(2.0)),
        (("key",), (-1.0, 0.0, 0.0), pytest.approx(2.0)),
        (("key",), (0.0, 0.0, 1.0), None),
    ]
    replay(result, STAIRCASE)
    # no straight line out: along every axis, face diagonal and cube diagonal the key's
    # sweep cuts into the base
    base, key = union(STAIRCASE["base"]), corners(STAIRCASE["key"][0], np.zeros(3))
    for d in itertools.product((-1, 0, 1), repeat=3):
        if any(d):
            sweep = manifold3d.Manifold.hull_points(np.vstack([key, key + 100 * np.array(d)]))
            assert (sweep ^ base).volume() > 0.1
    console = Console(record=True, width=200)
    console.print(render(result))
    text = console.export_text()
    assert "level 4" in text and "first separation: 4 moves" in text


def test_a_search_under_too_few_states_says_it_was_cut():
    result = plan_meshes(assembly_of(STAIRCASE), max_states=3)
    assert not result.feasible and result.cut and result.stuck == ("base", "key")
    assert result.root.status == "cut" and result.root.states > 3


def test_what_a_monotone_plan_takes_apart_comes_apart_in_one_move_per_separation():
    cells = guillotine_cells(6, seed=2)
    parts = {f"b{k}": [(tuple(lo), tuple(hi))] for k, (lo, hi) in enumerate(cells)}
    assembly = assembly_of(parts)
    assert plan(assembly).feasible
    result = plan_meshes(assembly)
    assert result.feasible and result.level == "1.1.1.1.1"

    def check(node: Separation | None) -> None:
        if node is None:
            return
        [move] = node.moves
        # each separation is one the monotone planner accepts: an extended translation
        assert extended_free(assembly, move.parts, move.direction, assembly.tolerance(), node.parts)
        check(node.removed)
        check(node.left)

    check(result.root)
    replay(result, parts)


@pytest.mark.parametrize(("cavity", "states"), [((2, 1, 1), 1), ((3, 1, 1), 2)])
def test_a_box_sealed_in_a_cage_is_stuck_after_every_reachable_state(cavity, states):
    # in a cavity its own size the box cannot move; one unit longer along x it has two
    # places, both enclosed
    cage = cube((-1, -1, -1), np.add(cavity, 1)) - cube((0, 0, 0), cavity)
    assembly = Assembly(
        [Part("cage", mesh_of(cage)), Part("box", mesh_of(cube((0, 0, 0), (2, 1, 1))))]
    )
    result = plan_meshes(assembly)
    assert not result.feasible and not result.cut
    assert result.root.status == "stuck" and result.root.states == states
    assert result.stuck == ("box", "cage") and result.level == ""


def test_convex_pieces_of_a_hollow_cage_fill_it_exactly():
    cage = cube((-1, -1, -1), (4, 2, 2)) - cube((0, 0, 0), (3, 1, 1))
    pieces = convex_pieces(mesh_of(cage), Tolerance(scale=10.0).for_mesh())
    hulls = [manifold3d.Manifold.hull_points(p) for p in pieces]
    # the pieces are convex (their hulls are themselves), fill the cage and do not overlap
    assert sum(h.volume() for h in hulls) == pytest.approx(cage.volume())
    assert manifold3d.Manifold.batch_boolean(
        hulls, manifold3d.OpType.Add
    ).volume() == pytest.approx(cage.volume())
    assert (
        manifold3d.Manifold.batch_boolean(hulls, manifold3d.OpType.Add) ^ cube((0, 0, 0), (3, 1, 1))
    ).volume() == 0


def test_plan_command_moves_multi_on_a_mesh_folder(tmp_path, capsys):
    for part in assembly_of(STAIRCASE):
        part.mesh.export(tmp_path / f"{part.name}.stl")
    try:
        main(["plan", str(tmp_path), "--moves", "multi", "--json"])
    except SystemExit as done:
        assert not done.code
    data = json.loads(capsys.readouterr().out)
    assert data["feasible"] and data["moves"] == "multi" and data["level"] == "4"
    assert [s["distance"] for s in data["steps"]] == [
        pytest.approx(3.0),
        pytest.approx(2.0),
        pytest.approx(2.0),
        None,
    ]
    assert data["steps"][1]["direction"] == [0.0, 0.0, 1.0]
    assert data["separations"]["removed_parts"] == ["key"]
