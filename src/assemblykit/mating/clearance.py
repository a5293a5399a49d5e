"""Interference of bodies that keep a freedom, over their whole parameter ranges (Liu & Popplestone
1990 step three, "the no-pairwise-interference constraint", and its Discussion: "sweep the
body concerned under the symmetry group of its constantly contacting features, then
intersect this swept volume with the rest of the assembly").

A body left with a revolute, prismatic, helical or cylindrical world coset moves as
``L(θ, s) = F·Rz(θ)·Tz(s)·F⁻¹·L₀`` (F the group's frame, its +z the axis). In the motion
frame ``F⁻¹·L₀`` the body is cut into z-bands (between its vertex heights) and angular
sectors; each piece lies in a cylindrical-coordinate box ``[r₀, r₁] × [z₀, z₁] ×
[α₀, α₁]`` (r₁ the largest vertex radius, r₀ the distance from the axis to the piece's
projection: both exact on a polyhedron). Two solids of revolution follow, both built by
manifold3d ``revolve`` of rectangles of the (r, z) half-plane:

* the **sweep** over a parameter box (θ ∈ [a, b], s ∈ [c, d]) contains every pose of the
  box: each piece revolved over ``[α₀ + a, α₁ + b]``, heights ``[z₀ + c, z₁ + d]``,
  outer polygon circumscribing the radius r₁, inner one inscribed in r₀;
* the **kernel** is contained in every pose of the box: the discs about the axis that
  lie inside the body (read from the mid-height section of a band, then confirmed by a
  manifold3d difference of zero volume), kept at heights reached by every slide of the
  box, inner polygons inscribed.

For two bodies A, B (fixed or moving) and a box of their joint parameters:
``vol(sweep_A ∩ sweep_B)`` within the touching threshold proves the box free;
``vol(kernel_A ∩ kernel_B)`` beyond it proves every pose of the box interferes. Boxes
neither proves are bisected (widest parameter first, angles weighted by the body's
radius) and their centres checked exactly: a free centre is a witness. The pair's
verdict is ``clear`` (free over the whole range, certified), ``free`` (a witness),
``blocked`` (every box proved to interfere) or ``undecided`` (the box budget ran out).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from enum import StrEnum
from functools import cached_property

import numpy as np
import shapely
import trimesh

from assemblykit.algebra import Coset, Kind, se3
from assemblykit.geometry.booleans import manifold3d
from assemblykit.geometry.interference import interference_threshold, solid, solids_interfere
from assemblykit.geometry.solids import placed
from assemblykit.tolerance import ModelTolerance

#: Polygon sides of a full revolution (manifold3d uses as many for a partial one).
SEGMENTS = 48
#: Angular sectors each band of a moving body is cut into.
SECTORS = 8
#: Most z-bands per body (vertex heights beyond are merged; bounds stay conservative).
MAX_BANDS = 24
#: Parameter boxes examined per pair of bodies before the verdict is ``undecided``.
BOX_BUDGET = 64
#: Halvings of a disc radius tried before a band is left out of the kernel.
DISC_HALVINGS = 3

#: The motions handled by the cylindrical-coordinate bounds (one or two parameters).
SWEPT = frozenset({Kind.REVOLUTE, Kind.PRISMATIC, Kind.HELICAL, Kind.CYLINDRICAL})

Interval = tuple[float, float]
Box = tuple[Interval, ...]


class Verdict(StrEnum):
    """What the joint parameter range of two bodies allows (module docstring)."""

    CLEAR = "clear"
    FREE = "free"
    BLOCKED = "blocked"
    UNDECIDED = "undecided"


@dataclass(frozen=True)
class Piece:
    """A piece of a band of a body in its motion frame: radii, heights, angles."""

    r0: float
    r1: float
    z0: float
    z1: float
    a0: float
    a1: float


@dataclass(frozen=True)
class Disc:
    """A disc about the motion axis inside the body: radius and heights."""

    radius: float
    z0: float
    z1: float


@dataclass(frozen=True, eq=False)
class Profile:
    """A body's cylindrical-coordinate bounds in its motion frame: the ``pieces`` (outer
    bound), the ``discs`` (inner bound, contiguous bands in height order) and the
    largest ``radius`` (to weigh angles against lengths)."""

    pieces: tuple[Piece, ...]
    discs: tuple[Disc, ...]
    radius: float


@dataclass(frozen=True, eq=False)
class Mover:
    """A body with its poses: fixed (``coset`` a point) or moving over ``span`` (the
    group parameters' ranges: angles in [-π, π], travels within the model's size)."""

    name: str
    mesh: trimesh.Trimesh
    coset: Coset
    span: Box
    profile: Profile | None

    @property
    def dof(self) -> int:
        return len(self.span)

    @cached_property
    def own_solid(self) -> manifold3d.Manifold:
        """The body's solid in its own frame, built once and moved to each pose."""
        return solid(self.mesh, self.name)

    @cached_property
    def placed_solid(self) -> manifold3d.Manifold:
        """The body's solid at the representative pose (a fixed body in every pose)."""
        return solid(placed(self.mesh, self.coset.rep), self.name)

    def solid_at(self, params: Sequence[float]) -> manifold3d.Manifold:
        """The body's solid at the group parameters ``params``."""
        return self.own_solid.transform(self.pose(params)[:3, :])

    def pose(self, params: Sequence[float]) -> np.ndarray:
        """The world pose at the group parameters ``params`` (the representative at 0)."""
        if not self.span:
            return self.coset.rep
        return self.coset.group.element(list(params)) @ self.coset.rep

    def extent(self, box: Box) -> tuple[Interval, Interval]:
        """The (θ, s) ranges in the motion frame that the parameter box reaches."""
        kind = self.coset.kind
        if kind is Kind.REVOLUTE:
            return box[0], (0.0, 0.0)
        if kind is Kind.PRISMATIC:
            return (0.0, 0.0), box[0]
        if kind is Kind.CYLINDRICAL:
            return box[0], box[1]
        # Helical: the slide follows the turn, s = pitch·θ; its range bounds it.
        pitch = self.coset.group.pitch
        ends = sorted((pitch * box[0][0], pitch * box[0][1]))
        return box[0], (ends[0], ends[1])

    def weights(self) -> tuple[float, ...]:
        """Length per unit of each parameter: the radius for an angle, 1 for a travel."""
        radius = self.profile.radius if self.profile is not None else 1.0
        kind = self.coset.kind
        if kind is Kind.PRISMATIC:
            return (1.0,)
        if kind is Kind.CYLINDRICAL:
            return (radius, 1.0)
        return (radius,)


def mover(name: str, mesh: trimesh.Trimesh, coset: Coset, tol: ModelTolerance) -> Mover:
    """The body ``name`` over its world ``coset``: fixed when the coset is a point, else
    moving over a full turn and, for a slide, the model's size either way."""
    if coset.is_point or coset.kind not in SWEPT:
        return Mover(name, mesh, coset, (), None)
    turn, travel = (-math.pi, math.pi), (-tol.scale, tol.scale)
    span = {
        Kind.REVOLUTE: (turn,),
        Kind.HELICAL: (turn,),
        Kind.PRISMATIC: (travel,),
        Kind.CYLINDRICAL: (turn, travel),
    }[coset.kind]
    frame = coset.group.frame
    return Mover(name, mesh, coset, span, profile(mesh, se3.inverse(frame) @ coset.rep, tol))


def sweepable(coset: Coset) -> bool:
    """Whether the cylindrical-coordinate bounds handle this coset (fixed or 1-2 dof)."""
    return coset.is_point or coset.kind in SWEPT


# ----------------------------------------------------------------------------- bounds


def profile(mesh: trimesh.Trimesh, motion_frame: np.ndarray, tol: ModelTolerance) -> Profile:
    """The cylindrical-coordinate bounds of ``mesh`` placed by ``motion_frame`` (module
    docstring): pieces by band and sector, and the confirmed discs about the axis."""
    body = solid(placed(mesh, motion_frame))
    vertices = np.asarray(body.to_mesh().vert_properties)[:, :3]
    radius = float(np.max(np.hypot(vertices[:, 0], vertices[:, 1])))
    levels = _levels(vertices[:, 2], tol.mesh_length)
    pieces: list[Piece] = []
    discs: list[Disc] = []
    step = 2 * math.pi / SECTORS
    for z0, z1 in itertools.pairwise(levels):
        # Cut a length tolerance inside the band: a cut along a face of the body leaves
        # that face behind as a flap of no volume, which must not widen the bounds.
        inset = tol.mesh_length
        band = body.trim_by_plane((0.0, 0.0, 1.0), z0 + inset).trim_by_plane(
            (0.0, 0.0, -1.0), -(z1 - inset)
        )
        if band.is_empty():
            continue
        for k in range(SECTORS):
            a0, a1 = k * step, (k + 1) * step
            # The sector a0 <= angle <= a1 (a1 - a0 < pi): left of ray a0, right of ray a1.
            piece = band.trim_by_plane((-math.sin(a0), math.cos(a0), 0.0), 0.0).trim_by_plane(
                (math.sin(a1), -math.cos(a1), 0.0), 0.0
            )
            # The piece's shadow on the xy plane: its farthest vertex and nearest point
            # give the piece's radii exactly.
            shadow = _shape(piece.project()) if not piece.is_empty() else shapely.Polygon()
            if shadow.is_empty or shadow.area <= tol.mesh_length**2:
                continue
            corners = shapely.get_coordinates(shadow)
            r1 = float(np.max(np.hypot(corners[:, 0], corners[:, 1])))
            r0 = float(shapely.distance(shadow, shapely.Point(0.0, 0.0)))
            pieces.append(Piece(r0, r1, z0, z1, a0, a1))
        disc = _disc(body, z0, z1, tol)
        if disc is not None:
            discs.append(disc)
    return Profile(tuple(pieces), tuple(discs), radius)


def _levels(heights: np.ndarray, merge: float) -> list[float]:
    """Distinct vertex heights (closer than ``merge`` are one), at most MAX_BANDS bands."""
    levels: list[float] = []
    for z in np.sort(heights):
        if not levels or z - levels[-1] > merge:
            levels.append(float(z))
    if len(levels) - 1 > MAX_BANDS:
        keep = np.linspace(0, len(levels) - 1, MAX_BANDS + 1).round().astype(int)
        levels = [levels[i] for i in keep]
    return levels


def _shape(section: manifold3d.CrossSection) -> shapely.Geometry:
    """A cross-section as a shapely region (contours combined by the even-odd rule)."""
    region = shapely.Polygon()
    for contour in section.to_polygons():
        if len(contour) >= 3:
            region = shapely.symmetric_difference(region, shapely.Polygon(contour))
    return region


def _disc(body: manifold3d.Manifold, z0: float, z1: float, tol: ModelTolerance) -> Disc | None:
    """The disc about the axis inside ``body`` between z0 and z1: its radius read from the
    mid-height section, then confirmed (halved if needed) by an empty difference."""
    region = _shape(body.slice(0.5 * (z0 + z1)))
    origin = shapely.Point(0.0, 0.0)
    if region.is_empty or not region.contains(origin):
        return None
    radius = float(shapely.distance(region.boundary, origin))
    for _ in range(DISC_HALVINGS):
        # Vertices on the radius: the polygon lies inside the true disc.
        cylinder = manifold3d.Manifold.cylinder(z1 - z0, radius, radius, SEGMENTS).translate(
            (0.0, 0.0, z0)
        )
        outside = (cylinder - body).volume()
        if outside <= tol.mesh_length * cylinder.surface_area():
            return Disc(radius, z0, z1)
        radius *= 0.5
    return None


def sweep_solid(body: Mover, box: Box) -> manifold3d.Manifold:
    """A solid containing the body in every pose of the parameter ``box`` (world)."""
    if body.profile is None:
        return body.placed_solid
    (a, b), (c, d) = body.extent(box)
    outer = 1.0 / math.cos(math.pi / SEGMENTS)
    parts = []
    for p in body.profile.pieces:
        span = (p.a1 - p.a0) + (b - a)
        rect = manifold3d.CrossSection.square((p.r1 * outer - p.r0, (p.z1 + d) - (p.z0 + c)))
        rect = rect.translate((p.r0, p.z0 + c))
        if span >= 2 * math.pi:
            parts.append(manifold3d.Manifold.revolve(rect, SEGMENTS))
        else:
            wedge = manifold3d.Manifold.revolve(rect, SEGMENTS, math.degrees(span))
            parts.append(wedge.rotate((0.0, 0.0, math.degrees(p.a0 + a))))
    union = manifold3d.Manifold.batch_boolean(parts, manifold3d.OpType.Add)
    return union.transform(body.coset.group.frame[:3, :])


def kernel_solid(body: Mover, box: Box) -> manifold3d.Manifold | None:
    """A solid inside the body in every pose of the parameter ``box`` (world), or
    ``None`` when no disc survives the box's slide."""
    if body.profile is None:
        return body.placed_solid
    _, (c, d) = body.extent(box)
    discs = body.profile.discs
    parts = []
    # Runs of contiguous discs: a point stays inside while its height plus the slide
    # stays in the run, at the run's smallest radius.
    for i in range(len(discs)):
        radius = discs[i].radius
        for j in range(i, len(discs)):
            if j > i and discs[j].z0 > discs[j - 1].z1:
                break
            radius = min(radius, discs[j].radius)
            low, high = discs[i].z0 + d, discs[j].z1 + c
            if high > low:
                parts.append(
                    manifold3d.Manifold.cylinder(high - low, radius, radius, SEGMENTS).translate(
                        (0.0, 0.0, low)
                    )
                )
    if not parts:
        return None
    union = manifold3d.Manifold.batch_boolean(parts, manifold3d.OpType.Add)
    return union.transform(body.coset.group.frame[:3, :])


# ----------------------------------------------------------------------------- verdicts


@dataclass(frozen=True)
class PairResult:
    """The verdict on two bodies over their joint range, with a free ``witness`` (group
    parameters of the first body, then of the second) when one is known."""

    verdict: Verdict
    witness: tuple[float, ...] | None = None


def overlaps(
    first: Mover, a: Sequence[float], second: Mover, b: Sequence[float], tol: ModelTolerance
) -> bool:
    """The exact test at one joint parameter value (manifold3d volumes)."""
    threshold = interference_threshold(first.mesh, second.mesh, tol.for_mesh())
    return solids_interfere(first.solid_at(a), second.solid_at(b), threshold)


def judge_pair(
    first: Mover, second: Mover, tol: ModelTolerance, budget: int = BOX_BUDGET
) -> PairResult:
    """The verdict on ``first`` and ``second`` over their joint parameter box (module
    docstring): sweeps for the whole range, then bisection with kernels and exact
    centres."""
    threshold = interference_threshold(first.mesh, second.mesh, tol.for_mesh())
    split = first.dof
    full: Box = (*first.span, *second.span)
    if not full:
        clear = not overlaps(first, (), second, (), tol)
        return PairResult(Verdict.CLEAR if clear else Verdict.BLOCKED, () if clear else None)
    together = sweep_solid(first, full[:split]) ^ sweep_solid(second, full[split:])
    if together.volume() <= threshold:
        return PairResult(Verdict.CLEAR, tuple(0.5 * (lo + hi) for lo, hi in full))
    weights = (*first.weights(), *second.weights())
    queue: list[Box] = [full]
    examined = 0
    while queue:
        if examined >= budget:
            return PairResult(Verdict.UNDECIDED)
        box = queue.pop(0)
        examined += 1
        centre = tuple(0.5 * (lo + hi) for lo, hi in box)
        if not overlaps(first, centre[:split], second, centre[split:], tol):
            return PairResult(Verdict.FREE, centre)
        inner_a, inner_b = kernel_solid(first, box[:split]), kernel_solid(second, box[split:])
        if inner_a is not None and inner_b is not None and (inner_a ^ inner_b).volume() > threshold:
            continue
        widest = max(range(len(box)), key=lambda k: (box[k][1] - box[k][0]) * weights[k])
        lo, hi = box[widest]
        middle = 0.5 * (lo + hi)
        for half in ((lo, middle), (middle, hi)):
            queue.append((*box[:widest], half, *box[widest + 1 :]))
    return PairResult(Verdict.BLOCKED)
