"""COMPAS JSON documents written by hand for the tests: boxes as COMPAS meshes and
blocks (docs/geometry.md, "Loaders and their conventions")."""

from __future__ import annotations

from collections.abc import Sequence

BOX_FACES = {
    "0": [0, 3, 2, 1],
    "1": [4, 5, 6, 7],
    "2": [0, 1, 5, 4],
    "3": [1, 2, 6, 5],
    "4": [2, 3, 7, 6],
    "5": [3, 0, 4, 7],
}
"""The faces of :func:`box_mesh`, outward."""


def box_mesh(low: Sequence[float], high: Sequence[float]) -> dict:
    """A COMPAS mesh (``vertex``, ``face``): the box between ``low`` and ``high``, its
    lower face's corners first, counter-clockwise seen from above."""
    corners = [(x, y, z) for z in (0, 1) for x, y in ((0, 0), (1, 0), (1, 1), (0, 1))]
    vertex = {
        str(i): {axis: (high if c[k] else low)[k] for k, axis in enumerate("xyz")}
        for i, c in enumerate(corners)
    }
    return {"vertex": vertex, "face": BOX_FACES}


def block(low: Sequence[float], high: Sequence[float]) -> dict:
    """A COMPAS 2 block: :func:`box_mesh` as ``compas_assembly`` writes it."""
    return {"dtype": "compas_assembly.datastructures/Block", "data": box_mesh(low, high)}
