"""``load_assembly``: read any assembly input (docs/geometry.md, "Loaders and their
conventions"), dispatching by kind.

* a folder → mesh folder (:func:`assemblykit.io.meshes.load_mesh_folder`);
* ``.yaml`` / ``.yml``, or ``.json`` with a top-level ``parts`` list → manifest;
* ``.step`` / ``.stp`` → STEP (:func:`assemblykit.io.step.load_step`, extra ``cad``);
* ``.xmpuzzle`` → BurrTools puzzle, as its first stored solution
  (:func:`assemblykit.io.burrtools.load_burrtools`);
* other ``.json`` → COMPAS (:func:`assemblykit.io.compas.load_compas`);
* a single mesh file → a one-part assembly.

:func:`contact_report` gathers what the ``contacts`` command shows.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from assemblykit.errors import GeometryError, InputError
from assemblykit.geometry.contact_values import Contact
from assemblykit.geometry.contacts import assembly_contacts, assembly_surfaces
from assemblykit.geometry.precision import mesh_precision
from assemblykit.io.documents import read_json, read_text
from assemblykit.io.meshes import MESH_SUFFIXES, load_manifest, load_mesh_folder, read_mesh
from assemblykit.model.assembly import Assembly, Part
from assemblykit.model.surfaces import Surface
from assemblykit.tolerance import Tolerance


def _is_manifest_json(path: Path) -> bool:
    try:
        data = read_json(read_text(path), str(path))
    except InputError:
        return False  # the COMPAS reader names the fault
    return isinstance(data, dict) and isinstance(data.get("parts"), list)


def load_assembly(path: str | Path, tol: Tolerance | None = None, settle: bool = True) -> Assembly:
    """The assembly stored at ``path`` (module docstring); ``tol`` becomes its policy;
    ``settle`` closes thin layers left by rounded mesh-folder poses
    (:func:`assemblykit.io.meshes.load_mesh_folder`)."""
    path = Path(path)
    if path.is_dir():
        return load_mesh_folder(path, tol, settle)
    if not path.exists():
        raise InputError("no such file or folder", source=str(path))
    suffix = path.suffix.lower()
    if suffix in (".yaml", ".yml") or (suffix == ".json" and _is_manifest_json(path)):
        return load_manifest(path, tol)
    if suffix == ".json":
        from assemblykit.io.compas import load_compas

        return load_compas(path, tol)
    if suffix in (".step", ".stp"):
        from assemblykit.io.step import load_step

        return load_step(path, tol)
    if suffix == ".xmpuzzle":
        from assemblykit.io.burrtools import load_burrtools

        return load_burrtools(path, tol)
    if suffix in MESH_SUFFIXES:
        notes: list[str] = []
        part = Part(path.stem, read_mesh(path, notes), source=str(path))
        return Assembly(
            [part],
            source=str(path),
            policy=tol,
            precision=mesh_precision(part.mesh),
            warnings=notes,
        )
    raise GeometryError(
        "unknown assembly kind (expected a mesh folder, .yaml manifest, .step, COMPAS .json "
        "or .xmpuzzle)",
        source=str(path),
    )


def _surface_dict(surface: Surface) -> dict[str, Any]:
    entry: dict[str, Any] = {"type": surface.feature().type_name, "point": surface.point.tolist()}
    if surface.kind == "plane":
        entry["normal"] = surface.axis.tolist() if surface.axis is not None else None
    elif surface.axis is not None:
        entry["axis"] = surface.axis.tolist()
    if surface.kind in ("cylinder", "sphere", "torus"):
        entry["radius"] = surface.radius
    if surface.kind == "cone":
        entry["half_angle"] = surface.half_angle
    entry["area"] = surface.area
    return entry


def _contact_dict(contact: Contact) -> dict[str, Any]:
    return {
        "a": contact.a,
        "b": contact.b,
        "area": contact.area,
        "planar": [
            {"normal": p.normal.tolist(), "area": p.area, "polygon": p.polygon.tolist()}
            for p in contact.planar
        ],
        "curved": [
            {
                "kind": c.kind,
                "center": c.center.tolist(),
                "axis": None if c.axis is None else c.axis.tolist(),
                "radius": c.radius,
                "inner": c.inner,
                "extent": None if c.extent is None else list(c.extent),
                "half_angle": c.half_angle,
            }
            for c in contact.curved
        ],
    }


@dataclass(frozen=True)
class ContactReport:
    """What the ``contacts`` command reports: the assembly's parts with their surface
    features, its contacts and its interferences ``(a, b, volume)``, found with the
    tolerance ``policy`` (``None``: the assembly's own) raised to the input's measured
    precision."""

    assembly: Assembly
    contacts: list[Contact]
    surfaces: dict[str, tuple[Surface, ...]]
    interferences: list[tuple[str, str, float]]
    policy: Tolerance | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON form: the assembly summary, ``features`` per part, the ``tolerance`` used
        and why (:meth:`Assembly.tolerance_summary`), ``contacts`` and ``interferences``."""
        summary = self.assembly.to_dict()
        for name, entry in summary["parts"].items():
            entry["features"] = [_surface_dict(s) for s in self.surfaces[name]]
        summary["tolerance"] = self.assembly.tolerance_summary(self.policy)
        summary["contacts"] = [_contact_dict(c) for c in self.contacts]
        summary["interferences"] = [{"a": a, "b": b, "volume": v} for a, b, v in self.interferences]
        return summary


def contact_report(assembly: Assembly, tol: Tolerance | None = None) -> ContactReport:
    """Contacts, surface features and interferences of ``assembly``."""
    from assemblykit.geometry.interference import interferences

    return ContactReport(
        assembly,
        assembly_contacts(assembly, tol),
        {name: assembly_surfaces(assembly, name, tol) for name in assembly.parts},
        interferences(assembly, tol),
        tol,
    )
