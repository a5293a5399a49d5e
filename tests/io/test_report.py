"""JSON helpers shared by every result type: rounding that never hides a mismatch."""

from __future__ import annotations

import enum
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from assemblykit.errors import NumericError
from assemblykit.io.report import json_number, jsonable, pose_list
from assemblykit.tolerance import Tolerance, using


class Motion(enum.Enum):
    REVOLUTE = "revolute"


@dataclass(frozen=True)
class Inner:
    offset: np.ndarray
    ok: np.bool_


class WithDict:
    def to_dict(self) -> dict[str, object]:
        return {"value": np.float64(0.5)}


def test_noise_below_the_tolerance_prints_as_zero_and_the_rest_keeps_12_digits():
    tol = Tolerance()
    assert json_number(math.cos(math.pi / 2), tol) == 0.0
    assert json_number(-1e-12, tol) == 0.0
    assert json_number(1 / 3, tol) == 0.333333333333
    assert json_number(2.0000000000004, tol) == 2.0


def test_a_mismatch_above_the_tolerance_is_never_rounded_away():
    tol = Tolerance()
    assert json_number(2e-6, tol) == 2e-6
    assert json_number(1.00000000002e-3, tol) == 1.00000000002e-3
    with using(Tolerance(rel_length=1e-3, angle=1e-3)):
        assert json_number(5e-4) == 0.0
        assert json_number(2e-3) == 2e-3


@given(st.floats(allow_nan=False, allow_infinity=False))
def test_rounding_keeps_every_value_above_the_tolerance_within_its_last_digit(x: float):
    tol = Tolerance()
    out = json_number(x, tol)
    if abs(x) > min(tol.length, tol.angle):
        assert out != 0.0 and math.copysign(1, out) == math.copysign(1, x)
        assert abs(out - x) <= 5e-12 * abs(x)
    else:
        assert out == 0.0


def test_non_finite_values_stay_visible():
    assert [json_number(v) for v in (math.inf, -math.inf, math.nan)] == ["inf", "-inf", "nan"]


def test_jsonable_converts_nested_results():
    value = {
        "pose": np.eye(2),
        "count": np.int64(4),
        "motion": Motion.REVOLUTE,
        "inner": Inner(np.array([1e-17, 1.5]), np.bool_(True)),
        "set": frozenset({"b", "a"}),
        "tuple": (1, None, "x"),
        "path": Path("a/b.yaml"),
        "custom": WithDict(),
        3: "key",
    }
    out = jsonable(value)
    assert out == {
        "pose": [[1.0, 0.0], [0.0, 1.0]],
        "count": 4,
        "motion": "revolute",
        "inner": {"offset": [0.0, 1.5], "ok": True},
        "set": ["a", "b"],
        "tuple": [1, None, "x"],
        "path": "a/b.yaml",
        "custom": {"value": 0.5},
        "3": "key",
    }
    json.dumps(out, allow_nan=False)


def test_jsonable_keeps_truth_values_and_rounds_numbers_under_the_tolerance_given():
    loose = Tolerance(rel_length=1e-3, angle=1e-3)
    assert jsonable([True, np.bool_(False), 1, np.float32(0.5)]) == [True, False, 1, 0.5]
    assert type(jsonable(True)) is bool and type(jsonable(np.int32(7))) is int
    assert jsonable({"small": np.float64(5e-4), "big": 2e-3}, loose) == {"small": 0.0, "big": 0.002}
    assert jsonable((np.float64(5e-4),)) == [0.0005]


def test_jsonable_rejects_what_it_cannot_represent():
    with pytest.raises(TypeError, match="cannot turn a object into JSON"):
        jsonable(object())


def test_pose_list():
    c = math.cos(math.pi / 2)
    pose = np.array([[c, -1, 0, 1], [1, c, 0, 2], [0, 0, 1, 3], [0, 0, 0, 1]])
    assert pose_list(pose) == [
        [0.0, -1.0, 0.0, 1.0],
        [1.0, 0.0, 0.0, 2.0],
        [0.0, 0.0, 1.0, 3.0],
        [0.0, 0.0, 0.0, 1.0],
    ]
    with pytest.raises(NumericError, match="4x4"):
        pose_list(np.eye(3))
    with pytest.raises(NumericError, match="non-finite"):
        pose_list(np.full((4, 4), np.nan))
