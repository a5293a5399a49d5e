"""Blocking for infinitesimal rigid motions, Γ_g (Wilson & Latombe 1992, "Infinitesimal rigid
motions").

A twist ``(omega; v)`` (``v`` is the velocity of the point at the origin:
docs/architecture.md, "Conventions") moves a point ``p`` of a part with velocity
``v + omega x p``. At a contact point ``p`` with normal ``n`` pointing from the moving
part into the other, the twist is allowed
iff ``n . (v + omega x p) <= 0``, i.e. ``w . (omega; v) <= 0`` with the wrench
``w = (p x n; n)``. For planar patches the points are the vertices of the patch's
convex hull (Wilson & Latombe 1992, "for each vertex v of the convex hull of the contacting area");
for curved patches the normals generating the patch's normal cone at both ends of its
axial extent (:meth:`~assemblykit.geometry.contacts.CurvedPatch.samples`; exact for
cylinders and spheres, whose constraints are linear in the normal).

The S⁵ arrangement: every distinct hyperplane ``w . xi = 0`` of the assembly's contact
points (taken about their centroid with rotations scaled by the model size, so both
weigh alike) cuts twist space; up to ``RIGID_MAX_HYPERPLANES`` of them, its
full-dimensional cells are enumerated (:mod:`assemblykit.blocking.twist_arrangement`)
and each carries its DBG: ``i -> j`` iff some constraint of a contact where ``i``
touches ``j`` is violated in the cell. A subassembly free in such a DBG leaves by a
twist that breaks every one of its contacts. Freedom that needs sliding (a twist on
some hyperplanes, e.g. a block held between two walls turning between them) lies on the
lower-dimensional cells, which are not enumerated: for it, and beyond the limit, a
linear program "maximise the total separation ``-sum w . xi`` over allowed twists in a
box" (scipy ``linprog``, HiGHS) decides each candidate and its optimum is the witness.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Iterable
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import networkx as nx
import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import linprog
from scipy.spatial import ConvexHull, QhullError

from assemblykit.algebra import se3
from assemblykit.blocking.dbg import DirectionalBlockingGraph, Region, Removal
from assemblykit.blocking.twist_arrangement import arrangement_cells, snap_hyperplanes
from assemblykit.geometry.contact_values import Contact, PlanarPatch
from assemblykit.graphs import component_labels
from assemblykit.tolerance import ModelTolerance

RIGID_MAX_SIZE = 2
# about 4 s of linear programs at 12 hyperplanes in general position (2048 cells); the
# count of cells grows as m^5
RIGID_MAX_HYPERPLANES = 12


def _patch_hull_points(patch: PlanarPatch) -> NDArray[np.float64]:
    poly = np.asarray(patch.polygon, dtype=np.float64).reshape(-1, 3)
    n = np.asarray(patch.normal, dtype=np.float64)
    # the hull's first vertex depends on the frame's turn: it orders the contact points
    e1, e2 = se3.axis_basis(n / np.linalg.norm(n), turned=True)
    try:
        hull = ConvexHull(np.column_stack([poly @ e1, poly @ e2]))
    except QhullError:
        return poly
    vertices: NDArray[np.intp] = hull.vertices
    return poly[vertices]


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
        # the inner part's outward normals on the part of the surface really touched
        p, n = curved.samples()
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


def stops_every_twist(
    points: NDArray[np.float64], normals: NDArray[np.float64], tol: ModelTolerance
) -> bool:
    """Whether contacts at ``points`` with ``normals`` stop every twist of one part
    against the other: their wrenches (:func:`wrenches`, about the points' centroid)
    positively span twist space, by a margin. Where the twists ``x`` with every
    ``w . x <= 1`` stay within ``R`` of the origin (twelve linear programs, HiGHS), every
    twist pushes into some contact at ``|x|_inf / R`` at least; the pair stops them when
    that is ten times the mesh angle tolerance, which the blocking graphs take for
    sliding (:meth:`RigidBlockingGraph.dbg`)."""
    if len(points) < 7:
        return False
    rows = wrenches(points, normals, points.mean(axis=0), tol.scale)
    if np.linalg.matrix_rank(rows) < 6:
        return False
    reach = 0.0
    for objective in np.vstack([np.eye(6), -np.eye(6)]):
        found = linprog(
            -objective, A_ub=rows, b_ub=np.ones(len(rows)), bounds=(None, None), method="highs"
        )
        if found.status != 0:
            return False
        reach = max(reach, -float(found.fun))
    return 1.0 / (reach * math.sqrt(6)) > 10 * tol.mesh_angle


def world_twist(
    x: NDArray[np.float64], origin: NDArray[np.float64], scale: float
) -> NDArray[np.float64]:
    """The unit twist ``(omega; v)`` (``v`` at the world origin) of a twist ``x`` taken
    about ``origin`` with its rotation multiplied by ``scale`` (as in :func:`wrenches`)."""
    omega = x[:3] / scale
    v = x[3:] - np.cross(omega, origin)
    twist = np.concatenate([omega, v])
    return twist / float(np.linalg.norm(twist))


@dataclass(frozen=True, eq=False)
class TwistArrangement:
    """The S⁵ arrangement of Γ_g (module docstring), in the coordinates of
    :func:`wrenches` about ``origin``: the distinct unit hyperplane ``normals``; for
    every contact point (contacts in order) its hyperplane ``plane_of``, orientation
    ``orient`` and contact ``contact_of``; the full-dimensional cells' ``signs`` and
    interior ``points``, ``None`` when there are more than ``RIGID_MAX_HYPERPLANES``
    hyperplanes (not built)."""

    origin: NDArray[np.float64]
    normals: NDArray[np.float64]
    plane_of: NDArray[np.int64]
    orient: NDArray[np.int8]
    contact_of: NDArray[np.int64]
    signs: NDArray[np.int8] | None
    points: NDArray[np.float64] | None

    @property
    def status(self) -> str:
        """``built: ...`` or ``not built: N hyperplanes > limit`` (for the JSON)."""
        m = len(self.normals)
        if self.signs is None:
            return f"not built: {m} hyperplanes > {RIGID_MAX_HYPERPLANES}"
        return f"built: {m} hyperplanes, {len(self.signs)} regions"


def twist_arrangement(contacts: Iterable[Contact], tol: ModelTolerance) -> TwistArrangement:
    """The hyperplanes of every contact point of the contacts (normals from ``a`` into
    ``b``), snapped (:func:`~assemblykit.blocking.twist_arrangement.snap_hyperplanes`),
    and the cells of their arrangement when there are at most
    ``RIGID_MAX_HYPERPLANES``."""
    pts, nrm, owner = [np.zeros((0, 3))], [np.zeros((0, 3))], [np.zeros(0, np.int64)]
    for k, contact in enumerate(contacts):
        p, n = contact_points(contact)
        pts.append(p)
        nrm.append(n)
        owner.append(np.full(len(p), k, dtype=np.int64))
    points, normals = np.concatenate(pts), np.concatenate(nrm)
    origin = points.mean(axis=0) if len(points) else np.zeros(3)
    planes, plane_of, orient = snap_hyperplanes(wrenches(points, normals, origin, tol.scale), tol)
    signs, cells = None, None
    if len(planes) <= RIGID_MAX_HYPERPLANES:
        signs, cells = arrangement_cells(planes, tol)
    return TwistArrangement(origin, planes, plane_of, orient, np.concatenate(owner), signs, cells)


@dataclass(frozen=True, eq=False)
class RigidBlockingGraph:
    """Γ_g of an assembly: blocking under infinitesimal rigid motions, from the cells of
    the S⁵ arrangement when it is small enough and by linear programs otherwise
    (module docstring)."""

    parts: tuple[str, ...]
    contacts: tuple[Contact, ...]
    tol: ModelTolerance
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
            return np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
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
        return world_twist(result.x, origin, self.tol.scale)

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

    @cached_property
    def arrangement(self) -> TwistArrangement:
        """The S⁵ arrangement of the contacts (built once, on first use)."""
        return twist_arrangement(self.contacts, self.tol)

    def _cell_arcs(self) -> list[frozenset[tuple[str, str]]]:
        """The arcs of every cell's DBG: ``a -> b`` for a contact where some point's
        constraint is positive in the cell, ``b -> a`` where one is negative."""
        arr = self.arrangement
        if arr.signs is None:
            return []
        speeds = arr.signs[:, arr.plane_of] * arr.orient  # sign of n . velocity per point
        out: list[set[tuple[str, str]]] = [set() for _ in range(len(arr.signs))]
        for k, c in enumerate(self.contacts):
            rows = speeds[:, arr.contact_of == k]
            for cell in np.flatnonzero(np.any(rows > 0, axis=1)):
                out[cell].add((c.a, c.b))
            for cell in np.flatnonzero(np.any(rows < 0, axis=1)):
                out[cell].add((c.b, c.a))
        return [frozenset(arcs) for arcs in out]

    def _cell_twists(self) -> list[NDArray[np.float64]]:
        arr = self.arrangement
        cells = np.zeros((0, 6)) if arr.points is None else arr.points
        return [world_twist(x, arr.origin, self.tol.scale) for x in cells]

    def regions(self) -> list[Region]:
        """The full-dimensional cells of the S⁵ arrangement (dimension 5) with a unit
        twist inside each and its DBG; empty when the arrangement is not built."""
        return [
            Region(twist, 5, DirectionalBlockingGraph(self.parts, twist, arcs))
            for twist, arcs in zip(self._cell_twists(), self._cell_arcs(), strict=True)
        ]

    def _candidates(self, max_size: int) -> list[frozenset[str]]:
        graph: nx.Graph[str] = nx.Graph()
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

    def frees_some(self) -> bool:
        """Whether some rigid twist frees a proper subassembly: :meth:`removable` is not
        empty. The connected subassemblies of at most ``RIGID_MAX_SIZE`` parts are tried
        first, one small linear program each (:meth:`free_twist`), then whether the
        parts are :meth:`held_together`, so that the arrangement of S⁵, whose cells grow
        as the fifth power of the contacts, is built only when neither decides."""
        if any(self.free_twist(s) is not None for s in self._candidates(RIGID_MAX_SIZE)):
            return True
        if self.held_together():
            return False
        return bool(self.removable())

    def held_together(self) -> bool:
        """Whether pairs of parts whose contacts alone stop every twist of one against
        the other (:func:`stops_every_twist`) join every part: then no twist moves a
        proper subassembly, as some such pair crosses from it to the rest, and no rigid
        motion frees any (a certificate, where :meth:`removable` searches the
        arrangement)."""
        index = {name: k for k, name in enumerate(self.parts)}
        held = [
            (index[c.a], index[c.b])
            for c in self.contacts
            if stops_every_twist(*contact_points(c), self.tol)
        ]
        labels = component_labels(len(self.parts), np.array(held, dtype=np.int64).reshape(-1, 2))
        return len(set(labels.tolist())) == 1

    def removable(self, max_size: int | None = None) -> list[Removal]:
        """Subassemblies that some rigid twist frees (a necessary condition for
        removal, Wilson & Latombe 1992): those free in a cell's DBG (up to ``max_size`` parts), with
        the cells' twists, which break all their contacts; then the connected ones (up
        to ``max_size``, default ``RIGID_MAX_SIZE`` parts) not found so, whose freedom
        needs sliding or lies beyond the arrangement's limit, each with its LP witness."""
        found: dict[frozenset[str], list[NDArray[np.float64]]] = defaultdict(list)
        by_arcs: dict[frozenset[tuple[str, str]], list[NDArray[np.float64]]] = defaultdict(list)
        for twist, arcs in zip(self._cell_twists(), self._cell_arcs(), strict=True):
            by_arcs[arcs].append(twist)
        for arcs, twists in by_arcs.items():
            graph = DirectionalBlockingGraph(self.parts, twists[0], arcs)
            for subset in graph.free_subassemblies():
                if max_size is None or len(subset) <= max_size:
                    found[subset].extend(twists)
        for subset in self._candidates(max_size or RIGID_MAX_SIZE):
            if subset not in found:
                witness = self.free_twist(subset)
                if witness is not None:
                    found[subset].append(witness)
        removals = [Removal(s, tuple(t)) for s, t in found.items()]
        return sorted(removals, key=lambda r: (len(r.parts), sorted(r.parts)))

    def to_dict(self) -> dict[str, Any]:
        """JSON of docs/blocking.md, "Output": ``regions`` counts only the full-dimensional cells
        (``faces``; ``null`` when the arrangement is not built); lower-dimensional cells
        are not enumerated (``vertices`` and ``edges`` are ``null``); ``arrangement``
        says whether it was built."""
        arr = self.arrangement
        return {
            "motion": self.motion,
            "parts": list(self.parts),
            "contacts": len(self.contacts),
            "regions": {
                "vertices": None,
                "edges": None,
                "faces": None if arr.signs is None else len(arr.signs),
            },
            "arrangement": arr.status,
            "removable": [r.to_dict() for r in self.removable()],
        }
