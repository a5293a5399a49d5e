"""Multi-move disassembly of voxel pieces, every plan replayed cell by cell."""

from __future__ import annotations

import itertools
import json
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from assemblykit.io.burrtools import load_puzzle, solution_count
from assemblykit.planning.multimove import (
    Move,
    MultiMovePlan,
    Separation,
    moving_groups,
    plan_voxels,
)
from assemblykit.render import render
from cli_runs import run
from datasets import dataset

ROOT = Path(__file__).resolve().parents[2]
STAIRCASE = ROOT / "src" / "assemblykit" / "examples" / "puzzles" / "staircase.xmpuzzle"
# a channel through a 5 x 5 x 3 block: the key leaves by +x 2, +y 2 and then +z
CHANNEL = [(1, 1, 1), (2, 1, 1), (3, 1, 1), (3, 2, 1), (3, 3, 1), (3, 3, 2)]


def block(size: tuple[int, int, int], holes: list[tuple[int, int, int]]) -> np.ndarray:
    every = np.argwhere(np.ones(size, dtype=bool))
    return np.array([c for c in every.tolist() if tuple(c) not in set(holes)], dtype=np.int64)


def cage_and_key(channel: list[tuple[int, int, int]]) -> tuple[list[str], list[np.ndarray]]:
    return ["cage", "key"], [block((5, 5, 3), channel), np.array([channel[0]], dtype=np.int64)]


def replay(plan: MultiMovePlan, voxels: dict[str, np.ndarray]) -> None:
    """Apply every move of ``plan`` to the cells one unit at a time and assert that no
    two parts of the subassembly being taken apart ever share a cell, that the last move
    of each separation takes the moved parts wholly beyond the rest along its direction
    (from there on nothing can meet them), and that every part ends alone or in a kept
    group."""
    ends: list[tuple[str, ...]] = []

    def disjoint(parts: tuple[str, ...], offsets: dict[str, np.ndarray]) -> bool:
        placed = np.concatenate([voxels[name] + offsets[name] for name in parts])
        return len(np.unique(placed, axis=0)) == len(placed)

    def reach(
        parts: list[str], offsets: dict[str, np.ndarray], direction: np.ndarray
    ) -> np.ndarray:
        """How far along ``direction`` the cells of ``parts`` lie (one value per cell)."""
        return np.concatenate([(voxels[n] + offsets[n]) @ direction for n in parts])

    def clear(move: Move, rest: list[str], offsets: dict[str, np.ndarray]) -> bool:
        """Whether the cells moved by ``move`` all lie beyond those of ``rest``."""
        direction = np.array(move.direction)
        ahead = reach(list(move.parts), offsets, direction).min()
        return bool(ahead > reach(rest, offsets, direction).max())

    def walk(node: Separation | None, offsets: dict[str, np.ndarray]) -> None:
        if node is None:
            return
        if node.status != "separated":
            assert node.status == "group"
            ends.append(node.parts)
            return
        assert disjoint(node.parts, offsets)
        for move in node.moves:
            direction = np.array(move.direction)
            assert set(move.parts) < set(node.parts) and abs(direction).sum() == 1
            rest = [n for n in node.parts if n not in move.parts]
            # to infinity: until the moved cells all lie beyond the others, which takes
            # at most the depth of the whole subassembly along the move
            depth = int(np.ptp(reach(list(node.parts), offsets, direction))) + 1
            steps = depth if move.distance is None else move.distance
            moved = 0
            while moved < steps and not (move.distance is None and clear(move, rest, offsets)):
                for name in move.parts:
                    offsets[name] = offsets[name] + direction
                moved += 1
                assert disjoint(node.parts, offsets)
            if move.distance is None:
                assert clear(move, rest, offsets), "the last move does not get clear of the rest"
                for name in move.parts:
                    offsets[name] = offsets[name] - moved * direction
        assert set(node.removed_parts) == set(node.moves[-1].parts) or set(node.parts) - set(
            node.removed_parts
        ) == set(node.moves[-1].parts)
        for half_parts, child in (
            (node.removed_parts, node.removed),
            (tuple(p for p in node.parts if p not in node.removed_parts), node.left),
        ):
            if len(half_parts) == 1:
                ends.append(half_parts)
            else:
                assert child is not None and set(child.parts) == set(half_parts)
                walk(child, offsets)

    if plan.root is None:
        ends.append(tuple(voxels))
    walk(plan.root, {name: np.zeros(3, dtype=np.int64) for name in voxels})
    assert sorted(p for end in ends for p in end) == sorted(voxels)


def test_a_key_leaves_its_cage_by_the_staircase():
    names, voxels = cage_and_key(CHANNEL)
    result = plan_voxels(names, voxels)
    assert result.feasible and result.level == "3" and result.first_moves == 3
    moves = [(m.parts, m.direction, m.distance) for m in result.root.moves]
    assert moves == [
        (("key",), (1, 0, 0), 2),
        (("key",), (0, 1, 0), 2),
        (("key",), (0, 0, 1), None),
    ]
    assert result.root.removed_parts == ("key",)
    replay(result, dict(zip(names, voxels, strict=True)))


def test_a_sealed_cage_is_stuck_and_a_limit_cuts_the_search():
    names, voxels = cage_and_key([(2, 2, 1)])
    sealed = plan_voxels(names, voxels)
    assert not sealed.feasible and not sealed.cut
    assert sealed.root.status == "stuck" and sealed.root.states == 1
    assert sealed.stuck == ("cage", "key") and sealed.level == ""
    cut = plan_voxels(*cage_and_key(CHANNEL), max_states=2)
    assert cut.cut and cut.root.status == "cut" and cut.first_moves is None
    assert "search cut at 2 states" in render(cut).title
    assert cut.to_dict()["cut"] is True


def test_grouped_parts_stay_together():
    # a and c share a group; b lies two cells beyond c along +x, the first removal found
    voxels = [np.array([[0, 0, 0]]), np.array([[1, 0, 0]]), np.array([[3, 0, 0]])]
    result = plan_voxels(["a", "c", "b"], voxels, groups=[1, 1, 0])
    assert result.feasible and result.level == "1"
    assert result.root.removed_parts == ("b",)
    assert [(m.direction, m.distance) for m in result.root.moves] == [((1, 0, 0), None)]
    assert result.root.left.status == "group" and result.root.left.parts == ("a", "c")
    replay(result, dict(zip(["a", "c", "b"], voxels, strict=True)))
    alone = plan_voxels(["a", "c"], voxels[:2], groups=[1, 1])
    assert alone.feasible and alone.root.status == "group" and alone.level == ""


@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(0, 3), min_size=27, max_size=27))
def test_any_packing_of_a_small_box_comes_apart_by_moves_that_replay(owners):
    # each cell of a 3 x 3 x 3 box goes to one of up to four pieces (3: left empty)
    grid = np.array(owners).reshape(3, 3, 3)
    names = [f"p{k}" for k in range(3) if (grid == k).any()]
    voxels = [np.argwhere(grid == int(name[1:])) for name in names]
    result = plan_voxels(names, voxels, max_states=2_000)
    if result.root is not None and result.root.status == "separated":
        assert result.first_moves >= 1 and result.level.startswith(str(result.first_moves))
    if result.feasible:
        replay(result, dict(zip(names, voxels, strict=True)))
    else:
        assert result.stuck


def test_json_has_the_tree_the_level_and_the_plan_keys():
    names, voxels = cage_and_key(CHANNEL)
    data = plan_voxels(names, voxels, reference_level="3").to_dict()
    assert {"feasible", "steps", "stuck", "separations", "level"} <= set(data)
    assert data["level"] == data["reference_level"] == "3"
    assert data["separations"]["moves"][2] == {
        "parts": ["key"],
        "direction": [0, 0, 1],
        "distance": None,
        "together": True,
    }
    assert [s["motion"] for s in data["steps"]] == ["translation"] * 3
    assert all(s["together"] is True and "moves" not in s for s in data["steps"])


def lock_and_keys() -> tuple[list[str], list[np.ndarray]]:
    """A lock bar under two keys in a box (x 0..4, y -1..3, z 0..3). The lock fills
    ``(1, 0..2, 1)`` and rises +z out of three holes in the lid ``(1, 0..2, 3)``
    through ``(1, 0..2, 2)``; the keys, two cells long along x, sit on its ends there,
    ``(1..2, 0, 2)`` and ``(1..2, 2, 2)``. A key is too long for the holes, the box
    holds it on every side but +x, where one empty cell ``(3, y, 2)`` lets it slide by
    exactly 1. The keys are side by side: neither is in the other's way."""
    lock = [(1, 0, 1), (1, 1, 1), (1, 2, 1)]
    first = [(1, 0, 2), (2, 0, 2)]
    second = [(1, 2, 2), (2, 2, 2)]
    empty = [(3, 0, 2), (3, 2, 2), (1, 1, 2), (1, 0, 3), (1, 1, 3), (1, 2, 3)]
    whole = {(x, y, z) for x in range(5) for y in range(-1, 4) for z in range(4)}
    box = sorted(whole - {*lock, *first, *second, *empty})
    return ["box", "lock", "k1", "k2"], [np.array(c) for c in (box, lock, first, second)]


def test_keys_that_slide_side_by_side_move_independently_in_one_move():
    # by hand: the lock leaves only once both keys have slid +x by 1; moving both at once
    # is one move (BurrTools counts a move of several pieces the same way by the same
    # distance as one), then the lock leaves +z: two moves. The keys stop each other
    # nowhere along +x, so the move says they move independently, each by 1 along +x.
    names, voxels = lock_and_keys()
    result = plan_voxels(names, voxels, groups=[1, 0, 1, 1])
    assert result.feasible and result.level == "2"
    slide, leave = result.root.moves
    assert (slide.parts, slide.direction, slide.distance) == (("k1", "k2"), (1, 0, 0), 1)
    assert not slide.together and slide.groups == (("k1",), ("k2",))
    assert (leave.parts, leave.direction, leave.distance) == (("lock",), (0, 0, 1), None)
    assert leave.together
    step = result.to_dict()["steps"][0]
    assert step["together"] is False
    assert step["moves"] == [
        {"parts": ["k1"], "direction": [1.0, 0.0, 0.0], "distance": 1},
        {"parts": ["k2"], "direction": [1.0, 0.0, 0.0], "distance": 1},
    ]
    assert result.to_dict()["steps"][1]["together"] is True
    replay(result, dict(zip(names, voxels, strict=True)))
    # the moves listed, one after another, replay too
    cells = dict(zip(names, voxels, strict=True))
    offsets = {name: np.zeros(3, dtype=np.int64) for name in names}
    for move in step["moves"]:
        for _ in range(move["distance"]):
            for name in move["parts"]:
                offsets[name] = offsets[name] + np.array(move["direction"], dtype=np.int64)
            placed = np.concatenate([cells[n] + offsets[n] for n in names])
            assert len(np.unique(placed, axis=0)) == len(placed)


def test_moving_groups_split_what_does_not_hold_together():
    # "j blocks i" arcs: a pushes b, which nothing holds back: b goes first, then a;
    # c and d block each other and move as one
    assert moving_groups(["a", "b"], [("a", "b")]) == (("b",), ("a",))
    assert moving_groups(["c", "d"], [("c", "d"), ("d", "c")]) == (("c", "d"),)
    assert moving_groups(["a", "b", "c"], [("a", "x")]) == (("a",), ("b",), ("c",))


def test_move_labels_are_the_projects_directions():
    assert Move(("key",), (1, 0, 0), 2).label == "+X"
    assert Move(("key",), (0, 0, -1), None).label == "-Z"
    assert Move(("key",), (0.6, -0.8, 0.0), None).label == "(0.6, -0.8, 0)"


def test_plan_command_moves_multi(capsys):
    code, out, err = run(capsys, "plan", str(STAIRCASE), "--moves", "multi", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["feasible"] and data["level"] == "3" and data["moves"] == "multi"
    # one piece per move: each moves as one rigid group
    assert [s["together"] for s in data["steps"]] == [True, True, True]
    code, out, _ = run(capsys, "plan", str(STAIRCASE), "--moves", "multi")
    assert code == 0 and "first separation: 3 moves" in out
    code, _, err = run(capsys, "plan", str(STAIRCASE), "--moves", "multi", "--solution", "4")
    assert code == 2 and "no solution 4" in err
    gearbox = ROOT / "src" / "assemblykit" / "examples" / "gearbox_demo" / "gearbox.yaml"
    code, _, err = run(capsys, "plan", str(gearbox), "--moves", "multi")
    # gears are meshes too, but need more convex pieces than the mesh search takes
    assert code == 2 and "convex pieces" in err


@pytest.mark.slow
def test_plan_command_on_burrtools_files_compares_with_the_stored_level(capsys):
    pelikan = str(dataset("burrtools/PelikanBurr.xmpuzzle"))
    code, out, err = run(capsys, "plan", pelikan, "--moves", "multi", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["feasible"] and data["first_moves"] == 98
    assert data["level"] == data["reference_level"] == "98.1.2.1.4.2"
    tree = data["separations"]
    assert len(tree["moves"]) == 98 and tree["moves"][-1]["distance"] is None
    assert all(m["distance"] >= 1 for m in tree["moves"][:-1])
    assert len(data["steps"]) == 98 + 1 + 2 + 1 + 4 + 2
    code, out, _ = run(capsys, "plan", pelikan, "--moves", "multi")
    assert code == 0 and "first separation: 98 moves (stored level 98.1.2.1.4.2)" in out
    burrs = str(dataset("burrtools/SolidSixPieceBurrs.xmpuzzle"))
    argv = ("plan", burrs, "--moves", "multi", "--problem", "0", "--solution", "257", "--json")
    code, out, err = run(capsys, *argv)
    assert code == 0, err
    data = json.loads(out)
    assert data["level"] == data["reference_level"] == "1.2.1.1.1"
    second = data["separations"]["left"] or data["separations"]["removed"]
    assert [m["distance"] for m in second["moves"]] == [1, None]
    code, _, err = run(capsys, "plan", burrs, "--moves", "multi", "--problem", "1")
    assert code == 2 and "no problem 1 (the file has 1)" in err


@pytest.mark.parametrize(
    ("name", "level"),
    [
        ("CubeInCage.xmpuzzle", "4.9.3"),
        ("AlPackino.xmpuzzle", "1.1.1.1.1.2.1.3.1.2.1.2"),
        pytest.param("DraculasDentalDesaster.xmpuzzle", "3.5.16.6.4.1.1.1", marks=pytest.mark.slow),
        ("PelikanBurr.xmpuzzle", "98.1.2.1.4.2"),
    ],
)
def test_puzzles_come_apart_in_as_many_moves_as_burrtools_says(name, level):
    puzzle = load_puzzle(dataset(f"burrtools/{name}"))
    result = plan_voxels(
        puzzle.names,
        [p.voxels for p in puzzle.pieces],
        [p.group for p in puzzle.pieces],
        reference_level=puzzle.level,
    )
    assert puzzle.level == level
    assert result.first_moves == int(level.split(".")[0])
    assert result.level == level
    replay(result, {p.name: p.voxels for p in puzzle.pieces})


def line_spans(cells: np.ndarray, axis: int) -> dict[tuple[int, ...], tuple[int, int]]:
    """The lowest and highest coordinate along ``axis`` of the cells on each line
    parallel to it (keyed by the other two coordinates)."""
    spans: dict[tuple[int, ...], tuple[int, int]] = {}
    for cell in cells.tolist():
        key = tuple(cell[:axis] + cell[axis + 1 :])
        low, high = spans.get(key, (cell[axis], cell[axis]))
        spans[key] = (min(low, cell[axis]), max(high, cell[axis]))
    return spans


def has_monotone_plan(voxels: list[np.ndarray]) -> bool:
    """Whether the pieces come apart by single translations to infinity along the axes,
    one subassembly at a time (a monotone two-handed plan), by exhausting the splits:
    a set leaves along +axis iff on every line no cell left behind lies ahead of its
    rearmost cell there."""
    spans = [[line_spans(v, axis) for axis in range(3)] for v in voxels]

    def leaves(moving: tuple[int, ...], staying: tuple[int, ...], axis: int, sign: int) -> bool:
        rear: dict[tuple[int, ...], int] = {}
        for k in moving:
            for key, (low, high) in spans[k][axis].items():
                back = low if sign > 0 else -high  # sign x coordinate of the rearmost cell
                rear[key] = min(rear.get(key, back), back)
        for k in staying:
            for key, (low, high) in spans[k][axis].items():
                if key in rear and (high if sign > 0 else -low) > rear[key]:
                    return False
        return True

    @cache
    def apart(members: tuple[int, ...]) -> bool:
        return len(members) == 1 or any(
            apart(moving)
            and apart(staying)
            and any(leaves(moving, staying, a, s) for a in range(3) for s in (1, -1))
            for size in range(1, len(members))
            for moving in itertools.combinations(members, size)
            for staying in [tuple(m for m in members if m not in moving)]
        )

    return apart(tuple(range(len(voxels))))


@pytest.mark.parametrize("solution", [0, 128, 256, 257, 290, 313])
def test_a_sample_of_six_piece_burrs_comes_apart_at_the_stored_level(solution):
    # solutions 257..313 have no monotone plan: each needs two moves for a separation
    # (every one of the 314 is checked in the slow tier)
    puzzle = load_puzzle(dataset("burrtools/SolidSixPieceBurrs.xmpuzzle"), solution=solution)
    voxels = [p.voxels for p in puzzle.pieces]
    result = plan_voxels(puzzle.names, voxels)
    assert result.feasible and result.level == puzzle.level
    replay(result, {p.name: p.voxels for p in puzzle.pieces})
    monotone = solution < 257
    assert has_monotone_plan(voxels) is monotone
    assert (max(result.root.levels()) > 1) is not monotone


@pytest.mark.slow
def test_every_six_piece_burr_comes_apart_at_the_level_burrtools_stores():
    path = dataset("burrtools/SolidSixPieceBurrs.xmpuzzle")
    assert solution_count(path) == 314
    no_monotone_plan, several_moves = [], []
    for solution in range(314):
        puzzle = load_puzzle(path, solution=solution)
        voxels = [p.voxels for p in puzzle.pieces]
        result = plan_voxels(puzzle.names, voxels)
        assert result.feasible and result.level == puzzle.level, solution
        replay(result, {p.name: p.voxels for p in puzzle.pieces})
        if not has_monotone_plan(voxels):
            no_monotone_plan.append(solution)
        if max(result.root.levels()) > 1:
            several_moves.append(solution)
    # the 57 burrs without a monotone plan are exactly those whose plan (and BurrTools'
    # stored one, level 1.2.1.1.1) needs two moves for a separation: solutions 257..313
    assert no_monotone_plan == several_moves == list(range(257, 314))
