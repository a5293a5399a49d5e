"""Γ_g: infinitesimal rigid motions, from the S⁵ arrangement and by linear programming
(Wilson & Latombe 1992, Fig. 5)."""

from __future__ import annotations

import numpy as np
from blocking_helpers import ContactAssembly, square

from assemblykit.blocking.graphs import blocking_graph
from assemblykit.blocking.rigid import RIGID_MAX_HYPERPLANES, contact_points, stops_every_twist
from assemblykit.geometry.contacts import Contact, PlanarPatch
from assemblykit.tolerance import Tolerance


def point(normal, at) -> PlanarPatch:
    """A point contact (a patch reduced to one vertex)."""
    return PlanarPatch(np.asarray(normal, float), np.asarray([at], float), 0.0)


def fig5_points() -> ContactAssembly:
    """Wilson & Latombe 1992, Fig. 5 with point contacts: a block wedged in the x-z plane (floor at
    x = 0.5, ceiling at x = 0.9, left wall at z = 0.9, right wall at z = 0.1) and held in
    y by a wall on each side at different x. Every translation is blocked; turning about
    y through (0.7, 0.5) with a little turn about z breaks all six contacts."""
    return ContactAssembly(
        ["block", "frame"],
        [
            Contact(
                "block",
                "frame",
                planar=(
                    point([0, 0, -1], [0.5, 0.5, 0.0]),
                    point([0, 0, 1], [0.9, 0.5, 1.0]),
                    point([-1, 0, 0], [0.0, 0.5, 0.9]),
                    point([1, 0, 0], [1.0, 0.5, 0.1]),
                    point([0, 1, 0], [0.2, 1.0, 0.5]),
                    point([0, -1, 0], [0.8, 0.0, 0.5]),
                ),
            )
        ],
    )


def wedged_block() -> ContactAssembly:
    """A unit block (x, z in [0, 1]) held by small patches: floor near x = 0.5, ceiling
    near x = 0.9, left wall near z = 0.9, right wall near z = 0.1, and the two y walls.
    Every translation is blocked; a rotation about y through (0.7, 0.5) frees it."""
    h = 0.05
    patches = (
        square([0, 0, -1], (0.5, 0.5, 0.0), h),
        square([0, 0, 1], (0.9, 0.5, 1.0), h),
        square([-1, 0, 0], (0.0, 0.5, 0.9), h),
        square([1, 0, 0], (1.0, 0.5, 0.1), h),
        square([0, 1, 0], (0.5, 1.0, 0.5), 0.4),
        square([0, -1, 0], (0.5, 0.0, 0.5), 0.4),
    )
    return ContactAssembly(["block", "frame"], [Contact("block", "frame", planar=patches)])


def test_rotation_frees_what_translation_cannot():
    asm = wedged_block()
    translations = blocking_graph(asm, "infinitesimal")
    assert frozenset({"block"}) not in {r.parts for r in translations.removable()}
    rigid = blocking_graph(asm, "rigid")
    removal = {r.parts: r for r in rigid.removable()}[frozenset({"block"})]
    (twist,) = removal.directions
    omega, v = twist[:3], twist[3:]
    assert abs(np.linalg.norm(twist) - 1) < 1e-12
    assert np.linalg.norm(omega) > 0.1
    assert abs(omega[0]) < 1e-9 and abs(omega[2]) < 1e-9  # about the y axis
    # the twist moves every contact point of the block outward or tangentially
    pts, normals = rigid.constraints({"block"})
    speeds = np.einsum("ij,ij->i", normals, v + np.cross(omega, pts))
    assert np.all(speeds <= 1e-9) and np.any(speeds < -1e-6)
    assert rigid.dbg(twist).is_free({"block"})


def test_rotation_is_blocked_with_a_full_floor_and_ceiling():
    asm = wedged_block()
    contact = asm.given[0]
    full = Contact(
        "block",
        "frame",
        planar=(
            *contact.planar,
            square([0, 0, -1], (0.5, 0.5, 0.0), 0.45),
            square([0, 0, 1], (0.5, 0.5, 1.0), 0.45),
        ),
    )
    rigid = blocking_graph(ContactAssembly(["block", "frame"], [full]), "rigid")
    assert rigid.free_twist({"block"}) is None
    assert rigid.removable() == []
    assert rigid.to_dict()["removable"] == []
    assert not rigid.frees_some() and rigid.held_together()
    # with the floor and ceiling of the first, a turn frees it
    assert blocking_graph(asm, "rigid").frees_some()
    assert not blocking_graph(asm, "rigid").held_together()


def test_fig5_is_freed_by_a_rotation_in_a_cell_of_the_arrangement():
    asm = fig5_points()
    assert blocking_graph(asm, "infinitesimal").removable() == []
    rigid = blocking_graph(asm, "rigid")
    # no single part is freed by the linear program alone: the arrangement decides
    assert rigid.frees_some() == bool(rigid.removable()) is True
    result = rigid.to_dict()
    # the in-plane constraints (omega_y, v_x, v_z) and the y walls (omega_x, omega_z,
    # v_y) are independent: 4 generic planes of R^3 (14 cells) times 2 of R^3 (4 cells)
    assert result["regions"] == {"vertices": None, "edges": None, "faces": 56}
    assert result["arrangement"] == "built: 6 hyperplanes, 56 regions"
    assert len(rigid.regions()) == 56
    assert {r.dimension for r in rigid.regions()} == {5}
    removal = {r.parts: r for r in rigid.removable()}[frozenset({"block"})]
    (twist,) = removal.directions  # one cell: all six contacts break
    omega, v = twist[:3], twist[3:]
    assert abs(np.linalg.norm(twist) - 1) < 1e-12
    assert abs(omega[1]) > 0.1
    pts, normals = rigid.constraints({"block"})
    speeds = np.einsum("ij,ij->i", normals, v + np.cross(omega, pts))
    assert np.all(speeds < -1e-6)
    assert rigid.dbg(twist).is_free({"block"})


def test_block_on_a_table_lifts_off_in_one_of_14_cells():
    # the four corners give hyperplanes (p_y, -p_x, 0; 0, 0, 1) spanning a 3-space of
    # twists, in general position there: 2 (1 + 3 + 3) = 14 cells
    table = Contact("block", "table", planar=(square([0, 0, -1], (0.0, 0.0, 0.0), 0.5),))
    rigid = blocking_graph(ContactAssembly(["block", "table"], [table]), "rigid")
    regions = rigid.regions()
    assert len(regions) == 14
    free = {r.parts: r.directions for r in rigid.removable()}
    assert set(free) == {frozenset({"block"}), frozenset({"table"})}
    # one cell each: the block lifts straight up, the table drops (no sliding part)
    assert np.allclose(free[frozenset({"block"})], [[0, 0, 0, 0, 0, 1]], atol=1e-9)
    assert np.allclose(free[frozenset({"table"})], [[0, 0, 0, 0, 0, -1]], atol=1e-9)
    # in the other 12 cells some corner sinks in while another lifts: both arcs
    both = [r for r in regions if r.dbg.arcs == {("block", "table"), ("table", "block")}]
    assert len(both) == 12


def test_beyond_the_limit_the_lp_witness_decides():
    rigid = blocking_graph(wedged_block(), "rigid")
    result = rigid.to_dict()
    assert len(rigid.arrangement.normals) > RIGID_MAX_HYPERPLANES
    assert result["arrangement"] == (
        f"not built: {len(rigid.arrangement.normals)} hyperplanes > {RIGID_MAX_HYPERPLANES}"
    )
    assert result["regions"]["faces"] is None
    assert rigid.regions() == []
    assert [r["parts"] for r in result["removable"]] == [["block"], ["frame"]]


def boxed(inner: str, outer: str, origin, faces: int = 6) -> Contact:
    """``inner``, a unit cube at ``origin``, touching ``outer`` on its first ``faces``
    faces (+x, -x, +y, -y, +z, -z), each whole."""
    normals = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
    centre = np.asarray(origin, dtype=float) + 0.5
    patches = tuple(square(n, centre + 0.5 * np.asarray(n), 0.5) for n in normals[:faces])
    return Contact(inner, outer, planar=patches)


def test_a_cube_touched_on_all_six_faces_stops_every_twist_and_on_five_does_not():
    for faces, stopped in ((6, True), (5, False)):
        p, n = contact_points(boxed("cube", "box", (0, 0, 0), faces))
        assert stops_every_twist(p, n, Tolerance()) is stopped


def test_parts_held_together_pair_by_pair_free_no_subassembly():
    # a cube boxed in a second, itself boxed in a third (each pair touching on every
    # face): the pairs join all three, so no twist moves any subassembly, which the
    # linear program of each subassembly confirms on its own
    contacts = [boxed("a", "b", (0, 0, 0)), boxed("b", "c", (5, 0, 0))]
    rigid = blocking_graph(ContactAssembly(["a", "b", "c"], contacts), "rigid")
    assert rigid.held_together() and not rigid.frees_some()
    for subset in ({"a"}, {"b"}, {"c"}, {"a", "b"}, {"b", "c"}, {"a", "c"}):
        assert rigid.free_twist(subset) is None
    # with one face of the second pair gone, "c" no longer holds "b": the pair b-c
    # lifts apart, which both the certificate and the search see
    opened = [boxed("a", "b", (0, 0, 0)), boxed("b", "c", (5, 0, 0), faces=5)]
    rigid = blocking_graph(ContactAssembly(["a", "b", "c"], opened), "rigid")
    assert not rigid.held_together() and rigid.frees_some()
    assert rigid.free_twist({"a", "b"}) is not None
