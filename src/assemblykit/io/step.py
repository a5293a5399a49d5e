"""Assemblies from STEP files (DESIGN.md §5.2; extra ``cad``: OCP from
``cadquery-ocp-novtk``, imported only when a STEP file is read).

Each solid is one part, named from the file's product structure (ISO 10303-44: each
``PRODUCT`` is placed by ``NEXT_ASSEMBLY_USAGE_OCCURRENCE`` entities in the product that
uses it), read through OCP's XCAF document: a solid is named after the product it makes
up, and the instances of a product used several times are numbered in file order
(``pin_1``, ``pin_2``, ...). A solid without a product name of its own (a product of
several solids, an unnamed one, or one with the placeholder name Open CASCADE's writer
gives unnamed shapes) is ``solid<i>``, ``i`` its 1-based place among all
solids. The products that are assemblies below the whole (subassemblies) become the
assembly's ``groups``, named and numbered the same way, each listing the parts it holds
(``motion --subassembly NAME`` takes one).

Each part's faces keep their exact surface (plane, cylinder, cone, sphere, torus, with
axes and radii) for feature recognition (Liu 1997, §2), and are
tessellated into the part's mesh; the triangles of each face are recorded so contacts
can tell which surface they lie on. Faces of other surface types are only tessellated.
OCP reads STEP lengths in millimetres.

Tessellation: linear deflection ``LINEAR_DEFLECTION`` x the solid's bounding-box
diagonal and angular deflection ``ANGULAR_DEFLECTION`` (below the smooth-edge angle of
:mod:`assemblykit.geometry.recognition`).

A damaged file is read as far as OCP can, and what it dropped is said: the solid
entities declared in the file (``MANIFOLD_SOLID_BREP``, ``BREP_WITH_VOIDS``,
``FACETED_BREP``) that OCP could not read, or whose shell lost its faces, are listed in
the assembly's ``skipped`` items. OCP prints its parse errors on the process's own
standard output (file descriptor 1, with terminal colour codes), where they would break
``--json`` output: descriptor 1 is redirected to a temporary file while OCP reads, and
what it said becomes the assembly's ``warnings``.
"""

from __future__ import annotations

import contextlib
import ctypes
import importlib
import os
import re
import sys
import tempfile
from collections import Counter
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import trimesh
from numpy.typing import NDArray

from assemblykit.errors import GeometryError, MissingExtraError
from assemblykit.geometry.recognition import is_convex
from assemblykit.model.assembly import Assembly, Part, Skipped
from assemblykit.model.surfaces import Surface
from assemblykit.tolerance import Tolerance

LINEAR_DEFLECTION = 1e-3
ANGULAR_DEFLECTION = 0.2
SOLID_ENTITIES = ("MANIFOLD_SOLID_BREP", "BREP_WITH_VOIDS", "FACETED_BREP")
_SOLID_TYPES = {
    "StepShape_ManifoldSolidBrep",
    "StepShape_BrepWithVoids",
    "StepShape_FacetedBrep",
}
_DECLARED = re.compile(
    r"#(\d+)\s*=\s*(" + "|".join(SOLID_ENTITIES) + r")\s*\(\s*'((?:[^']|'')*)'", re.IGNORECASE
)
_ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")
_PLACEHOLDER = re.compile(r"Open CASCADE STEP translator [\d.]+ [\d.]+")
"""The product name Open CASCADE's STEP writer gives a shape that has none."""


_OCP_NAMES = {
    "Bnd": ("Bnd_Box",),
    "BRep": ("BRep_Tool",),
    "BRepAdaptor": ("BRepAdaptor_Surface",),
    "BRepBndLib": ("BRepBndLib",),
    "BRepMesh": ("BRepMesh_IncrementalMesh",),
    "GeomAbs": ("GeomAbs_SurfaceType",),
    "collections": ("Sequence_TDF_Label",),
    "IFSelect": ("IFSelect_ReturnStatus",),
    "STEPCAFControl": ("STEPCAFControl_Reader",),
    "TCollection": ("TCollection_ExtendedString",),
    "TDataStd": ("TDataStd_Name",),
    "TDF": ("TDF_Label",),
    "TDocStd": ("TDocStd_Document",),
    "TopAbs": ("TopAbs_Orientation", "TopAbs_ShapeEnum"),
    "TopExp": ("TopExp_Explorer",),
    "TopLoc": ("TopLoc_Location",),
    "TopoDS": ("TopoDS",),
    "XCAFDoc": ("XCAFDoc_DocumentTool",),
}


def _ocp() -> Any:
    """The OCP names used here, or :class:`MissingExtraError` when OCP is absent."""
    try:
        modules = {m: importlib.import_module(f"OCP.{m}") for m in _OCP_NAMES}
    except ImportError:
        raise MissingExtraError("cadquery-ocp-novtk", "cad", "reading STEP files") from None
    return SimpleNamespace(
        **{n: getattr(modules[m], n) for m, names in _OCP_NAMES.items() for n in names}
    )


def _vec(xyz: Any) -> NDArray[np.float64]:
    return np.array([xyz.X(), xyz.Y(), xyz.Z()], dtype=np.float64)


def _face_triangles(ocp: Any, face: Any) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """The triangulation of a face in world coordinates, oriented outward."""
    location = ocp.TopLoc_Location()
    triangulation = ocp.BRep_Tool.Triangulation_s(face, location)
    if triangulation is None:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    transform = location.Transformation()
    points = np.array(
        [
            _vec(triangulation.Node(i).Transformed(transform))
            for i in range(1, triangulation.NbNodes() + 1)
        ]
    )
    triangles = (
        np.array(
            [triangulation.Triangle(i).Get() for i in range(1, triangulation.NbTriangles() + 1)],
            dtype=np.int64,
        )
        - 1
    )
    if face.Orientation() == ocp.TopAbs_Orientation.TopAbs_REVERSED:
        triangles = triangles[:, ::-1]
    return points, triangles


def _surface(
    ocp: Any,
    face: Any,
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    ids: NDArray[np.int64],
) -> Surface | None:
    """The exact surface of a face, oriented by its (outward) triangles."""
    kinds = ocp.GeomAbs_SurfaceType
    adaptor = ocp.BRepAdaptor_Surface(face)
    kind = adaptor.GetType()
    corners = vertices[faces]
    area = float(
        np.linalg.norm(
            np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1
        ).sum()
        / 2
    )
    common: dict[str, Any] = {"faces": ids, "area": area}
    if kind == kinds.GeomAbs_Plane:
        position = adaptor.Plane().Position()
        normal = _vec(position.Direction())
        outward = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]).sum(axis=0)
        normal = normal if normal @ outward > 0 else -normal
        return Surface("plane", _vec(position.Location()), normal, **common)
    if kind == kinds.GeomAbs_Sphere:
        sphere = adaptor.Sphere()
        centre = _vec(sphere.Location())
        convex = is_convex(vertices, faces, centre, None)
        return Surface("sphere", centre, None, radius=sphere.Radius(), convex=convex, **common)
    if kind in (kinds.GeomAbs_Cylinder, kinds.GeomAbs_Cone, kinds.GeomAbs_Torus):
        if kind == kinds.GeomAbs_Cylinder:
            exact = adaptor.Cylinder()
        elif kind == kinds.GeomAbs_Cone:
            exact = adaptor.Cone()
        else:
            exact = adaptor.Torus()
        axis_line = exact.Axis()
        axis, origin = _vec(axis_line.Direction()), _vec(axis_line.Location())
        if kind == kinds.GeomAbs_Cone:
            # apex and axis from the apex towards the opening
            origin = _vec(exact.Apex())
            axis = axis if exact.SemiAngle() > 0 else -axis
        along = (vertices[np.unique(faces)] - origin) @ axis
        convex = is_convex(vertices, faces, origin, axis)
        if kind == kinds.GeomAbs_Cylinder:
            foot = origin + along.min() * axis
            return Surface(
                "cylinder",
                foot,
                axis,
                radius=exact.Radius(),
                convex=convex,
                extent=(0.0, float(np.ptp(along))),
                **common,
            )
        if kind == kinds.GeomAbs_Cone:
            return Surface(
                "cone",
                origin,
                axis,
                half_angle=abs(exact.SemiAngle()),
                convex=convex,
                extent=(float(along.min()), float(along.max())),
                **common,
            )
        return Surface(
            "torus",
            origin,
            axis,
            radius=exact.MajorRadius(),
            minor_radius=exact.MinorRadius(),
            convex=convex,
            **common,
        )
    return None


def _solid_part(ocp: Any, solid: Any, name: str, source: str) -> Part:
    box = ocp.Bnd_Box()
    ocp.BRepBndLib.Add_s(solid, box)
    diagonal = float(np.sqrt(box.SquareExtent()))
    ocp.BRepMesh_IncrementalMesh(
        solid, LINEAR_DEFLECTION * diagonal, False, ANGULAR_DEFLECTION, True
    )
    explorer = ocp.TopExp_Explorer(solid, ocp.TopAbs_ShapeEnum.TopAbs_FACE)
    blocks: list[tuple[Any, NDArray[np.float64], NDArray[np.int64]]] = []
    while explorer.More():
        face = ocp.TopoDS.Face(explorer.Current())
        points, triangles = _face_triangles(ocp, face)
        if len(triangles):
            blocks.append((face, points, triangles))
        explorer.Next()
    if not blocks:
        raise GeometryError(f"{name} has no tessellated faces", source=source)
    starts = np.cumsum([0] + [len(p) for _, p, _ in blocks])
    vertices = np.vstack([p for _, p, _ in blocks])
    faces = np.vstack([t + s for (_, _, t), s in zip(blocks, starts, strict=False)])
    mesh = trimesh.Trimesh(vertices=vertices, faces=faces, process=True)
    keep = mesh.nondegenerate_faces()  # tessellated poles and apexes leave slivers
    mesh.update_faces(keep)
    if not mesh.is_watertight:
        raise GeometryError(f"{name} does not tessellate into a closed mesh", source=source)
    renumbered = np.cumsum(keep) - 1
    counts = np.cumsum([0] + [len(t) for _, _, t in blocks])
    merged_v, merged_f = np.asarray(mesh.vertices), np.asarray(mesh.faces, dtype=np.int64)
    surfaces = []
    for k, (face, _, _) in enumerate(blocks):
        ids = np.arange(counts[k], counts[k + 1], dtype=np.int64)
        ids = renumbered[ids[keep[ids]]]
        surface = _surface(ocp, face, merged_v, merged_f[ids], ids) if len(ids) else None
        if surface is not None:
            surfaces.append(surface)
    return Part(name, mesh, np.eye(4), tuple(surfaces), source)


def _flush_c_streams() -> None:
    """Flush the C library's output buffers (where OCP's messages wait), if it has any."""
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None).fflush(None)


@contextlib.contextmanager
def _captured_stdout() -> Iterator[list[str]]:
    """Redirect file descriptor 1 to a temporary file inside the block; the list yielded
    receives what was written there, without terminal colour codes, line by line."""
    sys.stdout.flush()
    _flush_c_streams()
    said: list[str] = []
    saved = os.dup(1)
    with tempfile.TemporaryFile() as sink:
        os.dup2(sink.fileno(), 1)
        try:
            yield said
        finally:
            _flush_c_streams()
            os.dup2(saved, 1)
            os.close(saved)
            sink.seek(0)
            text = _ANSI.sub("", sink.read().decode("utf-8", errors="replace"))
            lines = (" ".join(line.strip(" *").split()) for line in text.splitlines())
            said.extend(dict.fromkeys(line for line in lines if line))


def declared_solids(text: str) -> list[tuple[str, str, str]]:
    """The solid entities a STEP file's text declares, in file order: ``(label, type,
    name)``, e.g. ``("#386", "MANIFOLD_SOLID_BREP", "")``."""
    return [
        (f"#{m.group(1)}", m.group(2).upper(), m.group(3).replace("''", "'"))
        for m in _DECLARED.finditer(text)
    ]


def _readable(entity: Any) -> bool:
    """Whether a solid entity of the STEP model has a shell with faces."""
    try:
        shell = entity.Outer()
        return shell is not None and shell.NbCfsFaces() > 0
    except (AttributeError, RuntimeError):
        return False


def _skipped_solids(
    declared: list[tuple[str, str, str]], model: Any, transferred: int
) -> list[Skipped]:
    """The declared solids OCP dropped: those whose entity in the model has no readable
    shell (matched to the declarations in file order), and, when fewer solids came out
    than were declared without such a culprit, the missing count."""
    entities = [
        model.Value(i)
        for i in range(1, model.NbEntities() + 1)
        if model.Value(i).DynamicType().Name() in _SOLID_TYPES
    ]
    skipped = []
    if len(entities) == len(declared):
        for (label, kind, name), entity in zip(declared, entities, strict=True):
            if not _readable(entity):
                item = f"{label} {kind}" + (f" '{name}'" if name else "")
                skipped.append(Skipped(item, "its shell could not be read; the solid is left out"))
    missing = len(declared) - transferred
    if missing > len(skipped):
        skipped.append(
            Skipped(
                f"{missing - len(skipped)} of {len(declared)} declared solids",
                "not transferred by the STEP reader; they are left out",
            )
        )
    return skipped


@dataclass(frozen=True)
class _Solid:
    """One solid of the product structure, placed: the name of the product it makes up
    (empty when that product has several solids or no name) and the subassemblies
    around it (indices into the list of groups)."""

    product: str
    shape: Any
    groups: tuple[int, ...]


def numbered(bases: Sequence[str]) -> list[str]:
    """Unique names for ``bases`` in order: a base used once is kept, one used ``n``
    times becomes ``base_1`` ... ``base_n`` (skipping names already taken)."""
    totals = Counter(bases)
    taken = {base for base in bases if totals[base] == 1}
    seen: Counter[str] = Counter()
    names = []
    for base in bases:
        name = base
        while totals[base] > 1 and (name == base or name in taken):
            seen[base] += 1
            name = f"{base}_{seen[base]}"
        taken.add(name)
        names.append(name)
    return names


def _label_name(ocp: Any, label: Any) -> str:
    """The name the STEP reader gave an XCAF label (the product's name), or ``""`` when
    it has none or only the writer's placeholder."""
    attribute = ocp.TDataStd_Name()
    if not label.FindAttribute(ocp.TDataStd_Name.GetID_s(), attribute):
        return ""
    name = str(attribute.Get().ToExtString()).strip()
    return "" if _PLACEHOLDER.fullmatch(name) else name


def _labels(ocp: Any, fill: Any) -> list[Any]:
    """The labels an XCAF query writes into a label sequence, as a list."""
    sequence = ocp.Sequence_TDF_Label()
    fill(sequence)
    return [sequence.Value(i) for i in range(1, sequence.Length() + 1)]


def _product_solids(
    ocp: Any,
    tool: Any,
    label: Any,
    location: Any,
    within: tuple[int, ...],
    groups: list[str],
) -> Iterator[_Solid]:
    """The solids of the product at ``label`` placed by ``location``, depth first in
    file order; each subassembly met below it appends its name to ``groups``."""
    if tool.IsAssembly_s(label):
        for component in _labels(ocp, lambda seq: tool.GetComponents_s(label, seq, False)):
            referred = ocp.TDF_Label()
            tool.GetReferredShape_s(component, referred)
            placed = location.Multiplied(tool.GetLocation_s(component))
            inner = within
            if tool.IsAssembly_s(referred):
                groups.append(_label_name(ocp, referred) or "subassembly")
                inner = (*within, len(groups) - 1)
            yield from _product_solids(ocp, tool, referred, placed, inner, groups)
        return
    shape = tool.GetShape_s(label).Moved(location)
    explorer = ocp.TopExp_Explorer(shape, ocp.TopAbs_ShapeEnum.TopAbs_SOLID)
    solids = []
    while explorer.More():
        solids.append(ocp.TopoDS.Solid(explorer.Current()))
        explorer.Next()
    product = _label_name(ocp, label) if len(solids) == 1 else ""
    yield from (_Solid(product, solid, within) for solid in solids)


def _structure(ocp: Any, document: Any) -> tuple[list[_Solid], list[str]]:
    """Every solid of the document's product structure and the subassembly names. The
    free products are the roots; when there are several, those that are assemblies are
    subassemblies too."""
    tool = ocp.XCAFDoc_DocumentTool.ShapeTool_s(document.Main())
    roots = _labels(ocp, tool.GetFreeShapes)
    groups: list[str] = []
    solids: list[_Solid] = []
    for root in roots:
        within: tuple[int, ...] = ()
        if len(roots) > 1 and tool.IsAssembly_s(root):
            groups.append(_label_name(ocp, root) or "subassembly")
            within = (len(groups) - 1,)
        solids += _product_solids(ocp, tool, root, ocp.TopLoc_Location(), within, groups)
    return solids, groups


def load_step(path: str | Path, tol: Tolerance | None = None) -> Assembly:
    """An assembly with one part per solid of the STEP file at ``path``, named from its
    product structure, its subassemblies as ``groups`` (module docstring): the solids it
    could not read are in its ``skipped`` items, and what the reader printed in its
    ``warnings``."""
    ocp = _ocp()
    source = str(Path(path))
    if not Path(path).is_file():
        raise GeometryError("STEP file not found", source=source)
    declared = declared_solids(Path(path).read_bytes().decode("latin-1"))
    reader = ocp.STEPCAFControl_Reader()
    reader.SetNameMode(True)
    document = ocp.TDocStd_Document(ocp.TCollection_ExtendedString("MDTV-XCAF"))
    with _captured_stdout() as warnings:
        status = reader.ReadFile(source)
        if status == ocp.IFSelect_ReturnStatus.IFSelect_RetDone:
            reader.Transfer(document)
    if status != ocp.IFSelect_ReturnStatus.IFSelect_RetDone:
        said = f": {'; '.join(warnings)}" if warnings else ""
        raise GeometryError(f"cannot read STEP file{said}", source=source)
    solids, group_names = _structure(ocp, document)
    if not solids:
        said = f": {'; '.join(warnings)}" if warnings else ""
        raise GeometryError(f"no solids in STEP file{said}", source=source)
    names = numbered([s.product or f"solid{i}" for i, s in enumerate(solids, start=1)])
    parts = [_solid_part(ocp, s.shape, n, source) for s, n in zip(solids, names, strict=True)]
    groups = {
        name: tuple(n for s, n in zip(solids, names, strict=True) if index in s.groups)
        for index, name in enumerate(numbered(group_names))
    }
    distinct = len({hash(s.shape.Located(ocp.TopLoc_Location())) for s in solids})
    return Assembly(
        parts,
        units="mm",
        units_source="file",
        source=source,
        exact=True,
        policy=tol,
        skipped=_skipped_solids(declared, reader.Reader().Model(), distinct),
        warnings=warnings,
        groups=groups,
    )
