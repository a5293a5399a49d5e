"""Linear and affine subspaces of R^3 in closed form, and the minimum-norm solution of
the symmetric positive semi-definite 3x3 systems that meet them (docs/algebra.md §2.4: the
translation parts V of TR groups and the centres of their meets).

A subspace keeps only its dimension and one unit vector (dim 1: its direction, dim 2:
its normal); the arithmetic is plain floats, as it runs on the hot path of every
closed-form coset intersection (§2.5).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from assemblykit.algebra import se3
from assemblykit.tolerance import Tolerance

__all__ = [
    "Subspace",
    "Sym3",
    "Vec3",
    "affine_meet_point",
    "parallel",
    "psd_solve",
    "subspace_join",
    "subspace_meet",
    "unit_cross",
]

#: A symmetric 3x3 matrix by its upper triangle (m00, m01, m02, m11, m12, m22).
Sym3 = tuple[float, float, float, float, float, float]
#: A 3-vector as Python floats.
Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class Subspace:
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


def parallel(a: NDArray[np.float64], b: NDArray[np.float64], tol: Tolerance) -> bool:
    """Whether the unit vectors ``a`` and ``b`` are parallel or antiparallel (the sine of
    their angle within the angular tolerance)."""
    a0, a1, a2 = se3.as_floats(a)
    b0, b1, b2 = se3.as_floats(b)
    c0, c1, c2 = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
    return math.sqrt(c0 * c0 + c1 * c1 + c2 * c2) <= tol.angle


def unit_cross(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """The unit vector along a x b (a and b not parallel)."""
    a0, a1, a2 = se3.as_floats(a)
    b0, b1, b2 = se3.as_floats(b)
    c0, c1, c2 = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
    size = math.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
    return np.array((c0 / size, c1 / size, c2 / size))


def subspace_meet(a: Subspace, b: Subspace, tol: Tolerance) -> Subspace:
    """Intersection of two subspaces of R^3."""
    if a.dim == 0 or b.dim == 3:
        return a
    if b.dim == 0 or a.dim == 3:
        return b
    assert a.vec is not None and b.vec is not None
    if a.dim == 1 and b.dim == 1:
        return a if parallel(a.vec, b.vec, tol) else Subspace(0)
    if a.dim == 2 and b.dim == 2:
        if parallel(a.vec, b.vec, tol):
            return a
        return Subspace(1, unit_cross(a.vec, b.vec))
    line, plane = (a, b) if a.dim == 1 else (b, a)
    assert line.vec is not None and plane.vec is not None
    return line if abs(float(line.vec @ plane.vec)) <= tol.angle else Subspace(0)


def subspace_join(a: Subspace, b: Subspace, tol: Tolerance) -> Subspace:
    """Sum of two subspaces of R^3."""
    if a.dim == 0 or b.dim == 3:
        return b
    if b.dim == 0 or a.dim == 3:
        return a
    assert a.vec is not None and b.vec is not None
    if a.dim == 1 and b.dim == 1:
        if parallel(a.vec, b.vec, tol):
            return a
        return Subspace(2, unit_cross(a.vec, b.vec))
    if a.dim == 2 and b.dim == 2:
        return a if parallel(a.vec, b.vec, tol) else Subspace(3)
    line, plane = (a, b) if a.dim == 1 else (b, a)
    assert line.vec is not None and plane.vec is not None
    return plane if abs(float(line.vec @ plane.vec)) <= tol.angle else Subspace(3)


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


def affine_meet_point(
    na: NDArray[np.float64], sa: Subspace, nb: NDArray[np.float64], sb: Subspace, tol: Tolerance
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
