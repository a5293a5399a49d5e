"""Multi-move disassembly of voxel pieces, every plan replayed cell by cell."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from assemblykit.cli import main
from assemblykit.io.burrtools import load_puzzle
from assemblykit.planning.multimove import MultiMovePlan, Separation, plan_voxels
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
    of each separation leaves the rest behind for good, and that every part ends alone
    or in a kept group."""
    cells = {name: {tuple(c) for c in v.tolist()} for name, v in voxels.items()}
    ends: list[tuple[str, ...]] = []

    def shifted(name: str, offset: np.ndarray) -> set[tuple[int, ...]]:
        return {(x + offset[0], y + offset[1], z + offset[2]) for x, y, z in cells[name]}

    def disjoint(parts: tuple[str, ...], offsets: dict[str, np.ndarray]) -> bool:
        placed = np.concatenate([voxels[name] + offsets[name] for name in parts])
        return len(np.unique(placed, axis=0)) == len(placed)

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
            span = max(np.ptp(np.array(sorted(cells[n])), axis=0).max() for n in node.parts)
            steps = move.distance if move.distance is not None else int(span) + 60
            for _ in range(steps):
                for name in move.parts:
                    offsets[name] = offsets[name] + direction
                assert disjoint(node.parts, offsets)
            if move.distance is None:
                rest = set(node.parts) - set(move.parts)
                gone = set().union(*(shifted(n, offsets[n]) for n in move.parts))
                stay = set().union(*(shifted(n, offsets[n]) for n in rest))
                axis = int(np.flatnonzero(direction)[0])
                sign = int(direction[axis])
                # the moved parts now lie wholly beyond the rest along the move
                assert min(sign * c[axis] for c in gone) > max(sign * c[axis] for c in stay)
                for name in move.parts:
                    offsets[name] = offsets[name] - steps * direction
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
    assert "search cut at 2 states" in cut.render().title
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
    }
    assert [s["motion"] for s in data["steps"]] == ["translation"] * 3


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    try:
        main(list(argv))
        code = 0
    except SystemExit as done:
        code = int(done.code or 0)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_plan_command_moves_multi(capsys):
    code, out, err = run(capsys, "plan", str(STAIRCASE), "--moves", "multi", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["feasible"] and data["level"] == "3" and data["moves"] == "multi"
    code, out, _ = run(capsys, "plan", str(STAIRCASE), "--moves", "multi")
    assert code == 0 and "first separation: 3 moves" in out
    code, _, err = run(capsys, "plan", str(STAIRCASE), "--moves", "multi", "--solution", "4")
    assert code == 2 and "no solution 4" in err
    gearbox = ROOT / "src" / "assemblykit" / "examples" / "gearbox_demo" / "gearbox.yaml"
    code, _, err = run(capsys, "plan", str(gearbox), "--moves", "multi")
    assert code == 2 and ".xmpuzzle" in err


@pytest.mark.parametrize(
    ("name", "level"),
    [
        ("CubeInCage.xmpuzzle", "4.9.3"),
        ("AlPackino.xmpuzzle", "1.1.1.1.1.2.1.3.1.2.1.2"),
        ("DraculasDentalDesaster.xmpuzzle", "3.5.16.6.4.1.1.1"),
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


# solutions 257..313 are the 57 burrs whose second separation needs two moves
@pytest.mark.parametrize(
    ("solution", "level"),
    [(0, "1.1.1.1.1"), (257, "1.2.1.1.1"), (285, "1.2.1.1.1"), (313, "1.2.1.1.1")],
)
def test_six_piece_burrs_with_and_without_a_monotone_plan(solution, level):
    puzzle = load_puzzle(dataset("burrtools/SolidSixPieceBurrs.xmpuzzle"), solution=solution)
    result = plan_voxels(puzzle.names, [p.voxels for p in puzzle.pieces])
    assert result.feasible and result.level == level
    replay(result, {p.name: p.voxels for p in puzzle.pieces})
