"""Assemblies from STEP files (DESIGN.md §5.2; extra ``cad``: OCP from
``cadquery-ocp-novtk``, imported only when a STEP file is read).

Each solid is one part, named ``solid<i>`` (1-based, file order). Its faces keep their
exact surface (plane, cylinder, cone, sphere, torus, with axes and radii) for feature
recognition (seed 003 §2), and are tessellated into the part's mesh; the triangles of
each face are recorded so contacts can tell which surface they lie on. Faces of other
surface types are only tessellated. OCP reads STEP lengths in millimetres.

Tessellation: linear deflection ``LINEAR_DEFLECTION`` x the solid's bounding-box
diagonal and angular deflection ``ANGULAR_DEFLECTION`` (below the smooth-edge angle of
:mod:`assemblykit.geometry.recognition`).
"""

from __future__ import annotations

import importlib
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import trimesh
from numpy.typing import NDArray

from assemblykit.errors import GeometryError, MissingExtraError
from assemblykit.geometry.recognition import Surface, is_convex
from assemblykit.model.assembly import Assembly, Part
from assemblykit.tolerance import Tolerance

LINEAR_DEFLECTION = 1e-3
ANGULAR_DEFLECTION = 0.2


_OCP_NAMES = {
    "Bnd": ("Bnd_Box",),
    "BRep": ("BRep_Tool",),
    "BRepAdaptor": ("BRepAdaptor_Surface",),
    "BRepBndLib": ("BRepBndLib",),
    "BRepMesh": ("BRepMesh_IncrementalMesh",),
    "GeomAbs": ("GeomAbs_SurfaceType",),
    "IFSelect": ("IFSelect_ReturnStatus",),
    "STEPControl": ("STEPControl_Reader",),
    "TopAbs": ("TopAbs_Orientation", "TopAbs_ShapeEnum"),
    "TopExp": ("TopExp_Explorer",),
    "TopLoc": ("TopLoc_Location",),
    "TopoDS": ("TopoDS",),
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


def load_step(path: str | Path, tol: Tolerance | None = None) -> Assembly:
    """An assembly with one part per solid of the STEP file at ``path`` (module docstring)."""
    ocp = _ocp()
    source = str(Path(path))
    if not Path(path).is_file():
        raise GeometryError("STEP file not found", source=source)
    reader = ocp.STEPControl_Reader()
    if reader.ReadFile(source) != ocp.IFSelect_ReturnStatus.IFSelect_RetDone:
        raise GeometryError("cannot read STEP file", source=source)
    reader.TransferRoots()
    shape = reader.OneShape()
    explorer = ocp.TopExp_Explorer(shape, ocp.TopAbs_ShapeEnum.TopAbs_SOLID)
    parts = []
    while explorer.More():
        solid = ocp.TopoDS.Solid(explorer.Current())
        parts.append(_solid_part(ocp, solid, f"solid{len(parts) + 1}", source))
        explorer.Next()
    if not parts:
        raise GeometryError("no solids in STEP file", source=source)
    return Assembly(parts, units="mm", units_source="file", source=source, exact=True, policy=tol)
