"""Blocking for infinitesimal rigid motions, Γ_g (seed 004, "Infinitesimal rigid
motions").

A twist ``(omega; v)`` (DESIGN.md §4: ``v`` is the velocity of the point at the origin)
moves a point ``p`` of a part with velocity ``v + omega x p``. At a contact point ``p``
with normal ``n`` pointing from the moving part into the other, the twist is allowed
iff ``n . (v + omega x p) <= 0``, i.e. ``w . (omega; v) <= 0`` with the wrench
``w = (p x n; n)``. For planar patches the points are the vertices of the patch's
convex hull (seed 004, "for each vertex v of the convex hull of the contacting area");
for curved patches the sampled boundary points with the surface normals there.

A subassembly is free when some allowed twist breaks at least one contact: the linear
program "maximise the total separation ``-sum w . xi`` over allowed twists in a box"
(scipy ``linprog``, HiGHS) decides it and its optimum is the witness twist. The S⁵
arrangement itself is not enumerated.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import networkx as nx
import numpy as np
from numpy.typing import ArrayLike, NDArray
from rich.table import Table
from scipy.optimize import linprog
from scipy.spatial import ConvexHull, QhullError

from assemblykit.blocking.dbg import DirectionalBlockingGraph, Region, Removal
from assemblykit.geometry.contacts import Contact, CurvedPatch, PlanarPatch
from assemblykit.tolerance import Tolerance

RIGID_MAX_SIZE = 2
CURVED_SAMPLES = 8


def _patch_hull_points(patch: PlanarPatch) -> NDArray[np.float64]:
    poly = np.asarray(patch.polygon, dtype=np.float64).reshape(-1, 3)
    n = np.asarray(patch.normal, dtype=np.float64)
    e1 = np.cross(n, np.eye(3)[int(np.argmin(np.abs(n)))])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n / np.linalg.norm(n), e1)
    try:
        hull = ConvexHull(np.column_stack([poly @ e1, poly @ e2]))
    except QhullError:
        return poly
    return poly[hull.vertices]


def _curved_points(patch: CurvedPatch) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Points of a curved patch and the outward normals of its inner part there."""
    center = np.asarray(patch.center, dtype=np.float64)
    if patch.points is not None:
        pts = np.asarray(patch.points, dtype=np.float64).reshape(-1, 3)
    else:
        axis = np.asarray(patch.axis if patch.axis is not None else [0.0, 0.0, 1.0])
        axis = axis / np.linalg.norm(axis)
        e1 = np.cross(axis, np.eye(3)[int(np.argmin(np.abs(axis)))])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(axis, e1)
        phi = np.linspace(0, 2 * np.pi, CURVED_SAMPLES, endpoint=False)
        ring = np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2
        ends = patch.extent or (0.0, 0.0)
        pts = np.concatenate([center + s * axis + patch.radius * ring for s in ends])
    if patch.kind == "spherical" or patch.axis is None:
        normals = pts - center
    else:
        axis = np.asarray(patch.axis, dtype=np.float64) / np.linalg.norm(patch.axis)
        rel = pts - center
        radial = rel - np.outer(rel @ axis, axis)
        radial /= np.linalg.norm(radial, axis=1, keepdims=True)
        normals = np.cos(patch.half_angle) * radial - np.sin(patch.half_angle) * axis
    return pts, normals / np.linalg.norm(normals, axis=1, keepdims=True)


def contact_points(contact: Contact) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Contact points and unit normals from ``contact.a`` into ``contact.b``."""
    pts: list[NDArray[np.float64]] = []
    nrm: list[NDArray[np.float64]] = []
    for patch in contact.planar:
        n = np.asarray(patch.normal, dtype=np.float64)
        hull = _patch_hull_points(patch)
        pts.append(hull)
        nrm.append(np.tile(n / np.linalg.norm(n), (len(hull), 1)))
    for curved in contact.curved:
        p, n = _curved_points(curved)
        pts.append(p)
        nrm.append(n if curved.inner == contact.a else -n)
    if not pts:
        return np.zeros((0, 3)), np.zeros((0, 3))
    return np.concatenate(pts), np.concatenate(nrm)


def wrenches(
    points: NDArray[np.float64],
    normals: NDArray[np.float64],
    origin: NDArray[np.float64],
    scale: float,
) -> NDArray[np.float64]:
    """Rows ``((p - origin) x n / scale; n)``: the constraints on a twist taken about
    ``origin`` with its rotation part multiplied by ``scale``."""
    return np.column_stack([np.cross(points - origin, normals) / scale, normals])


@dataclass(frozen=True, eq=False)
class RigidBlockingGraph:
    """Γ_g of an assembly: blocking under infinitesimal rigid motions, queried by LP."""

    parts: tuple[str, ...]
    contacts: tuple[Contact, ...]
    tol: Tolerance
    motion: str = "rigid"

    def constraints(
        self, subassembly: Iterable[str]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Contact points and normals out of ``subassembly`` into the rest."""
        inside = set(subassembly)
        pts, nrm = [np.zeros((0, 3))], [np.zeros((0, 3))]
        for c in self.contacts:
            if (c.a in inside) != (c.b in inside):
                p, n = contact_points(c)
                pts.append(p)
                nrm.append(n if c.a in inside else -n)
        return np.concatenate(pts), np.concatenate(nrm)

    def free_twist(self, subassembly: Iterable[str]) -> NDArray[np.float64] | None:
        """A unit twist ``(omega; v)`` that moves ``subassembly`` away from the rest
        without penetration to first order, or ``None`` if every allowed twist keeps
        all contacts (LP, module docstring). The LP takes twists about the contacts'
        centroid with rotations scaled by the model size, so both weigh alike; HiGHS
        solves to about 1e-7, so optima below the mesh angle tolerance count as zero."""
        pts, nrm = self.constraints(subassembly)
        if len(pts) == 0:
            return np.r_[0.0, 0.0, 0.0, 0.0, 0.0, 1.0]
        origin = pts.mean(axis=0)
        rows = wrenches(pts, nrm, origin, self.tol.scale)
        result = linprog(
            c=rows.sum(axis=0),
            A_ub=rows,
            b_ub=np.zeros(len(rows)),
            bounds=[(-1.0, 1.0)] * 6,
            method="highs",
        )
        if result.status != 0 or -result.fun <= self.tol.mesh_angle:
            return None
        omega = result.x[:3] / self.tol.scale
        v = result.x[3:] - np.cross(omega, origin)  # velocity of the point at the origin
        twist = np.r_[omega, v]
        return twist / np.linalg.norm(twist)

    def dbg(self, twist: ArrayLike) -> DirectionalBlockingGraph:
        """G(xi, A): ``j`` blocks ``i`` iff moving ``i`` alone by the twist pushes into
        ``j`` at some contact point."""
        xi = np.asarray(twist, dtype=np.float64).ravel()
        xi = xi / np.linalg.norm(xi)
        arcs = set()
        for c in self.contacts:
            p, n = contact_points(c)
            speeds = n @ xi[3:] + np.cross(p, n) @ xi[:3]
            if np.any(speeds > self.tol.mesh_angle):
                arcs.add((c.a, c.b))
            if np.any(-speeds > self.tol.mesh_angle):
                arcs.add((c.b, c.a))
        return DirectionalBlockingGraph(self.parts, xi, frozenset(arcs))

    def regions(self) -> list[Region]:
        """The S⁵ arrangement is not enumerated: no regions."""
        return []

    def _candidates(self, max_size: int) -> list[frozenset[str]]:
        graph = nx.Graph()
        graph.add_nodes_from(self.parts)
        graph.add_edges_from(c.pair for c in self.contacts)
        found: set[frozenset[str]] = set()
        frontier = {frozenset([p]) for p in self.parts}
        for _ in range(max_size):
            found |= frontier
            frontier = {
                s | {m} for s in frontier for p in s for m in graph.neighbors(p) if m not in s
            }
        everything = frozenset(self.parts)
        return sorted((s for s in found if s != everything), key=lambda s: (len(s), sorted(s)))

    def removable(self, max_size: int | None = None) -> list[Removal]:
        """Connected subassemblies (up to ``max_size`` parts, default
        ``RIGID_MAX_SIZE``) that some rigid twist frees, each with its witness twist:
        a necessary condition for removal (seed 004)."""
        out = []
        for subset in self._candidates(max_size or RIGID_MAX_SIZE):
            twist = self.free_twist(subset)
            if twist is not None:
                out.append(Removal(subset, (twist,)))
        return out

    def to_dict(self) -> dict[str, Any]:
        """JSON of DESIGN.md §5.3 (no regions: the S⁵ arrangement is not enumerated)."""
        return {
            "motion": self.motion,
            "parts": list(self.parts),
            "contacts": len(self.contacts),
            "regions": {"vertices": 0, "edges": 0, "faces": 0},
            "removable": [r.to_dict() for r in self.removable()],
        }

    def render(self) -> Table:
        """A table of the removable subassemblies with their witness twists."""
        table = Table(title=f"rigid NDBG: {len(self.parts)} parts, {len(self.contacts)} contacts")
        table.add_column("removable parts")
        table.add_column("twist (omega; v)")
        for r in self.removable():
            table.add_row(", ".join(sorted(r.parts)), np.array2string(r.directions[0], precision=3))
        return table
