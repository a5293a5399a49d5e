"""The unilateral reading of contacts: which twists a part may make when faces only push.

Liu 1997 reads every contact as a fit: the surfaces stay coincident and the motions are
the symmetry group of the compound feature. A real face contact only pushes, so a part
may also move *away* from an obstacle. To first order, a twist ξ = (ω; v) of the moving
part (docs/architecture.md, "Conventions": ``v`` is the velocity of the point at the
origin) is allowed at a contact point ``p`` with unit normal ``n`` pointing out of the
moving part into the obstacle iff

    n · (v + ω × p) ≤ 0,    i.e.   a · ξ ≤ 0  with  a = (p × n; n).

The allowed twists form a polyhedral cone K = {ξ : A ξ ≤ 0}. Its lineality space
{A ξ = 0} is the first-order bilateral motion; a twist of K outside it breaks at least
one contact (a *lift-off*). For planar patches the vertices of each polygon suffice,
because the constraint is affine in ``p``; curved patches are sampled by the caller.

Reported here: whether K ≠ {0}, a witness lift-off twist (a lift-off translation when
there is one, else found by linear programming, scipy ``linprog`` with HiGHS), and the
translational part of K, {d : n · d ≤ 0 for all n},
as its sliding directions (lineality basis) and its lift-off rays (extreme rays of the
pointed part). A block on a table has sliding directions spanning the table and the
single lift-off ray +z: its free translations are the upper hemisphere.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import sparse
from scipy.optimize import linprog
from scipy.spatial import ConvexHull, cKDTree

from assemblykit.errors import NumericError
from assemblykit.tolerance import Tolerance, current

Vector = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class UnilateralReading:
    """The cone of free twists of a moving part under push-only contacts.

    ``free``: some non-zero twist is allowed (bilateral or lift-off). ``sliding``: an
    orthonormal basis of the translations that keep every contact. ``lift_off``: unit
    extreme rays of the free translations that break a contact. ``witness``: a twist
    ``(omega; v)`` of the free cone that breaks at least one contact (``None`` if every
    allowed twist keeps all contacts), ``v`` in model units per unit of ``omega``.
    """

    free: bool
    sliding: tuple[Vector, ...]
    lift_off: tuple[Vector, ...]
    witness: Vector | None

    @property
    def can_lift_off(self) -> bool:
        """Whether some allowed twist breaks a contact."""
        return self.witness is not None

    def to_dict(self) -> dict[str, Any]:
        """``free``, ``lift_off`` and ``sliding`` (lists of unit vectors), ``witness``
        (``{omega, v}`` or ``None``)."""
        witness = (
            None
            if self.witness is None
            else {"omega": self.witness[:3].tolist(), "v": self.witness[3:].tolist()}
        )
        return {
            "free": self.free,
            "lift_off": [d.tolist() for d in self.lift_off],
            "sliding": [d.tolist() for d in self.sliding],
            "witness": witness,
        }


def constraint_rows(points: NDArray[np.float64], normals: NDArray[np.float64]) -> NDArray:
    """The rows ``a = (p × n; n)`` of ``A ξ ≤ 0``, one per contact point (module docstring)."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    normals = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    return np.hstack([np.cross(points, normals), normals])


def _null_space(matrix: NDArray[np.float64], threshold: float, dim: int) -> NDArray:
    """Orthonormal rows spanning {x : matrix x = 0}, singular values ≤ ``threshold`` as zero."""
    if matrix.shape[0] == 0:
        return np.eye(dim)
    # with at least ``dim`` rows the reduced SVD already holds every right singular vector
    _, sigma, vt = np.linalg.svd(matrix, full_matrices=matrix.shape[0] < dim)
    rank = int(np.count_nonzero(sigma > threshold))
    return vt[rank:]


def _unique_directions(vectors: NDArray[np.float64], tol: Tolerance) -> NDArray:
    """Unit vectors with repeats (within the angle tolerance, found with a k-d tree)
    removed: of every group of near-equal vectors the first is kept."""
    vectors = np.asarray(vectors, dtype=np.float64).reshape(-1, 3)
    if len(vectors) < 2:
        return vectors
    pairs = cKDTree(vectors).query_pairs(tol.angle, output_type="ndarray")
    repeated = np.zeros(len(vectors), dtype=bool)
    repeated[pairs.max(axis=1)] = True
    return vectors[~repeated]


def translation_cone(
    normals: NDArray[np.float64], tol: Tolerance | None = None
) -> tuple[tuple[Vector, ...], tuple[Vector, ...]]:
    """The free translations {d : n · d ≤ 0 for every normal} as ``(sliding, rays)``.

    ``sliding`` is an orthonormal basis of the lineality space (directions keeping every
    contact) and ``rays`` the unit extreme rays of the cone's pointed part, which lies in
    the orthogonal complement of ``sliding``. The pointed part is the polar of the cone
    spanned by the normals; its extreme rays are the outward normals of the facets of
    conv({0} ∪ normals) that pass through the origin (scipy ``ConvexHull``, so the cost
    is O(m log m) in the number of contact normals).
    """
    tol = current() if tol is None else tol
    normals = _unique_directions(normals, tol)
    sliding = _null_space(normals, tol.angle, 3)
    if len(sliding) == 3:
        return tuple(sliding), ()
    basis = _null_space(sliding, tol.angle, 3) if len(sliding) else np.eye(3)
    rays = _polar_rays(normals @ basis.T, tol) @ basis
    return tuple(sliding), tuple(_unique_directions(rays, tol))


def _polar_rays(coords: NDArray[np.float64], tol: Tolerance) -> NDArray[np.float64]:
    """Unit extreme rays of {d : c · d ≤ 0 for every row c} when the rows span the space
    (``coords`` is m x k, k = 1, 2 or 3)."""
    k = coords.shape[1]
    if k == 1:
        signs = np.sign(coords[:, 0])
        return -signs[:1, None] if np.all(signs == signs[0]) else np.zeros((0, 1))
    hull = ConvexHull(np.vstack([np.zeros(k), coords]))
    # hull.equations rows (a, b): a · x + b ≤ 0 inside, a the unit outward normal
    through_origin = np.abs(hull.equations[:, -1]) <= tol.angle
    return hull.equations[through_origin, :-1]


def lift_off_witnesses(
    sets: Sequence[tuple[NDArray[np.float64], NDArray[np.float64]]],
    scale: float = 1.0,
    tol: Tolerance | None = None,
) -> list[Vector | None]:
    """For each ``(points, normals)``: a twist ``(omega; v)`` with every ``a · ξ ≤ 0``
    and some ``a · ξ < 0``, or ``None`` when every allowed twist keeps all contacts.

    One linear program (HiGHS) per set: maximise the summed slack -Σ aᵢ·ξ over A ξ ≤ 0
    within a box; the optimum is positive iff some contact can be broken. The sets are
    independent, so they are solved together as one block-diagonal (sparse) program:
    one solver call however many parts. Points are centred and divided by ``scale`` so
    that rotations and translations weigh alike; each witness is returned in world
    coordinates, normalised so that ``(omega, v / scale)`` is a unit.
    """
    tol = current() if tol is None else tol
    blocks, centers = [], []
    for points, normals in sets:
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        center = points.mean(axis=0) if len(points) else np.zeros(3)
        blocks.append(constraint_rows((points - center) / scale, normals))
        centers.append(center)
    if not blocks or not any(len(b) for b in blocks):
        return [None] * len(blocks)
    matrix = sparse.block_diag([b if len(b) else np.zeros((0, 6)) for b in blocks], "csr")
    found = linprog(
        np.concatenate([b.sum(axis=0) for b in blocks]),
        A_ub=matrix,
        b_ub=np.zeros(matrix.shape[0]),
        bounds=[(-1.0, 1.0)] * matrix.shape[1],
        method="highs",
    )
    if found.status != 0:
        raise NumericError(f"lift-off linear program failed: {found.message}")
    witnesses: list[Vector | None] = []
    for i, (block, center) in enumerate(zip(blocks, centers, strict=True)):
        twist = found.x[6 * i : 6 * i + 6]
        if len(block) == 0 or -float(block.sum(axis=0) @ twist) <= tol.angle:
            witnesses.append(None)
            continue
        twist = twist / np.linalg.norm(twist)
        # velocity at the world origin from the velocity at the centre: v0 = v(c) - w x c
        witnesses.append(
            np.concatenate([twist[:3], scale * twist[3:] - np.cross(twist[:3], center)])
        )
    return witnesses


def unilateral_readings(
    sets: Sequence[tuple[NDArray[np.float64], NDArray[np.float64]]],
    scale: float = 1.0,
    tol: Tolerance | None = None,
) -> list[UnilateralReading]:
    """The unilateral reading of each ``(points, normals)`` (normals out of the moving
    set): the translation cone per set, and one batched program for the witnesses of
    the sets that no translation lifts off."""
    tol = current() if tol is None else tol
    cones, bilateral = [], []
    for points, normals in sets:
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        center = points.mean(axis=0) if len(points) else np.zeros(3)
        rows = constraint_rows((points - center) / scale, normals)
        bilateral.append(len(_null_space(rows, tol.angle, 6)) > 0)
        cones.append(translation_cone(normals, tol))
    # a lift-off ray is already a witness; the linear program is needed only without one
    pending = [i for i, (_, rays) in enumerate(cones) if not rays]
    witnesses = lift_off_witnesses([sets[i] for i in pending], scale, tol)
    solved = dict(zip(pending, witnesses, strict=True))
    readings = []
    for i, (sliding, rays) in enumerate(cones):
        witness = np.concatenate([np.zeros(3), rays[0]]) if rays else solved[i]
        readings.append(
            UnilateralReading(
                free=bilateral[i] or witness is not None,
                sliding=sliding,
                lift_off=rays,
                witness=witness,
            )
        )
    return readings


def unilateral_reading(
    points: NDArray[np.float64],
    normals: NDArray[np.float64],
    scale: float = 1.0,
    tol: Tolerance | None = None,
) -> UnilateralReading:
    """The unilateral reading of contact points with normals out of the moving part."""
    return unilateral_readings([(points, normals)], scale, tol)[0]
