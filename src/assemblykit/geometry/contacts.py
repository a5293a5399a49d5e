"""Contacts between the parts of an assembly: the value types.

A :class:`Contact` joins two parts ``a`` and ``b`` that touch. It holds the planar
patches where their faces coincide with opposite normals, and the curved patches where
cylinders, cones or spheres coincide. Seeds 003 and 004 start from exactly this: "the
specification of the contact surfaces between parts".

Convention: every normal stored here is the outward normal of part ``a``'s surface, so
it points from ``a`` into ``b``. Translating ``a`` infinitesimally along ``d`` pushes
into ``b`` across a planar patch iff ``d . normal > 0`` (seed 004, DBG arcs).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

CurvedKind = Literal["cylindrical", "conical", "spherical"]


@dataclass(frozen=True, eq=False)
class PlanarPatch:
    """One planar contact polygon: ``polygon`` (k x 3, world, counter-clockwise seen
    from the tip of ``normal``), its ``area``, and ``normal`` pointing from ``a`` into ``b``."""

    normal: NDArray[np.float64]
    polygon: NDArray[np.float64]
    area: float

    @property
    def centroid(self) -> NDArray[np.float64]:
        """Mean of the polygon's vertices (a point on the contact plane)."""
        return np.asarray(self.polygon.mean(axis=0), dtype=np.float64)


@dataclass(frozen=True, eq=False)
class CurvedPatch:
    """A curved contact: coaxial cylinders or cones, or concentric spheres.

    ``center`` is a point on the axis (cylinder), the apex (cone) or the centre
    (sphere); ``axis`` is the unit axis (``None`` for spheres); ``radius`` the common
    radius (cylinders, spheres) and ``half_angle`` the cone's half-angle.
    ``inner`` names the part that is inside (the shaft or ball). ``extent`` is the axial
    interval ``(s0, s1)`` of the contact, measured from ``center`` along ``axis``.
    ``points`` samples the patch's boundary in world coordinates (for rigid-motion LPs).
    """

    kind: CurvedKind
    center: NDArray[np.float64]
    axis: NDArray[np.float64] | None
    radius: float
    inner: str
    extent: tuple[float, float] | None = None
    half_angle: float = 0.0
    points: NDArray[np.float64] | None = None


@dataclass(frozen=True, eq=False)
class Contact:
    """All contact surfaces between parts ``a`` and ``b``."""

    a: str
    b: str
    planar: tuple[PlanarPatch, ...] = ()
    curved: tuple[CurvedPatch, ...] = ()

    @property
    def area(self) -> float:
        """Summed area of the planar patches."""
        return float(sum(p.area for p in self.planar))

    @property
    def pair(self) -> tuple[str, str]:
        """The two part names, ``(a, b)``."""
        return (self.a, self.b)
