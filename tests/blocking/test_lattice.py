"""Blocking of parts made of unit cells decided on the cells (blocking/lattice.py),
against hand-placed cubes and against the projection of the same parts' meshes
(``blocking.extended.projected_arcs``) on six-piece burrs along every lattice
direction."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from assemblykit.blocking.extended import extended_arcs, projected_arcs
from assemblykit.blocking.lattice import cells_block, lattice_direction
from assemblykit.io.burrtools import load_burrtools, voxel_mesh
from assemblykit.model.assembly import Assembly, Part
from assemblykit.tolerance import Tolerance
from datasets import dataset

LATTICE = [e for e in itertools.product((-1, 0, 1), repeat=3) if any(e)]
ONE = np.array([[0, 0, 0]])


@pytest.mark.parametrize(
    ("offset", "direction", "blocks"),
    [
        ((2, 0, 0), (1, 0, 0), True),  # ahead, in line
        ((2, 0, 0), (-1, 0, 0), False),  # behind
        ((2, 1, 0), (1, 0, 0), False),  # beside the line: faces touch the sweep only
        ((1, 1, 0), (1, 1, 0), True),  # on the diagonal
        ((2, 1, 0), (1, 1, 0), True),  # a cell off the diagonal: the sweep cuts its corner
        ((3, 1, 0), (1, 1, 0), False),  # two off: edges meet, interiors do not
        ((1, 1, 1), (1, 1, 0), False),  # out of the plane of the move
        ((2, 2, 1), (1, 1, 1), True),
        ((2, 2, 0), (1, 1, 1), False),
    ],
)
def test_a_cube_blocks_another_as_drawn_by_hand(offset, direction, blocks):
    still = np.array([offset])
    assert cells_block(ONE, still, np.array(direction)) is blocks


def test_a_lattice_direction_is_one_within_the_angle_tolerance():
    tol = Tolerance()
    diagonal = np.array([1.0, 1.0, 0.0]) / np.sqrt(2)
    assert lattice_direction(diagonal, tol).tolist() == [1, 1, 0]
    assert lattice_direction(diagonal + np.array([0, 1e-8, 0]), tol).tolist() == [1, 1, 0]
    assert lattice_direction(diagonal + np.array([0, 1e-4, 0]), tol) is None
    assert lattice_direction(np.array([1.0, 2.0, 0.0]), tol) is None


@pytest.mark.parametrize("solution", [0, 257])
def test_burrs_block_on_their_cells_as_their_meshes_do(solution):
    """Every ordered pair of pieces, along all 26 lattice directions: the cells decide
    as the projection of the meshes does (a solvable burr and one with no monotone
    plan)."""
    path = dataset("burrtools/SolidSixPieceBurrs.xmpuzzle")
    if path is None:
        pytest.skip("six-piece burrs not bundled")
    assembly = load_burrtools(path, solution=solution)
    names = list(assembly.names)
    tol = assembly.tolerance()
    for e in LATTICE:
        d = np.array(e, dtype=np.float64) / np.linalg.norm(e)
        assert extended_arcs(assembly, d, names, names, tol) == projected_arcs(
            assembly, d, names, names, tol
        ), e


def test_a_part_not_made_of_cells_goes_to_its_mesh():
    # a cube of side 1.5 is no union of unit cells: the projection decides
    cells = Part("cells", voxel_mesh(np.array([[0, 0, 0], [1, 0, 0]]), "two cells"))
    block = voxel_mesh(np.array([[3, 0, 0]]), "one cell")
    big = Part("big", block.copy().apply_scale(1.5))
    assembly = Assembly([cells, big])
    tol = assembly.tolerance()
    d = np.array([1.0, 0.0, 0.0])
    arcs = extended_arcs(assembly, d, ["cells"], ["big"], tol)
    assert arcs == projected_arcs(assembly, d, ["cells"], ["big"], tol) == {("cells", "big")}
