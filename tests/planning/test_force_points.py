"""Which vertices of the contact polygons are corners
(:func:`assemblykit.planning.force_points._corners`): a vertex strictly between its two
neighbours on the segment joining them is none, a vertex repeated counts once, and every
other vertex is one."""

from __future__ import annotations

import numpy as np

from assemblykit.planning.force_points import _corners


def test_a_vertex_off_the_segment_is_kept():
    square = np.array([[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0]], dtype=np.float64)
    sides = (square + np.roll(square, -1, axis=0)) / 2
    ring = np.stack([square, sides], axis=1).reshape(-1, 3)
    assert _corners([ring], 1e-15).tolist() == [True, False] * 4
    # a vertex bent outwards beyond the resolution is a corner
    bent = ring.copy()
    bent[1, 1] -= 1e-9
    assert _corners([bent], 1e-15).sum() == 5
    # the tip of a spike going back along its side (both neighbours at one point) is a
    # corner; the vertex before it lies between its neighbours, the tip included
    spike = np.array([[0, 0, 0], [2, 0, 0], [3, 0, 0], [2, 0, 0], [2, 2, 0]], dtype=np.float64)
    assert _corners([spike], 1e-15).tolist() == [True, False, True, True, True]
    # polygons one after the other: each closes on itself; two points are both corners
    together = [square[:2], ring, spike, np.zeros((0, 3))]
    assert _corners(together, 1e-15).tolist() == (
        [True, True] + [True, False] * 4 + [True, False, True, True, True]
    )
    assert _corners([], 1e-15).tolist() == []


def test_a_corner_given_twice_is_kept_once():
    # the cross vault's contact polygons repeat some corners within 1e-16: each copy lies
    # between the other and its far neighbour, so both used to be dropped and the corner
    # lost; the first copy stays, the repeat goes, and so does a closing repeat
    square = np.array([[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0]], dtype=np.float64)
    twice = np.insert(square, 2, square[1] + [0.0, 1e-17, 0.0], axis=0)
    assert _corners([twice], 1e-15).tolist() == [True, True, False, True, True]
    closed = np.vstack([square, square[:1]])
    assert _corners([closed], 1e-15).tolist() == [False, True, True, True, True]
    assert _corners([np.zeros((3, 3))], 1e-15).tolist() == [True, False, False]
