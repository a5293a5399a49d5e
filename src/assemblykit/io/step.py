r"""Assemblies from STEP files (docs/geometry.md, "Loaders and their conventions"; extra
``cad``: OCP from ``cadquery-ocp-novtk``, imported only when a STEP file is read).

Each solid is one part, named from the file's product structure (ISO 10303-44: each
``PRODUCT`` is placed by ``NEXT_ASSEMBLY_USAGE_OCCURRENCE`` entities in the product that
uses it), read through OCP's XCAF document:

* a solid is named after the product it makes up. A product name that is only a
  placeholder (``Open CASCADE STEP translator 8.0 1.1``, which Open CASCADE's writer gives
  unnamed products, or a shape type such as ``SOLID`` or ``COMPOUND``, which XCAF gives
  unnamed shapes) is no name: the solid is then named after the instance that places
  it, when the occurrence has a name (not XCAF's reference ``=>[0:1:1:2]`` nor a bare
  number), else after the nearest subassembly around it that has a name (its instance's
  or its product's: build123d and CadQuery write each named object as an assembly of
  one product named ``SOLID``), and otherwise it is ``solid<i>``, ``i`` its 1-based
  place among all solids;
* distinct products with one name keep distinct names, suffixed as CAD tools do: the
  first one met keeps the name, the next ones are ``Body (2)``, ``Body (3)``, ...;
* the instances of a product used several times are numbered in file order
  (``pin_1``, ``pin_2``; ``Body (2)_1``, ``Body (2)_2``);
* the solids of a product made of several solids are numbered in order after the name
  of their instance: ``bracket_1``, ``bracket_2`` for a product used once, and
  ``bracket_2_1`` for the first solid of its second instance. The assembly's
  ``products`` list them under their instance's name (``bracket``, ``bracket_2``): one
  physical part, which ``plan`` moves as one (docs/planning.md, "Interfering parts").

A numbered name already taken by another part is skipped (:func:`numbered`). The
products that are assemblies below the whole (subassemblies) become the assembly's
``groups``, named and numbered the same way (``subassembly`` when unnamed), each listing
the parts it holds (``motion --subassembly NAME`` takes one).

Names are decoded as ISO 10303-21:2016 §6.4.3 says (OCCT's reader does this for the
product structure; :func:`decode_step_string` for the names read from the file's text):
``\X\hh`` is one ISO 8859-1 character, ``\X2\...\X0\`` UTF-16 code units, ``\X4\...\X0\``
UCS-4 characters, ``\S\c`` the character ``c`` + 128 of the ISO 8859 part that ``\PA\`` ...
``\PI\`` selects (part 1 at first), ``\\`` a backslash and ``''`` an apostrophe.
``\X\80`` ... ``\X\9F`` are C1 control characters in ISO 8859-1 and are kept as such (a
file written with a DOS code page, where 0x87 is ``ç``, does not say so).

Each part's faces keep their exact surface (plane, cylinder, cone, sphere, torus, with
axes and radii) for feature recognition (Liu 1997, §2), and are
tessellated into the part's mesh; the triangles of each face are recorded so contacts
can tell which surface they lie on. A face whose surface is a B-spline, Bezier, swept
(of revolution or extrusion) or offset surface lying within ``CONVERSION_TOLERANCE`` x
the solid's bounding-box diagonal of a plane, cylinder, cone, sphere or torus keeps that
analytic surface (OCCT's ``GeomConvert_SurfToAnaSurf``, which checks the distance on a
21 x 21 grid of the surface): writers store analytic faces so, Open CASCADE's within
about 3e-12. Faces of other surface types are only tessellated. OCP reads STEP lengths
in millimetres.

A product's shells and faces outside its solids (a surface model) are sewn, and each
closed shell is read as a solid, turned outwards (:func:`_surface_solids`; said in the
assembly's ``warnings``); surfaces enclosing no volume and wireframe edges are listed in
its ``skipped`` items.

A product placed several times is meshed and its surfaces recognised once, where the
product puts it (the solid without its placement), and each instance is that part
moved by its placement (:func:`_placed`): the gripper's 144 solids are 36 distinct
ones.

Tessellation: linear deflection ``LINEAR_DEFLECTION`` x the solid's bounding-box
diagonal and angular deflection ``ANGULAR_DEFLECTION`` (below the smooth-edge angle of
:mod:`assemblykit.geometry.recognition`). When BRepMesh leaves a face without triangles
or the mesh open, the solid is meshed again from scratch with each setting of
``MESH_RETRIES`` (finer, coarser, relative to each edge), then once more after
``ShapeFix_Shape`` repaired it. If none closes the mesh, each hole of the first mesh is
closed by a fan of triangles about the mean of its boundary loop, kept when the closed
mesh's volume is within ``FILL_VOLUME_TOLERANCE`` of the solid's exact volume (BRepGProp);
otherwise the part is the convex hull of its triangles and B-rep vertices (without exact
surfaces), and when these span no volume the part is left out and listed in the
assembly's ``skipped`` items. Each of these steps is said in the assembly's
``warnings``, e.g. ``screw_3: BRepMesh left 1 face untriangulated; its convex hull is
used``; the other parts are kept. A file none of whose solids gives a part is an error.

The kernel puts every vertex of a face on its surface, so the chords of a concave face
(a hole, a female cone, a socket, the concave side of a torus) cut into the void: a pin
modelled at exactly its hole's diameter would share a volume with the plate. The
vertices of such faces are moved into the material
(:func:`assemblykit.geometry.tessellation.inside_vertices`, in the planes of the faces
around them): each triangle then lies on the material side of its exact surface, so the
mesh lies inside the solid and within the linear deflection of it, and solids that share
no volume have meshes that share none (docs/geometry.md, "STEP tessellation"). Should
a move take a vertex beyond the solid's box by more than ``BOX_MARGIN`` of its diagonal,
the part keeps its vertices on its surface and its warning says so.

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
import itertools
import os
import re
import sys
import tempfile
from collections import Counter
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import trimesh
from numpy.typing import NDArray
from scipy.spatial import QhullError

from assemblykit.algebra.se3 import unit
from assemblykit.errors import GeometryError, MissingExtraError
from assemblykit.geometry.nonmanifold import split_touching
from assemblykit.geometry.recognition import is_convex
from assemblykit.geometry.tessellation import inside_vertices
from assemblykit.model.assembly import Assembly, Part, Skipped
from assemblykit.model.surfaces import Surface
from assemblykit.tolerance import Tolerance

LINEAR_DEFLECTION = 1e-3
ANGULAR_DEFLECTION = 0.2
CONVERSION_TOLERANCE = 1e-6
"""Distance, relative to the solid's bounding-box diagonal, within which a B-spline,
Bezier, swept or offset face counts as the analytic surface it is close to."""
SEWING_TOLERANCE = 1e-4
"""Gap, relative to the bounding-box diagonal of a product's loose faces, that sewing
them closes (:func:`_surface_solids`): writers of surface models leave gaps of a few
thousandths of a millimetre between faces, a tenth of the linear deflection, so the
mesh does not see them."""
MESH_RETRIES = (
    ("a 3 times finer deflection", LINEAR_DEFLECTION / 3, ANGULAR_DEFLECTION / 2, False),
    ("a 10 times coarser deflection", 10 * LINEAR_DEFLECTION, 2 * ANGULAR_DEFLECTION, False),
    ("a deflection of 1% of each edge", 0.01, ANGULAR_DEFLECTION, True),
)
"""The settings a solid is meshed again with when BRepMesh leaves a face without
triangles or the mesh open: what the warning calls it, the linear deflection (relative to
the solid's bounding-box diagonal, or to each edge's size when the last item is true),
and the angular deflection."""
FILL_VOLUME_TOLERANCE = 0.01
"""Relative difference from the solid's exact volume within which a mesh whose holes
were closed by fans of triangles is kept."""
BOX_MARGIN = 0.01
"""Distance, relative to the solid's bounding-box diagonal, beyond the solid's box that
no vertex moved into the material may reach: ten times the linear deflection, far
beyond the sag it moves by."""
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
_PLACEHOLDER = re.compile(
    r"Open CASCADE STEP translator [\d.]+ [\d.]+"
    r"|COMPOUND|COMPSOLID|SOLID|SHELL|FACE|WIRE|EDGE|VERTEX|SHAPE"
)
"""The product names that are no names: the one Open CASCADE's STEP writer gives a shape
that has none, and the shape types XCAF names unnamed shapes after (``TopAbs::Print``)."""
_INSTANCE_PLACEHOLDER = re.compile(r"=>\[[\d:]+\]|\d+")
"""The occurrence names that are no names: XCAF's reference to the product placed (the
label entry ``=>[0:1:1:2]``), which Open CASCADE's writer stores, and a bare number (the
occurrence's id, which the reader takes when the name is empty)."""


_OCP_NAMES = {
    "Bnd": ("Bnd_Box",),
    "BRep": ("BRep_Tool",),
    "BRepAdaptor": ("BRepAdaptor_Surface",),
    "BRepBndLib": ("BRepBndLib",),
    "BRepBuilderAPI": ("BRepBuilderAPI_Sewing",),
    "BRepGProp": ("BRepGProp",),
    "BRepMesh": ("BRepMesh_IncrementalMesh",),
    "BRepTools": ("BRepTools",),
    "Geom": ("Geom_RectangularTrimmedSurface",),
    "GeomAbs": ("GeomAbs_SurfaceType",),
    "GeomAdaptor": ("GeomAdaptor_Surface",),
    "GeomConvert": ("GeomConvert_SurfToAnaSurf",),
    "GProp": ("GProp_GProps",),
    "gp": ("gp_Trsf", "gp_TrsfForm"),
    "collections": ("Sequence_TDF_Label",),
    "IFSelect": ("IFSelect_ReturnStatus",),
    "ShapeFix": ("ShapeFix_Shape", "ShapeFix_Solid"),
    "STEPCAFControl": ("STEPCAFControl_Reader",),
    "TCollection": ("TCollection_AsciiString", "TCollection_ExtendedString"),
    "TDataStd": ("TDataStd_Name",),
    "TDF": ("TDF_Label", "TDF_Tool"),
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


def _transformed(ocp: Any, points: NDArray[np.float64], transform: Any) -> NDArray[np.float64]:
    """``points`` (N x 3) moved by the ``gp_Trsf`` ``transform``, computed as OCCT's
    ``gp_Pnt::Transform`` computes each point (its form first, then the vectorial part
    row by row, the scale, the translation), in the same order of operations, so that
    the coordinates are the ones OCCT gives, to the last bit."""
    forms = ocp.gp_TrsfForm
    form = transform.Form()
    shift = np.array(transform.TranslationPart().Coord(), dtype=np.float64)
    if form == forms.gp_Identity:
        return points
    if form == forms.gp_Translation:
        return points + shift
    if form == forms.gp_Scale:
        return points * transform.ScaleFactor() + shift
    if form == forms.gp_PntMirror:
        return -points + shift
    matrix = transform.HVectorialPart()
    x, y, z = points.T
    moved = np.stack(
        [
            matrix.Value(row, 1) * x + matrix.Value(row, 2) * y + matrix.Value(row, 3) * z
            for row in (1, 2, 3)
        ],
        axis=1,
    )
    scale = transform.ScaleFactor()
    if scale != 1.0:
        moved = moved * scale
    return moved + shift


def _face_triangles(ocp: Any, face: Any) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """The triangulation of a face in world coordinates, oriented outward (a reversed
    face's triangles turned, and so are those a mirroring placement, as of a left-hand
    copy of a part, turns inside out)."""
    location = ocp.TopLoc_Location()
    triangulation = ocp.BRep_Tool.Triangulation_s(face, location)
    if triangulation is None:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    nodes = np.array(
        [triangulation.Node(i).Coord() for i in range(1, triangulation.NbNodes() + 1)],
        dtype=np.float64,
    ).reshape(-1, 3)
    points = _transformed(ocp, nodes, location.Transformation())
    triangles = (
        np.array(
            [triangulation.Triangle(i).Get() for i in range(1, triangulation.NbTriangles() + 1)],
            dtype=np.int64,
        )
        - 1
    )
    reversed_face = face.Orientation() == ocp.TopAbs_Orientation.TopAbs_REVERSED
    if reversed_face != location.Transformation().IsNegative():
        triangles = triangles[:, ::-1]
    return points, triangles


def _analytic(ocp: Any, face: Any, tol: float) -> Any | None:
    """The analytic surface of a face as an adaptor (``GetType``, ``Plane``, ``Cylinder``,
    ``Cone``, ``Sphere``, ``Torus``): its own surface when that is a plane, cylinder,
    cone, sphere or torus; for a B-spline, Bezier, swept or offset surface, the one of
    these it lies within ``tol`` of, as OCCT's ``GeomConvert_SurfToAnaSurf`` finds it
    (over the whole surface, then over the face's parameter range, as a face may use an
    analytic piece of a larger surface); ``None`` otherwise. Both are in world
    coordinates (``BRep_Tool::Surface`` applies the face's location)."""
    kinds = ocp.GeomAbs_SurfaceType
    adaptor = ocp.BRepAdaptor_Surface(face)
    kind = adaptor.GetType()
    if kind in (
        kinds.GeomAbs_Plane,
        kinds.GeomAbs_Cylinder,
        kinds.GeomAbs_Cone,
        kinds.GeomAbs_Sphere,
        kinds.GeomAbs_Torus,
    ):
        return adaptor
    if kind not in (
        kinds.GeomAbs_BSplineSurface,
        kinds.GeomAbs_BezierSurface,
        kinds.GeomAbs_SurfaceOfRevolution,
        kinds.GeomAbs_SurfaceOfExtrusion,
        kinds.GeomAbs_OffsetSurface,
    ):
        return None
    surface = ocp.BRep_Tool.Surface_s(face)
    if isinstance(surface, ocp.Geom_RectangularTrimmedSurface):
        # the converter takes a B-spline or Bezier surface as such, not trimmed
        surface = surface.BasisSurface()
    converter = ocp.GeomConvert_SurfToAnaSurf(surface)
    analytic = converter.ConvertToAnalytical(tol)
    if analytic is None:
        bounds = surface.Bounds()
        face_bounds = ocp.BRepTools.UVBounds_s(face)
        umin, vmin = max(face_bounds[0], bounds[0]), max(face_bounds[2], bounds[2])
        umax, vmax = min(face_bounds[1], bounds[1]), min(face_bounds[3], bounds[3])
        if umin < umax and vmin < vmax and (umin, umax, vmin, vmax) != tuple(bounds):
            analytic = converter.ConvertToAnalytical(tol, umin, umax, vmin, vmax)
    return None if analytic is None else ocp.GeomAdaptor_Surface(analytic)


def _surface(
    ocp: Any,
    exact: Any,
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    ids: NDArray[np.int64],
) -> Surface:
    """The surface of a face whose analytic surface is the adaptor ``exact``
    (:func:`_analytic`): its kind, axis and radii from the surface, its orientation
    (outward normal of a plane, convexity) and extent from the face's outward triangles
    ``faces`` (numbered ``ids`` in the part's mesh)."""
    kinds = ocp.GeomAbs_SurfaceType
    kind = exact.GetType()
    corners = vertices[faces]
    area = float(
        np.linalg.norm(
            np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1
        ).sum()
        / 2
    )
    common: dict[str, Any] = {"faces": ids, "area": area}
    if kind == kinds.GeomAbs_Plane:
        position = exact.Plane().Position()
        normal = _vec(position.Direction())
        outward = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]).sum(axis=0)
        normal = normal if normal @ outward > 0 else -normal
        return Surface("plane", _vec(position.Location()), normal, **common)
    if kind == kinds.GeomAbs_Sphere:
        sphere = exact.Sphere()
        centre = _vec(sphere.Location())
        convex = is_convex(vertices, faces, centre, None)
        return Surface("sphere", centre, None, radius=sphere.Radius(), convex=convex, **common)
    if kind == kinds.GeomAbs_Cylinder:
        primitive = exact.Cylinder()
    elif kind == kinds.GeomAbs_Cone:
        primitive = exact.Cone()
    else:
        primitive = exact.Torus()
    axis_line = primitive.Axis()
    axis, origin = _vec(axis_line.Direction()), _vec(axis_line.Location())
    if kind == kinds.GeomAbs_Cone:
        # apex and axis from the apex towards the opening
        origin = _vec(primitive.Apex())
        axis = axis if primitive.SemiAngle() > 0 else -axis
    along = (vertices[np.unique(faces)] - origin) @ axis
    convex = is_convex(vertices, faces, origin, axis)
    if kind == kinds.GeomAbs_Cylinder:
        foot = origin + along.min() * axis
        return Surface(
            "cylinder",
            foot,
            axis,
            radius=primitive.Radius(),
            convex=convex,
            extent=(0.0, float(np.ptp(along))),
            **common,
        )
    if kind == kinds.GeomAbs_Cone:
        return Surface(
            "cone",
            origin,
            axis,
            half_angle=abs(primitive.SemiAngle()),
            convex=convex,
            extent=(float(along.min()), float(along.max())),
            **common,
        )
    return Surface(
        "torus",
        origin,
        axis,
        radius=primitive.MajorRadius(),
        minor_radius=primitive.MinorRadius(),
        convex=convex,
        **common,
    )


_Block = tuple[Any, NDArray[np.float64], NDArray[np.int64]]
"""A face and its triangles: their points and their corners' indices into them."""


def _faces(ocp: Any, shape: Any) -> list[Any]:
    """The faces of ``shape``, in the order of its topology."""
    explorer = ocp.TopExp_Explorer(shape, ocp.TopAbs_ShapeEnum.TopAbs_FACE)
    faces = []
    while explorer.More():
        faces.append(ocp.TopoDS.Face(explorer.Current()))
        explorer.Next()
    return faces


def _mesh_faces(
    ocp: Any, shape: Any, deflection: float, angle: float, relative: bool, clean: bool
) -> tuple[list[_Block], int]:
    """Mesh ``shape`` with BRepMesh (after ``BRepTools::Clean`` removed the triangulation
    it has, when ``clean``, so that the new settings apply: BRepMesh keeps one that meets
    the deflection); the faces that have triangles with them, and the number of faces
    left without. With ``clean`` (a retry, which only a complete mesh serves), the
    faces' triangles are not read when some face has no triangulation at all."""
    if clean:
        ocp.BRepTools.Clean_s(shape)
    ocp.BRepMesh_IncrementalMesh(shape, deflection, relative, angle, True)
    faces = _faces(ocp, shape)
    if clean:
        location = ocp.TopLoc_Location()
        if untriangulated := sum(
            ocp.BRep_Tool.Triangulation_s(face, location) is None for face in faces
        ):
            return [], untriangulated
    blocks: list[_Block] = []
    missing = 0
    for face in faces:
        points, triangles = _face_triangles(ocp, face)
        if len(triangles):
            blocks.append((face, points, triangles))
        else:
            missing += 1
    return blocks, missing


def _merged(blocks: Sequence[_Block]) -> tuple[trimesh.Trimesh, NDArray[np.bool_]]:
    """One mesh of the faces' triangles, their shared points merged and the degenerate
    triangles dropped (``keep`` marks, in the faces' order, the triangles kept)."""
    starts = np.cumsum([0] + [len(p) for _, p, _ in blocks])
    vertices = np.vstack([p for _, p, _ in blocks])
    faces = np.vstack([t + s for (_, _, t), s in zip(blocks, starts, strict=False)])
    mesh = trimesh.Trimesh(vertices=vertices, faces=faces, process=True)
    keep = np.asarray(mesh.nondegenerate_faces())  # tessellated poles and apexes leave slivers
    mesh.update_faces(keep)
    return mesh, keep


def _fanned(mesh: trimesh.Trimesh) -> trimesh.Trimesh | None:
    """``mesh`` with each hole closed by a fan of triangles about the mean of its boundary
    loop, turned against the loop's edges so that the winding stays consistent; the
    original triangles keep their places, the fans come after them. ``None`` when the
    boundary is not a set of simple loops (two loops through one vertex)."""
    faces = np.asarray(mesh.faces, dtype=np.int64)
    directed = faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    _, inverse, counts = np.unique(
        np.sort(directed, axis=1), axis=0, return_inverse=True, return_counts=True
    )
    following: dict[int, int] = {}
    for a, b in directed[counts[inverse.ravel()] == 1].tolist():
        if a in following:
            return None
        following[a] = b
    vertices = [np.asarray(mesh.vertices, dtype=np.float64)]
    fans: list[tuple[int, int, int]] = []
    centre = len(vertices[0])
    while following:
        start = next(iter(following))
        loop = [start]
        while (after := following.pop(loop[-1], start)) != start:
            loop.append(after)
        if len(loop) < 3:
            return None
        vertices.append(vertices[0][loop].mean(axis=0)[None])
        fans += [(b, a, centre) for a, b in zip(loop, loop[1:] + loop[:1], strict=True)]
        centre += 1
    if not fans:
        return None
    return trimesh.Trimesh(
        np.vstack(vertices), np.vstack([faces, np.array(fans, dtype=np.int64)]), process=False
    )


def _hull(points: NDArray[np.float64]) -> trimesh.Trimesh | None:
    """The convex hull of ``points``, or ``None`` when they span no volume."""
    if len(points) < 4:
        return None
    centred = points - points.mean(axis=0)
    size = float(np.abs(centred).max())
    if size == 0 or np.linalg.matrix_rank(centred / size, tol=1e-9) < 3:
        return None
    try:
        hull = trimesh.convex.convex_hull(points)
    except QhullError:
        return None
    return hull if hull.volume > 0 else None


def _brep_points(ocp: Any, shape: Any) -> NDArray[np.float64]:
    """The points of the B-rep vertices of ``shape``."""
    explorer = ocp.TopExp_Explorer(shape, ocp.TopAbs_ShapeEnum.TopAbs_VERTEX)
    points = []
    while explorer.More():
        points.append(_vec(ocp.BRep_Tool.Pnt_s(ocp.TopoDS.Vertex(explorer.Current()))))
        explorer.Next()
    return np.array(points, dtype=np.float64).reshape(-1, 3)


@dataclass(frozen=True)
class _Tessellation:
    """A solid's closed mesh: ``blocks``, its faces with their triangles, whose exact
    surfaces the part keeps (none for a convex hull); ``keep``, the triangles of the
    blocks left in ``mesh`` (the first ones, in order); ``note``, what was done to get
    it (``""`` when BRepMesh closed the mesh at once)."""

    blocks: list[_Block]
    mesh: trimesh.Trimesh
    keep: NDArray[np.bool_]
    note: str


def _closed(
    ocp: Any, shape: Any, deflection: float, angle: float, relative: bool
) -> tuple[list[_Block], trimesh.Trimesh, NDArray[np.bool_]] | None:
    """The faces of ``shape`` meshed from scratch with these settings and their merged
    mesh, when every face has triangles and the mesh is closed; ``None`` otherwise."""
    blocks, missing = _mesh_faces(ocp, shape, deflection, angle, relative, clean=True)
    if missing or not blocks:
        return None
    mesh, keep = _merged(blocks)
    return (blocks, mesh, keep) if mesh.is_watertight else None


def _split(
    ocp: Any, solid: Any, mesh: trimesh.Trimesh
) -> tuple[trimesh.Trimesh, NDArray[np.bool_], str] | None:
    """Where ``mesh``, closed, has edges that more than two triangles share (the solid's
    surface meets itself along a line), the mesh with its sheets split there
    (:func:`~assemblykit.geometry.nonmanifold.split_touching`) when its volume is within
    ``FILL_VOLUME_TOLERANCE`` of the solid's exact one, every triangle kept, and what
    was done; else ``None``."""
    edges = mesh.edges_sorted
    _, shared = np.unique(edges, axis=0, return_counts=True)
    if np.any(shared == 1) or not np.any(shared > 2):
        return None
    split = split_touching(mesh)
    volume = _exact_volume(ocp, solid)
    if split is None or abs(split.volume - volume) > FILL_VOLUME_TOLERANCE * volume:
        return None
    touching = int(np.count_nonzero(shared > 2))
    said = f"{touching} edge{'s' * (touching != 1)}"
    note = f"its surface meets itself along {said}; its mesh is split there into sheets"
    return split, np.ones(len(split.faces), dtype=bool), note


def _exact_volume(ocp: Any, solid: Any) -> float:
    """The volume of the exact ``solid`` (OCCT's ``BRepGProp``)."""
    properties = ocp.GProp_GProps()
    ocp.BRepGProp.VolumeProperties_s(solid, properties)
    return abs(float(properties.Mass()))


def _tessellated(ocp: Any, solid: Any, diagonal: float) -> _Tessellation | str:
    """The closed mesh of a solid (module docstring): BRepMesh's, meshed again with each
    of ``MESH_RETRIES`` and after ``ShapeFix_Shape``'s repair when it leaves a face without
    triangles or the mesh open, else the first mesh with its holes closed by fans (when
    its volume is within ``FILL_VOLUME_TOLERANCE`` of the solid's exact one), else the
    convex hull of the triangles' and B-rep vertices' points; or why there is none."""
    blocks, missing = _mesh_faces(
        ocp, solid, LINEAR_DEFLECTION * diagonal, ANGULAR_DEFLECTION, False, clean=False
    )
    first = _merged(blocks) if blocks else None
    if not missing and first is not None and first[0].is_watertight:
        return _Tessellation(blocks, *first, "")
    if not missing and first is not None and (split := _split(ocp, solid, first[0])):
        return _Tessellation(blocks, *split)
    if missing:
        problem = f"BRepMesh left {missing} face{'s' if missing > 1 else ''} untriangulated"
    else:
        problem = "BRepMesh's triangles leave its mesh open"
    for setting, deflection, angle, relative in MESH_RETRIES:
        scale = 1.0 if relative else diagonal
        if again := _closed(ocp, solid, deflection * scale, angle, relative):
            return _Tessellation(*again, f"{problem}; meshed again with {setting}")
    repair = ocp.ShapeFix_Shape(solid)
    repair.Perform()
    repaired = repair.Shape()
    if again := _closed(ocp, repaired, LINEAR_DEFLECTION * diagonal, ANGULAR_DEFLECTION, False):
        return _Tessellation(*again, f"{problem}; meshed again after ShapeFix_Shape's repair")
    if first is not None and (fanned := _fanned(first[0])) is not None:
        volume = _exact_volume(ocp, solid)
        with np.errstate(divide="ignore", invalid="ignore"):  # a flat fill has no volume
            closed_volume = abs(fanned.volume) if fanned.is_winding_consistent else 0.0
        if (
            fanned.is_watertight
            and fanned.is_winding_consistent
            and abs(closed_volume - volume) <= FILL_VOLUME_TOLERANCE * volume
        ):
            loops = len(fanned.vertices) - len(first[0].vertices)
            closed = (
                "the hole this leaves in its mesh is closed by a fan of triangles"
                if loops == 1
                else f"the {loops} holes this leaves in its mesh are closed by fans of triangles"
            )
            return _Tessellation(blocks, fanned, first[1], f"{problem}; {closed}")
    points = [_brep_points(ocp, solid)]
    if first is not None:
        points.append(np.asarray(first[0].vertices, dtype=np.float64))
    hull = _hull(np.vstack(points))
    if hull is not None:
        return _Tessellation(
            [], hull, np.zeros(0, dtype=bool), f"{problem}; its convex hull is used"
        )
    return f"{problem}, and its triangles and vertices span no volume; the part is left out"


def _placed(ocp: Any, local: Part, name: str, placement: Any) -> Part:
    """The part ``local`` (a solid meshed where its product puts it) moved by the
    ``gp_Trsf`` ``placement`` of one of its instances and named ``name``: its vertices
    moved as OCCT moves points (:func:`_transformed`), its triangles turned back where
    the placement mirrors, its surfaces' points and axes moved with it."""
    matrix = np.array([[placement.Value(r, c) for c in (1, 2, 3)] for r in (1, 2, 3)])
    faces = np.asarray(local.mesh.faces)
    # each instance owns its arrays: a part moved later moves alone
    mesh = trimesh.Trimesh(
        np.array(_transformed(ocp, np.asarray(local.mesh.vertices), placement)),
        np.array(faces[:, ::-1] if placement.IsNegative() else faces),
        process=False,
    )
    surfaces = tuple(
        replace(
            surface,
            point=_transformed(ocp, surface.point[None], placement)[0],
            axis=None if surface.axis is None else unit(matrix @ surface.axis),
        )
        for surface in local.surfaces
    )
    return Part(name, mesh, np.eye(4), surfaces, local.source)


def _solid_part(ocp: Any, solid: Any, source: str) -> tuple[Part | str, str]:
    """The part a solid makes (named ``""``), with the exact surfaces of its faces, or
    why it is left out; and what had to be done to mesh it (``""`` when nothing:
    module docstring)."""
    box = ocp.Bnd_Box()
    ocp.BRepBndLib.Add_s(solid, box)
    diagonal = float(np.sqrt(box.SquareExtent()))
    tessellation = _tessellated(ocp, solid, diagonal)
    if isinstance(tessellation, str):
        return tessellation, ""
    blocks, mesh, keep = tessellation.blocks, tessellation.mesh, tessellation.keep
    if not blocks:  # a convex hull, on which no face of the solid lies
        return Part("", mesh, np.eye(4), (), source), tessellation.note
    renumbered = np.cumsum(keep) - 1
    counts = np.cumsum([0] + [len(t) for _, _, t in blocks])
    merged_v, merged_f = np.asarray(mesh.vertices), np.asarray(mesh.faces, dtype=np.int64)
    surfaces = []
    for k, (face, _, _) in enumerate(blocks):
        ids = np.arange(counts[k], counts[k + 1], dtype=np.int64)
        ids = renumbered[ids[keep[ids]]]
        exact = _analytic(ocp, face, CONVERSION_TOLERANCE * diagonal) if len(ids) else None
        surface = _surface(ocp, exact, merged_v, merged_f[ids], ids) if exact is not None else None
        if surface is not None:
            surfaces.append(surface)
    # the vertices of concave faces go into the material (module docstring), and stay
    # in the solid's box
    inside = inside_vertices(merged_v, merged_f, surfaces)
    low, high = np.array(box.CornerMin().Coord()), np.array(box.CornerMax().Coord())
    margin = BOX_MARGIN * diagonal
    if np.all((inside >= low - margin) & (inside <= high + margin)):
        mesh.vertices = inside
        return Part("", mesh, np.eye(4), tuple(surfaces), source), tessellation.note
    kept = "its vertices are left on its surface: moved into its material, some left its box"
    note = f"{tessellation.note}; {kept}" if tessellation.note else kept
    return Part("", mesh, np.eye(4), tuple(surfaces), source), note


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


_ESCAPE = re.compile(
    r"\\X\\([0-9A-F]{2})"
    r"|\\X2\\((?:[0-9A-F]{4})*)\\X0\\"
    r"|\\X4\\((?:[0-9A-F]{8})*)\\X0\\"
    r"|\\S\\(.)"
    r"|\\P([A-I])\\"
    r"|(\\\\)"
    r"|('')",
    re.IGNORECASE | re.DOTALL,
)
"""The escapes of a STEP string (ISO 10303-21:2016 §6.4.3), one group each: ``\\X\\hh``,
``\\X2\\...\\X0\\``, ``\\X4\\...\\X0\\``, ``\\S\\c``, ``\\Px\\``, ``\\\\``, ``''``."""


def _code_point(value: int) -> str:
    """The character of a UCS-4 code, U+FFFD when it is none (a surrogate, or beyond
    U+10FFFF)."""
    return "\ufffd" if value > 0x10FFFF or 0xD800 <= value <= 0xDFFF else chr(value)


def decode_step_string(text: str) -> str:
    """The characters a STEP string means, ``text`` being what stands between its
    apostrophes (ISO 10303-21:2016 §6.4.3): ``\\X\\hh`` is the ISO 8859-1 character of
    code ``hh`` (so U+0000 ... U+00FF: ``\\X\\87`` is the C1 control U+0087),
    ``\\X2\\hhhh...\\X0\\`` UTF-16 code units (surrogate pairs joined), ``\\X4\\hhhhhhhh
    ...\\X0\\`` UCS-4 characters, ``\\S\\c`` the character of code ``c`` + 128 in the
    part of ISO 8859 that the last ``\\PA\\`` ... ``\\PI\\`` selected (part 1 at
    first), ``\\\\`` one backslash and ``''`` one apostrophe. A backslash that starts
    none of these stays as it is; a code that is no character becomes U+FFFD."""
    decoded: list[str] = []
    part = 1
    end = 0
    for match in _ESCAPE.finditer(text):
        decoded.append(text[end : match.start()])
        end = match.end()
        latin, utf16, ucs4, shifted, page, backslash, _ = match.groups()
        if latin is not None:
            decoded.append(chr(int(latin, 16)))
        elif utf16 is not None:
            decoded.append(bytes.fromhex(utf16).decode("utf-16-be", errors="replace"))
        elif ucs4 is not None:
            decoded += [_code_point(int(ucs4[i : i + 8], 16)) for i in range(0, len(ucs4), 8)]
        elif shifted is not None:
            code = ord(shifted) + 128
            decoded.append(
                bytes([code]).decode(f"iso8859_{part}", errors="replace")
                if code < 256
                else match.group()
            )
        elif page is not None:
            part = "ABCDEFGHI".index(page.upper()) + 1
        else:
            decoded.append("\\" if backslash else "'")
    decoded.append(text[end:])
    return "".join(decoded)


def declared_solids(text: str) -> list[tuple[str, str, str]]:
    """The solid entities a STEP file's text declares, in file order: ``(label, type,
    name)``, e.g. ``("#386", "MANIFOLD_SOLID_BREP", "")``, the name decoded
    (:func:`decode_step_string`)."""
    return [
        (f"#{m.group(1)}", m.group(2).upper(), decode_step_string(m.group(3)))
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
                skipped.append(
                    Skipped(item, "its shell could not be read; the solid is left out", True)
                )
    missing = len(declared) - transferred
    if missing > len(skipped):
        skipped.append(
            Skipped(
                f"{missing - len(skipped)} of {len(declared)} declared solids",
                "not transferred by the STEP reader; they are left out",
                True,
            )
        )
    return skipped


@dataclass(frozen=True)
class _Solid:
    """One solid of the product structure, placed: ``name``, the name it takes from the
    product it makes up or else from the instance placing it (``""`` when neither has
    one); ``key``, the product's XCAF label entry; ``instance``, which placement of a
    product it belongs to (counting all placements met); ``piece``, its 1-based place
    among the product's solids (0 when the product has one solid); ``groups``, the
    subassemblies around it (indices into the list of groups); ``made``, what it was
    made from when the file gave no solid (``"a closed shell"``)."""

    name: str
    key: str
    instance: int
    piece: int
    shape: Any
    groups: tuple[int, ...]
    made: str = ""


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


def distinct_products(named: Sequence[tuple[str, str]]) -> list[str]:
    """Names for ``named`` items ``(name, key)``, ``key`` telling which product an item
    is: the first product met with a name keeps it, the next products with that name
    become ``name (2)``, ``name (3)``, ... in order (skipping names taken), as CAD tools
    name copies; items of one product keep one name, and empty names stay empty."""
    taken = {name for name, _ in named}
    chosen: dict[tuple[str, str], str] = {}
    products: Counter[str] = Counter()
    for name, key in named:
        if not name or (name, key) in chosen:
            continue
        products[name] += 1
        label = name
        while products[name] > 1 and (label == name or label in taken):
            label = f"{name} ({products[name]})"
            if label in taken:
                products[name] += 1
        taken.add(label)
        chosen[name, key] = label
    return [chosen.get(item, "") for item in named]


def _placement_names(solids: Sequence[_Solid]) -> list[str]:
    """Per solid, the name of the placement it belongs to: its product's name made
    distinct (:func:`distinct_products`), the placements of one product numbered
    (:func:`numbered`); ``""`` for a solid without a name."""
    bases = distinct_products([(s.name, s.key) for s in solids])
    placements: dict[int, str] = {}
    for solid, base in zip(solids, bases, strict=True):
        if base:
            placements.setdefault(solid.instance, base)
    placed = dict(zip(placements, numbered(list(placements.values())), strict=True))
    return [placed[s.instance] if base else "" for s, base in zip(solids, bases, strict=True)]


def _part_names(solids: Sequence[_Solid], placements: Sequence[str]) -> list[str]:
    """The parts' names (module docstring): each solid's placement name
    (:func:`_placement_names`), the solids of a product of several numbered after it;
    ``solid<i>`` for a solid without a name."""
    names = []
    for i, (solid, placement) in enumerate(zip(solids, placements, strict=True), start=1):
        if not placement:
            names.append(f"solid{i}")
        elif solid.piece:
            names.append(f"{placement}_{solid.piece}")
        else:
            names.append(placement)
    return names if len(set(names)) == len(names) else numbered(names)


def _label_name(ocp: Any, label: Any, instance: bool = False) -> str:
    """The name the STEP reader gave an XCAF label (a product's, or an occurrence's when
    ``instance``), or ``""`` when it has none or only a placeholder (``_PLACEHOLDER``,
    and for an occurrence ``_INSTANCE_PLACEHOLDER``). The reader has decoded the STEP
    string's escapes. (OCP's ``FindAttribute`` crashes on a label without the attribute,
    so ``IsAttribute`` is asked first.)"""
    name_id = ocp.TDataStd_Name.GetID_s()
    if not label.IsAttribute(name_id):
        return ""
    attribute = ocp.TDataStd_Name()
    label.FindAttribute(name_id, attribute)
    name = str(attribute.Get().ToExtString()).strip()
    if _PLACEHOLDER.fullmatch(name) or (instance and _INSTANCE_PLACEHOLDER.fullmatch(name)):
        return ""
    return name


def _entry(ocp: Any, label: Any) -> str:
    """The entry of an XCAF label (``0:1:1:2``), which tells its product apart."""
    entry = ocp.TCollection_AsciiString()
    ocp.TDF_Tool.Entry_s(label, entry)
    return str(entry.ToCString())


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
    groups: list[tuple[str, str]],
    placed_as: str,
    placements: Iterator[int],
    left_out: list[Skipped],
) -> Iterator[_Solid]:
    """The solids of the product at ``label`` placed by ``location`` as the instance
    named ``placed_as`` (``""`` for none: the name of the instance, else that of the
    nearest subassembly around it with one), depth first in file order, with those its
    closed shells make (:func:`_surface_solids`); each subassembly met below it appends
    its name and product key to ``groups``, each placement of a product that is not an
    assembly takes the next number of ``placements``, and surfaces enclosing no volume
    are said in ``left_out``."""
    if tool.IsAssembly_s(label):
        for component in _labels(ocp, lambda seq: tool.GetComponents_s(label, seq, False)):
            referred = ocp.TDF_Label()
            tool.GetReferredShape_s(component, referred)
            placed = location.Multiplied(tool.GetLocation_s(component))
            instance = _label_name(ocp, component, instance=True)
            inner, given = within, instance or placed_as
            if tool.IsAssembly_s(referred):
                product = _label_name(ocp, referred)
                name = product or instance or "subassembly"
                groups.append((name, _entry(ocp, referred)))
                inner = (*within, len(groups) - 1)
                given = instance or product or placed_as
            yield from _product_solids(
                ocp, tool, referred, placed, inner, groups, given, placements, left_out
            )
        return
    shape = tool.GetShape_s(label).Moved(location)
    kind = ocp.TopAbs_ShapeEnum
    solids = [(ocp.TopoDS.Solid(s), "") for s in _subshapes(ocp, shape, kind.TopAbs_SOLID)]
    name = _label_name(ocp, label) or placed_as
    closed, open_surfaces = _surface_solids(ocp, shape)
    solids += [(solid, "a closed shell") for solid in closed]
    if open_surfaces:
        left_out.append(
            Skipped(
                name or "an unnamed product",
                f"{open_surfaces}: surfaces enclosing no volume, not a solid; left out",
            )
        )
    edges = len(_subshapes(ocp, shape, kind.TopAbs_EDGE, kind.TopAbs_FACE))
    if edges:
        left_out.append(
            Skipped(
                name or "an unnamed product",
                f"{edges} edge{'s' * (edges != 1)} of wireframe geometry, no volume; left out",
            )
        )
    key, placement = _entry(ocp, label), next(placements)
    for piece, (solid, made) in enumerate(solids, start=1):
        yield _Solid(name, key, placement, piece if len(solids) > 1 else 0, solid, within, made)


def _subshapes(ocp: Any, shape: Any, kind: Any, outside: Any = None) -> list[Any]:
    """The subshapes of ``shape`` of type ``kind``, in file order; with ``outside``,
    only those not inside a subshape of that type."""
    explorer = (
        ocp.TopExp_Explorer(shape, kind)
        if outside is None
        else ocp.TopExp_Explorer(shape, kind, outside)
    )
    found = []
    while explorer.More():
        found.append(explorer.Current())
        explorer.Next()
    return found


def _closed_and_open(ocp: Any, shells: list[Any]) -> tuple[list[Any], list[Any]]:
    """``shells`` parted into the closed ones and the others, in order."""
    closed = [ocp.BRep_Tool.IsClosed_s(shell) for shell in shells]
    return (
        [shell for shell, shut in zip(shells, closed, strict=True) if shut],
        [shell for shell, shut in zip(shells, closed, strict=True) if not shut],
    )


def _surface_solids(ocp: Any, shape: Any) -> tuple[list[Any], str]:
    """The solids that the shells and faces of ``shape`` outside its solids enclose
    (a surface model, as some writers store a closed body: ``SHELL_BASED_SURFACE_MODEL``),
    and what of them encloses no volume, said in words (``""`` when nothing). Faces
    that do not make a closed shell are sewn first (``BRepBuilderAPI_Sewing``, closing
    gaps up to :data:`SEWING_TOLERANCE` of their bounding-box diagonal); each closed
    shell becomes a solid turned outwards (``ShapeFix_Solid``), kept when its volume is
    positive."""
    kind = ocp.TopAbs_ShapeEnum
    shells = _subshapes(ocp, shape, kind.TopAbs_SHELL, kind.TopAbs_SOLID)
    faces = _subshapes(ocp, shape, kind.TopAbs_FACE, kind.TopAbs_SHELL)
    closed, loose = _closed_and_open(ocp, shells)
    loose += faces
    if loose:
        box = ocp.Bnd_Box()
        for item in loose:
            ocp.BRepBndLib.Add_s(item, box)
        sewing = ocp.BRepBuilderAPI_Sewing(SEWING_TOLERANCE * float(np.sqrt(box.SquareExtent())))
        for item in loose:
            sewing.Add(item)
        sewing.Perform()
        sewn = sewing.SewedShape()
        shells = _subshapes(ocp, sewn, kind.TopAbs_SHELL)
        sewn_closed, loose = _closed_and_open(ocp, shells)
        closed += sewn_closed
        loose += _subshapes(ocp, sewn, kind.TopAbs_FACE, kind.TopAbs_SHELL)
    solids = []
    for shell in closed:
        solid = ocp.ShapeFix_Solid().SolidFromShell(ocp.TopoDS.Shell(shell))
        properties = ocp.GProp_GProps()
        ocp.BRepGProp.VolumeProperties_s(solid, properties)
        if properties.Mass() > 0:
            solids.append(solid)
        else:
            loose.append(shell)
    if not loose:
        return solids, ""
    faces_left = sum(len(_subshapes(ocp, item, kind.TopAbs_FACE)) for item in loose)
    return solids, f"{faces_left} face{'s' * (faces_left != 1)}"


def _structure(
    ocp: Any, document: Any
) -> tuple[list[_Solid], list[tuple[str, str]], list[Skipped]]:
    """Every solid of the document's product structure, the subassemblies' names and
    product keys, and the surfaces left out (:func:`_product_solids`). The free products
    are the roots; when there are several, those that are assemblies are subassemblies
    too."""
    tool = ocp.XCAFDoc_DocumentTool.ShapeTool_s(document.Main())
    roots = _labels(ocp, tool.GetFreeShapes)
    groups: list[tuple[str, str]] = []
    solids: list[_Solid] = []
    left_out: list[Skipped] = []
    placements = itertools.count()
    for root in roots:
        within: tuple[int, ...] = ()
        if len(roots) > 1 and tool.IsAssembly_s(root):
            groups.append((_label_name(ocp, root) or "subassembly", _entry(ocp, root)))
            within = (len(groups) - 1,)
        solids += _product_solids(
            ocp, tool, root, ocp.TopLoc_Location(), within, groups, "", placements, left_out
        )
    return solids, groups, left_out


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
    solids, group_items, left_out = _structure(ocp, document)
    if not solids:
        said = "; ".join([*(f"{s.item}: {s.reason}" for s in left_out), *warnings])
        raise GeometryError(f"no solids in STEP file{': ' + said if said else ''}", source=source)
    placements = _placement_names(solids)
    names = _part_names(solids, placements)
    products: dict[str, list[str]] = {}
    for solid, placement, name in zip(solids, placements, names, strict=True):
        if solid.piece and placement:
            products.setdefault(placement, []).append(name)
    parts: list[Part] = []
    unmeshed: list[Skipped] = []
    notes: list[str] = []
    # each solid of a product is meshed once, where the product puts it, and each
    # instance is that mesh placed (module docstring)
    meshed: list[tuple[Any, Part | str, str]] = []
    for solid, name in zip(solids, names, strict=True):
        if solid.made:
            notes.append(f"{name}: {solid.made}, read as a solid")
        placement = solid.shape.Location().Transformation()
        if abs(placement.ScaleFactor()) != 1.0:
            # a scaled instance (a mapped item's scale) is meshed as placed: its radii
            # are not the product's
            part, note = _solid_part(ocp, solid.shape, source)
            placement = ocp.gp_Trsf()
        else:
            local = solid.shape.Located(ocp.TopLoc_Location())
            found = next((m for m in meshed if m[0].IsEqual(local)), None)
            if found is None:
                found = (local, *_solid_part(ocp, local, source))
                meshed.append(found)
            _, part, note = found
        if note:
            notes.append(f"{name}: {note}")
        if isinstance(part, str):
            unmeshed.append(Skipped(name, part))
        else:
            parts.append(_placed(ocp, part, name, placement))
    if not parts:
        said = "; ".join(f"{s.item}: {s.reason}" for s in unmeshed)
        raise GeometryError(f"no solid of the STEP file could be meshed: {said}", source=source)
    groups = {
        name: tuple(n for s, n in zip(solids, names, strict=True) if index in s.groups)
        for index, name in enumerate(numbered(distinct_products(group_items)))
    }
    distinct = len({hash(s.shape.Located(ocp.TopLoc_Location())) for s in solids})
    return Assembly(
        parts,
        units="mm",
        units_source="file",
        source=source,
        exact=True,
        policy=tol,
        skipped=[
            *_skipped_solids(declared, reader.Reader().Model(), distinct),
            *left_out,
            *unmeshed,
        ],
        warnings=[*warnings, *notes],
        groups=groups,
        products=products,
    )
