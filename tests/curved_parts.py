"""Parts touching on part of a surface of revolution, built with manifold3d booleans, and
an independent check that a part leaves along a direction (a swept overlap volume)."""

from __future__ import annotations

from pathlib import Path

import manifold3d
import numpy as np
import trimesh

import assemblykit
from assemblykit.model.assembly import Assembly, Part
from assemblykit.model.packings import box_mesh as box

BALL_JOINT = Path(assemblykit.__file__).parent / "examples" / "motion" / "ball_joint"
RADIUS = 1.0
ROD_LENGTH = 4.0
SECTIONS = 32


def rod(length: float = ROD_LENGTH) -> trimesh.Trimesh:
    """A cylinder of radius 1 along y, centred at the origin: its axis lies at z = 0."""
    mesh = trimesh.creation.cylinder(radius=RADIUS, height=length, sections=SECTIONS)
    mesh.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [1.0, 0.0, 0.0]))
    return mesh


def rod_in_groove(through: bool) -> Assembly:
    """A rod lying in a half-round channel cut along y into the top (z = 0) of a block
    4 wide and 2 deep. ``through``: the block is as long as the rod and the channel runs
    through it; otherwise the block is 6 long and the channel's closed ends touch the
    rod's end faces."""
    length = ROD_LENGTH if through else ROD_LENGTH + 2.0
    block = box([-2.0, -length / 2, -2.0], [2.0, length / 2, 0.0])
    cutter = rod(ROD_LENGTH + 2.0 if through else ROD_LENGTH)
    grooved = block.difference(cutter, engine="manifold")
    return Assembly([Part("block", grooved), Part("rod", rod())])


def shaft_in_hole() -> Assembly:
    """The rod through a block 4 x 4 x 4 bored along y with the rod's own cross-section."""
    block = box([-2.0, -2.0, -2.0], [2.0, 2.0, 2.0])
    bored = block.difference(rod(ROD_LENGTH + 2.0), engine="manifold")
    return Assembly([Part("block", bored), Part("rod", rod())])


def ball_in_closed_socket() -> Assembly:
    """A ball of radius 1 in a spherical cavity of the same mesh inside a 4-cube."""
    ball = trimesh.creation.icosphere(subdivisions=2, radius=RADIUS)
    housing = box([-2.0, -2.0, -2.0], [2.0, 2.0, 2.0]).difference(ball, engine="manifold")
    return Assembly([Part("housing", housing), Part("ball", ball)])


def _solid(mesh: trimesh.Trimesh) -> manifold3d.Manifold:
    return manifold3d.Manifold(
        manifold3d.Mesh64(
            vert_properties=np.ascontiguousarray(mesh.vertices, dtype=np.float64),
            tri_verts=np.ascontiguousarray(mesh.faces, dtype=np.uint64),
        )
    )


def swept_overlaps(
    assembly: Assembly, moving: str, direction: np.ndarray, distances: np.ndarray
) -> tuple[np.ndarray, float]:
    """The volume ``moving`` shares with the other parts, translated by each distance
    along ``direction`` (manifold3d booleans), and the largest volume the interference
    policy counts as touching (length tolerance times the smaller surface area)."""
    d = np.asarray(direction, dtype=np.float64) / np.linalg.norm(direction)
    mover = _solid(assembly.parts[moving].mesh)
    others = [p.mesh for name, p in assembly.parts.items() if name != moving]
    length = assembly.tolerance().length
    area = min(float(assembly.parts[moving].mesh.area), *(float(m.area) for m in others))
    volumes = [
        sum((mover.translate(tuple(t * d)) ^ _solid(other)).volume() for other in others)
        for t in distances
    ]
    return np.array(volumes), length * area


# small steps first (the local test), then out to well beyond the parts' size
DISTANCES = np.concatenate([[1e-4, 1e-3, 1e-2], np.linspace(0.05, 10.0, 40)])
