"""Joints that several higher pairs between the same two instances make together
(docs/inference.md, "Joints made by several contacts"; docs/algebra.md §2.4, §3).

One point held in a plane or a line is not a coset (docs/algebra.md §3), but several
points of one body held in loci of one other body can be: their poses are then the
transporter of the body's points onto the loci, a coset of the loci's stabiliser
(Liu & Popplestone 1990, §3: a relative location is a coset of the symmetry group of the
features in contact). Two patterns are met in closed form here:

* **points on one line** ℓ (``point_on_line``, two planes meeting in ℓ, or a cylinder
  lying on two planes, whose axis points lie on the line where the offset planes meet):
  the body's points must lie on one line of the body, and every pose carries that line
  onto ℓ, either way round: the coset of C(ℓ)⋊{I, flip} (``cylindrical``, two
  components), the flip a half-turn about a line across ℓ;
* **points on parallel planes** (``point_on_plane``, ``distance`` to a plane), at least
  three not on one line: the body direction m that the poses carry onto the planes'
  normal n is fixed by the points' heights up to the choice of side (m·cᵢ + k = hᵢ,
  |m| = 1). Equal heights give m = ±e (e normal to the points' plane): the coset of
  G(n)⋊{I, flip} (``planar``, two components); a single m (the points off one plane, or
  a slope of exactly 1) the coset G(n) (``planar``). Two other choices of m are two
  cosets that make no single one: left to the other rules.

The representative is the pose of least motion from the pose as written: the least
rotation (about the body's origin) that turns the body's line or direction onto the
locus, then the shortest translation that puts the points on it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from assemblykit.algebra import Coset, Mismatch, MismatchKind, SymmetryGroup, se3
from assemblykit.tolerance import ModelTolerance

Vector = NDArray[np.float64]


@dataclass(frozen=True)
class PointHold:
    """One point of the held body (``point``, its body frame) and the locus it is held in
    (``rows @ (y - origin) = 0`` in the locus body's frame, orthonormal ``rows``: one for
    a plane, two for a line)."""

    point: Vector
    origin: Vector
    rows: Vector


@dataclass(frozen=True)
class Layout:
    """The shape of a set of body points: their centroid, the unit principal directions
    (largest spread first, a right-handed frame) and how far the points lie off their best
    line and off their best plane (model units)."""

    centroid: Vector
    axes: Vector
    off_line: float
    off_plane: float


def layout(points: Vector) -> Layout:
    """The principal directions of ``points`` (rows) about their centroid."""
    centroid = points.mean(axis=0)
    spread = points - centroid
    axes = np.linalg.svd(spread, full_matrices=True)[2]
    if np.linalg.det(axes) < 0:
        axes[2] = -axes[2]
    line = spread - np.outer(spread @ axes[0], axes[0])
    off_line = float(np.linalg.norm(line, axis=1).max())
    off_plane = float(np.abs(spread @ axes[2]).max())
    return Layout(centroid, axes, off_line, off_plane)


def least_rotation(start: Vector, end: Vector) -> Vector:
    """The rotation matrix of least angle turning the unit ``start`` onto the unit ``end``
    (about their common normal; a half-turn about a perpendicular when they are opposite)."""
    axis = np.cross(start, end)
    sine = float(np.linalg.norm(axis))
    cosine = float(start @ end)
    if sine <= 1e-15:
        if cosine > 0:
            return np.eye(3)
        return se3.rotation(se3.axis_basis(start)[0], math.pi)[:3, :3]
    return se3.rotation(axis / sine, math.atan2(sine, cosine))[:3, :3]


def _pose(rotation: Vector, translation: Vector) -> Vector:
    pose = np.eye(4)
    pose[:3, :3] = rotation
    pose[:3, 3] = translation
    return pose


def _line_of(held: PointHold) -> tuple[Vector, Vector]:
    """The point nearest the origin and the unit direction of a line locus."""
    direction = np.cross(held.rows[0], held.rows[1])
    direction = direction / np.linalg.norm(direction) + 0.0
    foot = held.origin - (held.origin @ direction) * direction
    return foot, direction


def line_joint(held: Sequence[PointHold], tol: ModelTolerance) -> Coset | Mismatch | None:
    """Points held on one line ℓ (module docstring): the coset of C(ℓ)⋊{I, flip} at the
    pose of least motion, or a ``distance`` mismatch when the body's points are not on one
    line (how far off their best line); None when the loci are not one line."""
    if len(held) < 2 or any(len(h.rows) != 2 for h in held):
        return None
    origin, direction = _line_of(held[0])
    for h in held[1:]:
        foot, other = _line_of(h)
        offset = foot - origin
        if (
            np.linalg.norm(np.cross(direction, other)) > tol.angle
            or np.linalg.norm(offset - (offset @ direction) * direction) > tol.length
        ):
            return None
    shape = layout(np.array([h.point for h in held]))
    if shape.off_line > tol.length:
        return Mismatch(
            MismatchKind.DISTANCE,
            shape.off_line,
            "the points held on one line are not on one line of their body (one lies"
            f" {shape.off_line:.6g} off it)",
        )
    along = shape.axes[0]
    target = direction if along @ direction >= 0 else -direction
    turn = least_rotation(along, target)
    moved = turn @ held[0].point
    offset = moved - origin
    foot = origin + (offset @ direction) * direction
    flip = se3.rotation(se3.axis_basis(direction)[0], math.pi, foot)
    group = SymmetryGroup.cylindrical(foot, direction).with_known_discrete((flip,), (), tol)
    return Coset(group, _pose(turn, foot - moved))


def _normal_of(held: Sequence[PointHold], tol: ModelTolerance) -> tuple[Vector, Vector] | None:
    """The common unit normal of plane loci and each plane's height along it, or None
    when some locus is no plane or the planes are not parallel."""
    if any(len(h.rows) != 1 for h in held):
        return None
    normal = held[0].rows[0]
    if any(np.linalg.norm(np.cross(normal, h.rows[0])) > tol.angle for h in held[1:]):
        return None
    return normal, np.array([normal @ h.origin for h in held])


def _short(gap: float, spread: float, slope: float) -> Mismatch:
    return Mismatch(
        MismatchKind.DISTANCE,
        gap,
        f"the points span at most {spread:.6g} across the planes, which need"
        f" {slope * spread:.6g}: {gap:.6g} short",
    )


def _directions(
    points: Vector, heights: Vector, shape: Layout, tol: ModelTolerance
) -> tuple[tuple[Vector, ...], bool] | Mismatch:
    """The unit body directions m with m·cᵢ + k = hᵢ for all points (for some k), and
    whether they are the two sides ±e of the points' plane (equal heights): one or two
    (the points on one plane of the body), or the mismatch when there is none. Heights
    are matched within the length tolerance over the points' reach."""
    spread = points - shape.centroid
    rise = heights - heights.mean()
    flat = shape.off_plane <= tol.length
    basis = shape.axes[:2] if flat else shape.axes
    coords = spread @ basis.T
    slope = np.linalg.lstsq(coords, rise, rcond=None)[0]
    miss = float(np.abs(coords @ slope - rise).max())
    if miss > tol.length:
        return Mismatch(
            MismatchKind.DISTANCE,
            miss,
            f"the points cannot all reach their planes: one misses by {miss:.6g}",
        )
    gradient = slope @ basis
    size = float(np.linalg.norm(gradient))
    normal = shape.axes[2]
    unit = gradient / size if size > 0 else normal
    reach = float(np.ptp(spread @ unit))
    if flat and size * reach <= tol.length:
        return (normal, -normal), True
    gap = (size - 1.0) * reach
    if gap > tol.length:
        return _short(gap, reach, size)
    if not flat:
        if -gap > tol.length:
            return _tilt(-gap)
        return (unit,), False
    lift = math.sqrt(max(0.0, 1.0 - size * size))
    if lift * reach <= tol.length:
        return (unit,), False
    return (gradient + lift * normal, gradient - lift * normal), False


def _tilt(gap: float) -> Mismatch:
    return Mismatch(
        MismatchKind.DISTANCE,
        gap,
        f"the points cannot all reach their planes: they miss by {gap:.6g} at the best tilt",
    )


def _along_line(
    points: Vector, heights: Vector, shape: Layout, tol: ModelTolerance
) -> Mismatch | None:
    """Points of one body line held on parallel planes: the line must rise between them
    as their planes do, at a slope of at most 1 (the line along the normal). The mismatch
    by which they cannot, else None (the poses then make no coset: 4 dof)."""
    along = (points - shape.centroid) @ shape.axes[0]
    rise = heights - heights.mean()
    slope = float(along @ rise / (along @ along))
    miss = float(np.abs(slope * along - rise).max())
    if miss > tol.length:
        return Mismatch(
            MismatchKind.DISTANCE,
            miss,
            f"the points cannot all reach their planes: one misses by {miss:.6g}",
        )
    reach = float(np.ptp(along))
    gap = (abs(slope) - 1.0) * reach
    return _short(gap, reach, abs(slope)) if gap > tol.length else None


def plane_joint(held: Sequence[PointHold], tol: ModelTolerance) -> Coset | Mismatch | None:
    """Points held on parallel planes, at least three not on one line (module docstring):
    the coset of G(n) (or G(n)⋊{I, flip} when the points lie on one plane at one height)
    at the pose of least motion, or the ``distance`` mismatch by which the points miss
    their planes (points on one line too: :func:`_along_line`); None for other loci,
    points on one line that reach their planes, or two choices of side that make two
    cosets."""
    found = _normal_of(held, tol) if len(held) >= 2 else None
    if found is None:
        return None
    normal, heights = found
    points = np.array([h.point for h in held])
    shape = layout(points)
    if shape.off_line <= tol.length:
        return _along_line(points, heights, shape, tol)
    found_sides = _directions(points, heights, shape, tol)
    if isinstance(found_sides, Mismatch):
        return found_sides
    choices, flipped = found_sides
    if len(choices) == 2 and not flipped:
        return None
    best = max(choices, key=lambda m: float(m @ normal))
    turn = least_rotation(best, normal)
    lift = float(np.mean(heights - points @ turn.T @ normal))
    translation = lift * normal
    group = SymmetryGroup.planar(normal)
    if flipped:
        level = float(normal @ (turn @ shape.centroid + translation))
        flip = se3.rotation(se3.axis_basis(normal)[0], math.pi, level * normal)
        group = group.with_known_discrete((flip,), (), tol)
    return Coset(group, _pose(turn, translation))
