"""Right cosets H . x0 of symmetry groups, their intersections and products
(docs/algebra.md §2.5, §5.2-§5.3).

A relation between body 1 and body 2 is the set of relative positions X = L1^-1 L2;
for lower pairs it is a right coset H . x0 with H in body 1's frame. Intersections
are cosets of the intersected group or empty; products are cosets only when the two
groups permute (otherwise a :class:`Chain`). Transporters of characteristic invariants
(:mod:`assemblykit.algebra.invariants` finds X0 and Stab) are cosets too. Coset
intersections meet the groups of connected cosets and cyclic lattices directly
(:mod:`assemblykit.algebra.connected_meets`).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np

from assemblykit import formatting as fmt
from assemblykit.algebra import invariants as inv
from assemblykit.algebra import se3
from assemblykit.algebra.caching import cached
from assemblykit.algebra.connected_meets import connected_meet, lattice_meet, tr_meet
from assemblykit.algebra.groups import (
    IDENTITY_MATRIX,
    SymmetryGroup,
    classify_algebra,
    lattice_parameter,
    one_parameter,
)
from assemblykit.algebra.invariants import Invariant, LineInvariant, Mismatch, MismatchKind
from assemblykit.algebra.lattices import IntegerPoints, commensurate, integer_points
from assemblykit.algebra.lie import (
    Kind,
    RotationPart,
    helix_residual,
    rank_threshold,
    scaled_twists,
)
from assemblykit.algebra.subspaces import Subspace
from assemblykit.errors import GroupError, NumericError
from assemblykit.tolerance import Tolerance, current

__all__ = [
    "Chain",
    "Coset",
    "EmptySet",
    "stabilizer",
    "transporter",
]

#: Starts of the deterministic multi-start least squares (docs/algebra.md §2.5 "Numeric fallback").
NUMERIC_STARTS = 24

#: Lattice steps tried on each side when intersecting a lattice coset.
LATTICE_SEARCH = 64

_TRANSLATIONS = frozenset({Kind.FIXED, Kind.PRISMATIC, Kind.TRANSLATION2, Kind.TRANSLATION3})
_CONTAINS_T3 = frozenset({Kind.TRANSLATION3, Kind.SCHOENFLIES, Kind.FREE})
# Products of connected groups that are groups once the bracket test passes (§5.3 table).
_PRODUCT_GROUPS = frozenset(
    frozenset(pair)
    for pair in (
        (Kind.REVOLUTE, Kind.PRISMATIC),
        (Kind.HELICAL, Kind.PRISMATIC),
        (Kind.REVOLUTE, Kind.HELICAL),
        (Kind.HELICAL, Kind.HELICAL),
        (Kind.REVOLUTE, Kind.TRANSLATION2),
        (Kind.HELICAL, Kind.TRANSLATION2),
        (Kind.CYLINDRICAL, Kind.TRANSLATION2),
        (Kind.PLANAR, Kind.PRISMATIC),
        (Kind.PSEUDO_PLANAR, Kind.PRISMATIC),
        (Kind.PLANAR, Kind.PSEUDO_PLANAR),
        (Kind.PLANAR, Kind.CYLINDRICAL),
        (Kind.PLANAR, Kind.HELICAL),
        (Kind.PSEUDO_PLANAR, Kind.PSEUDO_PLANAR),
        (Kind.PSEUDO_PLANAR, Kind.CYLINDRICAL),
        (Kind.PSEUDO_PLANAR, Kind.HELICAL),
    )
)


@dataclass(frozen=True)
class EmptySet:
    """The empty relation. ``proven=False`` means only that the numeric search found no
    solution: "no solution found", never a claim of emptiness (§2.5)."""

    mismatch: Mismatch
    proven: bool = True

    @property
    def dof(self) -> int:
        """Not a manifold: reported as -1."""
        return -1

    @property
    def n_components(self) -> int:
        """No components."""
        return 0

    def contains(self, x: np.ndarray, tol: Tolerance | None = None) -> bool:
        """Nothing is in the empty set."""
        return False


@dataclass(frozen=True, eq=False)
class Coset:
    """The right coset H . x0 (``group`` H in body 1's frame, ``rep`` x0), docs/algebra.md §2.2."""

    group: SymmetryGroup
    rep: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "rep", np.asarray(self.rep, dtype=np.float64))

    # ------------------------------------------------------------------ properties

    @property
    def dof(self) -> int:
        """Dimension of the coset (that of H0)."""
        return self.group.dof

    @property
    def kind(self) -> Kind:
        """The Hervé kind of H0."""
        return self.group.kind

    @property
    def n_components(self) -> float | int:
        """Number of components (``math.inf`` for a lattice)."""
        return self.group.n_components

    @property
    def is_point(self) -> bool:
        """A single relative position (dof 0, one component): merge on identity."""
        return self.dof == 0 and self.n_components == 1

    def points(self) -> list[np.ndarray]:
        """The finitely many elements of a dof-0 finite coset."""
        if self.dof != 0 or self.group.lattice:
            raise GroupError(f"a {self.kind.value} coset is not a finite set of points")
        return [self.group.element((), i) @ self.rep for i in range(len(self.group.reps))]

    @cached
    def rep_inverse(self) -> np.ndarray:
        """x0^-1 (cached: membership and intersections use it)."""
        return se3.inverse(self.rep)

    @cached
    def transporter_flats(self) -> tuple[tuple[Any, ...], tuple[Any, ...]]:
        """The characteristic invariants of a TR group H as floats (§2.4), and the same
        moved by x0^-1: the objects of body 2 that the relation maps onto them (§2.5
        transporter; cached for repeated intersections)."""
        body1 = inv.characteristic_flats(self.group.kind, self.group.frame)
        return body1, inv.move_flats(self.rep, body1, inverse=True)

    def invariants(self) -> dict[str, Any]:
        """Invariants of the set in body-1 coordinates (those of H, e.g. the axis line)."""
        return self.group.invariants

    def sample(self, rng: np.random.Generator, n: int = 1) -> list[np.ndarray]:
        """``n`` random members."""
        return [g @ self.rep for g in self.group.sample(rng, n)]

    def describe(self) -> str:
        """One line: the group and the representative's translation."""
        return f"{self.group.describe()} . x0 (x0 translation {self.rep[:3, 3].round(9).tolist()})"

    def __repr__(self) -> str:
        """One line in words, e.g. ``Coset(revolute, 1 dof, axis through (0, 0, 0) along
        +Z)``: the kind, the dof, the invariants that place it (those of a fixed coset:
        the representative's translation) and its discrete components."""
        inv = self.group.invariants
        if "axis" in inv:
            where = f"axis through {fmt.vector(inv['point'])} along {fmt.direction(inv['axis'])}"
        elif "point" in inv:
            where = f"about {fmt.vector(inv['point'])}"
        elif "direction" in inv:
            where = f"along {fmt.direction(inv['direction'])}"
        elif "normal" in inv:
            where = f"normal {fmt.direction(inv['normal'])}"
        elif self.kind is Kind.FIXED:
            where = f"at {fmt.vector(self.rep[:3, 3])}"
        else:
            where = ""
        pitch = f"pitch {fmt.number(inv['pitch'])}" if "pitch" in inv else ""
        if self.group.lattice:
            parts = "a lattice of components"
        else:
            parts = fmt.count(len(self.group.reps), "component") if len(self.group.reps) > 1 else ""
        return fmt.summary(
            "Coset", self.kind.value, fmt.count(self.dof, "dof", "dof"), where, pitch, parts
        )

    # ------------------------------------------------------------------ set operations

    def contains(self, x: np.ndarray, tol: Tolerance | None = None) -> bool:
        """Whether ``x`` in H . x0, i.e. x x0^-1 in H."""
        return self.group.contains(np.asarray(x, float) @ self.rep_inverse, tol)

    def inverse(self) -> Coset:
        """(H x0)^-1 = (x0^-1 H x0) . x0^-1 (§5.2 reversal)."""
        ri = se3.inverse(self.rep)
        return Coset(self.group.conjugate(ri), ri)

    def left(self, t: np.ndarray) -> Coset:
        """T . (H x0) = (T H T^-1) . T x0."""
        return Coset(self.group.conjugate(t), t @ self.rep)

    def right(self, t: np.ndarray) -> Coset:
        """(H x0) . T."""
        return Coset(self.group, self.rep @ t)

    def conjugate(self, t: np.ndarray) -> Coset:
        """T (H x0) T^-1."""
        return Coset(self.group.conjugate(t), t @ self.rep @ se3.inverse(t))

    def intersect(self, other: Coset, tol: Tolerance | None = None) -> Coset | EmptySet:
        """(A a) ∩ (B b) = (A ∩ B) . c for any common c, or empty (docs/algebra.md §2.5).

        TR groups: transporter of the characteristic invariants (closed form, with the
        failed congruence test when empty). Helical groups: the exact group meet and a
        common point from the numeric fallback. Finite parts: the pairs of components that
        may meet (:func:`_component_pairs`), with the result of meeting every pair.
        """
        tol = tol or current()
        if isinstance(other, Chain):
            raise GroupError(
                "a chain ∩ coset needs the chain solvers (docs/algebra.md §5.2 rule 4)"
            )
        if self.group.lattice or other.group.lattice:
            return _lattice_coset_meet(self, other, tol)
        if self.group.is_connected and other.group.is_connected:
            return _connected_meet(self, other, tol)
        a, b = self.group, other.group
        a0, b0 = a.connected_part, b.connected_part
        pieces = [
            _connected_meet(Coset(a0, a.reps[i] @ self.rep), Coset(b0, b.reps[j] @ other.rep), tol)
            for i, j in _component_pairs(self, other, tol)
        ]
        found = [p for p in pieces if isinstance(p, Coset)]
        if not found:
            empties = [p for p in pieces if isinstance(p, EmptySet)]
            return next((e for e in empties if not e.proven), empties[0])
        base = found[0]
        extra = tuple(c.rep @ se3.inverse(base.rep) for c in found[1:])
        group = base.group.with_known_discrete(extra, base.group.lattice, tol)
        return Coset(group, base.rep)

    def product(self, other: Coset | Chain, tol: Tolerance | None = None) -> Coset | Chain:
        """(A a)(B b) = A (a B a^-1) . ab: a coset iff A and K = a B a^-1 permute
        (bracket test to reject, the §5.3 table to accept), else a :class:`Chain`."""
        tol = tol or current()
        if isinstance(other, Chain):
            return Chain((self, *other.factors))
        a_grp = self.group
        k_grp = other.group.conjugate(self.rep)
        rep = self.rep @ other.rep
        if a_grp.includes(k_grp, tol):
            return Coset(a_grp, rep)
        if k_grp.includes(a_grp, tol):
            return Coset(k_grp, rep)
        group = _group_product(a_grp, k_grp, tol)
        return Chain((self, other)) if group is None else Coset(group, rep)


def _component_pairs(p: Coset, q: Coset, tol: Tolerance) -> list[tuple[int, int]]:
    """The pairs (i, j) of components A0 alpha_i a of P = A a and B0 beta_j b of Q = B b
    that may meet, in the order of all pairs and with (0, 0) first (docs/algebra.md §2.5
    "Finite parts").

    When B0 ⊂ A0, A0 alpha a ∩ B0 beta b is B0 beta b if beta b a^-1 is in A0 alpha and
    empty otherwise, so each beta needs only the components of A near beta b a^-1
    (:meth:`SymmetryGroup.components_near`); likewise when A0 ⊂ B0. The pairs are cut
    only when the meets of components are in closed form (both groups TR, or one of
    them of dof 0): their empty answers are all proven, so when no pair meets, the
    answer of the pair (0, 0) is the result, as with every pair met. Otherwise every pair.
    """
    a, b = p.group, q.group
    closed_form = (a.is_tr and b.is_tr) or a.dof == 0 or b.dof == 0
    if closed_form and a.connected_part.includes(b.connected_part, tol):
        shift = q.rep @ p.rep_inverse
        near = [
            (i, j) for j, beta in enumerate(b.reps) for i in a.components_near(beta @ shift, tol)
        ]
    elif closed_form and b.connected_part.includes(a.connected_part, tol):
        shift = p.rep @ q.rep_inverse
        near = [
            (i, j) for i, alpha in enumerate(a.reps) for j in b.components_near(alpha @ shift, tol)
        ]
    else:
        return list(itertools.product(range(len(a.reps)), range(len(b.reps))))
    return sorted({(0, 0), *near})


def _lattice_steps(bound: int) -> list[int]:
    """0, 1, -1, 2, -2, ... up to +-bound."""
    return [0, *(s * k for k in range(1, bound + 1) for s in (1, -1))]


def _lattice_coset_meet(p: Coset, q: Coset, tol: Tolerance) -> Coset | EmptySet:
    """(G0 <tau> Gamma a) ∩ Q: the group meet, and a common point in closed form for a
    trivial G0 (:func:`_cyclic_coset_meet`); otherwise searched over the lattice steps
    k = 0, +-1, ... (each step a connected coset intersection). Without a hit within
    ``LATTICE_SEARCH`` steps the answer is "no solution found"."""
    lat, other = (p, q) if p.group.lattice else (q, p)
    if len(lat.group.lattice) != 1 or other.group.lattice:
        raise GroupError("intersection of cosets of these lattice groups is not supported")
    group = lattice_meet(p.group, q.group, tol)
    if lat.group.kind is Kind.FIXED:
        found = _cyclic_coset_meet(lat, other, group, tol)
        if found is not None:
            return found
    g0, tau = lat.group.connected_part, lat.group.lattice[0]
    o0 = other.group.connected_part
    for k in _lattice_steps(LATTICE_SEARCH):
        step = lat.group.element(np.zeros(g0.dof), 0, (k,)) @ se3.inverse(lat.group.reps[0])
        for gamma, beta in itertools.product(lat.group.reps, other.group.reps):
            piece = _connected_meet(
                Coset(g0, step @ gamma @ lat.rep), Coset(o0, beta @ other.rep), tol
            )
            if isinstance(piece, Coset):
                return Coset(group, piece.rep)
    message = f"no lattice element found within {LATTICE_SEARCH} steps of {tau[:3, 3].tolist()}"
    return EmptySet(Mismatch(MismatchKind.RESIDUAL, math.inf, message), proven=False)


def _cyclic_coset_meet(
    lat: Coset, other: Coset, group: SymmetryGroup, tol: Tolerance
) -> Coset | EmptySet | None:
    """(<tau> Gamma a) ∩ Q in closed form (§2.4 "Finite parts", §7), ``group`` being the
    group meet.

    For each component gamma a, the one-parameter group L through tau gives the hull
    L gamma a ⊃ {tau^k gamma a}; its intersection with Q is empty or K d with K ⊂ L.
    Writing d = exp(s0 log tau) gamma a and K = L, {I} or <exp(c log tau)>, the
    common points are the integers k in s0 + cZ (:func:`integer_points`). ``None``
    when no closed form applies (no axial translation, an unproven empty hull meet or
    an incommensurate c): the caller searches.
    """
    tau = lat.group.lattice[0]
    line = one_parameter(tau, tol)
    if line is None:
        return None
    along = float(line.axis @ tau[:3, 3])
    empty: EmptySet | None = None
    for gamma in lat.group.reps:
        base = gamma @ lat.rep
        hull = Coset(line, base).intersect(other, tol)
        if isinstance(hull, EmptySet):
            if not hull.proven:
                return None
            empty = empty or hull
            continue
        met = hull.group
        if met.dof > 0:
            points = IntegerPoints(0, 1)
        else:
            s0 = lattice_parameter(line, tau, hull.rep @ se3.inverse(base))
            period: Fraction | None = Fraction(0)
            if met.lattice:
                period = commensurate(lattice_parameter(line, tau, met.lattice[0]), tol)
            if period is None:
                return None
            found = integer_points(s0, period, along, tol)
            if found is None:
                miss = abs(s0 - round(s0)) * abs(along)
                text = f"the lattice steps of {abs(along):.6g} miss the other set"
                empty = empty or EmptySet(Mismatch(MismatchKind.DISTANCE, miss, text))
                continue
            points = found
        c = lat.group.element((), 0, (points.start,)) @ base
        if not (lat.contains(c, tol) and other.contains(c, tol)):
            return None
        return Coset(group, c)
    assert empty is not None
    return empty


def _connected_meet(p: Coset, q: Coset, tol: Tolerance) -> Coset | EmptySet:
    """The intersection of two cosets of connected groups (§2.5): a point tested for
    membership, the transporter of TR groups, the helical closed form, else the numeric
    fallback."""
    for point, other in ((p, q), (q, p)):
        if point.dof == 0:
            if other.contains(point.rep, tol):
                return point
            if not (p.group.is_tr and q.group.is_tr):
                return EmptySet(
                    Mismatch(MismatchKind.RESIDUAL, 1.0, "the fixed position is not in the set")
                )
    if p.group.is_tr and q.group.is_tr:
        (ta, sa), (tb, sb) = p.transporter_flats, q.transporter_flats
        return flat_transporter(ta + tb, sa + sb, tr_meet(p.group, q.group, tol), tol)
    if p.group.is_tr or q.group.is_tr:
        helical, other = (q, p) if p.group.is_tr else (p, q)
        found = _helical_meet(helical, other, tol)
        if found is not None:
            return found
    return _numeric_meet(p, q, tol)


#: The TR hull of each helical family: C(N, u) contains H(N, u, p), X(u) contains Y(u, p).
_HULL = {Kind.HELICAL: Kind.CYLINDRICAL, Kind.PSEUDO_PLANAR: Kind.SCHOENFLIES}


def _screw_coordinates(group: SymmetryGroup, g: np.ndarray) -> tuple[float, float]:
    """(rotation angle about the axis, translation along it) of ``g`` in the group frame."""
    c = group.frame_inverse @ g @ group.frame
    return math.atan2(c[1, 0], c[0, 0]), float(c[2, 3])


def _helical_meet(p: Coset, q: Coset, tol: Tolerance) -> Coset | EmptySet | None:
    """(H a) ∩ (B b) for a helical or pseudo-planar H and a TR group B, in closed form
    (docs/algebra.md §2.4 table, §2.5): a one-parameter problem in the screw angle.

    The TR hull C of H (C(N, u) for H(N, u, p), X(u) for Y(u, p)) meets B b a^-1 in a
    TR coset K d (closed form; empty means empty, as H ⊂ C). Within K d the screw
    condition t_u = p (theta + 2 pi n) is solved exactly: a rotation of K about u fixes
    theta (a thread against a face: the angle is fixed by the offset); otherwise a
    translation of K with a component along u fixes the axial position (a thread and a
    key: the lead lattice); otherwise d, moved onto the nearest turn, is the only
    candidate. ``None`` when the membership check of the constructed point fails within
    rounding (the caller then searches numerically, never claiming emptiness).
    """
    h = p.group
    hull = SymmetryGroup(_HULL[h.kind], h.frame)
    target = Coset(q.group, q.rep @ p.rep_inverse)
    found = _connected_meet(Coset(hull, np.eye(4)), target, tol)
    if isinstance(found, EmptySet):
        return found
    k, d = found.group, found.rep
    theta, shift = _screw_coordinates(h, d)
    u = h.axis
    w = _steepest_translation(k.tr_shape[1], u)
    along = float(w @ u)
    if k.tr_shape[0] is RotationPart.LINE:
        step = se3.rotation(u, shift / h.pitch - theta, k.origin)
    elif abs(along) > tol.angle:
        step = se3.translation(w * ((h.pitch * theta - shift) / along))
    else:
        # d is the only candidate up to whole turns: slide it along the axis onto the
        # nearest turn of the helix and test the other relation by its residual (stable
        # when d itself is ill-conditioned along the axis, e.g. an axis almost in a face).
        turns = round((shift / h.pitch - theta) / (2.0 * math.pi))
        step = se3.translation(u * (h.pitch * (theta + 2.0 * math.pi * turns) - shift))
        c = step @ d @ p.rep
        if p.contains(c, tol) and q.contains(c, tol):
            return Coset(connected_meet(p.group, q.group, tol), c)
        miss = helix_residual(h.pitch, shift, theta)
        if miss <= tol.length:
            return None
        text = f"the positions miss the screw's phase by {miss:.6g} along its axis"
        return EmptySet(Mismatch(MismatchKind.DISTANCE, miss, text))
    c = step @ d @ p.rep
    if not (p.contains(c, tol) and q.contains(c, tol)):
        return None
    return Coset(connected_meet(p.group, q.group, tol), c)


def _steepest_translation(v: Subspace, u: np.ndarray) -> np.ndarray:
    """The unit vector of the subspace ``v`` with the largest component along ``u``
    (zero when ``v`` is trivial)."""
    if v.dim == 0:
        return np.zeros(3)
    if v.dim == 3:
        return u
    assert v.vec is not None
    if v.dim == 1:
        return v.vec
    return se3.unit(u - float(u @ v.vec) * v.vec)


def _residual_vector(d: np.ndarray, scale: float) -> np.ndarray:
    """The 12 entries of a difference of transforms, rotation rows scaled to lengths."""
    return np.concatenate(((d[:3, :3] * scale).ravel(), d[:3, 3]))


def _multistart(
    residual: Callable[[np.ndarray], np.ndarray], angles: np.ndarray, length: float
) -> Iterator[Any]:
    """The fits of the deterministic multi-start over group parameters (§2.5 "Numeric
    fallback"): :data:`NUMERIC_STARTS` starts, Levenberg-Marquardt while the 12 residual
    entries are at least as many as the parameters."""
    starts = se3.random_starts(angles, length, NUMERIC_STARTS)
    method = "lm" if angles.size <= 12 else "trf"
    return se3.multistart_least_squares(residual, starts, method=method)


def _numeric_meet(p: Coset, q: Coset, tol: Tolerance) -> Coset | EmptySet:
    """A common point from least squares over both parameterisations, from a deterministic
    multi-start (§2.5 "Numeric fallback"); never claims emptiness."""
    a, b = p.group, q.group
    group = connected_meet(a, b, tol)
    na = a.dof
    length = max(tol.scale, se3.norm(p.rep[:3, 3]), se3.norm(q.rep[:3, 3]))
    angles = np.concatenate((a.angle_parameters(), b.angle_parameters()))

    def residual(x: np.ndarray) -> np.ndarray:
        d = a.element(x[:na]) @ p.rep - b.element(x[na:]) @ q.rep
        return _residual_vector(d, length)

    best = math.inf
    for sol in _multistart(residual, angles, length):
        best = min(best, float(np.max(np.abs(sol.fun))))
        c = a.element(sol.x[:na]) @ p.rep
        if p.contains(c, tol) and q.contains(c, tol):
            return Coset(group, c)
    return EmptySet(
        Mismatch(MismatchKind.RESIDUAL, best, f"no solution found (best residual {best:.3g})"),
        proven=False,
    )


def _bracket(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The Lie bracket of twists (omega; v): (w1 x w2; w1 x v2 - w2 x v1)."""
    return np.concatenate(
        (se3.cross(x[:3], y[:3]), se3.cross(x[:3], y[3:]) - se3.cross(y[:3], x[3:]))
    )


def _group_product(a: SymmetryGroup, k: SymmetryGroup, tol: Tolerance) -> SymmetryGroup | None:
    """The group A K when it is one (§5.3), else ``None``."""
    if a.lattice or k.lattice:
        return None
    basis = np.hstack((a.algebra, k.algebra))
    scaled = scaled_twists(basis, tol)
    u, s, _ = np.linalg.svd(scaled, full_matrices=False)
    q = u[:, : int(np.sum(s > rank_threshold(tol)))]
    for i, j in itertools.combinations(range(basis.shape[1]), 2):
        br = scaled_twists(_bracket(basis[:, i], basis[:, j])[:, None], tol)
        if float(np.max(np.abs(br - q @ (q.T @ br)))) > rank_threshold(tol):
            return None
    kinds = frozenset({a.kind, k.kind})
    accepted = (
        kinds <= _TRANSLATIONS
        or a.kind in _CONTAINS_T3
        or k.kind in _CONTAINS_T3
        or kinds in _PRODUCT_GROUPS
    )
    if not accepted:
        return None
    unscaled = q.copy()
    unscaled[3:] *= tol.scale
    try:
        g0 = classify_algebra(unscaled, tol)
    except NumericError:
        # closed under brackets only within a loose tolerance (nearly parallel axes of
        # rounded numbers): no group of the table, so the product stays a chain
        return None
    if a.is_connected and k.is_connected:
        return g0
    k0 = k.connected_part
    if not all(k0.conjugate(alpha).equals(k0, tol) for alpha in a.reps):
        return None
    reps = tuple(alpha @ kappa for alpha in a.reps for kappa in k.reps)
    try:
        return g0.with_discrete(reps=reps, tol=tol)
    except GroupError:
        return None


@dataclass(frozen=True, eq=False)
class Chain:
    """A product of cosets that is not a coset (§5.2 rule 3): the set
    H1 x1 H2 x2 ... Hn xn of relative positions."""

    factors: tuple[Coset, ...]

    @property
    def kind(self) -> str:
        """Always "chain"."""
        return "chain"

    def product(self, other: Coset | Chain) -> Chain:
        """The longer chain (self . other)."""
        more = other.factors if isinstance(other, Chain) else (other,)
        return Chain((*self.factors, *more))

    def _compose(self, params: np.ndarray, components: tuple[int, ...]) -> np.ndarray:
        out = np.eye(4)
        start = 0
        for f, comp in zip(self.factors, components, strict=True):
            out = out @ f.group.element(params[start : start + f.dof], comp) @ f.rep
            start += f.dof
        return out

    @cached
    def dof(self) -> int:
        """Dimension of h1 + Ad(g1) h2 + Ad(g1 g2) h3 + ... at generic points (max over a
        few deterministic samples)."""
        rng = np.random.default_rng(0)
        tol = current()
        best = 0
        for _ in range(4):
            cols, prefix = [], np.eye(4)
            for f in self.factors:
                cols.append(se3.adjoint(prefix) @ f.group.algebra)
                prefix = prefix @ f.sample(rng, 1)[0]
            stacked = scaled_twists(np.hstack(cols), tol)
            if stacked.size:
                s = np.linalg.svd(stacked, compute_uv=False)
                best = max(best, int(np.sum(s > rank_threshold(tol) * max(1.0, s[0]))))
        return best

    def sample(self, rng: np.random.Generator, n: int = 1) -> list[np.ndarray]:
        """``n`` random members (products of random members of each factor)."""
        out = []
        for _ in range(n):
            g = np.eye(4)
            for f in self.factors:
                g = g @ f.sample(rng, 1)[0]
            out.append(g)
        return out

    def contains(self, x: np.ndarray, tol: Tolerance | None = None) -> bool:
        """Whether ``x`` is in the product set, by least squares over the factors'
        parameters from a deterministic multi-start."""
        tol = tol or current()
        x = np.asarray(x, dtype=np.float64)
        if any(f.group.lattice for f in self.factors):
            raise GroupError("membership in a chain of lattice cosets is not supported")
        angles = np.concatenate([f.group.angle_parameters() for f in self.factors])
        length = max(tol.scale, se3.norm(x[:3, 3]))
        length = max([length] + [se3.norm(f.rep[:3, 3]) for f in self.factors])
        comps = itertools.product(*(range(len(f.group.reps)) for f in self.factors))
        for components in comps:

            def residual(p: np.ndarray, comp: tuple[int, ...] = components) -> np.ndarray:
                return _residual_vector(self._compose(p, comp) - x, length)

            for sol in _multistart(residual, angles, length):
                d = self._compose(sol.x, components) @ se3.inverse(x)
                if se3.poses_equal(d, IDENTITY_MATRIX, tol):
                    return True
        return False


# ----------------------------------------------------------------------------- transporters


def flat_transporter(
    targets: tuple[Any, ...], sources: tuple[Any, ...], group: SymmetryGroup, tol: Tolerance
) -> Coset | EmptySet:
    """The transporter of directed float invariants whose targets have stabiliser
    ``group`` (§2.5 closed form, :func:`assemblykit.algebra.invariants.flat_transport`)."""
    found = inv.flat_transport(targets, sources, tol)
    if isinstance(found, Mismatch):
        return EmptySet(found)
    return Coset(group, found)


def _directed_transporter(
    targets: tuple[Invariant, ...], sources: tuple[Invariant, ...], tol: Tolerance
) -> Coset | EmptySet:
    found = inv.directed_transport(targets, sources, tol)
    if isinstance(found, Mismatch):
        return EmptySet(found)
    return Coset(*found)


def transporter(
    targets: tuple[Invariant, ...] | list[Invariant],
    sources: tuple[Invariant, ...] | list[Invariant],
    tol: Tolerance | None = None,
) -> Coset | EmptySet:
    """{X in SE(3) : X . sources[i] = targets[i] for all i} (docs/algebra.md §2.5).

    ``targets`` are in body-1 coordinates, ``sources`` in body-2 coordinates. Empty when
    the tuples are not congruent (the first failing test is reported); undirected lines
    give a union over the direction choices, i.e. extra components.
    """
    tol = tol or current()
    choices = inv.direction_choices(tuple(targets), tuple(sources))
    if isinstance(choices, Mismatch):
        return EmptySet(choices)
    directed_t, variants = choices
    results = [_directed_transporter(directed_t, s, tol) for s in variants]
    if len(results) == 1:
        return results[0]
    cosets = [r for r in results if isinstance(r, Coset)]
    if not cosets:
        return results[0]
    base = cosets[0]
    reps = tuple(c.rep @ se3.inverse(base.rep) for c in cosets[1:])
    return Coset(base.group.with_known_discrete(reps=reps, tol=tol), base.rep)


def stabilizer(
    invariants: tuple[Invariant, ...] | list[Invariant], tol: Tolerance | None = None
) -> SymmetryGroup:
    """The group fixing every invariant; undirected lines contribute flips (§2.4)."""
    tol = tol or current()
    invs = tuple(invariants)
    if all(not isinstance(i, LineInvariant) or i.directed for i in invs):
        return inv.directed_stabilizer(invs, tol)
    result = transporter(invs, invs, tol)
    assert isinstance(result, Coset)
    return result.group
