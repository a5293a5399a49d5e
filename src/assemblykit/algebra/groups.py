"""Symmetry subgroups of SE(3): G = G0 . Gamma (docs/algebra.md §2.2).

G0 is one of Hervé's 12 connected families (§2.1, :mod:`assemblykit.algebra.lie`)
placed by a frame F (G0 = F K F^-1 with K canonical: axis/normal +z through the
origin); Gamma is a finite transversal ``reps`` (always containing I) and optional
``lattice`` generators of an infinite discrete quotient (helical lattices, §2.2).
Components are looked up by coset keys (§2.3 "Discrete parts"), so the operations on
Gamma cost about |Gamma|, not |Gamma|^2.
"""

from __future__ import annotations

import importlib
import math
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from assemblykit.algebra import se3
from assemblykit.algebra.caching import cached
from assemblykit.algebra.lie import (
    DIMENSION,
    HELICAL_KINDS,
    ROTATIONS,
    Kind,
    RotationPart,
    canonical_basis,
    canonical_element,
    classify_subalgebra,
    in_canonical,
    rank_threshold,
    scaled_twists,
)
from assemblykit.algebra.loci import Locus, LocusKind
from assemblykit.algebra.subspaces import Subspace, subspace_meet
from assemblykit.errors import GroupError
from assemblykit.tolerance import Tolerance, current

__all__ = [
    "IDENTITY_MATRIX",
    "MAX_FINITE_ORDER",
    "MEET_SPREAD",
    "SymmetryGroup",
    "classify_algebra",
    "lattice_parameter",
    "one_parameter",
]

#: Largest finite group built by closure (``extended_by``); beyond it the group is not finite.
MAX_FINITE_ORDER = 1_000

#: How far, in multiples of the bound on a tolerance's effect on coset keys, the meet of
#: two discrete groups looks for the components that may meet (:meth:`components_near`).
MEET_SPREAD = 16.0

#: The identity transform that stands first in every group's ``reps`` (shared, read-only:
#: membership tests skip it by identity).
IDENTITY_MATRIX = np.eye(4)
IDENTITY_MATRIX.setflags(write=False)


@dataclass(frozen=True, eq=False)
class SymmetryGroup:
    """A subgroup G = G0 . Gamma of SE(3) (docs/algebra.md §2.2).

    ``kind``/``frame``/``pitch`` place the connected part G0 = F K F^-1; ``reps`` is a
    finite transversal of G/G0 (world elements, the first is I) and ``lattice`` the
    generators of an infinite discrete quotient. Elements are g0 . lambda . gamma.
    """

    kind: Kind
    frame: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    pitch: float = 0.0
    reps: tuple[NDArray[np.float64], ...] = (IDENTITY_MATRIX,)
    lattice: tuple[NDArray[np.float64], ...] = ()

    # ------------------------------------------------------------------ constructors

    @classmethod
    def connected(
        cls, kind: Kind | str, frame: NDArray[np.float64], pitch: float = 0.0
    ) -> SymmetryGroup:
        """The connected group F K(kind, pitch) F^-1; a zero pitch gives R or G."""
        k = Kind(kind)
        if k in HELICAL_KINDS and pitch == 0.0:
            k = Kind.REVOLUTE if k is Kind.HELICAL else Kind.PLANAR
        return cls(
            k, np.asarray(frame, dtype=np.float64), float(pitch) if k in HELICAL_KINDS else 0.0
        )

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
        reps = tuple(se3.rotation(axis, math.tau * k / n, point) for k in range(n))
        return cls(Kind.FIXED, np.eye(4), 0.0, reps)

    @classmethod
    def lattice_group(cls, generators: Any) -> SymmetryGroup:
        """The infinite discrete group generated by ``generators`` (translations or screws)."""
        return cls.identity().with_discrete(lattice=tuple(generators))

    # ------------------------------------------------------------------ properties

    @property
    def dof(self) -> int:
        """Dimension of G0 (Hervé dimension)."""
        return DIMENSION[self.kind]

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
        """Whether G0 is a TR group (not helical; docs/algebra.md §2.4)."""
        return self.kind not in HELICAL_KINDS

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
        return se3.adjoint(self.frame) @ canonical_basis(self.kind, self.pitch)

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
        if k in HELICAL_KINDS:
            out["pitch"] = self.pitch
        return out

    @cached
    def translation_part(self) -> tuple[Subspace, tuple[NDArray[np.float64], float] | None]:
        """G0 ∩ T3 = {t in V : t.u in c Z} as (V, (u, c) or None) (§2.4, lattice rows)."""
        k, u = self.kind, self.axis
        if k in (Kind.FIXED, Kind.REVOLUTE, Kind.SPHERICAL):
            return Subspace(0), None
        if k in (Kind.PRISMATIC, Kind.CYLINDRICAL):
            return Subspace(1, u), None
        if k in (Kind.TRANSLATION2, Kind.PLANAR):
            return Subspace(2, u), None
        if k is Kind.HELICAL:
            return Subspace(1, u), (u, math.tau * abs(self.pitch))
        if k is Kind.PSEUDO_PLANAR:
            return Subspace(3), (u, math.tau * abs(self.pitch))
        return Subspace(3), None

    @cached
    def tr_shape(self) -> tuple[RotationPart, Subspace]:
        """Rotation type and translation subspace V of a TR group G0 = T(V) ⋊ Rot."""
        return ROTATIONS[self.kind], self.translation_part[0]

    # ------------------------------------------------------------------ elements

    def element(
        self, params: Any = (), component: int = 0, steps: tuple[int, ...] = ()
    ) -> NDArray[np.float64]:
        """F k(params) F^-1 . lambda . reps[component], lambda = prod lattice[i]^steps[i]."""
        k = canonical_element(self.kind, self.pitch, np.atleast_1d(np.asarray(params, float)))
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
            params *= np.where(self.angle_parameters(), math.pi, scale)
            steps = tuple(int(s) for s in rng.integers(-3, 4, len(self.lattice)))
            out.append(self.element(params, int(rng.integers(len(self.reps))), steps))
        return out

    def angle_parameters(self) -> NDArray[np.bool_]:
        """Which of the parameters of :meth:`element` are angles (the others are lengths)."""
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
        return in_canonical(self.kind, self.pitch, self.frame_inverse @ g @ self.frame, tol)

    def contains(self, t: NDArray[np.float64], tol: Tolerance | None = None) -> bool:
        """Whether ``t`` is in G (docs/algebra.md §2.3, with reps and lattice projection)."""
        return self._component(t, tol or current()) is not None

    def _component(self, t: NDArray[np.float64], tol: Tolerance) -> int | None:
        """The first index i with t in G0 . Lambda . reps[i], or ``None`` when t is not in G.

        Without a lattice the candidates are the components whose coset keys are near that
        of t (:class:`_CosetTable`, docs/algebra.md §2.3 "Discrete parts"), so the cost does not
        grow with the number of components."""
        if not self.lattice:
            if len(self.reps) == 1:
                return 0 if self._in_connected(t, tol) else None
            return self._rep_table(tol).find(t)
        for i, gamma in enumerate(self.reps):
            g = t @ se3.inverse(gamma) if gamma is not IDENTITY_MATRIX else t
            if self._in_lattice_coset(g, tol):
                return i
        return None

    def components_near(self, t: NDArray[np.float64], tol: Tolerance | None = None) -> list[int]:
        """The indices i, in order, of the components G0 . reps[i] that may hold ``t``: all of
        them with a lattice, else those whose coset keys are within :data:`MEET_SPREAD`
        times the tolerance bound of the key of t (:class:`_CosetTable`), a superset of
        the components holding t. Meets of discrete groups pair only these (§2.4)."""
        if self.lattice or len(self.reps) == 1:
            return list(range(len(self.reps)))
        return self._rep_table(tol or current()).near(t, MEET_SPREAD)

    @cached
    def _rep_tables(self) -> dict[Tolerance, _CosetTable]:
        """The coset tables of ``reps``, one per tolerance used (filled by :meth:`_rep_table`)."""
        return {}

    def _rep_table(self, tol: Tolerance) -> _CosetTable:
        """``reps`` keyed by their G0-cosets under ``tol`` (built on first use, then kept)."""
        table = self._rep_tables.get(tol)
        if table is None:
            table = _CosetTable(self.connected_part, tol)
            table.extend(self.reps, distinct=True)
            self._rep_tables[tol] = table
        return table

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
            space = Subspace(3)
        elif k is Kind.REVOLUTE:
            space = Subspace(1, self.axis)
        elif k is Kind.PRISMATIC:
            space = Subspace(2, self.axis)
        elif k in (Kind.TRANSLATION2, Kind.PLANAR):
            space = Subspace(1, self.axis)
        else:
            raise GroupError(f"a lattice over a {k.value} group is not supported")
        tol = current()
        for gen in self.lattice:
            if se3.rotation_angle(gen) > tol.angle:
                axis = se3.unit(se3.rotation_vector(gen[:3, :3]))
                space = subspace_meet(space, Subspace(1, axis), tol)
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
        q, _ = np.linalg.qr(scaled_twists(self.algebra, tol))
        b = scaled_twists(other.algebra, tol)
        res = b - q @ (q.T @ b)
        return float(np.max(np.abs(res))) <= rank_threshold(tol)

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
        """T G T^-1 (docs/algebra.md §2.3 conjugation)."""
        ti = se3.inverse(t)
        reps = tuple(IDENTITY_MATRIX if g is IDENTITY_MATRIX else t @ g @ ti for g in self.reps)
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
        unique = _dedupe(g0, [IDENTITY_MATRIX, *elements[: len(reps)]], tol)
        group = SymmetryGroup(
            g0.kind, g0.frame, g0.pitch, tuple(unique), tuple(elements[len(reps) :])
        )
        if lattice:
            group._check_lattice(tol)
        group._check_closed(tol)
        return group

    def _check_closed(self, tol: Tolerance) -> None:
        """Raise unless reps . reps is in G, i.e. Gamma is closed under composition.

        Generators B are taken from reps greedily (each one not yet reached) and every
        reached component is multiplied by each of them: reps . B in G with every rep a
        product of generators is the same condition as reps . reps in G. Each new generator
        at least doubles the subgroup reached (Lagrange), so |B| <= log2 |reps| + 1 and
        the test costs O(|reps| log |reps|) memberships instead of |reps|^2.
        """
        gens: list[NDArray[np.float64]] = []
        used: dict[int, int] = {0: 0}
        for i, rep in enumerate(self.reps):
            if i in used:
                continue
            gens.append(rep)
            work = list(used)
            while work:
                m = work.pop()
                for g in gens[used[m] :]:
                    j = self._component(self.reps[m] @ g, tol)
                    if j is None:
                        raise GroupError("the discrete part is not closed under composition")
                    if j not in used:
                        used[j] = 0
                        work.append(j)
                used[m] = len(gens)

    def with_known_discrete(
        self,
        reps: tuple[NDArray[np.float64], ...] = (),
        lattice: tuple[NDArray[np.float64], ...] = (),
        tol: Tolerance | None = None,
    ) -> SymmetryGroup:
        """G0 . Gamma for a discrete part known to form a group with G0 (components of an
        intersection of groups, flips of a stabiliser): duplicates are merged, the
        rigidity, normaliser and closure checks of :meth:`with_discrete` are skipped
        (n normaliser tests and O(n log n) memberships for n components)."""
        g0 = self.connected_part
        unique = _dedupe(g0, [IDENTITY_MATRIX, *reps], tol or current())
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
        table = _CosetTable(g0, tol)
        table.extend([*self.reps, *extra])
        frontier = list(table.members)
        gens = [*self.reps[1:], *extra]
        while frontier:
            new = []
            for a in frontier:
                for b in gens:
                    c = a @ b
                    if table.find(c) is None:
                        table.add(c)
                        new.append(c)
            if len(table.members) > MAX_FINITE_ORDER:
                raise GroupError("the generated discrete group is not finite")
            frontier = new
        return SymmetryGroup(g0.kind, g0.frame, g0.pitch, tuple(table.members), self.lattice)

    # ------------------------------------------------------------------ orbits

    def orbit(self, point: Any, tol: Tolerance | None = None) -> Locus:
        """The orbit of ``point`` under G (docs/algebra.md §2.3 orbit table)."""
        tol = tol or current()
        x = np.asarray(point, dtype=np.float64)
        if any(se3.rotation_angle(g) > tol.angle for g in self.lattice):
            raise GroupError("the orbit under a discrete screw group is not a supported locus")
        members = [self._connected_orbit(se3.apply(g, x), tol) for g in self.reps]
        if len(members) == 1 and not self.lattice:
            return members[0]
        return Locus(
            LocusKind.UNION, members=tuple(members), steps=tuple(g[:3, 3] for g in self.lattice)
        )

    def _connected_orbit(self, x: NDArray[np.float64], tol: Tolerance) -> Locus:
        k, u, n = self.kind, self.axis, self.origin
        d = x - n
        radial = d - (d @ u) * u
        rho = se3.norm(radial)
        foot = n + (d @ u) * u
        if k is Kind.FIXED:
            return Locus(LocusKind.POINT, point=x)
        if k is Kind.PRISMATIC:
            return Locus(LocusKind.LINE, point=x, direction=u)
        if k in (Kind.TRANSLATION2, Kind.PLANAR):
            return Locus(LocusKind.PLANE, point=x, direction=u)
        if k is Kind.SPHERICAL:
            return Locus(LocusKind.SPHERE, point=n.copy(), radius=se3.norm(d))
        if k in (Kind.TRANSLATION3, Kind.SCHOENFLIES, Kind.FREE, Kind.PSEUDO_PLANAR):
            return Locus(LocusKind.SPACE)
        if k is Kind.REVOLUTE:
            if rho <= tol.length:
                return Locus(LocusKind.POINT, point=x)
            return Locus(LocusKind.CIRCLE, point=foot, direction=u, radius=rho)
        if rho <= tol.length:
            return Locus(LocusKind.LINE, point=x, direction=u)
        if k is Kind.CYLINDRICAL:
            return Locus(LocusKind.CYLINDER, point=n.copy(), direction=u, radius=rho)
        return Locus(
            LocusKind.HELIX, point=n.copy(), direction=u, radius=rho, pitch=self.pitch, through=x
        )

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
        if k in HELICAL_KINDS:
            text += f", pitch {fmt.number(self.pitch)}"
        if len(self.reps) > 1:
            # the discrete components of G (docs/algebra.md §2.2), in an engineer's words
            text += f", {len(self.reps)} symmetric positions"
        if self.lattice:
            steps = "; ".join(fmt.vector(g[:3, 3]) for g in self.lattice)
            text += f", lattice generated by steps {steps}"
        return text

    def intersect(self, other: SymmetryGroup, tol: Tolerance | None = None) -> SymmetryGroup:
        """G ∩ G' by ``intersect_groups``, imported when called (``meets`` is above ``groups``)."""
        warnings.warn(
            "SymmetryGroup.intersect is deprecated; use assemblykit.algebra.intersect_groups",
            DeprecationWarning,
            stacklevel=2,
        )
        meets = importlib.import_module("assemblykit.algebra.meets")
        meet: SymmetryGroup = meets.intersect_groups(self, other, tol)
        return meet

    def __repr__(self) -> str:
        return f"SymmetryGroup<{self.describe()}>"


_IDENTITY = SymmetryGroup(Kind.FIXED, IDENTITY_MATRIX)


def _dedupe(
    g0: SymmetryGroup, elements: list[NDArray[np.float64]], tol: Tolerance
) -> list[NDArray[np.float64]]:
    """One representative per G0-coset, in order of first appearance."""
    table = _CosetTable(g0, tol)
    table.extend(elements)
    return table.members


#: Points (model units, canonical frame) whose images under an element key its G0-coset.
_KEY_POINTS = np.array([[0.6, -0.2, 0.3], [0.3, 0.7, -0.5], [0.7, 0.4, 0.8]])

#: Fixed generic weights that fold the invariant features of a coset into one number.
_KEY_WEIGHTS = np.random.default_rng(20_240_601).uniform(0.5, 1.0, 9)

#: The smallest angle tolerance the bound on key differences assumes: it also covers the
#: rounding of F^-1 g F, about 1e-16 of the reach, when a user asks for down to 1e-15.
_KEY_ROUNDING = 1e-12


def _coset_features(
    g0: SymmetryGroup, elements: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Features of the G0-cosets G0 . g of ``elements`` (n x 4 x 4), invariant under left
    multiplication by G0 (docs/algebra.md §2.3 "Discrete parts"): with c = F^-1 g F in the
    canonical frame, the K-invariant coordinates of the images c(p) of three points p
    (e.g. radius and height for R, x and y for T, all three for E) and the rotation rows
    K leaves unchanged (all of R without rotations, the z row with rotations about z).

    Returns (point features n x a, rotation features n x b, reach n): reach bounds the
    images c(p) and the magnitudes rounding acts on, which sets how far a tolerance
    moves the point features (:meth:`_CosetTable.width`).
    """
    c = g0.frame_inverse @ elements @ g0.frame
    r = c[:, :3, :3]
    x = r @ _KEY_POINTS + c[:, :3, 3:]
    n = len(elements)
    rotation = ROTATIONS[g0.kind]
    if rotation is RotationPart.NONE:
        turned = r.reshape(n, 9)
    elif rotation is RotationPart.LINE:
        turned = r[:, 2, :]
    else:
        turned = np.zeros((n, 0))
    kind = g0.kind
    rho = np.hypot(x[:, 0], x[:, 1])
    if kind is Kind.FIXED:
        placed = x.reshape(n, 9)
    elif kind is Kind.PRISMATIC:
        placed = x[:, :2].reshape(n, 6)
    elif kind in (Kind.TRANSLATION2, Kind.PLANAR):
        placed = x[:, 2]
    elif kind is Kind.REVOLUTE:
        placed = np.hstack((rho, x[:, 2]))
    elif kind in (Kind.HELICAL, Kind.CYLINDRICAL):
        placed = rho
    elif kind is Kind.SPHERICAL:
        placed = np.linalg.norm(x, axis=1)
    else:
        placed = np.zeros((n, 0))
    reach = (
        np.max(np.linalg.norm(x, axis=1), axis=1)
        + np.linalg.norm(elements[:, :3, 3], axis=1)
        + se3.norm(g0.origin)
    )
    return placed, turned, reach


class _CosetTable:
    """Elements of distinct G0-cosets with a lookup of the member whose coset holds a
    given element (docs/algebra.md §2.3 "Discrete parts").

    Each element has a scalar key, a fixed weighted sum of :func:`_coset_features`. When
    g f^-1 passes the membership predicate of G0, the keys of g and f differ by less than
    :meth:`width` (each feature is 1-Lipschitz in the image points, and the predicate
    bounds the part of g f^-1 outside K by the length and angle tolerances), so only
    members in the neighbouring buckets of that width are tested, with the same predicate
    as a scan of all members: the answers are those of the scan, in the same order.
    """

    def __init__(self, g0: SymmetryGroup, tol: Tolerance) -> None:
        self.g0 = g0
        self.tol = tol
        self.members: list[NDArray[np.float64]] = []
        self._keys: list[float] = []
        self._reach = 0.0
        self._width = 1.0
        self._buckets: dict[int, list[int]] = {}
        placed, turned, _ = _coset_features(g0, IDENTITY_MATRIX[None])
        self._weights = (_KEY_WEIGHTS[: placed.shape[1]], _KEY_WEIGHTS[: turned.shape[1]])

    def _keys_of(
        self, elements: list[NDArray[np.float64]] | tuple[NDArray[np.float64], ...]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The keys and reaches of ``elements``."""
        placed, turned, reach = _coset_features(self.g0, np.asarray(elements, dtype=np.float64))
        return placed @ self._weights[0] + turned @ self._weights[1], reach

    def width(self, reach: float) -> float:
        """A bound, with a factor 4 to spare, on the key difference of two elements of one
        G0-coset whose images c(p) are within ``reach``: a point feature moves by at most
        3 angle . reach + 2 length, a rotation-row feature by at most 3 angle."""
        tol = self.tol
        angle = max(tol.angle, _KEY_ROUNDING)
        placed, turned = (float(np.sum(w)) for w in self._weights)
        return 4.0 * (
            2.0 * tol.length
            + placed * (3.0 * angle * reach + 2.0 * tol.length)
            + turned * 3.0 * angle
        )

    def near(self, g: NDArray[np.float64], spread: float, key: float | None = None) -> list[int]:
        """The indices, in order, of the members whose keys are within ``spread`` times
        :meth:`width` of the key of ``g`` (and maybe a little further)."""
        if key is None:
            key = float(self._keys_of([g])[0][0])
        bucket, steps = math.floor(key / self._width), math.ceil(spread)
        return sorted(
            i for b in range(bucket - steps, bucket + steps + 1) for i in self._buckets.get(b, ())
        )

    def find(self, g: NDArray[np.float64], key: float | None = None) -> int | None:
        """The index of the first member f with g f^-1 in G0, else ``None``."""
        for i in self.near(g, 1.0, key):
            f = self.members[i]
            if self.g0._in_connected(g if f is IDENTITY_MATRIX else g @ se3.inverse(f), self.tol):
                return i
        return None

    def add(
        self, g: NDArray[np.float64], key: float | None = None, reach: float | None = None
    ) -> None:
        """Append ``g`` as a new member. The buckets are sized for twice the largest reach
        so far, and rebuilt when a member reaches beyond that."""
        if key is None or reach is None:
            keys, reaches = self._keys_of([g])
            key, reach = float(keys[0]), float(reaches[0])
        self.members.append(g)
        self._keys.append(key)
        if reach > self._reach:
            self._reach = 2.0 * reach
            self._width = self.width(self._reach)
            self._buckets = {}
            for i, k in enumerate(self._keys):
                self._buckets.setdefault(math.floor(k / self._width), []).append(i)
        else:
            bucket = math.floor(key / self._width)
            self._buckets.setdefault(bucket, []).append(len(self._keys) - 1)

    def extend(
        self,
        elements: list[NDArray[np.float64]] | tuple[NDArray[np.float64], ...],
        distinct: bool = False,
    ) -> None:
        """Add the elements not in a member's coset (all of them when ``distinct``)."""
        if not elements:
            return
        keys, reaches = self._keys_of(elements)
        for g, key, reach in zip(elements, keys.tolist(), reaches.tolist(), strict=True):
            if distinct or self.find(g, key) is None:
                self.add(g, key, reach)


def classify_algebra(basis: NDArray[np.float64], tol: Tolerance) -> SymmetryGroup:
    """The connected group whose Lie algebra is spanned by ``basis`` (6 x k) (§2.1 steps
    1-5, :func:`assemblykit.algebra.lie.classify_subalgebra`)."""
    placed = classify_subalgebra(basis, tol)
    if placed.kind is Kind.FIXED:
        return SymmetryGroup.identity()
    return SymmetryGroup.connected(placed.kind, placed.frame, placed.pitch)


def one_parameter(tau: NDArray[np.float64], tol: Tolerance) -> SymmetryGroup | None:
    """The connected one-parameter group {exp(s log tau)} through a lattice generator
    that translates along its axis (a translation: T; a screw: H), else ``None``.

    Its elements are exp(s log tau), with s the ratio of their translation along the
    axis to that of tau (:func:`lattice_parameter`).
    """
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
