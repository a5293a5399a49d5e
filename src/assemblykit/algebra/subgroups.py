"""Symmetry subgroups of SE(3): G = G0 . Gamma (ALGEBRA.md §2).

G0 is one of Hervé's 12 connected families (§2.1) placed by a frame F
(G0 = F K F^-1 with K canonical: axis/normal +z through the origin); Gamma is a
finite transversal ``reps`` (always containing I) and optional ``lattice``
generators of an infinite discrete quotient (helical lattices, §2.2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

import numpy as np
from numpy.typing import NDArray

from assemblykit.algebra import se3
from assemblykit.algebra.caching import cached
from assemblykit.algebra.lattices import MAX_LATTICE_DENOMINATOR, commensurate
from assemblykit.errors import GroupError, NumericError
from assemblykit.tolerance import Tolerance, current

__all__ = ["MAX_LATTICE_DENOMINATOR", "Kind", "Locus", "SymmetryGroup"]

#: Largest finite group built by closure (``extended_by``); beyond it the group is not finite.
MAX_FINITE_ORDER = 1_000

_TWO_PI = 2.0 * math.pi
# Printed coordinates below this are rounding noise and shown as 0 (display only).
_EYE4 = np.eye(4)
_EYE4.setflags(write=False)


class Kind(StrEnum):
    """Hervé's 12 families of connected subgroups of SE(3) (ALGEBRA.md §2.1)."""

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


_DIM = {
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
_HELICAL = frozenset({Kind.HELICAL, Kind.PSEUDO_PLANAR})
# Rotation part of a TR group (§2.4 characteristic-invariant view): none, about one line
# direction, or about a point.
_LINEAR = {
    Kind.FIXED: "none",
    Kind.PRISMATIC: "none",
    Kind.TRANSLATION2: "none",
    Kind.TRANSLATION3: "none",
    Kind.REVOLUTE: "line",
    Kind.CYLINDRICAL: "line",
    Kind.PLANAR: "line",
    Kind.SCHOENFLIES: "line",
    Kind.HELICAL: "line",
    Kind.PSEUDO_PLANAR: "line",
    Kind.SPHERICAL: "point",
    Kind.FREE: "point",
}


# ----------------------------------------------------------------------------- subspaces


#: A symmetric 3x3 matrix by its upper triangle (m00, m01, m02, m11, m12, m22).
Sym3 = tuple[float, float, float, float, float, float]
Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class _Sub:
    """A linear subspace of R^3 in closed form: dim 1 keeps its direction, dim 2 its normal."""

    dim: int
    vec: NDArray[np.float64] | None = None

    def perp_projector(self) -> NDArray[np.float64]:
        """The orthogonal projector onto the complement of the subspace."""
        if self.dim == 0:
            return np.eye(3)
        if self.dim == 3:
            return np.zeros((3, 3))
        assert self.vec is not None
        outer = np.outer(self.vec, self.vec)
        return np.eye(3) - outer if self.dim == 1 else outer

    def residual(self, w: NDArray[np.float64]) -> float:
        """Length of the component of ``w`` outside the subspace."""
        if self.dim == 3:
            return 0.0
        if self.dim == 0:
            return se3.norm(w)
        assert self.vec is not None
        if self.dim == 1:
            return se3.norm(w - (w @ self.vec) * self.vec)
        return abs(float(w @ self.vec))

    def project(self, w: NDArray[np.float64]) -> NDArray[np.float64]:
        """The orthogonal projection of ``w`` onto the subspace."""
        return w - self.perp_projector() @ w

    def perp_sym(self) -> Sym3:
        """:meth:`perp_projector` as the upper triangle (m00, m01, m02, m11, m12, m22)."""
        if self.dim == 0:
            return (1.0, 0.0, 0.0, 1.0, 0.0, 1.0)
        if self.dim == 3:
            return (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        assert self.vec is not None
        u0, u1, u2 = se3.as_floats(self.vec)
        outer = (u0 * u0, u0 * u1, u0 * u2, u1 * u1, u1 * u2, u2 * u2)
        if self.dim == 2:
            return outer
        return (1.0 - outer[0], -outer[1], -outer[2], 1.0 - outer[3], -outer[4], 1.0 - outer[5])


def _parallel(a: NDArray[np.float64], b: NDArray[np.float64], tol: Tolerance) -> bool:
    a0, a1, a2 = se3.as_floats(a)
    b0, b1, b2 = se3.as_floats(b)
    c0, c1, c2 = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
    return math.sqrt(c0 * c0 + c1 * c1 + c2 * c2) <= tol.angle


def _unit_cross(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """The unit vector along a x b (a and b not parallel)."""
    a0, a1, a2 = se3.as_floats(a)
    b0, b1, b2 = se3.as_floats(b)
    c0, c1, c2 = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
    size = math.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
    return np.array((c0 / size, c1 / size, c2 / size))


def _sub_meet(a: _Sub, b: _Sub, tol: Tolerance) -> _Sub:
    """Intersection of two subspaces of R^3."""
    if a.dim == 0 or b.dim == 3:
        return a
    if b.dim == 0 or a.dim == 3:
        return b
    assert a.vec is not None and b.vec is not None
    if a.dim == 1 and b.dim == 1:
        return a if _parallel(a.vec, b.vec, tol) else _Sub(0)
    if a.dim == 2 and b.dim == 2:
        if _parallel(a.vec, b.vec, tol):
            return a
        return _Sub(1, _unit_cross(a.vec, b.vec))
    line, plane = (a, b) if a.dim == 1 else (b, a)
    assert line.vec is not None and plane.vec is not None
    return line if abs(float(line.vec @ plane.vec)) <= tol.angle else _Sub(0)


def _sub_join(a: _Sub, b: _Sub, tol: Tolerance) -> _Sub:
    """Sum of two subspaces of R^3."""
    if a.dim == 0 or b.dim == 3:
        return b
    if b.dim == 0 or a.dim == 3:
        return a
    assert a.vec is not None and b.vec is not None
    if a.dim == 1 and b.dim == 1:
        if _parallel(a.vec, b.vec, tol):
            return a
        return _Sub(2, _unit_cross(a.vec, b.vec))
    if a.dim == 2 and b.dim == 2:
        return a if _parallel(a.vec, b.vec, tol) else _Sub(3)
    line, plane = (a, b) if a.dim == 1 else (b, a)
    assert line.vec is not None and plane.vec is not None
    return plane if abs(float(line.vec @ plane.vec)) <= tol.angle else _Sub(3)


def _cramer(m: Sym3, rhs: Vec3, det: float) -> Vec3:
    """The solution of ``m x = rhs`` for a regular symmetric ``m`` = (m00, m01, m02, m11,
    m12, m22) with determinant ``det`` (the adjugate of a symmetric matrix is symmetric)."""
    a, b, c, e, f, i = m
    r0, r1, r2 = rhs
    c00, c01, c02 = e * i - f * f, c * f - b * i, b * f - c * e
    c11, c12, c22 = a * i - c * c, b * c - a * f, a * e - b * b
    return (
        (c00 * r0 + c01 * r1 + c02 * r2) / det,
        (c01 * r0 + c11 * r1 + c12 * r2) / det,
        (c02 * r0 + c12 * r1 + c22 * r2) / det,
    )


def psd_solve(m: Sym3, rhs: Vec3, tol: Tolerance) -> Vec3:
    """The minimum-norm least-squares solution of ``m x = rhs`` for a symmetric positive
    semi-definite 3x3 ``m`` (a sum of projectors) given by its upper triangle (m00, m01,
    m02, m11, m12, m22), in closed form: Cramer's rule when regular, otherwise completed
    by the null space (rank 2) or the single range direction (rank 1). Plain float
    arithmetic: this is the hot path of every transporter.

    Regularity is a numerical decision (``tol.precision``), not a geometric one: the
    completed solutions depend on the coordinates, so a regular system called singular
    under a loose tolerance would give congruent tuples frames that do not correspond.
    """
    a, b, c, e, f, i = m
    trace = a + e + i
    eps = tol.precision
    if trace <= eps:
        return (0.0, 0.0, 0.0)
    det = a * (e * i - f * f) + b * (c * f - b * i) + c * (b * f - c * e)
    if abs(det) > eps * trace**3:
        return _cramer(m, rhs, det)
    rows = ((a, b, c), (b, e, f), (c, f, i))
    best, null = 0.0, (0.0, 0.0, 0.0)
    for p, q in ((0, 1), (0, 2), (1, 2)):
        (x0, x1, x2), (y0, y1, y2) = rows[p], rows[q]
        w = (x1 * y2 - x2 * y1, x2 * y0 - x0 * y2, x0 * y1 - x1 * y0)
        size = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
        if size > best:
            best, null = size, (w[0] / size, w[1] / size, w[2] / size)
    if best > eps * trace**2:
        # m + n n^T is regular and maps n to n, so the solution has no null component.
        n0, n1, n2 = null
        full = (a + n0 * n0, b + n0 * n1, c + n0 * n2, e + n1 * n1, f + n1 * n2, i + n2 * n2)
        fa, fb, fc, fe, ff, fi = full
        det = fa * (fe * fi - ff * ff) + fb * (fc * ff - fb * fi) + fc * (fb * ff - fc * fe)
        return _cramer(full, rhs, det)
    k = 0 if a >= e and a >= i else (1 if e >= i else 2)
    v0, v1, v2 = rows[k]
    size = math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
    v0, v1, v2 = v0 / size, v1 / size, v2 / size
    along = (v0 * rhs[0] + v1 * rhs[1] + v2 * rhs[2]) / trace
    return (v0 * along, v1 * along, v2 * along)


def _affine_meet_point(
    na: NDArray[np.float64], sa: _Sub, nb: NDArray[np.float64], sb: _Sub, tol: Tolerance
) -> NDArray[np.float64]:
    """A point of (na + sa) ∩ (nb + sb), known to be non-empty: the least-squares
    point nearest to ``na`` (so a frame origin already valid is kept)."""
    pa, (b00, b01, b02, b11, b12, b22) = sa.perp_sym(), sb.perp_sym()
    a0, a1, a2 = se3.as_floats(na)
    d0, d1, d2 = (y - x for x, y in zip((a0, a1, a2), se3.as_floats(nb), strict=True))
    rhs = (
        b00 * d0 + b01 * d1 + b02 * d2,
        b01 * d0 + b11 * d1 + b12 * d2,
        b02 * d0 + b12 * d1 + b22 * d2,
    )
    m = (pa[0] + b00, pa[1] + b01, pa[2] + b02, pa[3] + b11, pa[4] + b12, pa[5] + b22)
    x0, x1, x2 = psd_solve(m, rhs, tol)
    return np.array((a0 + x0, a1 + x1, a2 + x2))


# ----------------------------------------------------------------------------- canonical K


def _canonical_basis(kind: Kind, pitch: float) -> NDArray[np.float64]:
    """The canonical Lie algebra basis (6 x dim, (omega; v)) of K (ALGEBRA.md §2.1 table)."""
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


def _canonical_element(
    kind: Kind, pitch: float, params: NDArray[np.float64]
) -> NDArray[np.float64]:
    """k(params) of the canonical family (ALGEBRA.md §5.1 normal form).

    Parameters: R, H (theta); T (s); C (theta, s); T2 (a, b); T3 (a, b, c);
    S (rotation vector); G, Y (a, b, theta); X (a, b, c, theta); D (tx, ty, tz, rotvec).
    """
    p = [float(x) for x in params]
    if len(p) != _DIM[kind]:
        raise GroupError(f"a {kind.value} group takes {_DIM[kind]} parameters, got {len(p)}")
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


def _helix_residual(pitch: float, tz: float, theta: float) -> float:
    """Length by which (theta, tz) misses the helix t_z = p (theta + 2 pi k) (§2.3)."""
    if pitch == 0.0:
        return abs(tz)
    d = tz / pitch - theta
    d -= _TWO_PI * round(d / _TWO_PI)
    return abs(pitch * d)


def _in_canonical(kind: Kind, pitch: float, g: NDArray[np.float64], tol: Tolerance) -> bool:
    """Membership of a canonical-frame element in K (ALGEBRA.md §2.3 predicate table)."""
    if kind is Kind.FREE:
        return True
    r, t = g[:3, :3], g[:3, 3]
    ang, length = tol.angle, tol.length
    if kind is Kind.SPHERICAL:
        return se3.norm(t) <= length
    if _LINEAR[kind] == "none":
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
        return _helix_residual(pitch, t[2], theta) <= length
    if math.hypot(t[0], t[1]) > length:
        return False
    if kind is Kind.REVOLUTE:
        return abs(float(t[2])) <= length
    if kind is Kind.HELICAL:
        return _helix_residual(pitch, t[2], theta) <= length
    return True


# ----------------------------------------------------------------------------- loci


@dataclass(frozen=True, eq=False)
class Locus:
    """The orbit of a point under a group (ALGEBRA.md §2.3 orbit table).

    ``kind`` is one of "point", "circle", "line", "helix", "cylinder", "plane", "sphere",
    "space", "union". ``point`` is the point itself (point), the centre (circle, sphere),
    a point on the axis (line, helix, cylinder: the axis point) or a point of the plane;
    ``direction`` the axis or normal; ``radius`` for circle/helix/cylinder/sphere;
    ``pitch`` and ``through`` (a point of the curve) for a helix; ``members`` and
    ``steps`` (lattice translations) for a union.
    """

    kind: str
    point: NDArray[np.float64] | None = None
    direction: NDArray[np.float64] | None = None
    radius: float = 0.0
    pitch: float = 0.0
    through: NDArray[np.float64] | None = None
    members: tuple[Locus, ...] = ()
    steps: tuple[NDArray[np.float64], ...] = ()

    def contains(self, p: NDArray[np.float64], tol: Tolerance | None = None) -> bool:
        """Whether the point ``p`` lies on the locus."""
        tol = tol or current()
        q = np.asarray(p, dtype=np.float64)
        if self.kind == "space":
            return True
        if self.kind == "union":
            return self._union_contains(q, tol)
        assert self.point is not None
        d = q - self.point
        if self.kind == "point":
            return se3.norm(d) <= tol.length
        if self.kind == "sphere":
            return abs(se3.norm(d) - self.radius) <= tol.length
        assert self.direction is not None
        u = self.direction
        along = float(d @ u)
        radial = d - along * u
        if self.kind == "plane":
            return abs(along) <= tol.length
        if self.kind == "line":
            return se3.norm(radial) <= tol.length
        rho = se3.norm(radial)
        if self.kind == "cylinder":
            return abs(rho - self.radius) <= tol.length
        if self.kind == "circle":
            return abs(along) <= tol.length and abs(rho - self.radius) <= tol.length
        return self._helix_contains(d, along, radial, rho, tol)

    def distance(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        """The distances of ``points`` (n x 3) from the locus, for the kinds a closed
        curve or surface has: point, circle, line, cylinder, plane, sphere, space.

        A circle's nearest point to ``p`` lies on the ray from the centre towards ``p``'s
        projection into its plane, at distance ``√(along² + (ρ − r)²)``."""
        q = np.atleast_2d(np.asarray(points, dtype=np.float64))
        if self.kind == "space":
            return np.zeros(len(q))
        if self.kind in ("helix", "union") or self.point is None:
            raise GroupError(f"no distance to a {self.kind} locus")
        d = q - self.point
        if self.kind in ("point", "sphere"):
            r: NDArray[np.float64] = np.linalg.norm(d, axis=1)
            return r if self.kind == "point" else np.abs(r - self.radius)
        assert self.direction is not None
        along = d @ self.direction
        rho: NDArray[np.float64] = np.linalg.norm(d - along[:, None] * self.direction, axis=1)
        if self.kind == "plane":
            return np.abs(along)
        if self.kind == "line":
            return rho
        if self.kind == "cylinder":
            return np.abs(rho - self.radius)
        return np.hypot(along, rho - self.radius)

    def _helix_contains(
        self,
        d: NDArray[np.float64],
        along: float,
        radial: NDArray[np.float64],
        rho: float,
        tol: Tolerance,
    ) -> bool:
        assert self.through is not None and self.point is not None and self.direction is not None
        u = self.direction
        d0 = self.through - self.point
        along0 = float(d0 @ u)
        radial0 = d0 - along0 * u
        if abs(rho - self.radius) > tol.length:
            return False
        angle = math.atan2(float(se3.cross(radial0, radial) @ u), float(radial0 @ radial))
        return _helix_residual(self.pitch, along - along0, angle) <= tol.length

    def _union_contains(self, q: NDArray[np.float64], tol: Tolerance) -> bool:
        if not self.steps:
            return any(m.contains(q, tol) for m in self.members)
        step = self.steps[0]
        for m in self.members:
            assert m.point is not None
            k = round(float((q - m.point) @ step) / float(step @ step))
            if any(m.contains(q - j * step, tol) for j in (k - 1, k, k + 1)):
                return True
        return False


# ----------------------------------------------------------------------------- the group


@dataclass(frozen=True, eq=False)
class SymmetryGroup:
    """A subgroup G = G0 . Gamma of SE(3) (ALGEBRA.md §2.2).

    ``kind``/``frame``/``pitch`` place the connected part G0 = F K F^-1; ``reps`` is a
    finite transversal of G/G0 (world elements, the first is I) and ``lattice`` the
    generators of an infinite discrete quotient. Elements are g0 . lambda . gamma.
    """

    kind: Kind
    frame: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    pitch: float = 0.0
    reps: tuple[NDArray[np.float64], ...] = (_EYE4,)
    lattice: tuple[NDArray[np.float64], ...] = ()

    # ------------------------------------------------------------------ constructors

    @classmethod
    def connected(
        cls, kind: Kind | str, frame: NDArray[np.float64], pitch: float = 0.0
    ) -> SymmetryGroup:
        """The connected group F K(kind, pitch) F^-1; a zero pitch gives R or G."""
        k = Kind(kind)
        if k in _HELICAL and pitch == 0.0:
            k = Kind.REVOLUTE if k is Kind.HELICAL else Kind.PLANAR
        return cls(k, np.asarray(frame, dtype=np.float64), float(pitch) if k in _HELICAL else 0.0)

    @classmethod
    def identity(cls) -> SymmetryGroup:
        """The trivial group {I} (one shared immutable value)."""
        return _IDENTITY

    @classmethod
    def revolute(cls, point: Any, axis: Any) -> SymmetryGroup:
        """R(N, u): rotations about the line through ``point`` along ``axis``."""
        return cls.connected(Kind.REVOLUTE, se3.frame(point, axis))

    @classmethod
    def prismatic(cls, direction: Any) -> SymmetryGroup:
        """T(u): translations along ``direction``."""
        return cls.connected(Kind.PRISMATIC, se3.frame((0.0, 0.0, 0.0), direction))

    @classmethod
    def helical(cls, point: Any, axis: Any, pitch: float) -> SymmetryGroup:
        """H(N, u, p): screws with signed pitch ``p`` (lead 2 pi p) about the line."""
        return cls.connected(Kind.HELICAL, se3.frame(point, axis), pitch)

    @classmethod
    def cylindrical(cls, point: Any, axis: Any) -> SymmetryGroup:
        """C(N, u): rotations about and translations along the line."""
        return cls.connected(Kind.CYLINDRICAL, se3.frame(point, axis))

    @classmethod
    def translation2(cls, normal: Any) -> SymmetryGroup:
        """T2(n): translations perpendicular to ``normal``."""
        return cls.connected(Kind.TRANSLATION2, se3.frame((0.0, 0.0, 0.0), normal))

    @classmethod
    def translation3(cls) -> SymmetryGroup:
        """T3: all translations."""
        return cls.connected(Kind.TRANSLATION3, np.eye(4))

    @classmethod
    def spherical(cls, center: Any) -> SymmetryGroup:
        """S(N): rotations about the point ``center``."""
        return cls.connected(Kind.SPHERICAL, se3.translation(center))

    @classmethod
    def planar(cls, normal: Any) -> SymmetryGroup:
        """G(n): planar gliding (translations ⊥ n, rotations about lines ∥ n)."""
        return cls.connected(Kind.PLANAR, se3.frame((0.0, 0.0, 0.0), normal))

    @classmethod
    def pseudo_planar(cls, normal: Any, pitch: float) -> SymmetryGroup:
        """Y(n, p): translations ⊥ n and screws of pitch ``p`` along n."""
        return cls.connected(Kind.PSEUDO_PLANAR, se3.frame((0.0, 0.0, 0.0), normal), pitch)

    @classmethod
    def schoenflies(cls, direction: Any) -> SymmetryGroup:
        """X(u): all translations and rotations about lines ∥ u."""
        return cls.connected(Kind.SCHOENFLIES, se3.frame((0.0, 0.0, 0.0), direction))

    @classmethod
    def free(cls) -> SymmetryGroup:
        """D = SE(3)."""
        return cls(Kind.FREE)

    @classmethod
    def finite(cls, elements: Any, tol: Tolerance | None = None) -> SymmetryGroup:
        """The finite group whose elements are ``elements`` (closure is checked)."""
        return cls.identity().with_discrete(reps=tuple(elements), tol=tol)

    @classmethod
    def cyclic(cls, point: Any, axis: Any, n: int) -> SymmetryGroup:
        """C_n: rotations by 2 pi k / n about the line (point, axis)."""
        if n < 1:
            raise GroupError(f"a cyclic group needs n >= 1, got {n}")
        reps = tuple(se3.rotation(axis, _TWO_PI * k / n, point) for k in range(n))
        return cls(Kind.FIXED, np.eye(4), 0.0, reps)

    @classmethod
    def lattice_group(cls, generators: Any) -> SymmetryGroup:
        """The infinite discrete group generated by ``generators`` (translations or screws)."""
        return cls.identity().with_discrete(lattice=tuple(generators))

    # ------------------------------------------------------------------ properties

    @property
    def dof(self) -> int:
        """Dimension of G0 (Hervé dimension)."""
        return _DIM[self.kind]

    @property
    def n_components(self) -> float | int:
        """Number of components: |Gamma|, or ``math.inf`` with a lattice."""
        return math.inf if self.lattice else len(self.reps)

    @property
    def is_connected(self) -> bool:
        """Whether G = G0."""
        return len(self.reps) == 1 and not self.lattice

    @property
    def is_tr(self) -> bool:
        """Whether G0 is a TR group (not helical; ALGEBRA.md §2.4)."""
        return self.kind not in _HELICAL

    @cached
    def connected_part(self) -> SymmetryGroup:
        """G0 alone."""
        if self.is_connected:
            return self
        return SymmetryGroup(self.kind, self.frame, self.pitch)

    @cached
    def frame_inverse(self) -> NDArray[np.float64]:
        """F^-1 (cached: every membership test uses it)."""
        return se3.inverse(self.frame)

    @property
    def axis(self) -> NDArray[np.float64]:
        """The +z of the frame: axis, direction or normal of G0."""
        return self.frame[:3, 2]

    @property
    def origin(self) -> NDArray[np.float64]:
        """The frame origin: a point on the axis, or the centre."""
        return self.frame[:3, 3]

    @cached
    def algebra(self) -> NDArray[np.float64]:
        """The world Lie algebra basis Ad_F (canonical basis), 6 x dof."""
        return se3.adjoint(self.frame) @ _canonical_basis(self.kind, self.pitch)

    @cached
    def invariants(self) -> dict[str, Any]:
        """The geometric invariants of G0 in the frame of the group's body (§2.1 table)."""
        k = self.kind
        out: dict[str, Any] = {}
        if k in (Kind.REVOLUTE, Kind.HELICAL, Kind.CYLINDRICAL, Kind.SPHERICAL):
            out["point"] = self.origin.copy()
        if k in (Kind.REVOLUTE, Kind.HELICAL, Kind.CYLINDRICAL):
            out["axis"] = self.axis.copy()
        if k in (Kind.PRISMATIC, Kind.SCHOENFLIES):
            out["direction"] = self.axis.copy()
        if k in (Kind.TRANSLATION2, Kind.PLANAR, Kind.PSEUDO_PLANAR):
            out["normal"] = self.axis.copy()
        if k in _HELICAL:
            out["pitch"] = self.pitch
        return out

    @cached
    def _translation_part(self) -> tuple[_Sub, tuple[NDArray[np.float64], float] | None]:
        """G0 ∩ T3 = {t in V : t.u in c Z} as (V, (u, c) or None) (§2.4, lattice rows)."""
        k, u = self.kind, self.axis
        if k in (Kind.FIXED, Kind.REVOLUTE, Kind.SPHERICAL):
            return _Sub(0), None
        if k in (Kind.PRISMATIC, Kind.CYLINDRICAL):
            return _Sub(1, u), None
        if k in (Kind.TRANSLATION2, Kind.PLANAR):
            return _Sub(2, u), None
        if k is Kind.HELICAL:
            return _Sub(1, u), (u, _TWO_PI * abs(self.pitch))
        if k is Kind.PSEUDO_PLANAR:
            return _Sub(3), (u, _TWO_PI * abs(self.pitch))
        return _Sub(3), None

    @cached
    def _tr_shape(self) -> tuple[str, _Sub]:
        """Rotation type and translation subspace V of a TR group G0 = T(V) ⋊ Rot."""
        return _LINEAR[self.kind], self._translation_part[0]

    # ------------------------------------------------------------------ elements

    def element(
        self, params: Any = (), component: int = 0, steps: tuple[int, ...] = ()
    ) -> NDArray[np.float64]:
        """F k(params) F^-1 . lambda . reps[component], lambda = prod lattice[i]^steps[i]."""
        k = _canonical_element(self.kind, self.pitch, np.atleast_1d(np.asarray(params, float)))
        g = self.frame @ k @ self.frame_inverse
        for gen, n in zip(self.lattice, steps, strict=False):
            g = g @ np.linalg.matrix_power(gen if n >= 0 else se3.inverse(gen), abs(n))
        return g @ self.reps[component]

    def sample(
        self, rng: np.random.Generator, n: int = 1, scale: float = 10.0
    ) -> list[NDArray[np.float64]]:
        """``n`` random members (angles in [-pi, pi], lengths in [-scale, scale])."""
        out = []
        for _ in range(n):
            params = rng.uniform(-1.0, 1.0, self.dof)
            params *= np.where(self._angle_params(), math.pi, scale)
            steps = tuple(int(s) for s in rng.integers(-3, 4, len(self.lattice)))
            out.append(self.element(params, int(rng.integers(len(self.reps))), steps))
        return out

    def _angle_params(self) -> NDArray[np.float64]:
        k = self.kind
        flags = {
            Kind.REVOLUTE: [1],
            Kind.HELICAL: [1],
            Kind.CYLINDRICAL: [1, 0],
            Kind.SPHERICAL: [1, 1, 1],
            Kind.PLANAR: [0, 0, 1],
            Kind.PSEUDO_PLANAR: [0, 0, 1],
            Kind.SCHOENFLIES: [0, 0, 0, 1],
            Kind.FREE: [0, 0, 0, 1, 1, 1],
        }.get(k, [0] * self.dof)
        return np.asarray(flags, dtype=bool)

    # ------------------------------------------------------------------ membership

    def _in_connected(self, g: NDArray[np.float64], tol: Tolerance) -> bool:
        if self.kind is Kind.FREE:
            return True
        return _in_canonical(self.kind, self.pitch, self.frame_inverse @ g @ self.frame, tol)

    def contains(self, t: NDArray[np.float64], tol: Tolerance | None = None) -> bool:
        """Whether ``t`` is in G (ALGEBRA.md §2.3, with reps and lattice projection)."""
        tol = tol or current()
        for gamma in self.reps:
            g = t @ se3.inverse(gamma) if gamma is not _EYE4 else t
            if not self.lattice:
                if self._in_connected(g, tol):
                    return True
            elif self._in_lattice_coset(g, tol):
                return True
        return False

    @cached
    def _lattice_projection(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Directions W where G0 never translates and each generator's translation is additive,
        and the generators' coordinates along them (for integer projection, §2.3)."""
        w = self._quotient_directions()
        coords = np.column_stack([w.T @ gen[:3, 3] for gen in self.lattice])
        return w, coords

    def _quotient_directions(self) -> NDArray[np.float64]:
        k = self.kind
        if k is Kind.FIXED:
            space = _Sub(3)
        elif k is Kind.REVOLUTE:
            space = _Sub(1, self.axis)
        elif k is Kind.PRISMATIC:
            space = _Sub(2, self.axis)
        elif k in (Kind.TRANSLATION2, Kind.PLANAR):
            space = _Sub(1, self.axis)
        else:
            raise GroupError(f"a lattice over a {k.value} group is not supported")
        tol = current()
        for gen in self.lattice:
            if se3.rotation_angle(gen) > tol.angle:
                axis = se3.unit(se3.rotation_vector(gen[:3, :3]))
                space = _sub_meet(space, _Sub(1, axis), tol)
        basis = {0: np.zeros((3, 0)), 3: np.eye(3)}.get(space.dim)
        if basis is None:
            assert space.vec is not None
            f = se3.frame((0.0, 0.0, 0.0), space.vec)[:3, :3]
            basis = f[:, 2:] if space.dim == 1 else f[:, :2]
        return basis

    def _in_lattice_coset(self, g: NDArray[np.float64], tol: Tolerance) -> bool:
        w, coords = self._lattice_projection
        k, *_ = np.linalg.lstsq(coords, w.T @ g[:3, 3], rcond=None)
        steps = tuple(round(float(x)) for x in k)
        lam = self.element(np.zeros(self.dof), 0, steps)
        return self._in_connected(g @ se3.inverse(lam), tol)

    # ------------------------------------------------------------------ comparison

    def _algebra_includes(self, other: SymmetryGroup, tol: Tolerance) -> bool:
        if other.dof == 0:
            return True
        if other.dof > self.dof:
            return False
        if self.kind is Kind.FREE:
            return True
        q, _ = np.linalg.qr(_scaled(self.algebra, tol))
        b = _scaled(other.algebra, tol)
        res = b - q @ (q.T @ b)
        return float(np.max(np.abs(res))) <= _rank_threshold(tol)

    def includes(self, other: SymmetryGroup, tol: Tolerance | None = None) -> bool:
        """Whether ``other`` is a subgroup of this group."""
        tol = tol or current()
        if not self._algebra_includes(other, tol):
            return False
        return all(self.contains(g, tol) for g in (*other.reps, *other.lattice))

    def equals(self, other: SymmetryGroup, tol: Tolerance | None = None) -> bool:
        """Whether both groups are the same set (kinds, invariants, discrete parts)."""
        tol = tol or current()
        return (
            self.kind is other.kind
            and self.n_components == other.n_components
            and self.includes(other, tol)
            and other.includes(self, tol)
        )

    # ------------------------------------------------------------------ transforms

    def conjugate(self, t: NDArray[np.float64]) -> SymmetryGroup:
        """T G T^-1 (ALGEBRA.md §2.3 conjugation)."""
        ti = se3.inverse(t)
        reps = tuple(_EYE4 if g is _EYE4 else t @ g @ ti for g in self.reps)
        return SymmetryGroup(
            self.kind, t @ self.frame, self.pitch, reps, tuple(t @ g @ ti for g in self.lattice)
        )

    def with_discrete(
        self,
        reps: tuple[NDArray[np.float64], ...] = (),
        lattice: tuple[NDArray[np.float64], ...] = (),
        tol: Tolerance | None = None,
    ) -> SymmetryGroup:
        """G0 . Gamma for the discrete part ``reps``/``lattice`` (closure under G0 checked)."""
        tol = tol or current()
        g0 = self.connected_part
        elements = [np.asarray(g, dtype=np.float64) for g in (*reps, *lattice)]
        for g in elements:
            if not se3.is_rigid(g, tol):
                raise GroupError("a discrete group element is not a rigid transform")
            if not g0.conjugate(g).equals(g0, tol):
                raise GroupError(f"an element does not normalise the {g0.kind.value} part")
        unique = _dedupe(g0, [_EYE4, *elements[: len(reps)]], tol)
        group = SymmetryGroup(
            g0.kind, g0.frame, g0.pitch, tuple(unique), tuple(elements[len(reps) :])
        )
        if lattice:
            group._check_lattice(tol)
        for a in unique:
            for b in unique:
                if not group.contains(a @ b, tol):
                    raise GroupError("the discrete part is not closed under composition")
        return group

    def with_known_discrete(
        self,
        reps: tuple[NDArray[np.float64], ...] = (),
        lattice: tuple[NDArray[np.float64], ...] = (),
        tol: Tolerance | None = None,
    ) -> SymmetryGroup:
        """G0 . Gamma for a discrete part known to form a group with G0 (components of an
        intersection of groups, flips of a stabiliser): duplicates are merged, the
        rigidity, normaliser and closure checks of :meth:`with_discrete` are skipped
        (they cost O(n^3) membership tests for n components)."""
        g0 = self.connected_part
        unique = _dedupe(g0, [_EYE4, *reps], tol or current())
        return SymmetryGroup(g0.kind, g0.frame, g0.pitch, tuple(unique), tuple(lattice))

    def _check_lattice(self, tol: Tolerance) -> None:
        _, coords = self._lattice_projection
        if coords.shape[0] == 0 or np.linalg.matrix_rank(coords, tol=tol.length) < coords.shape[1]:
            raise GroupError("lattice generators must move along independent free directions")

    def extended_by(self, elements: Any, tol: Tolerance | None = None) -> SymmetryGroup:
        """The group generated by G and ``elements`` normalising G0 (flips, swaps, §4.1)."""
        tol = tol or current()
        g0 = self.connected_part
        extra = [np.asarray(g, dtype=np.float64) for g in elements]
        for g in extra:
            if not g0.conjugate(g).equals(g0, tol):
                raise GroupError(f"an element does not normalise the {g0.kind.value} part")
        found = _dedupe(g0, [*self.reps, *extra], tol)
        frontier = list(found)
        gens = [*self.reps[1:], *extra]
        while frontier:
            new = []
            for a in frontier:
                for b in gens:
                    c = a @ b
                    if not any(g0.contains(c @ se3.inverse(f), tol) for f in found):
                        found.append(c)
                        new.append(c)
            if len(found) > MAX_FINITE_ORDER:
                raise GroupError("the generated discrete group is not finite")
            frontier = new
        return SymmetryGroup(g0.kind, g0.frame, g0.pitch, tuple(found), self.lattice)

    # ------------------------------------------------------------------ orbits

    def orbit(self, point: Any, tol: Tolerance | None = None) -> Locus:
        """The orbit of ``point`` under G (ALGEBRA.md §2.3 orbit table)."""
        tol = tol or current()
        x = np.asarray(point, dtype=np.float64)
        if any(se3.rotation_angle(g) > tol.angle for g in self.lattice):
            raise GroupError("the orbit under a discrete screw group is not a supported locus")
        members = [self._connected_orbit(se3.apply(g, x), tol) for g in self.reps]
        if len(members) == 1 and not self.lattice:
            return members[0]
        return Locus("union", members=tuple(members), steps=tuple(g[:3, 3] for g in self.lattice))

    def _connected_orbit(self, x: NDArray[np.float64], tol: Tolerance) -> Locus:
        k, u, n = self.kind, self.axis, self.origin
        d = x - n
        radial = d - (d @ u) * u
        rho = se3.norm(radial)
        foot = n + (d @ u) * u
        if k is Kind.FIXED:
            return Locus("point", point=x)
        if k is Kind.PRISMATIC:
            return Locus("line", point=x, direction=u)
        if k in (Kind.TRANSLATION2, Kind.PLANAR):
            return Locus("plane", point=x, direction=u)
        if k is Kind.SPHERICAL:
            return Locus("sphere", point=n.copy(), radius=se3.norm(d))
        if k in (Kind.TRANSLATION3, Kind.SCHOENFLIES, Kind.FREE, Kind.PSEUDO_PLANAR):
            return Locus("space")
        if k is Kind.REVOLUTE:
            if rho <= tol.length:
                return Locus("point", point=x)
            return Locus("circle", point=foot, direction=u, radius=rho)
        if rho <= tol.length:
            return Locus("line", point=x, direction=u)
        if k is Kind.CYLINDRICAL:
            return Locus("cylinder", point=n.copy(), direction=u, radius=rho)
        return Locus("helix", point=n.copy(), direction=u, radius=rho, pitch=self.pitch, through=x)

    # ------------------------------------------------------------------ text

    def describe(self) -> str:
        """One line, e.g. "revolute about line through (0, 0, 1) along +Z" (points and
        directions by the shared formatter: axes as +Z, tiny values as 0)."""
        from assemblykit import formatting as fmt

        k, inv = self.kind, self.invariants
        if k in (Kind.REVOLUTE, Kind.CYLINDRICAL, Kind.HELICAL):
            text = (
                f"{k.value} about line through {fmt.vector(inv['point'])}"
                f" along {fmt.direction(inv['axis'])}"
            )
        elif k is Kind.SPHERICAL:
            text = f"spherical about {fmt.vector(inv['point'])}"
        elif "direction" in inv:
            text = f"{k.value} along {fmt.direction(inv['direction'])}"
        elif "normal" in inv:
            text = f"{k.value} with normal {fmt.direction(inv['normal'])}"
        else:
            text = k.value
        if k in _HELICAL:
            text += f", pitch {fmt.number(self.pitch)}"
        if len(self.reps) > 1:
            text += f", {len(self.reps)} discrete components"
        if self.lattice:
            steps = "; ".join(fmt.vector(g[:3, 3]) for g in self.lattice)
            text += f", lattice generated by steps {steps}"
        return text

    def intersect(self, other: SymmetryGroup, tol: Tolerance | None = None) -> SymmetryGroup:
        """G ∩ G' (ALGEBRA.md §2.4): :func:`assemblykit.algebra.cosets.intersect_groups`."""
        # the finite parts meet as cosets, which build on groups
        from assemblykit.algebra.cosets import intersect_groups

        return intersect_groups(self, other, tol)

    def __repr__(self) -> str:
        return f"SymmetryGroup<{self.describe()}>"


_IDENTITY = SymmetryGroup(Kind.FIXED, _EYE4)

# ----------------------------------------------------------------------------- helpers


def _scaled(basis: NDArray[np.float64], tol: Tolerance) -> NDArray[np.float64]:
    """Twists with the v rows in units of the model scale (angles and lengths comparable)."""
    out = np.array(basis, dtype=np.float64)
    out[3:] /= tol.scale
    return out


def _rank_threshold(tol: Tolerance) -> float:
    return max(tol.angle, tol.rel_length)


def _dedupe(
    g0: SymmetryGroup, elements: list[NDArray[np.float64]], tol: Tolerance
) -> list[NDArray[np.float64]]:
    """One representative per G0-coset, in order of first appearance."""
    out: list[NDArray[np.float64]] = []
    for g in elements:
        if not any(g0.contains(g @ se3.inverse(f), tol) for f in out):
            out.append(g)
    return out


def _null_space(m: NDArray[np.float64], tol: Tolerance) -> NDArray[np.float64]:
    _, s, vt = np.linalg.svd(m)
    rank = int(np.sum(s > _rank_threshold(tol)))
    return vt[rank:].T


def _tr_meet(a: SymmetryGroup, b: SymmetryGroup, tol: Tolerance) -> SymmetryGroup:
    """Closed-form intersection of two connected TR groups T(V) ⋊ Rot (§2.4, SRC 8 reading).

    The rotation parts meet as linear groups; the centres must agree modulo V_a + V_b
    (otherwise only translations remain, or, for two points, rotations about their line).
    """
    (lin_a, va), (lin_b, vb) = a._tr_shape, b._tr_shape
    v = _sub_meet(va, vb, tol)
    u: NDArray[np.float64] | None = None
    if "none" in (lin_a, lin_b):
        lin = "none"
    elif lin_a == "line" and lin_b == "line":
        lin = "line" if _parallel(a.axis, b.axis, tol) else "none"
        u = a.axis
    elif lin_a == "line" or lin_b == "line":
        lin, u = "line", (a.axis if lin_a == "line" else b.axis)
    else:
        lin = "point"
    center = a.origin
    if lin != "none":
        w = _sub_join(va, vb, tol)
        delta = a.origin - b.origin
        if lin == "line":
            assert u is not None
            if w.residual(delta - (delta @ u) * u) > tol.length:
                lin = "none"
            else:
                along = _Sub(1, u)
                center = _affine_meet_point(
                    a.origin, _sub_join(va, along, tol), b.origin, _sub_join(vb, along, tol), tol
                )
        elif w.residual(delta) > tol.length:
            # Two centres with no common translation: rotations about the line joining them.
            lin, u = "line", se3.unit(-delta)
        else:
            center = _affine_meet_point(a.origin, va, b.origin, vb, tol)
    return _tr_group(lin, u, center, v)


def _tr_group(
    lin: str, u: NDArray[np.float64] | None, center: NDArray[np.float64], v: _Sub
) -> SymmetryGroup:
    """The TR group with rotation part ``lin`` (about ``u`` through ``center``) and V = ``v``."""
    origin = (0.0, 0.0, 0.0)
    if lin == "none":
        if v.dim == 0:
            return SymmetryGroup.identity()
        if v.dim == 3:
            return SymmetryGroup.translation3()
        assert v.vec is not None
        kind = Kind.PRISMATIC if v.dim == 1 else Kind.TRANSLATION2
        return SymmetryGroup(kind, se3.frame(origin, v.vec))
    if lin == "point":
        kind = Kind.SPHERICAL if v.dim == 0 else Kind.FREE
        return SymmetryGroup(kind, se3.translation(center))
    assert u is not None
    kind = {0: Kind.REVOLUTE, 1: Kind.CYLINDRICAL, 2: Kind.PLANAR, 3: Kind.SCHOENFLIES}[v.dim]
    return SymmetryGroup(kind, se3.frame(center, u))


def classify_algebra(basis: NDArray[np.float64], tol: Tolerance | None = None) -> SymmetryGroup:
    """The connected group whose Lie algebra is spanned by ``basis`` (6 x k) (§2.1 steps 1-5)."""
    tol = tol or current()
    if basis.shape[1] == 0:
        return SymmetryGroup.identity()
    thr = _rank_threshold(tol)
    q, _ = np.linalg.qr(_scaled(basis, tol))
    q[3:] *= tol.scale
    _, s, vt = np.linalg.svd(q[:3])
    r_w = int(np.sum(s > thr))
    trans = q[3:] @ vt[r_w:].T if r_w < q.shape[1] else np.zeros((3, 0))
    tq = np.linalg.qr(trans)[0] if trans.shape[1] else trans
    r_t = tq.shape[1]
    zero = np.zeros(3)
    if r_w == 0:
        if r_t == 3:
            return SymmetryGroup.translation3()
        if r_t == 1:
            return SymmetryGroup(Kind.PRISMATIC, se3.frame(zero, tq[:, 0]))
        return SymmetryGroup(Kind.TRANSLATION2, se3.frame(zero, se3.cross(tq[:, 0], tq[:, 1])))
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
            return SymmetryGroup.connected(Kind.HELICAL if helical else Kind.REVOLUTE, f, pitch)
        if r_t == 1:
            return SymmetryGroup(Kind.CYLINDRICAL, f)
        if r_t == 2:
            kind = Kind.PSEUDO_PLANAR if helical else Kind.PLANAR
            return SymmetryGroup.connected(kind, se3.frame(zero, u), pitch)
        return SymmetryGroup(Kind.SCHOENFLIES, se3.frame(zero, u))
    if r_w == 3 and r_t == 3:
        return SymmetryGroup.free()
    if r_w == 3 and r_t == 0:
        rows = np.vstack([-se3.skew(q[:3, i]) for i in range(3)])
        center, *_ = np.linalg.lstsq(rows, q[3:].T.reshape(-1), rcond=None)
        return SymmetryGroup.spherical(center)
    raise NumericError(f"not a subalgebra of se(3): rotation rank {r_w}, translation rank {r_t}")


def _screw_generator(
    a: SymmetryGroup, b: SymmetryGroup, tol: Tolerance
) -> NDArray[np.float64] | None:
    """The discrete screw of H/Y(p) ∩ H/Y(q) about a common axis, p != q (§2.4 table).

    Solving p theta = q (theta + 2 pi m) gives theta in (2 pi q / (p - q)) Z.
    """
    if a.kind not in _HELICAL or b.kind not in _HELICAL or not _parallel(a.axis, b.axis, tol):
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
    theta = _TWO_PI * q / (a.pitch - q)
    params = [theta] if a.kind is Kind.HELICAL else [0.0, 0.0, theta]
    return a.element(params)


def _translation_lattice(
    a: SymmetryGroup, b: SymmetryGroup, tol: Tolerance
) -> list[NDArray[np.float64]]:
    """Generators of the discrete part of (G0a ∩ T3) ∩ (G0b ∩ T3) (§2.4 lattice rows)."""
    (va, ca), (vb, cb) = a._translation_part, b._translation_part
    w = _sub_meet(va, vb, tol)
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
    if not _parallel(da, db, tol):
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
        return _tr_meet(a, b, tol)
    if a.includes(b, tol):
        return b
    if b.includes(a, tol):
        return a
    ka = a.dof
    null = _null_space(_scaled(np.hstack((a.algebra, -b.algebra)), tol), tol)
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
    return SymmetryGroup(c0.kind, c0.frame, c0.pitch, (_EYE4,), tuple(gens))


def lattice_meet(a: SymmetryGroup, b: SymmetryGroup, tol: Tolerance) -> SymmetryGroup:
    """G ∩ G' when one side is a cyclic lattice <tau> (trivial G0): the sublattice
    <tau^m> inside the other group (§2.4 "Finite parts").

    Closed form when the other group is connected or cyclic: m comes from the rational
    test on the one-parameter group through tau (:func:`_cyclic_meet`). Otherwise the
    first power k = 1..MAX_LATTICE_DENOMINATOR with tau^k in the other group generates it.
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
    for _ in range(MAX_LATTICE_DENOMINATOR):
        power = power @ tau
        if b.contains(power, tol):
            return SymmetryGroup(Kind.FIXED, np.eye(4), 0.0, (_EYE4,), (power,))
    return SymmetryGroup.identity()


def _is_cyclic(g: SymmetryGroup) -> bool:
    """Whether G = <tau> is an infinite cyclic group (one lattice generator, trivial G0)."""
    return g.kind is Kind.FIXED and len(g.reps) == 1 and len(g.lattice) == 1


def one_parameter(tau: NDArray[np.float64], tol: Tolerance | None = None) -> SymmetryGroup | None:
    """The connected one-parameter group {exp(s log tau)} through a lattice generator
    that translates along its axis (a translation: T; a screw: H), else ``None``.

    Its elements are exp(s log tau), with s the ratio of their translation along the
    axis to that of tau (:func:`lattice_parameter`).
    """
    tol = tol or current()
    group = classify_algebra(se3.log(tau)[:, None], tol)
    if group.kind not in (Kind.PRISMATIC, Kind.HELICAL):
        return None
    if abs(float(group.axis @ tau[:3, 3])) <= tol.length:
        return None
    return group


def lattice_parameter(
    line: SymmetryGroup, tau: NDArray[np.float64], g: NDArray[np.float64]
) -> float:
    """s with g = exp(s log tau), for g in the one-parameter group ``line`` through tau:
    rotations about the axis leave the translation along it additive."""
    u = line.axis
    return float(u @ g[:3, 3]) / float(u @ tau[:3, 3])


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
        return SymmetryGroup(Kind.FIXED, np.eye(4), 0.0, (_EYE4,), (tau,))
    if not met.lattice:
        return SymmetryGroup.identity()
    frac = commensurate(lattice_parameter(line, tau, met.lattice[0]), tol)
    if frac is None:
        return SymmetryGroup.identity()
    power = np.linalg.matrix_power(tau, abs(frac.numerator))
    if not b.contains(power, tol):
        return None
    return SymmetryGroup(Kind.FIXED, np.eye(4), 0.0, (_EYE4,), (power,))
