"""Hervé's 12 families of connected subgroups of SE(3) and their Lie algebras
(Hervé 1999; docs/algebra.md §2.1, §2.3).

Each family is a canonical group K (axis or normal +z through the origin) with its Lie
algebra basis, its elements k(params) and its membership predicate; a connected group
is F K F^-1 for a frame F. :func:`classify_subalgebra` names the family and frame of
the connected group whose Lie algebra a basis of twists spans (§2.1 steps 1-5).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum

import numpy as np
from numpy.typing import NDArray

from assemblykit.algebra import se3
from assemblykit.errors import GroupError, NumericError
from assemblykit.tolerance import Tolerance

__all__ = [
    "DIMENSION",
    "HELICAL_KINDS",
    "ROTATIONS",
    "Kind",
    "Placement",
    "RotationPart",
    "canonical_basis",
    "canonical_element",
    "classify_subalgebra",
    "helix_residual",
    "in_canonical",
    "null_space",
    "rank_threshold",
    "scaled_twists",
]


class Kind(StrEnum):
    """Hervé's 12 families of connected subgroups of SE(3) (docs/algebra.md §2.1)."""

    FIXED = "fixed"
    REVOLUTE = "revolute"
    PRISMATIC = "prismatic"
    HELICAL = "helical"
    CYLINDRICAL = "cylindrical"
    TRANSLATION2 = "translation2"
    TRANSLATION3 = "translation3"
    SPHERICAL = "spherical"
    PLANAR = "planar"
    PSEUDO_PLANAR = "pseudo-planar"
    SCHOENFLIES = "schoenflies"
    FREE = "free"

    def __str__(self) -> str:
        return self.value


#: The dimension of each family (Hervé dimension, the dof of its groups).
DIMENSION = {
    Kind.FIXED: 0,
    Kind.REVOLUTE: 1,
    Kind.PRISMATIC: 1,
    Kind.HELICAL: 1,
    Kind.CYLINDRICAL: 2,
    Kind.TRANSLATION2: 2,
    Kind.TRANSLATION3: 3,
    Kind.SPHERICAL: 3,
    Kind.PLANAR: 3,
    Kind.PSEUDO_PLANAR: 3,
    Kind.SCHOENFLIES: 4,
    Kind.FREE: 6,
}
#: The families whose elements screw (a non-zero pitch couples rotation and translation).
HELICAL_KINDS = frozenset({Kind.HELICAL, Kind.PSEUDO_PLANAR})


class RotationPart(StrEnum):
    """The rotations of a TR group (docs/algebra.md §2.4 characteristic-invariant view): none,
    about lines of one direction, or about a point."""

    NONE = "none"
    LINE = "line"
    POINT = "point"


#: The rotation part of each family (helical families count as rotating about a line).
ROTATIONS = {
    Kind.FIXED: RotationPart.NONE,
    Kind.PRISMATIC: RotationPart.NONE,
    Kind.TRANSLATION2: RotationPart.NONE,
    Kind.TRANSLATION3: RotationPart.NONE,
    Kind.REVOLUTE: RotationPart.LINE,
    Kind.CYLINDRICAL: RotationPart.LINE,
    Kind.PLANAR: RotationPart.LINE,
    Kind.SCHOENFLIES: RotationPart.LINE,
    Kind.HELICAL: RotationPart.LINE,
    Kind.PSEUDO_PLANAR: RotationPart.LINE,
    Kind.SPHERICAL: RotationPart.POINT,
    Kind.FREE: RotationPart.POINT,
}


# ----------------------------------------------------------------------------- canonical K


def canonical_basis(kind: Kind, pitch: float) -> NDArray[np.float64]:
    """The canonical Lie algebra basis (6 x dim, (omega; v)) of K (docs/algebra.md §2.1 table)."""
    e = np.eye(6)
    rz, tx, ty, tz = e[:, 2], e[:, 3], e[:, 4], e[:, 5]
    sz = rz + pitch * tz
    cols: dict[Kind, list[NDArray[np.float64]]] = {
        Kind.FIXED: [],
        Kind.REVOLUTE: [rz],
        Kind.PRISMATIC: [tz],
        Kind.HELICAL: [sz],
        Kind.CYLINDRICAL: [rz, tz],
        Kind.TRANSLATION2: [tx, ty],
        Kind.TRANSLATION3: [tx, ty, tz],
        Kind.SPHERICAL: [e[:, 0], e[:, 1], rz],
        Kind.PLANAR: [rz, tx, ty],
        Kind.PSEUDO_PLANAR: [sz, tx, ty],
        Kind.SCHOENFLIES: [rz, tx, ty, tz],
        Kind.FREE: list(e.T),
    }
    return np.column_stack(cols[kind]) if cols[kind] else np.zeros((6, 0))


def canonical_element(kind: Kind, pitch: float, params: NDArray[np.float64]) -> NDArray[np.float64]:
    """k(params) of the canonical family (docs/algebra.md §5.1 normal form).

    Parameters: R, H (theta); T (s); C (theta, s); T2 (a, b); T3 (a, b, c);
    S (rotation vector); G, Y (a, b, theta); X (a, b, c, theta); D (tx, ty, tz, rotvec).
    """
    p = [float(x) for x in params]
    if len(p) != DIMENSION[kind]:
        raise GroupError(f"a {kind.value} group takes {DIMENSION[kind]} parameters, got {len(p)}")
    z = (0.0, 0.0, 1.0)
    if kind is Kind.FIXED:
        return np.eye(4)
    if kind is Kind.REVOLUTE:
        return se3.rot_z(p[0])
    if kind is Kind.PRISMATIC:
        return se3.translation((0.0, 0.0, p[0]))
    if kind is Kind.HELICAL:
        return se3.screw((0.0, 0.0, 0.0), z, pitch, p[0])
    if kind is Kind.CYLINDRICAL:
        return se3.rot_z(p[0]) @ se3.translation((0.0, 0.0, p[1]))
    if kind is Kind.TRANSLATION2:
        return se3.translation((p[0], p[1], 0.0))
    if kind is Kind.TRANSLATION3:
        return se3.translation(p)
    if kind is Kind.SPHERICAL:
        out = np.eye(4)
        out[:3, :3] = se3.rotation_matrix(p)
        return out
    if kind is Kind.PLANAR:
        return se3.translation((p[0], p[1], 0.0)) @ se3.rot_z(p[2])
    if kind is Kind.PSEUDO_PLANAR:
        return se3.translation((p[0], p[1], 0.0)) @ se3.screw((0.0, 0.0, 0.0), z, pitch, p[2])
    if kind is Kind.SCHOENFLIES:
        return se3.translation(p[:3]) @ se3.rot_z(p[3])
    out = se3.translation(p[:3])
    out[:3, :3] = se3.rotation_matrix(p[3:])
    return out


def helix_residual(pitch: float, tz: float, theta: float) -> float:
    """Length by which (theta, tz) misses the helix t_z = p (theta + 2 pi k) (§2.3)."""
    if pitch == 0.0:
        return abs(tz)
    d = tz / pitch - theta
    d -= math.tau * round(d / math.tau)
    return abs(pitch * d)


def in_canonical(kind: Kind, pitch: float, g: NDArray[np.float64], tol: Tolerance) -> bool:
    """Membership of a canonical-frame element in K (docs/algebra.md §2.3 predicate table)."""
    if kind is Kind.FREE:
        return True
    r, t = g[:3, :3], g[:3, 3]
    ang, length = tol.angle, tol.length
    if kind is Kind.SPHERICAL:
        return se3.norm(t) <= length
    if ROTATIONS[kind] is RotationPart.NONE:
        if float(np.max(np.abs(r - np.eye(3)))) > ang:
            return False
        if kind is Kind.FIXED:
            return se3.norm(t) <= length
        if kind is Kind.PRISMATIC:
            return math.hypot(t[0], t[1]) <= length
        if kind is Kind.TRANSLATION2:
            return abs(float(t[2])) <= length
        return True
    # Rotation about z (R, H, C, G, Y, X): "R ∥ z".
    if math.sqrt(r[0, 2] ** 2 + r[1, 2] ** 2 + (r[2, 2] - 1.0) ** 2) > ang:
        return False
    if kind is Kind.SCHOENFLIES:
        return True
    theta = math.atan2(r[1, 0], r[0, 0])
    if kind is Kind.PLANAR:
        return abs(float(t[2])) <= length
    if kind is Kind.PSEUDO_PLANAR:
        return helix_residual(pitch, t[2], theta) <= length
    if math.hypot(t[0], t[1]) > length:
        return False
    if kind is Kind.REVOLUTE:
        return abs(float(t[2])) <= length
    if kind is Kind.HELICAL:
        return helix_residual(pitch, t[2], theta) <= length
    return True


# ----------------------------------------------------------------------------- twists


def scaled_twists(basis: NDArray[np.float64], tol: Tolerance) -> NDArray[np.float64]:
    """Twists with the v rows in units of the model scale (angles and lengths comparable)."""
    out = np.array(basis, dtype=np.float64)
    out[3:] /= tol.scale
    return out


def rank_threshold(tol: Tolerance) -> float:
    """The singular value below which scaled twists count as dependent."""
    return max(tol.angle, tol.rel_length)


def null_space(m: NDArray[np.float64], tol: Tolerance) -> NDArray[np.float64]:
    """An orthonormal basis (columns) of the null space of ``m`` under :func:`rank_threshold`."""
    _, s, vt = np.linalg.svd(m)
    rank = int(np.sum(s > rank_threshold(tol)))
    return vt[rank:].T


@dataclass(frozen=True, eq=False)
class Placement:
    """The connected group F K(kind, pitch) F^-1 by its family, frame F and pitch."""

    kind: Kind
    frame: NDArray[np.float64]
    pitch: float = 0.0


_ORIGIN = np.zeros(3)


def classify_subalgebra(basis: NDArray[np.float64], tol: Tolerance) -> Placement:
    """The family and frame of the connected group whose Lie algebra is spanned by
    ``basis`` (6 x k), docs/algebra.md §2.1 steps 1-5 (Hervé 1999)."""
    if basis.shape[1] == 0:
        return Placement(Kind.FIXED, np.eye(4))
    thr = rank_threshold(tol)
    q, _ = np.linalg.qr(scaled_twists(basis, tol))
    q[3:] *= tol.scale
    _, s, vt = np.linalg.svd(q[:3])
    r_w = int(np.sum(s > thr))
    trans = q[3:] @ vt[r_w:].T if r_w < q.shape[1] else np.zeros((3, 0))
    tq = np.linalg.qr(trans)[0] if trans.shape[1] else trans
    r_t = tq.shape[1]
    if r_w == 0:
        if r_t == 3:
            return Placement(Kind.TRANSLATION3, np.eye(4))
        if r_t == 1:
            return Placement(Kind.PRISMATIC, se3.frame(_ORIGIN, tq[:, 0]))
        return Placement(Kind.TRANSLATION2, se3.frame(_ORIGIN, se3.cross(tq[:, 0], tq[:, 1])))
    if r_w == 1:
        xi = q @ vt[0]
        w = xi[:3]
        xi = xi / se3.norm(w)
        u, vel = xi[:3], xi[3:]
        vel = vel - tq @ (tq.T @ vel)
        pitch = float(u @ vel)
        foot = se3.cross(u, vel)
        f = se3.frame(foot, u)
        helical = abs(pitch) > tol.length
        if r_t == 0:
            return Placement(Kind.HELICAL, f, pitch) if helical else Placement(Kind.REVOLUTE, f)
        if r_t == 1:
            return Placement(Kind.CYLINDRICAL, f)
        if r_t == 2:
            planar = se3.frame(_ORIGIN, u)
            if helical:
                return Placement(Kind.PSEUDO_PLANAR, planar, pitch)
            return Placement(Kind.PLANAR, planar)
        return Placement(Kind.SCHOENFLIES, se3.frame(_ORIGIN, u))
    if r_w == 3 and r_t == 3:
        return Placement(Kind.FREE, np.eye(4))
    if r_w == 3 and r_t == 0:
        rows = np.vstack([-se3.skew(q[:3, i]) for i in range(3)])
        center, *_ = np.linalg.lstsq(rows, q[3:].T.reshape(-1), rcond=None)
        return Placement(Kind.SPHERICAL, se3.translation(center))
    raise NumericError(f"not a subalgebra of se(3): rotation rank {r_w}, translation rank {r_t}")
