"""Former home of planar polygon assemblies: the data class is
:class:`assemblykit.model.polygons.PolygonAssembly`, its contacts and blocking terms are
in :mod:`assemblykit.blocking.planar`. The old names keep working, with a
:class:`DeprecationWarning` (docs/architecture.md, "Deprecated names")."""

from __future__ import annotations

from assemblykit.deprecation import moved

__getattr__ = moved(
    __name__,
    {
        "PolygonAssembly": "assemblykit.model.polygons",
        "PolygonContacts": "assemblykit.blocking.planar",
        "counter_clockwise": "assemblykit.blocking.planar",
        "edge_contacts": "assemblykit.blocking.planar",
        "section_polygons": "assemblykit.blocking.planar",
    },
)
