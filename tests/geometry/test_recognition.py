"""Surface recognition on meshes: planes, shafts and holes, balls and sockets, cones."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
import trimesh

from assemblykit.features.primitives import Ball, Cone, Hole, Plane, Shaft, Socket
from assemblykit.geometry import recognition
from assemblykit.geometry.contacts import assembly_surfaces
from assemblykit.geometry.recognition import recognise, segment
from assemblykit.tolerance import Tolerance
from datasets import dataset, shared_assembly

TOL = Tolerance(scale=10.0).for_mesh()


def curved(mesh: trimesh.Trimesh):
    return [s for s in recognise(mesh, TOL) if s.kind != "plane"]


def test_box_has_six_planes_with_outward_normals_and_no_curved_surface():
    surfaces = recognise(trimesh.creation.box(extents=[2, 2, 2]), TOL)
    assert [s.kind for s in surfaces] == ["plane"] * 6
    for s in surfaces:
        assert s.area == pytest.approx(4.0)
        assert s.axis @ s.point == pytest.approx(1.0)  # outward: the plane is 1 from the centre


def test_coplanar_triangles_merge_into_one_group():
    seg = segment(
        *(np.asarray(a) for a in (trimesh.creation.box().vertices, trimesh.creation.box().faces)),
        TOL,
    )
    assert len(seg.normal) == 6 and seg.flat.all() and not seg.curved.any()


def test_shaft_axis_radius_and_feature():
    mesh = trimesh.creation.cylinder(radius=1.5, height=4.0, sections=64)
    mesh.apply_translation([1, 2, 3])
    (shaft,) = curved(mesh)
    assert shaft.kind == "cylinder" and shaft.convex
    assert shaft.radius == pytest.approx(1.5, abs=1e-9)
    assert abs(shaft.axis @ [0, 0, 1]) == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(shaft.point[:2], [1, 2], atol=1e-9)
    assert shaft.extent == pytest.approx((0.0, 4.0))
    feature = shaft.feature()
    assert isinstance(feature, Shaft) and feature.radius == pytest.approx(1.5, abs=1e-9)
    assert sum(isinstance(s.feature(), Plane) for s in recognise(mesh, TOL)) == 2


def test_hole_in_a_plate_is_concave():
    cutter = trimesh.creation.cylinder(radius=1.0, height=5.0, sections=48)
    plate = trimesh.creation.box(extents=[4, 4, 2]).difference(cutter, engine="manifold")
    (hole,) = curved(plate)
    assert not hole.convex and isinstance(hole.feature(), Hole)
    assert hole.radius == pytest.approx(1.0, abs=1e-6)


def test_ball_and_socket():
    ball = trimesh.creation.icosphere(subdivisions=3, radius=2.0)
    (surface,) = curved(ball)
    assert surface.kind == "sphere" and surface.convex
    assert surface.radius == pytest.approx(2.0, abs=1e-9)
    assert isinstance(surface.feature(), Ball)
    socket = trimesh.creation.box(extents=[6, 6, 6]).difference(ball, engine="manifold")
    (inside,) = curved(socket)
    assert not inside.convex and isinstance(inside.feature(), Socket)


def test_cone_apex_axis_and_half_angle():
    mesh = trimesh.creation.cone(radius=1.0, height=2.0, sections=64)
    (cone,) = curved(mesh)
    assert cone.kind == "cone" and cone.convex
    assert cone.half_angle == pytest.approx(np.arctan(0.5), abs=1e-9)
    np.testing.assert_allclose(cone.point, [0, 0, 2], atol=1e-9)
    np.testing.assert_allclose(cone.axis, [0, 0, -1], atol=1e-9)
    assert isinstance(cone.feature(), Cone)


def rounded_box(radius: float) -> trimesh.Trimesh:
    """The hull of eight spheres: a 1 x 2 x 0.5 box core with every edge rounded to
    ``radius`` (cylinders) and every corner a sphere octant."""
    import manifold3d

    spheres = [
        manifold3d.Manifold.sphere(radius, 32).translate((x, y, z))
        for x in (0.0, 1.0)
        for y in (0.0, 2.0)
        for z in (0.0, 0.5)
    ]
    mesh = manifold3d.Manifold.batch_hull(spheres).to_mesh64()
    return trimesh.Trimesh(np.asarray(mesh.vert_properties)[:, :3], np.asarray(mesh.tri_verts))


def test_rounded_edges_and_corners_are_split_into_cylinders_spheres_and_planes():
    # every face joins its neighbours smoothly, so the whole box is one smooth region
    surfaces = recognise(rounded_box(0.1), Tolerance(scale=2.6).for_mesh())
    cylinders = [s for s in surfaces if s.kind == "cylinder"]
    spheres = [s for s in surfaces if s.kind == "sphere"]
    planes = [s for s in surfaces if s.kind == "plane"]
    assert len(cylinders) == 12 and len(spheres) == 8 and len(planes) == 6
    for s in cylinders + spheres:
        assert s.radius == pytest.approx(0.1, abs=1e-6)
        assert s.convex
    # four rounded edges along each axis; corners centred on the spheres' centres
    axes = sorted(int(np.argmax(np.abs(s.axis))) for s in cylinders)
    assert axes == [0] * 4 + [1] * 4 + [2] * 4
    centres = {tuple(np.round(s.point, 6) + 0.0) for s in spheres}
    assert centres == {(x, y, z) for x in (0.0, 1.0) for y in (0.0, 2.0) for z in (0.0, 0.5)}
    assert sorted(round(s.area, 6) for s in planes) == [0.5, 0.5, 1.0, 1.0, 2.0, 2.0]
    assert isinstance(cylinders[0].feature(), Shaft) and isinstance(spheres[0].feature(), Ball)


def test_asap_beam_fillets_are_found():

    beam = shared_assembly("asap_beam_assembly")
    surfaces = assembly_surfaces(beam, "0")
    cylinders = [s for s in surfaces if s.kind == "cylinder"]
    spheres = [s for s in surfaces if s.kind == "sphere"]
    # the edges are rounded to 0.0762 (0.03 inch, in centimetres), outward
    assert len(cylinders) >= 40 and len(spheres) >= 8
    for s in cylinders + spheres:
        assert s.radius == pytest.approx(0.0762, abs=2e-3)
        assert s.convex


def test_groups_regrouped_after_a_bent_one_are_measured_as_if_all_were_measured_again(
    monkeypatch: pytest.MonkeyPatch,
):
    """On the ASAP beam's first part, 672 triangles sit in groups that are not flat and
    fall back to their strict groups; only those are measured again, and every group's
    plane, point, area, bounds, order and deviation equal measuring all groups anew."""
    from assemblykit.io.assembly import load_assembly

    bent_counts = []
    regrouped = recognition._regrouped

    def spy(*args: Any) -> Any:
        bent_counts.append(int(args[-1].sum()))
        return regrouped(*args)

    monkeypatch.setattr(recognition, "_regrouped", spy)
    beam = load_assembly(dataset("asap_beam_assembly"))
    mesh = beam["0"].mesh
    vertices, faces = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    seg = segment(vertices, faces, beam.tolerance())
    assert bent_counts == [672]
    again = recognition._group_planes(vertices[faces], seg.normals, seg.areas, seg.group)
    names = ("normal", "point", "area", "lo", "hi", "order", "start", "deviation")
    for name, value in zip(names, again, strict=True):
        np.testing.assert_array_equal(getattr(seg, name), value, err_msg=name)


def _sliver_and_triangle(lift: float) -> tuple[np.ndarray, np.ndarray]:
    """A sliver A B C (10 long, 0.02 wide) and a wide triangle A C D sharing A C, all in
    z = 0 but C lifted by ``lift`` (vertex noise)."""
    vertices = np.array([[0, 0, 0], [10, 0, 0], [10, 0.02, lift], [0, 10, 0]], dtype=float)
    return vertices, np.array([[0, 1, 2], [0, 2, 3]])


def test_a_noisy_sliver_stays_in_its_face():
    # tolerance 1e-5; C lifted 5e-6 tilts the sliver's plane by 5e-6 / 0.02 = 2.5e-4 rad,
    # putting D 10 x 2.5e-4 = 2.5e-3 off it, while B lies 10 x 5e-7 = 5e-6 off the wide
    # triangle's plane z = 5e-7 x: one flat face, as all four points are within 1e-5 of
    # a plane; the strict test (both ways) splits it
    vertices, faces = _sliver_and_triangle(5e-6)
    tol = Tolerance(scale=10.0, rel_length=1e-6)
    seg = segment(vertices, faces, tol)
    assert seg.group[0] == seg.group[1] and seg.flat.all()
    assert seg.deviation[0] <= 5e-6
    strict = segment(vertices, faces, tol, strict=True)
    assert strict.group[0] != strict.group[1]


def test_a_sliver_lifted_beyond_the_tolerance_is_its_own_face():
    # C lifted 2e-4: B lies 10 x 2e-5 = 2e-4 off the wide triangle's plane
    vertices, faces = _sliver_and_triangle(2e-4)
    seg = segment(vertices, faces, Tolerance(scale=10.0, rel_length=1e-6))
    assert seg.group[0] != seg.group[1]


def test_points_within_the_tolerance_of_a_plane_are_never_a_huge_cylinder():
    # a flat disc of 32 fan triangles with vertex noise 1e-9: a cylinder of enormous
    # radius fits it within the tolerance, but it is a plane
    angles = np.linspace(0, 2 * np.pi, 33)[:-1]
    rim = np.column_stack([np.cos(angles), np.sin(angles), 1e-9 * np.sin(5 * angles)])
    vertices = np.vstack([[0, 0, 0], rim])
    faces = np.array([[0, 1 + k, 1 + (k + 1) % 32] for k in range(32)])
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    from assemblykit.geometry.recognition import fit_surface

    tri = mesh.triangles
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normals = cross / np.linalg.norm(cross, axis=1)[:, None]
    areas = np.linalg.norm(cross, axis=1) / 2
    tol = Tolerance(scale=2.0).for_mesh()
    found = fit_surface(vertices, faces, normals, areas, tol, np.arange(32), ("cylinder",))
    assert found is None
