"""Fasteners named in plans (planning/fasteners.py): a part drawn out of round holes
along their axis is a pin, or a screw where it interferes with a hole by design; on
hand-built meshes whose fits and directions are known by hand. (The STEP cases, a pin
in a hole of its diameter and a self-tapping screw, are in tests/io/test_step_fits.py.)"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import trimesh

from assemblykit.geometry.overlaps import resolve_overlaps
from assemblykit.model.assembly import Assembly, Part
from assemblykit.planning.fasteners import Fastener, Thread, drawn_summary, implied_thread
from assemblykit.planning.planner import plan
from assemblykit.viz.viewer import report_html
from plan_checks import assert_steps_clear
from stability_blocks import box


def rod_through_blocks(rod: float, hole: float, head: float = 2.5) -> Assembly:
    """Two blocks 8 x 8 x 3 side by side along x (x in [-4, 4] and [4, 12]) with a hole
    of radius ``hole`` along x at y = z = 0 through both, on a base plate below them,
    and a rod of radius ``rod`` 20 long through both holes, its head (radius ``head``,
    1 long) against the first block's outer face at x = -4."""
    drill = trimesh.creation.cylinder(hole, 40, sections=48)
    drill.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))
    blocks = [
        trimesh.boolean.difference([box((8, 8, 3), (x, -4, -1.5)), drill], engine="manifold")
        for x in (-4.0, 4.0)
    ]
    shank = trimesh.creation.cylinder(rod, 16, sections=48)
    head = trimesh.creation.cylinder(head, 1.0, sections=48)
    shank.apply_translation([0, 0, 8])
    head.apply_translation([0, 0, -0.5])
    pin = trimesh.boolean.union([shank, head], engine="manifold")
    pin.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))
    pin.apply_translation([-4, 0, 0])
    return Assembly(
        [
            Part("first", blocks[0]),
            Part("second", blocks[1]),
            Part("rod", pin),
            Part("base", box((16, 8, 1), (-4, -4, -2.5))),
        ]
    )


@pytest.mark.parametrize(
    ("rod", "kind"), [(1.0, "pin"), (1.007, "pressed"), (1.009, "pressed"), (1.04, "screw")]
)
def test_a_rod_drawn_out_of_two_holes_is_named_with_both(rod, kind):
    # at the holes' radius it is a pin; 0.04 larger it cuts a thread into both blocks
    # by design (resolved by trimming it) and is a screw; 0.007 or 0.009 larger (under
    # 1% of the radius, as ISO interference fits press) it is pressed in, no thread
    prepared = resolve_overlaps(rod_through_blocks(rod, 1.0))
    assert len(prepared.overlaps) == (0 if kind == "pin" else 2)
    result = plan(prepared, max_and_or_parts=0)
    assert result.feasible
    (out,) = [s for s in result.steps if "rod" in s.parts]
    assert out.parts == ("rod",)
    # out along -x, the head's side: through both holes and nothing else
    np.testing.assert_allclose(out.direction, [-1, 0, 0], atol=1e-9)
    # the second block may slide off the rod's far end first (+x): the rod then
    # leaves the first block's hole alone
    holes = [name for name in ("first", "second") if name in out.rest]
    assert holes[0] == "first"
    found = out.to_dict()["fastener"]
    assert found["axis"] == pytest.approx([-1.0, 0.0, 0.0], abs=1e-12)
    assert found["diameter"] == pytest.approx(2.0, rel=1e-6)  # the holes' (a trimmed rod's)
    assert {k: v for k, v in found.items() if k not in ("axis", "diameter")} == {
        "part": "rod",
        "kind": kind,
        "holes": holes,
        # by hand: an M2 (2 mm), whose tip at x = 12 leaves the first block at x = -4,
        # 16 mm at 0.4 per turn
        **(
            {"thread": {"size": "M2", "pitch": 0.4, "turns": 40.0, "implied": True}}
            if kind == "screw"
            else {}
        ),
    }
    assert out.fastener is not None
    assert (
        out.fastener.summary()
        == {
            "pin": "pull pin",
            "pressed": "press out",
            "screw": "unscrew M2 (pitch 0.4, 40 turns)",
        }[kind]
    )
    # the blocks lifted off the base are no fasteners
    assert all(s.fastener is None for s in result.steps if "rod" not in s.parts)
    assert all("fastener" not in s.to_dict() for s in result.steps if "rod" not in s.parts)


@pytest.mark.parametrize(("head", "kind"), [(2.5, "screw"), (6.0, None)])
def test_a_body_pressed_onto_its_shaft_is_no_fastener(head, kind):
    # the rod pressed into both holes (0.04 larger) of a frame (the two blocks and a deep
    # plate in one part) leaves along -x, its head's side; with a head of 2.5 radii of
    # the fit it is a screw, with a disc of radius 6 (six radii, as a motor or servo
    # whose shaft is pressed into a pulley or horn) it is no fastener
    parts = rod_through_blocks(1.04, 1.0, head=head).parts
    frame = trimesh.boolean.union(
        [parts["first"].mesh, parts["second"].mesh, box((16, 8, 8), (-4, -4, -9.5))],
        engine="manifold",
    )
    prepared = resolve_overlaps(Assembly([Part("frame", frame), parts["rod"]]))
    assert len(prepared.overlaps) == 1
    result = plan(prepared, max_and_or_parts=0)
    assert result.feasible
    (out,) = result.steps
    assert out.parts == ("rod",)
    np.testing.assert_allclose(out.direction, [-1, 0, 0], atol=1e-9)
    assert (out.fastener and out.fastener.kind) == kind
    assert ("fastener" in out.to_dict()) is (kind is not None)


@pytest.mark.parametrize(
    ("diameter", "units", "size", "pitch"),
    [
        (2.9, "mm", "M3", 0.5),
        (6.0, "mm", "M6", 1.0),
        (0.8, "cm", "M8", 0.125),  # in the model's unit: 1.25 mm
        (0.012, "m", "M12", 0.00175),
        (4.5, "mm", None, None),  # between M4 and M5: no size within 10 %
        (3.0, None, None, None),  # no unit, no size
    ],
)
def test_a_thread_is_implied_by_an_iso_diameter_in_a_known_unit(diameter, units, size, pitch):
    thread = implied_thread(diameter, 10 * (pitch or 1), units)
    if size is None:
        assert thread is None
    else:
        assert thread is not None and (thread.size, thread.turns) == (size, 10.0)
        assert thread.pitch == pytest.approx(pitch, rel=1e-12)


def headed_rod(x: float, radius: float) -> trimesh.Trimesh:
    """A rod of ``radius`` along z from z = 0 to 4 at (x, 0), its head (radius 2, 1 high)
    on top."""
    shank = trimesh.creation.cylinder(radius, 4.0, sections=48)
    shank.apply_translation([x, 0, 2])
    head = trimesh.creation.cylinder(2.0, 1.0, sections=48)
    head.apply_translation([x, 0, 4.5])
    return trimesh.boolean.union([shank, head], engine="manifold")


def test_each_part_of_a_step_that_leaves_alone_is_named_with_its_fastener():
    # a plate 4 thick with three holes of radius 1 along z: two screws 0.04 larger and a
    # pin of the holes' radius, their heads on top; the three leave upwards in one step,
    # each on its own, and each move names its fastener: by hand, an M2 whose tip at
    # z = 0 leaves the plate's top at z = 4 in 4 / 0.4 = 10 turns
    drills = [trimesh.creation.cylinder(1.0, 10, sections=48) for _ in range(3)]
    for x, drill in zip((-6, 0, 6), drills, strict=True):
        drill.apply_translation([x, 0, 2])
    plate = trimesh.boolean.difference([box((20, 8, 4), (-10, -4, 0)), *drills], engine="manifold")
    rods = [Part(f"screw {i}", headed_rod(x, 1.04)) for i, x in enumerate((-6, 0))]
    assembly = Assembly([Part("plate", plate), *rods, Part("pin", headed_rod(6, 1.0))])
    prepared = resolve_overlaps(assembly)
    result = plan(prepared, max_and_or_parts=0)
    assert result.feasible
    (step,) = result.steps
    assert set(step.parts) == {"screw 0", "screw 1", "pin"} and step.fastener is None
    np.testing.assert_allclose(step.direction, [0, 0, 1], atol=1e-9)
    moves = {tuple(move["parts"]): move.get("fastener") for move in step.to_dict()["moves"]}
    assert set(moves) == {("screw 0",), ("screw 1",), ("pin",)}
    for name in ("screw 0", "screw 1"):
        assert moves[(name,)]["kind"] == "screw"
        assert moves[(name,)]["thread"] == {
            "size": "M2",
            "pitch": 0.4,
            "turns": 10.0,
            "implied": True,
        }
    assert moves[("pin",)]["kind"] == "pin" and "thread" not in moves[("pin",)]
    assert step.summary() == "translation; unscrew 2 x M2; pull 1 pin"
    # the report's step table and caption say it as the text table does
    page = report_html(prepared, result)
    assert "<td>translation; unscrew 2 x M2; pull 1 pin</td>" in page
    assert "along +Z (translation; unscrew 2 x M2; pull 1 pin)" in page


@pytest.mark.parametrize(
    ("name", "diameter", "size"),
    [
        ("M2x10_1", 1.6, "M2"),  # a self-tapping M2 in its 1.6 mm pilot hole
        ("SG90.6_BS EN ISO 7045 - M2 x 4 - Z - 4S_2", 2.0, "M2"),
        ("Screw M1.6 x 5", 1.6, "M1.6"),
        ("screw", 1.6, "M1.6"),  # no size written: the diameter's
        ("M3 bracket", 10.0, "M10"),  # a name far from the fit is not believed
        ("M2x10", 3.0, "M3"),
        ("DM3x10", 3.0, "M3"),  # no size: "DM3" is no ISO designation
    ],
)
def test_a_size_written_in_the_name_is_believed_near_its_fit(name, diameter, size):
    thread = implied_thread(diameter, 4.0, "mm", name)
    assert thread is not None and thread.size == size
    assert thread.turns == pytest.approx(4.0 / thread.pitch, abs=0.05)


def test_a_screw_is_sized_by_the_diameter_it_was_drawn_at_not_by_its_pilot_hole():
    # a rod of radius 1.2 cut into holes of radius 1.0 (2 mm: the tap drill of an M2.5,
    # and within 10% of an M2): the ring it shares with each 8 mm block is, by hand,
    # pi (1.2^2 - 1^2) 8 = 11.06 mm^3, so it was drawn 2.4 mm across, an M2.5; its tip
    # at x = 12 leaves the first block at x = -4, 16 mm at 0.45 a turn
    prepared = resolve_overlaps(rod_through_blocks(1.2, 1.0))
    assert [o.volume for o in prepared.overlaps] == pytest.approx([11.06, 11.06], rel=0.01)
    result = plan(prepared, max_and_or_parts=0)
    (out,) = [s for s in result.steps if "rod" in s.parts]
    assert out.fastener is not None and out.fastener.kind == "screw"
    assert out.fastener.diameter == pytest.approx(2.0, rel=1e-6)
    assert out.fastener.summary() == "unscrew M2.5 (pitch 0.45, 35.6 turns)"


def test_a_step_counts_its_screws_nuts_bolts_and_pins_by_size():
    z = np.array([0.0, 0.0, 1.0])
    m5, m3 = Thread("M5", 0.8, 6.0), Thread("M3", 0.5, 4.0)
    drawn = [
        Fastener("a", "screw", z, ("plate",), thread=m3),
        Fastener("b", "nut", z, ("bolt1",), thread=m5),
        Fastener("c", "nut", z, ("bolt2",), thread=m5),
        Fastener("d", "bolt", z, ("plate",), thread=replace(m5, turns=0.0)),
        Fastener("e", "pin", z, ("plate",)),
    ]
    assert drawn_summary(drawn) == (
        "unscrew 1 x M3; unscrew nuts 2 x M5; pull bolts 1 x M5; pull 1 pin"
    )
    assert [f.summary() for f in drawn[1:4]] == [
        "unscrew nut M5 (pitch 0.8, 6 turns)",
        "unscrew nut M5 (pitch 0.8, 6 turns)",
        "pull bolt M5",
    ]


def bolted_by_name(name: str, nut: bool) -> Assembly:
    """A block 24 x 24 x 6 (z from 0 to 6) with a blind hole of radius 1.5 (an M3's
    diameter) from its top down to z = 1 at x = -6, under a plate 3 thick (z from 6 to 9)
    with through holes of that radius there and of radius 4 (an M8's) at x = 5, the
    block's hole there through it too: in the first, a part ``name`` of the holes'
    radius from z = 2 up, its head (radius 2.75, 2 high) on the plate; in the second a
    bolt ``M8 bolt`` of radius 4 from z = 0 up, its head under the block, and with
    ``nut`` a hexagon nut (13 across flats, 6.5 high) on it from the plate's top."""

    def drill(x: float, radius: float, bottom: float, height: float) -> trimesh.Trimesh:
        mesh = trimesh.creation.cylinder(radius, height, sections=48)
        mesh.apply_translation([x, 0, bottom + height / 2])
        return mesh

    block = trimesh.boolean.difference(
        [box((24, 24, 6), (-12, -12, 0)), drill(-6, 1.5, 1, 10), drill(5, 4, -1, 10)],
        engine="manifold",
    )
    plate = trimesh.boolean.difference(
        [box((24, 24, 3), (-12, -12, 6)), drill(-6, 1.5, 5, 5), drill(5, 4, 5, 5)],
        engine="manifold",
    )
    screw = trimesh.boolean.union([drill(-6, 1.5, 2, 7), drill(-6, 2.75, 9, 2)], engine="manifold")
    bolt = trimesh.boolean.union([drill(5, 4, 0, 15.5), drill(5, 7, -3, 3)], engine="manifold")
    parts = [Part("block", block), Part("plate", plate), Part(name, screw), Part("M8 bolt", bolt)]
    if nut:
        hexagon = trimesh.creation.cylinder(13 / np.sqrt(3), 6.5, sections=6)
        hexagon.apply_translation([5, 0, 9 + 3.25])
        parts.append(
            Part(
                "nut",
                trimesh.boolean.difference([hexagon, drill(5, 4, 8, 9)], engine="manifold"),
            )
        )
    return Assembly(parts)


@pytest.mark.parametrize(("name", "kind"), [("M3 Bolt", "screw"), ("dowel", "pin")])
def test_a_part_drawn_at_the_size_its_name_writes_is_unscrewed_from_its_last_hole(name, kind):
    # drawn at 3 mm in holes of 3 mm (no thread modelled, no volume shared), the part
    # named "M3 Bolt" is a screw: by hand it is threaded into the block, the last hole
    # on its way in, its tip at z = 2 leaving the block's top at z = 6 in 4 / 0.5 = 8
    # turns; named otherwise it is a pin. The M8 bolt, its head under the block and no
    # nut on it, lets the plate lift off it, then leaves downwards threaded into the
    # block: its tip at z = 15.5 leaves the block's bottom in 15.5 / 1.25 = 12.4 turns
    assembly = bolted_by_name(name, nut=False)
    result = plan(assembly, max_and_or_parts=0)
    assert result.feasible
    assert_steps_clear(assembly, result)
    fasteners = {f.part: f for step in result.steps for f in step.fasteners}
    assert fasteners[name].kind == kind and fasteners[name].holes == ("block", "plate")
    said = "unscrew M3 (pitch 0.5, 8 turns)" if kind == "screw" else "pull pin"
    assert fasteners[name].summary() == said
    assert fasteners["M8 bolt"].holes == ("block",)
    assert fasteners["M8 bolt"].summary() == "unscrew M8 (pitch 1.25, 12.4 turns)"


def test_a_bolt_named_by_its_size_is_pulled_once_its_nut_is_off():
    # with its nut on, the M8 bolt is held by it: the nut is unscrewed upwards first,
    # from its back face at z = 9 to the bolt's tip at z = 15.5 (6.5 / 1.25 = 5.2
    # turns), and the bolt is then pulled out downwards, no thread left to turn
    assembly = bolted_by_name("M3 Bolt", nut=True)
    result = plan(assembly, max_and_or_parts=0)
    assert result.feasible
    assert_steps_clear(assembly, result)
    when = {name: k for k, step in enumerate(result.steps) for name in step.parts}
    assert when["nut"] < when["M8 bolt"]
    fasteners = {f.part: f for step in result.steps for f in step.fasteners}
    assert fasteners["nut"].summary() == "unscrew nut M8 (pitch 1.25, 5.2 turns)"
    assert fasteners["M8 bolt"].summary() == "pull bolt M8"
    assert fasteners["M3 Bolt"].summary() == "unscrew M3 (pitch 0.5, 8 turns)"
