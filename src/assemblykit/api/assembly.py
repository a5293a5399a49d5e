"""An assembly that finds its own contacts and surfaces (DESIGN.md §5.4;
:mod:`assemblykit.api`)."""

from __future__ import annotations

from pathlib import Path

from assemblykit.features.primitives import Feature
from assemblykit.geometry.contacts import Contact, assembly_contacts, assembly_surfaces
from assemblykit.io import assembly as assembly_files
from assemblykit.model import assembly as assembly_model
from assemblykit.model.surfaces import Surface
from assemblykit.tolerance import Tolerance


class Assembly(assembly_model.Assembly):
    """An assembly of rigid parts (:class:`assemblykit.model.assembly.Assembly`) that finds
    its contacts and surfaces; a sub-assembly of it (``subset``, ``with_part``) is one too."""

    def contacts(self, tol: Tolerance | None = None) -> list[Contact]:
        """The contacts between touching parts, computed once per tolerance (Liu 1997 and
        Wilson & Latombe 1992 start from "the specification of the contact surfaces
        between parts"; :func:`assemblykit.geometry.contacts.assembly_contacts`)."""
        return assembly_contacts(self, tol)

    def surfaces(self, name: str, tol: Tolerance | None = None) -> tuple[Surface, ...]:
        """The surfaces of part ``name``: its exact CAD surfaces, else those recognised on
        its mesh (:func:`assemblykit.geometry.contacts.assembly_surfaces`)."""
        return assembly_surfaces(self, name, tol)

    def features(self, name: str, tol: Tolerance | None = None) -> list[Feature]:
        """The surface features of part ``name`` as :mod:`assemblykit.features` objects
        (Liu 1997 §2, oriented primitive features)."""
        return [s.feature() for s in self.surfaces(name, tol)]


def load_assembly(path: str | Path, tol: Tolerance | None = None, settle: bool = True) -> Assembly:
    """The assembly stored at ``path`` (:func:`assemblykit.io.assembly.load_assembly`);
    ``tol`` becomes its policy; ``settle`` closes thin layers left by rounded mesh-folder
    poses."""
    loaded = assembly_files.load_assembly(path, tol, settle)
    made = Assembly.like(loaded, scale=loaded.scale)
    made.memo = loaded.memo
    return made
