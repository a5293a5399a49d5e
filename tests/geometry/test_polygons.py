"""Tests of polygons in the plane, the geometry layer: polygons turned counter-clockwise
and refused when they cross themselves, and the contact segments of a polygon assembly,
kept in its memo."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from assemblykit.errors import GeometryError
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.geometry.polygons import PolygonContacts, counter_clockwise
from assemblykit.io.polygons import load_polygons

PLANAR = Path(__file__).resolve().parents[2] / "src" / "assemblykit" / "examples" / "planar"


def test_clockwise_points_are_turned_and_self_crossing_ones_refused():
    clockwise = np.array([[0, 0], [0, 1], [1, 1], [1, 0]], dtype=float)
    turned = counter_clockwise(clockwise, "a")
    x, y = turned[:, 0], turned[:, 1]
    assert 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) == 1.0  # shoelace: +1
    assert {tuple(p) for p in turned} == {tuple(p) for p in clockwise}
    bow_tie = np.array([[0, 0], [1, 1], [1, 0], [0, 1]], dtype=float)
    with pytest.raises(GeometryError, match=r"parts\.tie"):
        counter_clockwise(bow_tie, "tie", "f.yaml")


def test_polygon_contacts_are_kept_in_the_memo_and_restricted():
    hands = load_polygons(PLANAR / "three_hands.yaml")
    found = assembly_contacts(hands)
    assert [c.pair for c in found] == [("base", "bar"), ("base", "block"), ("bar", "block")]
    assert hands.memo.of(PolygonContacts).found == {hands.tolerance(): found}
    assert assembly_contacts(hands) is found
    two = hands.subset(["bar", "base"])
    (kept,) = two.memo.of(PolygonContacts).found.values()
    assert [c.pair for c in kept] == [("base", "bar")] and kept[0] is found[0]
    assert len(hands.memo.of(PolygonContacts).found[hands.tolerance()]) == 3


def test_polygon_contacts_need_no_higher_layer():
    # a polygon assembly made by hand is measured by the geometry layer alone
    script = (
        "import sys, numpy as np\n"
        "from assemblykit.geometry.contacts import assembly_contacts\n"
        "from assemblykit.model.polygons import PolygonAssembly\n"
        "square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)\n"
        "found = assembly_contacts(PolygonAssembly({'a': square, 'b': square + [1, 0]}))\n"
        "print([c.pair for c in found], 'assemblykit.blocking' in sys.modules)\n"
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert done.stdout.split("\n")[0] == "[('a', 'b')] False", done.stderr
