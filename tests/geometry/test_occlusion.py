"""Exact extended blocking on triangle meshes by projection (Wilson & Latombe 1992, "Extended
translations"), checked by hand and against swept volumes built with manifold3d."""

from __future__ import annotations

import manifold3d
import numpy as np
import pytest
import trimesh

from assemblykit.geometry import occlusion
from assemblykit.geometry.interference import interferes, solid
from assemblykit.geometry.occlusion import occluded_pairs, shadows, view_frame
from assemblykit.tolerance import Tolerance

TOL = Tolerance(scale=10.0)
BOTH = ~np.eye(2, dtype=bool)
UP, DOWN, EAST = [0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]


def mesh_of(shape: manifold3d.Manifold) -> trimesh.Trimesh:
    out = shape.to_mesh64()
    return trimesh.Trimesh(np.array(out.vert_properties[:, :3]), np.array(out.tri_verts))


def cube(lo, hi) -> manifold3d.Manifold:
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    return manifold3d.Manifold.cube(tuple(hi - lo)).translate(tuple(lo))


def blocked(meshes, direction) -> set[tuple[int, int]]:
    return occluded_pairs(shadows(meshes, direction, TOL), BOTH, TOL)


def swept(mesh: trimesh.Trimesh, direction, length: float) -> trimesh.Trimesh:
    """Oracle: the mesh with the prisms of its forward triangles, one manifold3d union."""
    step = length * np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    front = mesh.triangles[mesh.face_normals @ step > 0]
    prisms = [manifold3d.Manifold.hull_points(np.vstack([t, t + step])) for t in front]
    return mesh_of(manifold3d.Manifold.batch_boolean([solid(mesh), *prisms], manifold3d.OpType.Add))


def pin_in_blind_hole() -> list[trimesh.Trimesh]:
    bore = manifold3d.Manifold.cylinder(3.0, 0.5, 0.5, 16).translate((0.0, 0.0, -1.0))
    housing = cube([-2, -2, -2], [2, 2, 2]) - bore  # the hole opens at the top, z = 2
    pin = manifold3d.Manifold.cylinder(4.0, 0.5, 0.5, 16).translate((0.0, 0.0, -1.0))
    return [mesh_of(pin), mesh_of(housing)]


def test_view_frame_is_orthonormal_with_the_direction_last():
    frame = view_frame([0.0, 3.0, 4.0])
    assert np.allclose(frame @ frame.T, np.eye(3))
    assert np.allclose(frame[2], [0.0, 0.6, 0.8])


def test_pin_leaves_a_blind_hole_along_its_axis_only():
    meshes = pin_in_blind_hole()
    assert blocked(meshes, UP) == {(1, 0)}  # the pin goes; the housing cannot go up
    assert blocked(meshes, DOWN) == {(0, 1)}
    for d in (EAST, [0.0, 1.0, 0.0], [0.0, 0.1, 1.0], [0.1, 0.0, 1.0]):
        assert blocked(meshes, d) == {(0, 1), (1, 0)}, d


def test_hook_under_a_ledge_is_blocked_upwards_and_free_sideways():
    # an L: a foot under the ledge of a wall, a post rising beside it
    hook = mesh_of(cube([0, 0, 0], [3, 1, 1]) + cube([0, 0, 1], [1, 1, 4]))
    wall = mesh_of(cube([1, -1, 1], [5, 2, 2]) + cube([4, -1, 0], [5, 2, 1]))
    meshes = [hook, wall]
    assert (0, 1) in blocked(meshes, UP)
    assert (0, 1) not in blocked(meshes, [-1.0, 0.0, 0.0])
    assert (0, 1) not in blocked(meshes, [0.0, 1.0, 0.0])
    assert (0, 1) in blocked(meshes, EAST)


def test_touching_faces_do_not_block():
    below, above = mesh_of(cube([0, 0, 0], [1, 1, 1])), mesh_of(cube([0, 0, 1], [1, 1, 2]))
    assert blocked([below, above], UP) == {(0, 1)}
    assert blocked([below, above], EAST) == set()
    # a neighbour sharing only an edge in projection does not block either
    beside = mesh_of(cube([1, 0, 1], [2, 1, 2]))
    assert blocked([below, beside], UP) == set()


def test_agrees_with_swept_volumes():
    meshes = pin_in_blind_hole()
    rng = np.random.default_rng(7)
    directions = [UP, DOWN, EAST, *rng.normal(size=(5, 3))]
    for d in directions:
        expected = {
            (i, j)
            for i in range(2)
            for j in range(2)
            if i != j and interferes(swept(meshes[i], d, 20.0), meshes[j], TOL.for_mesh())
        }
        assert blocked(meshes, d) == expected, d


@pytest.mark.parametrize("count", [0, 1, 8, 10**6])
def test_looking_at_the_largest_triangles_first_changes_no_answer(count, monkeypatch):
    # none, a few or all triangles of each mesh in the first pass: the pairs found are
    # those of the whole meshes, the hook and the wall included
    hook = mesh_of(cube([0, 0, 0], [3, 1, 1]) + cube([0, 0, 1], [1, 1, 4])).subdivide()
    wall = mesh_of(cube([1, -1, 1], [5, 2, 2]) + cube([4, -1, 0], [5, 2, 1]))
    meshes = [*pin_in_blind_hole(), hook, wall]
    allowed = ~np.eye(len(meshes), dtype=bool)
    rng = np.random.default_rng(3)
    directions = [UP, DOWN, EAST, *rng.normal(size=(4, 3))]
    expected = [occluded_pairs(shadows(meshes, d, TOL), allowed, TOL) for d in directions]
    monkeypatch.setattr(occlusion, "_FIRST_TRIANGLES", count)
    for d, pairs in zip(directions, expected, strict=True):
        assert occluded_pairs(shadows(meshes, d, TOL), allowed, TOL) == pairs, d
    assert any(pairs for pairs in expected)


@pytest.mark.parametrize(("scale", "kept"), [(100.0, 0), (1.0, 1)])
def test_a_side_face_whose_shadow_is_thinner_than_the_tolerance_casts_none(scale, kept):
    # tilted 5e-5 off the view direction (beyond the angle tolerance 1e-5), the triangle
    # projects to a sliver 5e-5 wide: below the tolerance 1e-6 x 100, above 1e-6 x 1
    triangle = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [0, 5e-5, 1]], [[0, 1, 2]], process=False)
    view = shadows([triangle], [0, 0, 1], Tolerance(scale=scale).for_mesh())
    assert len(view.owner) == kept


def test_clipped_triangles_match_shapely_intersections():
    import shapely

    from assemblykit.geometry.occlusion import clip_triangles

    rng = np.random.default_rng(3)
    first = rng.uniform(0.0, 1.0, (3000, 3, 2))
    second = rng.uniform(0.0, 1.0, (3000, 3, 2))
    second[:50] = first[:50]  # the same triangle
    second[50:100] = first[50:100, ::-1]  # the same, wound the other way
    second[100:150, :2] = first[100:150, :2]  # a shared edge
    second[150:200] = first[150:200] + 2.0  # apart
    points, corner, area, perimeter = clip_triangles(first, second)
    overlap = shapely.intersection(shapely.polygons(first), shapely.polygons(second))
    np.testing.assert_allclose(area, shapely.area(overlap), atol=1e-12)
    solid = shapely.area(overlap) > 1e-9
    np.testing.assert_allclose(perimeter[solid], shapely.length(overlap)[solid], atol=1e-12)
    assert not corner[150:200].any()
    # the same polygons, vertices in order around them
    found = [shapely.Polygon(points[k, corner[k]]) for k in np.flatnonzero(solid)]
    assert shapely.area(shapely.symmetric_difference(found, overlap[solid])).max() < 1e-12


def hull_test(meshes, direction) -> set[tuple[int, int]]:
    """The pairs the convex-hull outlines leave possible along ``direction``."""
    hulls = [occlusion.hull_vertices(m) for m in meshes]
    pairs = np.array([(i, j) for i in range(len(meshes)) for j in range(len(meshes)) if i != j])
    keep = occlusion.hulls_may_block(hulls, pairs, direction, TOL)
    return {(int(i), int(j)) for (i, j), k in zip(pairs, keep, strict=True) if k}


def test_hull_outlines_rule_out_sliding_and_neighbours_and_keep_what_blocks():
    below, above = mesh_of(cube([0, 0, 0], [1, 1, 1])), mesh_of(cube([0, 0, 1], [1, 1, 2]))
    # sliding along the face they share: the outlines meet on a segment only
    assert hull_test([below, above], EAST) == set()
    # lifting: only the lower block runs into the upper one
    assert hull_test([below, above], UP) == {(0, 1)}
    beside = mesh_of(cube([3, 0, 0], [4, 1, 1]))
    assert hull_test([below, beside], UP) == set()
    assert hull_test([below, beside], EAST) == {(0, 1)}


def test_hull_outlines_of_a_tessellated_cylinder_hold_it():
    rod = trimesh.creation.cylinder(radius=2.0, height=10.0, sections=256)
    corners = occlusion.hull_vertices(rod)
    assert len(corners) < len(rod.convex_hull.vertices) / 4
    outer = trimesh.convex.convex_hull(corners)
    assert outer.volume >= rod.volume
    assert outer.volume < 1.1 * rod.volume
    # every vertex of the rod inside the polytope (up to rounding)
    normals, offsets = (
        outer.face_normals,
        np.einsum("ij,ij->i", outer.face_normals, outer.triangles[:, 0]),
    )
    assert np.all(rod.vertices @ normals.T <= offsets + 1e-9)


@pytest.mark.parametrize("seed", range(6))
def test_hull_outlines_never_rule_out_a_block_the_meshes_show(seed):
    # a hook and a wall placed at random, along random directions: every pair the
    # projection test finds blocking is kept by the hull test
    rng = np.random.default_rng(seed)
    hook = cube([0, 0, 0], [3, 1, 1]) + cube([0, 0, 1], [1, 1, 4])
    wall = cube([1, -1, 1], [5, 2, 2]) + cube([4, -1, 0], [5, 2, 1])
    meshes = [mesh_of(hook), mesh_of(wall.translate(tuple(rng.uniform(-2, 2, 3))))]
    for d in [UP, DOWN, EAST, *rng.normal(size=(12, 3))]:
        assert blocked(meshes, d) <= hull_test(meshes, d), d


def test_a_witness_found_along_one_direction_shows_the_block_along_its_neighbours():
    hook = mesh_of(cube([0, 0, 0], [3, 1, 1]) + cube([0, 0, 1], [1, 1, 4]))
    wall = mesh_of(cube([1, -1, 1], [5, 2, 2]) + cube([4, -1, 0], [5, 2, 1]))
    meshes = [hook, wall]
    witnesses = occlusion.blocking_witnesses(shadows(meshes, UP, TOL), BOTH, TOL)
    face_hook, face_wall = witnesses[(0, 1)]
    # a backward face of the hook under a forward face of the wall
    assert hook.face_normals[face_hook] @ UP < 0 < wall.face_normals[face_wall] @ UP
    tilted = [0.05, 0.02, 1.0]
    assert occlusion.witnesses_hold(meshes, [(0, 1, face_hook, face_wall)], tilted, TOL).all()
    # sideways the hook leaves: no witness can show a block there
    away = [-1.0, 0.0, 0.0]
    assert not occlusion.witnesses_hold(meshes, [(0, 1, face_hook, face_wall)], away, TOL).any()


def hook_witnesses(
    rng: np.random.Generator,
) -> tuple[list[trimesh.Trimesh], list[tuple[int, int, int, int]]]:
    """A hook and a wall moved at random, and the witnesses the projection test found
    along eight random directions."""
    hook = cube([0, 0, 0], [3, 1, 1]) + cube([0, 0, 1], [1, 1, 4])
    wall = cube([1, -1, 1], [5, 2, 2]) + cube([4, -1, 0], [5, 2, 1])
    meshes = [mesh_of(hook), mesh_of(wall.translate(tuple(rng.uniform(-1, 1, 3))))]
    found = {}
    for d in rng.normal(size=(8, 3)):
        found |= occlusion.blocking_witnesses(shadows(meshes, d, TOL), BOTH, TOL)
    return meshes, [(i, j, *faces) for (i, j), faces in found.items()]


@pytest.mark.parametrize("seed", range(4))
def test_a_witness_holds_only_where_the_projection_test_blocks(seed):
    rng = np.random.default_rng(seed)
    meshes, witnesses = hook_witnesses(rng)
    held_somewhere = 0
    for d in [UP, DOWN, EAST, *rng.normal(size=(10, 3))]:
        held = occlusion.witnesses_hold(meshes, witnesses, d, TOL)
        shown = {(w[0], w[1]) for w, h in zip(witnesses, held, strict=True) if h}
        assert shown <= blocked(meshes, d), d
        held_somewhere += len(shown)
    assert held_somewhere > 0


@pytest.mark.parametrize("seed", range(3))
def test_witnesses_along_many_directions_hold_where_they_hold_one_direction_at_a_time(seed):
    # the hook's witnesses tested along forty directions at once give, per direction,
    # the verdicts of forty separate tests, and show only blocks of the projection test
    rng = np.random.default_rng(seed)
    meshes, witnesses = hook_witnesses(rng)
    directions = np.vstack([UP, DOWN, EAST, rng.normal(size=(37, 3))])
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    frames = np.array([occlusion.view_frame(d) for d in directions])
    along = occlusion.witnesses_hold_along(meshes, witnesses, frames, TOL)
    assert along.shape == (len(witnesses), len(directions)) and along.any()
    for k, d in enumerate(directions):
        assert list(along[:, k]) == list(occlusion.witnesses_hold(meshes, witnesses, d, TOL))
        shown = {(w[0], w[1]) for w, h in zip(witnesses, along[:, k], strict=True) if h}
        assert shown <= blocked(meshes, d), d
    assert occlusion.witnesses_hold_along(meshes, [], frames, TOL).shape == (0, 40)


@pytest.mark.parametrize("seed", range(4))
def test_projecting_only_the_faces_near_the_other_outline_finds_the_same_blocks(seed):
    rng = np.random.default_rng(seed)
    hook = cube([0, 0, 0], [3, 1, 1]) + cube([0, 0, 1], [1, 1, 4])
    wall = cube([1, -1, 1], [5, 2, 2]) + cube([4, -1, 0], [5, 2, 1])
    far = cube([20, 20, 20], [21, 21, 21])
    meshes = [mesh_of(hook), mesh_of(wall.translate(tuple(rng.uniform(-1, 1, 3)))), mesh_of(far)]
    allowed = ~np.eye(3, dtype=bool)
    spheres = [occlusion.triangle_spheres(m) for m in meshes]
    hulls = [occlusion.hull_vertices(m) for m in meshes]
    dropped = 0
    for d in [UP, DOWN, EAST, *rng.normal(size=(10, 3))]:
        faces = occlusion.faces_near_outlines(spheres, hulls, np.argwhere(allowed), d, TOL)
        every = occluded_pairs(shadows(meshes, d, TOL), allowed, TOL)
        culled = occluded_pairs(shadows(meshes, d, TOL, faces), allowed, TOL)
        assert culled == every, d
        dropped += sum(len(m.faces) - len(f) for m, f in zip(meshes, faces, strict=True))
    assert dropped > 0
