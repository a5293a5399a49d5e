"""Bodies: named features, lookup errors, moving a body, the task-file form."""

from __future__ import annotations

import math

import numpy as np
import pytest

from assemblykit.algebra import se3
from assemblykit.errors import FeatureError, SchemaError, UnknownNameError
from assemblykit.features import Hole, Plane
from assemblykit.model.body import Body

BLOCK = {
    "features": {
        "bottom": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, -1]},
        "bore": {"type": "hole", "point": [5, 5, 10], "axis": [0, 0, -1], "radius": 2},
    }
}


def test_from_dict_builds_named_features():
    block = Body.from_dict("block", BLOCK)
    assert not block.fixed
    assert isinstance(block.feature("bottom"), Plane)
    bore = block.feature("bore")
    assert isinstance(bore, Hole) and bore.name == "bore" and bore.radius == 2
    assert Body.from_dict("table", {"fixed": True}).fixed


def test_unknown_feature_names_body_and_feature():
    block = Body.from_dict("block", BLOCK)
    with pytest.raises(UnknownNameError) as info:
        block.feature("top")
    assert "body 'block' has no feature 'top'" in str(info.value)
    assert "bottom, bore" in str(info.value)


def test_feature_errors_name_the_field_path():
    bad = {
        "features": {"bore": {"type": "hole", "point": [0, 0, 0], "axis": [0, 0, 1], "radius": -1}}
    }
    with pytest.raises(FeatureError) as info:
        Body.from_dict("block", bad)
    assert info.value.where == "bodies.block.features.bore"
    with pytest.raises(SchemaError, match="fixed"):
        Body.from_dict("block", {"fixed": "yes"})
    with pytest.raises(SchemaError, match="colour"):
        Body.from_dict("block", {"colour": 1})


def test_features_mapping_is_read_only():
    block = Body.from_dict("block", BLOCK)
    with pytest.raises(TypeError):
        block.features["x"] = Plane((0, 0, 0), (0, 0, 1))  # type: ignore[index]


def test_transformed_moves_every_feature():
    block = Body.from_dict("block", BLOCK)
    move = se3.translation((1, 0, 0)) @ se3.rot_x(math.pi)
    moved = block.transformed(move)
    assert moved.name == "block" and set(moved.features) == {"bottom", "bore"}
    assert np.allclose(moved.feature("bottom").normal, (0, 0, 1))
    assert np.allclose(moved.feature("bore").point, (6, -5, -10))
    assert np.allclose(moved.feature("bore").axis, (0, 0, 1))
