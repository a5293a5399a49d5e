"""BurrTools ``.xmpuzzle`` loading: placements, the stored separation trees, meshes."""

from __future__ import annotations

import gzip
import itertools
from pathlib import Path

import numpy as np
import pytest

from assemblykit.errors import InputError, SchemaError
from assemblykit.io.assembly import load_assembly
from assemblykit.io.burrtools import (
    REMOVED_BEYOND,
    ROTATIONS,
    load_burrtools,
    load_puzzle,
    solution_count,
    voxel_mesh,
)
from datasets import dataset

ROOT = Path(__file__).resolve().parents[2]
STAIRCASE = ROOT / "src" / "assemblykit" / "examples" / "puzzles" / "staircase.xmpuzzle"
# first-separation move counts of BurrTools' stored disassemblies, read off the files
LEVELS = {
    "CubeInCage.xmpuzzle": "4.9.3",
    "DraculasDentalDesaster.xmpuzzle": "3.5.16.6.4.1.1.1",
    "PelikanBurr.xmpuzzle": "98.1.2.1.4.2",
    "AlPackino.xmpuzzle": "1.1.1.1.1.2.1.3.1.2.1.2",
}


def puzzle_xml(shapes: list[tuple[str, str, str]], counts: list[int], assembly: str) -> str:
    """A one-problem puzzle: ``shapes`` as ``(size "x y z", cells, name)``, the last one
    the result; ``counts`` copies of each other shape; one solution ``assembly``."""
    voxels = "".join(
        f'<voxel x="{s.split()[0]}" y="{s.split()[1]}" z="{s.split()[2]}" name="{n}" '
        f'type="0">{cells}</voxel>'
        for s, cells, n in shapes
    )
    uses = "".join(f'<shape id="{i}" count="{c}"/>' for i, c in enumerate(counts))
    return (
        f'<?xml version="1.0"?><puzzle version="2"><gridType type="0"/><shapes>{voxels}'
        f'</shapes><problems><problem time="7"><shapes>{uses}</shapes>'
        f'<result id="{len(shapes) - 1}"/><solutions><solution><assembly>{assembly}'
        "</assembly></solution></solutions></problem></problems></puzzle>"
    )


def cells(array: np.ndarray) -> set[tuple[int, ...]]:
    return {tuple(c) for c in array.tolist()}


def test_rotations_are_the_24_proper_ones_in_burrtools_order():
    assert len({m.tobytes() for m in ROTATIONS}) == 24
    assert all(round(np.linalg.det(m)) == 1 for m in ROTATIONS)
    assert ROTATIONS[0].tolist() == np.eye(3).tolist()
    # by hand: 1 = X (y onto z), 4 = Y (x onto z), 16 = Z (x onto y), 5 = Y then X
    assert (ROTATIONS[1] @ [0, 1, 0]).tolist() == [0, 0, 1]
    assert (ROTATIONS[4] @ [1, 0, 0]).tolist() == [0, 0, 1]
    assert (ROTATIONS[16] @ [1, 0, 0]).tolist() == [0, 1, 0]
    assert (ROTATIONS[20] @ [1, 0, 0]).tolist() == [0, -1, 0]
    assert (ROTATIONS[5] @ [1, 2, 3]).tolist() == [-2, -3, 1]


def two_trominoes(folder: Path) -> Path:
    """A puzzle of two L trominoes (0,0,0), (1,0,0), (0,1,0), the second placed by
    transform 5, which sends (x, y, z) to (-y, -z, x)."""
    tromino = ("2 2 1", "###_", "L")
    result = ("3 3 3", "#" * 27, "Result")
    path = folder / "l.xmpuzzle"
    path.write_bytes(gzip.compress(puzzle_xml([tromino, result], [2], "0 0 0 0 2 2 0 5").encode()))
    return path


def test_pieces_are_placed_by_transform_and_position(tmp_path):
    puzzle = load_puzzle(two_trominoes(tmp_path))
    assert puzzle.names == ["L-1", "L-2"]
    assert cells(puzzle.pieces[0].voxels) == {(0, 0, 0), (1, 0, 0), (0, 1, 0)}
    assert cells(puzzle.pieces[1].voxels) == {(2, 2, 0), (2, 2, 1), (1, 2, 0)}
    assert puzzle.time == 7.0 and puzzle.separation is None and puzzle.level is None
    assert len(puzzle.filled) == 27 and len(puzzle.variable) == 0


def test_colours_and_unused_copies_are_read(tmp_path):
    bar = ("2 1 1", "#1#2", "Bar")
    result = ("2 2 1", "##+2+", "Result")
    text = puzzle_xml([bar, result], [3], "x 0 1 0 0 x").replace('count="3"', 'max="3"')
    path = tmp_path / "bar.xmpuzzle"
    path.write_text(text)  # an uncompressed file reads too
    puzzle = load_puzzle(path)
    assert puzzle.names == ["Bar-2"]
    assert cells(puzzle.pieces[0].voxels) == {(0, 1, 0), (1, 1, 0)}
    assert cells(puzzle.variable) == {(0, 1, 0), (1, 1, 0)}


@pytest.mark.parametrize(
    ("assembly", "error", "message"),
    [
        ("0 0 0 0 0 0 0 0", InputError, "overlap"),
        ("0 0 0 0 1 0 0 30", InputError, "mirrored transform 30"),
        ("0 0 0 0 1 0 0 48", SchemaError, "not one of 0..47"),
        ("0 0 0 0 1 0", SchemaError, "fewer pieces"),
        ("0 0 0 0 1 0 0 0 0", SchemaError, "more pieces"),
        ("0 0 0 0 1 0 zero 0", SchemaError, "expected an integer"),
    ],
)
def test_bad_solutions_name_the_fault(tmp_path, assembly, error, message):
    cube = ("1 1 1", "#", "Cube")
    path = tmp_path / "bad.xmpuzzle"
    path.write_text(puzzle_xml([cube, ("2 1 1", "##", "Result")], [2], assembly))
    with pytest.raises(error, match=message) as raised:
        load_puzzle(path)
    assert str(path) in str(raised.value)


def test_bad_files_and_choices_are_input_errors(tmp_path):
    broken = tmp_path / "broken.xmpuzzle"
    broken.write_text("<puzzle><shapes>")
    with pytest.raises(SchemaError, match="malformed XML"):
        load_puzzle(broken)
    entity = tmp_path / "entity.xmpuzzle"
    entity.write_text('<!DOCTYPE p [<!ENTITY a "b">]><puzzle/>')
    with pytest.raises(SchemaError, match="document type"):
        load_puzzle(entity)
    with pytest.raises(InputError, match="no solution 1"):
        load_puzzle(STAIRCASE, solution=1)
    with pytest.raises(InputError, match="no problem 2"):
        load_puzzle(STAIRCASE, problem=2)
    cube = ("1 1 1", "##", "Cube")
    short = tmp_path / "short.xmpuzzle"
    short.write_text(puzzle_xml([cube, cube], [1], "0 0 0 0"))
    with pytest.raises(SchemaError, match="2 cells for a 1x1x1 shape"):
        load_puzzle(short)


def test_voxel_meshes_are_closed_unit_cubes_even_when_touching_along_an_edge():
    bar = voxel_mesh(np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0]]))
    assert bar.is_watertight and bar.volume == pytest.approx(3.0)
    assert bar.bounds.tolist() == [[0, 0, 0], [3, 1, 1]]
    diagonal = voxel_mesh(np.array([[0, 0, 0], [1, 1, 0]]))
    assert diagonal.is_watertight and diagonal.volume == pytest.approx(2.0)
    # one piece touching itself along the edge x = y = 1, joined through the layer above
    loop = voxel_mesh(np.array([[0, 0, 0], [1, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1]]))
    assert loop.is_watertight and loop.volume == pytest.approx(5.0)
    assert len(loop.faces) == 2 * 22  # 30 squares of five cubes less 4 shared pairs


def test_load_assembly_reads_the_bundled_staircase():
    assembly = load_assembly(STAIRCASE)
    assert assembly.names == ["Cage", "Key"]
    assert assembly["Key"].volume == pytest.approx(1.0)
    assert assembly["Cage"].volume == pytest.approx(5 * 5 * 3 - 6)
    assert assembly.puzzle.names == ["Cage", "Key"]
    assert load_burrtools(STAIRCASE).source == str(STAIRCASE)


def test_a_puzzle_file_is_read_again_when_its_bytes_change(tmp_path):
    path = tmp_path / "puzzle.xmpuzzle"
    path.write_bytes(STAIRCASE.read_bytes())
    assert load_puzzle(path).names == ["Cage", "Key"]
    nested = ROOT / "src" / "assemblykit" / "examples" / "interlocking" / "nested_locks.xmpuzzle"
    path.write_bytes(nested.read_bytes())
    assert load_puzzle(path).names == load_puzzle(nested).names != ["Cage", "Key"]


def replay_stored(puzzle, node, origin: dict[int, np.ndarray]) -> None:
    """Check a stored separation independently: each state moves one set of pieces by
    one lattice vector, with no two pieces sharing a cell at any unit step, until the
    last state takes a set beyond ``REMOVED_BEYOND``; each half starts where its pieces
    were. ``origin`` holds each piece's position in the solution."""
    states = node.states
    assert len(states) >= 2
    for number, (before, after) in enumerate(itertools.pairwise(states)):
        step = after - before
        moved = set(np.flatnonzero(np.any(step != 0, axis=1)).tolist())
        assert moved
        if (np.abs(after) >= REMOVED_BEYOND).any():
            assert number == len(states) - 2
            gone = {node.pieces[k] for k in moved}
            kept = set(node.pieces) - gone
            halves = {frozenset(c.pieces) for c in (node.removed, node.left) if c is not None}
            assert halves <= {frozenset(gone), frozenset(kept)}
            continue
        assert len({tuple(step[k]) for k in moved}) == 1
        vector = step[next(iter(moved))]
        assert np.count_nonzero(vector) == 1
        for unit in range(1, int(np.abs(vector).sum()) + 1):
            seen: set[tuple[int, ...]] = set()
            for k, piece in enumerate(node.pieces):
                shift = before[k] - origin[piece] + (unit * np.sign(vector) if k in moved else 0)
                placed = cells(puzzle.pieces[piece].voxels + shift)
                assert not placed & seen
                seen |= placed
    index = {p: k for k, p in enumerate(node.pieces)}
    for child in (node.removed, node.left):
        if child is not None:
            # a half starts where its pieces were, up to one translation of the whole half
            delta = child.states[0] - np.array([states[-2][index[p]] for p in child.pieces])
            assert (delta == delta[0]).all()
            replay_stored(puzzle, child, {p: origin[p] + delta[0] for p in child.pieces})


@pytest.mark.parametrize("name", sorted(LEVELS))
def test_stored_solutions_fill_the_result_and_their_separations_replay(name):
    puzzle = load_puzzle(dataset(f"burrtools/{name}"))
    union = [c for p in puzzle.pieces for c in cells(p.voxels)]
    assert len(union) == len(set(union))  # no overlap
    assert cells(puzzle.filled) <= set(union) <= cells(puzzle.filled) | cells(puzzle.variable)
    assert puzzle.level == LEVELS[name]
    for piece in load_burrtools(dataset(f"burrtools/{name}")):
        assert piece.mesh.is_watertight
    volumes = [p.volume for p in load_burrtools(dataset(f"burrtools/{name}"))]
    assert volumes == pytest.approx([len(p.voxels) for p in puzzle.pieces])
    root = puzzle.separation
    assert sorted(root.pieces) == list(range(len(puzzle.pieces)))
    replay_stored(puzzle, root, dict(zip(root.pieces, root.states[0], strict=True)))


@pytest.mark.parametrize(
    ("info", "level"),
    [
        ("2 0 0", "1"),
        ("2 3 2 2 2 0 0 0 0 0 0", "1.2.1.1.1"),
        ("5 0 10 0 0 | 0 0 1 0 0", "4.9"),
        ("", None),
        ("2 0", None),
        ("2 0 0 0", None),
        ("2 -1 0", None),
    ],
)
def test_separation_info_gives_the_level(tmp_path, info, level):
    cube = ("1 1 1", "#", "Cube")
    text = puzzle_xml([cube, ("2 1 1", "##", "Result")], [2], "0 0 0 0 1 0 0 0").replace(
        "</assembly>", f"</assembly><separationInfo>{info}</separationInfo>"
    )
    path = tmp_path / "info.xmpuzzle"
    path.write_text(text)
    if level is None:
        with pytest.raises(SchemaError, match="separation tree") as raised:
            load_puzzle(path)
        assert "separationInfo" in str(raised.value)
    else:
        assert load_puzzle(path).level == level


def test_every_six_piece_burr_fills_the_knot():
    path = dataset("burrtools/SolidSixPieceBurrs.xmpuzzle")
    assert solution_count(path) == 314
    for solution in (0, 57, 313):
        puzzle = load_puzzle(path, solution=solution)
        union = [c for p in puzzle.pieces for c in cells(p.voxels)]
        assert len(puzzle.pieces) == 6 and len(union) == len(set(union))
        assert set(union) == cells(puzzle.filled)
    # each solution stores only the shape of BurrTools' separation tree (separationInfo)
    levels = [load_puzzle(path, solution=s).level for s in range(314)]
    assert levels == ["1.1.1.1.1"] * 257 + ["1.2.1.1.1"] * 57


def test_a_voxel_assembly_is_an_assembly_of_meshes_of_kind_voxels(tmp_path):
    path = two_trominoes(tmp_path)
    loaded = load_burrtools(path)
    assert (loaded.dimension, loaded.kind) == (3, "voxels")
    part = loaded.subset(["L-2"])
    assert part.kind == "voxels" and part.puzzle.names == ["L-2"]
    assert load_assembly(path).kind == "voxels"
