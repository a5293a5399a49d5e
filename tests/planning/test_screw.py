"""Turns in plans: a hook behind a lip that only a rotation frees."""

from __future__ import annotations

import itertools
import math

import manifold3d
import numpy as np
import pytest
import trimesh
from rich.console import Console

from assemblykit.algebra import se3
from assemblykit.geometry.interference import interference_threshold, solid
from assemblykit.model.assembly import Assembly, Part
from assemblykit.planning.screw import plan_with_screws, screw_removal

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


def hooked() -> Assembly:
    base = cube(*BASE[0])
    for lo, hi in BASE[1:]:
        base = base + cube(lo, hi)
    return Assembly([Part("base", mesh_of(base)), Part("hook", mesh_of(cube(*HOOK)))])


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


def test_an_independent_sweep_confirms_the_turn_and_that_no_translation_frees_the_hook():
    assembly = hooked()
    turn = screw_removal(assembly, ["hook"])
    base = solid(assembly["base"].mesh)
    limit = interference_threshold(assembly["base"].mesh, assembly["hook"].mesh)
    corners = np.asarray(assembly["hook"].mesh.vertices)
    # the hull of two poses a tenth of a degree apart holds the sweep between them, but
    # for arcs bulging past the chords by r (1 - cos 0.05 deg), under 2e-6 here
    fractions = np.linspace(0.0, 1.0, 501)
    poses = [se3.apply(turn.pose(f), corners) for f in fractions]
    for before, after in itertools.pairwise(poses):
        assert swept_volume(np.vstack([before, after]), base) <= limit
    assert swept_volume(np.vstack([poses[-1], poses[-1] + [0, 0, 100]]), base) <= limit
    # from the assembled pose every straight way out is blocked
    for direction in np.vstack([np.eye(3), -np.eye(3)]):
        assert swept_volume(np.vstack([corners, corners + 100 * direction]), base) > limit


def test_plan_with_turns_takes_the_hook_out_where_translations_stop():
    result = plan_with_screws(hooked())
    stuck = result.stages[0]  # the translation plan alone
    assert not stuck.feasible and stuck.interlocked[0].rigid_may_free
    assert result.feasible and len(result.screws) == 1
    data = result.to_dict()
    assert data["feasible"] and data["stuck"] == []
    assert [s["motion"] for s in data["steps"]] == ["screw"]
    assert data["steps"][0]["axis"]["direction"] == pytest.approx([0, -1, 0])
    console = Console(record=True, width=200)
    console.print(result.render())
    assert "turn 50.0 deg" in console.export_text()


def test_a_sealed_hook_has_no_turn_out():
    sealed = cube((-1, -1, -1), (4.5, 2, 2.5)) - cube(*HOOK)
    assembly = Assembly([Part("box", mesh_of(sealed)), Part("hook", mesh_of(cube(*HOOK)))])
    assert screw_removal(assembly, ["hook"]) is None
