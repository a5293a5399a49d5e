"""Oriented primitive features: validation, frames, task-file round trips, groups."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from assemblykit.algebra import se3
from assemblykit.errors import FeatureError, SchemaError
from assemblykit.features import (
    Axis,
    Ball,
    Cone,
    Frame,
    Hole,
    Plane,
    Point,
    Prism,
    Shaft,
    Socket,
    Thread,
    Torus,
    feature_from_dict,
    parse_angle,
)

EXAMPLES = [
    Plane(point=(1, 2, 3), normal=(0, 0, 2)),
    Shaft(point=(0, 0, 0), axis=(0, 0, 1), radius=2),
    Hole(point=(5, 5, 10), axis=(0, 0, -1), radius=2, directed=False),
    Ball(point=(0, 0, 1), radius=3),
    Socket(point=(0, 0, 1), radius=3),
    Cone(point=(0, 0, 0), axis=(1, 0, 0), half_angle=math.pi / 6, male=False),
    Torus(point=(0, 1, 0), axis=(0, 1, 0), major_radius=4, minor_radius=1),
    Thread(point=(0, 0, 0), axis=(0, 0, 1), radius=5, lead=1.5, hand="left", phase=0.5),
    Prism(point=(0, 0, 0), axis=(0, 0, 1), sides=4, size=2, ref=(1, 1, 0), directed=False),
    Point(point=(1, 1, 1)),
    Axis(point=(0, 0, 5), axis=(1, 0, 0), directed=False),
    Frame(matrix=se3.rotation((0, 0, 1), 0.3, (1, 0, 0))),
]

rigid = st.builds(
    lambda seed: se3.random_transform(np.random.default_rng(seed)),
    st.integers(min_value=0, max_value=2**32 - 1),
)


def test_vectors_are_normalised_float64_and_read_only():
    plane = Plane(point=[1, 2, 3], normal=[0, 0, 2])
    assert plane.normal.dtype == np.float64
    assert plane.normal.tolist() == [0.0, 0.0, 1.0]
    with pytest.raises(ValueError):
        plane.point[0] = 5.0


@pytest.mark.parametrize(
    ("feature", "origin", "z"),
    [
        (Plane((1, 2, 3), (0, 0, 1)), (1, 2, 3), (0, 0, 1)),
        (Shaft((0, 0, 0), (0, 1, 0), 2), (0, 0, 0), (0, 1, 0)),
        (Hole((5, 5, 10), (0, 0, -1), 2), (5, 5, 10), (0, 0, -1)),
        (Cone((1, 0, 0), (1, 0, 0), 0.3), (1, 0, 0), (1, 0, 0)),
        (Ball((0, 0, 4), 1), (0, 0, 4), (0, 0, 1)),
    ],
)
def test_frame_origin_on_feature_and_z_along_normal_or_axis(feature, origin, z):
    frame = feature.frame()
    assert np.allclose(frame[:3, 3], origin, atol=1e-12)
    assert np.allclose(frame[:3, 2], z, atol=1e-12)
    assert np.isclose(np.linalg.det(frame[:3, :3]), 1.0)


def test_thread_phase_turns_the_frame_x_axis_to_the_thread_start():
    thread = Thread((0, 0, 0), (0, 0, 1), radius=5, lead=1.5, phase="90 deg")
    base = se3.frame((0, 0, 0), (0, 0, 1))
    assert np.allclose(thread.frame()[:3, 0], base[:3, 1], atol=1e-12)
    assert thread.pitch == pytest.approx(1.5 / (2 * math.pi))
    left = Thread((0, 0, 0), (0, 0, 1), radius=5, lead=1.5, hand="left")
    assert left.pitch == pytest.approx(-1.5 / (2 * math.pi))


def test_prism_ref_is_made_perpendicular_and_sets_the_frame_x_axis():
    prism = Prism((0, 0, 0), (0, 0, 1), sides=6, size=1, ref=(1, 0, 5))
    assert prism.ref.tolist() == [1.0, 0.0, 0.0]
    assert np.allclose(prism.frame()[:3, 0], (1, 0, 0))


@pytest.mark.parametrize(
    ("data", "error", "text"),
    [
        ({"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 0]}, FeatureError, "normal"),
        (
            {"type": "plane", "point": [0, 0, 0], "normal": [0, float("nan"), 1]},
            FeatureError,
            "finite",
        ),
        (
            {"type": "shaft", "point": [0, 0, 0], "axis": [0, 0, 1], "radius": 0},
            FeatureError,
            "radius",
        ),
        ({"type": "hole", "point": [0, 0], "axis": [0, 0, 1], "radius": 1}, FeatureError, "point"),
        ({"type": "socket", "point": [0, 0, 0], "radius": -2}, FeatureError, "radius"),
        (
            {"type": "cone", "point": [0, 0, 0], "axis": [0, 0, 1], "half_angle": "90 deg"},
            FeatureError,
            "half_angle",
        ),
        (
            {"type": "cone", "point": [0, 0, 0], "axis": [0, 0, 1], "half_angle": 0},
            FeatureError,
            "half_angle",
        ),
        (
            {
                "type": "thread",
                "point": [0, 0, 0],
                "axis": [0, 0, 1],
                "radius": 1,
                "lead": 1,
                "hand": "up",
            },
            FeatureError,
            "hand",
        ),
        (
            {"type": "prism", "point": [0, 0, 0], "axis": [0, 0, 1], "sides": 1, "size": 1},
            FeatureError,
            "sides",
        ),
        (
            {
                "type": "prism",
                "point": [0, 0, 0],
                "axis": [0, 0, 1],
                "sides": 4,
                "size": 1,
                "ref": [0, 0, 3],
            },
            FeatureError,
            "ref",
        ),
        (
            {"type": "frame", "matrix": np.diag([1.0, 1.0, -1.0, 1.0]).tolist()},
            FeatureError,
            "rigid",
        ),
        (
            {"type": "torus", "point": [0, 0, 0], "axis": [0, 0, 1], "major_radius": 2},
            SchemaError,
            "minor_radius",
        ),
        ({"type": "wedge"}, SchemaError, "unknown feature type"),
        ({"type": "ball", "point": [0, 0, 0], "radius": 1, "colour": "red"}, SchemaError, "colour"),
        (
            {"type": "cone", "point": [0, 0, 0], "axis": [0, 0, 1], "half_angle": "thirty"},
            SchemaError,
            "angle",
        ),
    ],
)
def test_invalid_features_raise_errors_naming_the_place(data, error, text):
    with pytest.raises(error) as info:
        feature_from_dict("f", data, "bodies.peg.features.f")
    assert type(info.value) is error
    assert info.value.where.startswith("bodies.peg.features.f")
    assert text in str(info.value)


def test_constructor_errors_name_the_feature():
    with pytest.raises(FeatureError, match="collar: normal"):
        Plane((0, 0, 0), (0, 0, 0), name="collar")


def test_angles_in_degrees_or_radians():
    assert parse_angle("30 deg") == pytest.approx(math.pi / 6)
    assert parse_angle("0.5 rad") == 0.5
    assert parse_angle(0.25) == 0.25
    cone = feature_from_dict(
        "c", {"type": "cone", "point": [0, 0, 0], "axis": [0, 0, 1], "half_angle": "45 deg"}
    )
    assert cone.half_angle == pytest.approx(math.pi / 4)
    assert cone.name == "c"


@pytest.mark.parametrize("feature", EXAMPLES, ids=lambda f: f.type_name)
def test_task_file_round_trip(feature):
    data = feature.to_dict()
    assert data["type"] == feature.type_name
    again = feature_from_dict("x", data)
    assert type(again) is type(feature)
    redone = again.to_dict()
    assert redone.keys() == data.keys()
    for key, value in data.items():
        if isinstance(value, list):
            assert np.allclose(redone[key], value, rtol=0, atol=1e-15), key
        else:
            assert redone[key] == value, key
    assert np.allclose(again.frame(), feature.frame(), atol=1e-12)


@settings(max_examples=25, deadline=None)
@given(rigid)
def test_transformed_moves_the_frame(transform):
    for feature in EXAMPLES:
        moved = feature.transformed(transform)
        assert type(moved) is type(feature)
        expected, got = transform @ feature.frame(), moved.frame()
        # Only threads, prisms and frames carry a phase; elsewhere x is a free choice.
        if feature.type_name in ("thread", "prism", "frame"):
            keep = [0, 1, 2, 3]
        elif feature.type_name in ("ball", "socket", "point"):
            keep = [3]
        else:
            keep = [2, 3]
        assert np.allclose(got[:3, keep], expected[:3, keep], atol=1e-9), feature.type_name


@pytest.mark.parametrize(
    ("feature", "kind", "dof", "components"),
    [
        (Plane((0, 0, 0), (0, 0, 1)), "planar", 3, 1),
        (Shaft((0, 0, 0), (0, 0, 1), 2), "cylindrical", 2, 1),
        (Hole((0, 0, 0), (0, 0, 1), 2, directed=False), "cylindrical", 2, 2),
        (Ball((1, 0, 0), 1), "spherical", 3, 1),
        (Cone((0, 0, 0), (0, 0, 1), 0.3), "revolute", 1, 1),
        (Torus((0, 0, 0), (0, 0, 1), 5, 1), "revolute", 1, 2),
        (Thread((0, 0, 0), (0, 0, 1), 5, 1.5), "helical", 1, 1),
        (Thread((0, 0, 0), (0, 0, 1), 5, 1.5, directed=False), "helical", 1, 2),
        (Prism((0, 0, 0), (0, 0, 1), 6, 1), "prismatic", 1, 6),
        (Prism((0, 0, 0), (0, 0, 1), 6, 1, directed=False), "prismatic", 1, 12),
        (Point((0, 0, 0)), "spherical", 3, 1),
        (Axis((0, 0, 0), (1, 0, 0), directed=False), "cylindrical", 2, 2),
        (Frame(np.eye(4)), "fixed", 0, 1),
    ],
    ids=lambda v: getattr(v, "type_name", str(v)),
)
def test_groups_follow_the_table_of_algebra_section_4(feature, kind, dof, components):
    group = feature.group()
    assert (str(group.kind), group.dof, group.n_components) == (kind, dof, components)


def test_group_members():
    p = (1.0, 2.0, 3.0)
    shaft = Shaft(p, (0, 1, 0), 2, directed=False)
    assert shaft.group().contains(se3.rotation((0, 1, 0), 0.4, p) @ se3.translation((0, 5, 0)))
    assert shaft.group().contains(se3.rotation((1, 0, 0), math.pi, p))
    assert not Shaft(p, (0, 1, 0), 2).group().contains(se3.rotation((1, 0, 0), math.pi, p))
    thread = Thread(p, (0, 0, 1), radius=5, lead=1.5)
    assert thread.group().contains(se3.screw(p, (0, 0, 1), 1.5 / (2 * math.pi), 2.0))
    assert not thread.group().contains(se3.screw(p, (0, 0, 1), -1.5 / (2 * math.pi), 2.0))
    left = Thread(p, (0, 0, 1), radius=5, lead=1.5, hand="left")
    assert left.group().contains(se3.screw(p, (0, 0, 1), -1.5 / (2 * math.pi), 2.0))
    square = Prism(p, (0, 0, 1), sides=4, size=1)
    assert square.group().contains(se3.rotation((0, 0, 1), math.pi / 2, p))
    assert not square.group().contains(se3.rotation((0, 0, 1), math.pi / 4, p))
    assert not Plane(p, (0, 0, 1)).group().contains(se3.rot_x(math.pi))


def test_invariants_name_the_geometry():
    cone = Cone((1, 0, 0), (0, 0, 1), 0.3)
    line, apex = cone.invariants()
    assert np.allclose(line.point, (1, 0, 0)) and line.directed
    assert np.allclose(apex.point, (1, 0, 0))
    (plane,) = Plane((0, 0, 2), (0, 0, 1)).invariants()
    assert np.allclose(plane.normal, (0, 0, 1))
    assert not Shaft((0, 0, 0), (0, 0, 1), 1, directed=False).invariants()[0].directed
