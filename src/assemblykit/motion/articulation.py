"""Articulated assemblies: joints and coupled gear trains (Liu 1997 §4, Figs. 7-9).

Liu 1997 represents the gearbox by the motion group of each gear relative to the
housing, Lᵢ = aᵢ SO(2) aᵢ⁻¹ (a revolute about the gear's shaft, from a cylinder and a
plane), and the gear pairs by products Lᵢⱼ = Lᵢ Lⱼ "where the relative gear pitch ratio
is also embedded". Here every part whose motion (:func:`assemblykit.motion.motion`) is
a revolute is a candidate gear; two of them *mesh* when their axes are parallel and
their pitch circles are tangent. Externally, |N₁N₂| = R₁ + R₂ (R the largest distance
of the part's mesh from its axis, i.e. the pitch radius of a gear drawn as its pitch
cylinder), and the gears turn in opposite senses about the common axis direction:
ω₂ = -(R₁/R₂) ω₁. Internally, a gear inside a ring (internal) gear whose pitch circle
is its bore (r, the smallest distance of the ring's mesh from its axis):
|N₁N₂| = r − R > 0, and both turn the same way with equal pitch-line speeds,
r ω_ring = R ω_gear. The gear train's joint speeds are the null space of these coupling
equations (scipy): its dimension is the train's dof (1 for a simple train, 0 for a
locked loop), and for one dof the ratios of every gear to the first one.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import networkx as nx
import numpy as np
from numpy.typing import NDArray
from scipy.linalg import null_space

from assemblykit.algebra import Kind
from assemblykit.model.assembly import Assembly
from assemblykit.motion.freedom import Motion, MotionReport, motion
from assemblykit.tolerance import ModelTolerance, Tolerance

Vector = NDArray[np.float64]


@dataclass(frozen=True)
class Revolute:
    """A part turning about the line through ``point`` with unit ``direction``, with
    ``radius`` the largest and ``inner_radius`` the smallest distance of its mesh from
    that line (its pitch radii as a gear and as a ring gear)."""

    part: str
    point: Vector
    direction: Vector
    radius: float
    inner_radius: float = 0.0


@dataclass(frozen=True)
class GearMesh:
    """Gears ``a`` and ``b`` in mesh: ``ratio`` = ω_b / ω_a about their axis directions."""

    a: str
    b: str
    ratio: float

    def to_dict(self) -> dict[str, Any]:
        """``a``, ``b`` and ``ratio``."""
        return {"a": self.a, "b": self.b, "ratio": self.ratio}


@dataclass(frozen=True)
class GearTrain:
    """A connected set of meshing gears: ``dof`` of the coupled motion and, for one dof,
    the speed ``ratios`` of every gear to the first (``gears[0]``, ratio 1)."""

    gears: tuple[str, ...]
    meshes: tuple[GearMesh, ...]
    dof: int
    ratios: dict[str, float]

    def to_dict(self) -> dict[str, Any]:
        """``gears``, ``dof``, ``ratios`` and ``meshes``."""
        return {
            "gears": list(self.gears),
            "dof": self.dof,
            "ratios": dict(self.ratios),
            "meshes": [m.to_dict() for m in self.meshes],
        }


def revolute_of(assembly: Assembly, moved: Motion) -> Revolute | None:
    """The revolute joint of a single part whose motion is a revolute, else ``None``."""
    if moved.kind != Kind.REVOLUTE or len(moved.parts) != 1:
        return None
    axis = moved.to_dict()["axis"]
    point = np.asarray(axis["point"], dtype=np.float64)
    direction = np.asarray(axis["direction"], dtype=np.float64)
    offsets = np.asarray(assembly.part(moved.parts[0]).mesh.vertices, dtype=np.float64) - point
    radial = offsets - np.outer(offsets @ direction, direction)
    distances = np.linalg.norm(radial, axis=1)
    return Revolute(
        moved.parts[0], point, direction, float(np.max(distances)), float(np.min(distances))
    )


def _mesh_ratio(
    first: Revolute, second: Revolute, distance: float, tol: ModelTolerance
) -> float | None:
    """ω_second / ω_first, each about its own axis direction, for two revolutes on
    parallel axes ``distance`` apart; ``None`` if their pitch circles are not tangent
    (module docstring: an external mesh, or one gear inside the other's ring)."""
    if abs(distance - (first.radius + second.radius)) <= tol.length:
        ratio = -first.radius / second.radius
    elif distance <= tol.length:
        return None
    elif abs(distance - (first.inner_radius - second.radius)) <= tol.length:
        ratio = first.inner_radius / second.radius
    elif abs(distance - (second.inner_radius - first.radius)) <= tol.length:
        ratio = first.radius / second.inner_radius
    else:
        return None
    return ratio if float(first.direction @ second.direction) > 0 else -ratio


def gear_meshes(joints: Sequence[Revolute], tol: ModelTolerance) -> list[GearMesh]:
    """The pairs of revolutes with parallel axes and tangent pitch circles, external or
    internal (a gear in a ring gear)."""
    found = []
    for first, second in itertools.combinations(joints, 2):
        if np.linalg.norm(np.cross(first.direction, second.direction)) > tol.angle:
            continue
        offset = second.point - first.point
        distance = float(np.linalg.norm(np.cross(offset, first.direction)))
        ratio = _mesh_ratio(first, second, distance, tol)
        if ratio is not None:
            found.append(GearMesh(first.part, second.part, ratio))
    return found


def gear_trains(meshes: Iterable[GearMesh], tol: ModelTolerance) -> list[GearTrain]:
    """The gear trains (connected components of the meshes) with their coupled motion."""
    meshes = list(meshes)
    graph: nx.Graph[str] = nx.Graph()
    for m in meshes:
        graph.add_edge(m.a, m.b)
    trains = []
    for component in nx.connected_components(graph):
        gears = tuple(n for n in graph.nodes if n in component)
        index = {g: i for i, g in enumerate(gears)}
        inside = tuple(m for m in meshes if m.a in component)
        coupling = np.zeros((len(inside), len(gears)))
        for row, m in enumerate(inside):
            coupling[row, index[m.a]] = m.ratio
            coupling[row, index[m.b]] = -1.0
        speeds = null_space(coupling, rcond=tol.angle)
        dof = speeds.shape[1]
        ratios = {g: float(speeds[index[g], 0] / speeds[0, 0]) for g in gears} if dof == 1 else {}
        trains.append(GearTrain(gears, inside, dof, ratios))
    return trains


@dataclass(frozen=True, eq=False)
class Articulation:
    """The motions of an assembly with its gear trains coupled (Liu 1997 Fig. 9)."""

    report: MotionReport
    trains: tuple[GearTrain, ...]

    def to_dict(self) -> dict[str, Any]:
        """The motion report's ``parts`` and the ``gear_trains``."""
        return {**self.report.to_dict(), "gear_trains": [t.to_dict() for t in self.trains]}


def articulation(
    assembly: Assembly,
    subassemblies: Iterable[Sequence[str]] | None = None,
    tol: Tolerance | None = None,
) -> Articulation:
    """Every part's motion (and the given subassemblies'), with the gear trains formed
    by meshing revolute parts and their coupled motion."""
    report = motion(assembly, subassemblies, tol)
    working = assembly.tolerance(tol)
    joints = [j for m in report.motions.values() if (j := revolute_of(assembly, m)) is not None]
    return Articulation(report, tuple(gear_trains(gear_meshes(joints, working), working)))
