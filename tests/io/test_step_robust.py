"""STEP files as CAD tools write them: bodies stored as surfaces, analytic faces stored
as B-splines, a solid that BRepMesh does not mesh, product names that are placeholders,
repeated or escaped (ISO 10303-21:2016 §6.4.3), products of several solids."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from assemblykit.errors import GeometryError
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.geometry.overlaps import resolve_overlaps, touching_products
from assemblykit.io import step
from assemblykit.io.assembly import load_assembly
from assemblykit.io.step import declared_solids, decode_step_string, distinct_products
from assemblykit.planning.planner import plan
from datasets import dataset
from plan_checks import assert_steps_clear
from step_files import cut, exact_volume, write_step

cad = pytest.mark.cad


def _at(x: float, y: float, z: float) -> Any:
    from OCP.gp import gp_Trsf, gp_Vec
    from OCP.TopLoc import TopLoc_Location

    move = gp_Trsf()
    move.SetTranslation(gp_Vec(x, y, z))
    return TopLoc_Location(move)


class _Document:
    """An XCAF document written by OCP's XCAF writer: products (``product``), placed in
    assemblies (``place``), optionally named; an instance may be named too."""

    def __init__(self) -> None:
        from OCP.TCollection import TCollection_ExtendedString
        from OCP.TDocStd import TDocStd_Document
        from OCP.XCAFDoc import XCAFDoc_DocumentTool

        self.document = TDocStd_Document(TCollection_ExtendedString("MDTV-XCAF"))
        self.tool = XCAFDoc_DocumentTool.ShapeTool_s(self.document.Main())

    @staticmethod
    def _named(label: Any, name: str | None) -> Any:
        from OCP.TCollection import TCollection_ExtendedString
        from OCP.TDataStd import TDataStd_Name

        if name is not None:
            TDataStd_Name.Set_s(label, TCollection_ExtendedString(name))
        return label

    def assembly(self, name: str) -> Any:
        return self._named(self.tool.NewShape(), name)

    def product(self, name: str | None, *shapes: Any) -> Any:
        """A product of ``shapes`` (a compound when there are several); ``None``: XCAF
        names it after its shape type."""
        from OCP.BRep import BRep_Builder
        from OCP.TopoDS import TopoDS_Compound

        shape = shapes[0]
        if len(shapes) > 1:
            shape, builder = TopoDS_Compound(), BRep_Builder()
            builder.MakeCompound(shape)
            for part in shapes:
                builder.Add(shape, part)
        return self._named(self.tool.AddShape(shape, False), name)

    def place(
        self, assembly: Any, product: Any, at: tuple[float, float, float], name: str | None = None
    ) -> None:
        self._named(self.tool.AddComponent(assembly, product, _at(*at)), name)

    def write(self, path: Path) -> Path:
        from OCP.STEPCAFControl import STEPCAFControl_Writer
        from OCP.STEPControl import STEPControl_AsIs

        self.tool.UpdateAssemblies()
        writer = STEPCAFControl_Writer()
        writer.SetNameMode(True)
        writer.Transfer(self.document, STEPControl_AsIs)
        writer.Write(str(path))
        return path


def _box(x: float, y: float, z: float, at: tuple[float, float, float] = (0, 0, 0)) -> Any:
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.gp import gp_Pnt

    return BRepPrimAPI_MakeBox(gp_Pnt(*at), x, y, z).Shape()


def _cylinder(radius: float, height: float, at: tuple[float, float, float]) -> Any:
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt

    return BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(*at), gp_Dir(0, 0, 1)), radius, height).Shape()


def _nurbs(shape: Any) -> Any:
    """``shape`` with every face's surface (and edge's curve) made a B-spline."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert

    return BRepBuilderAPI_NurbsConvert(shape, True).Shape()


def _faces(shape: Any) -> list[Any]:
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer

    explorer, found = TopExp_Explorer(shape, TopAbs_FACE), []
    while explorer.More():
        found.append(explorer.Current())
        explorer.Next()
    return found


def _shell(faces: list[Any]) -> Any:
    """A shell of ``faces`` (closed when they close a volume), not a solid."""
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Shell

    shell, builder = TopoDS_Shell(), BRep_Builder()
    builder.MakeShell(shell)
    for face in faces:
        builder.Add(shell, face)
    shell.Closed(len(faces) == 6)
    return shell


# -- bodies stored as surfaces --------------------------------------------------------


@cad
@pytest.mark.parametrize("inside_out", [False, True], ids=["outwards", "inside-out"])
def test_a_body_stored_as_a_closed_shell_is_a_part_that_leaves(tmp_path, inside_out):
    """A lid written as a surface model (its six faces a closed shell, the writer's
    ``SHELL_BASED_SURFACE_MODEL``) on a solid base: the lid is a part of the box's volume
    (10 x 10 x 4), said read from a shell, and is lifted off (+z) clear of the base,
    as it would be drawn as a solid; turned inside out, the same."""
    pytest.importorskip("OCP")
    shell = _shell(_faces(_box(10, 10, 4, (5, 5, 5))))
    doc = _Document()
    rig = doc.assembly("rig")
    doc.place(rig, doc.product("base", _box(20, 20, 5)), (0, 0, 0))
    doc.place(rig, doc.product("lid", shell.Reversed() if inside_out else shell), (0, 0, 0))
    path = doc.write(tmp_path / "lid.step")
    assert "SHELL_BASED_SURFACE_MODEL" in path.read_text()
    asm = load_assembly(path)
    assert asm.names == ["base", "lid"] and asm.skipped == ()
    lid = asm.parts["lid"].mesh
    assert lid.is_watertight and lid.volume == pytest.approx(400, rel=1e-9)
    assert asm.warnings == ("lid: a closed shell, read as a solid",)
    result = plan(asm)
    assert result.feasible and [s.parts for s in result.steps] == [("lid",)]
    assert np.allclose(result.steps[0].direction, [0, 0, 1])
    assert_steps_clear(asm, result)


@cad
@pytest.mark.parametrize("gap", [0.0, 0.001], ids=["closed", "a thousandth apart"])
def test_loose_faces_that_close_a_body_are_sewn_into_a_part(tmp_path, gap):
    """The lid's product written as its six faces, not joined in a shell, its top face
    ``gap`` above where it closes the box (a writer's rounding): sewn, they close the
    same box, 10 x 10 x 4 to within the gap."""
    pytest.importorskip("OCP")
    doc = _Document()
    rig = doc.assembly("rig")
    doc.place(rig, doc.product("base", _box(20, 20, 5)), (0, 0, 0))
    doc.place(rig, doc.product("lid", *_lid_faces(gap)), (0, 0, 0))
    asm = load_assembly(doc.write(tmp_path / "faces.step"))
    assert asm.names == ["base", "lid"] and asm.skipped == ()
    assert 400 - 1e-9 <= asm.parts["lid"].mesh.volume <= 100 * (4 + gap) + 1e-9
    assert asm.warnings == ("lid: a closed shell, read as a solid",)


def _lid_faces(gap: float) -> list[Any]:
    """The six faces of the box 10 x 10 x 4 at (5, 5, 5), its top one raised by
    ``gap``."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
    from OCP.gp import gp_Trsf, gp_Vec

    raise_top = gp_Trsf()
    raise_top.SetTranslation(gp_Vec(0, 0, gap))
    faces = _faces(_box(10, 10, 4, (5, 5, 5)))
    top = max(range(len(faces)), key=lambda k: _shape_corners(faces[k])[:, 2].min())
    faces[top] = BRepBuilderAPI_Transform(faces[top], raise_top, True).Shape()
    return faces


def _shape_corners(shape: Any) -> np.ndarray:
    from OCP.BRep import BRep_Tool
    from OCP.TopAbs import TopAbs_VERTEX
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    explorer, corners = TopExp_Explorer(shape, TopAbs_VERTEX), []
    while explorer.More():
        corners.append(BRep_Tool.Pnt_s(TopoDS.Vertex(explorer.Current())).Coord())
        explorer.Next()
    return np.array(corners)


@cad
def test_faces_too_far_apart_to_close_a_body_are_left_out(tmp_path):
    """The lid's top face 0.5 above its sides, where sewing closes gaps of 1e-4 of the
    lid's diagonal (0.0015): no closed shell, so the lid is listed as left out."""
    pytest.importorskip("OCP")
    doc = _Document()
    rig = doc.assembly("rig")
    doc.place(rig, doc.product("base", _box(20, 20, 5)), (0, 0, 0))
    doc.place(rig, doc.product("lid", *_lid_faces(0.5)), (0, 0, 0))
    asm = load_assembly(doc.write(tmp_path / "apart.step"))
    assert asm.names == ["base"]
    assert [(s.item, s.reason) for s in asm.skipped] == [
        ("lid", "6 faces: surfaces enclosing no volume, not a solid; left out")
    ]


@cad
def test_open_surfaces_and_wireframe_are_said_left_out(tmp_path, capsys):
    """Five faces of a box (a sheet enclosing nothing) and a sketched edge beside a
    solid: the solid is the only part; the sheet and the edge are listed as left out,
    by their product's name, and the command line says so and plans the rest."""
    pytest.importorskip("OCP")
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
    from OCP.gp import gp_Pnt

    from cli_runs import run

    doc = _Document()
    rig = doc.assembly("rig")
    doc.place(rig, doc.product("base", _box(20, 20, 5)), (0, 0, 0))
    doc.place(rig, doc.product("sheet", _shell(_faces(_box(10, 10, 4))[:5])), (0, 0, 30))
    edge = BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 50), gp_Pnt(10, 10, 50)).Edge()
    doc.place(rig, doc.product("sketch", edge), (0, 0, 0))
    path = doc.write(tmp_path / "sheet.step")
    asm = load_assembly(path)
    assert asm.names == ["base"]
    assert [(s.item, s.reason, s.unreadable) for s in asm.skipped] == [
        ("sheet", "5 faces: surfaces enclosing no volume, not a solid; left out", False),
        ("sketch", "1 edge of wireframe geometry, no volume; left out", False),
    ]
    code, _, err = run(capsys, "plan", str(path))
    assert code == 0
    assert f"{path}: skipped sheet: 5 faces: surfaces enclosing no volume" in err


@cad
def test_a_file_of_surfaces_only_is_an_error_saying_what_it_holds(tmp_path, capsys):
    pytest.importorskip("OCP")
    from cli_runs import run

    path = tmp_path / "face.step"
    write_step(path, _faces(_box(10, 10, 4))[0])
    with pytest.raises(GeometryError, match=r"no solids in STEP file: .*1 face: surfaces"):
        load_assembly(path)
    code, out, err = run(capsys, "plan", str(path))
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and "1 face: surfaces enclosing no volume" in err


# -- mirrored placements ---------------------------------------------------------------


@cad
def test_a_mirrored_copy_of_a_part_is_the_mirror_image_of_it(tmp_path):
    """A bracket with a hole (a 10 x 10 x 2 plate, Ø4 hole 3 from its left edge), placed
    once as drawn and once mirrored in the plane x = 0 (a left-hand copy), on a base,
    with a Ø4 pin at its hole's diameter in each hole: the mirrored copy is the bracket's
    mirror image, its mesh outward (positive volume, the same 200 - 8π), its hole a hole
    (concave) at x = -3, and each pin's contact with its bracket cylindrical, so each pin
    leaves along its axis, clear of every part."""
    pytest.importorskip("OCP")
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt, gp_Trsf
    from OCP.TopLoc import TopLoc_Location

    plate = _cut(_box(10, 10, 2, (0, -5, 0)), _cylinder(2, 4, (3, 0, -1)))
    doc = _Document()
    rig = doc.assembly("rig")
    doc.place(rig, doc.product("base", _box(40, 20, 2, (-20, -10, -2))), (0, 0, 0))
    bracket = doc.product("bracket", plate)
    doc.place(rig, bracket, (0, 0, 0))
    mirror = gp_Trsf()
    mirror.SetMirror(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(1, 0, 0)))
    doc.tool.AddComponent(rig, bracket, TopLoc_Location(mirror))
    pin = doc.product("pin", _cylinder(2, 6, (0, 0, 0)))
    for x in (3, -3):
        doc.place(rig, pin, (x, 0, 0))
    asm = load_assembly(doc.write(tmp_path / "mirrored.step"))
    assert asm.names == ["base", "bracket_1", "bracket_2", "pin_1", "pin_2"]
    drawn, copy = asm.parts["bracket_1"].mesh, asm.parts["bracket_2"].mesh
    assert copy.is_watertight and copy.volume > 0
    assert copy.volume == pytest.approx(drawn.volume) == pytest.approx(200 - 8 * np.pi, rel=1e-2)
    assert np.allclose(drawn.bounds, [[0, -5, 0], [10, 5, 2]])
    mirrored = np.asarray(drawn.vertices) * [-1, 1, 1]
    assert np.allclose(
        np.unique(mirrored.round(9), axis=0), np.unique(copy.vertices.round(9), axis=0)
    )
    (hole,) = [s for s in asm.parts["bracket_2"].surfaces if s.kind == "cylinder"]
    assert not hole.convex and np.allclose(hole.point[:2], [-3, 0]) and hole.radius == 2
    curved = {(c.a, c.b): [k.kind for k in c.curved] for c in assembly_contacts(asm) if c.curved}
    assert curved[("bracket_1", "pin_1")] == curved[("bracket_2", "pin_2")] == ["cylindrical"]
    result = plan(asm)
    assert result.feasible
    assert_steps_clear(asm, result)


@cad
def test_a_product_placed_twice_is_the_same_part_in_each_place_and_scaled_where_scaled(
    tmp_path,
):
    """A pin (radius 2, 10 long) placed as drawn, 30 along x, and scaled 2 times about
    the origin (a mapped item's scale): the second is the first moved (its vertices 30
    along x), the third has radius 4 and 8 times the volume."""
    pytest.importorskip("OCP")
    from OCP.gp import gp_Pnt, gp_Trsf
    from OCP.TopLoc import TopLoc_Location

    doc = _Document()
    rig = doc.assembly("rig")
    pin = doc.product("pin", _cylinder(2, 10, (0, 0, 0)))
    doc.place(rig, pin, (0, 0, 0))
    doc.place(rig, pin, (30, 0, 0))
    double = gp_Trsf()
    double.SetScale(gp_Pnt(0, 0, 0), 2.0)
    doc.tool.AddComponent(rig, pin, TopLoc_Location(double))
    asm = load_assembly(doc.write(tmp_path / "pins.step"))
    first, moved, scaled = (asm.parts[n] for n in ("pin_1", "pin_2", "pin_3"))
    assert np.array_equal(moved.mesh.faces, first.mesh.faces)
    assert np.allclose(moved.mesh.vertices, first.mesh.vertices + np.array([30, 0, 0]), atol=1e-12)
    ((_, axis, radius),) = [
        (s.point, s.axis, s.radius) for s in moved.surfaces if s.kind == "cylinder"
    ]
    assert radius == 2.0 and np.allclose(np.abs(axis), [0, 0, 1])
    assert [s.radius for s in scaled.surfaces if s.kind == "cylinder"] == [4.0]
    assert scaled.mesh.volume == pytest.approx(8 * first.mesh.volume, rel=1e-2)


# -- analytic faces stored as B-splines ---------------------------------------------


@pytest.fixture(scope="module")
def bspline_step(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The plate with a through hole of radius 5 and the shaft of radius 5 in it, every
    face a B-spline surface."""
    pytest.importorskip("OCP")
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut

    plate = BRepAlgoAPI_Cut(_box(40, 40, 10, (-20, -20, 0)), _cylinder(5, 40, (0, 0, -10))).Shape()
    path = tmp_path_factory.mktemp("bspline") / "parts.step"
    write_step(path, _nurbs(plate), _nurbs(_cylinder(5, 30, (0, 0, -10))))
    return path


@cad
def test_bspline_faces_keep_their_cylinders_and_planes(bspline_step):
    text = bspline_step.read_text()
    assert "B_SPLINE_SURFACE" in text
    assert "CYLINDRICAL_SURFACE" not in text and "PLANE(" not in text
    asm = load_assembly(bspline_step)
    plate, shaft = asm["solid1"].surfaces, asm["solid2"].surfaces
    for surfaces, convex, planes in ((shaft, True, 2), (plate, False, 6)):
        (cylinder,) = [s for s in surfaces if s.kind == "cylinder"]
        assert cylinder.radius == pytest.approx(5.0, abs=1e-6)
        assert cylinder.convex is convex
        assert abs(cylinder.axis @ [0, 0, 1]) == pytest.approx(1.0, abs=1e-9)
        np.testing.assert_allclose(cylinder.point[:2], [0, 0], atol=1e-6)
        assert sorted(s.kind for s in surfaces) == ["cylinder"] + ["plane"] * planes
    top = [s for s in shaft if s.kind == "plane" and s.axis @ [0, 0, 1] > 0.5]
    assert len(top) == 1 and top[0].point[2] == pytest.approx(20.0, abs=1e-6)


@cad
def test_bspline_shaft_in_its_hole_is_a_cylindrical_contact(bspline_step):
    contacts = {c.pair: c for c in assembly_contacts(load_assembly(bspline_step))}
    assert set(contacts) == {("solid1", "solid2")}
    (cylinder,) = contacts["solid1", "solid2"].curved
    assert (cylinder.kind, cylinder.inner) == ("cylindrical", "solid2")
    assert cylinder.radius == pytest.approx(5.0, abs=1e-6)
    assert cylinder.extent == pytest.approx((0.0, 10.0), abs=1e-6)


@cad
def test_a_placed_bspline_face_keeps_its_placed_axis(tmp_path):
    pytest.importorskip("OCP")
    doc = _Document()
    rig = doc.assembly("rig")
    doc.place(rig, doc.product("shaft", _nurbs(_cylinder(2, 8, (0, 0, 0)))), (10, -3, 1))
    asm = load_assembly(doc.write(tmp_path / "placed.step"))
    (cylinder,) = [s for s in asm["shaft"].surfaces if s.kind == "cylinder"]
    assert cylinder.radius == pytest.approx(2.0, abs=1e-6)
    np.testing.assert_allclose(cylinder.point, [10, -3, 1], atol=1e-6)


# -- a solid that BRepMesh does not mesh --------------------------------------------


@pytest.fixture(scope="module")
def three_parts(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A plate (40 x 20 x 5), a pin (radius 2, height 10) standing on it and a ball
    (radius 3) lying on it, three named products."""
    pytest.importorskip("OCP")
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeSphere
    from OCP.gp import gp_Pnt

    doc = _Document()
    rig = doc.assembly("rig")
    doc.place(rig, doc.product("plate", _box(40, 20, 5)), (0, 0, 0))
    doc.place(rig, doc.product("pin", _cylinder(2, 10, (0, 0, 0))), (10, 10, 5))
    doc.place(
        rig, doc.product("ball", BRepPrimAPI_MakeSphere(gp_Pnt(0, 0, 0), 3).Shape()), (30, 10, 8)
    )
    return doc.write(tmp_path_factory.mktemp("mesh") / "three.step")


def _failing(monkeypatch: pytest.MonkeyPatch, fails: Callable[[str, Any, int], bool]) -> None:
    """BRepMesh's triangles of the faces for which ``fails(kind, face, asked)`` holds are
    not there (``kind``: the name of the face's surface type, ``asked``: how many times
    that face's triangles were asked for before)."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface

    original = step._face_triangles
    calls: dict[int, int] = {}

    def triangles(ocp: Any, face: Any) -> tuple[np.ndarray, np.ndarray]:
        asked = calls.get(hash(face), 0)
        calls[hash(face)] = asked + 1
        surface = BRepAdaptor_Surface(face)
        if fails(surface.GetType().name.removeprefix("GeomAbs_"), surface, asked):
            return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
        return original(ocp, face)

    monkeypatch.setattr(step, "_face_triangles", triangles)


def _at_the_bottom(kind: str, surface: Any) -> bool:
    """Whether a face is the plate's bottom face: the one in the plane z = 0 wider than
    the pin (solids are meshed where their products put them: the pin's bottom is in
    that plane too)."""
    if kind != "Plane":
        return False
    plane = surface.Plane()
    wide = surface.LastUParameter() - surface.FirstUParameter() > 10
    return abs(plane.Axis().Direction().Z()) == 1 and plane.Location().Z() == 0 and wide


@cad
def test_a_face_left_unmeshed_once_is_meshed_again(three_parts, monkeypatch):
    # the pin's side, the only cylinder, the first time
    _failing(monkeypatch, lambda kind, surface, asked: kind == "Cylinder" and asked == 0)
    asm = load_assembly(three_parts)
    assert asm.names == ["plate", "pin", "ball"] and asm.skipped == ()
    assert asm["pin"].mesh.is_watertight
    assert asm["pin"].volume == pytest.approx(np.pi * 4 * 10, rel=1e-2)
    assert [s.radius for s in asm["pin"].surfaces if s.kind == "cylinder"] == [2.0]
    (warning,) = asm.warnings
    assert warning.startswith("pin: BRepMesh left 1 face untriangulated; meshed again with")


@cad
def test_the_hole_of_a_face_never_meshed_is_closed(three_parts, monkeypatch):
    _failing(monkeypatch, lambda kind, surface, asked: _at_the_bottom(kind, surface))
    asm = load_assembly(three_parts)
    assert asm.names == ["plate", "pin", "ball"] and asm.skipped == ()
    assert asm["plate"].mesh.is_watertight
    assert asm["plate"].volume == pytest.approx(40 * 20 * 5, rel=1e-9)
    assert [s.kind for s in asm["plate"].surfaces] == ["plane"] * 5
    assert asm.warnings == (
        "plate: BRepMesh left 1 face untriangulated; the hole this leaves in its mesh is "
        "closed by a fan of triangles",
    )


@cad
def test_a_part_whose_holes_cannot_be_closed_is_its_convex_hull(three_parts, monkeypatch):
    # the pin without its side: closing its two circles would leave no volume
    _failing(monkeypatch, lambda kind, surface, asked: kind == "Cylinder")
    asm = load_assembly(three_parts)
    assert asm.names == ["plate", "pin", "ball"] and asm.skipped == ()
    assert asm["pin"].mesh.is_watertight and asm["pin"].surfaces == ()
    assert asm["pin"].volume == pytest.approx(np.pi * 4 * 10, rel=1e-2)
    np.testing.assert_allclose(asm["pin"].mesh.bounds, [[8, 8, 5], [12, 12, 15]], atol=1e-2)
    assert asm.warnings == ("pin: BRepMesh left 1 face untriangulated; its convex hull is used",)
    assert asm["ball"].volume == pytest.approx(4 / 3 * np.pi * 27, rel=1e-2)


@cad
def test_a_part_with_nothing_usable_is_skipped_and_the_others_kept(three_parts, monkeypatch):
    # the ball's only face: its two poles are all that is left
    _failing(monkeypatch, lambda kind, surface, asked: kind == "Sphere")
    asm = load_assembly(three_parts)
    assert asm.names == ["plate", "pin"]
    (skipped,) = asm.skipped
    assert skipped.item == "ball"
    assert skipped.reason.startswith("BRepMesh left 1 face untriangulated")
    assert skipped.reason.endswith("the part is left out")
    assert asm.to_dict()["skipped"] == [skipped.to_dict()]


@cad
def test_a_file_without_any_part_is_an_error(tmp_path, monkeypatch):
    pytest.importorskip("OCP")
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeSphere
    from OCP.gp import gp_Pnt

    path = tmp_path / "ball.step"
    write_step(path, BRepPrimAPI_MakeSphere(gp_Pnt(0, 0, 0), 3).Shape())
    _failing(monkeypatch, lambda kind, surface, asked: True)
    with pytest.raises(GeometryError, match=r"ball\.step.*solid1: BRepMesh left 1 face"):
        load_assembly(path)


@cad
def test_a_solid_that_touches_itself_along_an_edge_keeps_its_shape(tmp_path):
    # one solid: two unit cubes drawn as one prism whose outline passes twice through
    # (1, 1), so its side faces meet four at the edge x = y = 1 (valid for BRepCheck);
    # a cube fills the notch at x in [0, 1], y in [1, 2]. By hand the part's volume is
    # 2, not the 3 of its convex hull, and the cube shares nothing with it
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon
    from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
    from OCP.gp import gp_Pnt, gp_Vec

    from step_files import box

    outline = BRepBuilderAPI_MakePolygon()
    for x, y in [(0, 0), (1, 0), (1, 1), (2, 1), (2, 2), (1, 2), (1, 1), (0, 1)]:
        outline.Add(gp_Pnt(x, y, 0))
    outline.Close()
    face = BRepBuilderAPI_MakeFace(outline.Wire()).Face()
    steps = BRepPrimAPI_MakePrism(face, gp_Vec(0, 0, 1)).Shape()
    path = tmp_path / "steps.step"
    write_step(path, steps, box((0, 1, 0), (1, 1, 1)))
    asm = load_assembly(path)
    assert asm.warnings == (
        "solid1: its surface meets itself along 1 edge; its mesh is split there into sheets",
    )
    assert asm["solid1"].mesh.is_watertight
    assert asm["solid1"].volume == pytest.approx(2.0, rel=1e-9)
    assert {s.kind for s in asm["solid1"].surfaces} == {"plane"}
    assert resolve_overlaps(asm).overlaps == ()
    result = plan(asm, max_and_or_parts=0)
    assert result.feasible
    assert_steps_clear(asm, result)


@cad
@pytest.mark.slow
def test_the_gripper_loads_every_part():
    """``gripper.step`` of online-robotics/CAD-data (commit 74ada1e), 144 solids:
    BRepMesh never triangulates a conical face of each of the two M2 screws inside the
    servos."""
    asm = load_assembly(dataset("step_gripper/gripper.step"))
    assert len(asm.parts) + len(asm.skipped) == 144
    screws = [n for n in asm.names if "M2 x 4" in n]
    assert len(screws) == 2 - len(asm.skipped)
    assert len(asm.warnings) == 2
    for warning in asm.warnings:
        assert "M2 x 4" in warning and "BRepMesh left 1 face untriangulated" in warning
    assert all(asm[n].mesh.is_watertight for n in asm.names)
    assert "M3 Locknut_12_2" in asm.parts and "Laserteil 7_3" in asm.parts
    assert set(asm.groups) == {
        "Gripper",
        "SG90 - Micro Servo 9g - Tower Pro v2",
        "SG90 - Micro Servo 9g - Tower Pro v2 (2)",
        "Nuts and Bolts",
    }


# -- names --------------------------------------------------------------------------


@pytest.fixture(scope="module")
def named_step(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``rig`` places: an unnamed product three times (twice as named instances), a
    ``bracket`` of two solids twice, a ``lock`` of two solids once, and two different
    products both named ``Body``, each twice; and two different subassemblies both named
    ``arm``, each holding the same ``pad``."""
    pytest.importorskip("OCP")
    doc = _Document()
    rig = doc.assembly("rig")
    wheel = doc.product(None, _box(1, 1, 1))
    doc.place(rig, wheel, (0, 0, 0), "left wheel")
    doc.place(rig, wheel, (2, 0, 0), "right wheel")
    doc.place(rig, wheel, (4, 0, 0))
    bracket = doc.product("bracket", _box(1, 1, 1), _box(1, 1, 1, (2, 0, 0)))
    doc.place(rig, bracket, (0, 10, 0))
    doc.place(rig, bracket, (0, 20, 0))
    doc.place(rig, doc.product("lock", _box(1, 1, 1), _box(1, 1, 1, (2, 0, 0))), (0, 30, 0))
    small, large = doc.product("Body", _box(1, 1, 1)), doc.product("Body", _box(2, 2, 2))
    for x in (0, 5):
        doc.place(rig, small, (x, 40, 0))
    for x in (0, 5):
        doc.place(rig, large, (x, 50, 0))
    pad = doc.product("pad", _box(1, 1, 1))
    for y in (60, 70):
        arm = doc.assembly("arm")
        doc.place(arm, pad, (0, 0, 0))
        doc.place(rig, arm, (0, y, 0))
    return doc.write(tmp_path_factory.mktemp("names") / "rig.step")


@cad
def test_names_follow_products_instances_and_solids(named_step):
    asm = load_assembly(named_step)
    corners = {
        "left wheel": (0, 0),
        "right wheel": (2, 0),
        "solid3": (4, 0),
        "bracket_1_1": (0, 10),
        "bracket_1_2": (2, 10),
        "bracket_2_1": (0, 20),
        "bracket_2_2": (2, 20),
        "lock_1": (0, 30),
        "lock_2": (2, 30),
        "Body_1": (0, 40),
        "Body_2": (5, 40),
        "Body (2)_1": (0, 50),
        "Body (2)_2": (5, 50),
        "pad_1": (0, 60),
        "pad_2": (0, 70),
    }
    assert asm.names == list(corners)
    for name, corner in corners.items():
        np.testing.assert_allclose(asm[name].mesh.bounds[0][:2], corner, atol=1e-9)
    assert asm["Body (2)_1"].volume == pytest.approx(8.0)
    assert asm.groups == {"arm": ("pad_1",), "arm (2)": ("pad_2",)}
    assert asm.products == {
        "bracket_1": ("bracket_1_1", "bracket_1_2"),
        "bracket_2": ("bracket_2_1", "bracket_2_2"),
        "lock": ("lock_1", "lock_2"),
    }


def _cut(shape: Any, *tools: Any) -> Any:
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut

    for tool in tools:
        shape = BRepAlgoAPI_Cut(shape, tool).Shape()
    return shape


@pytest.fixture(scope="module")
def locknut_step(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A plate (z 0 to 2, a hole of radius 1.5), a screw of radius 1.5 through it (its
    head of radius 3 below) and a ``locknut`` product of two solids above the plate: the
    nut (z 2 to 6, a hole of radius 1.5, a cavity of radius 2.5 from z 3.5 to 4.5) and
    its nylon insert, the ring filling the cavity, whose hole (radius 1.2) the screw's
    thread cuts into."""
    pytest.importorskip("OCP")
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Fuse

    doc = _Document()
    rig = doc.assembly("rig")
    plate = _cut(_box(20, 20, 2, (-10, -10, 0)), _cylinder(1.5, 4, (0, 0, -1)))
    screw = BRepAlgoAPI_Fuse(_cylinder(1.5, 7, (0, 0, 0)), _cylinder(3, 1, (0, 0, -1))).Shape()
    cavity = _cylinder(2.5, 1, (0, 0, 3.5))
    nut = _cut(_box(8, 8, 4, (-4, -4, 2)), _cylinder(1.5, 6, (0, 0, 1)), cavity)
    insert = _cut(_cylinder(2.5, 1, (0, 0, 3.5)), _cylinder(1.2, 2, (0, 0, 3)))
    doc.place(rig, doc.product("plate", plate), (0, 0, 0))
    doc.place(rig, doc.product("screw", screw), (0, 0, 0))
    doc.place(rig, doc.product("locknut", nut, insert), (0, 0, 0))
    return doc.write(tmp_path_factory.mktemp("locknut") / "locknut.step")


@cad
def test_a_solid_named_only_by_the_subassembly_around_it_takes_its_name(tmp_path):
    # build123d and CadQuery write each named object as an assembly holding one product
    # that XCAF names after its shape type (SOLID): each part takes the name of the
    # assembly around it (an assembly placed twice numbers its parts, as a product
    # placed twice does), a named instance inside keeps its own name, and a product
    # with no name outside any named assembly is still solid<i>
    doc = _Document()
    rig = doc.assembly("Peg Turner")
    for name, at in (("Socket Body", 0), ("Handle Knob", 5)):
        wrapper = doc.assembly(name)
        doc.place(wrapper, doc.product("SOLID", _box(1, 1, 1)), (0, 0, 0))
        doc.place(rig, wrapper, (at, 0, 0))
    bolt = doc.assembly("M3 Bolt")
    doc.place(bolt, doc.product("SOLID", _box(1, 1, 3)), (0, 0, 0))
    for x in (10, 12):
        doc.place(rig, bolt, (x, 0, 0))
    knob = doc.assembly("knob")
    doc.place(knob, doc.product("SOLID", _box(1, 1, 1)), (0, 0, 0), "grip")
    doc.place(rig, knob, (15, 0, 0))
    doc.place(rig, doc.product(None, _box(1, 1, 1)), (20, 0, 0))
    asm = load_assembly(doc.write(tmp_path / "wrapped.step"))
    corners = {
        "Socket Body": 0,
        "Handle Knob": 5,
        "M3 Bolt_1": 10,
        "M3 Bolt_2": 12,
        "grip": 15,
        "solid6": 20,
    }
    assert asm.names == list(corners)
    for name, x in corners.items():
        assert asm[name].mesh.bounds[0][0] == pytest.approx(x, abs=1e-9)


@cad
def test_a_locknut_of_two_solids_is_planned_as_one_part(locknut_step):
    # the insert is captured in the nut: no translation separates them, as no fitter
    # would; the product is one part, and the screw's thread in the insert (a ring of
    # pi (1.5^2 - 1.2^2) x 1 = 2.545) is cut from the screw as designed interference
    asm = load_assembly(locknut_step)
    assert asm.names == ["plate", "screw", "locknut_1", "locknut_2"]
    assert asm.products == {"locknut": ("locknut_1", "locknut_2")}
    prepared = resolve_overlaps(asm)
    assert sorted(prepared.names) == ["locknut", "plate", "screw"]
    assert prepared.joined == {"locknut": ("locknut_1", "locknut_2")}
    assert prepared["locknut"].volume == pytest.approx(
        asm["locknut_1"].volume + asm["locknut_2"].volume, rel=1e-9
    )
    (overlap,) = prepared.overlaps
    assert {overlap.a, overlap.b} == {"screw", "locknut"}
    assert overlap.volume == pytest.approx(np.pi * (1.5**2 - 1.2**2), rel=0.02)
    assert overlap.resolution == "trimmed from screw"
    result = plan(prepared, max_and_or_parts=0)
    assert result.feasible and ("locknut",) in [s.parts for s in result.steps]
    assert result.to_dict()["joined"] == {"locknut": ["locknut_1", "locknut_2"]}
    assert_steps_clear(prepared, result)
    # planned solid by solid, the insert stays locked in its nut
    apart = plan(resolve_overlaps(asm, join_products=False), max_and_or_parts=0)
    assert not apart.feasible and {"locknut_1", "locknut_2"} <= set(apart.stuck)


@cad
def test_the_solids_of_a_product_that_lie_apart_stay_parts_of_their_own(tmp_path):
    # one product "bolts" of four solids: two bolts 10 apart, each drawn with a washer
    # touching it (a head on top of its washer), as one body; by hand the product falls
    # into two touching sets, each joined (named by its solids), the two sets apart
    doc = _Document()
    rig = doc.assembly("rig")
    solids = []
    for x in (0, 10):
        solids += [_box(2, 2, 6, (x, 0, 0)), _box(4, 4, 1, (x - 1, -1, 6))]
    doc.place(rig, doc.product("bolts", *solids), (0, 0, 0))
    doc.place(rig, doc.product("plate", _box(20, 6, 1, (-4, -2, -1))), (0, 0, 0))
    asm = load_assembly(doc.write(tmp_path / "bolts.step"))
    assert asm.products == {"bolts": ("bolts_1", "bolts_2", "bolts_3", "bolts_4")}
    assert touching_products(asm) == {
        "bolts_1+bolts_2": ("bolts_1", "bolts_2"),
        "bolts_3+bolts_4": ("bolts_3", "bolts_4"),
    }
    prepared = resolve_overlaps(asm)
    assert sorted(prepared.names) == ["bolts_1+bolts_2", "bolts_3+bolts_4", "plate"]
    assert prepared["bolts_1+bolts_2"].volume == pytest.approx(24 + 16, rel=1e-9)


@cad
def test_the_motion_of_a_product_of_two_solids_is_that_of_one_part(locknut_step, capsys):
    # the insert captured in its nut moves with it: the motion command takes the
    # product as one part, the locknut, as the plan does; solid by solid on request
    import json

    from assemblykit.geometry.overlaps import join_products
    from cli_runs import run

    asm = load_assembly(locknut_step)
    joined = join_products(asm)
    assert joined.names == ["plate", "screw", "locknut"] and joined.products == {}
    assert joined.joined == {"locknut": ("locknut_1", "locknut_2")}
    code, out, _ = run(capsys, "motion", str(locknut_step), "--json")
    assert code == 0
    assert list(json.loads(out)["parts"]) == ["plate", "screw", "locknut"]
    code, out, _ = run(capsys, "motion", str(locknut_step), "--json", "--split-products")
    assert code == 0
    assert list(json.loads(out)["parts"]) == ["plate", "screw", "locknut_1", "locknut_2"]


@cad
def test_a_joined_locknut_keeps_the_exact_surfaces_left_outside(locknut_step):
    # the union of nut and insert keeps its members' exact surfaces on its triangles:
    # the nut's bore (radius 1.5) above and below the insert, the insert's bore (1.2)
    # between, which the screw passes through
    asm = load_assembly(locknut_step)
    nut = resolve_overlaps(asm)["locknut"]
    assert len(nut.surfaces) == len(asm["locknut_1"].surfaces) + len(asm["locknut_2"].surfaces)
    bores = [s for s in nut.surfaces if s.kind == "cylinder" and s.radius < 2]
    assert sorted(round(s.radius, 6) for s in bores) == [1.2, 1.5, 1.5]
    assert all(not s.convex for s in bores)
    corners = np.asarray(nut.mesh.triangles)
    for surface in nut.surfaces:
        points = corners[surface.faces].reshape(-1, 3) - surface.point
        if surface.kind == "cylinder":
            along = points @ surface.axis
            across = np.linalg.norm(points - np.outer(along, surface.axis), axis=1)
            # the chords of the tessellation lie within its deflection of the cylinder
            assert np.allclose(across, surface.radius, atol=0.01 * surface.radius)
        elif surface.kind == "plane":
            assert np.allclose(points @ surface.axis, 0.0, atol=1e-9)
    # the bore of the insert runs between its faces at z 3.5 and 4.5
    (insert_bore,) = [s for s in bores if s.radius == pytest.approx(1.2)]
    z = corners[insert_bore.faces][..., 2]
    assert z.min() == pytest.approx(3.5) and z.max() == pytest.approx(4.5)


@pytest.mark.parametrize(
    ("named", "names"),
    [
        ([("Body", "a"), ("Body", "a"), ("Body", "b")], ["Body", "Body", "Body (2)"]),
        ([("Body", "a"), ("Body (2)", "c"), ("Body", "b")], ["Body", "Body (2)", "Body (3)"]),
        ([("", "a"), ("pin", "b"), ("", "c")], ["", "pin", ""]),
    ],
)
def test_distinct_products_of_one_name_get_distinct_names(named, names):
    assert distinct_products(named) == names


ESCAPED = {
    "Pe\\X\\E7a": "Peça",
    "Pe\\X\\87a": "Pe\x87a",  # a C1 control in ISO 8859-1, as the gripper has it
    "\\X2\\00E700E9\\X0\\x": "çéx",
    "\\X2\\D83DDE00\\X0\\": "\U0001f600",
    "\\X4\\0001F600\\X0\\": "\U0001f600",
    "\\S\\g": "ç",
    "\\PB\\\\S\\1": "ą",
    "a\\\\b": "a\\b",
    "it''s": "it's",
}
MALFORMED = {
    "\\\\X\\41": "\\X\\41",
    "100\\% \\X2\\00E\\X0\\": "100\\% \\X2\\00E\\X0\\",
}


@pytest.mark.parametrize(("text", "decoded"), [*ESCAPED.items(), *MALFORMED.items()])
def test_step_strings_decode_as_iso_10303_21_says(text, decoded):
    assert decode_step_string(text) == decoded


def _encoded(text: str, astral_in_x2: bool) -> str:
    """``text`` as a STEP string's content, every character outside printable ASCII
    escaped."""
    out = []
    for char in text:
        code = ord(char)
        if char in "\\'":
            out.append(char * 2)
        elif 0x20 <= code < 0x7F:
            out.append(char)
        elif code < 0x100:
            out.append(f"\\X\\{code:02X}")
        elif code < 0x10000 or astral_in_x2:
            out.append("\\X2\\" + char.encode("utf-16-be").hex().upper() + "\\X0\\")
        else:
            out.append(f"\\X4\\{code:08X}\\X0\\")
    return "".join(out)


@given(st.text(), st.booleans())
def test_decoding_undoes_encoding(text, astral_in_x2):
    assert decode_step_string(_encoded(text, astral_in_x2)) == text


def test_declared_solid_names_are_decoded():
    text = "#7=MANIFOLD_SOLID_BREP('Pe\\X\\E7a \\X2\\00E9\\X0\\ it''s',#8);"
    assert declared_solids(text) == [("#7", "MANIFOLD_SOLID_BREP", "Peça é it's")]


@pytest.fixture(scope="module")
def escaped_step(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A file written by OCP whose product names were replaced, in its text, by the
    escaped strings of ``ESCAPED``."""
    pytest.importorskip("OCP")
    doc = _Document()
    rig = doc.assembly("rig")
    for i in range(len(ESCAPED)):
        doc.place(rig, doc.product(f"NAME{i}X", _box(1, 1, 1)), (2 * i, 0, 0))
    path = doc.write(tmp_path_factory.mktemp("escaped") / "raw.step")
    text = path.read_text()
    for i, escaped in enumerate(ESCAPED):
        text = text.replace(f"NAME{i}X", escaped)
    path.write_text(text)
    return path


@cad
def test_product_names_come_decoded(escaped_step):
    asm = load_assembly(escaped_step)
    # the two smileys are two products of one name
    expected = list(ESCAPED.values())
    expected[4] = "\U0001f600 (2)"
    assert asm.names == expected


def _barrel(major: float, tube: float, half_height: float) -> Any:
    """A barrel turned about the z axis from an arc of a spindle torus's tube (major
    radius ``major`` under its tube radius ``tube``: the circle of the tube across the
    axis, its part at ``|z| <= half_height``), closed by two discs."""
    from OCP.BRepBuilderAPI import (
        BRepBuilderAPI_MakeEdge,
        BRepBuilderAPI_MakeFace,
        BRepBuilderAPI_MakeWire,
    )
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeRevol
    from OCP.GC import GC_MakeArcOfCircle
    from OCP.gp import gp_Ax1, gp_Dir, gp_Pnt

    rim = math.sqrt(tube**2 - half_height**2) - major
    low, middle = gp_Pnt(rim, 0, -half_height), gp_Pnt(tube - major, 0, 0)
    high = gp_Pnt(rim, 0, half_height)
    wire = BRepBuilderAPI_MakeWire()
    for edge in (
        BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(low, middle, high).Value()).Edge(),
        BRepBuilderAPI_MakeEdge(high, gp_Pnt(0, 0, half_height)).Edge(),
        BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, half_height), gp_Pnt(0, 0, -half_height)).Edge(),
        BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, -half_height), low).Edge(),
    ):
        wire.Add(edge)
    profile = BRepBuilderAPI_MakeFace(wire.Wire()).Face()
    axis = gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1))
    return BRepPrimAPI_MakeRevol(profile, axis, 2 * math.pi).Shape()


@cad
def test_a_barrel_turned_from_a_spindle_torus_keeps_its_shape(tmp_path):
    # the tube (radius 14) crosses the axis (major radius 10): the barrel is 4 wide at
    # its middle, sqrt(14² - 5²) - 10 = 3.07 at its ends, and 10 tall; a mesh read from
    # the tube's centre at each vertex's own azimuth went out to 5.4 and 11.7 tall
    barrel = _barrel(10.0, 14.0, 5.0)
    path = tmp_path / "barrel.step"
    write_step(path, barrel)
    (part,) = load_assembly(path).parts.values()
    assert [s.kind for s in part.surfaces if s.kind == "torus"] == ["torus"]
    (torus,) = [s for s in part.surfaces if s.kind == "torus"]
    assert (torus.radius, torus.minor_radius) == pytest.approx((10.0, 14.0), abs=1e-6)
    np.testing.assert_allclose(part.mesh.bounds, [[-4, -4, -5], [4, 4, 5]], atol=0.02)
    # the chords of its convex faces lie inside it
    exact = exact_volume(barrel)
    assert exact * 0.99 < part.mesh.volume <= exact
    assert not load_assembly(path).warnings


@cad
def test_vertices_moved_out_of_the_solids_box_are_left_on_its_surface(tmp_path, monkeypatch):
    path = tmp_path / "plate.step"
    write_step(path, cut(_box(40, 40, 10, (-20, -20, 0)), _cylinder(5, 40, (0, 0, -10))))
    kept = load_assembly(path)["solid1"].mesh
    monkeypatch.setattr(step, "inside_vertices", lambda vertices, faces, surfaces: 3 * vertices)
    asm = load_assembly(path)
    assert asm["solid1"].mesh.bounds.tolist() == [[-20, -20, 0], [20, 20, 10]]
    assert asm["solid1"].mesh.volume == pytest.approx(40 * 40 * 10 - math.pi * 25 * 10, rel=2e-3)
    assert asm.warnings == (
        "solid1: its vertices are left on its surface: moved into its material, some left its box",
    )
    assert kept.volume < asm["solid1"].mesh.volume  # the hole's chords sag into it
