"""The free sets of extended translations (blocking/free_cones.py): the overlays of
their chart regions stay exact where GEOS's floating overlay cannot node them."""

from __future__ import annotations

import pytest
import shapely

from assemblykit.blocking.free_cones import robust_union


def test_a_union_geos_cannot_node_is_taken_on_the_valid_pieces():
    # by hand: the bow tie's two triangles (0.25 each) and the square 0.2..0.8 (0.36)
    # overlap by 0.09 on each side: 0.5 + 0.36 - 0.18
    bow = shapely.Polygon([(0, 0), (1, 1), (1, 0), (0, 1)])
    square = shapely.box(0.2, 0.2, 0.8, 0.8)
    with pytest.raises(shapely.errors.GEOSException):
        shapely.union_all([bow, square])
    assert robust_union([bow, square]).area == pytest.approx(0.68, rel=1e-12)
    # a union GEOS nodes is the plain one
    assert robust_union([square, shapely.box(0.5, 0, 2, 1)]).area == pytest.approx(1.5 + 0.18)
