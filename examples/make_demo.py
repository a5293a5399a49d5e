"""Generate the bundled demo assembly: a small gearbox of 14 parts.

Run ``python examples/make_demo.py`` from the repository root. It writes one OBJ mesh
per part (in the part's own frame) and the YAML manifest ``gearbox.yaml`` (docs/geometry.md,
"Loaders and their conventions": ``parts: [{name, mesh, pose}]``) into
``src/assemblykit/examples/gearbox_demo/``, where ``assemblykit demo`` finds them in an
installed package.

The parts are exact boxes and faceted cylinders; holes are manifold3d differences with
the very cylinder that fills them, so pins, shafts and bores touch face to face along
coincident facets and no two parts overlap. Units are millimetres, z points up.

Layout: a base plate carries a housing (an open box) fixed by four dowel pins that run
through a cover into blind holes of the base. Inside, two shafts stand on the housing
floor and touch the cover; each carries a spacer and a gear. A plug closes a horizontal
hole in the housing's +x wall.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import manifold3d
import numpy as np
import trimesh
import yaml
from scipy.spatial.transform import Rotation

OUT = Path(__file__).resolve().parents[1] / "src" / "assemblykit" / "examples" / "gearbox_demo"

PIN_RADIUS, PIN_SEGMENTS = 3.0, 16
SHAFT_RADIUS, ROUND_SEGMENTS = 4.0, 24
PIN_XY = [(sx * 45.0, sy * 25.0) for sx in (-1, 1) for sy in (-1, 1)]
SHAFT_XY = [(-20.0, 0.0), (20.0, 0.0)]
PLUG_ROTATION_DEG = (0.0, 90.0, 0.0)
PLUG_AT = (40.0, 0.0, 20.0)
# cutters overshoot the faces they pierce so that no boolean works on coplanar faces
OVERSHOOT = 1.0


@dataclass(frozen=True)
class Part:
    """A part in its own frame and the translation/rotation placing it in the assembly."""

    name: str
    solid: manifold3d.Manifold
    translation: tuple[float, float, float]
    rotation_xyz_deg: tuple[float, float, float] = (0.0, 0.0, 0.0)


def box(lo: tuple[float, float, float], hi: tuple[float, float, float]) -> manifold3d.Manifold:
    """The axis-aligned box with corners ``lo`` and ``hi``."""
    size = tuple(h - low for low, h in zip(lo, hi, strict=True))
    return manifold3d.Manifold.cube(size).translate(lo)


def rod(radius: float, z0: float, z1: float, segments: int) -> manifold3d.Manifold:
    """A vertical faceted cylinder on the z axis from ``z0`` to ``z1``."""
    return manifold3d.Manifold.cylinder(z1 - z0, radius, radius, segments).translate((0, 0, z0))


def placed_rod(
    xy: tuple[float, float], radius: float, z0: float, z1: float, segments: int
) -> manifold3d.Manifold:
    """A vertical rod moved to ``xy``: used both as a part and as the cutter of its hole."""
    return rod(radius, z0, z1, segments).translate((xy[0], xy[1], 0.0))


def plug_solid(x0: float, x1: float) -> manifold3d.Manifold:
    """The horizontal plug cylinder (along +x) spanning ``x0..x1`` in world coordinates."""
    local = rod(SHAFT_RADIUS, x0 - PLUG_AT[0], x1 - PLUG_AT[0], ROUND_SEGMENTS)
    matrix = Rotation.from_euler("xyz", PLUG_ROTATION_DEG, degrees=True).as_matrix()
    affine = np.hstack([matrix, np.reshape(PLUG_AT, (3, 1))])
    return local.transform(affine)


def parts() -> list[Part]:
    """The 14 parts of the gearbox, in their own frames."""
    pin_holes = [placed_rod(xy, PIN_RADIUS, -5.0, 45.0 + OVERSHOOT, PIN_SEGMENTS) for xy in PIN_XY]
    shaft_holes = [
        placed_rod(xy, SHAFT_RADIUS, -OVERSHOOT, 50.0, ROUND_SEGMENTS) for xy in SHAFT_XY
    ]
    base = box((-60, -40, -15), (60, 40, 0)) - manifold3d.Manifold.batch_boolean(
        pin_holes, manifold3d.OpType.Add
    )
    housing = (
        box((-50, -30, 0), (50, 30, 40))
        - box((-40, -20, 5), (40, 20, 40 + OVERSHOOT))
        - manifold3d.Manifold.batch_boolean(pin_holes, manifold3d.OpType.Add)
        - plug_solid(40.0 - OVERSHOOT, 50.0 + OVERSHOOT)
    )
    cover = box((-50, -30, 40), (50, 30, 45)) - manifold3d.Manifold.batch_boolean(
        pin_holes, manifold3d.OpType.Add
    )
    made: list[Part] = [
        Part("base", base, (0.0, 0.0, 0.0)),
        Part("housing", housing, (0.0, 0.0, 0.0)),
        Part("cover", cover, (0.0, 0.0, 0.0)),
    ]
    made += [
        Part(f"pin_{i + 1}", rod(PIN_RADIUS, 0.0, 50.0, PIN_SEGMENTS), (x, y, -5.0))
        for i, (x, y) in enumerate(PIN_XY)
    ]
    for label, (x, y), hole in zip("ab", SHAFT_XY, shaft_holes, strict=True):
        spacer = rod(8.0, 5.0, 15.0, ROUND_SEGMENTS).translate((x, y, 0.0)) - hole
        gear = rod(15.0, 15.0, 23.0, 2 * ROUND_SEGMENTS).translate((x, y, 0.0)) - hole
        made += [
            Part(f"shaft_{label}", rod(SHAFT_RADIUS, 0.0, 35.0, ROUND_SEGMENTS), (x, y, 5.0)),
            Part(f"spacer_{label}", spacer.translate((-x, -y, -5.0)), (x, y, 5.0)),
            Part(f"gear_{label}", gear.translate((-x, -y, -15.0)), (x, y, 15.0)),
        ]
    made.append(
        Part(
            "plug",
            rod(SHAFT_RADIUS, 0.0, 10.0, ROUND_SEGMENTS),
            PLUG_AT,
            PLUG_ROTATION_DEG,
        )
    )
    return made


def to_trimesh(solid: manifold3d.Manifold) -> trimesh.Trimesh:
    """The triangle mesh of a manifold solid, in float64."""
    mesh = solid.to_mesh64()
    vertices = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3]
    return trimesh.Trimesh(vertices, np.asarray(mesh.tri_verts), process=True)


def write(out: Path = OUT) -> Path:
    """Write every part's OBJ file and the manifest; return the manifest's path."""
    out.mkdir(parents=True, exist_ok=True)
    entries = []
    for part in parts():
        mesh_name = f"{part.name}.obj"
        to_trimesh(part.solid).export(out / mesh_name, digits=10, include_normals=False)
        entries.append(
            {
                "name": part.name,
                "mesh": mesh_name,
                "pose": {
                    "translation": list(part.translation),
                    "rotation_xyz_deg": list(part.rotation_xyz_deg),
                },
            }
        )
    manifest = out / "gearbox.yaml"
    header = "# Generated by examples/make_demo.py: a 14-part gearbox in millimetres.\n"
    manifest.write_text(
        header
        + yaml.safe_dump(
            {"units": "mm", "parts": entries}, sort_keys=False, default_flow_style=None
        )
    )
    return manifest


if __name__ == "__main__":
    print(write())
