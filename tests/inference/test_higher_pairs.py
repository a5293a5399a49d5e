"""Higher pairs in closed form: a point held in planes and lines, alone and with a lower
pair (ALGEBRA.md §3, §5.3; inference/network.py folds the loci, inference/reduction.py
solves them). Every expected pose and invariant is worked out by hand in the comments."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import assemblykit
from assemblykit.algebra import se3
from assemblykit.features.primitives import Axis, Ball, Hole, Plane, Point, Shaft
from assemblykit.inference import solve_numeric_only
from assemblykit.io.spec import load_task
from assemblykit.model.body import Body
from assemblykit.model.relations import FeatureRef, Relation
from assemblykit.model.task import Situation, Task

EXACT = 1e-12
X, Y, Z = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)
TASKS = Path(assemblykit.__file__).parent / "examples" / "tasks"


def rel(kind: str, first: str, second: str, **options) -> Relation:
    return Relation(kind, (FeatureRef.parse(first), FeatureRef.parse(second)), options)


def make_task(bodies, *relations: Relation) -> Task:
    return Task("mm", {b.name: b for b in bodies}, (Situation("s1", tuple(relations)),))


def solve(bodies, *relations: Relation) -> dict:
    return make_task(bodies, *relations).solve(explain=True).to_dict()


def shift(x: float, y: float = 0.0, z: float = 0.0) -> np.ndarray:
    return se3.translation((x, y, z))


def unoriented(a, b) -> bool:
    return bool(np.linalg.norm(np.cross(np.asarray(a, float), np.asarray(b, float))) < EXACT)


# CadQuery's PointInPlane test re-expressed: the faces x = 0.5, y = 1, z = 1.5 of a fixed
# 1 x 2 x 3 box centred at the origin, and a point at the origin of body v.
BOX = Body(
    "box",
    {
        "right": Plane((0.5, 0, 0), X),
        "back": Plane((0, 1, 0), Y),
        "top": Plane((0, 0, 1.5), Z),
        "left": Plane((-0.5, 0, 0), (-1, 0, 0)),
    },
    fixed=True,
)
V = Body("v", {"tip": Point((0, 0, 0)), "bottom": Plane((0, 0, 0), (0, 0, -1))})
IN_RIGHT = rel("point_on_plane", "v.tip", "box.right")
IN_BACK = rel("point_on_plane", "v.tip", "box.back")
IN_TOP = rel("point_on_plane", "v.tip", "box.top")


def test_point_in_one_plane_keeps_five_dof_and_the_pose_as_written():
    out = solve([BOX, V], IN_RIGHT)
    v = out["bodies"]["v@s1"]
    assert (v["dof"], v["motion"], v["mechanism"]) == (5, "mechanism", "point-in-plane")
    # least motion: the tip (0,0,0) goes straight onto x = 0.5, no turn
    np.testing.assert_allclose(v["pose"], shift(0.5), atol=EXACT)
    assert unoriented(v["invariants"]["normal"], X)
    np.testing.assert_allclose(v["invariants"]["point"], [0.5, 0, 0], atol=EXACT)
    assert v["freedom"] == (
        "v@s1 can slide its point (0.5, 0, 0) in the plane normal to +X"
        " and turn about it: 5 dof; two more point_on_plane on the same point (making a"
        " spherical joint) and relations on the body's orientation would remove it"
    )


def test_point_in_two_planes_lies_on_their_line_with_four_dof():
    out = solve([BOX, V], IN_RIGHT, IN_BACK)
    v = out["bodies"]["v@s1"]
    assert (v["dof"], v["motion"], v["mechanism"]) == (4, "mechanism", "point-on-line")
    np.testing.assert_allclose(v["pose"], shift(0.5, 1.0), atol=EXACT)
    # x = 0.5 and y = 1 meet in the vertical line through (0.5, 1, 0)
    assert unoriented(v["invariants"]["direction"], Z)
    np.testing.assert_allclose(v["invariants"]["point"], [0.5, 1, 0], atol=EXACT)
    assert "higher-pair" in [step["rule"] for step in out["trace"]]


def test_point_in_three_planes_is_a_spherical_joint_about_the_corner():
    out = solve([BOX, V], IN_RIGHT, IN_BACK, IN_TOP)
    v = out["bodies"]["v@s1"]
    assert (v["dof"], v["motion"], v["solutions"]) == (3, "spherical", 1)
    np.testing.assert_allclose(v["invariants"]["center"], [0.5, 1, 1.5], atol=EXACT)
    # the representative is the pose as written moved onto the corner: identity rotation
    np.testing.assert_allclose(v["pose"], shift(0.5, 1.0, 1.5), atol=EXACT)
    assert v["freedom"] == (
        "v@s1 can turn about (0.5, 1, 1.5): 3 dof; a fits or coaxial through (0.5, 1, 1.5)"
        " (leaving a turn about that axis) and a stop off that axis would remove it"
    )
    assert "mechanism" not in v  # a Hervé family needs no other name
    assert ("free", "v@s1", 3, 3, v["freedom"]) in [
        (s["rule"], s["link"], s["dof_before"], s["dof_after"], s["detail"]) for s in out["trace"]
    ]
    assert "residue" not in [step["rule"] for step in out["trace"]]


@pytest.mark.parametrize(("relations", "dof"), [(1, 5), (2, 4), (3, 3)])
def test_the_numeric_solver_measures_the_same_dof(relations, dof):
    """An independent check of the closed forms' dof: the Jacobian rank of the residue."""
    task = make_task([BOX, V], *(IN_RIGHT, IN_BACK, IN_TOP)[:relations])
    answer = solve_numeric_only(task)["v@s1"]
    assert answer.dof == dof
    # the tip, at the body's origin, is at the pose's translation
    np.testing.assert_allclose(answer.pose[:relations, 3], [0.5, 1, 1.5][:relations], atol=1e-7)


def test_bundled_point_in_planes_task():
    for name in ("point_in_planes.rapt", "point_in_planes.yaml"):
        out = load_task(TASKS / name).solve().to_dict()["bodies"]
        found = [(out[k]["dof"], out[k]["motion"]) for k in ("one@s1", "two@s1", "three@s1")]
        assert found == [(5, "mechanism"), (4, "mechanism"), (3, "spherical")]
        np.testing.assert_allclose(out["three@s1"]["pose"], shift(0.5, 1, 1.5), atol=EXACT)


def test_parallel_planes_apart_are_a_distance_conflict():
    out = solve([BOX, V], IN_RIGHT, rel("point_on_plane", "v.tip", "box.left"))
    assert out["status"] == "inconsistent"
    (conflict,) = out["conflicts"]
    # x = 0.5 and x = -0.5: one unit apart
    assert (conflict["kind"], conflict["value"]) == ("distance", pytest.approx(1.0, abs=EXACT))
    assert len(conflict["relations"]) == 2


# A world with a table z = 0, two walls x = 5 and y = 0 (normals into the room... any
# orientation: a point on a plane does not see its side), a roof z = 5 and a rod, the
# line y = 0, z = 3 along x. The box's corner is (1, 1, 0), its ball centre (1, 1, 0).
WORLD = Body(
    "world",
    {
        "table": Plane((0, 0, 0), Z),
        "wall": Plane((5, 0, 0), (-1, 0, 0)),
        "side": Plane((0, 0, 0), Y),
        "end": Plane((0, 0, 0), X),
        "roof": Plane((0, 0, 5), (0, 0, -1)),
        "rod": Shaft((0, 0, 3), X, 1.0),
    },
    fixed=True,
)
BOXED = Body(
    "box",
    {
        "bottom": Plane((0, 0, 0), (0, 0, -1)),
        "corner": Point((1, 1, 0)),
        "ball": Ball((1, 1, 0), 1.0),
    },
)
ON_TABLE = rel("against", "box.bottom", "world.table")


def test_point_on_line_alone():
    out = solve([WORLD, BOXED], rel("point_on_line", "box.corner", "world.rod"))
    b = out["bodies"]["box@s1"]
    assert (b["dof"], b["motion"]) == (4, "mechanism")
    # nearest point of the rod to the corner (1,1,0) is (1,0,3): a shift (0,-1,3)
    np.testing.assert_allclose(b["pose"], shift(0, -1, 3), atol=EXACT)
    assert unoriented(b["invariants"]["direction"], X)
    np.testing.assert_allclose(b["invariants"]["point"], [1, 0, 3], atol=EXACT)


def test_point_on_line_and_plane_meet_in_a_spherical_joint():
    out = solve(
        [WORLD, BOXED],
        rel("point_on_line", "box.corner", "world.rod"),
        rel("point_on_plane", "box.corner", "world.wall"),
    )
    b = out["bodies"]["box@s1"]
    # the rod y = 0, z = 3 pierces the wall x = 5 at (5, 0, 3)
    assert (b["dof"], b["motion"]) == (3, "spherical")
    np.testing.assert_allclose(b["invariants"]["center"], [5, 0, 3], atol=EXACT)
    np.testing.assert_allclose(b["pose"], shift(4, -1, 3), atol=EXACT)


def test_sphere_on_plane_keeps_its_centre_on_the_offset_plane():
    out = solve([WORLD, BOXED], rel("distance", "box.ball", "world.table", distance=1.0))
    b = out["bodies"]["box@s1"]
    # the ball of radius 1 at (1,1,0) rests on z = 0: its centre on z = 1
    assert (b["dof"], b["motion"]) == (5, "mechanism")
    np.testing.assert_allclose(b["pose"], shift(0, 0, 1), atol=EXACT)
    assert unoriented(b["invariants"]["normal"], Z)
    np.testing.assert_allclose(b["invariants"]["point"], [1, 1, 1], atol=EXACT)


def test_sphere_in_a_corner_turns_about_its_centre():
    touching = [
        rel("distance", "box.ball", f"world.{plane}", distance=1.0)
        for plane in ("table", "side", "end")
    ]
    b = solve([WORLD, BOXED], *touching)["bodies"]["box@s1"]
    # one unit from z = 0, y = 0 and x = 0 (along their normals): the centre (1, 1, 1)
    assert (b["dof"], b["motion"]) == (3, "spherical")
    np.testing.assert_allclose(b["invariants"]["center"], [1, 1, 1], atol=EXACT)
    np.testing.assert_allclose(b["pose"], shift(0, 0, 1), atol=EXACT)


# ------------------------------------------------------------- with a lower pair


def test_box_on_table_with_corner_on_the_line_of_two_walls_turns_about_it():
    out = solve(
        [WORLD, BOXED],
        ON_TABLE,
        rel("point_on_plane", "box.corner", "world.wall"),
        rel("point_on_plane", "box.corner", "world.side"),
    )
    b = out["bodies"]["box@s1"]
    # the corner moves in z = 0; the walls meet in the vertical x = 5, y = 0, which
    # pierces z = 0 at (5, 0, 0): a revolute about the vertical there, 1 dof
    assert (b["dof"], b["motion"]) == (1, "revolute")
    np.testing.assert_allclose(b["invariants"]["point"], [5, 0, 0], atol=EXACT)
    assert unoriented(b["invariants"]["direction"], Z)
    np.testing.assert_allclose(b["pose"], shift(4, -1), atol=EXACT)
    assert b["freedom"] == (
        "box@s1 can turn about the axis through (5, 0, 0) along +Z: 1 dof;"
        " a stop against the turn (an against or point_on_plane off that axis) would remove it"
    )


def test_box_on_table_with_corner_in_three_planes_is_the_same_revolute():
    out = solve(
        [WORLD, BOXED],
        ON_TABLE,
        rel("point_on_plane", "box.corner", "world.wall"),
        rel("point_on_plane", "box.corner", "world.side"),
        rel("point_on_plane", "box.corner", "world.table"),
    )
    b = out["bodies"]["box@s1"]
    # the spherical joint at (5, 0, 0) intersected with the planar pair (cosets)
    assert (b["dof"], b["motion"]) == (1, "revolute")
    np.testing.assert_allclose(b["invariants"]["point"][:2], [5, 0], atol=EXACT)
    assert unoriented(b["invariants"]["direction"], Z)
    pose = np.asarray(b["pose"])
    np.testing.assert_allclose(se3.apply(pose, (1, 1, 0)), [5, 0, 0], atol=1e-9)
    np.testing.assert_allclose(pose[:3, :3] @ [0, 0, -1], [0, 0, -1], atol=1e-9)


def test_box_on_table_with_corner_on_a_parallel_rod_is_a_distance_conflict():
    out = solve([WORLD, BOXED], ON_TABLE, rel("point_on_line", "box.corner", "world.rod"))
    assert out["status"] == "inconsistent"
    (conflict,) = out["conflicts"]
    # the corner moves in z = 0, the rod runs parallel to it at z = 3
    assert (conflict["kind"], conflict["value"]) == ("distance", pytest.approx(3.0, abs=EXACT))


def test_box_on_table_with_corner_in_three_planes_off_the_table_conflicts():
    out = solve(
        [WORLD, BOXED],
        ON_TABLE,
        rel("point_on_plane", "box.corner", "world.wall"),
        rel("point_on_plane", "box.corner", "world.side"),
        rel("point_on_plane", "box.corner", "world.roof"),
    )
    assert out["status"] == "inconsistent"
    # the corner would sit at (5, 0, 5), 5 above the table it stays on
    (conflict,) = out["conflicts"]
    assert conflict["value"] == pytest.approx(5.0, abs=1e-9)


def test_box_on_table_with_corner_on_an_upright_post_turns_about_it():
    post = Body("world", {**WORLD.features, "post": Shaft((5, 0, 0), Z, 0.5)}, fixed=True)
    b = solve([post, BOXED], ON_TABLE, rel("point_on_line", "box.corner", "world.post"))["bodies"][
        "box@s1"
    ]
    # the post x = 5, y = 0 pierces the table's plane z = 0 at (5, 0, 0)
    assert (b["dof"], b["motion"]) == (1, "revolute")
    np.testing.assert_allclose(b["invariants"]["point"], [5, 0, 0], atol=EXACT)
    assert unoriented(b["invariants"]["direction"], Z)
    np.testing.assert_allclose(b["pose"], shift(4, -1), atol=EXACT)


def test_box_on_table_with_its_ball_touching_the_wall_slides_along_it():
    out = solve([WORLD, BOXED], ON_TABLE, rel("distance", "box.ball", "world.wall", distance=1.0))
    b = out["bodies"]["box@s1"]
    # the wall x = 5 faces -x: the centre stays on x = 4, in the plane z = 0 of the box's
    # planar pair: it slides along y through (4, 1, 0) and turns about the vertical
    assert (b["dof"], b["motion"], b["mechanism"]) == (2, "mechanism", "planar-point-on-line")
    np.testing.assert_allclose(b["pose"], shift(3), atol=EXACT)
    np.testing.assert_allclose(b["invariants"]["point"], [4, 1, 0], atol=EXACT)
    assert unoriented(b["invariants"]["direction"], Y)
    assert unoriented(b["invariants"]["normal"], Z)


# A cylinder of radius 1 lying on the table: its axle through (0, 0, 2) along (1, 0, 1)/√2
# is turned by the smallest rotation onto the table's plane (45° about y through (0, 0, 2))
# and lowered by 1 onto z = 1: R = Ry(π/4), t = (0, 0, 1) − R·(0, 0, 2) = (−√2, 0, 1 − √2).
SQRT2 = np.sqrt(2.0)
ROLLER = Body("roller", {"axle": Shaft((0, 0, 2), (1 / SQRT2, 0, 1 / SQRT2), 1.0)})
ON_ITS_SIDE = rel("distance", "roller.axle", "world.table", distance=1.0)


def test_cylinder_on_plane_keeps_four_dof_and_turns_least():
    out = solve([WORLD, ROLLER], ON_ITS_SIDE)
    b = out["bodies"]["roller@s1"]
    assert (b["dof"], b["motion"], b["mechanism"]) == (4, "mechanism", "line-on-plane")
    expected = se3.rot_y(np.pi / 4)
    expected[:3, 3] = [-SQRT2, 0, 1 - SQRT2]
    np.testing.assert_allclose(b["pose"], expected, atol=EXACT)
    np.testing.assert_allclose(b["invariants"]["direction"], X, atol=EXACT)
    np.testing.assert_allclose(b["invariants"]["point"], [0, 0, 1], atol=EXACT)
    assert unoriented(b["invariants"]["normal"], Z)
    # the independent measure: the residue's Jacobian rank
    assert solve_numeric_only(make_task([WORLD, ROLLER], ON_ITS_SIDE))["roller@s1"].dof == 4


def test_cylinder_lying_on_the_plane_as_written_stays_put():
    lying = Body("roller", {"axle": Shaft((0, 0, 1), Y, 1.0)})
    b = solve([WORLD, lying], ON_ITS_SIDE)["bodies"]["roller@s1"]
    np.testing.assert_allclose(b["pose"], np.eye(4), atol=EXACT)
    assert b["dof"] == 4


# A peg of radius 1 in a bore along z through the origin, its tip 2 below its origin;
# a box held by two faces (a prismatic pair along y).
PLANT = Body(
    "world",
    {
        **WORLD.features,
        "bore": Hole((0, 0, 0), (0, 0, -1), 1.0),
        "floor": Plane((0, 0, -5), Z),
        "back": Plane((0, 3, 0), Y),
    },
    fixed=True,
)
PEG = Body("peg", {"shaft": Shaft((0, 0, 0), (0, 0, -1), 1.0), "tip": Point((0, 0, -2))})
IN_BORE = rel("fits", "peg.shaft", "world.bore")
RAILED = Body(
    "box",
    {
        "bottom": Plane((0, 0, 0), (0, 0, -1)),
        "left": Plane((0, 0, 0), (-1, 0, 0)),
        "corner": Point((1, 1, 0)),
    },
)
ON_RAIL = (ON_TABLE, rel("against", "box.left", "world.end"))


def test_peg_in_a_bore_resting_on_the_floor_turns_about_its_axis():
    out = solve([PLANT, PEG], IN_BORE, rel("point_on_plane", "peg.tip", "world.floor"))
    b = out["bodies"]["peg@s1"]
    # the tip (0, 0, -2) slides down the bore's axis onto z = -5: a drop of 3, then only
    # the turn about the axis is left (the cylinder met with the planar group of z)
    assert (b["dof"], b["motion"]) == (1, "revolute")
    np.testing.assert_allclose(b["pose"], shift(0, 0, -3), atol=EXACT)
    np.testing.assert_allclose(b["invariants"]["point"][:2], [0, 0], atol=EXACT)
    assert unoriented(b["invariants"]["direction"], Z)
    assert "residue" not in [step["rule"] for step in out["trace"]]


def test_a_slide_stopped_by_a_point_on_a_plane_is_fixed():
    out = solve([PLANT, RAILED], *ON_RAIL, rel("point_on_plane", "box.corner", "world.back"))
    b = out["bodies"]["box@s1"]
    # the box slides along y only; its corner (1, 1, 0) reaches y = 3 after 2
    assert out["status"] == "solved"
    assert (b["dof"], b["motion"]) == (0, "fixed")
    np.testing.assert_allclose(b["pose"], shift(0, 2), atol=EXACT)


def test_a_slide_parallel_to_the_point_plane_misses_it_by_its_distance():
    out = solve([PLANT, RAILED], *ON_RAIL, rel("point_on_plane", "box.corner", "world.floor"))
    (conflict,) = out["conflicts"]
    # the corner slides along y in z = 0, 5 above the floor z = -5
    assert (conflict["kind"], conflict["value"]) == ("distance", pytest.approx(5.0, abs=EXACT))
    assert "point_on_plane box.corner world.floor @s1" in conflict["relations"]
    assert "against box.bottom world.table @s1" in conflict["relations"]


def test_an_instance_merged_into_another_says_its_own_name():
    task = Task(
        "mm",
        {"box": BOX, "v": V},
        (
            Situation("s1", (IN_RIGHT, IN_BACK, IN_TOP)),
            Situation("s2", ()),  # v stays where it was
        ),
    )
    bodies = task.solve().to_dict()["bodies"]
    assert bodies["v@s2"]["freedom"].startswith("v@s2 can turn about (0.5, 1, 1.5): 3 dof;")
    np.testing.assert_allclose(bodies["v@s2"]["pose"], shift(0.5, 1, 1.5), atol=EXACT)


def test_edge_on_face_is_a_line_in_the_plane():
    """An edge (a line feature) lying on a face: ``distance`` 0 between the line and the
    plane. The edge through (0, 0, 2) along (0, 1, 1)/√2 turns by the smallest rotation
    onto z = const, -45° about x through (0, 0, 2), then drops by 2 onto the table:
    R = Rx(-π/4), so R·(0, 0, 2) = (0, √2, √2) and t = (0, 0, 0) - R·(0, 0, 2) = (0, -√2, -√2)."""
    edge = Body("slab", {"edge": Axis((0, 0, 2), (0, 1 / SQRT2, 1 / SQRT2))})
    on_face = rel("distance", "slab.edge", "world.table", distance=0.0)
    b = solve([WORLD, edge], on_face)["bodies"]["slab@s1"]
    assert (b["dof"], b["motion"], b["mechanism"]) == (4, "mechanism", "line-on-plane")
    expected = se3.rot_x(-np.pi / 4)
    expected[:3, 3] = [0, -SQRT2, -SQRT2]
    np.testing.assert_allclose(b["pose"], expected, atol=EXACT)
    np.testing.assert_allclose(b["invariants"]["direction"], Y, atol=EXACT)
    np.testing.assert_allclose(b["invariants"]["point"], [0, 0, 0], atol=EXACT)
    # the relation written out at the pose: the edge's point on z = 0, its direction flat
    pose = np.asarray(b["pose"])
    assert se3.apply(pose, (0, 0, 2))[2] == pytest.approx(0.0, abs=EXACT)
    assert (pose[:3, :3] @ (0, 1 / SQRT2, 1 / SQRT2))[2] == pytest.approx(0.0, abs=EXACT)
    assert solve_numeric_only(make_task([WORLD, edge], on_face))["slab@s1"].dof == 4
