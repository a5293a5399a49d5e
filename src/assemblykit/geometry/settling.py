"""Settling: the least translations that close thin interpenetrations.

Parts designed to touch share thin layers once their poses are rounded (ASAP's
``final_state`` is written to 4 decimals) or their faces generated slightly off (COMPAS
vaults). Liu & Popplestone 1990 asks that mated parts do not occupy the same space; this module
finds how far they must move apart for that.

The shared volume ``V`` of solids ``A`` and ``B``, as a function of a translation ``t``
of ``A``, has the gradient ``∂V/∂t = ∫_{∂A ∩ B} n_A dS``: only the part of ``A``'s
boundary inside ``B`` sweeps new shared volume. For a layer of thickness ``h`` and unit
normal ``n`` over an area ``S``, ``V = h S`` and the gradient is ``S n``, so the
Gauss–Newton step ``−V g / |g|²`` moves ``A`` back by ``h`` along ``n``: out of the
layer and still in contact. Several pairs are closed together by the least-norm
translations that zero every pair's linearised volume (``numpy.linalg.lstsq``); the
step, shortened while it does not reduce the total volume, is repeated while the
total keeps shrinking.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import trimesh
from numpy.typing import NDArray

from assemblykit.geometry.booleans import manifold3d
from assemblykit.geometry.interference import solid

ROUNDS = 8
"""At most this many Gauss–Newton rounds (one or two close a flat layer)."""

PROGRESS = 0.9
"""A round must leave at most this fraction of the previous total volume to go on."""

STEP_FRACTIONS = (1.0, 0.5, 0.25, 0.125)
"""The fractions of a Gauss–Newton step tried in turn (backtracking): tapered and curved
layers make the linearised volume overshoot."""


@dataclass(frozen=True)
class Settlement:
    """Per part, the ``shifts`` (n x 3) that settle it; per pair of ``pairs``, the shared
    volume ``before`` and ``after`` them."""

    pairs: tuple[tuple[int, int], ...]
    shifts: NDArray[np.float64]
    before: tuple[float, ...]
    after: tuple[float, ...]

    @property
    def largest(self) -> float:
        """The longest shift."""
        return float(np.linalg.norm(self.shifts, axis=1).max(initial=0.0))


def overlap_gradient(
    a: manifold3d.Manifold, b: manifold3d.Manifold, a_id: int
) -> tuple[float, NDArray[np.float64]]:
    """``vol(A ∩ B)`` and its gradient with respect to a translation of ``A`` (module
    docstring); ``a_id`` is the original id of ``A`` (``Manifold.as_original``), which
    its triangles keep through transforms and booleans."""
    shared = a ^ b
    volume = float(shared.volume())
    if volume <= 0:
        return 0.0, np.zeros(3)
    mesh = shared.to_mesh64()
    vertices = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3]
    triangles = vertices[np.asarray(mesh.tri_verts, dtype=np.int64)]
    area_normals = 0.5 * np.cross(
        triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0]
    )
    runs = np.asarray(mesh.run_index, dtype=np.int64) // 3
    owner = np.repeat(np.asarray(mesh.run_original_id, dtype=np.int64), np.diff(runs))
    gradient = area_normals[owner == a_id].sum(axis=0)
    # opposite faces (the sides of a layer) cancel up to the rounding of the boolean's
    # vertices: a component below the resolution of the gradient's length is that residue
    gradient[np.abs(gradient) <= np.finfo(np.float64).eps * np.linalg.norm(gradient)] = 0.0
    return volume, gradient


def layer_thickness(a: manifold3d.Manifold, b: manifold3d.Manifold) -> tuple[float, float]:
    """``vol(A ∩ B)`` and the thickness of the layer it makes: the volume over the length
    of its gradient (:func:`overlap_gradient`), the length of the first Gauss–Newton
    step of :func:`settle` (module docstring: exactly ``h`` for a flat layer of thickness
    ``h``). A shared volume whose gradient vanishes (a part enclosed all round, where
    moving it any way shares as much) has an infinite thickness; no volume, none."""
    first = a.as_original()
    volume, gradient = overlap_gradient(first, b, first.original_id())
    if volume <= 0:
        return 0.0, 0.0
    length = float(np.linalg.norm(gradient))
    return volume, volume / length if length > 0 else np.inf


def settle(
    meshes: Sequence[trimesh.Trimesh],
    pairs: Sequence[tuple[int, int]],
    solids: Sequence[manifold3d.Manifold] | None = None,
) -> Settlement:
    """The least-norm translations of ``meshes`` after which the ``pairs`` (indices into
    ``meshes``) no longer share volume, as far as Gauss–Newton on the shared volumes
    gets (module docstring). Pairs that share none stay out of the system. ``solids``:
    the meshes' manifold3d solids when already made."""
    made = [solid(mesh) for mesh in meshes] if solids is None else solids
    solids = [each.as_original() for each in made]
    ids = [s.original_id() for s in solids]

    def measure(x: NDArray[np.float64]) -> list[tuple[float, NDArray[np.float64]]]:
        return [
            overlap_gradient(
                solids[i].translate(tuple(x[i])), solids[j].translate(tuple(x[j])), ids[i]
            )
            for i, j in pairs
        ]

    state = measure(np.zeros((len(meshes), 3)))
    before = tuple(volume for volume, _ in state)
    best = (sum(before), np.zeros((len(meshes), 3)), before)
    for _ in range(ROUNDS):
        rows = [(p, v, g) for p, (v, g) in enumerate(state) if v > 0 and g @ g > 0]
        if not rows:
            break
        system = np.zeros((len(rows), 3 * len(meshes)))
        for row, (p, _, g) in enumerate(rows):
            i, j = pairs[p]
            system[row, 3 * i : 3 * i + 3] = g
            system[row, 3 * j : 3 * j + 3] = -g
        rhs = -np.array([v for _, v, _ in rows])
        step = np.linalg.lstsq(system, rhs, rcond=None)[0].reshape(-1, 3)
        for fraction in STEP_FRACTIONS:
            trial = best[1] + fraction * step
            state = measure(trial)
            total = sum(volume for volume, _ in state)
            if total < best[0]:
                break
        else:
            break
        improved = total <= PROGRESS * best[0]
        best = (total, trial, tuple(volume for volume, _ in state))
        if not improved:
            break
    return Settlement(tuple(pairs), best[1], before, best[2])
