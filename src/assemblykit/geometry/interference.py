"""Interference between parts: the volume two solids share, by manifold3d booleans.

Touching parts share faces but no volume; interfering parts share a volume. The volume
of ``A ∩ B`` is computed exactly on the meshes by manifold3d (docs/geometry.md,
"Interference": trimesh's collision distances are wrong for convex parts, so volumes
decide). An overlap counts as interference when it is thicker than the length tolerance over
the smaller part's surface, i.e. when ``volume > tol.length x min(area_a, area_b)``.
"""

from __future__ import annotations

from collections.abc import Collection, Set
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import trimesh
from numpy.typing import NDArray

from assemblykit.errors import GeometryError
from assemblykit.geometry.booleans import manifold3d
from assemblykit.geometry.broad_phase import candidate_pairs
from assemblykit.tolerance import Tolerance, current

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly

ENCLOSED_SHARE = 1e-6
"""The share of a part's volume that may lie outside a cavity it is enclosed in (the
rounding of manifold3d's volumes: a part in a cavity is wholly inside it)."""


def solid(
    mesh: trimesh.Trimesh,
    name: str | None = None,
    *,
    original_id: int | None = None,
    face_ids: NDArray[np.int64] | None = None,
) -> manifold3d.Manifold:
    """The manifold3d solid of a closed triangle mesh (float64 vertices). With
    ``original_id`` (from ``manifold3d.Manifold.reserve_ids``) its triangles carry
    ``face_ids`` (default: their indices) under that id, so that the triangles of a
    boolean's result tell which face they lie on
    (:func:`assemblykit.geometry.overlaps.traced_mesh`). manifold3d keeps every edge
    between triangles of different ids; fewer ids (one per surface) leave it more to
    simplify and make its booleans faster."""
    numbered: dict[str, NDArray[np.generic]] = {}
    if original_id is not None:
        count = len(mesh.faces)
        ids = np.arange(count) if face_ids is None else face_ids
        numbered = {
            "face_id": np.ascontiguousarray(ids, dtype=np.uint64),
            "run_index": np.array([0, 3 * count], dtype=np.uint64),
            "run_original_id": np.array([original_id], dtype=np.uint32),
        }
    result = manifold3d.Manifold(
        manifold3d.Mesh64(
            vert_properties=np.ascontiguousarray(mesh.vertices, dtype=np.float64),
            tri_verts=np.ascontiguousarray(mesh.faces, dtype=np.uint64),
            **numbered,
        )
    )
    if result.status() != manifold3d.Error.NoError:
        raise GeometryError(
            f"mesh is not a closed oriented manifold ({result.status()})", where=name
        )
    return result


@dataclass
class Solids:
    """The manifold3d solids of an assembly's parts (:func:`solid`), a store of its memo
    (:class:`~assemblykit.model.assembly.Memo`): each made once, when first asked for
    (:func:`part_solid`), or kept by the loader that made it to settle the parts
    (:func:`keep_solids`), for the interference tests and the obstacles of blocking."""

    by_name: dict[str, manifold3d.Manifold] = field(default_factory=dict)

    def restricted(self, names: Set[str]) -> Solids:
        """The solids of the parts ``names`` (the same meshes)."""
        return Solids({name: made for name, made in self.by_name.items() if name in names})


def part_solid(assembly: Assembly, name: str) -> manifold3d.Manifold:
    """The solid of part ``name`` of ``assembly``, made once (:class:`Solids`)."""
    kept = assembly.memo.of(Solids).by_name
    if name not in kept:
        kept[name] = solid(assembly.parts[name].mesh, name)
    return kept[name]


def keep_solids(assembly: Assembly, solids: dict[str, manifold3d.Manifold]) -> None:
    """Keep ``solids``, those of parts of ``assembly`` by name, already made (each of its
    part's mesh as it is in the assembly), for :func:`part_solid`."""
    assembly.memo.of(Solids).by_name.update(solids)


def overlap_volume(mesh_a: trimesh.Trimesh, mesh_b: trimesh.Trimesh) -> float:
    """Volume of the intersection of two closed meshes, ``vol(A ∩ B)``."""
    return shared_volume(solid(mesh_a), solid(mesh_b))


def shared_volume(a: manifold3d.Manifold, b: manifold3d.Manifold) -> float:
    """Volume of the intersection of two solids (:func:`solid`), ``vol(A ∩ B)``."""
    return float((a ^ b).volume())


def interference_threshold(
    mesh_a: trimesh.Trimesh, mesh_b: trimesh.Trimesh, tol: Tolerance
) -> float:
    """The largest shared volume still counted as touching: the length tolerance times
    the smaller surface area (module docstring)."""
    return tol.length * min(float(mesh_a.area), float(mesh_b.area))


def interferes(
    mesh_a: trimesh.Trimesh, mesh_b: trimesh.Trimesh, tol: Tolerance | None = None
) -> bool:
    """Whether two closed meshes share more than a tolerance-thin volume."""
    if not _boxes_meet(mesh_a, mesh_b):
        return False
    return overlap_volume(mesh_a, mesh_b) > interference_threshold(mesh_a, mesh_b, tol or current())


def solids_interfere(a: manifold3d.Manifold, b: manifold3d.Manifold, threshold: float) -> bool:
    """Whether two solids (:func:`solid`) share more than ``threshold``
    (:func:`interference_threshold`), their bounding boxes compared first: the test of
    :func:`interferes` on solids already built, so that a body tried at many poses is
    built once and moved (``Manifold.transform``)."""
    low_a, high_a = np.split(np.asarray(a.bounding_box()), 2)
    low_b, high_b = np.split(np.asarray(b.bounding_box()), 2)
    if np.any(low_a > high_b) or np.any(low_b > high_a):
        return False
    return shared_volume(a, b) > threshold


def _boxes_meet(mesh_a: trimesh.Trimesh, mesh_b: trimesh.Trimesh) -> bool:
    return bool(
        np.all(mesh_a.bounds[0] <= mesh_b.bounds[1])
        and np.all(mesh_b.bounds[0] <= mesh_a.bounds[1])
    )


def interferences(
    assembly: Assembly, tol: Tolerance | None = None, among: Collection[str] | None = None
) -> list[tuple[str, str, float]]:
    """``(a, b, volume)`` for every pair of parts of ``assembly`` that interfere, in part
    order (with ``among``, the pairs with a part of it); only pairs whose bounding boxes
    overlap are tested (R-tree broad phase)."""
    tol = assembly.tolerance(tol)
    names = list(assembly.parts)
    if len(names) < 2:
        return []
    bounds = np.array([p.mesh.bounds for p in assembly.parts.values()])
    pairs = candidate_pairs(bounds, 0.0)
    if among is not None:
        asked = np.isin(np.array(names, dtype=object), list(among))
        pairs = pairs[asked[pairs].any(axis=1)]
    found = []
    for i, j in pairs:
        a, b = assembly.parts[names[i]], assembly.parts[names[j]]
        volume = shared_volume(part_solid(assembly, a.name), part_solid(assembly, b.name))
        if volume > interference_threshold(a.mesh, b.mesh, tol):
            found.append((a.name, b.name, volume))
    return found


def enclosures(assembly: Assembly, parts: Collection[str] | None = None) -> list[tuple[str, str]]:
    """``(inner, outer)`` for each part of ``parts`` (default: all) that lies in a void
    of another: within a closed inner shell of the other's mesh (a cavity, its triangles
    facing into it: a component of negative volume), manifold3d measuring all of the
    part's volume inside it. No translation or turn takes such a part out."""
    names = list(assembly.parts if parts is None else parts)
    found = []
    for outer in names:
        mesh = assembly.parts[outer].mesh
        if mesh.body_count < 2:
            continue
        for shell in mesh.split(only_watertight=True):
            if shell.volume >= 0:
                continue
            cavity = shell.copy()
            cavity.invert()
            low, high = cavity.bounds
            inside = solid(cavity, outer)
            for inner in names:
                part = assembly.parts[inner].mesh
                if inner == outer or np.any(part.bounds[0] < low) or np.any(part.bounds[1] > high):
                    continue
                shared = shared_volume(inside, part_solid(assembly, inner))
                if shared >= (1 - ENCLOSED_SHARE) * part.volume:
                    found.append((inner, outer))
    return found
