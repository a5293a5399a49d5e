"""Rotations in plans: finite screw motions that free what no translation frees.

Wilson & Latombe 1992 ("Infinitesimal rigid motions") block twists ``xi = (omega; v)`` at each
contact point ``p`` with normal ``n`` (from the moving set into the rest) unless
``w . xi <= 0`` for ``w = (p x n; n)``: Γ_g tells which sets an infinitesimal rigid
motion may free, a necessary condition only. When the translation planner stops at an
interlocked set that Γ_g may free, this module looks for a *finite* motion:

* candidates: rotations about lines through the set's contact points, along the
  coordinate axes and the cross products of its contact normals (the hinge lines a
  part can pivot on), both ways; a candidate must pass Γ_g's first-order test (no
  contact pushed into, at least one left);
* each is followed as a screw in ``samples`` steps up to ``max_angle``; every sampled
  pose is checked with manifold3d: the moved set may share with the rest no more than
  the interference threshold (:mod:`assemblykit.geometry.interference`);
* pure turns (pitch 0) are tried first; when none works, each line is tried again
  with a pitch ``h`` (a translation of ``h`` per radian along the axis, a *finite
  screw motion*): to first order a contact at ``p`` with normal ``n`` is pushed into
  by ``(omega x (p - c)) . n + h omega . n``, so each contact whose normal is not
  square to the axis (a thread's flank) bounds ``h`` on one side; the ends of the
  interval the contacts leave open are the pitches tried, the screw that slides along
  the flank it presses on;
* at each pose the set must then leave by a straight translation along a coordinate
  axis: the convex hull of the set before and after a translation longer than the
  model contains the whole sweep, so a hull that meets nothing is a sound exit.

A found motion is a plan step with its axis (a point and a direction), its angle, its
pitch and the exit direction that follows. Only sampled poses are checked during the turn: the
step between samples is ``max_angle / samples``.

A thread drawn on a screw and in its nut (or tapped hole) holds the screw in every
translation, and a quarter turn does not free it: it takes as many turns as the thread
is long. When no turn above frees a part, its **threads** are followed
(:func:`_thread_candidates`): about the axis of a cylinder of the part coaxial with a
cylinder of another part, one inside the other (a screw's shank or crests in a nut's
bore, or a nut about a screw), at the pitch of each ISO metric size near either
diameter (ISO 261's coarse pitches, right-handed first), both ways, the poses
checked every :data:`THREAD_STEP` until the part has advanced past the other part's
extent along the axis; it then leaves along the axis or a coordinate axis. The helical
group of that pitch holds the thread's surfaces onto themselves, so a drawn thread
with clearance is clear at every pose of its own motion, and any other pitch runs its
crests into the other's within a turn.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np
import trimesh
from numpy.typing import NDArray

from assemblykit.algebra import se3
from assemblykit.blocking.rigid import RigidBlockingGraph
from assemblykit.geometry.booleans import manifold3d
from assemblykit.geometry.contacts import assembly_contacts, assembly_surfaces
from assemblykit.geometry.interference import interference_threshold, solid
from assemblykit.model.assembly import Assembly
from assemblykit.model.surfaces import Surface
from assemblykit.planning.fasteners import ISO_COARSE_PITCH, MILLIMETRES
from assemblykit.planning.plan_values import Plan
from assemblykit.planning.planner import plan
from assemblykit.tolerance import ModelTolerance, Tolerance

MAX_ANGLE = math.pi / 2
"""Largest turn tried: a quarter turn frees the hooks and latches this looks for."""

SAMPLES = 90
"""Poses checked over ``MAX_ANGLE`` (one degree apart)."""

_EXITS = np.vstack([np.eye(3), -np.eye(3)])

THREAD_STEP = math.pi / 12
"""The turn between two poses checked while a part follows a thread (15 degrees)."""

THREAD_LATER_STEP = math.pi / 3
"""The turn between two poses checked after the first turn of a thread (60 degrees)."""

THREAD_MATCH = 0.25
"""How far (a share of the size) a fit's diameter may be from an ISO metric size for
that size's pitch to be tried on a thread drawn there: the shank, crests and bore of
an M3 are about 2.4, 3.0 and 2.5 to 3.1 mm."""


@dataclass(frozen=True, eq=False)
class ScrewStep:
    """``parts`` turn by ``angle`` (radians, right-handed) about the line through
    ``point`` along unit ``axis`` while translating ``pitch`` per radian along it, away
    from ``rest``, then translate along ``exit`` to infinity."""

    parts: tuple[str, ...]
    rest: tuple[str, ...]
    point: NDArray[np.float64]
    axis: NDArray[np.float64]
    angle: float
    exit: NDArray[np.float64]
    pitch: float = 0.0
    motion: str = "screw"

    def pose(self, fraction: float) -> NDArray[np.float64]:
        """The transform of the moved parts after ``fraction`` of the turn."""
        return se3.screw(self.point, self.axis, self.pitch, self.angle * fraction)

    def to_dict(self) -> dict[str, Any]:
        """JSON form: ``parts``, ``rest``, ``motion`` (``screw``), ``axis`` (``point``,
        ``direction``), ``angle`` (radians), ``angle_deg``, ``pitch`` (model units per
        radian along the axis; 0 for a pure turn), ``advance`` (pitch x angle) and
        ``exit``, ``turns`` (the angle in whole turns: a thread followed out takes
        several)."""
        return {
            "parts": list(self.parts),
            "rest": list(self.rest),
            "motion": self.motion,
            "axis": {"point": self.point.tolist(), "direction": self.axis.tolist()},
            "angle": self.angle,
            "angle_deg": math.degrees(self.angle),
            "pitch": self.pitch,
            "advance": self.pitch * self.angle,
            "turns": self.angle / (2 * math.pi),
            "direction": self.exit.tolist(),
            "exit": self.exit.tolist(),
        }


def _candidates(
    points: NDArray[np.float64], normals: NDArray[np.float64], tol: ModelTolerance, pitched: bool
) -> list[tuple[NDArray[np.float64], NDArray[np.float64], float]]:
    """Screw lines ``(point, signed axis, pitch)`` that pass Γ_g's first-order test (no
    contact pushed into, at least one left): pure turns, or with ``pitched`` the ends of
    the interval of pitches the contacts allow (module docstring)."""
    directions = [*np.eye(3)]
    for a in range(len(normals)):
        for b in range(a + 1, len(normals)):
            c = np.cross(normals[a], normals[b])
            if np.linalg.norm(c) > tol.angle:
                directions.append(c / np.linalg.norm(c))
    axes: list[NDArray[np.float64]] = []
    for d in directions:
        if all(abs(abs(float(d @ e)) - 1.0) > tol.angle for e in axes):
            axes.append(d)
    # one pivot per contact point, told apart at the length tolerance, kept exact
    _, first = np.unique(np.round(points / tol.length), axis=0, return_index=True)
    pivots = points[np.sort(first)]
    found = []
    for axis in axes:
        for sign in (1.0, -1.0):
            omega = sign * axis
            # along each normal: the turn's velocity of its contact point, and the pitch's
            along = normals @ omega
            for pivot in pivots:
                turn = np.einsum("ij,ij->i", np.cross(omega, points - pivot), normals)
                for pitch in _pitches(turn, along, tol) if pitched else [0.0]:
                    push = turn + pitch * along
                    if push.max() <= tol.length and push.min() < -tol.length:
                        found.append((pivot, omega, pitch))
    return found


def _pitches(
    turn: NDArray[np.float64], along: NDArray[np.float64], tol: ModelTolerance
) -> list[float]:
    """The finite, nonzero ends of the interval of pitches ``h`` with
    ``turn + h along <= 0`` at every contact (module docstring)."""
    slanted = np.abs(along) > tol.angle
    bounds = -turn[slanted] / along[slanted]
    low = bounds[along[slanted] < 0].max(initial=-np.inf)
    high = bounds[along[slanted] > 0].min(initial=np.inf)
    if low > high + tol.length:
        return []
    return [float(h) for h in (low, high) if np.isfinite(h) and abs(h) > tol.length]


def _placed(body: manifold3d.Manifold, pose: NDArray[np.float64]) -> manifold3d.Manifold:
    return body.transform(np.ascontiguousarray(pose[:3, :4]))


def _exit(
    body: manifold3d.Manifold,
    rest: manifold3d.Manifold,
    reach: float,
    limit: float,
    first: NDArray[np.float64] | None = None,
) -> NDArray[np.float64] | None:
    """A direction along which ``body`` leaves ``rest`` for good (module docstring):
    ``first`` when given and free, else a coordinate direction; None when none is."""
    corners = np.asarray(body.to_mesh().vert_properties, dtype=np.float64)[:, :3]
    for direction in _EXITS if first is None else np.vstack([first, _EXITS]):
        sweep = manifold3d.Manifold.hull_points(np.vstack([corners, corners + reach * direction]))
        if (sweep ^ rest).volume() <= limit:
            found: NDArray[np.float64] = direction
            return found
    return None


def _joined(assembly: Assembly, names: Iterable[str]) -> trimesh.Trimesh:
    """One mesh of the parts ``names``."""
    mesh = trimesh.util.concatenate([assembly[n].mesh for n in names])
    assert isinstance(mesh, trimesh.Trimesh)  # meshes concatenate to a mesh
    return mesh


def screw_removal(
    assembly: Assembly,
    parts: Iterable[str],
    tol: Tolerance | None = None,
    max_angle: float = MAX_ANGLE,
    samples: int = SAMPLES,
) -> ScrewStep | None:
    """A turn (a pure one if any works, else a screw with a pitch) that takes ``parts``
    out of the rest of ``assembly`` followed by a straight exit (module docstring), or
    None when no candidate works."""
    moving = tuple(p for p in assembly.names if p in set(parts))
    rest = tuple(p for p in assembly.names if p not in set(moving))
    if not moving or not rest:
        return None
    tol = assembly.tolerance(tol)
    graph = RigidBlockingGraph(tuple(assembly.names), tuple(assembly_contacts(assembly, tol)), tol)
    points, normals = graph.constraints(moving)
    if len(points) == 0:
        return None
    moving_mesh, rest_mesh = _joined(assembly, moving), _joined(assembly, rest)
    body, others = solid(moving_mesh), solid(rest_mesh)
    limit = interference_threshold(moving_mesh, rest_mesh, tol)
    reach = 2.0 * assembly.scale
    for pitched in (False, True):
        for pivot, omega, pitch in _candidates(points, normals, tol, pitched):
            axis = omega / np.linalg.norm(omega)
            for k in range(1, samples + 1):
                angle = max_angle * k / samples
                moved = _placed(body, se3.screw(pivot, axis, pitch, angle))
                if (moved ^ others).volume() > limit:
                    break
                leave = _exit(moved, others, reach, limit)
                if leave is not None:
                    # + 0.0: no negative zeros in what is printed
                    return ScrewStep(
                        moving, rest, pivot + 0.0, axis + 0.0, angle, leave + 0.0, pitch + 0.0
                    )
    for pivot, axis, pitch, angle in _thread_candidates(assembly, moving, rest, tol):
        if _follows(body, others, limit, pivot, axis, pitch, angle):
            moved = _placed(body, se3.screw(pivot, axis, pitch, angle))
            leave = _exit(moved, others, reach, limit, axis)
            if leave is not None:
                return ScrewStep(
                    moving, rest, pivot + 0.0, axis + 0.0, angle, leave + 0.0, pitch + 0.0
                )
    return None


def _follows(
    body: manifold3d.Manifold,
    others: manifold3d.Manifold,
    limit: float,
    pivot: NDArray[np.float64],
    axis: NDArray[np.float64],
    pitch: float,
    angle: float,
) -> bool:
    """Whether ``body`` turned about the line (``pivot``, ``axis``) with ``pitch`` per
    radian shares no more than ``limit`` with ``others`` at every pose checked up to
    ``angle``: :data:`THREAD_STEP` apart over the first turn, where a wrong pitch runs
    the crests into each other, then :data:`THREAD_LATER_STEP` apart (the thread holds
    itself onto itself; what else is in the way is met later)."""
    first = np.arange(1, math.ceil(2 * math.pi / THREAD_STEP) + 1) * THREAD_STEP
    later = np.arange(first[-1] + THREAD_LATER_STEP, angle, THREAD_LATER_STEP)
    for turn in [*first[first < angle], *later, angle]:
        moved = _placed(body, se3.screw(pivot, axis, pitch, float(turn)))
        if (moved ^ others).volume() > limit:
            return False
    return True


def _thread_candidates(
    assembly: Assembly, moving: tuple[str, ...], rest: tuple[str, ...], tol: ModelTolerance
) -> list[tuple[NDArray[np.float64], NDArray[np.float64], float, float]]:
    """The thread motions of ``moving`` out of ``rest`` (module docstring) as ``(point,
    unit axis it advances along, pitch per radian, angle)``: for each cylinder of a
    moving part coaxial with one of a part at rest, one inside the other, the ISO
    coarse pitches of the sizes within :data:`THREAD_MATCH` of either diameter (nearest
    first), right-handed then left-handed, along the axis both ways, each turned as far
    as takes the moving parts past the other part's extent along the axis. None where
    the model's unit is not a length one knows in millimetres."""
    scale = MILLIMETRES.get(assembly.units or "")
    if scale is None:
        return []
    found = []
    for inner, outer, other in _coaxial_fits(assembly, moving, rest, tol):
        assert inner.axis is not None
        line = inner.axis / np.linalg.norm(inner.axis)
        diameters = [2 * inner.radius * scale, 2 * outer.radius * scale]
        sizes = sorted(
            (s for s in ISO_COARSE_PITCH if any(abs(s - d) <= THREAD_MATCH * s for d in diameters)),
            key=lambda s: min(abs(s - d) for d in diameters),
        )
        here = np.vstack([np.asarray(assembly[n].mesh.vertices) for n in moving])
        there = np.asarray(assembly[other].mesh.vertices)
        for size in sizes:
            lead = ISO_COARSE_PITCH[size] / scale
            for hand in (1.0, -1.0):
                for axis in (line, -line):
                    advance = float((there @ axis).max() - (here @ axis).min())
                    if advance <= 0:
                        continue
                    angle = 2 * math.pi * (advance + tol.length) / lead
                    found.append((inner.point, axis, hand * lead / (2 * math.pi), angle))
    return found


def _coaxial_fits(
    assembly: Assembly, moving: tuple[str, ...], rest: tuple[str, ...], tol: ModelTolerance
) -> list[tuple[Surface, Surface, str]]:
    """``(inner, outer, other)``: a convex cylinder inside a concave one on the same
    axis (within 5% of the smaller radius), one on a moving part and one on a part
    ``other`` at rest, the outer one no smaller than the inner; each pair of radii
    once."""

    def cylinders(names: tuple[str, ...]) -> list[tuple[Surface, str]]:
        return [
            (s, n)
            for n in names
            for s in assembly_surfaces(assembly, n, tol)
            if s.kind == "cylinder" and s.axis is not None
        ]

    found: list[tuple[Surface, Surface, str]] = []
    seen: set[tuple[float, float]] = set()
    for a, _ in cylinders(moving):
        for b, other in cylinders(rest):
            if a.convex == b.convex:
                continue
            inner, outer = (a, b) if a.convex else (b, a)
            assert inner.axis is not None and outer.axis is not None
            u = inner.axis / np.linalg.norm(inner.axis)
            offset = outer.point - inner.point
            off_axis = float(np.linalg.norm(offset - (offset @ u) * u))
            parallel = float(np.linalg.norm(np.cross(u, outer.axis / np.linalg.norm(outer.axis))))
            near = 0.05 * min(inner.radius, outer.radius)
            key = (round(inner.radius / tol.length), round(outer.radius / tol.length))
            if (
                off_axis <= near
                and parallel <= tol.mesh_angle
                and inner.radius <= outer.radius + tol.length
                and key not in seen
            ):
                seen.add(key)
                found.append((inner, outer, other))
    return found


@dataclass(frozen=True, eq=False)
class ScrewPlan:
    """A translation plan (Wilson & Latombe 1992, "Extension and Variant": extended
    translations) extended by turns: ``stages[0]`` plans the whole; where it stops,
    ``screws[k]`` takes one part of the stuck set out by a turn and ``stages[k + 1]``
    plans what remains of that set."""

    stages: tuple[Plan, ...]
    screws: tuple[ScrewStep, ...]

    @property
    def feasible(self) -> bool:
        """True when the last stage takes everything apart."""
        return self.stages[-1].feasible

    def to_dict(self) -> dict[str, Any]:
        """The plan keys of docs/planning.md, "JSON" (``feasible``, ``steps``,
        ``stuck``) with the turns among the ``steps`` (``motion``: ``screw``), plus ``screws``."""
        steps: list[dict[str, Any]] = []
        for k, stage in enumerate(self.stages):
            steps += [s.to_dict() for s in stage.steps]
            if k < len(self.screws):
                steps.append(self.screws[k].to_dict())
        return {
            "feasible": self.feasible,
            "steps": steps,
            "stuck": list(self.stages[-1].stuck),
            "screws": [s.to_dict() for s in self.screws],
            "moves": "rigid",
        }


def plan_with_screws(
    assembly: Assembly, tol: Tolerance | None = None, fixed: Iterable[str] = ()
) -> ScrewPlan:
    """:func:`~assemblykit.planning.planner.plan`, then, while it stops at a stuck set,
    a turn (:func:`screw_removal`) of one of its parts and a plan of the others. The
    ``fixed`` parts are never moved, by a translation or a turn (docs/planning.md,
    "Fixed parts")."""
    anchored = tuple(fixed)
    stages = [plan(assembly, tol=tol, fixed=anchored)]
    screws: list[ScrewStep] = []
    while not stages[-1].feasible:
        stuck = assembly.subset(stages[-1].stuck)
        turn = next(
            (
                t
                for name in stuck.names
                if name not in anchored and (t := screw_removal(stuck, [name], tol)) is not None
            ),
            None,
        )
        if turn is None:
            break
        screws.append(turn)
        rest = stuck.subset(turn.rest)
        stages.append(plan(rest, tol=tol, fixed=[n for n in anchored if n in rest.names]))
    return ScrewPlan(tuple(stages), tuple(screws))
