"""The part of a surface of revolution two parts really touch (geometry/curved.py): arcs
of azimuths, the normals generating a patch's normal cone, on hand-made parts."""

from __future__ import annotations

import math

import numpy as np

from assemblykit.geometry.contacts import assembly_contacts, assembly_surfaces
from assemblykit.geometry.curved import (
    arc_angles,
    cone_generators,
    covered_arcs,
    intersect_arcs,
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
