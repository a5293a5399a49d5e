"""Rigid transforms of SE(3) and twists of se(3) (ALGEBRA.md §1).

Transforms are 4x4 float64 homogeneous matrices acting on column vectors
(``p_world = T @ p_body``). Twists are 6-vectors ordered ``(omega; v)`` where ``v`` is
the velocity of the point currently at the origin.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

from assemblykit.tolerance import Tolerance, current

#: Below this rotation angle the left Jacobian uses its Taylor series (cancellation otherwise).
_SERIES_SWITCH = 1e-8

__all__ = [
    "adjoint",
    "apply",
    "apply_direction",
    "cross",
    "exp",
    "frame",
    "hat",
    "identity",
    "inverse",
    "is_rigid",
    "log",
    "norm",
    "random_transform",
    "rot_x",
    "rot_y",
    "rot_z",
    "rotation",
    "rotation_angle",
    "screw",
    "skew",
    "translation",
    "unit",
    "vee",
]


def identity() -> np.ndarray:
    """The identity transform."""
    return np.eye(4)


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The cross product of two 3-vectors (plain arithmetic: ``np.cross`` is slow on 3-vectors)."""
    a0, a1, a2 = float(a[0]), float(a[1]), float(a[2])
    b0, b1, b2 = float(b[0]), float(b[1]), float(b[2])
    return np.array((a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0))


def norm(v: np.ndarray) -> float:
    """The Euclidean length of a vector."""
    return math.sqrt(float(v @ v))


def unit(v: np.ndarray | tuple[float, ...] | list[float]) -> np.ndarray:
    """``v`` scaled to unit length (float64); a zero vector is returned unchanged."""
    a = np.asarray(v, dtype=np.float64)
    n = math.sqrt(float(a @ a))
    return a / n if n > 0.0 else a.copy()


def skew(w: np.ndarray) -> np.ndarray:
    """The 3x3 matrix ``[w]x`` with ``[w]x @ x == cross(w, x)``."""
    x, y, z = (float(c) for c in w)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def _compose(r: np.ndarray, t: np.ndarray) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = r
    out[:3, 3] = t
    return out


def translation(v: np.ndarray | tuple[float, ...] | list[float]) -> np.ndarray:
    """The pure translation ``Tr(v)``."""
    out = np.eye(4)
    out[:3, 3] = np.asarray(v, dtype=np.float64)
    return out


def _axis_rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' formula for a unit ``axis``: exact at multiples of pi/2 for coordinate axes."""
    k = skew(axis)
    s, c = math.sin(angle), math.cos(angle)
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


def rotation(
    axis: np.ndarray | tuple[float, ...] | list[float],
    angle: float,
    point: np.ndarray | tuple[float, ...] | list[float] | None = None,
) -> np.ndarray:
    """Rotation by ``angle`` (right-handed) about the line through ``point`` along ``axis``."""
    r = _axis_rotation(unit(axis), angle)
    if point is None:
        return _compose(r, np.zeros(3))
    p = np.asarray(point, dtype=np.float64)
    return _compose(r, p - r @ p)


def rot_x(angle: float) -> np.ndarray:
    """``Rx(angle)`` about the x-axis through the origin."""
    return rotation((1.0, 0.0, 0.0), angle)


def rot_y(angle: float) -> np.ndarray:
    """``Ry(angle)`` about the y-axis through the origin."""
    return rotation((0.0, 1.0, 0.0), angle)


def rot_z(angle: float) -> np.ndarray:
    """``Rz(angle)`` about the z-axis through the origin."""
    return rotation((0.0, 0.0, 1.0), angle)


def screw(
    point: np.ndarray | tuple[float, ...] | list[float],
    axis: np.ndarray | tuple[float, ...] | list[float],
    pitch: float,
    angle: float,
) -> np.ndarray:
    """The screw motion ``Tr(pitch*angle*u) . Rot_L(angle)`` about the line L = (point, axis).

    ALGEBRA.md §1: ``Scr(theta; p) = Tr(0, 0, p theta) Rz(theta)`` placed on L.
    """
    u = unit(axis)
    out = rotation(u, angle, point)
    out[:3, 3] += pitch * angle * u
    return out


def inverse(t: np.ndarray) -> np.ndarray:
    """The inverse of a rigid transform (transpose of the rotation, no general inversion)."""
    r = t[:3, :3]
    return _compose(r.T, -(r.T @ t[:3, 3]))


def frame(
    origin: np.ndarray | tuple[float, ...] | list[float],
    z_axis: np.ndarray | tuple[float, ...] | list[float],
    x_hint: np.ndarray | tuple[float, ...] | list[float] | None = None,
) -> np.ndarray:
    """A right-handed frame at ``origin`` whose +z is ``z_axis``.

    The x axis is ``x_hint`` made perpendicular to z; without a usable hint it is the
    coordinate axis least aligned with z, made perpendicular (a deterministic choice).
    """
    z = unit(z_axis)
    x = None
    if x_hint is not None:
        h = np.asarray(x_hint, dtype=np.float64)
        h = h - (h @ z) * z
        if float(h @ h) > 0.0:
            x = unit(h)
    if x is None:
        e = np.zeros(3)
        e[int(np.argmin(np.abs(z)))] = 1.0
        x = unit(e - (e @ z) * z)
    y = cross(z, x)
    return _compose(np.column_stack((x, y, z)), np.asarray(origin, dtype=np.float64))


def apply(t: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Points (shape (3,) or (n, 3)) mapped by ``t``."""
    p = np.asarray(points, dtype=np.float64)
    return p @ t[:3, :3].T + t[:3, 3]


def apply_direction(t: np.ndarray, dirs: np.ndarray) -> np.ndarray:
    """Free vectors (shape (3,) or (n, 3)) rotated by ``t`` (translation ignored)."""
    return np.asarray(dirs, dtype=np.float64) @ t[:3, :3].T


def hat(xi: np.ndarray) -> np.ndarray:
    """The 4x4 matrix of the twist ``(omega; v)``: ``[[omega]x, v; 0, 0]``."""
    out = np.zeros((4, 4))
    out[:3, :3] = skew(xi[:3])
    out[:3, 3] = xi[3:]
    return out


def vee(m: np.ndarray) -> np.ndarray:
    """The twist ``(omega; v)`` of a 4x4 matrix of se(3) (inverse of :func:`hat`)."""
    return np.array([m[2, 1], m[0, 2], m[1, 0], m[0, 3], m[1, 3], m[2, 3]], dtype=np.float64)


def _left_jacobian(w: np.ndarray, theta: float) -> np.ndarray:
    """``V`` with ``exp(hat(w, v)) = (exp(w), V v)`` (closed form, ALGEBRA.md §1)."""
    k = skew(w)
    if theta < _SERIES_SWITCH:
        # Taylor terms beyond second order are below float64 resolution here.
        return np.eye(3) + 0.5 * k + (k @ k) / 6.0
    a = (1.0 - math.cos(theta)) / theta**2
    b = (theta - math.sin(theta)) / theta**3
    return np.eye(3) + a * k + b * (k @ k)


def exp(xi: np.ndarray) -> np.ndarray:
    """The exponential of the twist ``xi = (omega; v)`` in closed form."""
    xi = np.asarray(xi, dtype=np.float64)
    w, v = xi[:3], xi[3:]
    theta = math.sqrt(float(w @ w))
    r = Rotation.from_rotvec(w).as_matrix()
    return _compose(r, _left_jacobian(w, theta) @ v)


def log(t: np.ndarray) -> np.ndarray:
    """A twist ``xi`` with ``exp(xi) == t`` and rotation angle in [0, pi].

    The logarithm is multivalued (at angle pi and by 2 pi periodicity); it is used for
    parameterisation and residuals, never to decide membership (ALGEBRA.md §2.3).
    """
    w = Rotation.from_matrix(t[:3, :3]).as_rotvec()
    theta = math.sqrt(float(w @ w))
    v = np.linalg.solve(_left_jacobian(w, theta), t[:3, 3])
    return np.concatenate((w, v))


def adjoint(t: np.ndarray) -> np.ndarray:
    """The 6x6 adjoint: ``Ad_T (omega; v) = (R omega; R v + t x R omega)``."""
    r, p = t[:3, :3], t[:3, 3]
    out = np.zeros((6, 6))
    out[:3, :3] = r
    out[3:, 3:] = r
    out[3:, :3] = skew(p) @ r
    return out


def rotation_angle(t: np.ndarray) -> float:
    """The rotation angle of ``t`` in [0, pi] (robust near 0 and pi)."""
    return float(np.linalg.norm(Rotation.from_matrix(t[:3, :3]).as_rotvec()))


def is_rigid(t: np.ndarray, tol: Tolerance | None = None) -> bool:
    """Whether ``t`` is a proper rigid transform within the angular tolerance."""
    tol = tol or current()
    a = np.asarray(t, dtype=np.float64)
    if a.shape != (4, 4) or not np.all(np.isfinite(a)):
        return False
    r = a[:3, :3]
    ortho = float(np.max(np.abs(r.T @ r - np.eye(3))))
    bottom = float(np.max(np.abs(a[3] - (0.0, 0.0, 0.0, 1.0))))
    return ortho <= tol.angle and bottom <= tol.angle and float(np.linalg.det(r)) > 0.0


def random_transform(rng: np.random.Generator, scale: float = 10.0) -> np.ndarray:
    """A random rigid transform: uniform rotation and translation in ``[-scale, scale]^3``."""
    r = Rotation.random(random_state=rng).as_matrix()
    return _compose(r, rng.uniform(-scale, scale, 3))
