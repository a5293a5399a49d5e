"""Blocking constraints: when does one part block another along a direction d?

A :class:`BlockingTerm` says "``blocker`` blocks ``moving`` along every d with
``n . d > 0`` for all its normals ``n``" (an open polyhedral cone of directions; no
normals means every direction). A part blocks another along d iff one of their terms
holds at d. Every kind of motion of Wilson & Latombe 1992 reduces to such terms:

* infinitesimal translations (Γ_t): one term per planar contact patch, ``n`` the normal
  from ``moving`` into ``blocker`` ("the open half-sphere contains the direction of the
  outer normal"); curved patches as below;
* extended translations (Γ_e): one term per pair, the open cone of the Minkowski
  difference (:mod:`assemblykit.blocking.extended`).

Curved contacts (this module): the moving part is blocked along d iff ``n . d > 0`` for
some normal ``n`` of the contact patch, out of the moving part. The patch carries unit
normals generating the cone of its normals (:meth:`CurvedPatch.normal_cone`, from the
part of the surface both parts really cover), so the union of their half-spaces is
exactly the blocked set: a shaft in a hole (the whole circle, ``±e1, ±e2``) is blocked
along every direction but ±axis, a rod in a half-round groove everywhere but the closed
half-circle of directions out of the groove, a whole sphere everywhere, a ball in a
shallow cup everywhere but the cone above the rim. A cone's normals are sampled at a
few azimuths, and so are a spherical cap's extreme rays (the rim of a meshed cup has as
many as the mesh has sides, each a great circle of the arrangement): this can only leave
out blocked directions, so freedom stays a necessary condition, and the extended and
push-only readings use all of them.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from assemblykit.errors import FeatureError
from assemblykit.geometry.contact_values import Contact, CurvedPatch
from assemblykit.geometry.curved import CONE_AZIMUTHS, spread


@dataclass(frozen=True, eq=False)
class BlockingTerm:
    """``blocker`` blocks ``moving`` along d iff ``normals @ d > 0`` (all rows)."""

    moving: str
    blocker: str
    normals: NDArray[np.float64]

    @property
    def single(self) -> bool:
        """Whether the term is one half-space (it then adds to its pair's arc weight: Wilson &
        Latombe 1992, "Computation of Blocking Graph")."""
        return len(self.normals) == 1


def curved_normals(patch: CurvedPatch, moving_is_inner: bool) -> NDArray[np.float64]:
    """Normals of half-spaces whose union is the set of directions along which the
    moving part of a curved contact is blocked (module docstring): the patch's normal
    cone, out of the moving part (a spherical cap's at ``CONE_AZIMUTHS`` of its rays)."""
    if patch.kind != "spherical" and (patch.axis is None or not np.linalg.norm(patch.axis) > 0):
        raise FeatureError(f"{patch.kind} contact without an axis", where=patch.inner)
    normals = patch.normal_cone()
    if patch.kind == "spherical":
        normals = spread(normals, CONE_AZIMUTHS)
    return normals if moving_is_inner else -normals


def infinitesimal_terms(contacts: Iterable[Contact]) -> list[BlockingTerm]:
    """The Γ_t terms of the contacts, both ways (Wilson & Latombe 1992, 2D and 3D cases)."""
    terms: list[BlockingTerm] = []
    for contact in contacts:
        for patch in contact.planar:
            n = np.asarray(patch.normal, dtype=np.float64)
            n = n / np.linalg.norm(n)
            terms.append(BlockingTerm(contact.a, contact.b, n[None, :]))
            terms.append(BlockingTerm(contact.b, contact.a, -n[None, :]))
        for curved in contact.curved:
            for moving, blocker in ((contact.a, contact.b), (contact.b, contact.a)):
                normals = curved_normals(curved, moving == curved.inner)
                terms.extend(BlockingTerm(moving, blocker, n[None, :]) for n in normals)
    return terms


def positively_spanning(normals: NDArray[np.float64]) -> bool:
    """Whether the ``normals`` (rows) positively span space: every vector is a
    combination of them with non-negative weights. Then no direction ``d`` has
    ``n . d <= 0`` for every one but ``d = 0``: a part whose Γ_t terms have these
    normals cannot start to translate, so no translation, infinitesimal or extended,
    frees it (Wilson & Latombe 1992: blocking along ``d`` by a contact implies blocking
    by the part). They do exactly when they span space and some weights all at least
    one cancel (Gordan's alternative), one linear program (HiGHS)."""
    from scipy.optimize import linprog

    rows = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    if len(rows) < 4 or np.linalg.matrix_rank(rows) < 3:
        return False
    found = linprog(
        np.zeros(len(rows)), A_eq=rows.T, b_eq=np.zeros(3), bounds=(1, None), method="highs"
    )
    return bool(found.status == 0)
