"""A surface of a part: plane, cylinder, cone, sphere or torus, in world coordinates (Liu
1997 §2, oriented primitive features).

A plain value: read exactly from CAD (:mod:`assemblykit.io.step`) and kept on the
:class:`~assemblykit.model.assembly.Part`, or recognised on a triangle mesh
(:mod:`assemblykit.geometry.recognition`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from assemblykit.features.primitives import Ball, Cone, Feature, Hole, Plane, Shaft, Socket, Torus

SurfaceKind = Literal["plane", "cylinder", "cone", "sphere", "torus"]


@dataclass(frozen=True, eq=False)
class Surface:
    """One surface of a part, in world coordinates.

    ``point``: a point of the plane, the axis foot at the start of the surface
    (cylinder), the apex (cone), the centre (sphere, torus). ``axis``: the outward normal
    (plane) or the unit axis (cylinder, cone from apex to opening, torus); ``None`` for
    spheres. ``convex``: the material is inside (shaft, ball, male cone). ``extent``:
    the interval ``(s0, s1)`` covered along the axis from ``point``. ``faces``: the
    triangles of the part's mesh on this surface.
    """

    kind: SurfaceKind
    point: NDArray[np.float64]
    axis: NDArray[np.float64] | None
    faces: NDArray[np.int64]
    area: float
    radius: float = 0.0
    half_angle: float = 0.0
    minor_radius: float = 0.0
    convex: bool = True
    extent: tuple[float, float] = (0.0, 0.0)

    def feature(self) -> Feature:
        """The :mod:`assemblykit.features` primitive of this surface (Liu 1997 §2)."""
        if self.kind == "sphere":
            return (Ball if self.convex else Socket)(point=self.point, radius=self.radius)
        axis = self.axis
        assert axis is not None
        if self.kind == "plane":
            return Plane(point=self.point, normal=axis)
        if self.kind == "cylinder":
            cls = Shaft if self.convex else Hole
            return cls(point=self.point, axis=axis, radius=self.radius, directed=False)
        if self.kind == "cone":
            return Cone(point=self.point, axis=axis, half_angle=self.half_angle, male=self.convex)
        return Torus(
            point=self.point,
            axis=axis,
            major_radius=self.radius,
            minor_radius=self.minor_radius,
            male=self.convex,
        )

    def on_faces(self, faces: NDArray[np.int64], corners: NDArray[np.float64]) -> Surface:
        """This surface over the triangles ``faces`` alone (their corners ``corners``,
        ``len(faces) x 3 x 3``): its area, and for a cylinder or cone its extent along
        the axis (and a cylinder's foot), measured again on them. Used when a boolean
        cuts a part and some triangles of a surface remain (docs/planning.md,
        "Interfering parts")."""
        edges = corners[:, 1:] - corners[:, :1]
        area = float(np.linalg.norm(np.cross(edges[:, 0], edges[:, 1]), axis=1).sum() / 2)
        point, extent = self.point, self.extent
        if self.kind in ("cylinder", "cone") and len(faces):
            assert self.axis is not None
            along = (corners.reshape(-1, 3) - self.point) @ self.axis
            if self.kind == "cylinder":
                point = self.point + along.min() * self.axis
                extent = (0.0, float(np.ptp(along)))
            else:
                extent = (float(along.min()), float(along.max()))
        return replace(self, point=point, faces=faces, area=area, extent=extent)
