"""BurrTools puzzles (``.xmpuzzle``): voxel pieces placed as in a stored solution.

A ``.xmpuzzle`` file is gzip-compressed XML. Each ``<voxel>`` shape lists its cells x
fastest, then y, then z: ``#`` filled, ``+`` variable, ``_`` empty, each optionally
followed by a colour number. A problem names the shapes it uses (``count`` copies, or
``max`` for a piece range, whose unused copies a solution marks ``x``), the result shape,
and its solutions; a solution places every piece as ``x y z transform``.

Placement convention (worked out from the files and checked against every stored
solution and separation, see ``tests/io/test_burrtools.py``): a shape cell ``v`` lands
on ``R_t v + (x, y, z)``, i.e. the hotspot is the shape's origin cell and turns with it.
The 24 proper rotations are numbered ``t = 4 q + a``: first ``a`` quarter turns ``X``
(+y onto +z), then ``q`` quarter turns ``Y`` (+x onto +z) for ``q = 0..3``, one quarter
turn ``Z`` (+x onto +y) for ``q = 4`` and three for ``q = 5``; so transform 5 takes
``(x, y, z)`` to ``(-y, -z, x)``. Transforms 24..47 are mirror images, which no stored
solution uses; they are refused.

A ``<separation>`` tree is BurrTools' own disassembly: the pieces of a subassembly, the
positions of each piece after every move (a coordinate beyond :data:`REMOVED_BEYOND` means
"gone to infinity"), and the subassemblies ``removed`` and ``left`` by the separation.
Its *level* is the number of moves of each separation, in that order (``4.9.3``).
Files that keep only the shape of that tree store a ``<separationInfo>`` instead: the
tree in pre-order, one number per node, ``moves + 1`` for a separation (followed by its
two halves) and ``0`` for a half that is not separated further; its level lists the
nonzero numbers less one (``2 3 2 2 2 0 0 0 0 0 0`` is ``1.2.1.1.1``).
"""

from __future__ import annotations

import gzip
import io
import re
import zlib
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace
from functools import lru_cache
from pathlib import Path
from typing import ClassVar, Literal, Self
from xml.etree import ElementTree

import numpy as np
import trimesh
from numpy.typing import NDArray

from assemblykit.errors import GeometryError, InputError, SchemaError
from assemblykit.graphs import component_labels
from assemblykit.model.assembly import Assembly, Part
from assemblykit.tolerance import Tolerance

MAX_XML_BYTES = 64 * 2**20
"""Largest decompressed document read: a hundred times the largest known puzzle file, and
small enough that a compressed "zip bomb" is refused before it fills memory."""

MAX_CELLS = 10**7
"""Most cells one shape may declare (x * y * z)."""

REMOVED_BEYOND = 10_000
"""A separation state coordinate this far out means the piece has left (BurrTools adds
30,000 to the coordinate of removed pieces)."""

_CELL = re.compile(r"([#+_])\d*")


def _rotations() -> tuple[NDArray[np.int64], ...]:
    """BurrTools' 24 proper rotations in its numbering (module docstring)."""
    power = np.linalg.matrix_power
    x = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], dtype=np.int64)  # +y onto +z
    y = np.array([[0, 0, -1], [0, 1, 0], [1, 0, 0]], dtype=np.int64)  # +x onto +z
    z = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1]], dtype=np.int64)  # +x onto +y
    turns = [power(y, q) for q in range(4)] + [z, power(z, 3)]
    return tuple(turns[t // 4] @ power(x, t % 4) for t in range(24))


ROTATIONS = _rotations()
"""``ROTATIONS[t]`` is the matrix of BurrTools' transform ``t`` (0..23)."""


@dataclass(frozen=True)
class VoxelPiece:
    """One placed piece: its ``name``, the ``shape`` index it was made from, its
    ``group`` (pieces of one nonzero group may stay together) and its filled ``voxels``
    as an ``(N, 3)`` integer array of lattice cells in the assembled position."""

    name: str
    shape: int
    group: int
    voxels: NDArray[np.int64]


@dataclass(frozen=True)
class StoredSeparation:
    """A node of a stored separation tree: the ``pieces`` (indices into the puzzle's
    pieces), the piece positions after each move (``states``, shape
    ``(moves + 1, len(pieces), 3)``), and the ``removed`` and ``left`` subassemblies."""

    pieces: tuple[int, ...]
    states: NDArray[np.int64]
    removed: StoredSeparation | None
    left: StoredSeparation | None

    @property
    def moves(self) -> int:
        """Moves of this separation, the last one taking a subassembly to infinity."""
        return max(len(self.states) - 1, 0)

    def levels(self) -> tuple[int, ...]:
        """Move counts of this separation and then of every separation below it,
        ``removed`` before ``left`` (the order of :attr:`VoxelPuzzle.level`)."""
        below = [s.levels() for s in (self.removed, self.left) if s is not None]
        return (self.moves, *(n for part in below for n in part))


@dataclass(frozen=True)
class VoxelPuzzle:
    """A BurrTools puzzle as assembled by one stored solution: its ``pieces``, the
    result shape's ``filled`` and ``variable`` cells, BurrTools' own ``separation`` tree
    (when stored), the solver ``time`` the file records for the problem (seconds) and
    the move counts of a ``<separationInfo>`` (``separation_levels``, when stored
    instead of the tree)."""

    source: str
    pieces: tuple[VoxelPiece, ...]
    filled: NDArray[np.int64]
    variable: NDArray[np.int64]
    separation: StoredSeparation | None
    time: float | None
    separation_levels: tuple[int, ...] | None = None

    @property
    def names(self) -> list[str]:
        """Piece names in order."""
        return [p.name for p in self.pieces]

    @property
    def level(self) -> str | None:
        """BurrTools' level of the stored separation tree or, without one, of the
        stored ``<separationInfo>`` (``4.9.3``); None when the file stores neither."""
        if self.separation is not None:
            levels = self.separation.levels()
        elif self.separation_levels is not None:
            levels = self.separation_levels
        else:
            return None
        return ".".join(str(n) for n in levels)


PARSED_KEPT = 16
"""How many parsed puzzle documents are kept (:func:`_parsed`): a file of many puzzles
(every six-piece burr) is parsed once for all its solutions."""


def _document(path: Path) -> ElementTree.Element:
    """The parsed XML of the puzzle file at ``path`` (:func:`_parsed` of its bytes)."""
    source = str(path)
    try:
        raw = path.read_bytes()
    except OSError as error:
        raise InputError(f"cannot read the puzzle: {error.strerror}", source=source) from None
    return _parsed(raw, source)


@lru_cache(maxsize=PARSED_KEPT)
def _parsed(raw: bytes, source: str) -> ElementTree.Element:
    """The XML document of a puzzle file's bytes ``raw`` (gzip-compressed or not), read
    from ``source`` (named in errors); kept per bytes and source, the last
    :data:`PARSED_KEPT` of them (a pure function of immutable values)."""
    try:
        with gzip.GzipFile(fileobj=io.BytesIO(raw)) as stream:
            data = stream.read(MAX_XML_BYTES + 1)
    except (OSError, EOFError, zlib.error):
        data = raw  # an uncompressed .xmpuzzle is read as it is
    if len(data) > MAX_XML_BYTES:
        raise InputError(f"decompresses to more than {MAX_XML_BYTES} bytes", source=source)
    if b"<!DOCTYPE" in data or b"<!ENTITY" in data:
        raise SchemaError("document type declarations are not accepted", source=source)
    try:
        return ElementTree.fromstring(data)
    except ElementTree.ParseError as error:
        line, column = error.position
        raise SchemaError(
            "malformed XML", source=source, where=f"line {line}, column {column + 1}"
        ) from None


def _integer(text: str | None, source: str, where: str) -> int:
    try:
        return int(text or "")
    except ValueError:
        raise SchemaError(
            f"expected an integer, found {text!r}", source=source, where=where
        ) from None


def _integers(text: str | None, source: str, where: str) -> list[int]:
    return [_integer(token, source, where) for token in (text or "").split()]


def _shape(element: ElementTree.Element, index: int, source: str) -> dict[str, NDArray[np.int64]]:
    """The filled and variable cells of a ``<voxel>`` shape."""
    where = f"shape {index}"
    if element.tag != "voxel":
        raise SchemaError(f"unknown shape element <{element.tag}>", source=source, where=where)
    if element.get("type", "0") != "0":
        raise SchemaError("only the cube grid (type 0) is supported", source=source, where=where)
    size = [_integer(element.get(k), source, where) for k in "xyz"]
    if min(size) < 0 or int(np.prod(size)) > MAX_CELLS:
        raise SchemaError(f"bad shape size {size}", source=source, where=where)
    text = re.sub(r"\s+", "", element.text or "")
    cells = _CELL.findall(text)
    if len(cells) != int(np.prod(size)) or "".join(_CELL.sub("", text)):
        raise SchemaError(
            f"{len(cells)} cells for a {size[0]}x{size[1]}x{size[2]} shape",
            source=source,
            where=where,
        )
    grid = np.array(cells, dtype="<U1").reshape(size[2], size[1], size[0]).transpose(2, 1, 0)
    return {kind: np.argwhere(grid == kind).astype(np.int64) for kind in "#+"}


def _separation(element: ElementTree.Element, source: str, where: str) -> StoredSeparation:
    pieces_element = element.find("pieces")
    pieces = tuple(
        _integers(None if pieces_element is None else pieces_element.text, source, where)
    )
    states = []
    for k, state in enumerate(element.findall("state")):
        axes = [
            _integers(state.findtext(tag), source, f"{where} state {k}")
            for tag in ("dx", "dy", "dz")
        ]
        if any(len(a) != len(pieces) for a in axes):
            raise SchemaError(
                f"state {k} does not give one position per piece", source=source, where=where
            )
        states.append(np.array(axes, dtype=np.int64).T)
    removed = left = None
    for child in element.findall("separation"):
        kind = child.get("type")
        node = _separation(child, source, f"{where}/{kind}")
        if kind == "removed":
            removed = node
        elif kind == "left":
            left = node
        else:
            raise SchemaError(f"unknown separation type {kind!r}", source=source, where=where)
    shaped = np.array(states, dtype=np.int64).reshape(len(states), len(pieces), 3)
    return StoredSeparation(pieces, shaped, removed, left)


def _separation_levels(text: str | None, source: str, where: str) -> tuple[int, ...]:
    """The move counts of a ``<separationInfo>`` pre-order tree (module docstring);
    rotation counts that newer files append after ``|`` are not read."""
    values = _integers((text or "").split("|")[0], source, where)
    open_ends = 1
    for position, value in enumerate(values):
        if value < 0 or open_ends == 0:
            raise SchemaError(
                f"bad separation tree at value {position}: {value}", source=source, where=where
            )
        open_ends += 1 if value else -1
    if open_ends:
        raise SchemaError("the separation tree is incomplete", source=source, where=where)
    return tuple(value - 1 for value in values if value)


def _placed(
    cells: NDArray[np.int64], words: Sequence[str], source: str, where: str
) -> NDArray[np.int64]:
    numbers = [_integer(w, source, where) for w in words]
    transform = numbers[3]
    if not 0 <= transform < 48:
        raise SchemaError(f"transform {transform} is not one of 0..47", source=source, where=where)
    if transform >= 24:
        raise InputError(
            f"mirrored transform {transform} is not supported", source=source, where=where
        )
    return cells @ ROTATIONS[transform].T + np.array(numbers[:3], dtype=np.int64)


def _overlap(pieces: Sequence[VoxelPiece]) -> tuple[str, str] | None:
    """The first two pieces sharing a cell, or None."""
    owner: dict[tuple[int, ...], str] = {}
    for piece in pieces:
        for cell in map(tuple, piece.voxels.tolist()):
            if cell in owner:
                return owner[cell], piece.name
            owner[cell] = piece.name
    return None


def _problem(root: ElementTree.Element, problem: int, source: str) -> ElementTree.Element:
    problems = root.findall("problems/problem")
    if not 0 <= problem < len(problems):
        raise InputError(
            f"no problem {problem} (the file has {len(problems)})", source=source, where="--problem"
        )
    return problems[problem]


def solution_count(path: str | Path, problem: int = 0) -> int:
    """How many solutions problem ``problem`` of the puzzle at ``path`` stores."""
    path = Path(path)
    return len(
        _problem(_document(path.resolve()), problem, str(path)).findall("solutions/solution")
    )


def load_puzzle(path: str | Path, problem: int = 0, solution: int = 0) -> VoxelPuzzle:
    """Problem ``problem``'s stored solution ``solution`` of the BurrTools file ``path``
    (module docstring), with its pieces in assembled position. :class:`InputError`
    naming the file and place for a malformed file, a missing problem or solution, or a
    solution whose pieces overlap."""
    path = Path(path)
    source = str(path)
    root = _document(path.resolve())
    if root.tag != "puzzle":
        raise SchemaError("not a BurrTools puzzle (no <puzzle> root)", source=source)
    grid = root.find("gridType")
    if grid is not None and grid.get("type", "0") != "0":
        raise SchemaError("only the cube grid (gridType 0) is supported", source=source)
    shapes_element = root.find("shapes")
    elements = [] if shapes_element is None else list(shapes_element)
    shapes = [_shape(e, i, source) for i, e in enumerate(elements)]
    names = [e.get("name") for e in elements]
    chosen = _problem(root, problem, source)
    where = f"problem {problem}"

    def shape_index(text: str | None, what: str) -> int:
        index = _integer(text, source, f"{where} {what}")
        if not 0 <= index < len(shapes):
            raise SchemaError(f"no shape {index}", source=source, where=f"{where} {what}")
        return index

    slots: list[tuple[int, int, str]] = []
    for entry in chosen.findall("shapes/shape"):
        index = shape_index(entry.get("id"), "shape")
        copies = _integer(entry.get("count") or entry.get("max") or "1", source, where)
        base = names[index] or f"S{index + 1}"
        group = _integer(entry.get("group") or "0", source, where)
        for copy in range(copies):
            label = base if copies == 1 else f"{base}-{copy + 1}"
            slots.append((index, group, label))
    result_element = chosen.find("result")
    result = shapes[
        shape_index(None if result_element is None else result_element.get("id"), "result")
    ]
    solutions = chosen.findall("solutions/solution")
    if not 0 <= solution < len(solutions):
        raise InputError(
            f"no solution {solution} in {where} (it stores {len(solutions)})",
            source=source,
            where="--solution",
        )
    stored = solutions[solution]
    words = (stored.findtext("assembly") or "").split()
    pieces: list[VoxelPiece] = []
    taken: list[int] = []  # slot of each placed piece, to renumber the separation tree
    position = 0
    for slot, (index, group, label) in enumerate(slots):
        here = f"{where} solution {solution} piece {slot}"
        if position < len(words) and words[position] == "x":
            position += 1
            continue
        if position + 4 > len(words):
            raise SchemaError(
                "the assembly places fewer pieces than the problem has", source=source, where=here
            )
        voxels = _placed(shapes[index]["#"], words[position : position + 4], source, here)
        pieces.append(VoxelPiece(label, index, group, voxels))
        taken.append(slot)
        position += 4
    if position != len(words):
        raise SchemaError(
            "the assembly places more pieces than the problem has", source=source, where=where
        )
    clash = _overlap(pieces)
    if clash is not None:
        raise InputError(
            f"pieces {clash[0]} and {clash[1]} overlap in solution {solution}",
            source=source,
            where=where,
        )
    tree = stored.find("separation")
    separation = None if tree is None else _separation(tree, source, f"{where} separation")
    info = stored.find("separationInfo")
    levels = (
        None
        if info is None
        else _separation_levels(info.text, source, f"{where} solution {solution} separationInfo")
    )
    seconds = chosen.get("time")
    return VoxelPuzzle(
        source,
        tuple(pieces),
        result["#"],
        result["+"],
        separation,
        None if seconds is None else float(_integer(seconds, source, where)),
        levels,
    )


_CUBE = ((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1))
# the outward quad (counter-clockwise seen from outside) of each face direction
_QUADS = {
    (-1, 0, 0): (0, 4, 7, 3),
    (1, 0, 0): (1, 2, 6, 5),
    (0, -1, 0): (0, 1, 5, 4),
    (0, 1, 0): (3, 7, 6, 2),
    (0, 0, -1): (0, 3, 2, 1),
    (0, 0, 1): (4, 5, 6, 7),
}


def voxel_mesh(voxels: NDArray[np.int64], source: str | None = None) -> trimesh.Trimesh:
    """The closed surface of a union of unit cubes (cell ``c`` spans ``[c, c + 1]``): the
    faces between a filled and an empty cell.

    Cubes touching along an edge only (four faces on one edge) are joined through faces
    only: at such an edge each cube's two faces keep vertices of their own, so the
    surface is a closed 2-manifold even where a piece touches itself along an edge (the
    repair of :func:`assemblykit.io.meshes.repaired` handles separate solids only).
    :class:`GeometryError` names ``source`` if the result is not closed."""
    filled: set[tuple[int, int, int]] = {(x, y, z) for x, y, z in voxels.tolist()}
    corners: list[list[tuple[int, int, int]]] = []
    owner: list[tuple[int, int, int]] = []
    for x, y, z in sorted(filled):
        for (ux, uy, uz), quad in _QUADS.items():
            if (x + ux, y + uy, z + uz) not in filled:
                corners.append(
                    [(x + dx, y + dy, z + dz) for dx, dy, dz in (_CUBE[k] for k in quad)]
                )
                owner.append((x, y, z))
    # corner slot 4 q + k of quad q; slots across an edge two quads share are one vertex
    sides: dict[tuple[tuple[int, int, int], ...], list[int]] = {}
    for q, ring in enumerate(corners):
        for k in range(4):
            sides.setdefault(tuple(sorted((ring[k], ring[(k + 1) % 4]))), []).append(q)
    joins: list[tuple[int, int]] = []
    for edge, quads in sides.items():
        pairs = [tuple(quads)] if len(quads) == 2 else []
        if len(quads) == 4:  # two cubes meeting along the edge: pair faces of one cube
            pairs = [
                tuple(q for q in quads if owner[q] == cell) for cell in {owner[q] for q in quads}
            ]
        for first, second in pairs:
            for point in edge:
                joins.append(
                    (
                        4 * first + corners[first].index(point),
                        4 * second + corners[second].index(point),
                    )
                )
    slots = 4 * len(corners)
    links = np.array(joins, dtype=np.int64).reshape(-1, 2)
    label = component_labels(slots, links)
    positions = np.zeros((label.max() + 1 if slots else 0, 3), dtype=np.float64)
    positions[label] = np.array(corners, dtype=np.float64).reshape(-1, 3)
    corner_of = label.reshape(-1, 4)
    faces = np.concatenate([corner_of[:, [0, 1, 2]], corner_of[:, [0, 2, 3]]])
    mesh = trimesh.Trimesh(positions, faces, process=False)
    if not mesh.is_watertight or len(faces) == 0:
        raise GeometryError("the voxel piece has no closed surface", source=source)
    return mesh


class VoxelAssembly(Assembly):
    """An :class:`Assembly` of a BurrTools puzzle's pieces (unit-cube meshes) that keeps
    the :class:`VoxelPuzzle` for planning on the lattice (``puzzle``)."""

    kind: ClassVar[Literal["meshes", "voxels"]] = "voxels"

    def __init__(self, puzzle: VoxelPuzzle, tol: Tolerance | None = None) -> None:
        parts = [
            Part(p.name, voxel_mesh(p.voxels, f"{puzzle.source}: {p.name}"), source=puzzle.source)
            for p in puzzle.pieces
        ]
        super().__init__(parts, units="unit", units_source="file", source=puzzle.source, policy=tol)
        self.puzzle = puzzle

    @classmethod
    def like(
        cls, other: Assembly, parts: Iterable[Part] | None = None, scale: float | None = None
    ) -> Self:
        """:meth:`Assembly.like` (a subset of the pieces, as when a stuck set is
        explained) that keeps the puzzle's pieces among ``parts``."""
        plain = Assembly.like(other, parts, scale)
        derived = cls.__new__(cls)
        vars(derived).update(vars(plain))
        puzzle = getattr(other, "puzzle", None)
        if isinstance(puzzle, VoxelPuzzle):
            kept = tuple(p for p in puzzle.pieces if p.name in plain.parts)
            derived.puzzle = replace(puzzle, pieces=kept)
        return derived


def load_burrtools(
    path: str | Path, tol: Tolerance | None = None, problem: int = 0, solution: int = 0
) -> VoxelAssembly:
    """The puzzle at ``path`` (:func:`load_puzzle`) as an assembly of meshes."""
    return VoxelAssembly(load_puzzle(path, problem, solution), tol)
