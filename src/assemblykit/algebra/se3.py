"""Rigid transforms of SE(3) and twists of se(3) (docs/algebra.md §1).

Transforms are 4x4 float64 homogeneous matrices acting on column vectors
(``p_world = T @ p_body``). Twists are 6-vectors ordered ``(omega; v)`` where ``v`` is
the velocity of the point currently at the origin.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from assemblykit.tolerance import Tolerance, current

#: Below this rotation angle the left Jacobian uses its Taylor series (cancellation otherwise).
_SERIES_SWITCH = 1e-8

__all__ = [
    "adjoint",
    "apply",
    "apply_direction",
    "as_floats",
    "axis_basis",
    "cross",
    "exp",
    "frame",
    "frame_from_floats",
    "hat",
    "identity",
    "inverse",
    "is_rigid",
    "log",
    "matrix_from_columns",
    "multistart_least_squares",
    "norm",
    "poses_equal",
    "random_starts",
    "random_transform",
    "rot_x",
    "rot_y",
    "rot_z",
    "rotation",
    "rotation_angle",
    "rotation_matrix",
    "rotation_vector",
    "screw",
    "skew",
    "translation",
    "unit",
    "vee",
]


def identity() -> NDArray[np.float64]:
    """The identity transform."""
    return np.eye(4)


def cross(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """The cross product of two 3-vectors (plain arithmetic: ``np.cross`` is slow on 3-vectors)."""
    a0, a1, a2 = as_floats(a)
    b0, b1, b2 = as_floats(b)
    return np.array((a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0))


def norm(v: NDArray[np.float64]) -> float:
    """The Euclidean length of a vector."""
    return math.sqrt(float(v @ v))


def unit(v: NDArray[np.float64] | tuple[float, ...] | list[float]) -> NDArray[np.float64]:
    """``v`` scaled to unit length (float64); a zero vector is returned unchanged."""
    a = np.asarray(v, dtype=np.float64)
    n = math.sqrt(float(a @ a))
    return a / n if n > 0.0 else a.copy()


def line_classes(
    vectors: NDArray[np.float64], max_sine: float
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int8]]:
    """Group unit vectors that are parallel or antiparallel: each joins the first earlier
    leader whose sine with it is at most ``max_sine``, else leads a new class. Returns
    the leaders, the class of each vector and its orientation (+1 same, -1 opposite)."""
    units = np.asarray(vectors, dtype=np.float64).reshape(-1, 3)
    # leader by leader: the next leader is the first later vector none of the earlier
    # ones takes; each vector keeps the first nearest of the leaders before it
    x, y, z = units.T.copy()
    best = np.full(len(units), np.inf)
    index = np.zeros(len(units), dtype=np.int64)
    leads: list[int] = []
    i = 0
    while i < len(units):
        leads.append(i)
        a, b, c, tail = x[i], y[i], z[i], slice(i + 1, None)
        turn = (b * z[tail] - c * y[tail], c * x[tail] - a * z[tail], a * y[tail] - b * x[tail])
        sines = np.sqrt(turn[0] * turn[0] + turn[1] * turn[1] + turn[2] * turn[2])
        nearer = np.flatnonzero(sines < best[i + 1 :]) + i + 1
        best[nearer] = sines[nearer - i - 1]
        index[nearer] = len(leads) - 1
        apart = np.flatnonzero(best[i + 1 :] > max_sine)
        i = i + 1 + int(apart[0]) if len(apart) else len(units)
    leaders = units[leads]
    index[leads] = np.arange(len(leads))
    orient = np.where(np.einsum("ij,ij->i", leaders[index], units) > 0, 1, -1).astype(np.int8)
    orient[leads] = 1
    return leaders.reshape(-1, 3), index, orient


def skew(w: NDArray[np.float64]) -> NDArray[np.float64]:
    """The 3x3 matrix ``[w]x`` with ``[w]x @ x == cross(w, x)``."""
    x, y, z = (float(c) for c in w)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def _compose(r: NDArray[np.float64], t: NDArray[np.float64]) -> NDArray[np.float64]:
    out = np.eye(4)
    out[:3, :3] = r
    out[:3, 3] = t
    return out


def translation(v: NDArray[np.float64] | tuple[float, ...] | list[float]) -> NDArray[np.float64]:
    """The pure translation ``Tr(v)``."""
    out = np.eye(4)
    out[:3, 3] = np.asarray(v, dtype=np.float64)
    return out


def _axis_rotation(axis: NDArray[np.float64], angle: float) -> NDArray[np.float64]:
    """Rodrigues' formula for a unit ``axis``: exact at multiples of pi/2 for coordinate axes."""
    k = skew(axis)
    s, c = math.sin(angle), math.cos(angle)
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


def rotation(
    axis: NDArray[np.float64] | tuple[float, ...] | list[float],
    angle: float,
    point: NDArray[np.float64] | tuple[float, ...] | list[float] | None = None,
) -> NDArray[np.float64]:
    """Rotation by ``angle`` (right-handed) about the line through ``point`` along ``axis``."""
    r = _axis_rotation(unit(axis), angle)
    if point is None:
        return _compose(r, np.zeros(3))
    p = np.asarray(point, dtype=np.float64)
    return _compose(r, p - r @ p)


def rot_x(angle: float) -> NDArray[np.float64]:
    """``Rx(angle)`` about the x-axis through the origin."""
    return rotation((1.0, 0.0, 0.0), angle)


def rot_y(angle: float) -> NDArray[np.float64]:
    """``Ry(angle)`` about the y-axis through the origin."""
    return rotation((0.0, 1.0, 0.0), angle)


def rot_z(angle: float) -> NDArray[np.float64]:
    """``Rz(angle)`` about the z-axis through the origin."""
    return rotation((0.0, 0.0, 1.0), angle)


def screw(
    point: NDArray[np.float64] | tuple[float, ...] | list[float],
    axis: NDArray[np.float64] | tuple[float, ...] | list[float],
    pitch: float,
    angle: float,
) -> NDArray[np.float64]:
    """The screw motion ``Tr(pitch*angle*u) . Rot_L(angle)`` about the line L = (point, axis).

    docs/algebra.md §1: ``Scr(theta; p) = Tr(0, 0, p theta) Rz(theta)`` placed on L.
    """
    u = unit(axis)
    out = rotation(u, angle, point)
    out[:3, 3] += pitch * angle * u
    return out


def inverse(t: NDArray[np.float64]) -> NDArray[np.float64]:
    """The inverse of a rigid transform (transpose of the rotation, no general inversion;
    scalar arithmetic, which beats numpy calls on 4x4 matrices)."""
    (a, b, c, x), (d, e, f, y), (g, h, i, z) = t[:3].tolist()
    return np.array(
        (
            (a, d, g, -(a * x + d * y + g * z)),
            (b, e, h, -(b * x + e * y + h * z)),
            (c, f, i, -(c * x + f * y + i * z)),
            (0.0, 0.0, 0.0, 1.0),
        )
    )


def as_floats(
    v: NDArray[np.float64] | tuple[float, ...] | list[float],
) -> tuple[float, float, float]:
    """The three coordinates of a 3-vector as Python floats (fast scalar arithmetic)."""
    a, b, c = v.tolist() if isinstance(v, np.ndarray) else v
    return float(a), float(b), float(c)


def frame_from_floats(
    origin: tuple[float, float, float],
    z_axis: tuple[float, float, float],
    x_hint: tuple[float, float, float] | None = None,
) -> tuple[
    tuple[float, float, float],
    tuple[float, float, float],
    tuple[float, float, float],
    tuple[float, float, float],
]:
    """The columns (x, y, z, origin) of :func:`frame`, in plain float arithmetic (the
    frame construction is on the hot path of every transporter)."""
    zx, zy, zz = z_axis
    n = math.sqrt(zx * zx + zy * zy + zz * zz)
    if n > 0.0:
        zx, zy, zz = zx / n, zy / n, zz / n
    x: tuple[float, float, float] | None = None
    if x_hint is not None:
        hx, hy, hz = x_hint
        d = hx * zx + hy * zy + hz * zz
        hx, hy, hz = hx - d * zx, hy - d * zy, hz - d * zz
        h2 = hx * hx + hy * hy + hz * hz
        if h2 > 0.0:
            h = math.sqrt(h2)
            x = (hx / h, hy / h, hz / h)
    if x is None:
        # The coordinate axis least aligned with z (first one on ties), made perpendicular.
        az, bz, cz = abs(zx), abs(zy), abs(zz)
        k = 0 if az <= bz and az <= cz else (1 if bz <= cz else 2)
        ex, ey, ez = (k == 0) * 1.0, (k == 1) * 1.0, (k == 2) * 1.0
        d = (zx, zy, zz)[k]
        ex, ey, ez = ex - d * zx, ey - d * zy, ez - d * zz
        h = math.sqrt(ex * ex + ey * ey + ez * ez)
        x = (ex / h, ey / h, ez / h) if h > 0.0 else (ex, ey, ez)
    xx, xy, xz = x
    y = (zy * xz - zz * xy, zz * xx - zx * xz, zx * xy - zy * xx)
    return x, y, (zx, zy, zz), origin


def matrix_from_columns(columns: tuple[tuple[float, float, float], ...]) -> NDArray[np.float64]:
    """The 4x4 transform with rotation columns x, y, z and translation ``columns[3]``."""
    (x0, x1, x2), (y0, y1, y2), (z0, z1, z2), (o0, o1, o2) = columns
    return np.array(((x0, y0, z0, o0), (x1, y1, z1, o1), (x2, y2, z2, o2), (0.0, 0.0, 0.0, 1.0)))


def frame(
    origin: NDArray[np.float64] | tuple[float, ...] | list[float],
    z_axis: NDArray[np.float64] | tuple[float, ...] | list[float],
    x_hint: NDArray[np.float64] | tuple[float, ...] | list[float] | None = None,
) -> NDArray[np.float64]:
    """A right-handed frame at ``origin`` whose +z is ``z_axis``.

    The x axis is ``x_hint`` made perpendicular to z; without a usable hint it is the
    coordinate axis least aligned with z, made perpendicular (a deterministic choice).
    """
    hint = None if x_hint is None else as_floats(x_hint)
    return matrix_from_columns(frame_from_floats(as_floats(origin), as_floats(z_axis), hint))


def apply(t: NDArray[np.float64], points: NDArray[np.float64]) -> NDArray[np.float64]:
    """Points (shape (3,) or (n, 3)) mapped by ``t``."""
    p = np.asarray(points, dtype=np.float64)
    return p @ t[:3, :3].T + t[:3, 3]


def apply_direction(t: NDArray[np.float64], dirs: NDArray[np.float64]) -> NDArray[np.float64]:
    """Free vectors (shape (3,) or (n, 3)) rotated by ``t`` (translation ignored)."""
    return np.asarray(dirs, dtype=np.float64) @ t[:3, :3].T


def hat(xi: NDArray[np.float64]) -> NDArray[np.float64]:
    """The 4x4 matrix of the twist ``(omega; v)``: ``[[omega]x, v; 0, 0]``."""
    out = np.zeros((4, 4))
    out[:3, :3] = skew(xi[:3])
    out[:3, 3] = xi[3:]
    return out


def vee(m: NDArray[np.float64]) -> NDArray[np.float64]:
    """The twist ``(omega; v)`` of a 4x4 matrix of se(3) (inverse of :func:`hat`)."""
    return np.array([m[2, 1], m[0, 2], m[1, 0], m[0, 3], m[1, 3], m[2, 3]], dtype=np.float64)


def _left_jacobian(w: NDArray[np.float64], theta: float) -> NDArray[np.float64]:
    """``V`` with ``exp(hat(w, v)) = (exp(w), V v)`` (closed form, docs/algebra.md §1)."""
    k = skew(w)
    if theta < _SERIES_SWITCH:
        # Taylor terms beyond second order are below float64 resolution here.
        return np.eye(3) + 0.5 * k + (k @ k) / 6.0
    a = (1.0 - math.cos(theta)) / theta**2
    b = (theta - math.sin(theta)) / theta**3
    return np.eye(3) + a * k + b * (k @ k)


def rotation_matrix(w: NDArray[np.float64] | Sequence[float]) -> NDArray[np.float64]:
    """The rotation ``exp(skew(w))`` of the rotation vector ``w`` (Rodrigues' formula)."""
    v = np.asarray(w, dtype=np.float64)
    theta = math.sqrt(float(v @ v))
    k = skew(v)
    if theta < _SERIES_SWITCH:
        return np.eye(3) + k + 0.5 * (k @ k)
    return (
        np.eye(3) + (math.sin(theta) / theta) * k + ((1.0 - math.cos(theta)) / theta**2) * (k @ k)
    )


def rotation_vector(r: NDArray[np.float64]) -> NDArray[np.float64]:
    """The rotation vector (axis times angle in [0, pi]) of the rotation matrix ``r``.

    Through the unit quaternion, taken from the largest of its four squared components
    (Shepperd's method), so that it is accurate near 0 and near pi alike.
    """
    r = np.asarray(r, dtype=np.float64)
    trace = r[0, 0] + r[1, 1] + r[2, 2]
    squares = (trace, r[0, 0], r[1, 1], r[2, 2])
    k = int(np.argmax(squares))
    if k == 0:
        w = math.sqrt(max(1.0 + trace, 0.0)) / 2.0
        q = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]) / (4.0 * w)
    else:
        i, j, m = k - 1, k % 3, (k + 1) % 3
        q = np.empty(3)
        q[i] = math.sqrt(max(1.0 + 2.0 * r[i, i] - trace, 0.0)) / 2.0
        q[j] = (r[j, i] + r[i, j]) / (4.0 * q[i])
        q[m] = (r[m, i] + r[i, m]) / (4.0 * q[i])
        w = (r[m, j] - r[j, m]) / (4.0 * q[i])
    if w < 0.0:  # the same rotation; this sign gives the angle in [0, pi]
        w, q = -w, -q
    sine = math.sqrt(float(q @ q))
    if sine == 0.0:
        return np.zeros(3)
    return q * (2.0 * math.atan2(sine, w) / sine)


def exp(xi: NDArray[np.float64]) -> NDArray[np.float64]:
    """The exponential of the twist ``xi = (omega; v)`` in closed form."""
    xi = np.asarray(xi, dtype=np.float64)
    w, v = xi[:3], xi[3:]
    theta = math.sqrt(float(w @ w))
    return _compose(rotation_matrix(w), _left_jacobian(w, theta) @ v)


def log(t: NDArray[np.float64]) -> NDArray[np.float64]:
    """A twist ``xi`` with ``exp(xi) == t`` and rotation angle in [0, pi].

    The logarithm is multivalued (at angle pi and by 2 pi periodicity); it is used for
    parameterisation and residuals, never to decide membership (docs/algebra.md §2.3).
    """
    w = rotation_vector(t[:3, :3])
    theta = math.sqrt(float(w @ w))
    v = np.linalg.solve(_left_jacobian(w, theta), t[:3, 3])
    return np.concatenate((w, v))


def adjoint(t: NDArray[np.float64]) -> NDArray[np.float64]:
    """The 6x6 adjoint: ``Ad_T (omega; v) = (R omega; R v + t x R omega)``."""
    r, p = t[:3, :3], t[:3, 3]
    out = np.zeros((6, 6))
    out[:3, :3] = r
    out[3:, 3:] = r
    out[3:, :3] = skew(p) @ r
    return out


def rotation_angle(t: NDArray[np.float64]) -> float:
    """The rotation angle of ``t`` in [0, pi] (robust near 0 and pi)."""
    return float(np.linalg.norm(rotation_vector(t[:3, :3])))


def is_rigid(t: NDArray[np.float64], tol: Tolerance | None = None) -> bool:
    """Whether ``t`` is a proper rigid transform within the angular tolerance."""
    tol = tol or current()
    a = np.asarray(t, dtype=np.float64)
    if a.shape != (4, 4) or not np.all(np.isfinite(a)):
        return False
    r = a[:3, :3]
    ortho = float(np.max(np.abs(r.T @ r - np.eye(3))))
    bottom = float(np.max(np.abs(a[3] - (0.0, 0.0, 0.0, 1.0))))
    return ortho <= tol.angle and bottom <= tol.angle and float(np.linalg.det(r)) > 0.0


def random_transform(rng: np.random.Generator, scale: float = 10.0) -> NDArray[np.float64]:
    """A random rigid transform: uniform rotation and translation in ``[-scale, scale]^3``."""
    from scipy.spatial.transform import Rotation

    r = Rotation.random(random_state=rng).as_matrix()
    return _compose(r, rng.uniform(-scale, scale, 3))


def axis_basis(
    axes: NDArray[np.float64], *, turned: bool = False
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Unit vectors ``u, v`` completing each unit axis ``n`` to the right-handed frame
    ``(u, v, n)``, for one axis (shape (3,)) or for rows (shape (m, 3)): ``u`` along
    ``e x n`` for the coordinate axis ``e`` least aligned with ``n`` (the first on ties),
    ``v = n x u``. ``turned``: that frame turned half a turn about ``n``, ``u`` along
    ``n x e`` and ``v = n x u``, each the cross product itself (negating the other
    frame's vectors gives the same values but not always the same signs of zero)."""
    n = np.asarray(axes, dtype=np.float64)
    least = np.eye(3)[np.argmin(np.abs(n), axis=-1)]
    first, second = (n, least) if turned else (least, n)
    if n.ndim == 1:
        u = cross(first, second)
        u /= np.linalg.norm(u)
        return u, cross(n, u)
    u = np.cross(first, second)
    u /= np.linalg.norm(u, axis=-1, keepdims=True)
    return u, np.cross(n, u)


def poses_equal(
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    tol: Tolerance | None = None,
    *,
    numeric: bool = False,
) -> bool:
    """Whether two poses are one under the tolerance policy: every rotation entry within
    the angular tolerance and the translations within the length tolerance. ``numeric``
    poses come from the numeric solvers, whose precision is that of the mesh tolerances:
    these or the tolerance in force, whichever is looser."""
    tol = tol or current()
    angle, length = tol.angle, tol.length
    if numeric:
        angle, length = max(tol.mesh_angle, angle), max(tol.mesh_length, length)
    return (
        float(np.max(np.abs(a[:3, :3] - b[:3, :3]))) <= angle
        and norm(a[:3, 3] - b[:3, 3]) <= length
    )


def random_starts(
    angles: NDArray[np.bool_], length: float, count: int, seed: int = 0
) -> Iterator[NDArray[np.float64]]:
    """The deterministic starts of a multi-start over group parameters (docs/algebra.md §2.5
    "Numeric fallback"): zero, then ``count - 1`` seeded uniform draws, angles in
    [-pi, pi] and lengths in [-``length``, ``length``]."""
    rng = np.random.default_rng(seed)
    yield np.zeros(angles.size)
    for _ in range(count - 1):
        yield rng.uniform(-1.0, 1.0, angles.size) * np.where(angles, math.pi, length)


def multistart_least_squares(
    residual: Callable[[NDArray[np.float64]], NDArray[np.float64]],
    starts: Iterable[NDArray[np.float64]],
    **options: Any,
) -> Iterator[Any]:
    """``scipy.optimize.least_squares`` of ``residual`` from each start in turn, yielding
    each fit (its ``x``, ``fun``, ``jac``): a deterministic multi-start (docs/algebra.md §2.5
    "Numeric fallback") that the caller ends at the first fit it accepts. ``options`` go
    to ``least_squares`` unchanged; ``scipy.optimize`` is imported at the first start, so
    that only numeric cases pay for it."""
    from scipy.optimize import least_squares

    for x0 in starts:
        yield least_squares(residual, x0, **options)
