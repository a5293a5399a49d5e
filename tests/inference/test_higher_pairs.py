"""Higher pairs in closed form: a point held in planes and lines, a line lying on a plane
(a cylinder on a plane, an edge on a face), alone and with a lower pair or a point
(docs/algebra.md §3, §5.3; inference/network.py folds the loci, inference/reduction.py solves
them). Every expected pose and invariant is worked out by hand in the comments, and checked
against the relations' own residuals and the residue solver's Jacobian rank."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import assemblykit
from assemblykit.algebra import se3
from assemblykit.features.primitives import Axis, Ball, Hole, Plane, Point, Shaft
from assemblykit.inference import solve_numeric_only, solve_task
from assemblykit.io.tasks import load_task
from assemblykit.model.body import Body
from assemblykit.model.relations import FeatureRef, Relation, relation_residual
from assemblykit.model.task import Situation, Task

EXACT = 1e-12
X, Y, Z = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)
TASKS = Path(assemblykit.__file__).parent / "examples" / "tasks"


def rel(kind: str, first: str, second: str, **options) -> Relation:
    return Relation(kind, (FeatureRef.parse(first), FeatureRef.parse(second)), options)


def make_task(bodies, *relations: Relation) -> Task:
    return Task("mm", {b.name: b for b in bodies}, (Situation("s1", tuple(relations)),))


def solve(bodies, *relations: Relation) -> dict:
    return solve_task(make_task(bodies, *relations), explain=True).to_dict()


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
        out = solve_task(load_task(TASKS / name)).to_dict()["bodies"]
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


def assert_turns_in_the_bore_dropped_by_three(b: dict, out: dict) -> None:
    """The peg came down the bore's axis by 3 onto its support, in closed form, and only
    the turn about the axis is left."""
    assert (b["dof"], b["motion"]) == (1, "revolute")
    np.testing.assert_allclose(b["pose"], shift(0, 0, -3), atol=EXACT)
    np.testing.assert_allclose(b["invariants"]["point"][:2], [0, 0], atol=EXACT)
    assert unoriented(b["invariants"]["direction"], Z)
    assert "residue" not in [step["rule"] for step in out["trace"]]


def test_peg_in_a_bore_resting_on_the_floor_turns_about_its_axis():
    out = solve([PLANT, PEG], IN_BORE, rel("point_on_plane", "peg.tip", "world.floor"))
    b = out["bodies"]["peg@s1"]
    # the tip (0, 0, -2) slides down the bore's axis onto z = -5: a drop of 3, then only
    # the turn about the axis is left (the cylinder met with the planar group of z)
    assert_turns_in_the_bore_dropped_by_three(b, out)


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
    bodies = solve_task(task).to_dict()["bodies"]
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


# ------------------------------------------------- a line contact with a lower pair
#
# The table z = 0 and the wall x = 5 (normal -x) of WORLD; a bearing (a hole of radius 1
# along x) at the roller's height z = 1 and one at z = 3, and a spindle (an axis) at z = 1.
# The roller: radius 1, its axle the x axis, its end face at x = 2 facing +x, a lever
# tip 2 from the axle at (0, 2, 0) and a mark on its surface at (0, 1, 0).
SHOP = Body(
    "world",
    {
        **WORLD.features,
        "bearing": Hole((0, 0, 1), X, 1.0),
        "high": Hole((0, 0, 3), X, 1.0),
        "spindle": Axis((0, 0, 1), X),
    },
    fixed=True,
)
WHEEL = Body(
    "roller",
    {
        "axle": Shaft((0, 0, 0), X, 1.0),
        "end": Plane((2, 0, 0), X),
        "lever": Point((0, 2, 0)),
        "mark": Point((0, 1, 0)),
        "stub": Point((0, 0.5, 0)),
    },
)
LYING = rel("distance", "roller.axle", "world.table", distance=1.0)
# A slab whose bottom edge runs along x at z = 2 as written, its end face at x = 2.
SLAB = Body(
    "slab",
    {
        "edge": Axis((0, 0, 2), X),
        "tilted": Axis((0, 0, 2), (0.6, 0, 0.8)),
        "end": Plane((2, 0, 0), X),
        "bottom": Plane((0, 0, 2), (0, 0, -1)),
        "base": Plane((0, 0, 2.5), (0, 0, -1)),
    },
)
EDGE_DOWN = rel("distance", "slab.edge", "world.table", distance=0.0)


def residual_at(bodies: list[Body], pose, *relations: Relation) -> float:
    """The largest residual of ``relations`` (moving body first, world second) at ``pose``,
    straight from the relations' definitions (model/relations.py), not the reduction."""
    features = {f"{b.name}.{k}": f for b in bodies for k, f in b.features.items()}
    worst = 0.0
    for r in relations:
        first, second = (features[f"{ref.body}.{ref.feature}"] for ref in r.refs)
        residual = relation_residual(r.kind, first, second, r.options)
        worst = max(worst, float(np.abs(residual(np.asarray(pose))).max()))
    return worst


def about(point, direction, angle: float) -> np.ndarray:
    """The rotation by ``angle`` about the line through ``point`` along ``direction``."""
    return (
        shift(*point)
        @ se3.rotation(np.asarray(direction, float), angle)
        @ shift(*(-np.asarray(point, float)))
    )


def test_roller_on_the_table_with_its_end_against_a_wall_rolls_and_slides():
    relations = (LYING, rel("against", "roller.end", "world.wall"))
    out = solve([SHOP, WHEEL], *relations)
    b = out["bodies"]["roller@s1"]
    # the end face x = 2 goes onto the wall x = 5 (a shift of 3 along x), the axle onto
    # z = 1 (a lift of 1): the axle (3, 0, 1) + s·x can turn about itself and slide along
    # y (the wall's planar pair keeps its direction x; the table keeps its height)
    assert (b["dof"], b["motion"], b["mechanism"]) == (2, "mechanism", "roll-and-slide")
    np.testing.assert_allclose(b["pose"], shift(3, 0, 1), atol=EXACT)
    np.testing.assert_allclose(b["invariants"]["point"], [3, 0, 1], atol=EXACT)
    np.testing.assert_allclose(b["invariants"]["direction"], X, atol=EXACT)
    np.testing.assert_allclose(b["invariants"]["normal"], Z, atol=EXACT)
    assert b["freedom"] == (
        "roller@s1 can turn about its line through (3, 0, 1) along +X and slide that line"
        " sideways, keeping it parallel to the plane normal to +Z: 2 dof; a stop against the"
        " slide (an against or point_on_plane on a face whose normal leaves the plane of +X"
        " and +Z) and a stop off the line (the turn about it) would remove it"
    )
    rules = [step["rule"] for step in out["trace"]]
    assert "higher-pair" in rules and "residue" not in rules
    # the set as claimed: any turn about the line and slide along y keeps both relations;
    # a turn about the vertical or a lift does not (so it is no planar coset)
    pose = np.asarray(b["pose"])
    assert residual_at([SHOP, WHEEL], pose, *relations) < EXACT
    moved = shift(0, -1.3) @ about((3, 0, 1), X, 0.7) @ pose
    assert residual_at([SHOP, WHEEL], moved, *relations) < 1e-12
    assert residual_at([SHOP, WHEEL], about((3, 0, 1), Z, 0.1) @ pose, *relations) > 0.05
    assert residual_at([SHOP, WHEEL], shift(0, 0, 0.1) @ pose, *relations) > 0.05
    # the independent measure of the dof: the residue's Jacobian rank
    assert solve_numeric_only(make_task([SHOP, WHEEL], *relations))["roller@s1"].dof == 2


@pytest.mark.parametrize(("kind", "support"), [("fits", "bearing"), ("coaxial", "spindle")])
def test_roller_on_the_table_in_a_bearing_at_its_height_is_cylindrical(kind, support):
    relations = (LYING, rel(kind, "roller.axle", f"world.{support}"))
    out = solve([SHOP, WHEEL], *relations)
    b = out["bodies"]["roller@s1"]
    # the bearing's axis y = 0, z = 1 is the height of an axle resting on the table: the
    # line contact adds nothing, the roller slides along and turns about that axis
    assert out["status"] == "underconstrained"
    assert (b["dof"], b["motion"]) == (2, "cylindrical")
    assert "mechanism" not in b
    np.testing.assert_allclose(b["pose"], shift(0, 0, 1), atol=EXACT)
    np.testing.assert_allclose(b["invariants"]["point"][1:], [0, 1], atol=EXACT)
    assert unoriented(b["invariants"]["direction"], X)
    assert "residue" not in [step["rule"] for step in out["trace"]]
    pose = np.asarray(b["pose"])
    moved = about((0, 0, 1), X, 2.1) @ shift(4.2) @ pose
    assert residual_at([SHOP, WHEEL], moved, *relations) < 1e-12
    assert solve_numeric_only(make_task([SHOP, WHEEL], *relations))["roller@s1"].dof == 2


def test_roller_on_the_table_in_a_bearing_above_its_height_conflicts_by_the_gap():
    out = solve([SHOP, WHEEL], LYING, rel("fits", "roller.axle", "world.high"))
    assert out["status"] == "inconsistent"
    (conflict,) = out["conflicts"]
    # the bearing holds the axle at z = 3, the table at z = 1: two apart
    assert (conflict["kind"], conflict["value"]) == ("distance", pytest.approx(2.0, abs=EXACT))
    assert set(conflict["relations"]) == {
        "fits roller.axle world.high @s1",
        "distance roller.axle world.table @s1",
    }


def test_box_edge_on_the_table_with_its_end_against_a_wall_rolls_and_slides():
    relations = (EDGE_DOWN, rel("against", "slab.end", "world.wall"))
    b = solve([SHOP, SLAB], *relations)["bodies"]["slab@s1"]
    # the edge at z = 2 drops onto z = 0, the end face x = 2 moves onto x = 5: the box
    # can tip about its edge (3, 0, 0) + s·x and slide along y
    assert (b["dof"], b["motion"], b["mechanism"]) == (2, "mechanism", "roll-and-slide")
    np.testing.assert_allclose(b["pose"], shift(3, 0, -2), atol=EXACT)
    np.testing.assert_allclose(b["invariants"]["point"], [3, 0, 0], atol=EXACT)
    np.testing.assert_allclose(b["invariants"]["direction"], X, atol=EXACT)
    pose = np.asarray(b["pose"])
    moved = shift(0, 2.5) @ about((3, 0, 0), X, -0.4) @ pose
    assert residual_at([SHOP, SLAB], moved, *relations) < 1e-12
    assert solve_numeric_only(make_task([SHOP, SLAB], *relations))["slab@s1"].dof == 2


def test_box_on_the_table_with_an_edge_of_its_bottom_on_it_stays_planar():
    relations = (EDGE_DOWN, rel("against", "slab.bottom", "world.table"))
    out = solve([SHOP, SLAB], *relations)
    b = out["bodies"]["slab@s1"]
    # the edge lies in the bottom face: the planar pair of z, lowered by 2, holds it
    assert (b["dof"], b["motion"]) == (3, "planar")
    np.testing.assert_allclose(b["pose"], shift(0, 0, -2), atol=EXACT)
    assert unoriented(b["invariants"]["normal"], Z)
    assert "residue" not in [step["rule"] for step in out["trace"]]
    assert solve_numeric_only(make_task([SHOP, SLAB], *relations))["slab@s1"].dof == 3


def test_an_edge_above_the_face_on_the_table_conflicts_by_its_height():
    out = solve([SHOP, SLAB], EDGE_DOWN, rel("against", "slab.base", "world.table"))
    (conflict,) = out["conflicts"]
    # the base face is 0.5 above the edge: on the table, the edge stays 0.5 below it
    assert (conflict["kind"], conflict["value"]) == ("distance", pytest.approx(0.5, abs=EXACT))


def test_a_tilted_edge_cannot_lie_on_the_table_the_planar_pair_keeps_level():
    tilted = rel("distance", "slab.tilted", "world.table", distance=0.0)
    out = solve([SHOP, SLAB], tilted, rel("against", "slab.bottom", "world.table"))
    (conflict,) = out["conflicts"]
    # the edge along (0.6, 0, 0.8) rises at asin(0.8) from every plane z = const
    assert conflict["kind"] == "angle"
    assert conflict["value"] == pytest.approx(np.arcsin(0.8), abs=EXACT)


def test_roller_on_the_table_with_a_lever_tip_on_it_is_planar_in_two_rolls():
    relations = (LYING, rel("point_on_plane", "roller.lever", "world.table"))
    out = solve([SHOP, WHEEL], *relations)
    b = out["bodies"]["roller@s1"]
    # the axle lifted onto z = 1 (no turn needed); the tip (0, 2, 1) is 2 from the axle
    # and must come down to z = 0: a roll φ about +x puts it at height 1 + 2 sin φ = 0,
    # φ = -π/6 or -5π/6; the least roll is -π/6, then only slides in the table's plane
    # and turns about its normal are left: the planar coset, two components
    assert (b["dof"], b["motion"], b["solutions"]) == (3, "planar", 2)
    expected = se3.rot_x(-np.pi / 6)
    expected[:3, 3] = [0, 0, 1]
    np.testing.assert_allclose(b["pose"], expected, atol=EXACT)
    np.testing.assert_allclose(b["invariants"]["normal"], Z, atol=EXACT)
    assert "residue" not in [step["rule"] for step in out["trace"]]
    pose = np.asarray(b["pose"])
    assert residual_at([SHOP, WHEEL], pose, *relations) < EXACT
    other = about((0, 0, 1), X, -2 * np.pi / 3) @ pose  # the roll -5π/6
    assert residual_at([SHOP, WHEEL], other, *relations) < 1e-12
    moved = shift(1.5, -2) @ about((0, 0, 0), Z, 1.1) @ pose
    assert residual_at([SHOP, WHEEL], moved, *relations) < 1e-12
    assert solve_numeric_only(make_task([SHOP, WHEEL], *relations))["roller@s1"].dof == 3


def test_a_mark_on_the_roller_surface_touches_the_table_in_one_roll():
    b = solve([SHOP, WHEEL], LYING, rel("point_on_plane", "roller.mark", "world.table"))["bodies"][
        "roller@s1"
    ]
    # the mark (0, 1, 1) is 1 from the axle, the table 1 below it: sin φ = -1, φ = -π/2
    assert (b["dof"], b["motion"], b["solutions"]) == (3, "planar", 1)
    expected = se3.rot_x(-np.pi / 2)
    expected[:3, 3] = [0, 0, 1]
    np.testing.assert_allclose(b["pose"], expected, atol=EXACT)


def test_a_stub_too_short_to_reach_the_table_conflicts_by_what_it_lacks():
    out = solve([SHOP, WHEEL], LYING, rel("point_on_plane", "roller.stub", "world.table"))
    (conflict,) = out["conflicts"]
    # the stub is 0.5 from the axle, which stays 1 above the table: 0.5 short
    assert (conflict["kind"], conflict["value"]) == ("distance", pytest.approx(0.5, abs=EXACT))
    assert len(conflict["relations"]) == 2


def test_peg_tip_on_a_plane_along_the_bore_adds_nothing_or_misses_by_its_distance():
    """The tip lies on the bore's axis, which every pose of the cylindrical pair keeps:
    its orbit is the axis x = y = 0, in the plane y = 0 and 3 away from y = 3."""
    flat = solve([PLANT, PEG], IN_BORE, rel("point_on_plane", "peg.tip", "world.side"))
    b = flat["bodies"]["peg@s1"]
    assert (b["dof"], b["motion"]) == (2, "cylindrical")
    np.testing.assert_allclose(b["pose"], np.eye(4), atol=EXACT)
    assert "residue" not in [step["rule"] for step in flat["trace"]]
    out = solve([PLANT, PEG], IN_BORE, rel("point_on_plane", "peg.tip", "world.back"))
    (conflict,) = out["conflicts"]
    assert (conflict["kind"], conflict["value"]) == ("distance", pytest.approx(3.0, abs=EXACT))


def test_peg_tip_on_a_slanted_floor_turns_about_the_bore():
    """The plane through (0, 0, -5) of normal (1, 0, 1)/√2 crosses the bore's axis at
    (0, 0, -5): the tip (0, 0, -2) slides down 3 to it, then only the turn about the
    axis is left (the cylindrical pair met with the sphere about the tip)."""
    slant = Body("world", {**PLANT.features, "slant": Plane((0, 0, -5), (1, 0, 1))}, fixed=True)
    relations = (IN_BORE, rel("point_on_plane", "peg.tip", "world.slant"))
    out = solve([slant, PEG], *relations)
    b = out["bodies"]["peg@s1"]
    assert_turns_in_the_bore_dropped_by_three(b, out)
    assert solve_numeric_only(make_task([slant, PEG], *relations))["peg@s1"].dof == 1


def test_bundled_line_contacts_task():
    """The crate tips about its edge and slides along the wall; the flap's tip (0, 2, 1)
    comes down by the roll -atan(1/2) about its hinge (1·cos φ + 2·sin φ = 0), the least
    of the two, its hinge staying on the x axis."""
    tip = -np.arctan(0.5)
    flap = se3.rot_x(tip)
    for name in ("line_contacts.rapt", "line_contacts.yaml"):
        out = solve_task(load_task(TASKS / name)).to_dict()["bodies"]
        crate, hinged = out["crate@s1"], out["flap@s1"]
        assert (crate["dof"], crate["mechanism"]) == (2, "roll-and-slide")
        np.testing.assert_allclose(crate["pose"], shift(3, 0, -2), atol=EXACT)
        assert (hinged["dof"], hinged["motion"], hinged["solutions"]) == (3, "planar", 2)
        np.testing.assert_allclose(hinged["pose"], flap, atol=EXACT)
