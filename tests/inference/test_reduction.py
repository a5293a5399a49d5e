"""Network reduction on tasks built from the model (Corner et al. 1983 §III, docs/algebra.md §5.2,
§6)."""

from __future__ import annotations

import math
from collections.abc import Iterable
from importlib.resources import files

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from assemblykit.algebra import Coset, SymmetryGroup, se3
from assemblykit.features.primitives import Ball, Hole, Plane, Point, Prism, Shaft, Socket, Thread
from assemblykit.inference import solve_numeric_only, solve_task
from assemblykit.inference.reduction import model_scale, revolute_loop
from assemblykit.io.tasks import load_task
from assemblykit.model.body import Body
from assemblykit.model.relations import FeatureRef, Relation
from assemblykit.model.task import Action, Situation, Task
from assemblykit.tolerance import Tolerance, using


def body(name: str, fixed: bool = False, **features) -> Body:
    return Body(name, features, fixed)


def rel(kind: str, first: str, second: str, **options) -> Relation:
    return Relation(kind, (FeatureRef.parse(first), FeatureRef.parse(second)), options)


def act(kind: str, name: str, ref: str | None = None, by: float | None = None) -> Action:
    feature = FeatureRef.parse(ref) if ref else None
    if kind == "move":
        return Action("move", name, along=feature, by=by)
    return Action("turn", name, about=feature, by=by)


def situation(name: str, relations: Iterable[Relation] = (), actions: Iterable[Action] = ()):
    return Situation(name, tuple(relations), tuple(actions))


def make_task(bodies: Iterable[Body], *situations: Situation) -> Task:
    return Task("mm", {b.name: b for b in bodies}, tuple(situations))


def solve(bodies: Iterable[Body], *relations: Relation, explain: bool = False):
    """Solve a one-situation task ``s1`` and return its JSON dictionary."""
    return solve_task(make_task(bodies, situation("s1", relations)), explain=explain).to_dict()


def shift(x: float, y: float = 0.0, z: float = 0.0) -> np.ndarray:
    return se3.translation((x, y, z))


def rz(angle: float, about: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    return shift(*about) @ se3.rot_z(angle) @ shift(*(-np.asarray(about)))


def member_of_plane(pose, point, normal, world_point, world_normal) -> bool:
    """Whether ``pose`` puts a body plane (point, outward normal) against a world plane."""
    pose = np.asarray(pose)
    moved_normal = pose[:3, :3] @ np.asarray(normal, float)
    moved_point = pose[:3, :3] @ np.asarray(point, float) + pose[:3, 3]
    return bool(
        np.allclose(moved_normal, -np.asarray(world_normal, float), atol=1e-9)
        and math.isclose(
            float(np.dot(world_normal, moved_point - np.asarray(world_point, float))),
            0.0,
            abs_tol=1e-9,
        )
    )


Z = (0.0, 0.0, 1.0)
TABLE = body("table", fixed=True, top=Plane((0, 0, 0), Z))


def parallel(a, b) -> bool:
    a, b = np.asarray(a, float), np.asarray(b, float)
    return bool(np.linalg.norm(np.cross(a, b)) < 1e-9)


def on_line(point, origin, direction) -> bool:
    offset = np.asarray(point, float) - np.asarray(origin, float)
    return parallel(offset, direction) or np.linalg.norm(offset) < 1e-9


# ---------------------------------------------------------------- W examples, two bodies


def test_w1_single_against_is_planar():
    block = body("block", bottom=Plane((0, 0, 0), (0, 0, -1)))
    out = solve([TABLE, block], rel("against", "block.bottom", "table.top"))
    b = out["bodies"]["block@s1"]
    assert out["status"] == "underconstrained"
    assert (b["dof"], b["motion"], b["solutions"]) == (3, "planar", 1)
    assert parallel(b["invariants"]["normal"], Z)
    assert member_of_plane(b["pose"], (0, 0, 0), (0, 0, -1), (0, 0, 0), Z)
    assert out["bodies"]["table@s1"]["motion"] == "fixed"


def cube_walls(extra: bool = False, corner=(0.0, 0.0, 0.0)):
    c = np.asarray(corner)
    world = {
        "floor": Plane(c, (0, 0, 1)),
        "wall": Plane(c, (1, 0, 0)),
    }
    cube = {"bottom": Plane((0, 0, 0), (0, 0, -1)), "left": Plane((0, 0, 0), (-1, 0, 0))}
    relations = [
        rel("against", "cube.bottom", "room.floor"),
        rel("against", "cube.left", "room.wall"),
    ]
    if extra:
        world["back"] = Plane(c, (0, 1, 0))
        cube["front"] = Plane((0, 0, 0), (0, -1, 0))
        relations.append(rel("against", "cube.front", "room.back"))
    return [body("room", fixed=True, **world), body("cube", **cube)], relations


def test_w2_two_perpendicular_againsts_are_prismatic():
    bodies, relations = cube_walls()
    b = solve(bodies, *relations)["bodies"]["cube@s1"]
    assert (b["dof"], b["motion"]) == (1, "prismatic")
    assert parallel(b["invariants"]["direction"], (0, 1, 0))
    pose = np.asarray(b["pose"])
    assert np.allclose(pose[:3, :3], np.eye(3), atol=1e-9)
    assert np.allclose(pose[[0, 2], 3], 0, atol=1e-9)


def test_w3_three_againsts_fix_the_cube_and_offset_variant():
    bodies, relations = cube_walls(extra=True)
    out = solve(bodies, *relations)
    assert out["status"] == "solved"
    b = out["bodies"]["cube@s1"]
    assert (b["dof"], b["motion"], b["solutions"]) == (0, "fixed", 1)
    assert np.allclose(b["pose"], np.eye(4), atol=1e-9)
    bodies, relations = cube_walls(extra=True, corner=(1, 2, 3))
    b = solve(bodies, *relations)["bodies"]["cube@s1"]
    assert np.allclose(b["pose"], shift(1, 2, 3), atol=1e-9)


def test_w3b_angle_mismatch_is_inconsistent():
    ten = math.radians(10)
    room = body("room", fixed=True, floor=Plane((0, 0, 0), Z), wall=Plane((0, 0, 0), (1, 0, 0)))
    cube = body(
        "cube",
        bottom=Plane((0, 0, 0), (0, 0, -1)),
        left=Plane((0, 0, 0), (-math.cos(ten), 0, math.sin(ten))),
    )
    out = solve(
        [room, cube],
        rel("against", "cube.bottom", "room.floor"),
        rel("against", "cube.left", "room.wall"),
    )
    assert out["status"] == "inconsistent"
    (conflict,) = out["conflicts"]
    assert conflict["kind"] == "angle"
    assert conflict["value"] == pytest.approx(ten, rel=1e-6)
    assert sorted(conflict["relations"]) == [
        "against cube.bottom room.floor @s1",
        "against cube.left room.wall @s1",
    ]


def plate_and_pin(radius: float = 5.0):
    plate = body(
        "plate", fixed=True, top=Plane((0, 0, 0), Z), hole=Hole((0, 0, 0), (0, 0, -1), 5.0)
    )
    pin = body("pin", head=Plane((0, 0, 0), (0, 0, -1)), shaft=Shaft((0, 0, 0), (0, 0, -1), radius))
    return [plate, pin], [
        rel("fits", "pin.shaft", "plate.hole"),
        rel("against", "pin.head", "plate.top"),
    ]


def test_w4_fits_and_shoulder_is_revolute():
    bodies, relations = plate_and_pin()
    b = solve(bodies, *relations)["bodies"]["pin@s1"]
    assert (b["dof"], b["motion"]) == (1, "revolute")
    assert parallel(b["invariants"]["direction"], Z)
    assert on_line(b["invariants"]["point"], (0, 0, 0), Z)
    pose = np.asarray(b["pose"])
    assert np.allclose(pose[:3, 3], 0, atol=1e-9) and np.allclose(pose[:3, 2], Z, atol=1e-9)


def test_w4_radius_mismatch_is_inconsistent():
    bodies, relations = plate_and_pin(radius=4.9)
    out = solve(bodies, *relations)
    assert out["status"] == "inconsistent"
    assert out["conflicts"][0]["kind"] == "radius"
    assert out["conflicts"][0]["value"] == pytest.approx(0.1)
    assert out["conflicts"][0]["relations"] == ["fits pin.shaft plate.hole @s1"]


def two_pin_block(second=(0.0, 10.0, 0.0)):
    base = body("base", fixed=True, a1=Hole((0, 0, 0), Z, 2.0), a2=Hole((10, 0, 0), Z, 2.0))
    block = body("block", s1=Shaft((0, 0, 0), Z, 2.0), s2=Shaft(second, Z, 2.0))
    return [base, block], [rel("fits", "block.s1", "base.a1"), rel("fits", "block.s2", "base.a2")]


def test_w5_two_parallel_pins_slide_along_the_axes():
    bodies, relations = two_pin_block()
    b = solve(bodies, *relations)["bodies"]["block@s1"]
    assert (b["dof"], b["motion"]) == (1, "prismatic")
    assert parallel(b["invariants"]["direction"], Z)
    pose = np.asarray(b["pose"])
    assert np.allclose(pose[:3, :3], se3.rot_z(-math.pi / 2)[:3, :3], atol=1e-9)
    assert np.allclose(pose[:2, 3], 0, atol=1e-9)


def test_w6_unequal_spacing_is_a_distance_mismatch_of_two():
    bodies, relations = two_pin_block(second=(12.0, 0.0, 0.0))
    out = solve(bodies, *relations)
    assert out["status"] == "inconsistent"
    assert out["conflicts"][0]["kind"] == "distance"
    assert out["conflicts"][0]["value"] == pytest.approx(2.0)


def test_w7_shaft_parallel_to_face_is_prismatic_and_height_mismatch():
    base = body("base", fixed=True, floor=Plane((0, 0, 0), Z), bore=Hole((0, 0, 5), (1, 0, 0), 1.0))
    for height, expected in ((5.0, "underconstrained"), (4.0, "inconsistent")):
        slider = body(
            "slider",
            bottom=Plane((0, 0, 0), (0, 0, -1)),
            shaft=Shaft((0, 0, height), (1, 0, 0), 1.0),
        )
        out = solve(
            [base, slider],
            rel("against", "slider.bottom", "base.floor"),
            rel("fits", "slider.shaft", "base.bore"),
        )
        assert out["status"] == expected
    b = solve(
        [
            base,
            body(
                "slider",
                bottom=Plane((0, 0, 0), (0, 0, -1)),
                shaft=Shaft((0, 0, 5), (1, 0, 0), 1.0),
            ),
        ],
        rel("against", "slider.bottom", "base.floor"),
        rel("fits", "slider.shaft", "base.bore"),
    )["bodies"]["slider@s1"]
    assert (b["dof"], b["motion"]) == (1, "prismatic")
    assert parallel(b["invariants"]["direction"], (1, 0, 0))


def test_w9_two_balls_and_w10_three_balls():
    sockets = {
        "n1": Socket((0, 0, 0), 1.0),
        "n2": Socket((0, 0, 10), 1.0),
        "n3": Socket((10, 0, 0), 1.0),
    }
    frame = body("frame", fixed=True, **sockets)
    rod = body("rod", m1=Ball((0, 0, 0), 1.0), m2=Ball((0, 10, 0), 1.0), m3=Ball((10, 0, 0), 1.0))
    two = solve([frame, rod], rel("fits", "rod.m1", "frame.n1"), rel("fits", "rod.m2", "frame.n2"))
    b = two["bodies"]["rod@s1"]
    assert (b["dof"], b["motion"]) == (1, "revolute")
    assert parallel(b["invariants"]["direction"], Z)
    assert np.allclose(np.asarray(b["pose"]) @ [0, 10, 0, 1], [0, 0, 10, 1], atol=1e-9)
    straight = body(
        "rod", m1=Ball((0, 0, 0), 1.0), m2=Ball((0, 0, 10), 1.0), m3=Ball((10, 0, 0), 1.0)
    )
    three = solve(
        [frame, straight],
        rel("fits", "rod.m1", "frame.n1"),
        rel("fits", "rod.m2", "frame.n2"),
        rel("fits", "rod.m3", "frame.n3"),
    )
    assert three["status"] == "solved"
    assert np.allclose(three["bodies"]["rod@s1"]["pose"], np.eye(4), atol=1e-9)


def test_w11_ball_and_face_is_revolute_about_the_normal_through_the_centre():
    base = body("base", fixed=True, socket=Socket((0, 0, 1), 1.0), floor=Plane((0, 0, 0), Z))
    part = body("part", ball=Ball((0, 0, 1), 1.0), bottom=Plane((0, 0, 0), (0, 0, -1)))
    b = solve(
        [base, part],
        rel("fits", "part.ball", "base.socket"),
        rel("against", "part.bottom", "base.floor"),
    )["bodies"]["part@s1"]
    assert (b["dof"], b["motion"]) == (1, "revolute")
    assert on_line(b["invariants"]["point"], (0, 0, 1), Z)


def test_w14_square_peg_has_four_positions():
    base = body(
        "base",
        fixed=True,
        top=Plane((0, 0, 0), Z),
        hole=Prism((0, 0, 0), (0, 0, -1), 4, 1.0, male=False),
    )
    peg = body(
        "peg",
        collar=Plane((0, 0, 0), (0, 0, -1)),
        body=Prism((0, 0, 0), (0, 0, -1), 4, 1.0, male=True),
    )
    out = solve(
        [base, peg], rel("fits", "peg.body", "base.hole"), rel("against", "peg.collar", "base.top")
    )
    b = out["bodies"]["peg@s1"]
    assert out["status"] == "ambiguous"
    assert (b["dof"], b["solutions"], len(b["alternatives"])) == (0, 4, 3)
    angles = sorted(
        round(math.atan2(p[1][0], p[0][0]) % (2 * math.pi), 9)
        for p in [b["pose"], *b["alternatives"]]
    )
    assert angles == pytest.approx([0.0, math.pi / 2, math.pi, 3 * math.pi / 2])


def threaded_and_keyed(name: str, male: bool, fixed: bool = False, **extra) -> Body:
    """W16's nut (female) or bolt (male): a thread of radius 3 and lead 1.5 about z and a
    square key at (5, 0, 0), plus the ``extra`` features."""
    return body(
        name,
        fixed,
        thread=Thread((0, 0, 0), Z, 3.0, 1.5, male=male),
        key=Prism((5, 0, 0), Z, 4, 0.5, male=male),
        **extra,
    )


def test_w16_thread_and_key_is_a_lattice_not_merged():
    nut = threaded_and_keyed("nut", male=False, fixed=True)
    bolt = threaded_and_keyed("bolt", male=True)
    out = solve(
        [nut, bolt], rel("fits", "bolt.thread", "nut.thread"), rel("fits", "bolt.key", "nut.key")
    )
    b = out["bodies"]["bolt@s1"]
    assert b["solutions"] == "infinite"
    assert b["dof"] == 0
    assert out["status"] == "underconstrained"


def test_w20_slot_is_planar_and_thin_slab_inconsistent():
    slot = body(
        "slot", fixed=True, floor=Plane((0, 0, 0), Z), ceiling=Plane((0, 0, 10), (0, 0, -1))
    )
    for top, status in ((10.0, "underconstrained"), (9.9, "inconsistent")):
        slab = body("slab", bottom=Plane((0, 0, 0), (0, 0, -1)), top=Plane((0, 0, top), Z))
        out = solve(
            [slot, slab],
            rel("against", "slab.bottom", "slot.floor"),
            rel("against", "slab.top", "slot.ceiling"),
        )
        assert out["status"] == status
        if status == "underconstrained":
            assert out["bodies"]["slab@s1"]["motion"] == "planar"
        else:
            assert out["conflicts"][0]["value"] == pytest.approx(0.1)


# ---------------------------------------------------------------- situations and actions


def stacked_task(by: float | None = 5.0):
    block = body(
        "block",
        bottom=Plane((0, 0, 0), (0, 0, -1)),
        side=Plane((0, 0, 0), (-1, 0, 0)),
        front=Plane((0, 0, 0), (0, -1, 0)),
        top=Plane((0, 0, 2), Z),
        bore=Hole((1, 1, 2), (0, 0, -1), 0.5),
    )
    room = body(
        "room",
        fixed=True,
        floor=Plane((0, 0, 0), Z),
        wall=Plane((0, 0, 0), (1, 0, 0)),
        back=Plane((0, 0, 0), (0, 1, 0)),
    )
    pin = body("pin", shaft=Shaft((0, 0, 0), (0, 0, -1), 0.5), head=Plane((0, 0, 0), (0, 0, -1)))
    s1 = situation(
        "s1",
        [
            rel("against", "block.bottom", "room.floor"),
            rel("against", "block.side", "room.wall"),
            rel("against", "block.front", "room.back"),
            rel("fits", "pin.shaft", "block.bore"),
            rel("against", "pin.head", "block.top"),
        ],
    )
    s2 = situation("s2", actions=[act("move", "pin", "pin.shaft", by)])
    s3 = situation("s3", actions=[act("turn", "pin", "pin.shaft", math.pi / 2)])
    return make_task([room, block, pin], s1, s2, s3)


def test_stack_pinned_through_three_situations():
    out = solve_task(stacked_task()).to_dict()
    bodies = out["bodies"]
    for s in ("s1", "s2", "s3"):
        assert np.allclose(bodies[f"block@{s}"]["pose"], np.eye(4), atol=1e-9)
        assert bodies[f"block@{s}"]["motion"] == "fixed"
    # pin in s1: revolute about the bore axis through (1, 1), head on the block top z = 2
    pin1 = bodies["pin@s1"]
    assert (pin1["dof"], pin1["motion"]) == (1, "revolute")
    assert on_line(pin1["invariants"]["point"], (1, 1, 0), Z)
    # s2: moved 5 along its own shaft axis (pointing down in the world): z drops by 5
    p1, p2 = np.asarray(pin1["pose"]), np.asarray(bodies["pin@s2"]["pose"])
    assert np.allclose(p2[:3, 3] - p1[:3, 3], [0, 0, -5], atol=1e-9)
    assert np.allclose(p2[:3, :3], p1[:3, :3], atol=1e-9)
    assert bodies["pin@s2"]["motion"] == "revolute"  # still free to spin, now 5 lower
    # s3: turned a quarter about its axis: the axis line is unchanged
    p3 = np.asarray(bodies["pin@s3"]["pose"])
    assert np.allclose(p3[:3, 3], p2[:3, 3], atol=1e-9)


def test_move_along_without_amount_is_prismatic_and_free_move_is_free():
    out = solve_task(stacked_task(by=None)).to_dict()
    pin2 = out["bodies"]["pin@s2"]
    assert (pin2["dof"], pin2["motion"]) == (2, "cylindrical")
    free = stacked_task()
    s2 = situation("s2", actions=[act("move", "pin")])
    out = solve_task(make_task(free.bodies.values(), free.situations[0], s2)).to_dict()
    assert (out["bodies"]["pin@s2"]["dof"], out["bodies"]["pin@s2"]["motion"]) == (6, "free")
    assert np.allclose(out["bodies"]["block@s2"]["pose"], np.eye(4), atol=1e-9)


def test_explain_lists_the_rules_fired():
    out = solve_task(stacked_task(), explain=True).to_dict()
    rules = [step["rule"] for step in out["trace"]]
    assert "intersect" in rules and "merge" in rules
    first = next(s for s in out["trace"] if s["rule"] == "intersect")
    assert first["dof_before"] > first["dof_after"]


# ---------------------------------------------------------------- cycles and chaining


ROOM = body(
    "room",
    fixed=True,
    floor=Plane((0, 0, 0), Z),
    wall=Plane((0, 0, 0), (0, 1, 0)),
    far=Plane((0, 10, 0), (0, -1, 0)),
    ceiling=Plane((0, 0, 5), (0, 0, -1)),
)
CARRIAGE = body(
    "cart",
    bottom=Plane((0, 0, 0), (0, 0, -1)),
    back=Plane((0, 0, 0), (0, -1, 0)),
    top=Plane((0, 0, 1), Z),
    guide=Plane((0, 0, 1), (1, 0, 0)),
)
CART_ON_RAIL = [
    rel("against", "cart.bottom", "room.floor"),
    rel("against", "cart.back", "room.wall"),
]


def test_triangle_solved_by_chaining():
    """cart slides along x (T(x)); slider slides along y on the cart (T(y)); the slider's
    front touches the far wall y = 10 from y = 3: chaining T(x)·T(y) = T2 with the wall's
    G(y) gives T(x) at y = 7, and then the slider is fixed on the cart."""
    slider = body(
        "slider",
        bottom=Plane((0, 0, 1), (0, 0, -1)),
        side=Plane((0, 0, 1), (-1, 0, 0)),
        front=Plane((0, 3, 1), (0, 1, 0)),
    )
    out = solve(
        [ROOM, CARRIAGE, slider],
        *CART_ON_RAIL,
        rel("against", "slider.bottom", "cart.top"),
        rel("against", "slider.side", "cart.guide"),
        rel("against", "slider.front", "room.far"),
        explain=True,
    )
    cart, sl = out["bodies"]["cart@s1"], out["bodies"]["slider@s1"]
    assert (cart["dof"], cart["motion"]) == (1, "prismatic")
    assert (sl["dof"], sl["motion"]) == (1, "prismatic")
    assert parallel(sl["invariants"]["direction"], (1, 0, 0))
    offset = np.linalg.inv(np.asarray(cart["pose"])) @ np.asarray(sl["pose"])
    assert np.allclose(offset, shift(0, 7, 0), atol=1e-9)
    assert any(step["rule"] == "chain" for step in out["trace"])


def test_four_body_cycle_solved_by_chaining():
    """cart T(x) on the rail, post T(y) on the cart, block T(z) on the post, block top
    against the ceiling z = 5 from z = 3: the block is lifted by 2 and fixed on the post;
    post and block translate in the floor plane."""
    post = body(
        "post",
        bottom=Plane((0, 0, 1), (0, 0, -1)),
        side=Plane((0, 0, 1), (-1, 0, 0)),
        wx=Plane((0, 0, 2), (1, 0, 0)),
        wy=Plane((0, 0, 2), (0, 1, 0)),
    )
    block = body(
        "block",
        fx=Plane((0, 0, 2), (-1, 0, 0)),
        fy=Plane((0, 0, 2), (0, -1, 0)),
        top=Plane((0, 0, 3), Z),
    )
    out = solve(
        [ROOM, CARRIAGE, post, block],
        *CART_ON_RAIL,
        rel("against", "post.bottom", "cart.top"),
        rel("against", "post.side", "cart.guide"),
        rel("against", "block.fx", "post.wx"),
        rel("against", "block.fy", "post.wy"),
        rel("against", "block.top", "room.ceiling"),
        explain=True,
    )
    bodies = out["bodies"]
    assert (bodies["cart@s1"]["dof"], bodies["cart@s1"]["motion"]) == (1, "prismatic")
    assert (bodies["post@s1"]["dof"], bodies["post@s1"]["motion"]) == (2, "translation2")
    assert (bodies["block@s1"]["dof"], bodies["block@s1"]["motion"]) == (2, "translation2")
    offset = np.linalg.inv(np.asarray(bodies["post@s1"]["pose"])) @ bodies["block@s1"]["pose"]
    assert np.allclose(offset, shift(0, 0, 2), atol=1e-9)
    assert sum(step["rule"] == "chain" for step in out["trace"]) >= 2


def four_bar(stopped: bool):
    """Ground pivots A = (0,-2), D = (6,0); crank A->B = (0,0), coupler B->C = (3,4),
    rocker D->C; every link 1 thick, revolute joints (pin + face); body frames are the
    world frame in this reference configuration."""
    r = 0.5
    ground = body(
        "ground",
        fixed=True,
        top=Plane((0, 0, 0), Z),
        ha=Hole((0, -2, 0), Z, r),
        hd=Hole((6, 0, 0), Z, r),
        stop=Plane((1, 0, 0), (-1, 0, 0)),
    )
    crank = body(
        "crank",
        bottom=Plane((0, -2, 0), (0, 0, -1)),
        pa=Shaft((0, -2, 0), Z, r),
        top=Plane((0, 0, 1), Z),
        hb=Hole((0, 0, 0), Z, r),
        side=Plane((1, 0, 0), (1, 0, 0)),
    )
    coupler = body(
        "coupler",
        bottom=Plane((0, 0, 1), (0, 0, -1)),
        pb=Shaft((0, 0, 0), Z, r),
        pc=Shaft((3, 4, 0), Z, r),
    )
    rocker = body(
        "rocker",
        bottom=Plane((6, 0, 0), (0, 0, -1)),
        pd=Shaft((6, 0, 0), Z, r),
        top=Plane((6, 0, 1), Z),
        hc=Hole((3, 4, 0), Z, r),
    )
    relations = [
        rel("fits", "crank.pa", "ground.ha"),
        rel("against", "crank.bottom", "ground.top"),
        rel("fits", "coupler.pb", "crank.hb"),
        rel("against", "coupler.bottom", "crank.top"),
        rel("fits", "rocker.pd", "ground.hd"),
        rel("against", "rocker.bottom", "ground.top"),
        rel("fits", "coupler.pc", "rocker.hc"),
        rel("against", "coupler.bottom", "rocker.top"),
    ]
    if stopped:
        relations.append(rel("against", "crank.side", "ground.stop"))
    return [ground, crank, coupler, rocker], relations


def test_free_four_bar_has_one_dof_each():
    bodies, relations = four_bar(stopped=False)
    out = solve(bodies, *relations)
    bodies = out["bodies"]
    assert out["status"] == "underconstrained"
    assert {k: b["dof"] for k, b in bodies.items() if k != "ground@s1"} == {
        "crank@s1": 1,
        "coupler@s1": 1,
        "rocker@s1": 1,
    }
    assert bodies["crank@s1"]["motion"] == "revolute"
    assert bodies["rocker@s1"]["motion"] == "revolute"
    assert bodies["coupler@s1"]["motion"] == "mechanism"
    assert on_line(bodies["rocker@s1"]["invariants"]["point"], (6, 0, 0), Z)


def test_four_bar_with_crank_stopped_has_two_assembly_modes():
    """B = (0,0) fixed; C on the circles |C-B| = 5 and |C-D| = 5: C = (3,4) (the reference
    configuration) or (3,-4) (the coupler turned by -2·atan2(4,3) about B, the rocker by
    2·atan2(4,3) about D)."""
    bodies, relations = four_bar(stopped=True)
    out = solve(bodies, *relations, explain=True)
    assert out["status"] == "ambiguous"
    assert any(step["rule"] == "loop" for step in out["trace"])
    crank = out["bodies"]["crank@s1"]
    assert np.allclose(crank["pose"], np.eye(4), atol=1e-9)
    expected = {
        "coupler@s1": [np.eye(4), rz(-2 * math.atan2(4, 3))],
        "rocker@s1": [np.eye(4), rz(2 * math.atan2(4, 3), (6, 0, 0))],
    }
    for key, poses in expected.items():
        b = out["bodies"][key]
        assert (b["dof"], b["solutions"], len(b["alternatives"])) == (0, 2, 1)
        found = [np.asarray(b["pose"]), np.asarray(b["alternatives"][0])]
        for pose in poses:
            assert any(np.allclose(pose, f, atol=1e-9) for f in found)
    coupler_modes = [
        out["bodies"]["coupler@s1"]["pose"],
        out["bodies"]["coupler@s1"]["alternatives"][0],
    ]
    tips = sorted(tuple(np.round(np.asarray(p) @ [3, 4, 0, 1], 9)[:2]) for p in coupler_modes)
    assert tips == [(3.0, -4.0), (3.0, 4.0)]


def test_revolute_loop_that_cannot_close_is_inconsistent():
    bodies, relations = four_bar(stopped=True)
    short = body(
        "rocker",
        bottom=Plane((6, 0, 0), (0, 0, -1)),
        pd=Shaft((6, 0, 0), Z, 0.5),
        top=Plane((6, 0, 1), Z),
        hc=Hole((6, 0.5, 0), Z, 0.5),
    )
    out = solve([*bodies[:3], short], *relations)
    assert out["status"] == "inconsistent"
    assert out["conflicts"][0]["kind"] == "loop"
    # C sweeps the circle of radius 5 about B = (0, 0) and the circle of radius 0.5 about
    # D = (6, 0): they miss by 6 - 5 - 0.5
    assert out["conflicts"][0]["value"] == pytest.approx(0.5, abs=1e-9)
    assert "fits coupler.pc rocker.hc @s1" in out["conflicts"][0]["relations"]


# ---------------------------------------------------------------- coupled relations


def test_gear_pair_on_a_carrier():
    """Gears about (0,0) and (3,0) on a fixed carrier, ratio -2; gear 1 held at 0.3 rad by
    a stop face: gear 2 turns by -0.6 about its axis."""
    stop_dir = se3.rot_z(0.3)[:3, :3] @ np.array([0.0, 1.0, 0.0])
    carrier = body(
        "carrier",
        fixed=True,
        top=Plane((0, 0, 0), Z),
        h1=Hole((0, 0, 0), Z, 1.0),
        h2=Hole((3, 0, 0), Z, 1.0),
        stop=Plane(stop_dir, -stop_dir),
    )
    g1 = body(
        "g1",
        bottom=Plane((0, 0, 0), (0, 0, -1)),
        axle=Shaft((0, 0, 0), Z, 1.0),
        side=Plane((0, 1, 0), (0, 1, 0)),
    )
    g2 = body("g2", bottom=Plane((3, 0, 0), (0, 0, -1)), axle=Shaft((3, 0, 0), Z, 1.0))
    joints = [
        rel("fits", "g1.axle", "carrier.h1"),
        rel("against", "g1.bottom", "carrier.top"),
        rel("fits", "g2.axle", "carrier.h2"),
        rel("against", "g2.bottom", "carrier.top"),
        rel("gear", "g1.axle", "g2.axle", ratio=-2.0),
    ]
    free = solve([carrier, g1, g2], *joints)
    assert free["bodies"]["g1@s1"]["dof"] == 1 and free["bodies"]["g2@s1"]["dof"] == 1
    assert free["bodies"]["g2@s1"]["motion"] == "revolute"
    held = solve([carrier, g1, g2], *joints, rel("against", "g1.side", "carrier.stop"))
    assert held["status"] == "solved"
    assert np.allclose(held["bodies"]["g1@s1"]["pose"], rz(0.3), atol=1e-9)
    assert np.allclose(held["bodies"]["g2@s1"]["pose"], rz(-0.6, (3, 0, 0)), atol=1e-9)


def gripper(closing: float | None):
    palm = body(
        "palm",
        fixed=True,
        rail=Plane((0, 0, 0), Z),
        back=Plane((0, 0, 0), (0, 1, 0)),
        stop=Plane((-2 + (closing or 0), 0, 0), (1, 0, 0)),
    )
    jaw_a = body(
        "ja",
        bottom=Plane((-2, 0, 0), (0, 0, -1)),
        back=Plane((-2, 0, 0), (0, -1, 0)),
        face=Plane((-2, 0, 0), (1, 0, 0)),
        outer=Plane((-2, 0, 0), (-1, 0, 0)),
    )
    jaw_b = body(
        "jb",
        bottom=Plane((2, 0, 0), (0, 0, -1)),
        back=Plane((2, 0, 0), (0, -1, 0)),
        face=Plane((2, 0, 0), (-1, 0, 0)),
    )
    relations = [
        rel("against", "ja.bottom", "palm.rail"),
        rel("against", "ja.back", "palm.back"),
        rel("against", "jb.bottom", "palm.rail"),
        rel("against", "jb.back", "palm.back"),
        rel("mirror", "ja.face", "jb.face"),
    ]
    if closing is not None:
        relations.append(rel("against", "ja.outer", "palm.stop"))
    return [palm, jaw_a, jaw_b], relations


def _flat(parts):
    bodies, relations = parts
    return (bodies, *relations)


def test_mirror_gripper():
    free = solve(*_flat(gripper(None)))
    assert free["bodies"]["ja@s1"]["dof"] == 1 and free["bodies"]["jb@s1"]["dof"] == 1
    assert free["bodies"]["jb@s1"]["motion"] == "prismatic"
    held = solve(*_flat(gripper(0.5)))
    assert held["status"] == "solved"
    assert np.allclose(held["bodies"]["ja@s1"]["pose"], shift(0.5), atol=1e-9)
    assert np.allclose(held["bodies"]["jb@s1"]["pose"], shift(-0.5), atol=1e-9)


# ---------------------------------------------------------------- non-coset relations

BOX = body(
    "box",
    bottom=Plane((0, 0, 0), (0, 0, -1)),
    corner=Point((1, 1, 0)),
    up=Plane((0, 0, 1), Z),
    ball=Ball((1, 1, 0), 1.0),
)
WORLD_BODY = body(
    "world",
    fixed=True,
    table=Plane((0, 0, 0), Z),
    wall=Plane((5, 0, 0), (-1, 0, 0)),
    roof=Plane((0, 0, 5), (0, 0, -1)),
    mark=Point((5, 5, 5)),
    rod=Shaft((0, 0, 3), (1, 0, 0), 1.0),
    tilted=Plane((0, 0, 0), (0, 1, 0)),
)


@pytest.mark.parametrize(
    ("relation", "dof"),
    [
        (rel("point_on_plane", "box.corner", "world.wall"), 5),
        (rel("point_on_line", "box.corner", "world.rod"), 4),
        (rel("perpendicular", "box.up", "world.tilted"), 5),
        (rel("angle", "box.up", "world.tilted", angle=1.0), 5),
        (rel("distance", "box.corner", "world.mark", distance=2.0), 5),
    ],
)
def test_each_non_coset_relation_alone(relation, dof):
    out = solve([WORLD_BODY, BOX], relation)
    b = out["bodies"]["box@s1"]
    assert (b["dof"], b["motion"]) == (dof, "mechanism")


def test_box_against_table_with_corner_on_wall_has_two_dof():
    out = solve(
        [WORLD_BODY, BOX],
        rel("against", "box.bottom", "world.table"),
        rel("point_on_plane", "box.corner", "world.wall"),
        explain=True,
    )
    b = out["bodies"]["box@s1"]
    assert (b["dof"], b["motion"]) == (2, "mechanism")
    pose = np.asarray(b["pose"])
    assert pose[:3, :3] @ [1, 1, 0] @ [1, 0, 0] + pose[0, 3] == pytest.approx(5.0)
    assert member_of_plane(pose, (0, 0, 0), (0, 0, -1), (0, 0, 0), Z)
    # closed form: the nearest pose moves the corner (1,1,0) straight onto the wall x = 5;
    # the box slides along y and turns about the vertical through the corner
    np.testing.assert_allclose(pose, shift(4.0), atol=1e-9)
    inv = b["invariants"]
    assert parallel(inv["normal"], Z) and parallel(inv["direction"], (0, 1, 0))
    np.testing.assert_allclose(inv["point"], [5, 1, 0], atol=1e-9)
    assert "higher-pair" in [step["rule"] for step in out["trace"]]
    assert "residue" not in [step["rule"] for step in out["trace"]]


def test_non_coset_relations_that_cannot_hold_report_no_solution_found():
    out = solve(
        [WORLD_BODY, BOX],
        rel("against", "box.bottom", "world.table"),
        rel("point_on_plane", "box.corner", "world.roof"),
    )
    assert out["status"] == "inconsistent"
    conflict = out["conflicts"][0]
    # the corner moves in the table's plane z = 0, parallel to the roof 5 above it
    assert (conflict["kind"], conflict["value"]) == ("distance", pytest.approx(5.0, abs=1e-9))
    assert "point_on_plane box.corner world.roof @s1" in conflict["relations"]


# ---------------------------------------------------------------- laws and other paths


@settings(max_examples=15, deadline=None)
@given(
    angles=st.tuples(*[st.floats(-math.pi, math.pi)] * 3),
    offset=st.tuples(*[st.floats(-5, 5)] * 3),
)
def test_equivariance_of_the_answer(angles, offset):
    """Re-expressing the moving body's features by g⁻¹ turns its pose X into X·g, and
    leaves its motion group unchanged (docs/algebra.md §6, equivariance recipe). Exactly,
    at a tight tolerance: at the default (1e-6) a turn of g within it may be taken for
    none, and the answer is equivariant only to that tolerance."""
    g = shift(*offset) @ se3.rot_z(angles[0]) @ se3.rot_x(angles[1]) @ se3.rot_z(angles[2])
    bodies, relations = plate_and_pin()
    plate, pin = bodies
    moved = Body("pin", {k: f.transformed(se3.inverse(g)) for k, f in pin.features.items()})
    with using(Tolerance.relative(1e-9)):
        base = solve(bodies, *relations)["bodies"]["pin@s1"]
        out = solve([plate, moved], *relations)["bodies"]["pin@s1"]
    assert (out["dof"], out["motion"]) == (1, "revolute")
    assert parallel(out["invariants"]["direction"], Z)
    pose = np.asarray(out["pose"])
    # the answer set is R(z)·X: the new pose is some member of R(z)·X·g
    expected = np.asarray(base["pose"]) @ g
    relative = pose @ np.linalg.inv(expected)
    assert np.allclose(relative[:3, 2], Z, atol=1e-9)
    assert np.allclose(relative[:3, 3], 0, atol=1e-9)


def test_lattice_with_a_further_relation_goes_to_the_residue():
    """Thread + key between nut and bolt is a lattice; a collar against the nut face picks
    the bolt's height: left to the residue solver, which finds the pose at height 0."""
    nut = threaded_and_keyed("nut", male=False, fixed=True, face=Plane((0, 0, 0), Z))
    bolt = threaded_and_keyed("bolt", male=True, collar=Plane((0, 0, 0), (0, 0, -1)))
    out = solve(
        [nut, bolt],
        rel("fits", "bolt.thread", "nut.thread"),
        rel("fits", "bolt.key", "nut.key"),
        rel("against", "bolt.collar", "nut.face"),
        explain=True,
    )
    assert any(step["rule"] == "lattice" for step in out["trace"])
    b = out["bodies"]["bolt@s1"]
    assert b["dof"] == 0
    assert np.allclose(b["pose"], np.eye(4), atol=1e-6)


def test_numeric_only_path_agrees_with_reduction():
    bodies, relations = cube_walls(extra=True, corner=(1, 2, 3))
    task = make_task(bodies, situation("s1", relations))
    numeric = solve_numeric_only(task).to_dict()["bodies"]["cube@s1"]
    assert (numeric["dof"], numeric["solutions"]) == (0, 1)
    assert np.allclose(numeric["pose"], shift(1, 2, 3), atol=1e-6)


# ---------------------------------------------------------------- repeated geometry


def _cube(name: str, fixed: bool = False) -> Body:
    """A unit cube with its corner at the body origin, its six faces as planes."""
    return body(
        name,
        fixed=fixed,
        bottom=Plane((0, 0, 0), (0, 0, -1)),
        top=Plane((0, 0, 1), Z),
        left=Plane((0, 0, 0), (-1, 0, 0)),
        right=Plane((1, 0, 0), (1, 0, 0)),
        front=Plane((0, 0, 0), (0, -1, 0)),
        back=Plane((0, 1, 0), (0, 1, 0)),
    )


def _stack(count: int) -> tuple[list[Body], list[Relation]]:
    """``count`` equal cubes ``c1``... on a fixed ``base``, each seated on the one below by
    against + 2 coplanar (bottom on top, flush left and front): cube k sits at height k."""
    names = [f"c{k}" for k in range(1, count + 1)]
    relations = []
    for child, parent in zip(names, ["base", *names], strict=False):
        relations += [
            rel("against", f"{child}.bottom", f"{parent}.top"),
            rel("coplanar", f"{child}.left", f"{parent}.left"),
            rel("coplanar", f"{child}.front", f"{parent}.front"),
        ]
    return [_cube("base", fixed=True), *map(_cube, names)], relations


def test_a_stack_of_equal_cubes_reuses_one_intersection_and_traces_every_step():
    """Three equal cubes on a base, each seated by against + 2 coplanar: cube k sits at
    height k; every seat is traced as planar ∩ planar (3 -> 1) then ∩ planar (1 -> 0)."""
    bodies, relations = _stack(3)
    out = solve(bodies, *relations, explain=True)
    assert out["status"] == "solved"
    for k in range(1, 4):
        assert np.allclose(out["bodies"][f"c{k}@s1"]["pose"], shift(0, 0, k), atol=1e-12)
    steps = [(s["dof_before"], s["dof_after"]) for s in out["trace"] if s["rule"] == "intersect"]
    assert steps == [(3, 1), (1, 0)] * 3


@pytest.mark.parametrize("count", [40, pytest.param(100, marks=pytest.mark.slow)])
def test_numeric_only_solves_a_long_stack_of_cubes(count):
    """The whole stack handed to the residue solver, one start from the identity: solved,
    the top cube at height ``count`` (hand-computed: each seat lifts a cube by the unit
    edge below it and leaves it unturned). A stack is a long, badly conditioned chain (the
    smallest singular value of its Jacobian falls like 1/N²: 0.07 at 10 cubes, 0.0009 at
    100), so the residual is far above the tolerance while the gradient is already tiny."""
    bodies, relations = _stack(count)
    solution = solve_numeric_only(make_task(bodies, situation("s1", relations)), starts=1)
    assert solution.status == "solved"
    top = solution[f"c{count}@s1"]
    assert (top.dof, top.solutions) == (0, 1)
    assert np.allclose(top.pose, shift(0, 0, count), atol=1e-6)


def test_model_scale_counts_radii_and_sizes():
    """A pin of radius 5 and a square of circumradius 3 at the origin: the box is
    [-5, 5]^3 (the pin reaches furthest), diagonal 10·√3, not 0."""
    pin = Body("pin", {"shaft": Shaft(point=(0, 0, 0), axis=(0, 0, 1), radius=5.0)})
    key = Body("key", {"square": Prism(point=(0, 0, 0), axis=(0, 0, 1), sides=4, size=3.0)})
    flat = Body("flat", {"top": Plane(point=(0, 0, 0), normal=(0, 0, 1))}, fixed=True)
    situation = (Situation("s1"),)
    assert model_scale(Task("mm", {"pin": pin, "key": key}, situation)) == pytest.approx(
        10 * math.sqrt(3)
    )
    assert model_scale(Task("mm", {"flat": flat}, situation)) == 1.0  # no extent at all


def test_a_search_cut_at_its_limit_says_so_and_counts_what_it_found(tmp_path):
    """The W14 square peg with 100-sided prisms has exactly 100 poses, the written one
    turned about the axis by 2πk/100; the default search follows 64 of them and says so."""
    square = files("assemblykit") / "examples" / "tasks" / "w14_square_peg.yaml"
    path = tmp_path / "hundred.yaml"
    path.write_text(square.read_text().replace("sides: 4", "sides: 100"), encoding="utf-8")
    task = load_task(path)

    cut = solve_task(task)
    assert cut.status == "ambiguous"
    assert cut.cut is not None and (cut.cut.followed, cut.cut.not_followed) == (64, 36)
    assert cut.to_dict()["truncated"]["not_followed"] == 36
    assert cut["peg@s1"].solutions == 64

    whole = solve_task(task, max_branches=100)
    assert whole.cut is None and "truncated" not in whole.to_dict()
    peg = whole["peg@s1"]
    assert peg.solutions == 100
    turns = sorted(
        round(math.atan2(p[1, 0], p[0, 0]) / (2 * math.pi / 100)) % 100
        for p in (peg.pose, *peg.alternatives)
    )
    assert turns == list(range(100))
    for p in (peg.pose, *peg.alternatives):
        assert np.allclose(p[:3, 3], 0, atol=1e-12) and np.allclose(p[2, :3], [0, 0, 1])


def test_revolute_loop_carries_the_joint_point_by_the_closing_link():
    """R·R ∩ R with representatives that do not close (as before any solving): the joint
    point p2 = (1, 0, 0) of j is (1, -2, 0) in k (second rep Tr(0, 2, 0)); it sweeps the
    unit circle about the origin under the first link and the circle of radius √8 about
    (3, 0, 0) under the closing one, which meet at x = 1/3, y = ±√8/3."""
    z = (0.0, 0.0, 1.0)
    first = Coset(SymmetryGroup.revolute((0, 0, 0), z), se3.rot_z(math.pi / 2))
    second = Coset(SymmetryGroup.revolute((1, 0, 0), z), se3.translation((0, 2, 0)))
    closing = Coset(SymmetryGroup.revolute((3, 0, 0), z), np.eye(4))
    closed = revolute_loop(first, second, closing, Tolerance())
    assert closed is not None
    pairs, gap = closed
    assert gap == 0.0 and len(pairs) == 2
    met = sorted(tuple(np.round(se3.apply(x_ij, np.array([1.0, 0, 0])), 12)) for x_ij, _ in pairs)
    y = round(math.sqrt(8) / 3, 12)
    assert met == [(round(1 / 3, 12), -y, 0.0), (round(1 / 3, 12), y, 0.0)]
    for x_ij, x_ik in pairs:  # the loop closes: X_ij · X_jk = X_ik with X_jk in the second
        assert first.contains(x_ij) and closing.contains(x_ik)
        assert second.contains(se3.inverse(x_ij) @ x_ik)
