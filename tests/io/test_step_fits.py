"""Fits at nominal size read from STEP (docs/geometry.md, "STEP tessellation"): a pin in
a hole of its own diameter, and bolts through a plate, with nuts. The exact solids share
no volume (OCCT's boolean common, an independent check), and their meshes, tessellated
inside the solids, share none either: no interference, cylindrical contacts, and plans
whose every step an independent sweep confirms. Read with the kernel's own
tessellation (every vertex on its surface) the same files overlap, and the planner
finds nothing to take apart: these tests fail without the rule. A catalogue of
concave faces checks the rule on every kind of surface read from STEP."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import manifold3d
import numpy as np
import pytest

from assemblykit.algebra import Kind, se3
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.geometry.interference import interferences, overlap_volume, solid
from assemblykit.geometry.tessellation import sags_out
from assemblykit.io import step as step_module
from assemblykit.io.assembly import load_assembly
from assemblykit.io.step import LINEAR_DEFLECTION
from assemblykit.planning.planner import plan
from step_files import box, common_volume, cut, cylinder, fuse, hexagon, write_step

pytest.importorskip("OCP")

pytestmark = pytest.mark.cad

# shared volume (mm^3) still counted as none: float rounding of touching meshes
NOISE = 1e-9
Z = np.array([0.0, 0.0, 1.0])


def kernel_tessellation(path):
    """The assembly read with the kernel's tessellation as it is (vertices on the exact
    surfaces, chords of holes in the void)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(step_module, "inside_vertices", lambda vertices, faces, surfaces: vertices)
        return load_assembly(path)


def swept_overlap(mesh, direction, length: float, obstacle) -> float:
    """The volume the closed mesh ``obstacle`` shares with all that ``mesh`` passes
    through when translated by ``length`` along unit ``direction``: the solid where it
    starts and the prisms swept by its triangles that face the move (a point passed
    through lies on the segment from the last point where the start solid is left, on
    such a triangle); prisms whose boxes do not overlap the obstacle's are left out."""
    vertices, faces = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    step = length * np.asarray(direction, dtype=float)
    corners = vertices[faces]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    facing = corners[normals @ direction > 1e-9 * np.linalg.norm(normals, axis=1)]
    prisms = np.concatenate([facing, facing + step], axis=1)
    low, high = obstacle.bounds
    meets = np.all((prisms.min(axis=1) < high) & (prisms.max(axis=1) > low), axis=1)
    pieces = [solid(mesh)]
    pieces += [manifold3d.Manifold.hull_points(p) for p in prisms[meets]]
    sweep = manifold3d.Manifold.batch_boolean(pieces, manifold3d.OpType.Add)
    return float((sweep ^ solid(obstacle)).volume())


def sweep_overlaps(asm, steps, reverse: bool = False) -> list[float]:
    """Per step of a plan, the largest volume the moving parts, swept along its direction
    (or the opposite one) well past the assembly, share with a part still in place (the
    parts of ``rest``)."""
    length = 2.0 * float(np.linalg.norm(np.ptp(asm.bounds, axis=0)))
    return [
        max(
            swept_overlap(
                asm.parts[name].mesh,
                -move.direction if reverse else move.direction,
                length,
                asm.parts[other].mesh,
            )
            for name in move.parts
            for other in move.rest
        )
        for move in steps
    ]


@dataclass(frozen=True)
class Read:
    """Solids written to a STEP file and the file read back: with the rule
    (``assembly``) and with the kernel's tessellation as it is (``kernel``)."""

    shapes: tuple[Any, ...]
    assembly: Any
    kernel: Any


def read(path, *shapes) -> Read:
    write_step(path, *shapes)
    return Read(shapes, load_assembly(path), kernel_tessellation(path))


PLATE, PIN = "solid1", "solid2"


@pytest.fixture(scope="module")
def pin_in_hole(tmp_path_factory) -> Read:
    """A 40 x 40 x 10 plate with a through hole of radius 5 and a pin of radius exactly 5
    through it, its seam turned by 3 degrees (as two parts from two sources would be)."""
    plate = cut(box((-20, -20, 0), (40, 40, 10)), cylinder((0, 0, -10), 5.0, 40.0))
    pin = cylinder((0, 0, -10), 5.0, 30.0, turn=3.0)
    return read(tmp_path_factory.mktemp("fits") / "pin.step", plate, pin)


def test_a_pin_in_a_hole_of_its_diameter_touches_it_and_shares_no_volume(pin_in_hole):
    (plate, pin), asm, kernel = pin_in_hole.shapes, pin_in_hole.assembly, pin_in_hole.kernel
    assert common_volume(plate, pin) <= NOISE
    # the kernel's tessellation: the plate's chords cut into the pin (0.49 mm^3)
    assert overlap_volume(kernel[PLATE].mesh, kernel[PIN].mesh) > 0.1
    assert [pair[:2] for pair in interferences(kernel)] == [(PLATE, PIN)]
    assert overlap_volume(asm[PLATE].mesh, asm[PIN].mesh) <= NOISE
    assert interferences(asm) == []
    (contact,) = assembly_contacts(asm)
    (fit,) = contact.curved
    assert (contact.pair, fit.kind, fit.inner, fit.radius) == (
        (PLATE, PIN),
        "cylindrical",
        PIN,
        5.0,
    )
    # the hole's vertices moved off the circle by less than the linear deflection
    moved = np.linalg.norm(asm[PLATE].mesh.vertices - kernel[PLATE].mesh.vertices, axis=1)
    diagonal = float(np.linalg.norm(np.ptp(asm[PLATE].mesh.bounds, axis=0)))
    assert 0 < moved.max() <= LINEAR_DEFLECTION * diagonal
    np.testing.assert_array_equal(asm[PIN].mesh.vertices, kernel[PIN].mesh.vertices)
    np.testing.assert_array_equal(asm[PLATE].mesh.faces, kernel[PLATE].mesh.faces)


def test_the_pin_leaves_along_its_axis_through_a_free_sweep(pin_in_hole):
    asm, kernel = pin_in_hole.assembly, pin_in_hole.kernel
    found = plan(asm)
    assert found.feasible
    assert [abs(float(s.direction @ Z)) for s in found.steps] == pytest.approx([1.0])
    # pulled out of its hole: a pin (no thread modelled, no interference)
    (step,) = found.steps
    fastener = step.fastener
    assert fastener is not None and (fastener.part, fastener.kind) == (PIN, "pin")
    assert fastener.holes == (PLATE,) and abs(float(fastener.axis @ Z)) == pytest.approx(1.0)
    assert max(sweep_overlaps(asm, found.steps)) <= NOISE
    # the same sweep through the kernel's tessellation cuts into the plate, where the
    # planner finds no way out at all
    assert min(sweep_overlaps(kernel, found.steps)) > 0.1
    assert not plan(kernel).feasible


BOLTS, NUTS = ("solid2", "solid3"), ("solid4", "solid5")


@pytest.fixture(scope="module")
def bolted(tmp_path_factory) -> Read:
    """A 60 x 30 x 8 plate with two holes of radius 4; in each a bolt of radius 4 (a head
    of radius 7 on the plate) and a hexagon nut (13 across flats, hole of radius 4) under
    the plate, each cylinder's seam turned differently."""
    plate = box((-30, -15, 0), (60, 30, 8))
    bolts, nuts = [], []
    for k, x in enumerate((-15.0, 15.0)):
        plate = cut(plate, cylinder((x, 0, -1), 4.0, 10.0))
        shank = cylinder((x, 0, -5), 4.0, 13.0, turn=5 + 7 * k)
        bolts.append(fuse(shank, cylinder((x, 0, 8), 7.0, 4.0, turn=11)))
        nut = hexagon((x, 0, -5), 13.0, 5.0, turn=2)
        nuts.append(cut(nut, cylinder((x, 0, -6), 4.0, 7.0, turn=17 + 3 * k)))
    return read(tmp_path_factory.mktemp("fits") / "bolted.step", plate, *bolts, *nuts)


def test_bolts_and_nuts_at_nominal_size_fit_without_interference(bolted):
    shapes, asm, kernel = bolted.shapes, bolted.assembly, bolted.kernel
    assert max(common_volume(a, b) for i, a in enumerate(shapes) for b in shapes[i + 1 :]) <= NOISE
    # the kernel's tessellation: each hole's chords cut into its bolt
    assert {pair[:2] for pair in interferences(kernel)} == {
        (PLATE, BOLTS[0]),
        (PLATE, BOLTS[1]),
        (BOLTS[0], NUTS[0]),
        (BOLTS[1], NUTS[1]),
    }
    assert interferences(asm) == []
    fits = {c.pair: c.curved for c in assembly_contacts(asm) if c.curved}
    assert set(fits) == {(PLATE, b) for b in BOLTS} | set(zip(BOLTS, NUTS, strict=True))
    assert all(f.kind == "cylindrical" and f.radius == 4.0 for (f,) in fits.values())


def test_the_bolts_leave_along_their_axes_through_free_sweeps(bolted):
    asm = bolted.assembly
    found = plan(asm)
    assert found.feasible
    bolts_out = [move for move in found.steps if set(move.parts) & set(BOLTS)]
    assert bolts_out
    assert all(abs(float(move.direction @ Z)) == pytest.approx(1.0) for move in bolts_out)
    assert max(sweep_overlaps(asm, found.steps)) <= NOISE
    # the check is not blind: the bolts cannot go the other way
    assert min(sweep_overlaps(asm, bolts_out, reverse=True)) > 1.0


def test_bolts_turned_out_of_their_nuts_are_screws_of_an_implied_thread(bolted):
    # each bolt (radius 4: an M8) leaves upwards, out of the plate and of its nut, which
    # stays: it is turned out of the nut, its tip travelling from z = -5 to the nut's
    # top at z = 0, 5 / 1.25 = 4 turns; the nuts then leave with no bolt to unscrew from
    found = plan(bolted.assembly)
    screws = [f for move in found.steps for f in move.fasteners]
    assert sorted(f.part for f in screws) == sorted(BOLTS)
    for fastener, nut in zip(sorted(screws, key=lambda f: f.part), NUTS, strict=True):
        assert fastener.kind == "screw" and nut in fastener.holes and PLATE in fastener.holes
        assert fastener.thread is not None
        assert (fastener.thread.size, fastener.thread.pitch) == ("M8", 1.25)
        assert fastener.thread.turns == pytest.approx(4.0)
        assert fastener.summary() == "unscrew M8 (pitch 1.25, 4 turns)"
    assert max(sweep_overlaps(bolted.assembly, found.steps)) <= NOISE


@pytest.fixture(scope="module")
def trapped_head(tmp_path_factory) -> Read:
    """A 40 x 40 x 20 base with a counterbore of radius 7 and depth 5 in its top; in it
    the head (radius 7, 4 high, z in [15, 19]) of a bolt of radius 4 up to z = 36,
    through a plate 8 thick on the base (hole of radius 4) and a nut (radius 7, 5 high,
    hole of radius 4, 13 across flats: an M8's) on the plate: the bolt cannot leave
    before the nut."""
    base = cut(box((-20, -20, 0), (40, 40, 20)), cylinder((0, 0, 15), 7.0, 10.0))
    bolt = fuse(cylinder((0, 0, 15), 7.0, 4.0, turn=4), cylinder((0, 0, 18), 4.0, 18.0, turn=9))
    plate = cut(box((-20, -20, 20), (40, 40, 8)), cylinder((0, 0, 19), 4.0, 10.0, turn=13))
    nut = cut(hexagon((0, 0, 28), 13.0, 5.0, turn=10), cylinder((0, 0, 27), 4.0, 7.0, turn=21))
    return read(tmp_path_factory.mktemp("fits") / "trapped.step", base, bolt, plate, nut)


def test_a_nut_is_unscrewed_off_its_bolt_before_the_bolt_is_pulled(trapped_head):
    # the nut leaves upwards off the bolt's tip: from its back face at z = 28 to the tip
    # at z = 36, 8 / 1.25 = 6.4 turns of an M8; the plate is lifted off; the bolt is
    # then pulled out of its counterbore, a bolt whose nut is off (no turns left)
    asm = trapped_head.assembly
    found = plan(asm)
    assert found.feasible
    order = [move.parts for move in found.steps]
    assert order == [("solid4",), ("solid3",), ("solid2",)]
    nut, plate, bolt = (move.fastener for move in found.steps)
    assert nut is not None and plate is None and bolt is not None
    assert (nut.kind, nut.holes, nut.diameter) == ("nut", ("solid2",), 8.0)
    assert nut.summary() == "unscrew nut M8 (pitch 1.25, 6.4 turns)"
    assert nut.to_dict()["thread"] == {"size": "M8", "pitch": 1.25, "turns": 6.4, "implied": True}
    assert (bolt.kind, bolt.summary()) == ("bolt", "pull bolt M8")
    assert bolt.motion().kind == Kind.PRISMATIC and nut.motion().kind == Kind.HELICAL
    assert [float(move.direction @ Z) for move in found.steps] == pytest.approx([1, 1, 1])
    assert max(sweep_overlaps(asm, found.steps)) <= NOISE
    # the check is not blind: the bolt cannot leave downwards
    assert sweep_overlaps(asm, found.steps[2:], reverse=True)[0] > 1.0


@pytest.mark.parametrize(
    ("height", "hexagonal", "kind"),
    [(1.5, True, "pin"), (5.0, True, "screw"), (14.0, True, "pin"), (5.0, False, "pin")],
)
def test_a_washer_or_a_spacer_is_no_nut(tmp_path, height, hexagonal, kind):
    # round a bolt of radius 4 under its plate: a hexagon 1.5 thick (under 0.35 of the
    # diameter: a washer) or 14 long (over 1.5 diameters: a spacer), or a round ring 5
    # high (a spacer), leave it a pin; a hexagon 5 high is a nut and makes it a screw
    plate = cut(box((-20, -20, 0), (40, 40, 8)), cylinder((0, 0, -1), 4.0, 10.0))
    bolt = fuse(cylinder((0, 0, -16), 4.0, 24.0, turn=5), cylinder((0, 0, 8), 7.0, 4.0))
    body = (
        hexagon((0, 0, -height), 13.0, height)
        if hexagonal
        else cylinder((0, 0, -height), 7.0, height)
    )
    ring = cut(body, cylinder((0, 0, -20), 4.0, 30.0))
    asm = read(tmp_path / "ring.step", plate, bolt, ring).assembly
    (fastener,) = [f for move in plan(asm).steps for f in move.fasteners if f.part == "solid2"]
    assert fastener.kind == kind


def rotated(shape, axis, degrees: float):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
    from OCP.gp import gp_Ax1, gp_Dir, gp_Pnt, gp_Trsf

    turn = gp_Trsf()
    turn.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(*axis)), math.radians(degrees))
    return BRepBuilderAPI_Transform(shape, turn).Shape()


def moved_to(shape, x: float):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
    from OCP.gp import gp_Trsf, gp_Vec

    move = gp_Trsf()
    move.SetTranslation(gp_Vec(x, 0, 0))
    return BRepBuilderAPI_Transform(shape, move).Shape()


def filleted(shape, radius: float, pick):
    """``shape`` with its circular edges ``pick(circle)`` rounded."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.BRepFilletAPI import BRepFilletAPI_MakeFillet
    from OCP.GeomAbs import GeomAbs_CurveType
    from OCP.TopAbs import TopAbs_ShapeEnum
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    rounding = BRepFilletAPI_MakeFillet(shape)
    edges = TopExp_Explorer(shape, TopAbs_ShapeEnum.TopAbs_EDGE)
    while edges.More():
        edge = TopoDS.Edge(edges.Current())
        curve = BRepAdaptor_Curve(edge)
        if curve.GetType() == GeomAbs_CurveType.GeomAbs_Circle and pick(curve.Circle()):
            rounding.Add(radius, edge)
        edges.Next()
    return rounding.Shape()


CONCAVE = (
    "countersink",
    "slanted",
    "socket",
    "rounded rim",
    "shoulder",
    "groove",
    "ring",
    "D hole",
    "crossing",
    "slot",
)


@pytest.fixture(scope="module")
def concave_faces(tmp_path_factory):
    """One solid per way a concave face meets the faces around it, side by side in one
    file, read back: the part of each, by name."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCone, BRepPrimAPI_MakeSphere, BRepPrimAPI_MakeTorus
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt

    def along(z: float):
        return gp_Ax2(gp_Pnt(0, 0, z), gp_Dir(0, 0, 1))

    bored = cut(box((-10, -10, 0), (20, 20, 8)), cylinder((0, 0, -1), 3.0, 10.0))
    shapes = {
        # a hole and its countersink: a female cone and a cylinder, coaxial
        "countersink": cut(bored, BRepPrimAPI_MakeCone(along(5), 3.0, 6.0, 3.0001).Shape()),
        # a hole through a face at 35 degrees to its axis: the rim slides along the face
        "slanted": cut(
            rotated(box((-15, -15, -3), (30, 30, 6)), (1, 0, 0), 35),
            cylinder((0, 0, -20), 4.0, 40.0),
        ),
        # a shallow socket: its rim slides in the face, off the sphere's centre
        "socket": cut(
            box((-10, -10, -10), (20, 20, 10)), BRepPrimAPI_MakeSphere(gp_Pnt(0, 0, 2), 6).Shape()
        ),
        # a hole with a rounded rim: a male torus, concave about the axis, tangent to the face
        "rounded rim": filleted(bored, 1.0, lambda c: abs(c.Location().Z() - 8) < 1e-9),
        # a stepped shaft with a fillet in its shoulder: a female torus, inner half
        "shoulder": filleted(
            fuse(cylinder((0, 0, 0), 6.0, 5.0), cylinder((0, 0, 5), 3.0, 8.0)),
            1.0,
            lambda c: abs(c.Location().Z() - 5) < 1e-9 and abs(c.Radius() - 3) < 1e-9,
        ),
        # a bore with a round groove: a female torus, outer half, between two cylinders
        "groove": cut(
            cut(box((-10, -10, 0), (20, 20, 12)), cylinder((0, 0, -1), 4.0, 14.0)),
            BRepPrimAPI_MakeTorus(along(6), 4.0, 1.2).Shape(),
        ),
        "ring": BRepPrimAPI_MakeTorus(along(0), 6.0, 2.0).Shape(),
        # a hole with a flat: a plane parallel to the axis cuts the cylinder
        "D hole": fuse(bored, box((-5, 2.0, 0), (10, 3, 8))),
        # two holes crossing: the rim lies on both cylinders
        "crossing": cut(
            cut(box((-10, -10, -10), (20, 20, 20)), cylinder((0, 0, -11), 4.0, 22.0)),
            cylinder((-11, 0, 0), 3.0, 22.0, axis=(1, 0, 0)),
        ),
        # a slot: half circles tangent to flat sides, whose ends cannot move
        "slot": cut(
            box((-12, -8, 0), (24, 16, 6)),
            fuse(
                fuse(cylinder((-5, 0, -1), 3.0, 8.0), cylinder((5, 0, -1), 3.0, 8.0)),
                box((-5, -3, -1), (10, 6, 8)),
            ),
        ),
    }
    assert tuple(shapes) == CONCAVE
    path = tmp_path_factory.mktemp("fits") / "concave.step"
    write_step(path, *(moved_to(s, 40.0 * k) for k, s in enumerate(shapes.values())))
    return dict(zip(CONCAVE, load_assembly(path), strict=True))


def material_side(surface, points, normals) -> np.ndarray:
    """How far ``points`` lie from ``surface`` on its material side (negative: in the
    void); a torus's material side is read from the triangles' outward ``normals``."""
    if surface.kind == "sphere":
        return np.linalg.norm(points - surface.point, axis=1) - surface.radius
    rel = points - surface.point
    along = rel @ surface.axis
    off = rel - np.outer(along, surface.axis)
    rho = np.linalg.norm(off, axis=1)
    if surface.kind == "cylinder":
        return rho - surface.radius
    if surface.kind == "cone":
        return (rho - along * math.tan(surface.half_angle)) * math.cos(surface.half_angle)
    tube = np.column_stack([rho - surface.radius, along])
    from_tube = np.linalg.norm(tube, axis=1) - surface.minor_radius
    out = (tube[:, :1] * off / rho[:, None]) + tube[:, 1:] * surface.axis
    male = float(np.einsum("ij,ij->", normals, out)) > 0
    return -from_tube if male else from_tube


def test_the_solids_have_every_kind_of_concave_surface(concave_faces):
    kinds = {s.kind for part in concave_faces.values() for s in part.surfaces if sags_out(s)}
    assert kinds == {"cylinder", "cone", "sphere", "torus"}


@pytest.mark.parametrize("name", CONCAVE)
def test_every_concave_face_lies_in_its_solid_within_the_deflection(concave_faces, name):
    part = concave_faces[name]
    mesh, vertices = part.mesh, np.asarray(part.mesh.vertices)
    diagonal = float(np.linalg.norm(np.ptp(mesh.bounds, axis=0)))
    deflection = LINEAR_DEFLECTION * diagonal
    assert mesh.is_watertight and mesh.is_winding_consistent
    bary = np.array([(i, j, 5 - i - j) for i in range(6) for j in range(6 - i)]) / 5
    for surface in part.surfaces:
        corners = vertices[np.asarray(mesh.faces)[surface.faces]]
        if surface.kind == "plane":
            # planar faces stay planar
            offsets = (corners.reshape(-1, 3) - surface.point) @ surface.axis
            assert np.abs(offsets).max() <= 1e-9 * diagonal
            continue
        if not sags_out(surface):
            continue
        normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        points = np.einsum("bk,tkd->tbd", bary, corners).reshape(-1, 3)
        depth = material_side(surface, points, np.repeat(normals, len(bary), axis=0))
        # every point of the face's triangles in the material, but where the rounded
        # rim's vertices stay in the face it is tangent to: there the arcs sag by the
        # square of the sag over the fillet's radius (1)
        slack = deflection**2 if name == "rounded rim" else 1e-12 * diagonal
        assert depth.min() >= -slack, (surface.kind, depth.min())
        # and every vertex within the linear deflection of the surface
        ends = material_side(surface, corners.reshape(-1, 3), np.repeat(normals, 3, axis=0))
        assert np.abs(ends).max() <= deflection, surface.kind


@pytest.fixture(scope="module")
def self_tapping(tmp_path_factory) -> Read:
    """A 20 x 20 x 6 plate with a pilot hole of radius 1.45 and a self-tapping screw of
    radius 1.5 (0.1 mm larger in diameter, a head of radius 2.8 on the plate): the exact
    solids share the ring between the two cylinders."""
    plate = cut(box((-10, -10, 0), (20, 20, 6)), cylinder((0, 0, -1), 1.45, 8.0))
    screw = fuse(cylinder((0, 0, 0.5), 1.5, 5.6, turn=4), cylinder((0, 0, 6), 2.8, 2.0))
    return read(tmp_path_factory.mktemp("fits") / "tapping.step", plate, screw)


def test_a_trimmed_screw_keeps_its_surfaces_and_fits_its_pilot_hole(self_tapping):
    from assemblykit.geometry.overlaps import resolve_overlaps
    from assemblykit.motion.freedom import part_motion

    (plate, screw), asm = self_tapping.shapes, self_tapping.assembly
    shared = common_volume(plate, screw)
    # the ring: pi (1.5^2 - 1.45^2) x 5.5 mm of shank in the plate, by OCCT and by hand
    assert shared == pytest.approx(math.pi * (1.5**2 - 1.45**2) * 5.5, rel=1e-6)
    prepared = resolve_overlaps(asm)
    (overlap,) = prepared.overlaps
    assert overlap.resolution == f"trimmed from {PIN}"
    # the meshes lie inside their solids: they share a little less than the solids
    assert 0.9 * shared < overlap.volume <= shared
    trimmed = prepared[PIN]
    assert overlap_volume(trimmed.mesh, prepared[PLATE].mesh) <= 1e-6 * shared
    assert interferences(prepared) == []
    # the shank cut to the pilot hole is a shaft of its radius on the hole's axis, the
    # head's flat underside is still the plane it was
    shafts = [s for s in trimmed.surfaces if s.kind == "cylinder" and s.radius == 1.45]
    assert shafts and all(s.convex for s in shafts)
    assert all(abs(float(s.axis @ Z)) == pytest.approx(1.0) for s in shafts)
    planes = [s for s in trimmed.surfaces if s.kind == "plane" and s.axis @ Z < -0.99]
    assert any(abs(float(s.point @ Z) - 6.0) <= 1e-9 for s in planes)
    # so the screw fits the hole as a cylinder: it turns and slides on its axis
    (fit,) = next(c for c in assembly_contacts(prepared) if c.curved).curved
    assert (fit.kind, fit.inner, fit.radius) == ("cylindrical", PIN, 1.45)
    freedom = part_motion(prepared, PIN)
    assert freedom.dof >= 1
    found = plan(prepared)
    assert found.feasible
    (step,) = found.steps
    assert step.parts == (PIN,) and float(step.direction @ Z) == pytest.approx(1.0)
    assert max(sweep_overlaps(prepared, found.steps)) <= 1e-6 * shared
    # a fitter reads it as a screw turned out of the plate along its axis
    assert step.fastener is not None
    # an M3 (2.9 mm, 3% under 3): its tip at z = 0.5 turns out of the plate's top at
    # z = 6, 5.5 mm at 0.5 per turn
    assert step.to_dict()["fastener"] == {
        "part": PIN,
        "kind": "screw",
        "axis": [0.0, 0.0, 1.0],
        "holes": [PLATE],
        "diameter": pytest.approx(2.9, rel=1e-9),
        "thread": {"size": "M3", "pitch": 0.5, "turns": 11.0, "implied": True},
    }
    assert step.fastener.summary() == "unscrew M3 (pitch 0.5, 11 turns)"
    # the helical group of its pitch about the screw's axis: half a turn lifts it 0.25
    motion = step.fastener.motion()
    assert motion.kind is Kind.HELICAL and motion.dof == 1
    lift = se3.translation((0.0, 0.0, 0.25)) @ se3.rotation((0.0, 0.0, 1.0), math.pi)
    assert motion.contains(lift) and not motion.contains(se3.translation((0.0, 0.0, 0.25)))


def cone(centre, bottom: float, top: float, height: float):
    """A frustum on the z axis from ``centre``: radius ``bottom`` there, ``top`` at
    ``height`` above."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCone
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt

    frame = gp_Ax2(gp_Pnt(*map(float, centre)), gp_Dir(0.0, 0.0, 1.0))
    return BRepPrimAPI_MakeCone(frame, bottom, top, height).Shape()


@pytest.fixture(scope="module")
def threaded_screw(tmp_path_factory) -> Read:
    """A 20 x 20 x 5 plate with a hole of radius 1.25 and a screw with its thread drawn:
    a shank of the hole's radius from z = -3 to 5, sixteen crests every 0.5 from z = -3
    (rings of a triangular section out to radius 1.55, 0.4 high), and a head of radius
    2.75 from z = 5 - 0.001 to 7, sunk a hair into the plate's top, as a head drawn on
    a face often is: the shared volume is the crests in the plate and a thin disc under
    the head."""
    plate = cut(box((-10, -10, 0), (20, 20, 5)), cylinder((0, 0, -1), 1.25, 7.0))
    screw = fuse(cylinder((0, 0, -3), 1.25, 8.0), cylinder((0, 0, 5 - 0.001), 2.75, 2.001))
    for k in range(16):
        z = -3.0 + 0.5 * k
        screw = fuse(screw, cone((0, 0, z), 1.25, 1.55, 0.2))
        screw = fuse(screw, cone((0, 0, z + 0.2), 1.55, 1.25, 0.2))
    return read(tmp_path_factory.mktemp("thread") / "threaded.step", plate, screw)


def test_a_screw_with_its_thread_drawn_and_its_head_sunk_leaves_along_its_axis(
    threaded_screw,
):
    # the disc under the head is wide and thin: the principal axes of the shared volume
    # lie across the screw, and the plate's hole, which the crests surround, gives the
    # axis the thread is cut along, its crests below the plate too
    from assemblykit.geometry.overlaps import resolve_overlaps

    (plate, screw), asm = threaded_screw.shapes, threaded_screw.assembly
    shared = common_volume(plate, screw)
    disc = math.pi * (2.75**2 - 1.25**2) * 0.001
    assert shared > 10 * disc
    prepared = resolve_overlaps(asm)
    (overlap,) = prepared.overlaps
    assert overlap.resolution == f"trimmed from {PIN}"
    assert interferences(prepared) == []
    shank = prepared[PIN].mesh
    radius = np.linalg.norm(shank.vertices[:, :2], axis=1)
    assert radius[shank.vertices[:, 2] < 4.9].max() <= 1.25 + 1e-9
    found = plan(prepared, max_and_or_parts=0)
    assert found.feasible
    (step,) = found.steps
    assert step.parts == (PIN,) and float(step.direction @ Z) == pytest.approx(1.0)
    assert max(sweep_overlaps(prepared, found.steps)) <= 1e-6
    # pushed the other way the head runs into the plate
    assert max(sweep_overlaps(prepared, found.steps, reverse=True)) > 1.0
    assert step.fastener is not None and step.fastener.kind == "screw"


@pytest.fixture(scope="module")
def screwed_stack(tmp_path_factory) -> Read:
    """Three 20 x 20 x 4 plates at z in [0, 4], [6, 10] and [12, 16], each with a pilot
    hole of radius 1.45 whose seam is turned another way (so each is faceted at its own
    angles), and a self-tapping screw of radius 1.5 from z = -2 to 16 through all three,
    a head of radius 2.8 on the top plate up to z = 18."""
    plates = [
        cut(box((-10, -10, z), (20, 20, 4)), cylinder((0, 0, z - 1), 1.45, 6.0, turn=turn))
        for z, turn in ((0.0, 0.0), (6.0, 7.0), (12.0, 19.0))
    ]
    screw = fuse(cylinder((0, 0, -2), 1.5, 18.0, turn=4), cylinder((0, 0, 16), 2.8, 2.0))
    return read(tmp_path_factory.mktemp("stack") / "stack.step", *plates, screw)


def test_a_screw_tapped_through_plates_faceted_apart_leaves_along_its_axis(screwed_stack):
    # each plate's hole takes off the screw's thread to its own facets; the screw must
    # be inside all of them to pass, and a fitter turns it out through all three: its
    # shank is cut to within 1% of the holes' exact radius along its whole length
    from assemblykit.geometry.overlaps import THREAD_CLEARANCE_SHARE, resolve_overlaps

    asm = screwed_stack.assembly
    screw = "solid4"
    found = interferences(asm)
    assert sorted(a if b == screw else b for a, b, _ in found) == ["solid1", "solid2", "solid3"]
    prepared = resolve_overlaps(asm)
    assert interferences(prepared) == []
    shank = prepared[screw].mesh
    radius = np.linalg.norm(shank.vertices[:, :2], axis=1)
    below_head = shank.vertices[:, 2] < 16 - 1e-6
    assert radius[below_head].max() <= 1.45 + 1e-9
    assert radius[below_head].max() >= 1.45 * (1 - THREAD_CLEARANCE_SHARE) - 1e-9
    # the head still bears on the top plate
    assert shank.bounds[1][2] == pytest.approx(18.0) and radius.max() == pytest.approx(2.8, 1e-3)
    found = plan(prepared, max_and_or_parts=0)
    assert found.feasible
    first = found.steps[0]
    assert first.parts == (screw,) and float(first.direction @ Z) == pytest.approx(1.0)
    assert max(sweep_overlaps(prepared, found.steps)) <= 1e-6
    # pushed the other way the head runs into the top plate
    assert max(sweep_overlaps(prepared, found.steps[:1], reverse=True)) > 1.0


def test_a_flange_coupling_comes_apart_as_a_fitter_takes_it(tmp_path):
    # two flanges (discs of radius 40 with hubs, bores of radius 10) face to face, a
    # shaft of the bore's radius in each hub, four bolts of radius 4 at their holes'
    # radius through both discs (heads under the first) and a hexagon nut on each above
    # the second: everything at nominal size. By hand: the nuts come off upwards and the
    # bolts out downwards along their axes, the flanges part along the bolts once the
    # nuts are off, and each shaft leaves along the axis; every step is clear of every
    # part in place
    holes = [(28 * math.cos(a), 28 * math.sin(a)) for a in np.arange(4) * math.pi / 2]

    def flange(disc: float, hub: float):
        shape = fuse(cylinder((0, 0, disc), 40, 10), cylinder((0, 0, hub), 20, 20))
        shape = cut(shape, cylinder((0, 0, -100), 10, 300))
        for x, y in holes:
            shape = cut(shape, cylinder((x, y, -100), 4, 300))
        return shape

    shafts = [cylinder((0, 0, -60), 10, 58, turn=3), cylinder((0, 0, 22), 10, 58, turn=9)]
    bolts = [fuse(cylinder((x, y, -5), 7, 5), cylinder((x, y, 0), 4, 26)) for x, y in holes]
    nuts = [cut(hexagon((x, y, 20), 13, 6), cylinder((x, y, 19), 4, 8, turn=5)) for x, y in holes]
    shapes = (flange(0, -20), flange(10, 20), *shafts, *bolts, *nuts)
    asm = read(tmp_path / "flange.step", *shapes).assembly
    assert interferences(asm) == []
    found = plan(asm)
    assert found.feasible and max(sweep_overlaps(asm, found.steps)) <= NOISE
    first, second = "solid1", "solid2"
    bolt_names = {f"solid{k}" for k in range(5, 9)}
    nut_names = {f"solid{k}" for k in range(9, 13)}
    when = {name: k for k, step in enumerate(found.steps) for name in step.parts}
    moved = {name: step for step in found.steps for name in step.parts}
    for name in bolt_names | nut_names | {"solid3", "solid4"}:
        assert abs(float(moved[name].direction @ Z)) == pytest.approx(1.0)
    # a bolt leaves once its nut is off (or with it); the flanges part along the bolts'
    # axes once every nut is off (lifted off the bolts, or after them)
    assert all(when[f"solid{9 + k}"] <= when[f"solid{5 + k}"] for k in range(4))
    leaving = second if first not in when else first
    assert abs(float(moved[leaving].direction @ Z)) == pytest.approx(1.0)
    assert all(when[nut] <= when[leaving] for nut in nut_names)
    # each hexagon nut (13 across flats) is unscrewed off its M8 bolt, from its back
    # face at z = 20 to the bolt's tip at z = 26: 6 / 1.25 = 4.8 turns; each bolt then
    # pulled out
    fasteners = {f.part: f for step in found.steps for f in step.fasteners}
    for nut in nut_names:
        assert fasteners[nut].summary() == "unscrew nut M8 (pitch 1.25, 4.8 turns)"
    for bolt in bolt_names:
        assert fasteners[bolt].summary() == "pull bolt M8"


def test_a_ball_sealed_in_a_housing_is_said_enclosed_not_interlocked(tmp_path, capsys):
    """A 20 mm housing with a 16 mm cavity (one solid with a void: the writer's
    ``BREP_WITH_VOIDS``) and a ball of radius 3 floating in it: no motion takes the ball
    out, and the plan says why (``enclosed``), with no hint that a turn may free it."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeSphere
    from OCP.gp import gp_Pnt

    from cli_runs import run

    housing = cut(box((0, 0, 0), (20, 20, 20)), box((2, 2, 2), (16, 16, 16)))
    path = tmp_path / "sealed.step"
    write_step(path, housing, BRepPrimAPI_MakeSphere(gp_Pnt(10, 10, 10), 3).Shape())
    assert "BREP_WITH_VOIDS" in path.read_text()
    asm = load_assembly(path)
    outer, ball = asm.names
    assert asm.parts[outer].mesh.volume == pytest.approx(20**3 - 16**3, rel=1e-9)
    assert not interferences(asm)
    result = plan(asm)
    assert not result.feasible and sorted(result.stuck) == sorted(asm.names)
    (lock,) = result.interlocked
    assert lock.enclosed == ((ball, outer),)
    assert lock.reason == f"enclosed ({ball} in a void of {outer})"
    assert lock.to_dict()["enclosed"] == [{"part": ball, "in": outer}]
    code, out, _ = run(capsys, "plan", str(path))
    assert code == 0 and "in a void of" in out and "--moves rigid" not in out
