"""An assembly that finds its own contacts and surfaces, and a planar assembly of
polygons that shows itself as one (docs/tutorial.md §4; :mod:`assemblykit.api`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from assemblykit.features.primitives import Feature
from assemblykit.geometry.contact_values import Contacts
from assemblykit.geometry.contacts import assembly_contacts, assembly_surfaces
from assemblykit.geometry.polygons import PolygonContacts
from assemblykit.io import assembly as assembly_files
from assemblykit.io import polygons as polygon_files
from assemblykit.model import assembly as assembly_model
from assemblykit.model import polygons as polygon_model
from assemblykit.model.surfaces import Surface
from assemblykit.tolerance import Tolerance


class Assembly(assembly_model.Assembly):
    """An assembly of rigid parts (:class:`assemblykit.model.assembly.Assembly`) that finds
    its contacts and surfaces; a sub-assembly of it (``subset``, ``with_part``) is one too."""

    def contacts(self, tol: Tolerance | None = None) -> Contacts:
        """The contacts between touching parts, computed once per tolerance (Liu 1997 and
        Wilson & Latombe 1992 start from "the specification of the contact surfaces
        between parts"; :func:`assemblykit.geometry.contacts.assembly_contacts`): a list
        of :class:`~assemblykit.geometry.contacts.Contact` that shows as a table."""
        found = assembly_contacts(self, tol)
        return found if isinstance(found, Contacts) else Contacts(found)

    def surfaces(self, name: str, tol: Tolerance | None = None) -> tuple[Surface, ...]:
        """The surfaces of part ``name``: its exact CAD surfaces, else those recognised on
        its mesh (:func:`assemblykit.geometry.contacts.assembly_surfaces`)."""
        return assembly_surfaces(self, name, tol)

    def features(self, name: str, tol: Tolerance | None = None) -> list[Feature]:
        """The surface features of part ``name`` as :mod:`assemblykit.features` objects
        (Liu 1997 §2, oriented primitive features)."""
        return [s.feature() for s in self.surfaces(name, tol)]


class PolygonAssembly(polygon_model.PolygonAssembly):
    """A planar assembly of named polygons
    (:class:`assemblykit.model.polygons.PolygonAssembly`; Wilson & Latombe 1992,
    "2D case") that prints as one line and shows as a table: the value
    :func:`load_assembly` returns for a polygon file, which ``plan`` plans in the plane
    (docs/planning.md, "Planar assemblies")."""

    def __repr__(self) -> str:
        from assemblykit import formatting as fmt

        return fmt.summary(
            "PolygonAssembly",
            fmt.count(len(self.polygons), "part"),
            "2D",
            fmt.file_name(self.source),
        )

    def _repr_html_(self) -> str:
        """The polygons as a table: vertices and area (notebooks)."""
        from assemblykit import formatting as fmt

        rows = [
            (name, str(len(points)), fmt.number(_area(points)))
            for name, points in self.polygons.items()
        ]
        return fmt.html_summary(repr(self), ("part", "vertices", "area"), rows)

    def __len__(self) -> int:
        return len(self.polygons)

    def __contains__(self, name: object) -> bool:
        return name in self.polygons

    def contacts(self, tol: Tolerance | None = None) -> Contacts:
        """The contact segments between every two polygons, computed once per tolerance
        (:func:`assemblykit.geometry.polygons.polygon_contacts`), as a list that shows as
        a table."""
        found = assembly_contacts(self, tol)
        if isinstance(found, Contacts):
            return found
        shown = Contacts(found)
        self.memo.of(PolygonContacts).found[self.tolerance(tol)] = shown
        return shown


def _area(points: np.ndarray) -> float:
    """The area of a counter-clockwise polygon (k x 2), by the shoelace formula."""
    x, y = points[:, 0], points[:, 1]
    return float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y)) / 2


def load_assembly(
    path: str | Path, tol: Tolerance | None = None, settle: bool = True
) -> Assembly | PolygonAssembly:
    """Read an assembly in its assembled position from any input ``assemblykit`` reads.

    Mesh folders, YAML/JSON manifests, STEP files, COMPAS JSON, BurrTools puzzles and
    single mesh files give an :class:`Assembly` (docs/geometry.md, "Loaders and their
    conventions"; :func:`assemblykit.io.assembly.load_assembly`); a YAML file of 2D
    polygons, ``parts: {name: [[x, y], ...]}``, gives the :class:`PolygonAssembly` that
    ``plan`` plans in the plane (docs/planning.md, "Planar assemblies").

    Parameters
    ----------
    path : str or Path
        The file or mesh folder.
    tol : Tolerance, optional
        The tolerance policy of the assembly (the current one when ``None``); a polygon
        assembly takes its tolerance per call instead.
    settle : bool, default True
        Close the thin layers that rounded mesh-folder poses leave between parts.

    Returns
    -------
    Assembly or PolygonAssembly
        The parts, named and placed; it finds its own contacts (``contacts()``).

    Raises
    ------
    InputError
        The path is missing, the file cannot be read, or its content is not an assembly
        (a mesh that stays open, a polygon that is not simple, an unknown kind).
    MissingExtraError
        A STEP file without the ``cad`` extra installed.

    Examples
    --------
    >>> from pathlib import Path
    >>> import assemblykit
    >>> examples = Path(assemblykit.__file__).parent / "examples"
    >>> assemblykit.load_assembly(examples / "motion" / "hinge" / "hinge.yaml")
    Assembly(2 parts, mm, hinge.yaml)
    >>> hook = assemblykit.load_assembly(examples / "planar" / "hook.yaml")
    >>> hook
    PolygonAssembly(2 parts, 2D, hook.yaml)
    >>> hook.contacts()
    Contacts(1 touching pair, 2 planar patches, 0 curved patches)
    """
    if polygon_files.is_polygon_file(path):
        drawn = polygon_files.load_polygons(path)
        return PolygonAssembly(drawn.polygons, drawn.source)
    loaded = assembly_files.load_assembly(path, tol, settle)
    made = Assembly.like(loaded, scale=loaded.scale)
    made.memo = loaded.memo.restricted(set(loaded.parts))
    return made
