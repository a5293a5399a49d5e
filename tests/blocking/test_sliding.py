"""Parts that can only slide: free along an arc of a great circle or along isolated
directions, a set of no interior (docs/blocking.md, "Three kinds of motion").

Every answer is derived by hand in the comments and checked again by sweeping the parts
along the reported directions with manifold3d (``plan_checks``), apart from the code
under test."""

from __future__ import annotations

import json

import manifold3d
import numpy as np
import pytest
import trimesh

from assemblykit.blocking.extended import extended_free
from assemblykit.blocking.queries import can_extract, parts_to_remove_before, removal_before
from assemblykit.model.assembly import Assembly, Part
from assemblykit.model.packings import box_mesh as box
from assemblykit.model.polygons import PolygonAssembly
from assemblykit.planning.planner import plan, separable_by_translations
from assemblykit.planning.sequence import Step
from cli_runs import run
from plan_checks import assert_steps_clear

TURN = 40.0
"""Degrees by which the clamp of the lid turns about z."""


def _turned(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    turn = trimesh.transformations.rotation_matrix(np.radians(TURN), [0.0, 0.0, 1.0])
    return mesh.copy().apply_transform(turn)


def _cup() -> trimesh.Trimesh:
    """An open square cup, one non-convex body: outer half-size 2, walls and floor 0.2
    thick, rim at z = 2."""
    outer = manifold3d.Manifold.cube([4.0, 4.0, 2.0]).translate([-2.0, -2.0, 0.0])
    hollow = manifold3d.Manifold.cube([3.6, 3.6, 2.0]).translate([-1.8, -1.8, 0.2])
    mesh = (outer - hollow).to_mesh()
    return trimesh.Trimesh(mesh.vert_properties[:, :3], mesh.tri_verts)


def clamped_lid() -> Assembly:
    """A box in a cup shut by a lid that a bar on a frame clamps onto the cup's rim.

    In the frame's own axes (turned by ``TURN`` about z) the bar lies at
    ``v in [1.9, 2.2]``, ``z in [2.3, 2.6]`` over the lid's corner, on two legs at
    ``|u| in [3.5, 3.8]``; a wall stands behind, at ``v in [-3.6, -3.3]``; the table
    is part of the frame."""
    clamp = [
        box([-3.8, 1.9, 2.3], [3.8, 2.2, 2.6]),
        box([-3.8, 1.9, 0.0], [-3.5, 2.2, 2.3]),
        box([3.5, 1.9, 0.0], [3.8, 2.2, 2.3]),
        box([-6.0, -3.6, 0.0], [6.0, -3.3, 2.6]),
    ]
    frame = trimesh.util.concatenate([box([-7, -7, -1], [7, 7, 0]), *map(_turned, clamp)])
    return Assembly(
        [
            Part("frame", frame),
            Part("cup", _cup()),
            Part("inside", box([-1.2, -1.2, 0.2], [1.2, 1.2, 1.5])),
            Part("lid", box([-2, -2, 2], [2, 2, 2.3])),
        ]
    )


def lid_arc() -> tuple[float, float]:
    """The arc of directions, as angles from +x in degrees, along which the lid slides
    out, by hand. The rim holds it from below and the bar from above, so it moves in
    the plane z = 0 only; there, in the frame's axes ``(u, v)``, the lid's corners are
    ``(±2, ±2)`` turned by ``-TURN``: its farthest corner along +u is
    ``c = (2 cos t + 2 sin t, 2 cos t - 2 sin t)``, along -u ``-c``. It passes the
    right leg while the direction turns counter-clockwise of the line from ``c`` to
    the leg's corner ``(3.5, 2.2)``, and the left leg while it turns clockwise of the
    line from ``-c`` to ``(-3.5, 2.2)``; the wall closes the other side."""
    t = np.radians(TURN)
    c = np.array([2 * np.cos(t) + 2 * np.sin(t), 2 * np.cos(t) - 2 * np.sin(t)])
    first = np.degrees(np.arctan2(2.2 - c[1], 3.5 - c[0]))
    last = np.degrees(np.arctan2(2.2 + c[1], -3.5 + c[0]))
    return TURN + first, TURN + last


def planar(degrees: float, z: float = 0.0) -> np.ndarray:
    d = np.array([np.cos(np.radians(degrees)), np.sin(np.radians(degrees)), z])
    return d / np.linalg.norm(d)


def moved(parts: tuple[str, ...], direction: np.ndarray) -> Step:
    """A step for the independent sweep (the rest and blocking play no part in it)."""
    return Step(parts=parts, direction=np.asarray(direction, dtype=float), rest=(), blocking=())


def test_a_lid_clamped_on_a_cup_slides_out_along_an_arc_and_frees_the_box():
    asm = clamped_lid()
    tol = asm.tolerance()
    first, last = lid_arc()
    assert 110.7 < first < last < 145.6  # about 110.76 and 145.57 degrees
    # off the arc, and tilted up or down by a degree in its middle, the lid is held
    middle = (first + last) / 2
    for d in (planar(first - 1), planar(last + 1), planar(middle, 0.02), planar(middle, -0.02)):
        assert not extended_free(asm, ["lid"], d, tol)
    lid = can_extract(asm, ["lid"])
    assert lid is not None and lid.directions
    for d in lid.directions:
        angle = np.degrees(np.arctan2(d[1], d[0]))
        assert abs(d[2]) <= 1e-9 and first - 1e-6 <= angle <= last + 1e-6
    assert can_extract(asm, ["inside"]) is None
    # the box is held by the cup but along the cone above it, where only the lid is in
    # its way (the bar lies over the lid's corner, beyond the box's reach)
    found = removal_before(asm, "inside")
    assert found.parts == frozenset({"lid"}) and found.minimal
    assert found.direction is not None and found.direction[2] > 0.9
    assert parts_to_remove_before(asm, "inside") == frozenset({"lid"})
    assert parts_to_remove_before(asm, "lid") == frozenset()
    for d in lid.directions:
        assert_steps_clear(asm, [moved(("lid",), d), moved(("inside",), found.direction)])
    result = plan(asm)
    assert result.feasible and separable_by_translations(asm)
    # nothing lifts first: the first step slides in the rim's plane
    assert abs(result.steps[0].direction[2]) <= 1e-9
    assert_steps_clear(asm, result)


def drawer_cabinet() -> Assembly:
    """A cabinet against the wall of a room, a drawer in it touching its floor, top and
    sides, and a letter behind the drawer (between it and the cabinet's back), held on
    every side too. Every part is a union of boxes (the exact NDBG of cones)."""
    cabinet = trimesh.util.concatenate(
        [
            box([-2, -3, 0], [2, 1, 0.2]),
            box([-2, -3, 1.8], [2, 1, 2]),
            box([-2, -3, 0.2], [-1.8, 1, 1.8]),
            box([1.8, -3, 0.2], [2, 1, 1.8]),
            box([-1.8, -3, 0.2], [1.8, -2.8, 1.8]),
        ]
    )
    room = trimesh.util.concatenate([box([-4, -4, -1], [4, 4, 0]), box([-4, -4, 0], [4, -3, 3])])
    return Assembly(
        [
            Part("room", room),
            Part("cabinet", cabinet),
            Part("letter", box([-1.8, -2.8, 0.2], [1.8, -2.0, 1.8])),
            Part("drawer", box([-1.8, -2.0, 0.2], [1.8, 1.0, 1.8])),
        ]
    )


OUT = np.array([0.0, 1.0, 0.0])


def test_a_drawer_slides_out_along_one_direction_and_frees_the_letter_behind_it():
    asm = drawer_cabinet()
    tol = asm.tolerance()
    # by hand: the cabinet's floor and top hold the drawer along every direction out of
    # z = 0, its sides along every one out of x = 0, the letter along -y: only +y stays
    drawer = can_extract(asm, ["drawer"])
    assert drawer is not None and len(drawer.directions) == 1
    assert np.allclose(drawer.directions[0], OUT, atol=1e-12)
    for tilt in ([0.02, 1, 0], [0, 1, 0.02], [-0.02, 1, 0], [0, 1, -0.02]):
        assert not extended_free(asm, ["drawer"], np.array(tilt), tol)
    # the letter is held the same way, and along +y by the drawer alone
    assert can_extract(asm, ["letter"]) is None
    found = removal_before(asm, "letter")
    assert found.parts == frozenset({"drawer"}) and found.minimal
    assert found.direction is not None and np.allclose(found.direction, OUT, atol=1e-12)
    assert parts_to_remove_before(asm, "letter") == frozenset({"drawer"})
    assert parts_to_remove_before(asm, "drawer") == frozenset()
    assert_steps_clear(asm, [moved(("drawer",), OUT), moved(("letter",), OUT)])
    result = plan(asm)
    assert result.feasible and separable_by_translations(asm)
    assert result.steps[0].parts == ("drawer",)
    assert np.allclose(result.steps[0].direction, OUT, atol=1e-12)
    assert result.steps[0].to_dict()["together"] is True
    assert_steps_clear(asm, result)


def test_the_blocking_and_plan_commands_slide_the_drawer_out(tmp_path, capsys):
    folder = tmp_path / "cabinet"
    folder.mkdir()
    for name, part in drawer_cabinet().parts.items():
        part.mesh.export(folder / f"{name}.obj")
    code, out, err = run(capsys, "blocking", str(folder), "--motion", "extended", "--json")
    assert code == 0, err
    removable = {tuple(r["parts"]): r["directions"] for r in json.loads(out)["removable"]}
    assert np.allclose(removable[("drawer",)], [OUT], atol=1e-9)
    code, out, err = run(capsys, "plan", str(folder), "--json")
    assert code == 0, err
    first = json.loads(out)["steps"][0]
    assert first["parts"] == ["drawer"] and first["together"] is True
    assert np.allclose(first["direction"], OUT, atol=1e-9)


def prisms(model: PolygonAssembly) -> Assembly:
    """The polygons as unit-high prisms, for the independent sweeps of ``plan_checks``."""
    parts = []
    for name, polygon in model.polygons.items():
        section = manifold3d.CrossSection([np.asarray(polygon, dtype=np.float64)])
        mesh = manifold3d.Manifold.extrude(section, 1.0).to_mesh()
        parts.append(Part(name, trimesh.Trimesh(mesh.vert_properties[:, :3], mesh.tri_verts)))
    return Assembly(parts)


def slot_and_key() -> PolygonAssembly:
    """A bracket with a slot open to +x, a card at the back of the slot and a key in
    front of it, each as high as the slot."""
    return PolygonAssembly(
        {
            "bracket": np.array(
                [[-1, 0], [7, 0], [7, 1], [0, 1], [0, 2], [7, 2], [7, 3], [-1, 3]], float
            ),
            "card": np.array([[0, 1], [4, 1], [4, 2], [0, 2]], float),
            "key": np.array([[4, 1], [5, 1], [5, 2], [4, 2]], float),
        }
    )


PLUS_X = np.array([1.0, 0.0, 0.0])


def test_a_card_in_a_slot_slides_out_after_the_key_in_front_of_it(tmp_path, capsys):
    model = slot_and_key()
    # by hand: the slot's floor, roof and back hold both, except along +x exactly,
    # where the key holds the card; the bracket itself slides off along -x (its floor
    # and roof along the card and the key, its back away from them)
    key = can_extract(model, ["key"])
    assert key is not None and len(key.directions) == 1
    assert np.allclose(key.directions[0], PLUS_X, atol=1e-12)
    bracket = can_extract(model, ["bracket"])
    assert bracket is not None and len(bracket.directions) == 1
    assert np.allclose(bracket.directions[0], -PLUS_X, atol=1e-12)
    assert can_extract(model, ["card"]) is None
    # so one part must go first, the key or the bracket; both answers are minimal
    found = removal_before(model, "card")
    assert found.parts in (frozenset({"key"}), frozenset({"bracket"})) and found.minimal
    assert found.direction is not None
    assert parts_to_remove_before(model, "card") == found.parts
    assert parts_to_remove_before(model, "key") == frozenset()
    (first,) = found.parts
    solids = prisms(model)
    assert_steps_clear(
        solids,
        [
            moved((first,), (key if first == "key" else bracket).directions[0]),
            moved(("card",), found.direction),
        ],
    )
    result = plan(model)
    assert result.feasible and separable_by_translations(model)
    assert [(s.parts, s.to_dict()["together"]) for s in result.steps] == [
        (("key",), True),
        (("card",), True),
    ]
    assert all(np.allclose(s.direction, PLUS_X, atol=1e-12) for s in result.steps)
    assert_steps_clear(solids, result)
    path = tmp_path / "slot.yaml"
    path.write_text(
        "parts:\n"
        + "".join(f"  {name}: {poly.tolist()}\n" for name, poly in model.polygons.items())
    )
    code, out, err = run(capsys, "blocking", str(path), "--motion", "extended", "--json")
    assert code == 0, err
    removable = {tuple(r["parts"]): r["directions"] for r in json.loads(out)["removable"]}
    assert np.allclose(removable[("key",)], [[1.0, 0.0]], atol=1e-9)


def test_a_card_between_two_books_slides_along_one_line():
    model = PolygonAssembly(
        {
            "lower": np.array([[0, 0], [6, 0], [6, 1], [0, 1]], float),
            "card": np.array([[1, 1], [5, 1], [5, 2], [1, 2]], float),
            "upper": np.array([[0, 2], [6, 2], [6, 3], [0, 3]], float),
        }
    )
    # by hand: the books hold the card along every direction but +x and -x
    card = can_extract(model, ["card"])
    assert card is not None
    assert sorted(tuple(np.round(d, 12) + 0.0) for d in card.directions) == [
        (-1.0, 0.0, 0.0),
        (1.0, 0.0, 0.0),
    ]
    assert removal_before(model, "card").parts == frozenset()
    # the first step takes the card and the upper book out along the same line: each
    # leaves on its own, so the step says they move independently
    step = plan(model).steps[0]
    assert set(step.parts) == {"card", "upper"} and abs(step.direction[0]) == pytest.approx(1.0)
    data = step.to_dict()
    assert data["together"] is False
    assert sorted(m["parts"] for m in data["moves"]) == [["card"], ["upper"]]
    assert all(m["direction"] == data["direction"] for m in data["moves"])
    for m in data["moves"]:
        assert_steps_clear(prisms(model), [moved(tuple(m["parts"]), np.array(m["direction"]))])
