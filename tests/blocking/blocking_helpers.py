"""Hand-built assemblies for the blocking-graph tests: contacts given as value types."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import trimesh

from assemblykit.geometry.contacts import Contact, CurvedPatch, PlanarPatch, assembly_contacts
from assemblykit.model.assembly import Assembly, Memo, Part
from assemblykit.tolerance import Tolerance, current
from datasets import dataset


@dataclass(eq=False)
class ContactAssembly:
    """Just what the blocking graphs read: part names, contacts and a memo."""

    names: list[str]
    given: list[Contact]
    dimension: int = 3
    memo: Memo = field(default_factory=Memo)

    def contacts(self, tol: Tolerance | None = None) -> list[Contact]:
        return self.given

    def tolerance(self, tol: Tolerance | None = None) -> Tolerance:
        return tol or current()


assembly_contacts.register(ContactAssembly, ContactAssembly.contacts)


def square(normal, center=(0.0, 0.0, 0.0), half=0.5) -> PlanarPatch:
    """A square patch of side 2*half centred at ``center`` with the given normal."""
    n = np.asarray(normal, dtype=np.float64)
    n = n / np.linalg.norm(n)
    e1 = np.cross(n, np.eye(3)[int(np.argmin(np.abs(n)))])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    c = np.asarray(center, dtype=np.float64)
    poly = np.array(
        [c + half * (sx * e1 + sy * e2) for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    )
    return PlanarPatch(n, poly, (2 * half) ** 2)


def cylinder(axis, inner: str) -> CurvedPatch:
    return CurvedPatch(
        "cylindrical",
        np.zeros(3),
        np.asarray(axis, dtype=np.float64),
        1.0,
        inner,
        extent=(-1.0, 0.0),
    )


def mesh_assembly(meshes: dict[str, trimesh.Trimesh]) -> Assembly:
    return Assembly([Part(name, mesh) for name, mesh in meshes.items()])


def random_box_contacts(rng: np.random.Generator, n: int, c: int) -> ContactAssembly:
    """Boxes of random orientations: ``c`` contacts between random pairs of ``n`` parts,
    normals drawn from a few rotated box frames so that planes repeat."""
    frames = [
        trimesh.transformations.random_rotation_matrix(rng.random(3))[:3, :3] for _ in range(3)
    ]
    names = [f"p{i}" for i in range(n)]
    contacts = []
    for _ in range(c):
        a, b = rng.choice(n, 2, replace=False)
        frame = frames[rng.integers(len(frames))]
        normal = frame[:, rng.integers(3)] * rng.choice([-1.0, 1.0])
        contacts.append(Contact(names[a], names[b], planar=(square(normal),)))
    return ContactAssembly(names, contacts)


def compas_folder() -> Path:
    """The folder of the bundled COMPAS assemblies."""
    return dataset("compas_assembly")
