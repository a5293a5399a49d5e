"""Solids built from primitives and moved rigidly: boxes and cylinders combined by
manifold3d booleans (union of the added primitives minus the union of the cut ones),
and copies of meshes placed by a pose (``p_world = L @ p_body``: docs/architecture.md,
"Conventions").
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import trimesh
from numpy.typing import NDArray

from assemblykit.errors import GeometryError, SchemaError
from assemblykit.geometry.booleans import manifold3d
from assemblykit.geometry.interference import solid

Vector3 = tuple[float, float, float]

#: Sections of generated cylinders: enough that a facet's sagitta is under 0.5 % of r.
CYLINDER_SECTIONS = 48


@dataclass(frozen=True)
class Box:
    """An axis-aligned box given by its ``min`` and ``max`` corners."""

    min: Vector3
    max: Vector3


@dataclass(frozen=True)
class Cylinder:
    """A cylinder: base centre ``point``, ``axis`` direction, ``radius`` and ``height``."""

    point: Vector3
    axis: Vector3
    radius: float
    height: float


Primitive = Box | Cylinder


def placed(mesh: trimesh.Trimesh, pose: NDArray[np.float64]) -> trimesh.Trimesh:
    """A copy of ``mesh`` transformed by ``pose``."""
    moved = mesh.copy()
    moved.apply_transform(pose)
    return moved


def primitive_solid(spec: Primitive) -> manifold3d.Manifold:
    """The manifold3d solid of one primitive; :class:`SchemaError` for a box with
    ``max <= min`` on some axis or a zero cylinder axis."""
    if isinstance(spec, Box):
        lo, hi = np.asarray(spec.min, dtype=np.float64), np.asarray(spec.max, dtype=np.float64)
        if np.any(hi <= lo):
            raise SchemaError("a box needs max > min on every axis")
        return solid(trimesh.creation.box(bounds=np.stack([lo, hi])))
    axis = np.asarray(spec.axis, dtype=np.float64)
    length = float(np.linalg.norm(axis))
    if not math.isfinite(length) or length == 0:
        raise SchemaError("a cylinder axis must be a non-zero vector")
    start = np.asarray(spec.point, dtype=np.float64)
    end = start + spec.height * axis / length
    shape = trimesh.creation.cylinder(
        radius=spec.radius, segment=np.stack([start, end]), sections=CYLINDER_SECTIONS
    )
    return solid(shape)


def generated_mesh(
    add: Sequence[Primitive], cut: Sequence[Primitive] = (), where: str | None = None
) -> trimesh.Trimesh:
    """The closed mesh of the union of ``add`` minus the union of ``cut`` (manifold3d
    booleans); :class:`GeometryError` naming ``where`` when nothing is left."""
    if not add:
        raise GeometryError("a generated mesh needs at least one added primitive", where=where)
    result = manifold3d.Manifold.batch_boolean(
        [primitive_solid(p) for p in add], manifold3d.OpType.Add
    )
    if cut:
        result = result - manifold3d.Manifold.batch_boolean(
            [primitive_solid(p) for p in cut], manifold3d.OpType.Add
        )
    out = result.to_mesh()
    mesh = trimesh.Trimesh(
        np.asarray(out.vert_properties[:, :3], dtype=np.float64),
        np.asarray(out.tri_verts, dtype=np.int64),
        process=True,
    )
    if mesh.is_empty:
        raise GeometryError("the generated mesh is empty", where=where)
    return mesh
