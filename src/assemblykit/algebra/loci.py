"""Orbits of points under symmetry groups (docs/algebra.md §2.3 orbit table): points,
circles, lines, helices, cylinders, planes, spheres, all of space, and unions of them
over the discrete components of a group.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum

import numpy as np
from numpy.typing import NDArray

from assemblykit.algebra import se3
from assemblykit.algebra.lie import helix_residual
from assemblykit.errors import GroupError
from assemblykit.tolerance import Tolerance, current

__all__ = ["Locus", "LocusKind"]


class LocusKind(StrEnum):
    """The shapes an orbit takes (docs/algebra.md §2.3 orbit table)."""

    POINT = "point"
    CIRCLE = "circle"
    LINE = "line"
    HELIX = "helix"
    CYLINDER = "cylinder"
    PLANE = "plane"
    SPHERE = "sphere"
    SPACE = "space"
    UNION = "union"


@dataclass(frozen=True, eq=False)
class Locus:
    """The orbit of a point under a group (docs/algebra.md §2.3 orbit table).

    ``kind`` is a :class:`LocusKind`. ``point`` is the point itself (point), the centre
    (circle, sphere), a point on the axis (line, helix, cylinder: the axis point) or a
    point of the plane;
    ``direction`` the axis or normal; ``radius`` for circle/helix/cylinder/sphere;
    ``pitch`` and ``through`` (a point of the curve) for a helix; ``members`` and
    ``steps`` (lattice translations) for a union.
    """

    kind: LocusKind
    point: NDArray[np.float64] | None = None
    direction: NDArray[np.float64] | None = None
    radius: float = 0.0
    pitch: float = 0.0
    through: NDArray[np.float64] | None = None
    members: tuple[Locus, ...] = ()
    steps: tuple[NDArray[np.float64], ...] = ()

    def contains(self, p: NDArray[np.float64], tol: Tolerance | None = None) -> bool:
        """Whether the point ``p`` lies on the locus."""
        tol = tol or current()
        q = np.asarray(p, dtype=np.float64)
        if self.kind == LocusKind.SPACE:
            return True
        if self.kind == LocusKind.UNION:
            return self._union_contains(q, tol)
        assert self.point is not None
        d = q - self.point
        if self.kind == LocusKind.POINT:
            return se3.norm(d) <= tol.length
        if self.kind == LocusKind.SPHERE:
            return abs(se3.norm(d) - self.radius) <= tol.length
        assert self.direction is not None
        u = self.direction
        along = float(d @ u)
        radial = d - along * u
        if self.kind == LocusKind.PLANE:
            return abs(along) <= tol.length
        if self.kind == LocusKind.LINE:
            return se3.norm(radial) <= tol.length
        rho = se3.norm(radial)
        if self.kind == LocusKind.CYLINDER:
            return abs(rho - self.radius) <= tol.length
        if self.kind == LocusKind.CIRCLE:
            return abs(along) <= tol.length and abs(rho - self.radius) <= tol.length
        return self._helix_contains(d, along, radial, rho, tol)

    def distance(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        """The distances of ``points`` (n x 3) from the locus, for the kinds a closed
        curve or surface has: point, circle, line, cylinder, plane, sphere, space.

        A circle's nearest point to ``p`` lies on the ray from the centre towards ``p``'s
        projection into its plane, at distance ``√(along² + (ρ − r)²)``."""
        q = np.atleast_2d(np.asarray(points, dtype=np.float64))
        if self.kind == LocusKind.SPACE:
            return np.zeros(len(q))
        if self.kind in (LocusKind.HELIX, LocusKind.UNION) or self.point is None:
            raise GroupError(f"no distance to a {self.kind} locus")
        d = q - self.point
        if self.kind in (LocusKind.POINT, LocusKind.SPHERE):
            r: NDArray[np.float64] = np.linalg.norm(d, axis=1)
            return r if self.kind == LocusKind.POINT else np.abs(r - self.radius)
        assert self.direction is not None
        along = d @ self.direction
        rho: NDArray[np.float64] = np.linalg.norm(d - along[:, None] * self.direction, axis=1)
        if self.kind == LocusKind.PLANE:
            return np.abs(along)
        if self.kind == LocusKind.LINE:
            return rho
        if self.kind == LocusKind.CYLINDER:
            return np.abs(rho - self.radius)
        return np.hypot(along, rho - self.radius)

    def _helix_contains(
        self,
        d: NDArray[np.float64],
        along: float,
        radial: NDArray[np.float64],
        rho: float,
        tol: Tolerance,
    ) -> bool:
        assert self.through is not None and self.point is not None and self.direction is not None
        u = self.direction
        d0 = self.through - self.point
        along0 = float(d0 @ u)
        radial0 = d0 - along0 * u
        if abs(rho - self.radius) > tol.length:
            return False
        angle = math.atan2(float(se3.cross(radial0, radial) @ u), float(radial0 @ radial))
        return helix_residual(self.pitch, along - along0, angle) <= tol.length

    def _union_contains(self, q: NDArray[np.float64], tol: Tolerance) -> bool:
        if not self.steps:
            return any(m.contains(q, tol) for m in self.members)
        step = self.steps[0]
        for m in self.members:
            assert m.point is not None
            k = round(float((q - m.point) @ step) / float(step @ step))
            if any(m.contains(q - j * step, tol) for j in (k - 1, k, k + 1)):
                return True
        return False
