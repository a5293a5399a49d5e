"""Generate the bundled motion examples (Liu 1997): meshes, YAML manifests and STEP files.

Run ``python examples/make_motion_examples.py`` from the repository root. For every
example it writes, under ``src/assemblykit/examples/motion/<name>/``, one OBJ mesh per
part in world coordinates, the manifest ``<name>.yaml`` (docs/geometry.md,
"Loaders and their conventions") and, when OCP is installed (extra ``cad``), ``<name>.step``
with one named solid per part; then the picture of the gearbox's motions for the user guide,
``docs/images/motion.png``.

Each part is a small constructive solid (boxes, vertical cylinders, spheres, unions and
differences) rendered twice: faceted by manifold3d for the meshes and exactly by
OpenCascade for STEP, so both inputs describe the same model. A hole is the difference
with the very cylinder (or sphere) that fills it, so the facets of a pin and of its bore
coincide and no two parts overlap. Units are millimetres, z points up.

* ``gearbox`` (Liu 1997, Figs. 7-9): four gear discs on pins of a housing, a cover on
  the housing walls pinned by the four pins. Neighbouring gears have tangent pitch
  circles (radii 10, 20, 5, 25); gears sit on the floor and clear the cover.
* ``drawer``: a tray resting on two runners of a cabinet, guided by the side walls.
* ``hinge``: a door whose knuckle turns on a frame's pin and rests on the frame.
* ``ball_joint``: a ball with a stem resting in a spherical cup (less than a hemisphere).
* ``interlock`` (Liu 1997, Fig. 10): two hooked bars filling a channel closed by a keyed
  lid; every part alone is held, the two bars together slide out along x.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import manifold3d
import numpy as np
import trimesh
import yaml

OUT = Path(__file__).resolve().parents[1] / "src" / "assemblykit" / "examples" / "motion"
PICTURE = Path(__file__).resolve().parents[1] / "docs" / "images" / "motion.png"

ROUND_SEGMENTS = 32
# cutters overshoot the faces they pierce so that no boolean works on coplanar faces
OVERSHOOT = 1.0

Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class Box:
    """The axis-aligned box with corners ``lo`` and ``hi``."""

    lo: Vec3
    hi: Vec3


@dataclass(frozen=True)
class Rod:
    """The vertical cylinder of ``radius`` on the line through ``(x, y)`` from ``z0`` to ``z1``."""

    x: float
    y: float
    z0: float
    z1: float
    radius: float


@dataclass(frozen=True)
class Sphere:
    """The ball of ``radius`` about ``center``; ``rings`` are heights above the centre
    where the faceted sphere must have a ring of vertices (so that a plane or a rod of
    the same segments meets it along facet edges and never cuts a facet)."""

    center: Vec3
    radius: float
    rings: tuple[float, ...] = ()


@dataclass(frozen=True)
class Union:
    """The union of solids."""

    items: tuple[Solid, ...]


@dataclass(frozen=True)
class Cut:
    """``base`` minus every cutter."""

    base: Solid
    cutters: tuple[Solid, ...]


Solid = Box | Rod | Sphere | Union | Cut


def to_manifold(solid: Solid) -> manifold3d.Manifold:
    """The faceted solid (manifold3d)."""
    if isinstance(solid, Box):
        size = tuple(h - lo for lo, h in zip(solid.lo, solid.hi, strict=True))
        return manifold3d.Manifold.cube(size).translate(solid.lo)
    if isinstance(solid, Rod):
        rod = manifold3d.Manifold.cylinder(
            solid.z1 - solid.z0, solid.radius, solid.radius, ROUND_SEGMENTS
        )
        return rod.translate((solid.x, solid.y, solid.z0))
    if isinstance(solid, Sphere):
        return _faceted_sphere(solid)
    if isinstance(solid, Union):
        return manifold3d.Manifold.batch_boolean(
            [to_manifold(s) for s in solid.items], manifold3d.OpType.Add
        )
    cutters = manifold3d.Manifold.batch_boolean(
        [to_manifold(s) for s in solid.cutters], manifold3d.OpType.Add
    )
    return to_manifold(solid.base) - cutters


def _faceted_sphere(sphere: Sphere) -> manifold3d.Manifold:
    """The sphere revolved from a meridian with uniform latitudes plus ``rings``: every
    vertex lies exactly on the sphere."""
    heights = np.cos(np.linspace(np.pi, 0.0, ROUND_SEGMENTS // 2 + 1)) * sphere.radius
    heights = np.unique(np.concatenate([heights, sphere.rings]))
    radii = np.sqrt(np.clip(sphere.radius**2 - heights**2, 0.0, None))
    meridian = np.column_stack([radii, heights])
    solid = manifold3d.Manifold.revolve(manifold3d.CrossSection([meridian]), ROUND_SEGMENTS)
    return solid.translate(sphere.center)


def to_occ(solid: Solid) -> Any:
    """The exact solid (an OpenCascade ``TopoDS_Shape``; OCP is optional)."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse
    from OCP.BRepPrimAPI import (
        BRepPrimAPI_MakeBox,
        BRepPrimAPI_MakeCylinder,
        BRepPrimAPI_MakeSphere,
    )
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt

    if isinstance(solid, Box):
        return BRepPrimAPI_MakeBox(gp_Pnt(*solid.lo), gp_Pnt(*solid.hi)).Shape()
    if isinstance(solid, Rod):
        frame = gp_Ax2(gp_Pnt(solid.x, solid.y, solid.z0), gp_Dir(0.0, 0.0, 1.0))
        return BRepPrimAPI_MakeCylinder(frame, solid.radius, solid.z1 - solid.z0).Shape()
    if isinstance(solid, Sphere):
        return BRepPrimAPI_MakeSphere(gp_Pnt(*solid.center), solid.radius).Shape()
    if isinstance(solid, Union):
        shape = to_occ(solid.items[0])
        for item in solid.items[1:]:
            shape = BRepAlgoAPI_Fuse(shape, to_occ(item)).Shape()
        return shape
    shape = to_occ(solid.base)
    for cutter in solid.cutters:
        shape = BRepAlgoAPI_Cut(shape, to_occ(cutter)).Shape()
    return shape


def gearbox() -> dict[str, Solid]:
    """Housing with four pins, a pinned cover, four gears in a tangent train (Liu 1997, Fig. 7)."""
    gears = [(0.0, 10.0), (30.0, 20.0), (55.0, 5.0), (85.0, 25.0)]  # (x, radius)
    pin_radius = 3.0
    pins = [Rod(x, 0.0, 0.0, 20.0, pin_radius) for x, _ in gears]
    housing = Union(
        (
            Cut(
                Box((-30.0, -35.0, -10.0), (125.0, 35.0, 15.0)),
                (Box((-25.0, -30.0, 0.0), (120.0, 30.0, 15.0 + OVERSHOOT)),),
            ),
            *pins,
        )
    )
    cover = Cut(
        Box((-30.0, -35.0, 15.0), (125.0, 35.0, 20.0)),
        tuple(Rod(x, 0.0, 15.0 - OVERSHOOT, 20.0 + OVERSHOOT, pin_radius) for x, _ in gears),
    )
    parts: dict[str, Solid] = {"housing": housing, "cover": cover}
    for i, (x, radius) in enumerate(gears, start=1):
        parts[f"gear_{i}"] = Cut(
            Rod(x, 0.0, 0.0, 10.0, radius),
            (Rod(x, 0.0, -OVERSHOOT, 10.0 + OVERSHOOT, pin_radius),),
        )
    return parts


def drawer() -> dict[str, Solid]:
    """A cabinet open at +x with two runners, and a tray on the runners between the walls."""
    cabinet = Union(
        (
            Cut(
                Box((0.0, -25.0, 0.0), (60.0, 25.0, 40.0)),
                (Box((5.0, -20.0, 5.0), (60.0 + OVERSHOOT, 20.0, 35.0)),),
            ),
            Box((5.0, -20.0, 5.0), (60.0, -15.0, 7.0)),
            Box((5.0, 15.0, 5.0), (60.0, 20.0, 7.0)),
        )
    )
    tray = Cut(
        Box((10.0, -20.0, 7.0), (65.0, 20.0, 30.0)),
        (Box((12.0, -18.0, 9.0), (63.0, 18.0, 30.0 + OVERSHOOT)),),
    )
    return {"cabinet": cabinet, "tray": tray}


def hinge() -> dict[str, Solid]:
    """A frame with a vertical pin; a door's knuckle turns on the pin and rests on the frame."""
    pin = Rod(0.0, 0.0, -OVERSHOOT, 20.0, 3.0)
    frame = Union((Box((-20.0, -10.0, -10.0), (20.0, 10.0, 0.0)), pin))
    door = Union(
        (
            Cut(Rod(0.0, 0.0, 0.0, 20.0, 6.0), (Rod(0.0, 0.0, -OVERSHOOT, 21.0, 3.0),)),
            Box((5.0, -1.0, 2.0), (40.0, 1.0, 18.0)),
        )
    )
    return {"frame": frame, "door": door}


def ball_joint() -> dict[str, Solid]:
    """A ball (radius 10, centre at the origin) with a stem of radius 3 starting on the
    ball, in a cup cut to z = -2 (less than a hemisphere)."""
    stem_foot = float(np.sqrt(10.0**2 - 3.0**2))
    ball = Sphere((0.0, 0.0, 0.0), 10.0, rings=(-2.0, stem_foot))
    socket = Cut(Box((-15.0, -15.0, -15.0), (15.0, 15.0, -2.0)), (ball,))
    stem = Rod(0.0, 0.0, stem_foot, 30.0, 3.0)
    return {"socket": socket, "ball": Union((ball, stem))}


def interlock() -> dict[str, Solid]:
    """Liu 1997, Fig. 10: bars A, B hooked into each other fill a 3 x 3 channel (x-z
    section) of the base C, closed by the lid D whose keys sit in notches of C's walls."""
    width = 4.0
    bar_a = Union(
        (Box((0.0, 0.0, 0.0), (2.0, width, 1.0)), Box((1.0, 0.0, 1.0), (2.0, width, 2.0)))
    )
    bar_b = Union(
        (
            Box((0.0, 0.0, 1.0), (1.0, width, 3.0)),
            Box((1.0, 0.0, 2.0), (3.0, width, 3.0)),
            Box((2.0, 0.0, 0.0), (3.0, width, 2.0)),
        )
    )
    notches = (
        Box((1.0, -1.0, 2.5), (2.0, -0.5, 3.0 + OVERSHOOT)),
        Box((1.0, width + 0.5, 2.5), (2.0, width + 1.0, 3.0 + OVERSHOOT)),
    )
    base = Cut(
        Box((0.0, -1.0, -1.0), (3.0, width + 1.0, 3.0)),
        (Box((0.0 - OVERSHOOT, 0.0, 0.0), (3.0 + OVERSHOOT, width, 3.0 + OVERSHOOT)), *notches),
    )
    lid = Union(
        (
            Box((0.0, -1.0, 3.0), (3.0, width + 1.0, 4.0)),
            Box((1.0, -1.0, 2.5), (2.0, -0.5, 3.0)),
            Box((1.0, width + 0.5, 2.5), (2.0, width + 1.0, 3.0)),
        )
    )
    return {"bar_a": bar_a, "bar_b": bar_b, "base": base, "lid": lid}


EXAMPLES = {
    "gearbox": gearbox,
    "drawer": drawer,
    "hinge": hinge,
    "ball_joint": ball_joint,
    "interlock": interlock,
}


def write_meshes(name: str, parts: dict[str, Solid], folder: Path) -> None:
    """One OBJ per part (world coordinates) and the manifest ``<name>.yaml``."""
    entries = []
    for part, solid in parts.items():
        mesh = to_manifold(solid).to_mesh64()
        tri = trimesh.Trimesh(
            np.asarray(mesh.vert_properties[:, :3], dtype=np.float64),
            np.asarray(mesh.tri_verts, dtype=np.int64),
            process=True,
        )
        (folder / f"{part}.obj").write_text(trimesh.exchange.obj.export_obj(tri, digits=12))
        entries.append(
            {
                "name": part,
                "mesh": f"{part}.obj",
                "pose": {"translation": [0.0, 0.0, 0.0], "rotation_xyz_deg": [0.0, 0.0, 0.0]},
            }
        )
    header = f"# Generated by examples/make_motion_examples.py: the {name} motion example.\n"
    body = yaml.safe_dump({"units": "mm", "parts": entries}, sort_keys=False)
    (folder / f"{name}.yaml").write_text(header + body)


def write_step(parts: dict[str, Solid], path: Path) -> None:
    """A STEP file with one solid per part, each named after its part (XCAF labels)."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.ShapeUpgrade import ShapeUpgrade_UnifySameDomain
    from OCP.STEPCAFControl import STEPCAFControl_Writer
    from OCP.STEPControl import STEPControl_AsIs
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    document = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    shapes = XCAFDoc_DocumentTool.ShapeTool_s(document.Main())
    for part, solid in parts.items():
        # merge the faces a union splits, so every surface is one exact face
        unify = ShapeUpgrade_UnifySameDomain(to_occ(solid), True, True, True)
        unify.Build()
        label = shapes.AddShape(unify.Shape(), False)
        TDataStd_Name.Set_s(label, TCollection_ExtendedString(part))
    writer = STEPCAFControl_Writer()
    writer.SetNameMode(True)
    writer.Transfer(document, STEPControl_AsIs)
    if writer.Write(str(path)) != IFSelect_RetDone:
        raise RuntimeError(f"cannot write {path}")


def main() -> None:
    """Write every example."""
    try:
        import OCP  # noqa: F401
    except ImportError:
        has_ocp = False
    else:
        has_ocp = True
    for name, build in EXAMPLES.items():
        folder = OUT / name
        folder.mkdir(parents=True, exist_ok=True)
        parts = build()
        write_meshes(name, parts, folder)
        if has_ocp:
            write_step(parts, folder / f"{name}.step")
        print(f"{name}: {len(parts)} parts -> {folder}")
    write_picture(PICTURE)
    print(f"gearbox motions -> {PICTURE}")


def write_picture(path: Path) -> None:
    """The gearbox with the motion axes of its parts (``docs/motion.md``)."""
    import assemblykit
    from assemblykit.viz.motion_view import write_motion_png

    gearbox = assemblykit.load_assembly(OUT / "gearbox" / "gearbox.yaml")
    path.parent.mkdir(parents=True, exist_ok=True)
    write_motion_png(gearbox, assemblykit.motion(gearbox), path)


if __name__ == "__main__":
    main()
