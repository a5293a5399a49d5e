"""Polygons in the plane (Wilson & Latombe 1992, "2D case"), the geometry layer: the
contact segments of a :class:`~assemblykit.model.polygons.PolygonAssembly` (its
:func:`~assemblykit.geometry.contacts.assembly_contacts`, registered there), polygons
checked and turned counter-clockwise, and polygons cut from 3D meshes by a plane.

Two parts are in contact along a segment where an edge of one lies on an edge of the
other with opposite outward normals and the two overlap with positive length. Each
contact segment becomes a :class:`~assemblykit.geometry.contact_values.PlanarPatch` with
its in-plane normal (from part ``a`` into part ``b``), its two endpoints (z = 0) and its
length as area, so that the NDBG machinery treats the planar case on the circle of
directions S¹. The contacts found are kept per tolerance in the :class:`PolygonContacts`
store of the assembly's :class:`~assemblykit.model.assembly.Memo`. The blocking terms of
polygons are in :mod:`assemblykit.blocking.planar`.
"""

from __future__ import annotations

import itertools
from collections.abc import Set
from dataclasses import dataclass, field

import numpy as np
import trimesh
from numpy.typing import NDArray
from shapely.geometry import Polygon
from shapely.geometry.polygon import orient

from assemblykit.algebra import se3
from assemblykit.errors import GeometryError
from assemblykit.geometry.contact_values import Contact, PlanarPatch
from assemblykit.model.polygons import PolygonAssembly
from assemblykit.tolerance import ModelTolerance, Tolerance


@dataclass(eq=False)
class PolygonContacts:
    """The contact segments of a polygon assembly per tolerance (``found``), a store of
    its memo (:func:`polygon_contacts`)."""

    found: dict[Tolerance, list[Contact]] = field(default_factory=dict)

    def restricted(self, names: Set[str]) -> PolygonContacts:
        """The contacts among the polygons ``names`` alone, per tolerance: contacts are
        found pair by pair, so those of the other pairs still hold."""
        return PolygonContacts(
            {
                tol: [c for c in found if c.a in names and c.b in names]
                for tol, found in self.found.items()
            }
        )


def polygon_contacts(assembly: PolygonAssembly, tol: Tolerance | None = None) -> list[Contact]:
    """Contact segments between every two polygons of ``assembly`` (computed once per
    tolerance, kept in the :class:`PolygonContacts` of its memo): its
    :func:`~assemblykit.geometry.contacts.assembly_contacts`, registered there."""
    tol = assembly.tolerance(tol)
    kept = assembly.memo.of(PolygonContacts).found
    if tol not in kept:
        kept[tol] = edge_contacts(assembly.polygons, tol)
    return kept[tol]


def counter_clockwise(
    points: NDArray[np.float64], name: str, source: str | None = None
) -> NDArray[np.float64]:
    """``points`` (k x 2) as a counter-clockwise polygon without its closing vertex;
    :class:`GeometryError` naming part ``name`` when they are not a simple polygon of
    positive area."""
    poly = Polygon(points)
    if not poly.is_valid or poly.area <= 0:
        raise GeometryError(
            "not a simple polygon of positive area", source=source, where=f"parts.{name}"
        )
    return np.asarray(orient(poly, 1.0).exterior.coords, dtype=np.float64)[:-1]


def section_polygons(
    meshes: dict[str, trimesh.Trimesh],
    origin: NDArray[np.float64],
    normal: NDArray[np.float64],
) -> PolygonAssembly:
    """Cross-sections of meshes by the plane through ``origin`` with ``normal``, as
    polygons in one frame of that plane (the largest region of each part)."""
    n = np.asarray(normal, dtype=np.float64)
    n = n / np.linalg.norm(n)
    # the polygons' coordinates are in the plane's frame: its turn is part of the answer
    e1, e2 = se3.axis_basis(n, turned=True)
    to_2d = np.eye(4)
    to_2d[:3, :3] = np.vstack([e1, e2, n])
    to_2d[:3, 3] = -to_2d[:3, :3] @ np.asarray(origin, dtype=np.float64)
    polygons = {}
    for name, mesh in meshes.items():
        cut = mesh.section(plane_origin=origin, plane_normal=n)
        if cut is None:
            continue
        planar, _ = cut.to_2D(to_2D=to_2d, check=False)
        regions = planar.polygons_full
        if regions:
            # the triangulation leaves collinear vertices on the section's edges
            biggest = max(regions, key=lambda p: p.area).simplify(0)
            polygons[name] = counter_clockwise(np.asarray(biggest.exterior.coords)[:-1], name)
    return PolygonAssembly(polygons)


def _edges(poly: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    return poly, np.roll(poly, -1, axis=0)


def edge_contacts(polygons: dict[str, NDArray[np.float64]], tol: ModelTolerance) -> list[Contact]:
    """Contact segments between every two counter-clockwise polygons (module docstring)."""
    contacts = []
    boxes = {
        n: (p.min(axis=0) - tol.length, p.max(axis=0) + tol.length) for n, p in polygons.items()
    }
    for a, b in itertools.combinations(polygons, 2):
        (alo, ahi), (blo, bhi) = boxes[a], boxes[b]
        if np.any(alo > bhi) or np.any(blo > ahi):
            continue
        patches = []
        for p, q in zip(*_edges(polygons[a]), strict=True):
            u = (q - p) / np.linalg.norm(q - p)
            normal = np.array([u[1], -u[0]])  # outward for a counter-clockwise polygon
            for r, s in zip(*_edges(polygons[b]), strict=True):
                w = (s - r) / np.linalg.norm(s - r)
                if u @ w > 0 or abs(u[0] * w[1] - u[1] * w[0]) > tol.angle:
                    continue
                if abs(normal @ (r - p)) > tol.length or abs(normal @ (s - p)) > tol.length:
                    continue
                lo = max(0.0, min(u @ (r - p), u @ (s - p)))
                hi = min(float(u @ (q - p)), max(u @ (r - p), u @ (s - p)))
                if hi - lo > tol.length:
                    seg = np.array([[*(p + lo * u), 0.0], [*(p + hi * u), 0.0]])
                    patches.append(PlanarPatch(np.array([*normal, 0.0]), seg, hi - lo))
        if patches:
            contacts.append(Contact(a, b, planar=tuple(patches)))
    return contacts
