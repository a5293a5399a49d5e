"""Γ_t as direction tables (blocking/tables.py): parts left interfering block each other
along every direction, in the table and along directions added later."""

from __future__ import annotations

import numpy as np

from assemblykit.blocking.directions import DirectionTable
from assemblykit.blocking.tables import with_obstacles


def test_parts_left_interfering_block_each_other_along_every_direction():
    # three parts: 1 blocks 0 along the first direction only, 0 blocks 2 along the
    # second; 0 and 2 are drawn interfering
    directions = np.eye(3)[:2]
    table = DirectionTable.from_arcs(["p", "q", "r"], directions, [[(0, 1)], [(2, 0)]])

    def slots(added: np.ndarray) -> np.ndarray:
        return np.zeros((len(added), len(table.moving)), dtype=bool)

    blocked, added_slots = with_obstacles(table, slots, [(0, 2)])
    assert [blocked.masks(k) for k in range(2)] == [(0b110, 0, 0b001), (0b100, 0, 0b001)]
    # the slots stay sorted by moving part, then blocker
    pairs = list(zip(blocked.moving.tolist(), blocked.blocker.tolist(), strict=True))
    assert pairs == sorted(pairs) == [(0, 1), (0, 2), (2, 0)]
    # along a new direction, where no contact blocks, the pair still does
    new = added_slots(np.array([[0.0, 0.0, 1.0]]))
    assert new.tolist() == [[False, True, True]]
    # no pair: the table as it was
    assert with_obstacles(table, slots, [])[0] is table
