"""Closed meshes split into sheets where they meet themselves along an edge
(geometry/nonmanifold.py), on meshes whose shared edges are known by hand."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from assemblykit.geometry.nonmanifold import split_touching


def merged(*meshes: trimesh.Trimesh) -> trimesh.Trimesh:
    """One mesh of ``meshes``, their coincident vertices merged."""
    joined = trimesh.util.concatenate(meshes)
    return trimesh.Trimesh(joined.vertices, joined.faces, process=True)


def cube(corner: tuple[float, float, float]) -> trimesh.Trimesh:
    return trimesh.creation.box(bounds=[corner, np.add(corner, 1.0)])


def edges_shared(mesh: trimesh.Trimesh) -> list[int]:
    """How many triangles share each edge, sorted."""
    _, counts = np.unique(mesh.edges_sorted, axis=0, return_counts=True)
    return sorted(set(counts.tolist()))


@pytest.mark.parametrize(
    ("corners", "touching"),
    [
        # two cubes meeting along the edge x = y = 1: 4 triangles there
        ([(0, 0, 0), (1, 1, 0)], 1),
        # three cubes along a diagonal staircase: two such edges
        ([(0, 0, 0), (1, 1, 0), (2, 2, 0)], 2),
        # four cubes round the edge x = y = 1, two of them (diagonal) meeting there
        # with the other two missing: the same as the first, turned
        ([(1, 0, 0), (0, 1, 0)], 1),
        # two cubes meeting at a corner only: no edge is over-shared, a vertex is
        ([(0, 0, 0), (1, 1, 1)], 0),
    ],
)
def test_cubes_meeting_along_edges_become_closed_sheets(corners, touching):
    mesh = merged(*(cube(c) for c in corners))
    _, counts = np.unique(mesh.edges_sorted, axis=0, return_counts=True)
    assert int(np.count_nonzero(counts == 4)) == touching
    split = split_touching(mesh)
    assert split is not None
    assert split.is_watertight and split.is_winding_consistent
    assert edges_shared(split) == [2]
    # the same triangles, in order, at the same places; the volume is the cubes'
    np.testing.assert_array_equal(split.triangles, mesh.triangles)
    assert split.volume == pytest.approx(len(corners))
    assert len(split.vertices) == 8 * len(corners)


def test_an_open_mesh_is_not_split():
    mesh = merged(cube((0, 0, 0)), cube((1, 1, 0)))
    mesh.update_faces(np.arange(1, len(mesh.faces)))
    assert split_touching(mesh) is None


def test_a_closed_two_manifold_mesh_keeps_its_shape():
    mesh = trimesh.creation.icosphere(subdivisions=2)
    split = split_touching(mesh)
    assert split is not None
    np.testing.assert_array_equal(split.triangles, mesh.triangles)
    assert len(split.vertices) == len(mesh.vertices)
