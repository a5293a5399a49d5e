"""The part of a surface of revolution two parts really touch (geometry/curved.py): arcs
of azimuths, the normals generating a patch's normal cone, on hand-made parts."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from assemblykit.geometry.contacts import assembly_contacts, assembly_surfaces
from assemblykit.geometry.curved import (
    arc_angles,
    cone_generators,
    covered_arcs,
    generating_arc,
    intersect_arcs,
    revolution_normals,
)
from assemblykit.io.assembly import load_assembly
from assemblykit.tolerance import Tolerance
from curved_parts import BALL_JOINT, ball_in_closed_socket, rod_in_groove, shaft_in_hole

PI = math.pi
TOL = Tolerance()


def _rows(vectors: np.ndarray) -> set[tuple[float, ...]]:
    # to the mesh tolerance (1e-6 of the model size): recognised axes carry 1e-8 errors
    return {tuple(float(x) for x in np.round(v, 6) + 0.0) for v in vectors}


def test_arcs_merge_across_azimuth_zero_and_intersect_to_the_common_part() -> None:
    # [5.5, 2 pi] and [0, 1] are one arc across azimuth 0, ending at 1 + 2 pi
    across = intersect_arcs(np.array([[0.0, 2 * PI]]), np.array([[5.5, 1.0 + 2 * PI]]), 1e-9)
    np.testing.assert_allclose(across, [[5.5, 1.0 + 2 * PI]])
    common = intersect_arcs(across, np.array([[0.5, 3.0]]), 1e-9)
    np.testing.assert_allclose(common, [[0.5, 1.0]])
    # arcs that only meet at an azimuth (a line on the surface) share nothing
    assert len(intersect_arcs(np.array([[0.0, 1.0]]), np.array([[1.0, 2.0]]), 1e-9)) == 0


def test_an_arc_is_sampled_at_its_ends_and_at_most_a_step_apart() -> None:
    np.testing.assert_allclose(arc_angles(np.array([[PI, 2 * PI]]), PI / 2), [PI, 1.5 * PI, 2 * PI])
    np.testing.assert_allclose(
        arc_angles(np.array([[0.0, 2 * PI]]), PI / 2), [0, PI / 2, PI, 1.5 * PI]
    )
    np.testing.assert_allclose(arc_angles(np.array([[0.2, 0.5]]), PI / 2), [0.2, 0.5])


def _blocked(normals: np.ndarray, directions: np.ndarray) -> np.ndarray:
    # the union of the open half-spaces n . d > 0: the directions some normal blocks
    return (directions @ normals.T > 1e-9).any(axis=1)


def test_pieces_of_a_cylinder_give_the_one_arc_that_generates_their_normals() -> None:
    # pieces within a quarter turn: the arc from the first start to the last end
    pieces = np.array([[0.1, 0.3], [0.5, 0.6], [1.0, 1.4]])
    np.testing.assert_allclose(generating_arc(pieces, 1e-9), [[0.1, 1.4]])
    # the largest gap, 0.4 to 5.0, runs across azimuth 0 the other way round: the arc
    # starts at 5.0 and ends at 0.4 + 2 pi
    np.testing.assert_allclose(
        generating_arc(np.array([[0.0, 0.4], [5.0, 5.5]]), 1e-9), [[5.0, 0.4 + 2 * PI]]
    )
    # no gap of a half turn: the whole plane of normals
    spread = np.array([[0.0, 0.2], [2.0, 2.2], [4.0, 4.2]])
    np.testing.assert_allclose(generating_arc(spread, 1e-9), [[0.0, 2 * PI]])
    # a half-round groove keeps its half turn (the direction out of it stays free)
    np.testing.assert_allclose(generating_arc(np.array([[PI, 2 * PI]]), 1e-9), [[PI, 2 * PI]])


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.floats(0.0, 2 * PI - 0.02, allow_nan=False), st.floats(0.01, 1.5, allow_nan=False)
        ),
        min_size=1,
        max_size=6,
    )
)
def test_the_generating_arc_blocks_what_the_pieces_block(pieces) -> None:
    # the union of half-spaces of the pieces' normals (sampled finely, every 0.002 rad)
    # against that of the few normals of the one arc, on directions all round the axis
    arcs = intersect_arcs(
        np.array([[0.0, 2 * PI]]),
        np.array([[lo, min(lo + width, 2 * PI)] for lo, width in pieces]),
        1e-9,
    )
    axis = np.array([0.2, -0.3, 0.9]) / np.linalg.norm([0.2, -0.3, 0.9])
    fine = revolution_normals(axis, np.concatenate([np.arange(lo, hi, 0.002) for lo, hi in arcs]))
    few = revolution_normals(axis, arc_angles(generating_arc(arcs, 1e-9), PI / 2))
    assert len(few) <= 5
    rng = np.random.default_rng(len(pieces))
    directions = rng.normal(size=(400, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    # directions near the boundary of the blocked set (within the sampling's 0.002) aside
    margin = np.abs((directions @ fine.T).max(axis=1)) > 0.01
    assert margin.sum() > 300
    np.testing.assert_array_equal(
        _blocked(fine, directions)[margin], _blocked(few, directions)[margin]
    )


def test_the_triangles_of_a_half_cylinder_cover_half_a_turn() -> None:
    asm = rod_in_groove(through=True)
    (surface,) = [s for s in assembly_surfaces(asm, "block") if s.kind == "cylinder"]
    mesh = asm.parts["block"].mesh
    triangles = np.asarray(mesh.vertices)[np.asarray(mesh.faces)[surface.faces]]
    axis = np.array([0.0, 1.0, 0.0])
    arcs = covered_arcs(triangles, np.zeros(3), axis, 1e-9)
    # about +y the frame is e1 = y x x = -z, e2 = y x e1 = -x: the channel below z = 0
    # runs from azimuth -pi/2 (+x) through 0 (-z) to pi/2 (-x), i.e. [3 pi / 2, 5 pi / 2]
    np.testing.assert_allclose(arcs, [[1.5 * PI, 2.5 * PI]], atol=1e-9)


def test_a_rod_in_a_half_round_groove_touches_on_half_a_circle_of_normals() -> None:
    (contact,) = assembly_contacts(rod_in_groove(through=True))
    (patch,) = contact.curved
    assert patch.inner == "rod"
    # the rod's outward normals where the groove holds it: -x, -z, +x (ends and middle)
    assert _rows(patch.normal_cone()) == {(-1.0, 0.0, 0.0), (0.0, 0.0, -1.0), (1.0, 0.0, 0.0)}


def test_a_shaft_through_a_hole_keeps_the_whole_circle_of_normals() -> None:
    contact = next(c for c in assembly_contacts(shaft_in_hole()) if c.curved)
    (patch,) = contact.curved
    normals = patch.normal_cone()
    # four directions across the axis y, pairwise opposite: the whole circle
    assert len(normals) == 4
    np.testing.assert_allclose(normals[:, 1], 0.0, atol=1e-9)
    np.testing.assert_allclose(normals[:2], -normals[2:], atol=1e-9)
    assert abs(float(normals[0] @ normals[1])) < 1e-9


def test_cone_generators_are_the_extreme_rays_or_the_six_axes() -> None:
    corners = np.array([[1.0, 1.0, 1.0], [-1.0, 1.0, 1.0], [-1.0, -1.0, 1.0], [1.0, -1.0, 1.0]])
    inside = np.array([[0.0, 0.0, 1.0], [0.5, 0.2, 1.0], [0.0, 1.0, 1.0]])
    found = cone_generators(np.vstack([inside, corners]), TOL)
    assert _rows(found) == _rows(corners / math.sqrt(3.0))
    spanning = np.vstack([corners, -corners])
    assert _rows(cone_generators(spanning, TOL)) == _rows(np.vstack([np.eye(3), -np.eye(3)]))


def test_a_ball_in_a_closed_socket_is_held_by_every_direction() -> None:
    contact = next(c for c in assembly_contacts(ball_in_closed_socket()) if c.curved)
    (patch,) = contact.curved
    assert _rows(patch.normal_cone()) == _rows(np.vstack([np.eye(3), -np.eye(3)]))


def test_the_ball_joint_cup_is_generated_by_its_rim() -> None:
    (contact,) = assembly_contacts(load_assembly(BALL_JOINT / "ball_joint.yaml"))
    (patch,) = contact.curved
    normals = patch.normal_cone()
    # the cup is cut at z = -2 on the sphere of radius 10: its rim is the circle of
    # normals with z = -0.2, and every extreme ray of the cap lies on it
    assert len(normals) >= 8
    np.testing.assert_allclose(normals[:, 2], -0.2, atol=2e-3)
    np.testing.assert_allclose(np.linalg.norm(normals[:, :2], axis=1), math.sqrt(0.96), atol=2e-3)
    assert patch.points is not None and np.max(patch.points[:, 2]) <= -2.0 + 1e-6
