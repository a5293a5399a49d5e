"""Interlocked voxel assemblies decided by the lattice certificate
(``blocking.free_cones.lattice_locked``; docs/blocking.md, "Three kinds of motion"),
checked against an independent test of monotone two-handed translations along the axes
on the cells."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from assemblykit.blocking.extended import extended_free
from assemblykit.blocking.free_cones import exact_free_directions, lattice_locked
from assemblykit.blocking.lattice import lattice_cells
from assemblykit.io.burrtools import load_burrtools, voxel_mesh
from assemblykit.model.assembly import Assembly, Part
from assemblykit.planning.planner import plan
from datasets import dataset

BURRS = "burrtools/SolidSixPieceBurrs.xmpuzzle"
AXES = [(axis, sign) for axis in range(3) for sign in (1, -1)]


def _ahead(mover: np.ndarray, blocker: np.ndarray, axis: int, sign: int) -> bool:
    """A cell of ``blocker`` lies ahead of a cell of ``mover`` along the axis, in line."""
    diff = blocker[None, :, :] - mover[:, None, :]
    others = [k for k in range(3) if k != axis]
    in_line = np.all(diff[..., others] == 0, axis=-1)
    return bool(np.any(in_line & (diff[..., axis] * sign > 0)))


def _monotone(ahead: dict, pieces: frozenset[int], memo: dict) -> bool:
    """Whether ``pieces`` come apart by translations to infinity along the axes, one
    subassembly leaving the rest at a time, each half again (``ahead[i, j, axis]``: a
    cell of ``j`` ahead of one of ``i``)."""
    if len(pieces) < 2:
        return True
    if pieces not in memo:
        memo[pieces] = False
        for size in range(1, len(pieces)):
            for chosen in itertools.combinations(sorted(pieces), size):
                moving = frozenset(chosen)
                rest = pieces - moving
                if any(
                    not any(ahead[i, j, axis] for i in moving for j in rest) for axis in AXES
                ) and (_monotone(ahead, moving, memo) and _monotone(ahead, rest, memo)):
                    memo[pieces] = True
                    return True
    return bool(memo[pieces])


def _axis_verdict(cells: list[np.ndarray]) -> bool:
    pairs = itertools.permutations(range(len(cells)), 2)
    ahead = {(i, j, a): _ahead(cells[i], cells[j], *a) for i, j in pairs for a in AXES}
    return _monotone(ahead, frozenset(range(len(cells))), {})


@pytest.mark.parametrize(("solution", "feasible"), [(0, True), (257, False)])
def test_a_six_piece_burr_is_decided_as_the_axis_translations_decide_it(solution, feasible):
    assembly = load_burrtools(dataset(BURRS), solution=solution)
    cells = [np.asarray(p.voxels) for p in assembly.puzzle.pieces]
    assert _axis_verdict(cells) is feasible
    result = plan(assembly, max_hands=2)
    assert result.feasible is feasible
    if not feasible:
        stuck = {assembly.names.index(n) for n in result.stuck}
        assert lattice_locked([cells[i] for i in sorted(stuck)])
        assert not _axis_verdict([cells[i] for i in sorted(stuck)])


def test_the_cells_of_a_voxel_part_are_read_back_from_its_mesh():
    assembly = load_burrtools(dataset(BURRS), solution=257)
    for piece in assembly.puzzle.pieces:
        found = lattice_cells(assembly.parts[piece.name].mesh)
        assert found is not None
        assert sorted(map(tuple, found.tolist())) == sorted(map(tuple, piece.voxels.tolist()))
    slanted = Part("wedge", voxel_mesh(np.array([[0, 0, 0]])).apply_scale(0.5))
    assert lattice_cells(slanted.mesh) is None


def _diagonal_channel() -> tuple[np.ndarray, np.ndarray]:
    """A cube in a slab whose only way out is a channel along ``(1, 1, 0)``: the cells
    it sweeps along it (``|m - n| <= 1`` ahead) are empty, every axis is blocked."""
    key = np.array([[0, 0, 0]])
    cells = []
    for x, y, z in itertools.product(range(-2, 6), range(-2, 6), (-1, 0, 1)):
        channel = z == 0 and x >= 0 and y >= 0 and abs(x - y) <= 1
        if not channel:
            cells.append((x, y, z))
    return key, np.array(cells)


def test_a_cube_leaving_only_along_a_diagonal_is_not_called_locked():
    key, slab = _diagonal_channel()
    assert not _axis_verdict([key, slab])  # no axis frees it
    assert not lattice_locked([key, slab])
    parts = [Part("key", voxel_mesh(key)), Part("slab", voxel_mesh(slab))]
    assembly = Assembly(parts)
    tol = assembly.tolerance(None)
    assert extended_free(assembly, ["key"], np.array([1.0, 1.0, 0.0]), tol, ["key", "slab"])


def test_a_cube_in_a_closed_cage_is_locked_and_in_one_with_a_lid_is_not():
    key = np.array([[0, 0, 0]])
    cage = np.array([c for c in itertools.product(range(-1, 2), repeat=3) if any(c)])
    assert lattice_locked([key, cage])
    lid = cage[cage[:, 2] == 1]
    walls = cage[cage[:, 2] < 1]
    assert not lattice_locked([key, walls])  # lifts out
    assert not lattice_locked([key, walls, lid])  # the lid lifts off first


@pytest.mark.slow
def test_the_certificate_agrees_with_the_exact_free_sets_of_a_stuck_burr():
    # the general way (faces and cells of each part's exact free set, about 15 s) finds
    # no direction freeing any part of the set the certificate proves interlocked
    assembly = load_burrtools(dataset(BURRS), solution=257)
    stuck = list(plan(assembly, max_hands=2).stuck)
    cells = {p.name: np.asarray(p.voxels) for p in assembly.puzzle.pieces}
    assert len(stuck) == 5 and lattice_locked([cells[n] for n in stuck])
    tol = assembly.tolerance(None)
    for name in stuck:
        found = exact_free_directions(assembly, [name], tol, stuck)
        assert found.complete and not found.directions


def link(start: int, flat: bool) -> np.ndarray:
    """The cells of a chain link 5 long and 3 wide with holes at its second and fourth
    cells, starting at x = ``start``, lying in z = 0 (``flat``) or y = 0."""
    return np.array(
        [
            (start + a, b, 0) if flat else (start + a, 0, b)
            for a in range(5)
            for b in (-1, 0, 1)
            if not (b == 0 and a in (1, 3))
        ],
        dtype=np.int64,
    )


def test_a_chain_of_links_off_the_lattice_is_stuck_as_its_pairs_say():
    # twenty links, each through a hole of the next and holding that one's end in its
    # own hole, a quarter turn apart, as meshes moved off the unit lattice; a hook
    # hangs in the first link's free hole. Each pair of linked links is interlocked on
    # the lattice (the integer certificate, on their cells), so the linked pairs tie
    # all twenty: the plan lifts the hook out and names the twenty stuck, by
    # translations and by rigid motions alike (fifty, in 0.34 CPU s, are a figure of
    # benchmarks/bench_planning.py)
    cells = [link(3 * k, k % 2 == 0) for k in range(20)]
    assert all(lattice_locked([cells[k], cells[k + 1]]) for k in range(19))
    shift = np.array([0.37, 0.21, 0.13])
    parts = [
        Part(f"link {k:02d}", voxel_mesh(c).apply_translation(shift)) for k, c in enumerate(cells)
    ]
    hook = np.array([(1, 0, 0), (1, 0, 1), (2, 0, 1)], dtype=np.int64)
    parts.append(Part("hook", voxel_mesh(hook).apply_translation(shift)))
    result = plan(Assembly(parts, units="unit"))
    assert not result.feasible
    assert [s.parts for s in result.steps] == [("hook",)]
    np.testing.assert_allclose(result.steps[0].direction, [0, 0, 1], atol=1e-9)
    assert sorted(result.stuck) == [f"link {k:02d}" for k in range(20)]
    (lock,) = result.interlocked
    assert lock.translation_locked and not lock.rigid_may_free
