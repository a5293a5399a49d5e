"""Blocking terms of curved contacts from the normals of the patch really touched (seed
004, infinitesimal and extended translations): a rod in a half-round groove, the bundled
ball joint, and a full shaft and a full sphere that still block as before."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull, QhullError

from assemblykit.blocking.constraints import infinitesimal_terms, positively_spanning
from assemblykit.blocking.graphs import blocking_graph
from assemblykit.blocking.queries import can_extract, locally_free_directions
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.io.assembly import load_assembly
from curved_parts import (
    BALL_JOINT,
    DISTANCES,
    ball_in_closed_socket,
    rod_in_groove,
    shaft_in_hole,
    swept_overlaps,
)

RNG = np.random.default_rng(4)
# directions of the plane x = 0 at every 10 degrees, and random ones elsewhere
IN_PLANE = np.column_stack(
    [
        np.zeros(36),
        np.cos(np.radians(np.arange(0, 360, 10))),
        np.sin(np.radians(np.arange(0, 360, 10))),
    ]
)
SPREAD = RNG.normal(size=(200, 3))
DIRECTIONS = np.vstack([IN_PLANE, SPREAD / np.linalg.norm(SPREAD, axis=1, keepdims=True)])


def _free(ndbg, part: str, directions: np.ndarray) -> np.ndarray:
    return np.array([any(part in s for s in ndbg.dbg(d).free_subassemblies()) for d in directions])


def test_the_groove_lets_the_rod_out_along_the_closed_upper_half_circle_only() -> None:
    asm = rod_in_groove(through=True)
    ndbg = blocking_graph(asm, "infinitesimal")
    # the groove's normals into the block span the half circle -x, -z, +x, so d is free
    # iff d . n <= 0 for all of them: d_x = 0 and d_z >= 0 (the +z half of the plane
    # x = 0, with the axis directions +-y)
    expected = (np.abs(DIRECTIONS[:, 0]) < 1e-12) & (DIRECTIONS[:, 2] >= -1e-12)
    assert expected.sum() == 19
    np.testing.assert_array_equal(_free(ndbg, "rod", DIRECTIONS), expected)
    found = np.array(locally_free_directions(asm, ["rod"]))
    np.testing.assert_allclose(found[:, 0], 0.0, atol=1e-6)
    assert np.all(found[:, 2] >= -1e-6)
    assert {tuple(np.round(d, 6) + 0.0) for d in found} >= {(0.0, 1.0, 0.0), (0.0, -1.0, 0.0)}


def test_the_groove_terms_are_three_half_spaces_each_way() -> None:
    (contact,) = assembly_contacts(rod_in_groove(through=True))
    terms = infinitesimal_terms([contact])
    rows = {(t.moving, tuple(np.round(t.normals[0], 6) + 0.0)) for t in terms if t.moving == "rod"}
    assert rows == {("rod", (-1.0, 0.0, 0.0)), ("rod", (0.0, 0.0, -1.0)), ("rod", (1.0, 0.0, 0.0))}


def test_a_full_shaft_is_free_along_its_axis_only_and_a_full_sphere_nowhere() -> None:
    shaft = blocking_graph(shaft_in_hole(), "infinitesimal")
    expected = np.abs(np.abs(DIRECTIONS[:, 1]) - 1.0) < 1e-12
    assert expected.sum() == 2
    np.testing.assert_array_equal(_free(shaft, "rod", DIRECTIONS), expected)
    sphere = blocking_graph(ball_in_closed_socket(), "infinitesimal")
    assert not _free(sphere, "ball", DIRECTIONS).any()
    assert can_extract(ball_in_closed_socket(), ["ball"], "extended") is None


@pytest.mark.parametrize("motion", ["infinitesimal", "extended"])
def test_the_rod_lifts_out_of_a_closed_groove_straight_up(motion: str) -> None:
    asm = rod_in_groove(through=False)
    found = can_extract(asm, ["rod"], motion)
    assert found is not None
    # the closed ends hold it along y, the groove along -z and x: only +z is left
    for d in found.directions:
        np.testing.assert_allclose(d, [0.0, 0.0, 1.0], atol=1e-6)
    removable = {r.parts: r.directions for r in blocking_graph(asm, motion).removable()}
    assert frozenset({"rod"}) in removable
    volumes, touching = swept_overlaps(asm, "rod", found.directions[0], DISTANCES)
    assert np.all(volumes <= touching)
    # the same sweep sees the block along x: the check is not blind
    sideways, _ = swept_overlaps(asm, "rod", np.array([1.0, 0.0, 0.0]), DISTANCES[:6])
    assert sideways[-1] > 100 * touching


@pytest.mark.parametrize("motion", ["infinitesimal", "extended"])
def test_the_ball_joint_ball_lifts_out_of_its_cup(motion: str) -> None:
    asm = load_assembly(BALL_JOINT / "ball_joint.yaml")
    found = can_extract(asm, ["ball"], motion)
    assert found is not None
    up = found.directions[0]
    # the cup's rim is at 0.2 of the radius below the centre: the free cone is the cone
    # of half-angle asin(0.2) about +z, and the first direction examined is inside it
    assert up[2] >= np.sqrt(1.0 - 0.2**2) - 1e-3
    volumes, touching = swept_overlaps(asm, "ball", up, DISTANCES)
    assert np.all(volumes <= touching)
    down, _ = swept_overlaps(asm, "ball", -up, DISTANCES[:6])
    assert down[-1] > 100 * touching


AXES = np.vstack([np.eye(3), -np.eye(3)])


def test_the_six_axis_normals_positively_span_and_five_do_not() -> None:
    assert positively_spanning(AXES)
    assert not positively_spanning(AXES[:5])  # nothing stops a move along -z
    assert not positively_spanning(np.vstack([AXES[:2], AXES[3:5]]))  # all in a plane
    # a tetrahedron's outward normals positively span; three of them do not
    tetra = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], dtype=float)
    assert positively_spanning(tetra) and not positively_spanning(tetra[:3])


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(st.floats(0.05, np.pi - 0.05), st.floats(0, 2 * np.pi)), min_size=4, max_size=9
    )
)
def test_positive_spanning_is_the_origin_inside_the_normals_hull(angles) -> None:
    # independently: unit vectors positively span space exactly when the origin lies
    # inside their convex hull (every hull facet strictly on the far side of it)
    polar, azimuth = np.array(angles).T
    normals = np.column_stack(
        [np.sin(polar) * np.cos(azimuth), np.sin(polar) * np.sin(azimuth), np.cos(polar)]
    )
    try:
        hull = ConvexHull(normals)
    except QhullError:  # all in a plane: no hull, and no positive span either
        assert not positively_spanning(normals)
        return
    margin = float(hull.equations[:, 3].max())  # a . 0 + b for each facet, < 0 inside
    assume(abs(margin) > 1e-6)
    assert positively_spanning(normals) is (margin < 0)
