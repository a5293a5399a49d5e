"""Blocking for extended translations by swept volumes (seed 004, "Extended translations").

Part ``j`` blocks the extended translation of part ``i`` along ``d`` iff the volume
``i`` sweeps meets the interior of ``j``. The sweep of a closed polyhedron ``P`` along
``d`` is ``P`` together with the prisms swept by its front faces (normal · d > 0): a
point ``p + t d`` outside ``P`` lies on the ray leaving ``P`` through such a face, so
it lies in that face's prism. Each prism is the convex hull of a triangle and its
translate (manifold3d ``hull_points``) and the union is one manifold3d batch boolean,
exact for non-convex parts: a pin slides through its bore, a post lifts out of its
slot. Run ``assembly.scale`` far, the sweep passes every other part; whether it meets
one is :func:`assemblykit.geometry.interference.interferes` (a shared volume above the
touching tolerance).
"""

from __future__ import annotations

import manifold3d
import numpy as np
import trimesh
from numpy.typing import NDArray

from assemblykit.geometry.interference import solid
from assemblykit.tolerance import Tolerance


def swept_volume(
    mesh: trimesh.Trimesh, direction: NDArray[np.float64], length: float, tol: Tolerance
) -> trimesh.Trimesh:
    """The volume ``mesh`` sweeps translating ``length`` along ``direction`` (module doc).

    Faces within the angle tolerance of parallel to ``direction`` sweep no volume and
    are left out."""
    step = length * np.asarray(direction, dtype=np.float64) / np.linalg.norm(direction)
    front = mesh.triangles[mesh.face_normals @ step > tol.angle * length]
    prisms = [manifold3d.Manifold.hull_points(np.vstack([t, t + step])) for t in front]
    swept = manifold3d.Manifold.batch_boolean([solid(mesh), *prisms], manifold3d.OpType.Add)
    out = swept.to_mesh64()
    # copies: manifold3d hands out read-only buffers that it will not take back
    return trimesh.Trimesh(
        np.array(out.vert_properties[:, :3], dtype=np.float64),
        np.array(out.tri_verts, dtype=np.int64),
        process=False,
    )
