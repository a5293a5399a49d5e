"""STEP files written in the tests with OCP (the ``cad`` extra), for the STEP tests."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np


def write_step(path: Path | str, *shapes: Any) -> None:
    """``shapes`` written to ``path`` by Open CASCADE's STEP writer as one compound,
    unnamed (each solid a product named by the writer's placeholder)."""
    from OCP.BRep import BRep_Builder
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
    from OCP.TopoDS import TopoDS_Compound

    compound, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(compound)
    for shape in shapes:
        builder.Add(compound, shape)
    writer = STEPControl_Writer()
    writer.Transfer(compound, STEPControl_AsIs)
    writer.Write(str(path))


def helix_sweep(radius: float, pitch: float, height: float, profile: Any, z0: float = 0.0) -> Any:
    """The solid swept by the polygon ``profile`` (``(x, z)`` corners in the half-plane
    y = 0, x > 0, z from ``z0``) along the right-handed helix of ``radius`` and ``pitch``
    about the z axis from ``(radius, 0, z0)``, ``height`` tall: a thread's crest drawn as
    CAD draws it (a B-spline sweep)."""
    from OCP.BRepBuilderAPI import (
        BRepBuilderAPI_MakeEdge,
        BRepBuilderAPI_MakePolygon,
        BRepBuilderAPI_MakeWire,
    )
    from OCP.BRepLib import BRepLib
    from OCP.BRepOffsetAPI import BRepOffsetAPI_MakePipeShell
    from OCP.Geom import Geom_CylindricalSurface
    from OCP.Geom2d import Geom2d_Line
    from OCP.gp import gp_Ax3, gp_Dir, gp_Dir2d, gp_Pnt, gp_Pnt2d
    from OCP.ShapeFix import ShapeFix_Shape

    surface = Geom_CylindricalSurface(gp_Ax3(gp_Pnt(0.0, 0.0, z0), gp_Dir(0.0, 0.0, 1.0)), radius)
    # on the cylinder's (angle, height) plane the helix is the line height = pitch angle / 2 pi,
    # and its parameter is the length along that line
    line = Geom2d_Line(gp_Pnt2d(0.0, 0.0), gp_Dir2d(2 * math.pi, pitch))
    length = height * math.hypot(2 * math.pi, pitch) / pitch
    edge = BRepBuilderAPI_MakeEdge(line, surface, 0.0, length).Edge()
    BRepLib.BuildCurves3d_s(edge)
    polygon = BRepBuilderAPI_MakePolygon()
    for x, z in profile:
        polygon.Add(gp_Pnt(float(x), 0.0, z0 + float(z)))
    polygon.Close()
    pipe = BRepOffsetAPI_MakePipeShell(BRepBuilderAPI_MakeWire(edge).Wire())
    pipe.SetMode(True)
    pipe.Add(polygon.Wire())
    pipe.Build()
    pipe.MakeSolid()
    # the pipe's faces are not all turned outward; ShapeFix orients the solid
    fixed = ShapeFix_Shape(pipe.Shape())
    fixed.Perform()
    return fixed.Shape()


def cylinder(centre, radius: float, height: float, turn: float = 0.0, axis=(0, 0, 1)):
    """A cylinder from ``centre`` along ``axis``; ``turn`` (degrees) turns its seam, and so
    its tessellation, about the axis."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt

    axis = np.asarray(axis, dtype=float)
    seam = np.cross(axis, [0.0, 1.0, 0.0] if abs(axis[1]) < 0.9 else [1.0, 0.0, 0.0])
    seam /= np.linalg.norm(seam)
    seam = seam * math.cos(math.radians(turn)) + np.cross(axis, seam) * math.sin(math.radians(turn))
    frame = gp_Ax2(gp_Pnt(*map(float, centre)), gp_Dir(*axis), gp_Dir(*seam))
    return BRepPrimAPI_MakeCylinder(frame, radius, height).Shape()


def hexagon(centre, across_flats: float, height: float, turn: float = 0.0):
    """A hexagonal prism (a nut's body) standing on ``centre`` along +z, ``across_flats``
    wide; ``turn`` (degrees) turns it about its axis."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon
    from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
    from OCP.gp import gp_Pnt, gp_Vec

    x, y, z = map(float, centre)
    corner = across_flats / math.sqrt(3.0)
    polygon = BRepBuilderAPI_MakePolygon()
    for k in range(6):
        angle = math.radians(turn + 60.0 * k)
        polygon.Add(gp_Pnt(x + corner * math.cos(angle), y + corner * math.sin(angle), z))
    polygon.Close()
    face = BRepBuilderAPI_MakeFace(polygon.Wire()).Face()
    return BRepPrimAPI_MakePrism(face, gp_Vec(0.0, 0.0, float(height))).Shape()


def box(corner, size):
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.gp import gp_Pnt

    return BRepPrimAPI_MakeBox(gp_Pnt(*map(float, corner)), *map(float, size)).Shape()


def cut(a, b):
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut

    return BRepAlgoAPI_Cut(a, b).Shape()


def fuse(a, b):
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Fuse

    return BRepAlgoAPI_Fuse(a, b).Shape()


def exact_volume(shape) -> float:
    """OCCT's exact volume of ``shape`` (BRepGProp)."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    properties = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, properties)
    return abs(properties.Mass())


def common_volume(a, b) -> float:
    """OCCT's exact volume of ``a ∩ b`` (boolean common of the B-reps)."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Common

    return exact_volume(BRepAlgoAPI_Common(a, b).Shape())


def occ_mesh(shape: Any, deflection: float) -> tuple[np.ndarray, np.ndarray]:
    """The vertices and triangles of ``shape`` meshed by OCCT's BRepMesh to the linear
    ``deflection`` (absolute), read here face by face with their locations and
    orientations: a tessellation made without the project's reader, for checks."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopLoc import TopLoc_Location
    from OCP.TopoDS import TopoDS

    BRepMesh_IncrementalMesh(shape, deflection, False, 0.1, False)
    vertices, triangles, count = [], [], 0
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        face = TopoDS.Face(explorer.Current())
        location = TopLoc_Location()
        mesh = BRep_Tool.Triangulation_s(face, location)
        explorer.Next()
        if mesh is None:
            continue
        trsf = location.Transformation()
        nodes = [mesh.Node(i).Transformed(trsf).Coord() for i in range(1, mesh.NbNodes() + 1)]
        corners = np.array([mesh.Triangle(i).Get() for i in range(1, mesh.NbTriangles() + 1)]) - 1
        if face.Orientation() == TopAbs_REVERSED:
            corners = corners[:, ::-1]
        vertices.append(np.array(nodes))
        triangles.append(corners + count)
        count += len(nodes)
    return np.vstack(vertices), np.vstack(triangles)
