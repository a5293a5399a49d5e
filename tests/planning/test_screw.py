"""Turns in plans: a hook behind a lip that only a rotation frees."""

from __future__ import annotations

import itertools
import json
import math

import manifold3d
import numpy as np
import pytest
import trimesh
from rich.console import Console
from scipy.spatial.transform import Rotation

from assemblykit.cli import main
from assemblykit.model.assembly import Assembly, Part
from assemblykit.planning.screw import plan_with_screws, screw_removal
from assemblykit.render import render

# side view (x right, z up), extruded along y over [0, 1]: the base is a floor, a wall on
# the left, a post on the right carrying a lip over x in [3.4, 5] at z in [3.5, 4], and
# plates a quarter away in front and behind; the hook, a 3.5 x 1 x 1.5 block, lies on the
# floor against the wall with its right end under the lip
BASE = [
    ((-1, -1, -1), (6, 2, 0)),
    ((-1, -1, 0), (0, 2, 4)),
    ((5, -1, 0), (6, 2, 4)),
    ((3.4, -1, 3.5), (5, 2, 4)),
    ((0, -1, 0), (5, -0.25, 4)),
    ((0, 1.25, 0), (5, 2, 4)),
]
HOOK = ((0, 0, 0), (3.5, 1, 1.5))


def mesh_of(body: manifold3d.Manifold) -> trimesh.Trimesh:
    out = body.to_mesh()
    return trimesh.Trimesh(np.asarray(out.vert_properties)[:, :3], np.asarray(out.tri_verts))


def cube(lo, hi) -> manifold3d.Manifold:
    return manifold3d.Manifold.cube(np.subtract(hi, lo)).translate(lo)


def base_solid() -> manifold3d.Manifold:
    """The base built straight from its boxes (not through the assembly's meshes)."""
    base = cube(*BASE[0])
    for lo, hi in BASE[1:]:
        base = base + cube(lo, hi)
    return base


def turned(points: np.ndarray, point: np.ndarray, axis: np.ndarray, angle: float) -> np.ndarray:
    """``points`` turned by ``angle`` about the line through ``point`` along ``axis``."""
    return Rotation.from_rotvec(angle * axis).apply(points - point) + point


def hooked() -> Assembly:
    return Assembly([Part("base", mesh_of(base_solid())), Part("hook", mesh_of(cube(*HOOK)))])


def swept_volume(hull_points: np.ndarray, base: manifold3d.Manifold) -> float:
    return (manifold3d.Manifold.hull_points(hull_points) ^ base).volume()


def test_the_hook_turns_fifty_degrees_about_its_top_left_edge_then_lifts_out():
    assembly = hooked()
    turn = screw_removal(assembly, ["hook"])
    assert turn is not None and turn.parts == ("hook",) and turn.rest == ("base",)
    # a quarter turn about -y through the edge x = 0, z = 1.5 swings the right end up;
    # by hand, its lower right corner (3.5 cos a + 1.5 sin a) clears the lip's edge x = 3.4
    # between 49 and 50 degrees, the first whole degree sampled
    assert abs(turn.axis @ [0, 1, 0]) == pytest.approx(1.0)
    assert turn.point[[0, 2]] == pytest.approx([0.0, 1.5], abs=1e-5)
    assert math.degrees(turn.angle) == pytest.approx(50.0)
    assert turn.exit.tolist() == [0.0, 0.0, 1.0]
    data = turn.to_dict()
    assert data["motion"] == "screw" and data["angle_deg"] == pytest.approx(50.0)


CORNERS = np.array(list(itertools.product(*zip(*HOOK, strict=True))), dtype=float)
# overlaps below this are floating-point noise: the real ones near the answer are
# hundredths (the exit a degree early) or tenths (a degree the wrong way)
NOISE = 1e-9


def turn_is_clear(point: np.ndarray, axis: np.ndarray, angle: float, leave: np.ndarray) -> bool:
    """Whether the hook turned by ``angle`` about the line (``point``, ``axis``) and then
    sent along ``leave`` never cuts into the base. The hull of two poses a tenth of a
    degree apart holds the sweep between them, but for arcs bulging past the chords by
    r (1 - cos 0.05 deg), under 2e-6 here; the hull of the last pose and its copy far
    along ``leave`` holds the exit's sweep."""
    base = base_solid()
    poses = [turned(CORNERS, point, axis, a) for a in np.linspace(0.0, angle, 501)]
    pairs = [*itertools.pairwise(poses), (poses[-1], poses[-1] + 100 * leave)]
    return all(swept_volume(np.vstack(pair), base) <= NOISE for pair in pairs)


def test_an_independent_sweep_confirms_the_turn_and_that_no_translation_frees_the_hook():
    turn = screw_removal(hooked(), ["hook"])
    assert turn_is_clear(turn.point, turn.axis, turn.angle, turn.exit)
    # a degree short of the turn the lip still holds the hook; turning the other way
    # digs into the floor
    assert not turn_is_clear(turn.point, turn.axis, turn.angle - math.radians(1), turn.exit)
    assert not turn_is_clear(turn.point, -turn.axis, turn.angle, turn.exit)
    # from the assembled pose every straight way out is blocked
    base = base_solid()
    for direction in np.vstack([np.eye(3), -np.eye(3)]):
        assert swept_volume(np.vstack([CORNERS, CORNERS + 100 * direction]), base) > 1e-3


def test_plan_with_turns_takes_the_hook_out_where_translations_stop():
    result = plan_with_screws(hooked())
    stuck = result.stages[0]  # the translation plan alone
    assert not stuck.feasible and stuck.interlocked[0].rigid_may_free
    assert result.feasible and len(result.screws) == 1
    data = result.to_dict()
    assert data["feasible"] and data["stuck"] == []
    assert [s["motion"] for s in data["steps"]] == ["screw"]
    step = data["steps"][0]
    assert step["axis"]["direction"] == pytest.approx([0, -1, 0])
    # the step as printed, checked by the independent sweep
    axis = {name: np.array(value) for name, value in step["axis"].items()}
    assert turn_is_clear(axis["point"], axis["direction"], step["angle"], np.array(step["exit"]))
    console = Console(record=True, width=200)
    console.print(render(result))
    assert "turn 50.0 deg" in console.export_text()
    # the translation plan alone, as printed (its caption wrapped to the table's width),
    # says where to look, and that more hands would not do
    console.print(render(stuck))
    said = " ".join(console.export_text().split())
    assert "no number of hands takes it apart by translations" in said
    assert "turns and drawn threads: plan --moves rigid" in said


def test_plan_command_moves_rigid_prints_the_turn(tmp_path, capsys):
    for part in hooked():
        part.mesh.export(tmp_path / f"{part.name}.stl")
    try:
        main(["plan", str(tmp_path), "--moves", "rigid", "--json"])
    except SystemExit as done:
        assert not done.code
    data = json.loads(capsys.readouterr().out)
    assert data["feasible"] and data["moves"] == "rigid"
    [step] = data["steps"]
    assert step["motion"] == "screw" and step["parts"] == ["hook"]
    axis = {name: np.array(value) for name, value in step["axis"].items()}
    assert turn_is_clear(axis["point"], axis["direction"], step["angle"], np.array(step["exit"]))


def test_a_sealed_hook_has_no_turn_out():
    sealed = cube((-1, -1, -1), (4.5, 2, 2.5)) - cube(*HOOK)
    assembly = Assembly([Part("box", mesh_of(sealed)), Part("hook", mesh_of(cube(*HOOK)))])
    assert screw_removal(assembly, ["hook"]) is None


# a wedged latch: a 4 x 1 x 1 tooth on a floor between a wall at x = 0 and one at y = 0,
# its far end cut by the plane x + y - z = 4 and pressed against a wedge on that plane
# (the flank); a lip over x in [2.5, 3.5] two units above it and a tall plate across y
# in [3.6, 4.6] close the way up and the way out in front
FLANK = np.array([1.0, 1.0, -1.0]) / np.sqrt(3.0)


def flank_cut(body: manifold3d.Manifold, keep_below: bool) -> manifold3d.Manifold:
    side = 1.0 if keep_below else -1.0
    return body.trim_by_plane(tuple(-side * FLANK), float(-side * FLANK @ [4.0, 0.5, 0.5]))


def latch_base() -> manifold3d.Manifold:
    return (
        cube((-1, -1, -1), (6, 2, 0))
        + cube((-1, -1, 0), (0, 1, 4))
        + cube((-1, -1, 0), (6, 0, 4))
        + flank_cut(cube((2.5, 0, 0), (6, 2, 1)), keep_below=False)
        + cube((2.5, -1, 3), (3.5, 1, 3.5))
        + cube((-1, 3.6, -1), (6, 4.6, 20))
    )


TOOTH = flank_cut(cube((0, 0, 0), (4, 1, 1)), keep_below=True)


def latched() -> Assembly:
    return Assembly([Part("base", mesh_of(latch_base())), Part("tooth", mesh_of(TOOTH))])


def screw_is_clear(
    points: np.ndarray,
    base: manifold3d.Manifold,
    point: np.ndarray,
    axis: np.ndarray,
    angle: float,
    pitch: float,
    leave: np.ndarray,
) -> bool:
    """Whether the convex body with vertices ``points``, screwed by ``angle`` about the
    line (``point``, ``axis``) advancing ``pitch`` per radian along it, then sent along
    ``leave``, never cuts into ``base`` (hulls of poses a tenth of a degree apart, as
    :func:`turn_is_clear`)."""
    poses = [
        turned(points, point, axis, a) + pitch * a * axis for a in np.linspace(0.0, angle, 501)
    ]
    pairs = [*itertools.pairwise(poses), (poses[-1], poses[-1] + 100 * leave)]
    return all(swept_volume(np.vstack(pair), base) <= NOISE for pair in pairs)


def test_a_latch_pressed_on_a_flank_leaves_by_a_screw_that_slides_along_its_axis():
    turn = screw_removal(latched(), ["tooth"])
    assert turn is not None and turn.parts == ("tooth",)
    # no pure turn frees it, so the turn carries a pitch: about -y through the top edge
    # of the contact with the wall x = 0 (x = 0, z = 1), a point p of the contacts is
    # pushed along the normal n by ((1 - p_z, 0, p_x) + h (0, -1, 0)) . n; on the flank
    # (n = (1, 1, -1) / sqrt 3) at its vertex (3, 1, 0) that is (-2 - h) / sqrt 3, so
    # h >= -2, while the wall y = 0 (n = -y) asks h <= 0: the screw sliding on the flank
    # advances 2 per radian along +y
    assert turn.axis @ [0, -1, 0] == pytest.approx(1.0)
    assert turn.point[[0, 2]] == pytest.approx([0.0, 1.0], abs=1e-5)
    assert turn.pitch == pytest.approx(-2.0)
    data = turn.to_dict()
    assert data["pitch"] == pytest.approx(-2.0)
    assert data["advance"] == pytest.approx(-2.0 * turn.angle)
    points = np.asarray(TOOTH.to_mesh().vert_properties)[:, :3]
    base = latch_base()
    assert screw_is_clear(points, base, turn.point, turn.axis, turn.angle, turn.pitch, turn.exit)
    # the same turn without the slide, or a degree shorter, does not get out
    assert not screw_is_clear(points, base, turn.point, turn.axis, turn.angle, 0.0, turn.exit)
    short = turn.angle - math.radians(1)
    assert not screw_is_clear(points, base, turn.point, turn.axis, short, turn.pitch, turn.exit)
    # and no straight line out of the assembled pose: every axis and diagonal is blocked
    for d in itertools.product((-1, 0, 1), repeat=3):
        if any(d):
            assert swept_volume(np.vstack([points, points + 100 * np.array(d)]), base) > 1e-3


def test_plan_with_turns_prints_the_pitch():
    result = plan_with_screws(latched())
    # translations alone (any direction of the blocking graph) do not free the tooth
    assert not result.stages[0].feasible
    assert result.feasible and [s.pitch for s in result.screws] == [pytest.approx(-2.0)]
    console = Console(record=True, width=200)
    console.print(render(result))
    assert "pitch -2 per rad" in console.export_text()


def threaded_bolt(path) -> tuple[object, object, object]:
    """A 20 x 20 x 2 plate at z in [4, 6] with a clearance hole of radius 1.6; a screw with
    its thread drawn (a shank of radius 1.25 from z = -2 to 6, a right-handed crest of
    pitch 0.5 out to radius 1.55 from z = -1.5 over 7, a head of radius 2.75 up to z = 8)
    through it; and under it a 6 x 6 x 3 nut at z in [1, 4], bored to radius 1.55, its
    own crest in the screw's grooves, half a pitch along, 0.05 clear of the screw's
    flanks. Written to ``path`` as STEP;
    returns the three exact solids."""
    from step_files import box, cut, cylinder, fuse, helix_sweep, write_step

    plate = cut(box((-10, -10, 4), (20, 20, 2)), cylinder((0, 0, 3), 1.6, 4.0))
    crest = helix_sweep(1.4, 0.5, 7.0, [(1.24, -0.2), (1.55, 0.0), (1.24, 0.2)], z0=-1.5)
    screw = fuse(fuse(cylinder((0, 0, -2), 1.25, 8.0), crest), cylinder((0, 0, 6), 2.75, 2.0))
    ridge = [(1.7, -0.2), (1.56, -0.2), (1.25, 0.0), (1.56, 0.2), (1.7, 0.2)]
    inside = helix_sweep(1.4, 0.5, 3.5, ridge, z0=0.75)
    # the bore less the nut's crest, cut from the block (OCCT fuses the two as two solids)
    nut = cut(box((-3, -3, 1), (6, 6, 3)), cut(cylinder((0, 0, 0), 1.55, 5.0), inside))
    write_step(path, plate, screw, nut)
    return plate, screw, nut


@pytest.mark.cad
@pytest.mark.slow
def test_a_screw_with_its_thread_drawn_in_a_nut_is_unscrewed_turn_by_turn(tmp_path):
    # no translation frees a drawn thread; following it at the ISO pitch of its size
    # (M3: 0.5 a turn, right-handed) takes the screw out, then the nut comes away
    pytest.importorskip("OCP")
    from assemblykit.io.assembly import load_assembly
    from assemblykit.planning.planner import plan
    from step_files import occ_mesh

    path = tmp_path / "bolt.step"
    _, screw, nut = threaded_bolt(path)
    asm = load_assembly(path)
    _, screw_name, nut_name = asm.names
    stopped = plan(asm)
    assert not stopped.feasible and {screw_name, nut_name} <= set(stopped.stuck)
    found = plan_with_screws(asm)
    assert found.feasible
    (turn,) = found.screws
    assert turn.parts in ((screw_name,), (nut_name,))
    assert abs(float(turn.axis @ [0.0, 0.0, 1.0])) == pytest.approx(1.0)
    assert turn.pitch * 2 * math.pi == pytest.approx(0.5) and turn.pitch > 0
    # the screw's tip or the nut's far face goes past the other: 6 mm or more, 12 turns
    assert turn.angle / (2 * math.pi) >= 12

    def solid_of(shape: object) -> manifold3d.Manifold:
        # OCCT's own mesh of the exact solid, 0.005 from it (a tenth of the thread's
        # clearance), read without the project's reader
        vertices, triangles = occ_mesh(shape, 0.005)
        mesh = trimesh.Trimesh(vertices, triangles, process=True)
        return manifold3d.Manifold(
            manifold3d.Mesh64(
                vert_properties=np.ascontiguousarray(mesh.vertices),
                tri_verts=np.ascontiguousarray(mesh.faces, dtype=np.uint64),
            )
        )

    moving, still = (screw, nut) if turn.parts == (screw_name,) else (nut, screw)
    body, other = solid_of(moving), solid_of(still)

    def shared(pose: np.ndarray) -> float:
        moved = body.transform(np.ascontiguousarray(pose[:3, :4]))
        return float((moved ^ other).volume())

    # along the thread the two stay apart at every pose checked here (off the planner's
    # own samples, a turn and a sixth); half a pitch straight up runs the crests into
    # each other
    for angle in np.radians(7.0 + 67.0 * np.arange(7)):
        assert shared(turn.pose(angle / turn.angle)) <= 1e-3, angle
    lift = np.eye(4)
    lift[:3, 3] = 0.25 * np.asarray(turn.axis)
    assert shared(lift) > 0.1
    table = Console(width=120, record=True)
    table.print(render(found))
    text = table.export_text()
    assert "unscrew 16 turns, 0.5 per turn" in text
