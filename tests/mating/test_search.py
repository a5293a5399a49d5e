"""Step three and the answer: Liu & Popplestone 1990 Examples 1-2, emptied domains, loci,
sweeping."""

from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pytest
import trimesh
import yaml

from assemblykit.algebra import Coset, Locus, SymmetryGroup, se3
from assemblykit.geometry.interference import interference_threshold, overlap_volume
from assemblykit.geometry.solids import placed
from assemblykit.io.problem import load_problem, parse_problem
from assemblykit.mating import clearance, search
from assemblykit.mating.graph import build_graph
from assemblykit.mating.laws import equivalent_features
from assemblykit.mating.loci import locus_meet
from assemblykit.mating.search import MatingResult, mate, solve_csp
from assemblykit.tolerance import Tolerance

TOL = Tolerance()


def _answer(result: MatingResult) -> set[frozenset[tuple[int, str, str, str, str]]]:
    return {
        frozenset(
            (c.goal.number, c.goal.first, c.first, c.goal.second, c.second) for c in config.pairs
        )
        for config in result.configurations
    }


@pytest.fixture(scope="module")
def example1(mating_examples: Path) -> MatingResult:
    return mate(load_problem(mating_examples / "example1.yaml"))


@pytest.fixture(scope="module")
def example2_data(mating_examples: Path) -> dict:
    return yaml.safe_load((mating_examples / "example2.yaml").read_text())


def test_example1_gives_the_seed_answer(example1: MatingResult) -> None:
    assert _answer(example1) == {
        frozenset({(1, "b1", "comp1", "b4", "comp13"), (2, "b2", "comp1", "b4", "comp1"),
                   (3, "b3", "comp1", "b4", "comp12")}),
        frozenset({(1, "b1", "comp1", "b4", "comp1"), (2, "b2", "comp1", "b4", "comp13"),
                   (3, "b3", "comp1", "b4", "comp12")}),
    }  # fmt: skip
    assert example1.count == 8
    assert [c.copies for c in example1.configurations] == [4, 4]
    assert dict(example1.statistics) == {
        1: (6, 4, 4, 2, 2, 2),
        2: (6, 4, 4, 2, 2, 2),
        3: (3, 1, 1, 1, 1, 1),
    }
    assert example1.emptied is None and example1.rejected == 0


def test_example1_poses(example1: MatingResult) -> None:
    config = next(c for c in example1.configurations if c.pairs[0].second == "comp1")
    np.testing.assert_allclose(config.poses["b4"], np.eye(4), atol=1e-12)
    np.testing.assert_allclose(config.poses["b1"], se3.translation((-20, 0, 1)), atol=1e-9)
    np.testing.assert_allclose(config.poses["b2"], se3.translation((20, 0, 1)), atol=1e-9)
    np.testing.assert_allclose(config.poses["b3"], se3.translation((0, 0, 1)), atol=1e-9)
    assert config.motions == {}


def test_example1_json_and_or_and(example1: MatingResult) -> None:
    data = example1.to_dict()
    assert data["count"] == 8 and data["representatives"] == 2 and data["status"] == "solved"
    assert data["configurations"][0]["pairs"][2] == {
        "goal": 3,
        "first": ["b3", "comp1"],
        "second": ["b4", "comp12"],
    }
    assert data["statistics"]["domains"]["3"] == [3, 1, 1, 1, 1, 1]
    assert data["emptied"] is None
    assert example1.or_and().startswith("** [Or [And [fit [b1 comp1] [b4 comp1]]")


def test_example2_gives_the_seed_answer_through_loci(example2_data: dict) -> None:
    result = mate(parse_problem(example2_data))
    assert _answer(result) == {
        frozenset({(1, "b3", "comp1", "b1", "comp2"), (2, "b3", "comp2", "b2", "comp2"),
                   (3, "b1", "comp1", "b2", "comp1")}),
        frozenset({(1, "b3", "comp2", "b1", "comp2"), (2, "b3", "comp1", "b2", "comp2"),
                   (3, "b1", "comp1", "b2", "comp1")}),
    }  # fmt: skip
    assert result.count == 2
    # b1 is fixed (first in the file); b3 turns about b1's bore, b2 closes the triangle.
    config = next(c for c in result.configurations if c.pairs[0].first == "comp2")
    np.testing.assert_allclose(config.poses["b1"], np.eye(4), atol=1e-12)
    apex = se3.apply(config.poses["b1"], np.array([10.0, 0, 2]))
    np.testing.assert_allclose(
        se3.apply(config.poses["b2"], np.array([10.0, 0, 2])), apex, atol=1e-9
    )
    pins = [se3.apply(config.poses["b3"], np.array(p)) for p in ([0.0, 0, 2], [10.0, 0, 2])]
    # The triangle is equilateral with side 10: every joint is 10 from the others.
    for a, b in ((pins[0], pins[1]), (pins[0], apex), (pins[1], apex)):
        assert np.linalg.norm(a[:2] - b[:2]) == pytest.approx(10.0, abs=1e-9)


def test_example2_without_the_wall_has_both_loci_points(example2_data: dict) -> None:
    data = copy.deepcopy(example2_data)
    data["bodies"]["b3"]["mesh"]["add"].pop(1)
    result = mate(parse_problem(data))
    assert result.count == 4 and len(_answer(result)) == 2


def test_no_solution_names_the_goal_and_law(mating_examples: Path) -> None:
    result = mate(load_problem(mating_examples / "one_socket.yaml"))
    assert result.configurations == () and result.count == 0
    assert (result.emptied.goal, result.emptied.law) == (2, "mandatory request")
    assert result.to_dict()["emptied"] == {"goal": 2, "law": "mandatory request"}


def test_node_consistency_can_empty_a_domain(mating_examples: Path) -> None:
    data = yaml.safe_load((mating_examples / "example1.yaml").read_text())
    # A wall beside comp12 on b3's side too: b3 now collides in every seat.
    data["bodies"]["b4"]["mesh"]["add"].append({"box": {"min": [-8, -10, 0], "max": [8, -6, 4]}})
    result = mate(parse_problem(data))
    assert (result.emptied.goal, result.emptied.law) == (3, "node consistency")
    assert result.statistics[3] == (3, 0, 0, 0, 0, 0)


def test_circle_loci_meet_in_two_one_or_no_points() -> None:
    z = np.array([0.0, 0, 1])
    a = Locus("circle", point=np.zeros(3), direction=z, radius=10.0)
    b = Locus("circle", point=np.array([10.0, 0, 0]), direction=z, radius=10.0)
    points = locus_meet(a, b, TOL)
    np.testing.assert_allclose(points, [[5, math.sqrt(75), 0], [5, -math.sqrt(75), 0]], atol=1e-12)
    touching = Locus("circle", point=np.array([20.0, 0, 0]), direction=z, radius=10.0)
    np.testing.assert_allclose(locus_meet(a, touching, TOL), [[10, 0, 0]], atol=1e-12)
    far = Locus("circle", point=np.array([30.0, 0, 0]), direction=z, radius=5.0)
    assert locus_meet(a, far, TOL) == []
    lifted = Locus("circle", point=np.array([10.0, 0, 1]), direction=z, radius=10.0)
    assert locus_meet(a, lifted, TOL) == []


HINGE = {
    "bodies": {
        "frame": {
            "features": {
                "top": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]},
                "bore": {"type": "hole", "point": [0, 0, 0], "axis": [0, 0, -1], "radius": 1},
            },
            "compound": {"seat": ["top", "bore"]},
            "mesh": {
                "add": [
                    {"box": {"min": [-5, -5, -2], "max": [5, 5, 0]}},
                    {"box": {"min": [3, -1, 0], "max": [5, 1, 3]}},
                ],
                "cut": [
                    {"cylinder": {"point": [0, 0, -3], "axis": [0, 0, 1], "radius": 1, "height": 4}}
                ],
            },
        },
        "door": {
            "features": {
                "face": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, -1]},
                "pin": {"type": "shaft", "point": [0, 0, 0], "axis": [0, 0, -1], "radius": 1},
            },
            "compound": {"hinge": ["face", "pin"]},
            "mesh": {
                "add": [
                    {"box": {"min": [-1, -1, 0], "max": [8, 1, 1]}},
                    {
                        "cylinder": {
                            "point": [0, 0, 0],
                            "axis": [0, 0, -1],
                            "radius": 0.9,
                            "height": 1.5,
                        }
                    },
                ]
            },
        },
    },
    "goals": [["fit", "door", "frame"]],
}


def test_sweep_reports_the_range_of_motion_of_a_hinge() -> None:
    result = mate(parse_problem(HINGE))
    (config,) = result.configurations
    motion = config.motions["door"]
    assert (motion.kind, motion.parameter) == ("revolute", "angle")
    # The arm (half-width 1) clears the stop's corner (3, 1) beyond 2 atan(1/3); the
    # touching threshold of the interference policy allows a sliver of about 0.01 rad.
    (interval,) = motion.intervals
    limit = 2 * math.atan(1 / 3)
    assert interval == pytest.approx((limit, 2 * math.pi - limit), abs=0.02)
    assert interval[0] <= limit + 1e-9
    assert result.to_dict()["configurations"][0]["motions"]["door"]["motion"] == "revolute"


def test_sweep_rejects_a_body_with_no_free_position() -> None:
    data = copy.deepcopy(HINGE)
    data["bodies"]["frame"]["mesh"]["add"].append({"box": {"min": [-9, -9, 0], "max": [9, 9, 3]}})
    data["bodies"]["frame"]["mesh"]["cut"].append(
        {"box": {"min": [-1.5, -1.5, 0], "max": [1.5, 1.5, 4]}}
    )
    result = mate(parse_problem(data))
    assert result.configurations == () and result.rejected == 1


def test_cp_sat_finds_the_same_assignments(
    mating_examples: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pytest.importorskip("ortools")
    problem = load_problem(mating_examples / "example1.yaml")
    domains = equivalent_features(problem, build_graph(problem).domains)
    small = solve_csp(domains)
    monkeypatch.setattr(search, "SMALL_SEARCH", 0)
    large = solve_csp(domains)
    key = [{g: (c.first, c.second) for g, c in a.items()} for a in small]
    assert key == [{g: (c.first, c.second) for g, c in a.items()} for a in large]
    assert len(key) == 2


# ----------------------------------------------------------------------------- clearance


def _lens_area(radius: float, distance: float) -> float:
    """Area shared by two discs of equal radius whose centres are ``distance`` apart."""
    half = distance / 2
    return 2 * radius**2 * math.acos(half / radius) - half * math.sqrt(4 * radius**2 - distance**2)


def test_two_arms_overlapping_at_every_angle_have_no_configuration(mating_examples: Path) -> None:
    problem = load_problem(mating_examples / "two_arms.yaml")
    # By hand: the hubs (radius 3, height 1, centres 4 apart) share a lens at any angles.
    lens = _lens_area(3.0, 4.0)
    assert lens == pytest.approx(18 * math.acos(2 / 3) - 2 * math.sqrt(20))
    arm = problem.bodies["arm1"].mesh
    for first, second in ((0.0, 0.0), (1.0, -2.0), (math.pi, 0.5), (-2.5, 2.5)):
        a = placed(arm, se3.rot_z(first))
        b = placed(arm, se3.translation((4, 0, 0)) @ se3.rot_z(second))
        # The 48-gon hubs lose under 1 % of the lens.
        assert overlap_volume(a, b) > 0.98 * lens
    result = mate(problem)
    assert result.count == 0 and result.configurations == ()
    assert (result.emptied.goal, result.emptied.law) == (1, "arc consistency")
    assert result.emptied.reason == "arm1 and arm2 interfere in every position of goals 1 and 2"
    assert result.statistics[1] == (2, 2, 2, 2, 0, 0)
    assert result.to_dict()["status"] == "no solution"


def test_step_three_rejects_two_arms_that_interfere_everywhere(mating_examples: Path) -> None:
    problem = load_problem(mating_examples / "two_arms.yaml")
    domains = build_graph(problem).domains
    # Without the arc consistency pruning: arm1 on the left bore, arm2 on the right.
    pairs = (
        next(c for c in domains[1] if c.second == "seat_left"),
        next(c for c in domains[2] if c.second == "seat_right"),
    )
    placement = search.place(problem, pairs)
    assert placement.configurations == ()
    (rejection,) = placement.rejections
    assert rejection.bodies == ("arm1", "arm2") and rejection.proven
    assert rejection.reason == "arm1 and arm2 interfere in every position"


def test_two_arms_far_apart_turn_clear_of_each_other(mating_examples: Path) -> None:
    data = yaml.safe_load((mating_examples / "two_arms.yaml").read_text())
    # Bores 12 apart: the hubs are clear, the bars (length 10) cross only at some angles.
    data["bodies"]["base"]["features"]["right"]["point"] = [12, 0, 0]
    data["bodies"]["base"]["mesh"]["add"][0]["box"]["max"] = [18, 6, 0]
    data["bodies"]["base"]["mesh"]["cut"][1]["cylinder"]["point"] = [12, 0, -4]
    problem = parse_problem(data)
    result = mate(problem)
    assert result.count == 2 and result.rejections == ()
    arm = problem.bodies["arm1"].mesh
    threshold = interference_threshold(arm, arm, problem.tolerance.for_mesh())
    for config in result.configurations:
        a = placed(arm, config.poses["arm1"])
        b = placed(arm, config.poses["arm2"])
        assert overlap_volume(a, b) <= threshold
        for name in ("arm1", "arm2"):
            assert config.motions[name].kind == "revolute"
            assert overlap_volume(placed(arm, config.poses[name]), problem.bodies["base"].mesh) <= (
                threshold
            )


def test_shaft_only_fit_slides_its_head_out_of_the_base(mating_examples: Path) -> None:
    problem = load_problem(mating_examples / "shaft_fit.yaml")
    result = mate(problem)
    (config,) = result.configurations
    peg, base = problem.bodies["peg"].mesh, problem.bodies["base"].mesh
    # The representative pose (shaft frame on the bore frame) buries the head 2 deep:
    # 6 x 6 x 2 less the bore (a 48-gon of radius 1), computed here by manifold3d.
    bore = 24 * math.sin(2 * math.pi / 48)
    assert overlap_volume(peg, base) == pytest.approx(2 * (36 - bore), rel=1e-6)
    pose = config.poses["peg"]
    # The pose reported is within the cylindrical freedom (same axis, no tilt) ...
    np.testing.assert_allclose(pose[:3, 2], [0, 0, 1], atol=1e-9)
    np.testing.assert_allclose(pose[:2, 3], [0, 0], atol=1e-9)
    # ... lifted by the hand answer, 2, until the head rests on the top, and clear.
    assert pose[2, 3] == pytest.approx(2.0, abs=1e-3)
    threshold = interference_threshold(peg, base, problem.tolerance.for_mesh())
    assert overlap_volume(placed(peg, pose), base) <= threshold
    assert config.motions["peg"].kind == "cylindrical"


def test_cylindrical_bodies_are_judged_over_both_parameters() -> None:
    tol = Tolerance(scale=20.0)
    box = trimesh.creation.box(bounds=[[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]])
    axis_z = SymmetryGroup.cylindrical((0, 0, 0), (0, 0, 1))
    # A cube turning and sliding on the z axis against a plate with a hole of radius 1:
    # the cube's corner (radius sqrt 2) hits the plate at every turn, but a slide of
    # more than 1 above or below clears it (the witness).
    plate = trimesh.creation.box(bounds=[[-5.0, -5.0, -0.5], [5.0, 5.0, 0.5]])
    hole = trimesh.creation.cylinder(radius=1.0, height=2.0, sections=48)
    plate = trimesh.boolean.difference([plate, hole], engine="manifold")
    cube = clearance.mover("cube", box, Coset(axis_z, np.eye(4)), tol)
    fixed = clearance.mover("plate", plate, Coset(SymmetryGroup.identity(), np.eye(4)), tol)
    found = clearance.judge_pair(cube, fixed, tol)
    assert found.verdict is clearance.Verdict.FREE
    assert abs(found.witness[1]) >= 1.5 - 1e-9
    # Two cylindrical cubes on axes 1 apart: their cores (the largest discs about each
    # axis, radius 1) overlap whatever the turns, but the slides part them: free.
    other = Coset(SymmetryGroup.cylindrical((1, 0, 0), (0, 0, 1)), se3.translation((1, 0, 0)))
    second = clearance.mover("second", box, other, tol)
    assert clearance.judge_pair(cube, second, tol).verdict is clearance.Verdict.FREE
    # Turning only (revolute), the same two cubes share the cores' lens at every angle.
    turning = [
        clearance.mover(
            n, box, Coset(SymmetryGroup.revolute(p, (0, 0, 1)), se3.translation(p)), tol
        )
        for n, p in (("a", (0, 0, 0)), ("b", (1, 0, 0)))
    ]
    assert clearance.judge_pair(*turning, tol).verdict is clearance.Verdict.BLOCKED
    # Far apart (axes 4 apart, radius sqrt 2 each), the sweeps prove them clear.
    apart = clearance.mover(
        "c",
        box,
        Coset(SymmetryGroup.revolute((4, 0, 0), (0, 0, 1)), se3.translation((4, 0, 0))),
        tol,
    )
    assert clearance.judge_pair(turning[0], apart, tol).verdict is clearance.Verdict.CLEAR


EXAMPLE2_ANSWER = {
    frozenset({(1, "b3", "comp1", "b1", "comp2"), (2, "b3", "comp2", "b2", "comp2"),
               (3, "b1", "comp1", "b2", "comp1")}),
    frozenset({(1, "b3", "comp2", "b1", "comp2"), (2, "b3", "comp1", "b2", "comp2"),
               (3, "b1", "comp1", "b2", "comp1")}),
}  # fmt: skip


def _tilted(data: dict, tilt: float) -> dict:
    """example2 with b1's bore axis tilted by ``tilt`` radians (about x)."""
    tilted = copy.deepcopy(data)
    tilted["bodies"]["b1"]["features"]["bore"]["axis"] = [0.0, tilt, 1.0]
    return tilted


# a tilt of six-decimal data within the default angle tolerance (1e-6 rad) in the
# default tier, one near a looser tolerance in the slow one
@pytest.mark.parametrize(
    ("tilt", "tol"),
    [(1e-8, Tolerance()), pytest.param(1e-6, Tolerance(angle=1e-5), marks=pytest.mark.slow)],
)
def test_a_bore_tilted_within_the_angle_tolerance_mates_as_the_exact_one(
    example2_data: dict, tilt: float, tol: Tolerance
) -> None:
    result = mate(parse_problem(_tilted(example2_data, tilt), tol=tol))
    assert _answer(result) == EXAMPLE2_ANSWER
    assert result.count == 2


def test_a_bore_tilted_beyond_the_angle_tolerance_is_an_answer_not_a_crash(
    example2_data: dict,
) -> None:
    # 1e-4 rad is beyond the default (1e-6): b1's plane and bore no longer share a turn,
    # so no fit of a turning pin exists
    result = mate(parse_problem(_tilted(example2_data, 1e-4)))
    assert result.to_dict()["status"] == "no solution" and result.count == 0


def test_a_free_pose_search_cut_short_says_so(mating_examples: Path, monkeypatch) -> None:
    # the peg must slide 2 out of the base: one check cannot find that position
    monkeypatch.setattr(search, "WITNESS_CHECKS", 1)
    result = mate(load_problem(mating_examples / "shaft_fit.yaml"))
    assert result.count == 0
    (rejection,) = result.rejections
    assert not rejection.proven
    assert rejection.reason == (
        "no collision-free position found for base, peg within 1 checks (search cut short)"
    )


def test_a_free_pose_search_that_ends_finds_the_slide(mating_examples: Path) -> None:
    result = mate(load_problem(mating_examples / "shaft_fit.yaml"))
    assert result.count == 1 and result.rejections == ()


@pytest.mark.parametrize("sides", [6, 65, 100])
def test_a_prism_key_fits_its_socket_once_whatever_its_sides(sides: int) -> None:
    # the key's own symmetry maps each of the n turned fits onto the others: one
    # configuration (no cap on the number of sides)
    prism = {"type": "prism", "sides": sides, "size": 2, "point": [0, 0, 0], "axis": [0, 0, -1]}
    data = {
        "units": "mm",
        "bodies": {
            "base": {
                "features": {
                    "top": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]},
                    "socket": {**prism, "male": False},
                },
                "compound": {"c": ["top", "socket"]},
            },
            "key": {
                "features": {
                    "bottom": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, -1]},
                    "stem": {**prism, "male": True},
                },
                "compound": {"c": ["bottom", "stem"]},
            },
        },
        "goals": [["fit", "key", "base"]],
    }
    result = mate(parse_problem(data))
    assert result.to_dict()["status"] == "solved" and result.count == 1
