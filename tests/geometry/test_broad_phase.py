"""The broad phase of finding contacts: pairs of parts whose boxes meet, and the groups
of facets of each part near the other."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from assemblykit.geometry import broad_phase
from assemblykit.geometry.broad_phase import candidate_pairs


def test_broad_phase_pairs_boxes_that_overlap_once_inflated():
    bounds = np.array(
        [[[0, 0, 0], [1, 1, 1]], [[1, 0, 0], [2, 1, 1]], [[5, 5, 5], [6, 6, 6]]], float
    )
    assert candidate_pairs(bounds, 1e-9).tolist() == [[0, 1]]
    assert candidate_pairs(bounds, 1e-9, only=2).tolist() == []


@pytest.mark.parametrize("block", [1, 7, 1 << 21])
def test_facing_groups_are_every_pair_of_boxes_that_meet_near_both_parts(block, monkeypatch):
    # random group boxes on four parts: the pairs found are those a comparison of every
    # group of the first part with every group of the second finds, in the stated order
    monkeypatch.setattr(broad_phase, "_BOX_BLOCK", block)
    rng = np.random.default_rng(3)
    owner = rng.integers(0, 4, 300)
    lo = rng.uniform(0, 10, (300, 3)) + owner[:, None] * 2.0
    hi = lo + rng.uniform(0, 2, (300, 3))
    seg = SimpleNamespace(lo=lo, hi=hi)
    usable = rng.random(300) < 0.8
    part_lo = np.array([lo[owner == p].min(axis=0) for p in range(4)])
    part_hi = np.array([hi[owner == p].max(axis=0) for p in range(4)])
    pairs = np.array([[0, 1], [2, 1], [1, 3]])
    margin = 0.05
    g, h = broad_phase.facing_groups(seg, owner, usable, part_lo, part_hi, pairs, margin)

    def meet(a_lo, a_hi, b_lo, b_hi):
        return bool(np.all(a_lo <= b_hi + margin) and np.all(b_lo <= a_hi + margin))

    expected = [
        (a, b)
        for p, q in pairs
        for a in np.flatnonzero(usable & (owner == p))
        for b in np.flatnonzero(usable & (owner == q))
        if meet(lo[a], hi[a], lo[b], hi[b])
        and meet(lo[a], hi[a], part_lo[q], part_hi[q])
        and meet(lo[b], hi[b], part_lo[p], part_hi[p])
    ]
    assert list(zip(g.tolist(), h.tolist(), strict=True)) == expected
    assert len(expected) > 50
