"""STEP round trip built with OCP: a plate with a through hole and a shaft in it, a ball
in a socket; exact radii and axes, and the curved contacts between them. Part names and
subassemblies from the product structure (the bundled gearbox, a file written by OCP's
XCAF writer)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from assemblykit.errors import GeometryError
from assemblykit.features.primitives import Ball, Hole, Shaft, Socket
from assemblykit.geometry.contacts import assembly_contacts, assembly_surfaces
from assemblykit.io.assembly import load_assembly
from assemblykit.io.step import LINEAR_DEFLECTION, declared_solids, numbered
from cli_runs import run
from step_files import write_step

pytest.importorskip("OCP")

pytestmark = pytest.mark.cad


@pytest.fixture(scope="module")
def step_file(tmp_path_factory):
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepPrimAPI import (
        BRepPrimAPI_MakeBox,
        BRepPrimAPI_MakeCylinder,
        BRepPrimAPI_MakeSphere,
    )
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt

    axis = gp_Ax2(gp_Pnt(0, 0, -10), gp_Dir(0, 0, 1))
    plate = BRepAlgoAPI_Cut(
        BRepPrimAPI_MakeBox(gp_Pnt(-20, -20, 0), 40, 40, 10).Shape(),
        BRepPrimAPI_MakeCylinder(axis, 5.0, 40.0).Shape(),
    ).Shape()
    shaft = BRepPrimAPI_MakeCylinder(axis, 5.0, 30.0).Shape()
    centre = gp_Pnt(60, 0, 0)
    socket = BRepAlgoAPI_Cut(
        BRepPrimAPI_MakeBox(gp_Pnt(50, -10, -10), 20, 20, 10).Shape(),
        BRepPrimAPI_MakeSphere(centre, 4.0).Shape(),
    ).Shape()
    ball = BRepPrimAPI_MakeSphere(centre, 4.0).Shape()
    path = tmp_path_factory.mktemp("step") / "parts.step"
    write_step(path, plate, shaft, socket, ball)
    return path


def test_solids_become_parts_with_exact_surfaces(step_file):
    asm = load_assembly(step_file)
    assert asm.names == ["solid1", "solid2", "solid3", "solid4"]
    assert (asm.units, asm.units_source, asm.exact) == ("mm", "file", True)
    assert asm["solid1"].volume == pytest.approx(40 * 40 * 10 - np.pi * 25 * 10, rel=1e-2)


def test_recognised_features_have_exact_radii_and_axes(step_file):
    asm = load_assembly(step_file)
    (hole,) = [f for s in assembly_surfaces(asm, "solid1") if isinstance(f := s.feature(), Hole)]
    (shaft,) = [f for s in assembly_surfaces(asm, "solid2") if isinstance(f := s.feature(), Shaft)]
    for feature in (hole, shaft):
        assert feature.radius == 5.0
        assert abs(feature.axis @ [0, 0, 1]) == 1.0
        np.testing.assert_allclose(feature.point[:2], [0, 0], atol=1e-12)
    (socket,) = [
        f for s in assembly_surfaces(asm, "solid3") if isinstance(f := s.feature(), Socket)
    ]
    (ball,) = [f for s in assembly_surfaces(asm, "solid4") if isinstance(f := s.feature(), Ball)]
    assert socket.radius == 4.0 and ball.radius == 4.0
    np.testing.assert_allclose(ball.point, [60, 0, 0], atol=1e-12)


def test_shaft_in_hole_and_ball_in_socket_are_curved_contacts(step_file):
    contacts = {c.pair: c for c in assembly_contacts(load_assembly(step_file))}
    assert set(contacts) == {("solid1", "solid2"), ("solid3", "solid4")}
    (cylinder,) = contacts["solid1", "solid2"].curved
    assert (cylinder.kind, cylinder.inner, cylinder.radius) == ("cylindrical", "solid2", 5.0)
    assert cylinder.extent == pytest.approx((0.0, 10.0), abs=1e-9)
    assert contacts["solid1", "solid2"].planar == ()
    (sphere,) = contacts["solid3", "solid4"].curved
    assert (sphere.kind, sphere.inner, sphere.radius) == ("spherical", "solid4", 4.0)


def test_unreadable_step_names_the_file(tmp_path):
    path = tmp_path / "junk.step"
    path.write_text("this is not ISO-10303-21\n")
    with pytest.raises(GeometryError, match=r"junk\.step"):
        load_assembly(path)


@pytest.fixture(scope="module")
def damaged_step(tmp_path_factory):
    """Two stacked boxes written by OCP, the second one's shell cut short (its closing
    bracket lost): OCP reads the first and drops the second, printing parse errors."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.gp import gp_Pnt

    folder = tmp_path_factory.mktemp("damaged")
    good = folder / "two.step"
    write_step(
        good,
        BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), 10, 10, 10).Shape(),
        BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 10), 10, 10, 5).Shape(),
    )
    lines = good.read_text().splitlines()
    solids = [i for i, line in enumerate(lines) if "MANIFOLD_SOLID_BREP" in line]
    assert len(solids) == 2
    label = lines[solids[1]].split("=")[0].strip()
    shell = solids[1] + 1
    assert "CLOSED_SHELL" in lines[shell]
    lines[shell] = lines[shell].replace("));", ");")
    damaged = folder / "damaged.step"
    damaged.write_text("\n".join(lines) + "\n")
    return damaged, label


def test_a_damaged_solid_is_listed_as_skipped(damaged_step):
    path, label = damaged_step
    asm = load_assembly(path)
    assert list(asm.parts) == ["solid1"]
    assert [s.item for s in asm.skipped] == [f"{label} MANIFOLD_SOLID_BREP"]
    assert any("Incorrect Syntax" in w for w in asm.warnings)
    assert all("\x1b" not in w for w in asm.warnings)


def test_a_damaged_step_is_refused_and_with_partial_gives_what_was_read(damaged_step, capfd):
    # captured at the descriptors: OCP writes on descriptor 1, which must not reach the
    # JSON on standard output
    path, label = damaged_step
    code, out, err = run(capfd, "contacts", str(path), "--json")
    assert code == 2 and out == ""
    (line,) = err.strip().splitlines()
    assert str(path) in line and f"{label} MANIFOLD_SOLID_BREP" in line and "--partial" in line
    code, out, err = run(capfd, "contacts", str(path), "--json", "--partial")
    assert code == 0
    data = json.loads(out)
    assert list(data["parts"]) == ["solid1"]
    assert data["skipped"] == [
        {
            "item": f"{label} MANIFOLD_SOLID_BREP",
            "reason": "its shell could not be read; the solid is left out",
        }
    ]
    assert f"skipped {label} MANIFOLD_SOLID_BREP" in err


def test_an_intact_step_skips_nothing(step_file):
    asm = load_assembly(step_file)
    assert asm.skipped == () and asm.warnings == ()


GEARBOX = (
    Path(__file__).resolve().parents[2] / "src" / "assemblykit" / "examples" / "motion" / "gearbox"
)


def test_the_gearbox_parts_are_named_after_its_products():
    asm = load_assembly(GEARBOX / "gearbox.step")
    assert asm.names == ["housing", "cover", "gear_1", "gear_2", "gear_3", "gear_4"]
    assert asm.groups == {} and asm.skipped == ()
    # each name is on the right solid: the same part as the mesh of that name (up to
    # the deflection of the tessellation of the curved faces)
    meshes = load_assembly(GEARBOX / "gearbox.yaml")
    for name in asm.names:
        bounds = meshes[name].mesh.bounds
        deflection = LINEAR_DEFLECTION * np.linalg.norm(bounds[1] - bounds[0])
        np.testing.assert_allclose(asm[name].mesh.bounds, bounds, atol=deflection)
        assert asm[name].volume == pytest.approx(meshes[name].volume, rel=1e-2)


def _box(x: float, y: float, z: float):
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.gp import gp_Pnt

    return BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), x, y, z).Shape()


def _at(x: float, y: float, z: float):
    from OCP.gp import gp_Trsf, gp_Vec
    from OCP.TopLoc import TopLoc_Location

    move = gp_Trsf()
    move.SetTranslation(gp_Vec(x, y, z))
    return TopLoc_Location(move)


@pytest.fixture(scope="module")
def structured_step(tmp_path_factory):
    """A product structure written by OCP's XCAF writer: the product ``bench`` uses a
    ``housing`` plate (40 x 20 x 5), a ``pin`` (2 x 2 x 3) twice, and the subassembly
    ``gear_train`` placed on the plate, which uses a ``gear`` (8 x 8 x 4) twice, the two
    side by side and touching."""
    from OCP.STEPCAFControl import STEPCAFControl_Writer
    from OCP.STEPControl import STEPControl_AsIs
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    document = TDocStd_Document(TCollection_ExtendedString("MDTV-XCAF"))
    tool = XCAFDoc_DocumentTool.ShapeTool_s(document.Main())

    def product(name, label):
        TDataStd_Name.Set_s(label, TCollection_ExtendedString(name))
        return label

    bench = product("bench", tool.NewShape())
    housing = product("housing", tool.AddShape(_box(40, 20, 5), False))
    pin = product("pin", tool.AddShape(_box(2, 2, 3), False))
    train = product("gear_train", tool.NewShape())
    gear = product("gear", tool.AddShape(_box(8, 8, 4), False))
    tool.AddComponent(train, gear, _at(2, 2, 0))
    tool.AddComponent(train, gear, _at(10, 2, 0))
    tool.AddComponent(bench, housing, _at(0, 0, 0))
    tool.AddComponent(bench, pin, _at(30, 5, 5))
    tool.AddComponent(bench, pin, _at(30, 12, 5))
    tool.AddComponent(bench, train, _at(0, 0, 5))
    tool.UpdateAssemblies()
    writer = STEPCAFControl_Writer()
    writer.SetNameMode(True)
    writer.Transfer(document, STEPControl_AsIs)
    path = tmp_path_factory.mktemp("structure") / "bench.step"
    writer.Write(str(path))
    return path


def test_instances_of_one_product_are_numbered_and_placed(structured_step):
    text = structured_step.read_text()
    assert text.count("NEXT_ASSEMBLY_USAGE_OCCURRENCE") == 6
    asm = load_assembly(structured_step)
    assert asm.names == ["housing", "pin_1", "pin_2", "gear_1", "gear_2"]
    expected = {
        "housing": [[0, 0, 0], [40, 20, 5]],
        "pin_1": [[30, 5, 5], [32, 7, 8]],
        "pin_2": [[30, 12, 5], [32, 14, 8]],
        "gear_1": [[2, 2, 5], [10, 10, 9]],  # the train's place plus the gear's
        "gear_2": [[10, 2, 5], [18, 10, 9]],
    }
    for name, bounds in expected.items():
        np.testing.assert_allclose(asm[name].mesh.bounds, bounds, atol=1e-9)
    # three solids are declared (one per product); none is reported missing
    assert len(declared_solids(text)) == 3 and asm.skipped == ()


def test_a_subassembly_is_a_group_that_motion_takes(structured_step, capsys):
    from assemblykit.cli import main
    from assemblykit.motion.freedom import motion

    asm = load_assembly(structured_step)
    assert asm.groups == {"gear_train": ("gear_1", "gear_2")}
    assert asm.subset(["housing", "gear_2"]).groups == {"gear_train": ("gear_2",)}
    # each gear rests on the plate and against the other gear: it can only slide along
    # y; together they only rest on the plate: they slide in its plane and turn about z
    report = motion(asm, asm.groups.values())
    assert (report["gear_1"].kind, report["gear_1"].dof) == ("prismatic", 1)
    assert (report["gear_1+gear_2"].kind, report["gear_1+gear_2"].dof) == ("planar", 3)
    main(["motion", str(structured_step), "--subassembly", "gear_train", "--json"])
    parts = json.loads(capsys.readouterr().out)["parts"]
    assert (parts["gear_1+gear_2"]["motion"], parts["gear_1+gear_2"]["dof"]) == ("planar", 3)
    assert parts["gear_1"]["direction"] == pytest.approx([0.0, 1.0, 0.0], abs=1e-9)


@pytest.mark.parametrize(
    ("bases", "names"),
    [
        (["housing", "gear", "gear"], ["housing", "gear_1", "gear_2"]),
        (["pin", "pin_1", "pin"], ["pin_2", "pin_1", "pin_3"]),
        (["a", "b"], ["a", "b"]),
    ],
)
def test_numbered_names_are_unique(bases, names):
    assert numbered(bases) == names
