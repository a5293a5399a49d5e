"""Intersections of symmetry groups that need no coset intersection (docs/algebra.md §2.4):
two connected groups, in closed form for TR groups (Liu & Popplestone 1994: the meet
of their characteristic invariants) and otherwise through the Lie algebras plus the
helical discrete residue; and a cyclic lattice <tau> with any group, through the
one-parameter group that carries tau. Groups with finite components meet as cosets of
their connected parts (:func:`assemblykit.algebra.meets.intersect_groups`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from assemblykit.algebra import se3
from assemblykit.algebra.groups import (
    IDENTITY_MATRIX,
    SymmetryGroup,
    classify_algebra,
    lattice_parameter,
    one_parameter,
)
from assemblykit.algebra.lattices import commensurate, lattice_denominator
from assemblykit.algebra.lie import HELICAL_KINDS, Kind, RotationPart, null_space, scaled_twists
from assemblykit.algebra.subspaces import (
    Subspace,
    affine_meet_point,
    parallel,
    subspace_join,
    subspace_meet,
)
from assemblykit.errors import GroupError, NumericError
from assemblykit.tolerance import Tolerance

__all__ = ["connected_meet", "lattice_meet", "tr_meet"]


def tr_meet(a: SymmetryGroup, b: SymmetryGroup, tol: Tolerance) -> SymmetryGroup:
    """Closed-form intersection of two connected TR groups T(V) ⋊ Rot (§2.4, SRC 8 reading).

    The rotation parts meet as linear groups; the centres must agree modulo V_a + V_b
    (otherwise only translations remain, or, for two points, rotations about their line).
    """
    (lin_a, va), (lin_b, vb) = a.tr_shape, b.tr_shape
    v = subspace_meet(va, vb, tol)
    u: NDArray[np.float64] | None = None
    if RotationPart.NONE in (lin_a, lin_b):
        lin = RotationPart.NONE
    elif lin_a is RotationPart.LINE and lin_b is RotationPart.LINE:
        lin = RotationPart.LINE if parallel(a.axis, b.axis, tol) else RotationPart.NONE
        u = a.axis
    elif lin_a is RotationPart.LINE or lin_b is RotationPart.LINE:
        lin, u = RotationPart.LINE, (a.axis if lin_a is RotationPart.LINE else b.axis)
    else:
        lin = RotationPart.POINT
    center = a.origin
    if lin is not RotationPart.NONE:
        w = subspace_join(va, vb, tol)
        delta = a.origin - b.origin
        if lin is RotationPart.LINE:
            assert u is not None
            if w.residual(delta - (delta @ u) * u) > tol.length:
                lin = RotationPart.NONE
            else:
                along = Subspace(1, u)
                center = affine_meet_point(
                    a.origin,
                    subspace_join(va, along, tol),
                    b.origin,
                    subspace_join(vb, along, tol),
                    tol,
                )
        elif w.residual(delta) > tol.length:
            # Two centres with no common translation: rotations about the line joining them.
            lin, u = RotationPart.LINE, se3.unit(-delta)
        else:
            center = affine_meet_point(a.origin, va, b.origin, vb, tol)
    return _tr_group(lin, u, center, v)


def _tr_group(
    lin: RotationPart, u: NDArray[np.float64] | None, center: NDArray[np.float64], v: Subspace
) -> SymmetryGroup:
    """The TR group with rotation part ``lin`` (about ``u`` through ``center``) and V = ``v``."""
    origin = (0.0, 0.0, 0.0)
    if lin is RotationPart.NONE:
        if v.dim == 0:
            return SymmetryGroup.identity()
        if v.dim == 3:
            return SymmetryGroup.translation3()
        assert v.vec is not None
        kind = Kind.PRISMATIC if v.dim == 1 else Kind.TRANSLATION2
        return SymmetryGroup(kind, se3.frame(origin, v.vec))
    if lin is RotationPart.POINT:
        kind = Kind.SPHERICAL if v.dim == 0 else Kind.FREE
        return SymmetryGroup(kind, se3.translation(center))
    assert u is not None
    kind = {0: Kind.REVOLUTE, 1: Kind.CYLINDRICAL, 2: Kind.PLANAR, 3: Kind.SCHOENFLIES}[v.dim]
    return SymmetryGroup(kind, se3.frame(center, u))


def _screw_generator(
    a: SymmetryGroup, b: SymmetryGroup, tol: Tolerance
) -> NDArray[np.float64] | None:
    """The discrete screw of H/Y(p) ∩ H/Y(q) about a common axis, p != q (§2.4 table).

    Solving p theta = q (theta + 2 pi m) gives theta in (2 pi q / (p - q)) Z.
    """
    if (
        a.kind not in HELICAL_KINDS
        or b.kind not in HELICAL_KINDS
        or not parallel(a.axis, b.axis, tol)
    ):
        return None
    if abs(a.pitch - b.pitch) <= tol.length:
        return None
    if b.kind is Kind.HELICAL and a.kind is not Kind.HELICAL:
        a, b = b, a
    if a.kind is Kind.HELICAL and b.kind is Kind.HELICAL:
        delta = b.origin - a.origin
        if se3.norm(delta - (delta @ a.axis) * a.axis) > tol.length:
            return None
    # Pitch is intrinsic (H(N, u, p) = H(N, -u, p)), so the axis signs do not matter.
    q = b.pitch
    theta = math.tau * q / (a.pitch - q)
    params = [theta] if a.kind is Kind.HELICAL else [0.0, 0.0, theta]
    return a.element(params)


def _translation_lattice(
    a: SymmetryGroup, b: SymmetryGroup, tol: Tolerance
) -> list[NDArray[np.float64]]:
    """Generators of the discrete part of (G0a ∩ T3) ∩ (G0b ∩ T3) (§2.4 lattice rows)."""
    (va, ca), (vb, cb) = a.translation_part, b.translation_part
    w = subspace_meet(va, vb, tol)
    constraints = []
    for c in (ca, cb):
        if c is not None:
            proj = w.project(c[0])
            if se3.norm(proj) > tol.angle:
                constraints.append((proj, c[1]))
    if not constraints:
        return []
    if len(constraints) == 1:
        d, period = constraints[0]
        return [period * d / float(d @ d)]
    (da, pa), (db, pb) = constraints
    if not parallel(da, db, tol):
        m = np.vstack((da, db))
        pinv = np.linalg.pinv(m)
        return [pinv @ np.array([pa, 0.0]), pinv @ np.array([0.0, pb])]
    ratio = float(np.linalg.norm(db) / np.linalg.norm(da))
    # t.da in pa Z and t.da in (pb / ratio) Z: the lcm of the two periods, if commensurate.
    frac = commensurate(pa / (pb / ratio), tol)
    if frac is None:
        return []
    period = pa * frac.denominator
    return [period * da / float(da @ da)]


def connected_meet(a: SymmetryGroup, b: SymmetryGroup, tol: Tolerance) -> SymmetryGroup:
    """A0 ∩ B0: closed form for TR groups; otherwise Lie algebra null space plus the
    helical discrete residue, each generator checked numerically (§2.4)."""
    if a.is_tr and b.is_tr:
        return tr_meet(a, b, tol)
    if a.includes(b, tol):
        return b
    if b.includes(a, tol):
        return a
    ka = a.dof
    null = null_space(scaled_twists(np.hstack((a.algebra, -b.algebra)), tol), tol)
    c0 = classify_algebra(a.algebra @ null[:ka], tol)
    screw = _screw_generator(a, b, tol)
    gens = [screw] if screw is not None else []
    if screw is None:
        for step in _translation_lattice(a, b, tol):
            t = se3.translation(step)
            if not c0.contains(t, tol):
                gens.append(t)
    for g in gens:
        if not (a.contains(g, tol) and b.contains(g, tol)):
            raise NumericError(f"lattice element check failed for {a.describe()} ∩ {b.describe()}")
    if not gens:
        return c0
    return SymmetryGroup(c0.kind, c0.frame, c0.pitch, (IDENTITY_MATRIX,), tuple(gens))


def lattice_meet(a: SymmetryGroup, b: SymmetryGroup, tol: Tolerance) -> SymmetryGroup:
    """G ∩ G' when one side is a cyclic lattice <tau> (trivial G0): the sublattice
    <tau^m> inside the other group (§2.4 "Finite parts").

    Closed form when the other group is connected or cyclic: m comes from the rational
    test on the one-parameter group through tau (:func:`_cyclic_meet`). Otherwise the
    first power k = 1..lattice_denominator(tol) with tau^k in the other group generates it.
    """
    if not _is_cyclic(a):
        if _is_cyclic(b):
            return lattice_meet(b, a, tol)
        raise GroupError("intersection of these discrete groups is not supported")
    tau = a.lattice[0]
    if b.is_connected or _is_cyclic(b):
        found = _cyclic_meet(tau, b, tol)
        if found is not None:
            return found
    power = np.eye(4)
    for _ in range(lattice_denominator(tol)):
        power = power @ tau
        if b.contains(power, tol):
            return SymmetryGroup(Kind.FIXED, np.eye(4), 0.0, (IDENTITY_MATRIX,), (power,))
    return SymmetryGroup.identity()


def _is_cyclic(g: SymmetryGroup) -> bool:
    """Whether G = <tau> is an infinite cyclic group (one lattice generator, trivial G0)."""
    return g.kind is Kind.FIXED and len(g.reps) == 1 and len(g.lattice) == 1


def _cyclic_meet(
    tau: NDArray[np.float64], b: SymmetryGroup, tol: Tolerance
) -> SymmetryGroup | None:
    """<tau> ∩ B in closed form: with L the one-parameter group through tau, L ∩ B is L
    (every power), {I} (none but I) or <exp(c log tau)>, and tau^k is in B iff k is in
    cZ; for c = r/n in lowest terms that is rZ (the lcm rule of §2.4), and an
    incommensurate c leaves only I (§7). ``None`` when no closed form applies."""
    line = one_parameter(tau, tol)
    if line is None:
        return None
    met = connected_meet(b, line, tol) if b.is_connected else lattice_meet(b, line, tol)
    if met.dof > 0:
        return SymmetryGroup(Kind.FIXED, np.eye(4), 0.0, (IDENTITY_MATRIX,), (tau,))
    if not met.lattice:
        return SymmetryGroup.identity()
    frac = commensurate(lattice_parameter(line, tau, met.lattice[0]), tol)
    if frac is None:
        return SymmetryGroup.identity()
    power = np.linalg.matrix_power(tau, abs(frac.numerator))
    if not b.contains(power, tol):
        return None
    return SymmetryGroup(Kind.FIXED, np.eye(4), 0.0, (IDENTITY_MATRIX,), (power,))
