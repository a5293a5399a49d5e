"""Former home of planar polygon assemblies: the data class is
:class:`assemblykit.model.polygons.PolygonAssembly`, its contacts are in
:mod:`assemblykit.geometry.polygons` and its blocking terms in
:mod:`assemblykit.blocking.planar`. The old names keep working, with a
:class:`DeprecationWarning` (docs/architecture.md, "Deprecated names")."""

from __future__ import annotations

from assemblykit.deprecation import moved

__getattr__ = moved(
    __name__,
    {
        "PolygonAssembly": "assemblykit.model.polygons",
        "PolygonContacts": "assemblykit.geometry.polygons",
        "counter_clockwise": "assemblykit.geometry.polygons",
        "edge_contacts": "assemblykit.geometry.polygons",
        "section_polygons": "assemblykit.geometry.polygons",
    },
)
