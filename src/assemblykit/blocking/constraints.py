"""Blocking constraints: when does one part block another along a direction d?

A :class:`BlockingTerm` says "``blocker`` blocks ``moving`` along every d with
``n . d > 0`` for all its normals ``n``" (an open polyhedral cone of directions; no
normals means every direction). A part blocks another along d iff one of their terms
holds at d. Every kind of motion of seed 004 reduces to such terms:

* infinitesimal translations (Γ_t): one term per planar contact patch, ``n`` the normal
  from ``moving`` into ``blocker`` ("the open half-sphere contains the direction of the
  outer normal"); curved patches as below;
* extended translations (Γ_e): one term per pair, the open cone of the Minkowski
  difference (:mod:`assemblykit.blocking.extended`).

Curved contacts (this module): a cylinder's normals fill a great circle, so it blocks
every direction except ±axis, exactly the union of the four half-spaces ``±e1 . d > 0``,
``±e2 . d > 0`` (e1, e2 ⟂ axis); a sphere blocks every direction (six half-spaces
``±x, ±y, ±z``). A cone (inner part leaving along +axis, towards the opening) blocks the
directions entering any of its normals' half-spaces; it is sampled at a few azimuths,
which can only leave out blocked directions, so freedom stays a necessary condition.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from assemblykit.errors import FeatureError
from assemblykit.geometry.contacts import Contact, CurvedPatch

CONE_AZIMUTHS = 8
_AXES = np.eye(3)


@dataclass(frozen=True, eq=False)
class BlockingTerm:
    """``blocker`` blocks ``moving`` along d iff ``normals @ d > 0`` (all rows)."""

    moving: str
    blocker: str
    normals: NDArray[np.float64]

    @property
    def single(self) -> bool:
        """Whether the term is one half-space (it then adds to the seed's arc weight)."""
        return len(self.normals) == 1


def _perpendicular(axis: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    a = axis / np.linalg.norm(axis)
    helper = _AXES[int(np.argmin(np.abs(a)))]
    e1 = np.cross(a, helper)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(a, e1)


def curved_normals(patch: CurvedPatch, moving_is_inner: bool) -> NDArray[np.float64]:
    """Normals of half-spaces whose union is the set of directions along which the
    moving part of a curved contact is blocked (module docstring)."""
    if patch.kind == "spherical":
        return np.concatenate([_AXES, -_AXES])
    if patch.axis is None or not np.linalg.norm(patch.axis) > 0:
        raise FeatureError(f"{patch.kind} contact without an axis", where=patch.inner)
    e1, e2 = _perpendicular(np.asarray(patch.axis, dtype=np.float64))
    if patch.kind == "cylindrical":
        return np.array([e1, -e1, e2, -e2])
    axis = np.asarray(patch.axis, dtype=np.float64) / np.linalg.norm(patch.axis)
    phi = np.linspace(0.0, 2 * np.pi, CONE_AZIMUTHS, endpoint=False)
    radial = np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2
    inner_out = np.cos(patch.half_angle) * radial - np.sin(patch.half_angle) * axis
    return inner_out if moving_is_inner else -inner_out


def infinitesimal_terms(contacts: Iterable[Contact]) -> list[BlockingTerm]:
    """The Γ_t terms of the contacts, both ways (seed 004, 2D and 3D cases)."""
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
