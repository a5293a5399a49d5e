"""Blocks whose equilibrium is computed by hand, shared by the stability tests: a cube
on a slope, an overhanging stack of cubes and a corbelled arch; and the slack program
written out independently of the model's own (:func:`whole_residuals`)."""

from __future__ import annotations

import math

import numpy as np
import trimesh

from assemblykit.model.assembly import Assembly, Part
from assemblykit.planning.stability import CONE_SIDES, EquilibriumModel, least_residuals


def box(extents: tuple[float, ...], low: tuple[float, ...]) -> trimesh.Trimesh:
    """An axis-aligned box with its lowest corner at ``low``."""
    mesh = trimesh.creation.box(extents=extents)
    mesh.apply_translation(np.asarray(low) + np.asarray(extents) / 2)
    return mesh


def block_on_slope(degrees: float) -> Assembly:
    """A unit cube resting on the top face of a slab tilted by ``degrees`` about y."""
    turn = trimesh.transformations.rotation_matrix(math.radians(degrees), [0, 1, 0])
    slab = trimesh.creation.box(extents=(4.0, 4.0, 1.0))
    slab.apply_transform(turn)
    cube = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
    cube.apply_transform(turn)
    cube.apply_translation(turn[:3, :3] @ [0.0, 0.0, 1.0])
    return Assembly([Part("slope", slab), Part("block", cube)])


def overhanging_stack(overhang: float) -> Assembly:
    """Three unit cubes stacked; the top one shifted by ``overhang`` along x."""
    return Assembly(
        [
            Part("bottom", box((1, 1, 1), (0, 0, 0))),
            Part("middle", box((1, 1, 1), (0, 0, 1))),
            Part("top", box((1, 1, 1), (overhang, 0, 2))),
        ]
    )


def corbels(keystone: bool) -> Assembly:
    """A ground slab, two unit pillars (x in [-2, -1] and [1, 2]) and on each a corbel
    reaching inwards past its pillar: with a keystone (x in [-0.2, 0.2]) between them
    the corbels are 1.4 long (centre 0.1 beyond the pillar's edge), without it they are
    1.8 long and lean on each other at x = 0."""
    inner, outer = (0.2, 1.6) if keystone else (0.0, 1.8)
    parts = [
        Part("ground", box((6, 1, 1), (-3, 0, -1))),
        Part("pillar_l", box((1, 1, 1), (-2, 0, 0))),
        Part("pillar_r", box((1, 1, 1), (1, 0, 0))),
        Part("corbel_l", box((outer - inner, 1, 1), (-outer, 0, 1))),
        Part("corbel_r", box((outer - inner, 1, 1), (inner, 0, 1))),
    ]
    if keystone:
        parts.append(Part("keystone", box((0.4, 1, 1), (-0.2, 0, 1))))
    return Assembly(parts)


def whole_residuals(
    model: EquilibriumModel, present: np.ndarray, fixed: np.ndarray
) -> dict[str, float]:
    """Per free part of a state, its largest scaled residual at the slack program's
    optimum, written out from the model's public arrays over every free part and every
    polygon vertex at once (the model solves it piece by piece, on corners)."""
    free = present & ~fixed
    rows = (6 * np.flatnonzero(free)[:, None] + np.arange(6)).ravel()
    points = present[model.point_parts[:, 0]] & present[model.point_parts[:, 1]]
    columns = np.flatnonzero(np.repeat(points, CONE_SIDES))
    matrix = (model.normal_part + model.friction * model.tangent_part)[rows][:, columns]
    residual = np.abs(least_residuals(matrix.tocsc(), -model.load[rows])).reshape(-1, 6)
    return dict(zip(np.array(model.names)[free], residual.max(axis=1), strict=True))
