"""Candidate directions beyond the sampled ones, for a set of parts that no region of Γ_t
separates (docs/planning.md, "How a plan is found").

Γ_t (infinitesimal translations) is cheap (it only needs the contacts), so its regular
regions supply the candidate directions: one per region, the vertices and edges
included, as free directions are often isolated (a pin's axis). Where none of them
separates a set, the search adds, in turn:

* the coordinate axes and the axes of the cylindrical contacts, both ways, each decided
  within the angle tolerance (:func:`fit_axes`): normals a rounding apart leave a cluster
  of slivers where one vertex should be;
* a direction in every face of each part's exact free set among the set (Wilson &
  Latombe 1992, "Extension and Variant": extended translations) and, for a set of at
  most :data:`EXACT_GROUP_PARTS` parts none of which leaves alone, one in every face of
  the overlay of the pairs' blocked sets (:func:`exact_candidates`; docs/blocking.md,
  "Three kinds of motion"). A set of voxel parts that the lattice certificate proves
  interlocked gets none.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from assemblykit.blocking.arrangement import snap_normals
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.part_sets import bits
from assemblykit.tolerance import ModelTolerance

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly

EXACT_GROUP_PARTS = 12
"""The largest set left by the candidates of Γ_t whose groups get the directions of the
overlay of every pair's blocked set (single parts always get their free set's)."""


def fit_axes(assembly: Assembly, tol: ModelTolerance) -> NDArray[np.float64]:
    """The coordinate axes and the axes of the cylindrical contacts, both ways, each once
    within the angle tolerance: where the circles of every radial contact normal of a
    fit meet. Normals a rounding apart (tessellated CAD) make the arrangement a cluster
    of slivers there instead of one vertex, each on the blocked side of some circle; a
    direction added as a row of its own is decided within the tolerance
    (:func:`~assemblykit.blocking.tables.translation_slots`), so a ring lifts off its
    pins along their common axis."""
    axes = [np.eye(3)]
    for contact in assembly_contacts(assembly, tol):
        axes += [
            np.asarray(patch.axis, dtype=np.float64)[None]
            for patch in contact.curved
            if patch.kind == "cylindrical" and patch.axis is not None
        ]
    lines = snap_normals(np.vstack(axes), tol)[0]
    return np.vstack([lines, -lines])


def exact_candidates(
    assembly: Assembly, tol: ModelTolerance
) -> Callable[[int], NDArray[np.float64]]:
    """For a set of parts the sampled candidates do not separate: a direction in every
    face of each part's exact free set among the set (Wilson & Latombe 1992, "Extension
    and Variant": extended translations; each checked free), and,
    when none leaves alone and the set has at most ``EXACT_GROUP_PARTS`` parts, one in
    every face of the overlay of the pairs' blocked sets (over which every DBG is
    constant, so groups leaving together are found as well). A set of voxel parts the
    lattice certificate proves interlocked (:func:`_voxel_lock`) gets none: no direction
    frees any of its subsets, so none is computed."""
    from assemblykit.blocking.free_cones import blocked_by, exact_free_directions, overlay_faces

    names = tuple(assembly.names)
    locked = _voxel_lock(assembly)

    def directions(members: int) -> NDArray[np.float64]:
        among = [names[i] for i in bits(members)]
        if locked(among):
            return np.zeros((0, 3))
        found: list[NDArray[np.float64]] = []
        for name in among:
            found.extend(exact_free_directions(assembly, [name], tol, among, limit=2).directions)
        if found or len(among) > EXACT_GROUP_PARTS:
            return np.array(found).reshape(-1, 3)
        sets = []
        for a in among:
            for b in among:
                if a != b:
                    blocked = blocked_by(assembly, [a], b, tol)
                    if blocked is None:
                        return np.zeros((0, 3))
                    sets.append(blocked)
        return overlay_faces(sets, tol).directions

    return directions


def _voxel_lock(assembly: Assembly) -> Callable[[list[str]], bool]:
    """Whether a set of parts, all made of unit cells, is proved interlocked by
    :func:`~assemblykit.blocking.free_cones.lattice_locked` (no set of them leaves by one
    extended translation in any direction, docs/blocking.md, "Three kinds of motion"):
    then no exact free set needs computing. Each part's cells are found once."""
    from assemblykit.blocking.free_cones import LATTICE_LOCK_PARTS, lattice_locked
    from assemblykit.blocking.lattice import lattice_cells

    cells: dict[str, NDArray[np.int64] | None] = {}

    def locked(among: list[str]) -> bool:
        if not 1 < len(among) <= LATTICE_LOCK_PARTS:
            return False
        found = []
        for name in among:
            if name not in cells:
                cells[name] = lattice_cells(assembly.parts[name].mesh)
            part = cells[name]
            if part is None:
                return False
            found.append(part)
        return lattice_locked(found)

    return locked
