"""Rounded real-world numbers: the tolerance policy covers angles, answers are monotone in
the tolerance, and a near miss says how far to loosen it (assemblykit.tolerance)."""

from __future__ import annotations

import copy
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import assemblykit
from assemblykit.inference import solve_task
from assemblykit.inference.reduction import model_scale, task_tolerance
from assemblykit.io.documents import read_text, read_yaml
from assemblykit.io.spec import parse_task
from assemblykit.model.task import Rounding
from assemblykit.tolerance import (
    DEFAULT,
    MAX_REL_LENGTH,
    Tolerance,
    round_up,
    using,
    written_resolution,
)

TASKS = Path(assemblykit.__file__).parent / "examples" / "tasks"
BUNDLED = sorted(TASKS.glob("*.yaml"))
SQRT3_2 = math.sqrt(3.0) / 2.0
#: The default covers data rounded to 1e-7 of the model's size: ten times it.
ROUNDED_1E7 = DEFAULT
#: The tolerance of exact numbers (the default before real data's six decimals set it).
TIGHT = Tolerance.relative(1e-9)
SWEEP = (1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 3e-3, 1e-2)
#: Fewer steps for rounded input, whose residues are solved numerically (slower).
ROUNDED_SWEEP = (1e-9, 1e-8, 1e-7, 1e-6, 1e-4, 1e-2)


def load(path: Path) -> dict[str, Any]:
    return read_yaml(read_text(path), path.name)


def solve(data: dict[str, Any], tol: Tolerance | None = None) -> Any:
    task = parse_task(data)
    with using(tol or DEFAULT):
        return solve_task(task)


def answers(solution: Any) -> tuple[str, tuple[tuple[str, int, str], ...]]:
    """What must not change: the status and every instance's dof and motion kind."""
    return solution.status, tuple((k, b.dof, b.motion) for k, b in solution.bodies.items())


def noisy(data: dict[str, Any], rel: float, seed: int) -> dict[str, Any]:
    """Every feature point moved by N(0, rel x size) per coordinate and every axis or
    normal turned by N(0, rel) per coordinate, then renormalised (size: the model's
    bounding-box diagonal)."""
    rng = np.random.default_rng(seed)
    size = model_scale(parse_task(data))
    out = copy.deepcopy(data)
    for body in out["bodies"].values():
        for feature in (body.get("features") or {}).values():
            if "point" in feature:
                feature["point"] = (
                    np.asarray(feature["point"]) + rng.normal(size=3) * rel * size
                ).tolist()
            for key in ("normal", "axis"):
                if key in feature:
                    v = np.asarray(feature[key], dtype=float)
                    v = v / np.linalg.norm(v) + rng.normal(size=3) * rel
                    feature[key] = (v / np.linalg.norm(v)).tolist()
    return out


def scaled(data: dict[str, Any], k: float) -> dict[str, Any]:
    """The task with every length (points, radii, sizes, moves, offsets) times ``k``."""
    out = copy.deepcopy(data)
    for body in out["bodies"].values():
        for feature in (body.get("features") or {}).values():
            if "point" in feature:
                feature["point"] = [k * x for x in feature["point"]]
            for key in ("radius", "size", "lead"):
                if key in feature:
                    feature[key] = k * feature[key]
    for situation in out["situations"]:
        for action in situation.get("actions") or []:
            if action[0] == "move" and len(action) > 2 and "by" in action[2]:
                action[2]["by"] = k * action[2]["by"]
    return out


def rotated_and_rounded(data: dict[str, Any], rotation: np.ndarray, digits: int) -> dict[str, Any]:
    """The task turned by ``rotation`` about the origin (every feature point, normal, axis
    and reference direction), each number then written to ``digits`` decimals, as a
    CAD export of the model in another frame would write it."""
    out = copy.deepcopy(data)
    for body in out["bodies"].values():
        for feature in (body.get("features") or {}).values():
            for key in ("point", "normal", "axis", "ref"):
                if key in feature:
                    turned = rotation @ np.asarray(feature[key], dtype=float)
                    feature[key] = [round(float(x), digits) for x in turned]
    return out


def v_groove(cosine: float) -> dict[str, Any]:
    """A bar in a 120-degree V-groove along y; the groove's normals typed with ``cosine``
    for cos 30° (sin 60°), the bar's exact."""
    return {
        "units": "mm",
        "bodies": {
            "block": {
                "fixed": True,
                "features": {
                    "left": {"type": "plane", "point": [-5, 0, 0], "normal": [cosine, 0, 0.5]},
                    "right": {"type": "plane", "point": [5, 0, 0], "normal": [-cosine, 0, 0.5]},
                },
            },
            "bar": {
                "features": {
                    "a": {"type": "plane", "point": [-5, 0, 0], "normal": [-SQRT3_2, 0, -0.5]},
                    "b": {"type": "plane", "point": [5, 0, 0], "normal": [SQRT3_2, 0, -0.5]},
                }
            },
        },
        "situations": [
            {
                "name": "s1",
                "relations": [
                    ["against", "bar.a", "block.left"],
                    ["against", "bar.b", "block.right"],
                ],
            }
        ],
    }


def groove_mismatch(cosine: float) -> float:
    """By hand: the angle between the typed normals (±c, 0, 1/2) minus the exact 120°."""
    cos_between = (0.25 - cosine * cosine) / (0.25 + cosine * cosine)
    return abs(math.acos(cos_between) - 2 * math.pi / 3)


def test_the_angle_follows_the_relative_length_unless_given():
    assert Tolerance.relative() == DEFAULT
    assert Tolerance.relative(1e-6) == Tolerance(rel_length=1e-6, angle=1e-6)
    assert Tolerance.relative(1e-6, 1e-9) == Tolerance(rel_length=1e-6, angle=1e-9)
    assert Tolerance.relative(None, 1e-4) == Tolerance(angle=1e-4)
    # the arm turns an angle into the length it weighs: the scale when the angle follows
    assert Tolerance.relative(1e-6).with_scale(40.0).arm == pytest.approx(40.0)
    assert Tolerance.relative(1e-6, 1e-9).with_scale(40.0).arm == pytest.approx(40_000.0)
    assert Tolerance.relative(1e-6) == DEFAULT
    # numerical decisions never loosen with the tolerance
    assert Tolerance.relative(1e-2).precision == DEFAULT.precision == 1e-9
    assert Tolerance.relative(1e-12).precision == 1e-12


@pytest.mark.parametrize(
    ("value", "expected"),
    [(2.31e-5, 2.4e-5), (1e-6, 1.1e-6), (4.0378e-7, 4.1e-7), (0.0999, 0.1), (3e-9, 3.1e-9)],
)
def test_round_up_gives_two_digits_strictly_above(value, expected):
    assert round_up(value) == expected


def test_needed_tolerance_is_the_mismatch_over_the_size_within_a_thousandfold():
    tol = Tolerance.relative(1e-9).with_scale(10.0)
    assert tol.needed("distance", 1e-6) == 1.1e-7  # 1e-6 mm over 10 mm, rounded up
    assert tol.needed("angle", 4.0378e-7) == 4.1e-7
    assert tol.needed("distance", 1e-5) == 1.1e-6  # 1e-6 relative: 1000 x 1e-9, within
    assert tol.needed("distance", 2e-5) is None  # 2e-6 relative: beyond 1000 x 1e-9
    assert tol.needed("handedness", 1e-9) is None  # not a size
    assert Tolerance.relative(0.05).needed("distance", 0.5) is None  # beyond the maximum
    assert Tolerance.relative(0.05).needed("distance", MAX_REL_LENGTH / 2) == 0.051


def test_v_groove_with_six_decimal_cosines_is_prismatic_at_the_default():
    exact = solve(v_groove(SQRT3_2))
    assert exact.status == "underconstrained"
    assert (exact.bodies["bar@s1"].dof, exact.bodies["bar@s1"].motion) == (1, "prismatic")

    typed = v_groove(0.866025)
    bar = solve(typed).bodies["bar@s1"]
    assert (bar.dof, bar.motion) == (1, "prismatic")
    # written to six digits, the cosines may be 5e-7 off: the tolerance is at least ten
    # times the turn that allows, whatever was asked for
    assert parse_task(typed).rounding == Rounding(0.0, pytest.approx(5e-7, rel=1e-5))
    assert solve(typed, TIGHT).status == "underconstrained"

    # the same numbers written to full precision are taken as exact
    precise = v_groove(math.nextafter(0.866025, 1.0))
    assert parse_task(precise).rounding == Rounding()
    strict = solve(precise, TIGHT)
    (conflict,) = strict.conflicts
    assert conflict.kind == "angle"
    assert conflict.value == pytest.approx(groove_mismatch(0.866025), rel=1e-6)  # 4.04e-7 rad
    assert conflict.needed_tolerance == 4.1e-7

    loose = solve(precise, Tolerance.relative(1e-6))
    bar = loose.bodies["bar@s1"]
    assert loose.status == "underconstrained"
    assert (bar.dof, bar.motion) == (1, "prismatic")
    np.testing.assert_allclose(np.abs(bar.invariants["direction"]), [0, 1, 0], atol=1e-12)
    # the suggested tolerance is enough, and the one just below it is not
    assert solve(precise, Tolerance.relative(4.1e-7)).status == "underconstrained"
    assert solve(precise, Tolerance.relative(4.0e-7)).status == "inconsistent"
    # an explicit angle tolerance overrides the rule
    assert solve(precise, Tolerance.relative(1e-6, 1e-9)).status == "inconsistent"
    # and the answer holds at every looser tolerance, up to the largest allowed
    for t in (*SWEEP[SWEEP.index(1e-6) :], MAX_REL_LENGTH):
        bar = solve(precise, Tolerance.relative(t)).bodies["bar@s1"]
        assert (bar.dof, bar.motion) == (1, "prismatic"), t


def test_written_numbers_raise_the_tolerance_to_ten_times_their_rounding():
    # by hand: 12.346 (five digits) may be 5e-4 off, and the model is about 24.7 across
    data = offset_planes(0.0)
    data["bodies"]["table"]["features"]["far"]["point"] = [12.346, 0, 0]
    data["bodies"]["block"]["features"]["foot2"]["point"] = [12.346, 0, 0]
    task = parse_task(data)
    assert task.rounding == Rounding(5e-4, 0.0)
    tol = task_tolerance(task)
    assert tol.length == pytest.approx(10 * 5e-4)
    assert tol.angle == DEFAULT.angle
    # numbers as designed (few digits) or computed (full precision) are exact
    assert parse_task(offset_planes(0.25)).rounding == Rounding()
    assert task_tolerance(parse_task(offset_planes(0.25))).rel_length == DEFAULT.rel_length


@pytest.mark.parametrize(
    ("value", "resolution"),
    [
        (0.86603, 5e-6),
        (-0.707107, 5e-7),
        (123.457, 5e-4),
        (1.2345e-5, 5e-10),
        (12.5, 0.0),
        (0.25, 0.0),
        (100.0, 0.0),
        (1234567.0, 0.0),
        (math.sqrt(3) / 2, 0.0),
        (0.0, 0.0),
    ],
)
def test_the_resolution_of_a_written_number(value, resolution):
    assert written_resolution(value) == pytest.approx(resolution, rel=1e-12)


def offset_planes(offset: float) -> dict[str, Any]:
    """A block on two feet 10 apart, on two table planes ``offset`` apart in height."""
    return {
        "units": "mm",
        "bodies": {
            "table": {
                "fixed": True,
                "features": {
                    "near": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]},
                    "far": {"type": "plane", "point": [10, 0, offset], "normal": [0, 0, 1]},
                },
            },
            "block": {
                "features": {
                    "foot1": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, -1]},
                    "foot2": {"type": "plane", "point": [10, 0, 0], "normal": [0, 0, -1]},
                }
            },
        },
        "situations": [
            {
                "name": "s1",
                "relations": [
                    ["against", "block.foot1", "table.near"],
                    ["against", "block.foot2", "table.far"],
                ],
            }
        ],
    }


def test_offset_planes_are_nearly_consistent_with_the_tolerance_that_accepts_them():
    offset = 1e-6
    data = offset_planes(offset)
    size = math.hypot(10.0, offset)  # the bounding-box diagonal of the feature points
    assert solve(data).status == "underconstrained"  # 1e-7 of the size: within the default
    strict = solve(data, TIGHT)
    assert strict.status == "inconsistent"
    (conflict,) = strict.conflicts
    assert conflict.kind == "distance"
    assert conflict.value == pytest.approx(offset, rel=1e-9)
    # 1e-6 over a size a hair above 10: just below 1e-7, rounded up to 1.0e-7
    assert conflict.needed_tolerance >= offset / size
    assert conflict.needed_tolerance == 1e-7
    out = strict.to_dict()
    assert out["conflicts"][0]["needed_tolerance"] == 1e-7
    assert out["suggested_tolerance"] == 1e-7
    again = solve(data, Tolerance.relative(conflict.needed_tolerance))
    assert again.status == "underconstrained"
    assert (again.bodies["block@s1"].dof, again.bodies["block@s1"].motion) == (3, "planar")
    # the best common pose splits the miss: each relation misses by half the offset, so
    # the answer turns at half the suggestion, never above it
    assert solve(data, Tolerance.relative(0.45 * offset / size)).status == "inconsistent"
    assert solve(data, Tolerance.relative(0.55 * offset / size)).status == "underconstrained"


def test_a_misfit_of_1e_4_of_the_model_is_one_at_the_default_with_its_size():
    strict = solve(offset_planes(1e-3))
    assert strict.status == "inconsistent"
    (conflict,) = strict.conflicts
    assert conflict.kind == "distance" and conflict.value == pytest.approx(1e-3, rel=1e-9)
    assert conflict.needed_tolerance == 1e-4  # 1e-3 over a size a hair above 10


def test_a_far_miss_suggests_nothing():
    data = v_groove(0.8)  # about 3.3 degrees off
    (conflict,) = solve(data).conflicts
    assert conflict.needed_tolerance is None
    assert solve(data).to_dict()["suggested_tolerance"] is None


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: p.stem)
def test_rounded_bundled_tasks_keep_their_answers_at_the_default(path):
    data = load(path)
    assert answers(solve(noisy(data, 1e-7, 0), ROUNDED_1E7)) == answers(solve(data))


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: p.stem)
def test_rounded_bundled_tasks_are_nearly_consistent_at_a_tight_tolerance(path):
    data = load(path)
    strict = solve(noisy(data, 1e-7, 0), TIGHT)
    if answers(strict) == answers(solve(data, TIGHT)):
        return
    # every near miss names a tolerance below the default's tenfold
    assert strict.status == "inconsistent"
    assert strict.suggested_tolerance is not None
    assert strict.suggested_tolerance <= 1e-5


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: p.stem)
def test_bundled_tasks_in_a_generic_frame_written_to_six_decimals_keep_their_answers(path):
    # a rotation about (0.3, -0.7, 0.5) by 0.91 rad: no feature stays along an axis
    axis = np.array([0.3, -0.7, 0.5])
    turn = Rotation.from_rotvec(axis).as_matrix()
    data = load(path)
    assert answers(solve(rotated_and_rounded(data, turn, 6))) == answers(solve(data))


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: p.stem)
@pytest.mark.parametrize("k", [1e-3, 1e3])
def test_scaled_bundled_tasks_keep_their_answers_and_scale_their_positions(path, k):
    data = load(path)
    base, big = solve(data), solve(scaled(data, k))
    assert answers(big) == answers(base)
    # positions scale with the model, within the default tolerance (numeric residues are
    # solved to it; closed forms are exact to rounding)
    slack = DEFAULT.rel_length * model_scale(parse_task(data))
    for key, body in base.bodies.items():
        other = big.bodies[key]
        if body.dof == 0:  # a continuum's representative is any of its poses
            np.testing.assert_allclose(other.pose[:3, 3], k * body.pose[:3, 3], atol=k * slack)
            np.testing.assert_allclose(other.pose[:3, :3], body.pose[:3, :3], atol=slack)


CONSISTENT = ("solved", "ambiguous", "underconstrained")


@pytest.mark.parametrize(
    ("name", "rel", "seed"),
    [
        ("four_bar", 0.0, 0),
        ("four_bar", 1e-7, 0),
        ("four_bar", 1e-7, 1),
        ("peg_in_block", 0.0, 0),
        ("gear_pair", 1e-7, 0),
        ("w14_square_peg", 1e-7, 0),
        ("w6_unequal_pins", 0.0, 0),
    ],
)
def test_answers_are_monotone_in_the_tolerance(name, rel, seed):
    data = load(TASKS / f"{name}.yaml")
    steps = ROUNDED_SWEEP if rel else SWEEP
    if rel:
        data = noisy(data, rel, seed)
    sweep = [solve(data, Tolerance.relative(t)) for t in steps]
    statuses = [s.status for s in sweep]
    first = next((i for i, s in enumerate(statuses) if s in CONSISTENT), len(statuses))
    assert all(s in CONSISTENT for s in statuses[first:]), statuses
    if not rel:  # exact input: one answer at every tolerance
        assert len({answers(s) for s in sweep}) == 1, statuses
    else:  # rounded input: past the noise level, one answer
        settled = [answers(s) for s, t in zip(sweep, steps, strict=True) if t >= 1e-6]
        assert len(set(settled)) == 1


def tilted_edge(tilt: float) -> dict[str, Any]:
    """A block on a table whose edge should be perpendicular to the table's normal but is
    tilted ``tilt`` rad out of the block's bottom plane (a relation solved numerically)."""
    return {
        "units": "mm",
        "bodies": {
            "table": {
                "fixed": True,
                "features": {
                    "top": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]},
                    "up": {"type": "axis", "point": [0, 0, 0], "axis": [0, 0, 1]},
                },
            },
            "block": {
                "features": {
                    "bottom": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, -1]},
                    "edge": {
                        "type": "axis",
                        "point": [10, 0, 0],
                        "axis": [math.cos(tilt), 0, math.sin(tilt)],
                    },
                },
            },
        },
        "situations": [
            {
                "name": "s1",
                "relations": [
                    ["against", "block.bottom", "table.top"],
                    ["perpendicular", "block.edge", "table.up"],
                ],
            }
        ],
    }


def test_the_residue_holds_angles_to_the_angle_tolerance():
    """By hand: the best pose tilts the block by half the edge's tilt, so each relation
    misses by 5e-5 rad, weighed as 5e-5 x 10 (the model's size) = 5e-4."""
    data = tilted_edge(1e-4)
    strict = solve(data)
    (conflict,) = strict.conflicts
    assert conflict.kind == "residual"
    assert conflict.value == pytest.approx(5e-4, rel=1e-4)
    assert conflict.needed_tolerance == 5e-5
    for tol in (Tolerance.relative(5e-5), Tolerance.relative(1e-3), Tolerance.relative(1e-6, 1e-3)):
        loose = solve(data, tol)
        block = loose.bodies["block@s1"]
        assert (loose.status, block.dof, block.motion) == ("underconstrained", 3, "planar")
    # a loose length tolerance does not excuse an angle held tight
    assert solve(data, Tolerance.relative(1e-3, 1e-6)).status == "inconsistent"
    # tilted by 1e-6 rad (an axis written to six decimals), the default accepts it
    assert solve(tilted_edge(1e-6)).status == "underconstrained"
