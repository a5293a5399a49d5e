"""Tessellations moved inside their exact solids (geometry/tessellation.py): a polygonal
hole becomes the circumscribed polygon, a shaft stays as it is, and the triangles of
holes, slots, female cones, sockets and tori lie on the material side of their exact
surfaces, within the sag of the tessellation."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from assemblykit.geometry.tessellation import inside_vertices
from assemblykit.model.surfaces import Surface

Z = np.array([0.0, 0.0, 1.0])
# points of each triangle sampled by barycentric coordinates (edges and inside)
_STEPS = 12
BARY = (
    np.array([(i, j, _STEPS - i - j) for i in range(_STEPS + 1) for j in range(_STEPS + 1 - i)])
    / _STEPS
)


def samples(vertices, faces) -> np.ndarray:
    """Points spread over every triangle ``faces`` of ``vertices``, edges included."""
    return np.einsum("bk,tkd->tbd", BARY, np.asarray(vertices)[faces]).reshape(-1, 3)


ORIGIN = np.zeros(3)


def across(points, point=ORIGIN, axis=Z) -> tuple[np.ndarray, np.ndarray]:
    """Distance along ``axis`` from ``point`` and distance from the axis."""
    rel = points - point
    along = rel @ axis
    return along, np.linalg.norm(rel - np.outer(along, axis), axis=1)


def polygon(centre, radius: float, count: int, phase: float = 0.0) -> np.ndarray:
    angles = phase + 2 * np.pi * np.arange(count) / count
    return np.column_stack(
        [centre[0] + radius * np.cos(angles), centre[1] + radius * np.sin(angles)]
    )


def plate_with_hole(outline: shapely.Polygon, height: float, half: float = 10.0):
    """A square plate (sides ``2 half``, ``height`` thick) around the hole ``outline``,
    extruded along z."""
    square = [(-half, -half), (half, -half), (half, half), (-half, half)]
    plate = shapely.Polygon(square, [outline.exterior.coords])
    mesh = trimesh.creation.extrude_polygon(plate, height)
    return np.asarray(mesh.vertices), np.asarray(mesh.faces, dtype=np.int64), mesh


def planes_of(mesh: trimesh.Trimesh, skip: np.ndarray) -> list[Surface]:
    """The triangles of ``mesh`` outside ``skip`` grouped into planes (by normal and offset)."""
    rest = np.setdiff1d(np.arange(len(mesh.faces)), skip)
    normals = mesh.face_normals[rest]
    offsets = np.einsum("ij,ij->i", normals, mesh.triangles_center[rest])
    keys = np.round(np.column_stack([normals, offsets]), 6)
    _, group = np.unique(keys, axis=0, return_inverse=True)
    planes = []
    for g in np.unique(group):
        faces = rest[group.ravel() == g]
        normal = mesh.face_normals[faces[0]]
        planes.append(Surface("plane", mesh.triangles_center[faces[0]], normal, faces, 0.0))
    return planes


def hole(faces, centre=(0.0, 0.0), radius: float = 5.0, convex: bool = False) -> Surface:
    return Surface(
        "cylinder",
        np.array([centre[0], centre[1], 0.0]),
        Z,
        np.asarray(faces, dtype=np.int64),
        0.0,
        radius=radius,
        convex=convex,
    )


def walls_on(mesh: trimesh.Trimesh, centre, radius: float) -> np.ndarray:
    """The vertical triangles of ``mesh`` whose three vertices lie on the circle."""
    corners = np.asarray(mesh.vertices)[mesh.faces]
    on = np.abs(np.linalg.norm(corners[..., :2] - centre, axis=2) - radius) <= 1e-9 * radius
    return np.flatnonzero(on.all(axis=1) & (np.abs(mesh.face_normals[:, 2]) < 1e-9))


def test_a_polygonal_hole_becomes_the_circumscribed_polygon():
    r, n = 5.0, 12
    vertices, faces, mesh = plate_with_hole(shapely.Polygon(polygon((0, 0), r, n)), 4.0)
    walls = walls_on(mesh, (0, 0), r)
    assert len(walls) == 2 * n
    surfaces = [hole(walls), *planes_of(mesh, walls)]
    moved = inside_vertices(vertices, faces, surfaces)
    assert moved.dtype == np.float64 and moved is not vertices
    rim = np.unique(faces[walls])
    np.testing.assert_allclose(
        np.linalg.norm(moved[rim, :2], axis=1), r / math.cos(math.pi / n), rtol=1e-14
    )
    # radially, in the top and bottom planes; every other vertex stays
    np.testing.assert_array_equal(moved[rim, 2], vertices[rim, 2])
    turn = moved[rim, 0] * vertices[rim, 1] - moved[rim, 1] * vertices[rim, 0]
    np.testing.assert_allclose(turn, 0.0, atol=1e-13)
    np.testing.assert_array_equal(np.delete(moved, rim, axis=0), np.delete(vertices, rim, axis=0))
    # the chords now touch the circle from outside, and the mesh is still the same
    # closed, outward solid, a little smaller
    assert across(samples(moved, faces[walls]))[1].min() >= r * (1 - 1e-14)
    after = trimesh.Trimesh(moved, faces, process=False)
    assert after.is_watertight and after.is_winding_consistent
    assert (
        0 < mesh.volume - after.volume < 4.0 * math.pi * r**2 * (1 / math.cos(math.pi / n) ** 2 - 1)
    )


def test_a_shaft_stays_as_it_is():
    shaft = trimesh.creation.cylinder(radius=5.0, height=10.0, sections=12)
    walls = np.flatnonzero(np.abs(shaft.face_normals[:, 2]) < 1e-9)
    ends = np.setdiff1d(np.arange(len(shaft.faces)), walls)
    surfaces = [
        hole(walls, convex=True),
        Surface("plane", np.array([0, 0, 5.0]), Z, ends[shaft.face_normals[ends, 2] > 0], 0.0),
        Surface("plane", np.array([0, 0, -5.0]), -Z, ends[shaft.face_normals[ends, 2] < 0], 0.0),
    ]
    moved = inside_vertices(np.asarray(shaft.vertices), np.asarray(shaft.faces), surfaces)
    np.testing.assert_array_equal(moved, shaft.vertices)


@settings(max_examples=30, deadline=None)
@given(
    radius=st.floats(0.01, 1000.0),
    count=st.integers(5, 120),
    phase=st.floats(0.0, 2 * math.pi),
    height=st.floats(0.1, 50.0),
)
def test_every_chord_of_a_moved_hole_lies_outside_its_circle(radius, count, phase, height):
    outline = shapely.Polygon(polygon((0, 0), radius, count, phase))
    vertices, faces, mesh = plate_with_hole(outline, height, 2 * radius)
    walls = walls_on(mesh, (0, 0), radius)
    assert len(walls) == 2 * count
    rim = np.unique(faces[walls])
    # the polygon's vertices lie on the circle (up to rounding): that radius is exact
    exact = float(np.linalg.norm(vertices[rim, :2], axis=1).max())
    moved = inside_vertices(vertices, faces, [hole(walls, radius=exact), *planes_of(mesh, walls)])
    ends = moved[faces[walls]]
    middles = (ends + np.roll(ends, 1, axis=1)) / 2
    assert across(middles.reshape(-1, 3))[1].min() >= exact * (1 - 1e-12)
    # and no further than the circumscribed polygon
    bound = exact / math.cos(math.pi / count)
    assert np.linalg.norm(moved[rim, :2], axis=1).max() <= bound * (1 + 1e-12)


def test_the_sides_of_a_slot_stay_flat_and_pin_their_ends():
    """A slot: two half circles joined by tangent flat sides. A vertex where a side meets
    a half circle would leave the side if it moved: it stays on the circle, and the
    half circle's other vertices go beyond its tangent."""
    r, n = 3.0, 8  # each half circle in 8 steps of 22.5 degrees
    right = polygon((5, 0), r, 2 * n, -math.pi / 2)[: n + 1]
    left = polygon((-5, 0), r, 2 * n, math.pi / 2)[: n + 1]
    vertices, faces, mesh = plate_with_hole(shapely.Polygon(np.vstack([right, left])), 4.0)
    walls = {c: walls_on(mesh, (c, 0), r) for c in (5.0, -5.0)}
    flat = np.concatenate(list(walls.values()))
    surfaces = [*(hole(w, (c, 0), r) for c, w in walls.items()), *planes_of(mesh, flat)]
    moved = inside_vertices(vertices, faces, surfaces)
    for plane in surfaces[2:]:
        ids = np.unique(faces[plane.faces])
        offsets = (moved[ids] - plane.point) @ plane.axis
        np.testing.assert_allclose(offsets, 0.0, atol=1e-12)
    for c, w in walls.items():
        rho = across(samples(moved, faces[w]), np.array([c, 0, 0]))[1]
        assert rho.min() >= r * (1 - 1e-14)
        # the ends stay on the circle; their neighbours go to r / cos(22.5 degrees)
        radii = np.sort(
            np.unique(np.round(across(moved[np.unique(faces[w])], np.array([c, 0, 0]))[1], 12))
        )
        np.testing.assert_allclose(radii[0], r, rtol=1e-14)
        np.testing.assert_allclose(radii[-1], r / math.cos(math.pi / n), rtol=1e-12)


def grid(point, rows: int, columns: int, closed_rows: bool = False):
    """A grid of ``rows`` x ``columns`` points ``point(i, j)`` (columns closed around),
    triangulated; with ``closed_rows`` the rows close around too."""
    vertices = np.array([point(i, j) for i in range(rows) for j in range(columns)], dtype=float)
    faces = []
    for i in range(rows if closed_rows else rows - 1):
        for j in range(columns):
            a, b = i * columns + j, i * columns + (j + 1) % columns
            c, d = ((i + 1) % rows) * columns + j, ((i + 1) % rows) * columns + (j + 1) % columns
            faces += [(a, b, d), (a, d, c)]
    return vertices, np.array(faces, dtype=np.int64)


def outward(vertices, faces, away) -> np.ndarray:
    """``faces`` wound so their normals point along ``away(centroid)``."""
    corners = vertices[faces]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    flip = np.einsum("ij,ij->i", normal, away(corners.mean(axis=1))) < 0
    return np.where(flip[:, None], faces[:, ::-1], faces)


@pytest.mark.parametrize("steps", [6, 24, 96])
def test_a_female_cone_lies_outside_the_cone(steps):
    half = math.radians(30)
    apex = np.array([1.0, 2.0, -3.0])

    def point(i, j):
        s = 2.0 + 6.0 * i / 4
        a = 2 * math.pi * j / steps
        return apex + s * np.array(
            [math.tan(half) * math.cos(a), math.tan(half) * math.sin(a), 1.0]
        )

    vertices, faces = grid(point, 5, steps)
    faces = outward(vertices, faces, lambda c: -(c - apex) + ((c - apex) @ Z)[:, None] * Z)
    cone = Surface("cone", apex, Z, np.arange(len(faces)), 0.0, half_angle=half, convex=False)
    moved = inside_vertices(vertices, faces, [cone])
    along, rho = across(samples(moved, faces), apex)
    normal_distance = (rho - along * math.tan(half)) * math.cos(half)
    assert normal_distance.min() >= -1e-12
    # within the sag of the arcs: s tan(half) (1 / cos(pi / steps) - 1) at most
    along, rho = across(moved, apex)
    assert np.all(rho <= along * math.tan(half) / math.cos(math.pi / steps) * (1 + 1e-12))


@pytest.mark.parametrize("steps", [8, 24, 64])
def test_a_socket_lies_outside_its_sphere(steps):
    centre, radius = np.array([0.5, -1.0, 2.0]), 4.0

    def point(i, j):
        polar = math.pi / 2 + (math.pi / 2 - 0.2) * i / (steps // 4)
        a = 2 * math.pi * j / steps
        return centre + radius * np.array(
            [math.sin(polar) * math.cos(a), math.sin(polar) * math.sin(a), math.cos(polar)]
        )

    vertices, faces = grid(point, steps // 4 + 1, steps)
    faces = outward(vertices, faces, lambda c: centre - c)
    sphere = Surface(
        "sphere", centre, None, np.arange(len(faces)), 0.0, radius=radius, convex=False
    )
    moved = inside_vertices(vertices, faces, [sphere])
    assert np.linalg.norm(samples(moved, faces) - centre, axis=1).min() >= radius * (1 - 1e-12)
    # no further than the sag of a cap of the triangles' size
    sag = radius * (1 / math.cos(2 * math.pi / steps) - 1)
    assert np.linalg.norm(moved - centre, axis=1).max() <= radius + sag


def test_a_spindle_torus_is_left_alone():
    """The band of a lemon (major radius 10 under the tube's 14: the tube crosses the
    axis) between heights -5 and 5, convex: its chords lie inside it, and reading its
    points from the tube's centre at their own azimuth (10 out, where the nearest centre
    is 10 out the other way) would send them far out."""
    major, tube = 10.0, 14.0

    def point(i, j):
        z = -5.0 + 10.0 * i / 8
        rho, u = math.sqrt(tube**2 - z**2) - major, 2 * math.pi * j / 24
        return np.array([rho * math.cos(u), rho * math.sin(u), z])

    vertices, faces = grid(point, 9, 24)
    faces = outward(vertices, faces, lambda c: np.column_stack([c[:, :2], np.zeros(len(c))]))
    lemon = torus_about_z(major, tube, len(faces), convex=True)
    np.testing.assert_array_equal(inside_vertices(vertices, faces, [lemon]), vertices)


def torus_about_z(major: float, tube: float, faces: int, convex: bool) -> Surface:
    """A torus about the z axis through the origin, on the first ``faces`` triangles."""
    return Surface(
        "torus",
        np.zeros(3),
        Z,
        np.arange(faces),
        0.0,
        radius=major,
        minor_radius=tube,
        convex=convex,
    )


@pytest.mark.parametrize("material", ["inside", "outside"])
@pytest.mark.parametrize("steps", [12, 48])
def test_a_torus_lies_on_its_material_side(material, steps):
    """A ring (material inside the tube: its inner side is concave about the axis) and a
    toroidal cavity (material outside the tube)."""
    major, tube = 5.0, 1.5

    def point(i, j):
        u, v = 2 * math.pi * i / steps, 2 * math.pi * j / (steps // 2)
        rho = major + tube * math.cos(v)
        return np.array([rho * math.cos(u), rho * math.sin(u), tube * math.sin(v)])

    vertices, faces = grid(point, steps, steps // 2, closed_rows=True)

    def from_tube(points):
        rho = np.linalg.norm(points[:, :2], axis=1)
        across = points[:, :2] / rho[:, None] * (rho - major)[:, None]
        return np.column_stack([across, points[:, 2]])

    side = 1.0 if material == "inside" else -1.0
    faces = outward(vertices, faces, lambda c: side * from_tube(c))
    torus = torus_about_z(major, tube, len(faces), convex=material == "inside")
    moved = inside_vertices(vertices, faces, [torus])
    distance = np.linalg.norm(from_tube(samples(moved, faces)), axis=1)
    if material == "inside":
        assert distance.max() <= tube * (1 + 1e-12)
        # the outer half is convex both ways: vertices whose triangles all lie beyond
        # the sag of an arc of azimuth outside the middle of the tube stay
        rho = np.linalg.norm(vertices[:, :2], axis=1)
        sag = (major + tube) * (1 - math.cos(math.pi / steps))
        low = np.full(len(vertices), np.inf)
        np.minimum.at(low, faces, rho[faces].min(axis=1, keepdims=True).repeat(3, axis=1))
        outer = low > major + sag
        assert outer.sum() >= steps
        np.testing.assert_array_equal(moved[outer], vertices[outer])
    else:
        assert distance.min() >= tube * (1 - 1e-12)
    assert trimesh.Trimesh(moved, faces, process=False).is_watertight
