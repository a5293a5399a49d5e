"""Planar assemblies of polygonal parts (Wilson & Latombe 1992, "2D case"): the data.

A :class:`PolygonAssembly` is named simple polygons in the plane z = 0, counter-clockwise,
in assembled position: read from a YAML file by :mod:`assemblykit.io.polygons` or cut
from 3D meshes by a plane (:func:`assemblykit.geometry.polygons.section_polygons`). It is
an :class:`~assemblykit.model.assembly.AssemblyLike` of ``dimension`` 2 and ``kind``
``"polygons"``: the layers above give their planar variant for it, side by side with
the one for meshes (its contact segments and exact blocking terms in
:mod:`assemblykit.blocking.planar`, its search in :mod:`assemblykit.planning.planar`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar, Literal

import numpy as np
from numpy.typing import NDArray
from shapely.geometry import Polygon

from assemblykit.errors import UnknownNameError
from assemblykit.model.assembly import Memo, Overlap
from assemblykit.tolerance import ModelTolerance, Tolerance, current


@dataclass(eq=False)
class PolygonAssembly:
    """Named counter-clockwise polygons (k x 2) in the plane, in assembled position;
    ``memo`` keeps what was derived from them (:class:`~assemblykit.model.assembly.Memo`)."""

    polygons: dict[str, NDArray[np.float64]]
    source: str | None = None
    memo: Memo = field(default_factory=Memo, repr=False)

    dimension: ClassVar[Literal[2]] = 2
    """The space the parts move in: the plane."""

    kind: ClassVar[Literal["polygons"]] = "polygons"
    """What the parts are: polygons."""

    @property
    def names(self) -> list[str]:
        """Part names in order."""
        return list(self.polygons)

    @property
    def overlaps(self) -> tuple[Overlap, ...]:
        """No interfering pairs are resolved for polygons (an assembly of meshes lists
        those :func:`~assemblykit.geometry.overlaps.resolve_overlaps` found)."""
        return ()

    @property
    def joined(self) -> dict[str, tuple[str, ...]]:
        """No parts are joined for polygons (an assembly of meshes lists its joined
        parts' members)."""
        return {}

    def sizes(self) -> dict[str, float]:
        """The area of each polygon, by name in order."""
        return {name: float(Polygon(poly).area) for name, poly in self.polygons.items()}

    @property
    def scale(self) -> float:
        """Diagonal of the bounding box of all polygons (1 when empty)."""
        if not self.polygons:
            return 1.0
        pts = np.concatenate(list(self.polygons.values()))
        diag = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))
        return diag if diag > 0 else 1.0

    def tolerance(self, tol: Tolerance | None = None) -> ModelTolerance:
        """The tolerance policy ``tol`` (the current one when ``None``) scaled to this
        drawing; ``tol`` itself when it is this drawing's already."""
        if isinstance(tol, ModelTolerance) and tol.scale == self.scale:
            return tol
        return ModelTolerance.of((tol or current()).with_scale(self.scale))

    def subset(self, names: list[str]) -> PolygonAssembly:
        """The polygons named; its memo keeps what this one's holds for them."""
        missing = set(names) - set(self.polygons)
        if missing:
            raise UnknownNameError(f"no part named {sorted(missing)[0]!r}", source=self.source)
        return PolygonAssembly(
            {n: self.polygons[n] for n in self.polygons if n in names},
            self.source,
            memo=self.memo.restricted(set(names)),
        )
