"""Γ_e: blocking for extended translations (Wilson & Latombe 1992, "Extended translations")."""

from __future__ import annotations

from pathlib import Path

import manifold3d
import numpy as np
import pytest
import trimesh
from blocking_helpers import mesh_assembly

from assemblykit.blocking.cache import BlockingCache
from assemblykit.blocking.extended import (
    assembly_extended_terms,
    exact_extended,
    extended_arcs,
    extended_dbg,
    extended_free,
    extended_terms,
    shown_arcs,
)
from assemblykit.blocking.free_cones import ChartSet, _distinct_cones, exact_free_directions
from assemblykit.blocking.graphs import blocking_graph
from assemblykit.blocking.obstacles import THIN_LAYER
from assemblykit.blocking.queries import can_extract, removable_parts
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.geometry.interference import solid
from assemblykit.geometry.minkowski import triangle_cones
from assemblykit.io.assembly import load_assembly
from assemblykit.model.packings import box_mesh as box
from assemblykit.model.polygons import PolygonAssembly
from assemblykit.tolerance import DEFAULT, Tolerance
from datasets import shared_assembly


def ring(center, plane: str) -> trimesh.Trimesh:
    """A square ring of four bars (convex pieces): outer half-size 1.5, bar width 0.5,
    thickness 0.5, in the plane 'xy' or 'xz' around ``center``."""
    c = np.asarray(center, dtype=float)
    bars = []
    for lo, hi in (
        ([-1.5, -1.5], [-1.0, 1.5]),
        ([1.0, -1.5], [1.5, 1.5]),
        ([-1.0, -1.5], [1.0, -1.0]),
        ([-1.0, 1.0], [1.0, 1.5]),
    ):
        if plane == "xy":
            bars.append(
                box(c + np.array([lo[0], lo[1], -0.25]), c + np.array([hi[0], hi[1], 0.25]))
            )
        else:
            bars.append(
                box(c + np.array([lo[0], -0.25, lo[1]]), c + np.array([hi[0], 0.25, hi[1]]))
            )
    return trimesh.util.concatenate(bars)


def test_locally_free_but_blocked_farther_along():
    asm = mesh_assembly(
        {
            "table": box([-2, -2, -1], [2, 2, 0]),
            "block": box([0, 0, 0], [1, 1, 1]),
            "lamp": box([0, 0, 3], [1, 1, 4]),  # hangs above the block, not touching it
        }
    )
    up = np.array([0.0, 0.0, 1.0])
    local = blocking_graph(asm, "infinitesimal")
    assert local.dbg(up).is_free({"block"})
    extended = blocking_graph(asm, "extended")
    assert not extended.dbg(up).is_free({"block"})
    assert extended.dbg(up).blocks("lamp", "block")
    assert extended_dbg(asm, up, tuple(asm.names), asm.tolerance()).arcs == extended.dbg(up).arcs
    sideways = extended.dbg([1.0, 0.0, 0.0])
    assert sideways.is_free({"block"})
    for region in extended.regions():
        assert region.dbg.arcs == extended.dbg(region.direction).arcs


def post_on_plate(layer: float) -> object:
    """A 1 x 1 x 10 post standing on a 10 x 10 x 1 plate, sunk ``layer`` into it."""
    return mesh_assembly(
        {"plate": box([-5, -5, -1], [5, 5, 0]), "post": box([0, 0, -layer], [1, 1, 10 - layer])}
    )


def test_a_layer_thinner_than_the_interference_policy_is_a_contact():
    probe = post_on_plate(0.0)
    tol = probe.tolerance()
    # thicker than the length tolerance (the cones alone would block every direction),
    # thinner than what the policy calls interference (tolerance x the post's area 42)
    layer = 5 * tol.length
    asm = post_on_plate(layer)
    for direction in ([0, 0, 1], [1, 0, 0], [0, 1, 1]):
        assert extended_free(asm, ["post"], direction, tol)
    assert not extended_free(asm, ["post"], [0, 0, -1], tol)
    assert not extended_free(asm, ["post"], [1, 0, -1], tol)
    # the post is tested backed out of the plate by the layer, straight up
    np.testing.assert_allclose(
        BlockingCache.of(asm).obstacles.backout("post", "plate", tol), [0, 0, layer]
    )
    # a real interference stays an obstacle in every direction
    deep = post_on_plate(0.1)
    assert not any(extended_free(deep, ["post"], d, tol) for d in ([0, 0, 1], [1, 0, 0], [0, 1, 1]))


def test_a_layer_far_thinner_than_the_length_tolerance_is_not_backed_out():
    probe = post_on_plate(0.0)
    tol = probe.tolerance()
    # beyond rounding (the cube of the length tolerance), but settling would move the
    # post by a shift the tests drop anyway: it is a contact as it stands
    layer = THIN_LAYER * tol.length / 2
    asm = post_on_plate(layer)
    assert not BlockingCache.of(asm).obstacles.backout("post", "plate", tol).any()
    for direction in ([0, 0, 1], [1, 0, 0], [0, 1, 1]):
        assert extended_free(asm, ["post"], direction, tol)
    assert not extended_free(asm, ["post"], [0, 0, -1], tol)


def test_a_pin_sharing_a_rounding_volume_with_its_blind_hole_is_not_backed_out(monkeypatch):
    # a pin standing 4 deep in a blind hole of its radius: should its solids share a
    # volume of rounding (1e-15), backing it out of the hole along its whole depth would
    # free it sideways; it is not backed out, and only leaves up its axis
    hole = trimesh.creation.cylinder(1.0, 8, sections=32)
    hole.apply_translation([0, 0, 6])
    block = trimesh.boolean.difference([box((-5, -5, 0), (5, 5, 6)), hole], engine="manifold")
    pin = trimesh.creation.cylinder(1.0, 6, sections=32)
    pin.apply_translation([0, 0, 5])
    asm = mesh_assembly({"block": block, "pin": pin})
    tol = asm.tolerance()
    monkeypatch.setattr(
        "assemblykit.blocking.obstacles.layer_thickness", lambda *_: (1e-15, np.inf)
    )
    assert not BlockingCache.of(asm).obstacles.backout("pin", "block", tol).any()
    assert extended_arcs(asm, [1, 0, 0], ["pin"], ["block"], tol) == {("pin", "block")}
    assert extended_free(asm, ["pin"], [0, 0, 1], tol)


def test_interlocked_rings_have_no_removable_subassembly():
    asm = mesh_assembly({"r1": ring([0, 0, 0], "xy"), "r2": ring([1.25, 0, 0], "xz")})
    assert assembly_contacts(asm) == []
    g = blocking_graph(asm, "extended")
    assert g.removable() == []
    # without the interlock (second ring moved away) they separate
    apart = mesh_assembly({"r1": ring([0, 0, 0], "xy"), "r2": ring([5, 0, 0], "xz")})
    assert blocking_graph(apart, "extended").removable() != []


ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "src" / "assemblykit" / "examples" / "gearbox_demo" / "gearbox.yaml"


@pytest.mark.slow
def test_gearbox_pins_and_cover_lift_out_exactly():
    asm = shared_assembly(DEMO)
    tol = asm.tolerance()
    up = np.array([0.0, 0.0, 1.0])
    g = blocking_graph(asm, "extended")
    # the housing is not convex: Γ_e is exact at each region of Γ_t
    assert g.exact is not None
    dbg = g.dbg(up)
    for pin in ("pin_1", "pin_2", "pin_3", "pin_4"):
        assert not any(i == pin for i, _ in dbg.arcs), pin
        # sideways the pin runs into the cover's bore
        assert not extended_free(asm, [pin], [1.0, 0.0, 0.0], tol)
        found = can_extract(asm, [pin])
        assert found is not None and any(np.allclose(d, up) for d in found.directions)
    assert can_extract(asm, ["gear_a"]) is None  # inside the closed housing
    for region in g.regions()[:5]:
        assert region.dbg.arcs == extended_dbg(asm, region.direction, g.parts, tol).arcs


def test_asap_beam_parts_are_removable_along_exact_directions():
    asm = shared_assembly("asap_beam_assembly")
    tol = asm.tolerance()
    removals = removable_parts(asm)
    assert removals, "some beam part comes out by one translation"
    for removal in removals:
        for d in removal.directions[:2]:
            assert extended_free(asm, removal.parts, d, tol)


# a cube cage (outer half-size 2, cavity half-size 1) with one straight square tunnel of
# side 0.6 from the centre along the body diagonal, through the corner (2, 2, 2)
DIAGONAL = np.ones(3) / np.sqrt(3.0)


def tunnel_cage() -> trimesh.Trimesh:
    """One non-convex body: the shell minus the tunnel (manifold3d booleans)."""
    import manifold3d

    tunnel = manifold3d.Manifold.cube([0.6, 0.6, 5.0]).translate([-0.3, -0.3, 0.0])
    z = np.array([0.0, 0.0, 1.0])
    turn = trimesh.transformations.rotation_matrix(np.arccos(z @ DIAGONAL), np.cross(z, DIAGONAL))
    shell = manifold3d.Manifold.cube([4.0, 4.0, 4.0], True) - manifold3d.Manifold.cube(
        [2.0, 2.0, 2.0], True
    )
    mesh = (shell - tunnel.transform(turn[:3, :4])).to_mesh()
    return trimesh.Trimesh(mesh.vert_properties[:, :3], mesh.tri_verts)


def caged_cube() -> object:
    """The cage and a cube of side 0.3 floating at its centre: seen along the diagonal
    the cube is a regular hexagon of circumradius 0.3 √(2/3) = 0.245 (inradius 0.212),
    inside the tunnel's square of half-width 0.3; sideways it is 0.7 from every wall."""
    return mesh_assembly({"cage": tunnel_cage(), "cube": box([-0.15] * 3, [0.15] * 3)})


# Within the wall the tunnel is at least 1.2 long (from the cavity's corner, √3 from the
# centre, to the outer corner, 2√3, less the corners cut by the square's half-width): the
# hexagon drifts sideways by at most 2 (0.3 - 0.212) = 0.176 over it, tan θ < 0.147.
APERTURE = 0.15


def test_a_cube_leaves_a_one_piece_cage_only_through_its_diagonal_tunnel():
    asm = caged_cube()
    tol = asm.tolerance()
    assert assembly_contacts(asm) == []
    # hand-derived: free along the tunnel's axis, blocked 0.2 rad off it and along the axes
    assert extended_free(asm, ["cube"], DIAGONAL, tol)
    off = DIAGONAL + 0.2 * np.array([1.0, -1.0, 0.0]) / np.sqrt(2.0)
    assert not extended_free(asm, ["cube"], off, tol)
    for axis in np.vstack([np.eye(3), -np.eye(3)]):
        assert not extended_free(asm, ["cube"], axis, tol)
    free = exact_free_directions(asm, ["cube"], tol)
    assert free.complete and not free.tolerance_dependent and free.directions
    for d in free.directions:
        assert np.arccos(np.clip(d @ DIAGONAL, -1, 1)) < APERTURE
        assert extended_free(asm, ["cube"], d, tol)
    found = can_extract(asm, ["cube"])
    assert found is not None and not found.tolerance_dependent
    assert all(np.arccos(np.clip(d @ DIAGONAL, -1, 1)) < APERTURE for d in found.directions)


def test_blocks_found_along_several_directions_are_all_shown_by_faces_afterwards():
    # the caged cube is held along each axis by another wall of the cage: once the
    # projection test has found each block, faces alone show every one of them again
    # (not only the last found), and what faces show is always a block of Γ_e
    asm = caged_cube()
    tol = asm.tolerance()
    axes = np.vstack([np.eye(3), -np.eye(3)])
    for axis in axes:
        assert extended_arcs(asm, axis, ["cube"], ["cage"], tol) == {("cube", "cage")}
    for axis in axes:
        assert shown_arcs(asm, axis, ["cube"], ["cage"], tol) == {("cube", "cage")}, axis
    for d in [DIAGONAL, *np.random.default_rng(0).normal(size=(12, 3))]:
        shown = shown_arcs(asm, d, ["cube"], ["cage"], tol)
        assert shown <= extended_arcs(asm, d, ["cube"], ["cage"], tol), d
    assert shown_arcs(asm, DIAGONAL, ["cube"], ["cage"], tol) == set()


def test_pairs_known_to_block_are_arcs_and_the_others_are_still_tested():
    # the arcs along a direction are the same whether the faces kept for each pair are
    # asked first, the pairs they show are given as known, or no pair is known at all
    asm = caged_cube()
    tol = asm.tolerance()
    for d in [*np.vstack([np.eye(3), -np.eye(3)]), DIAGONAL]:
        arcs = extended_arcs(asm, d, ["cube", "cage"], ["cube", "cage"], tol)
        shown = shown_arcs(asm, d, ["cube", "cage"], ["cube", "cage"], tol)
        assert shown <= arcs
        for known in (shown, set()):
            given = extended_arcs(asm, d, ["cube", "cage"], ["cube", "cage"], tol, known=known)
            assert given == arcs, (d, known)
    # along the diagonal the cube leaves its cage: nothing known, nothing found
    assert extended_arcs(asm, DIAGONAL, ["cube"], ["cage"], tol, known=set()) == set()


def test_triangle_cones_of_a_face_above_a_face():
    # the unit triangle at z = 0 swept upwards meets the same triangle at z = 1 (shifted
    # by 0.1 in x): the cone is spanned by the nine differences, all with z = 1
    tri = np.array([[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]])
    normals, valid = triangle_cones(tri, tri + np.array([0.1, 0.0, 1.0]), None, None, tol=DEFAULT)
    assert valid.all()
    inside = np.all(normals[0] @ np.array([0.1, 0.0, 1.0]) >= 0)
    assert inside and np.any(normals[0] @ np.array([0.0, 0.0, -1.0]) < 0)
    # (2, 0, 1) is a difference only at a vertex: on the boundary, not inside (open cone)
    assert not np.all(normals[0][np.linalg.norm(normals[0], axis=1) > 0] @ [2.0, 0, 1] > 0)
    # coplanar faces (in contact) have no cone with an interior
    _, flat = triangle_cones(tri, tri + np.array([0.5, 0.5, 0.0]), None, None, tol=DEFAULT)
    assert not flat.any()


def test_repeated_cones_give_the_same_blocked_set():
    """Cones repeated with their rows scaled and reordered are one cone: the union built
    from the repeats equals the union of the distinct cones, and holds as many of them."""
    rng = np.random.default_rng(3)
    cones = rng.normal(size=(5, 3, 3))
    repeats = np.concatenate([cones, 2.5 * cones[:, ::-1], cones[:, [1, 0, 2]]])
    assert len(_distinct_cones(repeats)) == 5
    once, thrice = ChartSet.from_cones(cones), ChartSet.from_cones(repeats)
    for a, b in zip(once.regions, thrice.regions, strict=True):
        assert a.symmetric_difference(b).area <= 1e-12
    for d in rng.normal(size=(200, 3)):
        assert once.contains(d) == thrice.contains(d)


@pytest.mark.parametrize("example", ["gearbox_demo", "interlock.step", "key_in_steps"])
def test_one_blocker_each_tells_the_same_parts_apart(example):
    # with first_only every blocked part keeps one true arc, and no free part gets one:
    # along the coordinate axes and a tilted direction, compared with every arc
    from assemblykit.blocking.extended import extended_arcs

    found = sorted((Path(__file__).parents[2] / "src/assemblykit/examples").rglob(example))
    asm = load_assembly(found[0])
    tol = asm.tolerance()
    names = list(asm.names)
    for d in [*np.eye(3), *-np.eye(3), np.array([0.3, -0.5, 0.81])]:
        every = extended_arcs(asm, d, names, names, tol)
        some = extended_arcs(asm, d, names, names, tol, first_only=True)
        assert some <= every
        assert {a for a, _ in some} == {a for a, _ in every}


@pytest.mark.parametrize("seed", range(4))
def test_a_drawer_slides_along_its_rails_in_any_frame(seed):
    # a drawer on a floor between two rails under a lid, the whole turned at random:
    # along the rails it slides out (rounding of the turn must not tip the graze into a
    # block), a hundredth of a radian into the floor or across the rails it is blocked
    from scipy.spatial.transform import Rotation

    turn = Rotation.random(random_state=seed).as_matrix()
    frame = np.eye(4)
    frame[:3, :3] = turn
    boxes = {
        "floor": ((-5, -5, -1), (5, 5, 0)),
        "left": ((-3, -5, 0), (-2, 5, 3)),
        "right": ((2, -5, 0), (3, 5, 3)),
        "lid": ((-3, -5, 3), (3, 5, 4)),
        "drawer": ((-2, -2, 0), (2, 2, 3)),
    }
    meshes = {}
    for name, (lo, hi) in boxes.items():
        mesh = trimesh.creation.box(bounds=np.array([lo, hi], dtype=float))
        meshes[name] = mesh.apply_transform(frame)
    assembly = mesh_assembly(meshes)
    tol = assembly.tolerance()
    along = turn @ [0.0, 1.0, 0.0]
    assert extended_free(assembly, ["drawer"], along, tol)
    assert extended_free(assembly, ["drawer"], -along, tol)
    for blocked in ([0.0, 1.0, -0.01], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]):
        d = turn @ np.asarray(blocked)
        assert not extended_free(assembly, ["drawer"], d / np.linalg.norm(d), tol)
    # independently: the drawer swept 20 along the rails shares no volume with the rest
    corners = meshes["drawer"].vertices
    swept = manifold3d.Manifold.hull_points(np.vstack([corners, corners + 20 * along]))
    for name in ("floor", "left", "right", "lid"):
        assert (swept ^ solid(meshes[name])).volume() < 1e-6, name


def test_extended_terms_and_their_exactness_are_dispatched_on_the_kind_of_assembly():
    tol = Tolerance(scale=2.0)
    boxes = mesh_assembly({"low": box([0, 0, 0], [1, 1, 1]), "high": box([0, 0, 1], [1, 1, 2])})
    terms = assembly_extended_terms(boxes, tol)
    assert [(t.moving, t.blocker) for t in terms] == [
        (t.moving, t.blocker) for t in extended_terms(boxes, tol)
    ]
    assert exact_extended(boxes, boxes.names)
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    # an L is not convex: its Γ_e in the plane is exact all the same
    ell = np.array([[1, 0], [3, 0], [3, 2], [2, 2], [2, 1], [1, 1]], dtype=float)
    drawn = PolygonAssembly({"square": square, "ell": ell})
    assert exact_extended(drawn, drawn.names)
    assert {(t.moving, t.blocker) for t in assembly_extended_terms(drawn, tol)} == {
        ("square", "ell"),
        ("ell", "square"),
    }
    with pytest.raises(TypeError, match="no extended translations for a str"):
        exact_extended("neither", [])
