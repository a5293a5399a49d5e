"""Tests of Γ_e along the candidate directions as the search asks it
(:class:`~assemblykit.planning.extended_directions.ExtendedDirections`), against the DBGs
computed from scratch on the bundled gearbox."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from assemblykit.blocking.extended import extended_dbg
from assemblykit.part_sets import mask_of
from assemblykit.planning.extended_directions import ExtendedDirections
from datasets import shared_assembly

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "src" / "assemblykit" / "examples" / "gearbox_demo" / "gearbox.yaml"
UP, DOWN = np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, -1.0])


def test_pairs_tested_for_one_subassembly_serve_the_others():
    # blocking is pairwise: the DBG asked of a set, after its supersets or subsets were
    # asked, is the one computed from scratch
    assembly = shared_assembly(DEMO)
    names = tuple(assembly.names)
    tol = assembly.tolerance()
    directions = np.array([UP, DOWN, [1.0, 0.0, 0.0], [0.0, 0.6, 0.8]])
    extended = ExtendedDirections(assembly, directions, tol)
    rng = np.random.default_rng(3)
    everything = (1 << len(names)) - 1
    for _ in range(12):
        k = int(rng.integers(len(directions)))
        members = int(rng.integers(1, everything + 1)) | 1
        chosen = tuple(names[i] for i in range(len(names)) if members >> i & 1)
        expected = extended_dbg(assembly, directions[k], chosen, tol).arcs
        got = {(names[i], names[j]) for i, j in extended.graph(k, members).edges}
        assert got == expected
    # a single part asked alone is tested against the members given, no more
    fresh = ExtendedDirections(assembly, directions, tol)
    cover = names.index("cover")
    held = fresh.blockers(0, 1 << cover, everything)
    assert held == {cover: 0}  # the cover lifts off
    assert fresh.evaluated == {0}


def test_parts_leaving_along_many_directions_in_turn_are_those_of_the_extended_dbgs():
    # a search over many directions (a proof that a set is stuck) has the faces that
    # showed each pair blocking tested along a run of directions at once: who leaves
    # along each direction is still who leaves in the DBG computed from scratch
    assembly = shared_assembly(DEMO)
    names = tuple(assembly.names)
    tol = assembly.tolerance()
    rng = np.random.default_rng(5)
    directions = np.vstack([np.eye(3), -np.eye(3), rng.normal(size=(4, 3))])
    extended = ExtendedDirections(assembly, directions, tol)
    everything = (1 << len(names)) - 1
    left = 0
    for k in range(len(directions)):
        arcs = extended_dbg(assembly, directions[k], names, tol).arcs
        held = {names.index(a) for a, _ in arcs}
        expected = mask_of(i for i in range(len(names)) if i not in held)
        assert extended.leaving(k, everything, everything) == expected, k
        left += expected.bit_count()
    assert 0 < left < len(names) * len(directions)
