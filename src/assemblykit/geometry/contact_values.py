"""Contacts between the parts of an assembly: the value types.

A :class:`Contact` joins two parts ``a`` and ``b`` that touch. It holds the planar
patches where their faces coincide with opposite normals, and the curved patches where
cylinders, cones or spheres coincide. Liu 1997 and Wilson & Latombe 1992 start from exactly this:
"the specification of the contact surfaces between parts". :class:`Contacts` holds those
of a whole assembly, one per touching pair (docs/geometry.md, "The contact model");
:mod:`assemblykit.geometry.contacts` finds them.

Convention: every normal stored here is the outward normal of part ``a``'s surface, so
it points from ``a`` into ``b``. Translating ``a`` infinitesimally along ``d`` pushes
into ``b`` across a planar patch iff ``d . normal > 0`` (Wilson & Latombe 1992, DBG arcs).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from assemblykit.geometry.curved import (
    ARC_STEP,
    CONE_AZIMUTHS,
    TURN,
    arc_angles,
    revolution_normals,
)

CurvedKind = Literal["cylindrical", "conical", "spherical"]


@dataclass(frozen=True, eq=False)
class PlanarPatch:
    """One planar contact polygon: ``polygon`` (k x 3, world, counter-clockwise seen
    from the tip of ``normal``), its ``area``, and ``normal`` pointing from ``a`` into ``b``."""

    normal: NDArray[np.float64]
    polygon: NDArray[np.float64]
    area: float
    scatter: float = 0.0
    """How far the vertices of the two faces lie from their planes: the noise that makes
    the normal unsure (0 for exact faces)."""

    @property
    def centroid(self) -> NDArray[np.float64]:
        """Mean of the polygon's vertices (a point on the contact plane)."""
        return np.asarray(self.polygon.mean(axis=0), dtype=np.float64)

    def __repr__(self) -> str:
        from assemblykit import formatting as fmt

        return fmt.summary(
            "PlanarPatch",
            f"area {fmt.number(self.area)}",
            f"normal {fmt.direction(self.normal)}",
            fmt.count(len(self.polygon), "vertex", "vertices"),
        )


@dataclass(frozen=True, eq=False)
class CurvedPatch:
    """A curved contact: coaxial cylinders or cones, or concentric spheres.

    ``center`` is a point on the axis (cylinder), the apex (cone) or the centre
    (sphere); ``axis`` is the unit axis (``None`` for spheres); ``radius`` the common
    radius (cylinders, spheres) and ``half_angle`` the cone's half-angle.
    ``inner`` names the part that is inside (the shaft or ball). ``extent`` is the axial
    interval ``(s0, s1)`` of the contact, measured from ``center`` along ``axis``.
    ``normals`` (k x 3) are unit outward normals of the inner part on the part of the
    surface where the two really touch, whose non-negative combinations are every normal
    there (:mod:`assemblykit.geometry.curved`: a half-round groove gives a half circle of
    normals, a shallow cup a cap); ``None`` is the whole surface of revolution.
    ``points`` holds the contact region's vertices in world coordinates (for drawing).
    """

    kind: CurvedKind
    center: NDArray[np.float64]
    axis: NDArray[np.float64] | None
    radius: float
    inner: str
    extent: tuple[float, float] | None = None
    half_angle: float = 0.0
    points: NDArray[np.float64] | None = None
    normals: NDArray[np.float64] | None = None

    def __repr__(self) -> str:
        from assemblykit import formatting as fmt

        axis = "" if self.axis is None else f"axis {fmt.direction(self.axis)}"
        size = (
            f"half-angle {fmt.number(self.half_angle)}"
            if self.kind == "conical"
            else f"radius {fmt.number(self.radius)}"
        )
        return fmt.summary("CurvedPatch", self.kind, axis, size, f"inner {self.inner}")

    def normal_cone(self) -> NDArray[np.float64]:
        """Unit outward normals of the inner part generating the cone of the patch's
        normals (Wilson & Latombe 1992, "Infinitesimal translations": the inner part is blocked
        along ``d`` iff ``n . d > 0`` for one of them): ``normals``, or for the whole surface
        the four directions ``±e1, ±e2`` across a cylinder's axis, the six signed axes
        for a sphere, ``CONE_AZIMUTHS`` normals around a cone."""
        if self.normals is not None:
            return np.asarray(self.normals, dtype=np.float64).reshape(-1, 3)
        if self.kind == "spherical" or self.axis is None:
            return np.vstack([np.eye(3), -np.eye(3)])
        axis = np.asarray(self.axis, dtype=np.float64)
        if self.kind == "cylindrical":
            return revolution_normals(axis, arc_angles(np.array([[0.0, TURN]]), ARC_STEP))
        angles = arc_angles(np.array([[0.0, TURN]]), TURN / CONE_AZIMUTHS)
        return revolution_normals(axis, angles, self.half_angle)

    def samples(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Points of the patch with the inner part's outward unit normals there: each
        normal of :meth:`normal_cone` at both ends of the axial extent (cylinders,
        cones), or at ``center + radius n`` (spheres). The constraints of the unilateral
        and rigid readings at these points are those of the whole patch (module
        docstring of :mod:`assemblykit.geometry.curved`)."""
        normals = self.normal_cone()
        center = np.asarray(self.center, dtype=np.float64)
        if self.kind == "spherical" or self.axis is None:
            return center + self.radius * normals, normals
        axis = np.asarray(self.axis, dtype=np.float64)
        axis = axis / np.linalg.norm(axis)
        # the direction away from the axis where each normal holds
        radial = normals + math.sin(self.half_angle) * axis
        radial /= np.linalg.norm(radial, axis=1, keepdims=True)
        ends = self.extent if self.extent is not None else (0.0, 0.0)
        rings = []
        for s in ends:
            r = self.radius if self.kind == "cylindrical" else abs(s) * math.tan(self.half_angle)
            rings.append(center + s * axis + r * radial)
        return np.vstack(rings), np.vstack([normals, normals])


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

    def __repr__(self) -> str:
        from assemblykit import formatting as fmt

        planar = (
            f"{fmt.count(len(self.planar), 'planar patch', 'planar patches')}, "
            f"area {fmt.number(self.area)}"
            if self.planar
            else ""
        )
        curved = (
            f"{fmt.count(len(self.curved), 'curved patch', 'curved patches')}: "
            + ", ".join(p.kind for p in self.curved)
            if self.curved
            else ""
        )
        return fmt.summary("Contact", self.a, self.b, planar, curved)


class Contacts(list[Contact]):
    """The contacts of an assembly, one :class:`Contact` per touching pair (docs/geometry.md,
    "The contact model"): a list that prints as one line and shows as a table in notebooks,
    each pair's planar patches with their area and normals (from ``a`` into ``b``), and
    its curved patches by kind.

    >>> Contacts([Contact("peg", "block")])
    Contacts(1 touching pair, 0 planar patches, 0 curved patches)
    >>> Contacts()._repr_html_()[:40]
    '<p>Contacts(0 touching pairs, 0 planar p'
    """

    def __repr__(self) -> str:
        from assemblykit import formatting as fmt

        planar = sum(len(c.planar) for c in self)
        curved = sum(len(c.curved) for c in self)
        return fmt.summary(
            "Contacts",
            fmt.count(len(self), "touching pair"),
            fmt.count(planar, "planar patch", "planar patches"),
            fmt.count(curved, "curved patch", "curved patches"),
        )

    def _repr_html_(self) -> str:
        """The touching pairs as a table (notebooks)."""
        from assemblykit import formatting as fmt

        rows = [
            (
                c.a,
                c.b,
                str(len(c.planar)),
                fmt.number(c.area) if c.planar else "",
                fmt.name_list(sorted({fmt.direction(p.normal) for p in c.planar})),
                ", ".join(p.kind for p in c.curved),
            )
            for c in self
        ]
        headers = ("a", "b", "planar patches", "area", "normals (a into b)", "curved")
        return fmt.html_summary(repr(self), headers, rows)
