"""Tests of the blocking layer of polygons (Wilson & Latombe 1992, 2D case): extended
translations, Γ_e in the plane, on hand-drawn parts whose blocked arcs are derived from
their vertices."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from shapely.geometry import Polygon
from shapely.ops import unary_union

from assemblykit.blocking.graphs import blocking_graph
from assemblykit.blocking.ndbg import NonDirectionalBlockingGraph
from assemblykit.blocking.planar import blocked_normals, convex_pieces
from assemblykit.io.polygons import load_polygons
from assemblykit.model.polygons import PolygonAssembly
from assemblykit.tolerance import Tolerance

PLANAR = Path(__file__).resolve().parents[2] / "src" / "assemblykit" / "examples" / "planar"
TOL = Tolerance(scale=10.0)


def unit(degrees: float) -> np.ndarray:
    t = np.radians(degrees)
    return np.array([np.cos(t), np.sin(t)])


def blocked(normals: np.ndarray, degrees: float) -> bool:
    """Inside every open half-plane, beyond the angle tolerance (as the NDBG decides)."""
    return bool(np.all(normals[:, :2] @ unit(degrees) > TOL.angle))


def square(x: float, y: float, side: float = 1.0) -> np.ndarray:
    return np.array([[x, y], [x + side, y], [x + side, y + side], [x, y + side]], dtype=float)


def test_apart_pieces_block_along_the_open_arc_their_vertices_span():
    # q = [3, 4] x [0, 1] seen from p = [0, 1]^2: q - p spans [2, 4] x [-1, 1], whose
    # extreme directions are (2, -1) and (2, 1): atan(1/2) = 26.565 degrees either side
    normals = blocked_normals(square(0, 0), square(3, 0), TOL)
    assert len(normals) == 2
    assert blocked(normals, 0.0) and blocked(normals, 26.5) and blocked(normals, -26.5)
    assert not blocked(normals, 26.6) and not blocked(normals, -26.6)
    assert not blocked(normals, np.degrees(np.arctan2(1, 2)))  # grazing corners


def test_touching_pieces_block_a_half_circle_or_a_corner_cone():
    # along an edge: the open half-circle of the normal into the other piece
    edge = blocked_normals(square(0, 0), square(1, 0), TOL)
    assert np.allclose(edge, [[1, 0, 0]])
    # at a corner only: the open quarter between the two edges' normals
    corner = blocked_normals(square(0, 0), square(1, 1), TOL)
    assert len(corner) == 2
    assert blocked(corner, 45.0) and not blocked(corner, 0.0) and not blocked(corner, 90.0)
    # overlapping: every direction
    assert blocked_normals(square(0, 0), square(0.5, 0), TOL).shape == (0, 3)


def test_non_convex_polygon_is_cut_into_convex_pieces_of_its_area():
    # floor 8 + stop 2 + wall 4 + lip 3
    hook = load_polygons(PLANAR / "hook.yaml").polygons["hook"]
    pieces = convex_pieces(hook, TOL)
    assert len(pieces) > 1
    assert sum(Polygon(p).area for p in pieces) == 17
    assert unary_union([Polygon(p) for p in pieces]).symmetric_difference(Polygon(hook)).area == 0
    for piece in pieces:  # convex and counter-clockwise: every turn is to the left
        e = np.roll(piece, -1, axis=0) - piece
        f = np.roll(e, -1, axis=0)
        assert np.all(e[:, 0] * f[:, 1] - e[:, 1] * f[:, 0] > -1e-12)


def test_peg_leaves_the_hook_only_between_its_two_grazing_corners():
    # by hand: the stop blocks the peg on (-33.69, 18.43) degrees (corner (3, 1) meets
    # (6, 2) at atan(1/3)), the lip on (45, 146.31) (corner (3, 3) meets (3, 5)), the
    # wall on (90, 270) and the floor on (180, 360): the peg is free on [18.43, 45]
    model = load_polygons(PLANAR / "hook.yaml")
    ndbg = blocking_graph(model, "extended")
    assert isinstance(ndbg, NonDirectionalBlockingGraph)
    low, high = np.degrees(np.arctan2(1, 3)), 45.0
    for degrees in np.arange(0.0, 360.0, 0.5):
        free = ndbg.dbg(unit(degrees)).is_free(frozenset({"peg"}))
        assert free == (low <= degrees <= high), degrees
    assert ndbg.dbg(unit(low)).is_free(frozenset({"peg"}))
    assert ndbg.dbg(unit(high)).is_free(frozenset({"peg"}))
    assert not ndbg.dbg(unit(low - 1e-3)).is_free(frozenset({"peg"}))
    assert not ndbg.dbg(unit(high + 1e-3)).is_free(frozenset({"peg"}))
    # the regions freeing the peg: both end points and the open arc between them
    (peg,) = [r for r in ndbg.removable() if r.parts == frozenset({"peg"})]
    angles = sorted(np.degrees(np.arctan2(d[1], d[0])) for d in peg.directions)
    assert np.isclose(angles[0], low) and np.isclose(angles[-1], high)
    assert all(low < a < high for a in angles[1:-1]) and len(angles) >= 3
    # the hook leaves the peg along the opposite arc
    (hook,) = [r for r in ndbg.removable() if r.parts == frozenset({"hook"})]
    assert all(
        180 + low - 1e-9 <= np.degrees(np.arctan2(d[1], d[0])) % 360 for d in hook.directions
    )


def test_extended_blocking_sees_parts_that_do_not_touch():
    # a square on a floor with a roof above it, not touching the roof: Γ_t lets it go
    # up, Γ_e does not
    model = PolygonAssembly(
        {"floor": square(0, -1, 4), "box": square(1, 3), "roof": square(0, 6, 4)}
    )
    local = blocking_graph(model, "infinitesimal")
    grown = blocking_graph(model, "extended")
    assert local.dbg([0, 1]).is_free(frozenset({"box"}))
    assert grown.dbg([0, 1]).arcs >= {("box", "roof")}
    assert grown.dbg([1, 0]).is_free(frozenset({"box"}))
