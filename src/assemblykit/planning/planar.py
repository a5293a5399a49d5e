"""Planning for polygon assemblies (:class:`~assemblykit.model.polygons.PolygonAssembly`;
Wilson & Latombe 1992, "2D case"), the planning layer's planar variant: the tables the
planner of :mod:`assemblykit.planning.search` searches, and Γ_g restricted to the plane.

In the plane Γ_e is exact for every polygon (:mod:`assemblykit.blocking.planar`), so
the candidate directions are the regions of one arrangement of S¹: the points and open
arcs cut by the diameters of both Γ_t (contacts) and Γ_e (grown obstacles). It refines
both NDBGs, so each DBG is constant over each of its regions: a part that leaves along
some direction leaves along one of them. Γ_t over these directions bounds and explains
(``translation_locked``), Γ_e accepts the steps, as in 3D.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy.optimize import linprog

from assemblykit.blocking.directions import DirectionTable
from assemblykit.blocking.rigid import RIGID_MAX_SIZE, RigidBlockingGraph, wrenches
from assemblykit.blocking.tables import planar_direction_tables
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.part_sets import mask_of
from assemblykit.planning.search import Progress, Search
from assemblykit.tolerance import ModelTolerance

if TYPE_CHECKING:
    from assemblykit.model.polygons import PolygonAssembly

# twists (omega; v) of the plane z = 0: a turn about z and a translation in the plane
_PLANAR_TWIST_BOUNDS = [(0.0, 0.0), (0.0, 0.0), (-1.0, 1.0), (-1.0, 1.0), (-1.0, 1.0), (0.0, 0.0)]


@dataclass(frozen=True, eq=False)
class PlanarExtended(DirectionTable):
    """Γ_e of polygons along every candidate direction, exact and complete (module
    docstring): what
    :class:`assemblykit.planning.extended_directions.ExtendedDirections` computes pair
    by pair in 3D is known here for every direction at once."""

    def table(self, indices: Iterable[int], members: int | None = None) -> DirectionTable:
        """The DBGs among ``members`` (default: all parts) along the directions
        ``indices``, as a table."""
        chosen = sorted(set(indices))
        among = mask_of(range(len(self.names))) if members is None else members
        arcs = [list(self.graph(k, among).edges) for k in chosen]
        return DirectionTable.from_arcs(self.names, self.directions[chosen], arcs)

    @property
    def evaluated(self) -> set[int]:
        """Every direction: the whole table is exact."""
        return set(range(len(self.directions)))


def planar_tables(
    model: PolygonAssembly, tol: ModelTolerance
) -> tuple[DirectionTable, PlanarExtended, tuple[float, ...]]:
    """Γ_t and Γ_e of a polygon assembly along the regions of their common arrangement
    of S¹ (module docstring, :func:`~assemblykit.blocking.tables.planar_direction_tables`),
    and the parts' areas (the largest stays as the base)."""

    local, exact = planar_direction_tables(model, tol)
    area = model.sizes()
    return (
        local,
        PlanarExtended(exact.names, exact.directions, exact.slots, exact.moving, exact.blocker),
        tuple(area[name] for name in model.names),
    )


def planar_search(
    model: PolygonAssembly,
    tol: ModelTolerance,
    report: Progress,
    max_steps: int | None = None,
    fixed: Sequence[str] = (),
) -> Search:
    """The planner's search over a polygon assembly, run: Γ_t bounds and Γ_e accepts
    along every region of the common arrangement (:func:`planar_tables`), stopping after
    ``max_steps`` steps when given, never moving the ``fixed`` parts (docs/planning.md,
    "Fixed parts")."""
    translations, extended, volumes = planar_tables(model, tol)
    names = translations.names
    total = sum(volumes)
    volumes = tuple(v + total if n in fixed else v for n, v in zip(names, volumes, strict=True))
    mask = mask_of(k for k, name in enumerate(names) if name in fixed)
    search = Search(
        translations=translations,
        extended=extended,
        volumes=volumes,
        progress=report,
        max_steps=max_steps,
        fixed=mask,
    )
    search.disassemble(mask_of(range(len(translations.names))))
    return search


def planar_rigid_may_free(
    model: PolygonAssembly, parts: Iterable[str], tol: ModelTolerance
) -> bool:
    """Whether some infinitesimal rigid motion of the plane (a turn about z and a
    translation in z = 0) moves a proper part of ``parts`` away from the others without
    penetration, breaking some contact (Γ_g in 2D, Wilson & Latombe 1992, "Extension and
    Variant": "the 2D case is just simpler"). Each candidate set of at most
    ``RIGID_MAX_SIZE`` parts is decided by the linear program of
    :meth:`assemblykit.blocking.rigid.RigidBlockingGraph.free_twist`
    with the out-of-plane twist components held at zero."""
    names = tuple(parts)
    inside = set(names)
    contacts = tuple(c for c in assembly_contacts(model, tol) if c.a in inside and c.b in inside)
    graph = RigidBlockingGraph(names, contacts, tol)
    for size in range(1, min(RIGID_MAX_SIZE, len(names) - 1) + 1):
        for chosen in itertools.combinations(names, size):
            pts, nrm = graph.constraints(chosen)
            if len(pts) == 0:
                return True
            rows = wrenches(pts, nrm, pts.mean(axis=0), tol.scale)
            result = linprog(
                c=rows.sum(axis=0),
                A_ub=rows,
                b_ub=np.zeros(len(rows)),
                bounds=_PLANAR_TWIST_BOUNDS,
                method="highs",
            )
            if result.status == 0 and -result.fun > tol.mesh_angle:
                return True
    return False
