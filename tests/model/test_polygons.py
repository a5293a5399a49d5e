"""Tests of the data of planar assemblies: names in order, the scale the tolerance is
scaled to and sub-assemblies."""

from __future__ import annotations

import numpy as np
import pytest

from assemblykit.errors import UnknownNameError
from assemblykit.model.assembly import AssemblyLike
from assemblykit.model.polygons import PolygonAssembly
from assemblykit.tolerance import Tolerance


def square(x: float, y: float) -> np.ndarray:
    return np.array([[x, y], [x + 1, y], [x + 1, y + 1], [x, y + 1]], dtype=float)


def two_squares() -> PolygonAssembly:
    return PolygonAssembly({"b": square(1, 0), "a": square(0, 0)}, "two.yaml")


def test_polygons_are_an_assembly_of_the_plane():
    model = two_squares()
    like: AssemblyLike = model
    assert like.names == ["b", "a"] and len(like.memo) == 0
    assert model.names == ["b", "a"]
    assert (model.dimension, model.kind) == (2, "polygons")
    assert model.scale == pytest.approx(np.hypot(2, 1))
    assert model.tolerance(Tolerance()).scale == pytest.approx(np.hypot(2, 1))
    assert PolygonAssembly({}).scale == 1.0


def test_a_subset_keeps_the_polygons_named_in_order():
    model = two_squares()
    kept = model.subset(["a", "b"])
    assert kept.names == ["b", "a"] and kept.source == "two.yaml"
    assert kept.polygons["a"] is model.polygons["a"]
    with pytest.raises(UnknownNameError, match="'c'"):
        model.subset(["c"])


def test_a_polygon_s_size_is_its_area_and_nothing_is_cut_or_joined():
    # a unit square and a right triangle of legs 2 and 3 (shoelace: 3)
    model = PolygonAssembly(
        {"square": square(0, 0), "triangle": np.array([[2.0, 0.0], [4.0, 0.0], [2.0, 3.0]])}
    )
    assert model.sizes() == pytest.approx({"square": 1.0, "triangle": 3.0})
    assert list(model.sizes()) == ["square", "triangle"]
    assert model.overlaps == () and model.joined == {}
