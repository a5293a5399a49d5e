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

Each round measures every pair anew, so the solids of a pair of many triangles
(:data:`CUT_TRIANGLES`) are first cut to the box where they can meet: the overlap of
their bounding boxes grown by a margin ``m``. While
the pair's relative shift ``d`` stays below ``m`` in each coordinate, ``(A + d) ∩ B``
lies in that box, and the faces the cut makes lie outside ``B``: the cut solids share
the same volume, with the same faces of ``A`` inside ``B``, at a fraction of the
triangles. A pair shifted farther is measured on its whole solids.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
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

CUT_MARGIN = 0.01
"""The margin ``m`` by which a pair's box overlap is grown before its solids are cut to
it (module docstring), as a fraction of the diagonal of the smaller box: far beyond the
shifts that settling makes, which close layers of a rounding's thickness."""

CUT_TRIANGLES = 2000
"""Pairs with fewer triangles together are measured whole: their booleans cost about
what the cut itself does."""


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


def cut_to_meeting(
    a: manifold3d.Manifold, b: manifold3d.Manifold
) -> tuple[manifold3d.Manifold, manifold3d.Manifold, float]:
    """``a`` and ``b`` cut to the overlap of their bounding boxes grown by the margin
    ``m`` (:data:`CUT_MARGIN`), and ``m``: while ``b`` is shifted from ``a`` by less than
    ``m`` in each coordinate, the cut pair shares what the whole pair shares, through
    the same faces of ``a`` (module docstring). The triangles of each keep its original
    id. A pair of fewer than :data:`CUT_TRIANGLES` triangles is left whole (the margin
    is then infinite)."""
    if a.num_tri() + b.num_tri() < CUT_TRIANGLES:
        return a, b, np.inf
    low_a, high_a = np.split(np.asarray(a.bounding_box(), dtype=np.float64), 2)
    low_b, high_b = np.split(np.asarray(b.bounding_box(), dtype=np.float64), 2)
    diagonal = min(np.linalg.norm(high_a - low_a), np.linalg.norm(high_b - low_b))
    margin = CUT_MARGIN * float(diagonal)
    low = np.maximum(low_a, low_b) - margin
    high = np.minimum(high_a, high_b) + margin
    if np.any(low >= high) or margin <= 0:
        return a, b, np.inf
    box = manifold3d.Manifold.cube(tuple(high - low)).translate(tuple(low))
    return a ^ box, b ^ box, margin


def settle(
    meshes: Sequence[trimesh.Trimesh],
    pairs: Sequence[tuple[int, int]],
    solids: Sequence[manifold3d.Manifold] | None = None,
) -> Settlement:
    """The least-norm translations of ``meshes`` after which the ``pairs`` (indices into
    ``meshes``) no longer share volume, as far as Gauss–Newton on the shared volumes
    gets (module docstring). Pairs that share none stay out of the system. ``solids``:
    the meshes' manifold3d solids when already made.

    The rounds measure the pairs cut to where they meet (:func:`cut_to_meeting`). A cut
    solid's booleans resolve slivers more coarsely (their tolerance is the box's): when
    the cut pairs share nothing any more, the whole pairs are measured as well, and any
    sliver they still share is closed by rounds on them."""
    made = [solid(mesh) for mesh in meshes] if solids is None else solids
    solids = [each.as_original() for each in made]
    ids = [s.original_id() for s in solids]
    cut = [cut_to_meeting(solids[i], solids[j]) for i, j in pairs]

    def measure(x: NDArray[np.float64], whole: bool) -> list[tuple[float, NDArray[np.float64]]]:
        found = []
        for (i, j), (a, b, margin) in zip(pairs, cut, strict=True):
            if whole or np.abs(x[i] - x[j]).max() >= margin:
                a, b = solids[i], solids[j]
            found.append(
                overlap_gradient(a.translate(tuple(x[i])), b.translate(tuple(x[j])), ids[i])
            )
        return found

    start = np.zeros((len(meshes), 3))
    state = measure(start, whole=False)
    shifts, after = _descend(lambda x: measure(x, whole=False), pairs, start, state)
    if not any(after):
        shifts, after = _descend(
            lambda x: measure(x, whole=True), pairs, shifts, measure(shifts, whole=True)
        )
    return Settlement(tuple(pairs), shifts, tuple(volume for volume, _ in state), after)


def _descend(
    measure: Callable[[NDArray[np.float64]], list[tuple[float, NDArray[np.float64]]]],
    pairs: Sequence[tuple[int, int]],
    start: NDArray[np.float64],
    state: list[tuple[float, NDArray[np.float64]]],
) -> tuple[NDArray[np.float64], tuple[float, ...]]:
    """Gauss–Newton rounds (at most :data:`ROUNDS`) from the shifts ``start``, whose
    pairs' shared volumes and gradients are ``state``, on the volumes ``measure`` gives:
    the best shifts found and their pairs' volumes (module docstring)."""
    volumes = tuple(volume for volume, _ in state)
    best = (sum(volumes), start, volumes)
    for _ in range(ROUNDS):
        rows = [(p, v, g) for p, (v, g) in enumerate(state) if v > 0 and g @ g > 0]
        if not rows:
            break
        system = np.zeros((len(rows), start.size))
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
    return best[1], best[2]
