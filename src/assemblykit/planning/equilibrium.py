"""The equilibrium equations of rigid parts under gravity, assembled once per assembly,
and the verdicts drawn from them: which states stand, which parts would fall, the least
friction a state needs and whether it tips over.

The model is the rigid-block equilibrium analysis of masonry (Whiting, Ochsendorf and
Durand 2009, "Procedural modeling of structurally-sound masonry buildings"; the RBE
of compas_cra; docs/planning.md, "Under gravity"):

* every part is rigid; its weight (``density x volume``, uniform density unless given per
  part) acts at its volume centroid along the gravity direction;
* forces act at the contact points (:mod:`assemblykit.planning.force_points`), each
  compressive along the contact normal with friction inside a linearised Coulomb cone
  (:mod:`assemblykit.planning.equilibrium_programs`);
* fixed parts (ground, fixture) and held parts take any wrench.

A state stands when the first program finds a balance of its free parts' equations, on
the corners of the contact polygons (:meth:`EquilibriumModel.stands`); when it does not,
the slack program, each residual scaled by the part's weight and the model's size,
names the parts that would fall. The slack program is solved for each piece of the
state (free parts that no force point joins: :meth:`EquilibriumModel.pieces`) on its
own. What the programs found is kept in an explicit
:class:`~assemblykit.planning.equilibrium_memory.EquilibriumMemory`, passed by whoever
asks a series of questions, and answers later states with fewer programs. Loads are
homogeneous in rigid-block equilibrium (scaling gravity scales every force), so the
margin reported is the friction coefficient a balance of the state needs, less than
``mu / 32`` above the least one (:meth:`EquilibriumModel.friction_needed`); a state
that falls is told apart by whether it tips over, falling even with unbounded friction
(:meth:`EquilibriumModel.tips`), or slides.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property, partial
from types import MappingProxyType
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray

from assemblykit.errors import InputError, NumericError
from assemblykit.graphs import component_labels
from assemblykit.model.assembly import lowest_parts
from assemblykit.planning.equilibrium_memory import EquilibriumMemory, KeptBalance, ResidualKey
from assemblykit.planning.equilibrium_programs import (
    CONE_SIDES,
    LP_FEASIBILITY,
    LP_TIME_LIMIT,
    balance,
    cone_directions,
    least_residuals,
    point_sums,
    pyramid_gauge,
    solve_all,
)
from assemblykit.planning.force_points import contact_points
from assemblykit.planning.gravity import DOWN, FRICTION, Equilibrium, gravity_direction
from assemblykit.tolerance import Tolerance, order_key

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly

FRICTION_STEPS = 5
"""Bisection steps for the least friction coefficient: resolution ``mu / 2**5``."""

LOCAL_HOPS = 1
"""How many contacts :meth:`EquilibriumModel.stands` grows the region of unbalanced
parts by, one at a time, before it leaves the verdict to the whole program: a region
that one contact more does not prove falling rarely falls with more (docs/planning.md,
"Under gravity": the states a plan asks about)."""


THREADED_PARTS = 100
"""The free parts from which a piece's slack program is solved on a thread of its own
(:meth:`EquilibriumModel.solve_slack`): on the 527-block dome four such programs take
5.1 to 5.5 s on two threads against 8.9 to 9.3 s one after another, while the programs
of a few dozen parts, whose setup under Python's interpreter lock takes most of their
time, gain nothing and cost CPU time (the cross vault's whole plan with every piece on
threads: the same wall clock time, 16% more CPU)."""


def _own(memory: EquilibriumMemory | None) -> EquilibriumMemory:
    """``memory``, or when none is given a new one (kept for one call alone)."""
    return EquilibriumMemory() if memory is None else memory


@dataclass(frozen=True, eq=False)
class EquilibriumModel:
    """The equilibrium equations of every part of an assembly, assembled once.

    Column ``p * CONE_SIDES + s`` is generator ``s`` of force point ``p``; its force on
    the pushed part is ``normal_part + mu * tangent_part`` (the two sparse matrices,
    6 rows per part: force, then moment about ``origin`` divided by ``scale``, each row
    divided by the part's weight), and the opposite on the pushing part. ``load`` holds
    the scaled weights. A state (a subset of the parts, some of them fixed) keeps the
    rows of its free parts and the columns of the points between its parts (of the
    ``corners`` among them in the first program).

    The model is a value: what its programs find for one state and keep for the next is
    in the :class:`~assemblykit.planning.equilibrium_memory.EquilibriumMemory` given to
    its methods as ``memory`` (none given: a new one, kept for that call alone).
    """

    names: tuple[str, ...]
    normal_part: sp.csr_matrix
    tangent_part: sp.csr_matrix
    load: NDArray[np.float64]
    point_parts: NDArray[np.int64]
    corners: NDArray[np.bool_]
    heights: NDArray[np.float64]
    offsets: NDArray[np.float64]
    """Each centre's distance from the vertical through the middle of the assembly's
    bounds (what orders parts of equal height: :attr:`levels`)."""
    fixed: tuple[str, ...]
    friction: float
    threshold: float

    @cached_property
    def _index(self) -> Mapping[str, int]:
        """Each part's index in :attr:`names`."""
        return MappingProxyType({name: i for i, name in enumerate(self.names)})

    @cached_property
    def levels(self) -> NDArray[np.int64]:
        """The parts in the order in which they are taken down (a rank each): the highest
        first, and of equal heights the nearest the middle (a keystone before its
        corbels), both compared by :func:`order_key` at the scale of the assembly, so
        that mirror images are equal whatever the rounding (then by index)."""
        if not len(self.heights):
            return np.zeros(0, dtype=np.int64)
        scale = float(np.ptp(self.heights) + self.offsets.max())
        keys = [
            (order_key(float(h), scale), order_key(float(r), scale), i)
            for i, (h, r) in enumerate(zip(self.heights, self.offsets, strict=True))
        ]
        ranks = np.empty(len(keys), dtype=np.int64)
        ranks[[i for *_, i in sorted(keys)]] = np.arange(len(keys))
        return ranks

    @property
    def resolution(self) -> float:
        """The width of :meth:`friction_needed`'s last bracket:
        ``friction / 2**FRICTION_STEPS``."""
        return float(self.friction / 2**FRICTION_STEPS)

    def mask(self, names: Iterable[str] | None) -> NDArray[np.bool_]:
        """``names`` (default: all parts) as a boolean vector over :attr:`names`."""
        out = np.zeros(len(self.names), dtype=bool)
        if names is None:
            out[:] = True
        else:
            out[[self._index[n] for n in names]] = True
        return out

    def _rows(self, free: NDArray[np.bool_]) -> NDArray[np.int64]:
        """The equations (rows) of the ``free`` parts."""
        return (6 * np.flatnonzero(free)[:, None] + np.arange(6)).ravel()

    def _touching(self, present: NDArray[np.bool_]) -> NDArray[np.bool_]:
        """The force points between two parts of ``present``."""
        return present[self.point_parts[:, 0]] & present[self.point_parts[:, 1]]

    def _acting_on(self, parts: NDArray[np.bool_]) -> NDArray[np.bool_]:
        """The force points with a part of ``parts`` on one side or the other."""
        return parts[self.point_parts[:, 0]] | parts[self.point_parts[:, 1]]

    def _columns(self, selected: NDArray[np.bool_]) -> NDArray[np.int64]:
        """The generator columns of the ``selected`` points."""
        return (CONE_SIDES * np.flatnonzero(selected)[:, None] + np.arange(CONE_SIDES)).ravel()

    def _matrix(
        self, rows: NDArray[np.int64], selected: NDArray[np.bool_], mu: float
    ) -> sp.csc_matrix:
        """The equations ``rows`` over the generators of the ``selected`` points."""
        columns = self._columns(selected)
        part = self.normal_part[rows][:, columns] + mu * self.tangent_part[rows][:, columns]
        return sp.csc_matrix(part)

    @cached_property
    def _point_wrenches(self) -> tuple[sp.csr_matrix, sp.csr_matrix, sp.csr_matrix]:
        """The scaled wrenches (6 rows per part) of a unit force at each point along its
        normal, ``u`` and ``v`` (three P-column matrices): generator ``s`` is the normal
        one plus ``mu (cos t u + sin t v)``, and the ``CONE_SIDES`` angles ``t`` are
        spread evenly, so the tangent columns are recovered as their weighted means."""
        cos, sin = cone_directions()
        spread = 2.0 / CONE_SIDES
        points = self.normal_part.shape[1] // CONE_SIDES
        return (
            sp.csr_matrix(self.normal_part[:, ::CONE_SIDES]),
            sp.csr_matrix(self.tangent_part @ point_sums(spread * cos, points)),
            sp.csr_matrix(self.tangent_part @ point_sums(spread * sin, points)),
        )

    def _point_forces(self, weights: NDArray[np.float64], mu: float) -> KeptBalance:
        """The balance of generator weights ``weights`` at ``mu`` as forces."""
        cos, sin = cone_directions()
        per_point = weights.reshape(-1, CONE_SIDES)
        forces = np.stack([per_point.sum(axis=1), mu * per_point @ cos, mu * per_point @ sin], 1)
        return KeptBalance(forces, pyramid_gauge(forces[:, 1:]))

    def _over_every_equation(
        self, rows: NDArray[np.int64], certificate: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """A Farkas certificate over the equations ``rows`` as one over every equation
        (zero on the others)."""
        y = np.zeros(len(self.load))
        y[rows] = certificate
        return y

    def stands(
        self,
        present: NDArray[np.bool_],
        fixed: NDArray[np.bool_],
        friction: float | None = None,
        local: bool = True,
        *,
        memory: EquilibriumMemory | None = None,
    ) -> bool:
        """Whether the equations of ``present`` alone have a solution with ``fixed``
        immobile: the first program, on the corners (:func:`balance`), whose balance or
        certificate ``memory`` keeps. With ``local``, the balances and certificates kept
        decide first where they can (:meth:`_local_verdict`); its verdicts are the whole
        program's."""
        memory = _own(memory)
        free = present & ~fixed
        if not free.any():
            return True
        points = self._touching(present)
        if not points.any():
            return False
        mu = self.friction if friction is None else friction
        selected = points & self.corners
        if local:
            verdict = self._local_verdict(present, free, selected, mu, memory)
            if verdict is not None:
                return verdict
            # the states of a plan mostly need the friction the last one needed, and a
            # balance found there is one here too, of use to the friction's search
            end = memory.bracket_end
            hint = mu if end is None else end * self.resolution
            if hint < mu and self.stands(present, fixed, hint, memory=memory):
                return True
        found, certificate = self._whole_program(free, selected, mu)
        if found is None:
            if certificate is not None:
                memory.keep_certificate(certificate)
            return False
        memory.keep_balance(found)
        return True

    def _whole_program(
        self, free: NDArray[np.bool_], selected: NDArray[np.bool_], mu: float
    ) -> tuple[KeptBalance | None, NDArray[np.float64] | None]:
        """The first program of the ``free`` parts' equations over the ``selected``
        points at ``mu`` (:func:`balance`): the balance found, as point forces, or else
        the certificate that there is none, over every equation (``None`` when the
        solver that answered gave none)."""
        rows = self._rows(free)
        found = balance(self._matrix(rows, selected, mu), -self.load[rows])
        if found.forces is None:
            if found.certificate is None:
                return None, None
            return None, self._over_every_equation(rows, found.certificate)
        weights = np.zeros(self.normal_part.shape[1])
        weights[self._columns(selected)] = found.forces
        return self._point_forces(weights, mu), None

    def reference(self, present: NDArray[np.bool_], fixed: NDArray[np.bool_]) -> KeptBalance | None:
        """A balance of ``present`` with ``fixed`` immobile at the model's friction (one
        first program on the whole state), ``None`` when it falls or has no free part:
        for :attr:`EquilibriumMemory.reference`, whose states taken from this one are
        then proved to fall from the equations around what they took
        (:meth:`_local_verdict`); ``None`` too when no solver decides it
        (:class:`NumericError`: a shortcut that cannot answer does not stop the plan).
        The first step of the 527-block dome's plan proves 31 of its candidates fall so,
        in 0.4 s together, where a whole program takes 1.5 to 2 s each."""
        free = present & ~fixed
        selected = self._touching(present) & self.corners
        if not free.any() or not selected.any():
            return None
        try:
            return self._whole_program(free, selected, self.friction)[0]
        except NumericError:
            return None

    def _unbalanced(
        self, forces: NDArray[np.float64], free: NDArray[np.bool_]
    ) -> NDArray[np.bool_]:
        """The ``free`` parts whose equations the point ``forces`` (P x 3) leave with a
        residual beyond :data:`LP_FEASIBILITY`."""
        normal, along_u, along_v = self._point_wrenches
        wrench = normal @ forces[:, 0] + along_u @ forces[:, 1] + along_v @ forces[:, 2]
        error = np.abs(-self.load - wrench).reshape(-1, 6).max(axis=1)
        unbalanced: NDArray[np.bool_] = free & (error > LP_FEASIBILITY)
        return unbalanced

    def _first_certifying(
        self,
        free: NDArray[np.bool_],
        selected: NDArray[np.bool_],
        mu: float,
        memory: EquilibriumMemory,
    ) -> int | None:
        """The number of the first certificate kept (its ``y``) that, restricted to the
        equations of the ``free`` parts, proves that they have no balance over the
        ``selected`` points at ``mu`` (``None`` when none does): no generator gains
        from it (``matrix.T @ y >= 0``, to :data:`LP_FEASIBILITY` of the loads' share)
        while the loads do (``rhs @ y < 0``). A part removed takes its generators away
        and a part held its equations: either can spoil one, which the test sees. Every
        certificate is tested at once, per point: generator ``s`` of a point gains what
        its normal wrench gains plus ``mu (cos t_s u + sin t_s v)`` of what its ``u`` and
        ``v`` wrenches gain (:attr:`_point_wrenches`), three products where the
        generators would take ``CONE_SIDES`` times as many. The tangential part gains
        nothing on the average of a point's generators, so a certificate that a normal
        wrench spoils is spoilt, and only the others have their tangential gains
        computed."""
        if not len(memory.certificates):
            return None
        numbers, stacked = memory.stacked_certificates()
        kept = stacked * np.repeat(free, 6)[:, None]
        shares = -self.load @ kept
        normal_wrench, u_wrench, v_wrench = (m[selected] for m in self._point_wrenches_by_point)
        proven = shares < 0
        normal = normal_wrench @ kept[:, proven]
        proven[proven] = normal.min(axis=0, initial=0.0) >= LP_FEASIBILITY * shares[proven]
        if not proven.any():
            return None
        normal = normal[:, proven[shares < 0]]
        along_u, along_v = u_wrench @ kept[:, proven], v_wrench @ kept[:, proven]
        cos, sin = cone_directions()
        least = np.full_like(normal, np.inf)
        for c, s in zip(cos, sin, strict=True):
            np.minimum(least, c * along_u + s * along_v, out=least)
        worst = (normal + mu * least).min(axis=0, initial=0.0)
        proven[proven] = worst >= LP_FEASIBILITY * shares[proven]
        if not proven.any():
            return None
        shown = {numbers[i] for i in np.flatnonzero(proven)}
        return next(number for number, _ in memory.certificates.items() if number in shown)

    @cached_property
    def _point_wrenches_by_point(self) -> tuple[sp.csr_matrix, sp.csr_matrix, sp.csr_matrix]:
        """:attr:`_point_wrenches` transposed: a row per point, whose wrench on every
        equation a certificate's gain is one product with."""
        normal, along_u, along_v = self._point_wrenches
        return sp.csr_matrix(normal.T), sp.csr_matrix(along_u.T), sp.csr_matrix(along_v.T)

    def _local_verdict(
        self,
        present: NDArray[np.bool_],
        free: NDArray[np.bool_],
        selected: NDArray[np.bool_],
        mu: float,
        memory: EquilibriumMemory,
    ) -> bool | None:
        """The verdict of :meth:`stands` where what ``memory`` keeps decides it (``None``
        where it does not):

        * *stands* when a balance kept, without the forces on parts absent from this
          state, still balances every free part with forces that ``mu``'s pyramids
          hold (a balance at one friction coefficient is one at every larger one);
        * *falls* when a certificate kept still proves it (:meth:`_first_certifying`), or when
          the parts the last balance (before any is kept, the memory's
          :attr:`~EquilibriumMemory.reference`) leaves unbalanced, or pushes on with more
          friction than ``mu`` allows, grown by contacts (:data:`LOCAL_HOPS`), cannot balance
          even with every part around them immobile (pushing on them however it must):
          a Farkas certificate on their equations alone is one for the whole state,
          and is kept.

        Removing a block leaves its neighbours to be proved, a dozen parts, where the
        whole program has all of them; a region holding more than half the free parts
        is left to the whole program, and so is a region whose program no solver
        decides (:class:`NumericError`: a shortcut that cannot answer does not stop
        the plan)."""
        for number, candidate in tuple(memory.balances.items()):
            if np.any((candidate.gauge - mu * candidate.forces[:, 0])[selected] > LP_FEASIBILITY):
                continue
            kept = candidate.forces * selected[:, None]
            if not self._unbalanced(kept, free).any():
                memory.use_balance(number, KeptBalance(kept, candidate.gauge * selected))
                return True
        proof = self._first_certifying(free, selected, mu, memory)
        if proof is not None:
            memory.use_certificate(proof)
            return False
        latest = memory.latest_balance() if len(memory.balances) else memory.reference
        if latest is None:
            return None
        forces, gauge = latest.forces * selected[:, None], latest.gauge
        region = self._unbalanced(forces, free)
        ends = self.point_parts
        # and the parts on both sides of the points whose forces mu's pyramids do not hold
        slipping = selected & (gauge - mu * forces[:, 0] > LP_FEASIBILITY)
        region[ends[slipping].ravel()] = True
        region &= free
        if not region.any():
            return None
        for _ in range(LOCAL_HOPS):
            near = np.zeros_like(region)
            near[ends[selected & region[ends[:, 0]], 1]] = True
            near[ends[selected & region[ends[:, 1]], 0]] = True
            region |= near & free
            if 2 * int(region.sum()) > int(free.sum()):
                return None
            rows = self._rows(region)
            touching = selected & self._acting_on(region)
            try:
                found = balance(self._matrix(rows, touching, mu), -self.load[rows])
            except NumericError:
                return None
            if not found.found:
                if found.certificate is not None:
                    memory.keep_certificate(self._over_every_equation(rows, found.certificate))
                return False
        return None

    def residuals(
        self,
        present: NDArray[np.bool_],
        fixed: NDArray[np.bool_],
        friction: float | None = None,
        *,
        memory: EquilibriumMemory | None = None,
    ) -> NDArray[np.float64]:
        """Per part, the largest scaled residual of its six equations at the optimum of
        the slack program (0 for fixed and absent parts). A state that stands is told by
        the equations alone first, on the corners (:meth:`stands`): that program is
        smaller, and its answer is all zeros. The slack program is on the corners too
        (:func:`least_residuals`: the residuals of the interior of its optimal face)."""
        memory = _own(memory)
        if self.stands(present, fixed, friction, memory=memory):
            return np.zeros(len(self.names))
        return self.slack(present, fixed, friction, memory=memory)

    def pieces(
        self, present: NDArray[np.bool_], fixed: NDArray[np.bool_]
    ) -> list[NDArray[np.bool_]]:
        """The free parts of a state in pieces that no force point joins (connected
        components of the contacts between free parts; immobile parts join nothing, as
        they take any wrench). The programs of a state are those of its pieces side by
        side: no generator acts on the equations of two pieces."""
        free = present & ~fixed
        ends = self.point_parts
        joined = free[ends[:, 0]] & free[ends[:, 1]]
        label = component_labels(len(self.names), ends[joined])
        return [free & (label == piece) for piece in np.unique(label[free])]

    def slack(
        self,
        present: NDArray[np.bool_],
        fixed: NDArray[np.bool_],
        friction: float | None = None,
        *,
        memory: EquilibriumMemory | None = None,
    ) -> NDArray[np.float64]:
        """The slack program of :meth:`residuals` alone, for a state known not to stand:
        per part, the largest scaled residual of its equations at its optimum. It is
        solved piece by piece (:meth:`pieces`, together: :meth:`solve_slack`), and
        ``memory`` keeps a piece's residuals: a removal elsewhere leaves them as they
        were."""
        memory = _own(memory)
        mu = self.friction if friction is None else friction
        keyed = self._keyed_pieces(present, fixed, mu)
        self._solve_pieces([(present, keyed)], mu, memory)
        out = np.zeros(len(self.names))
        for key, piece in keyed:
            out[piece] = memory.residuals.recall(
                key, partial(self._piece_residuals, present, piece, mu)
            )
        return out

    def solve_slack(
        self,
        states: Iterable[tuple[NDArray[np.bool_], NDArray[np.bool_]]],
        friction: float | None = None,
        *,
        memory: EquilibriumMemory,
    ) -> None:
        """Solve together the slack programs of the pieces of ``states`` (each
        ``(present, fixed)``, known not to stand) whose residuals ``memory`` lacks, and
        keep them there as :meth:`slack` would, state after state: :meth:`slack` then
        answers each of them from ``memory``. The candidates of a plan's step where no
        removal stands each ask one (docs/planning.md, "Under gravity")."""
        mu = self.friction if friction is None else friction
        keyed = [(present, self._keyed_pieces(present, fixed, mu)) for present, fixed in states]
        self._solve_pieces(keyed, mu, memory)

    def _keyed_pieces(
        self, present: NDArray[np.bool_], fixed: NDArray[np.bool_], mu: float
    ) -> list[tuple[ResidualKey, NDArray[np.bool_]]]:
        """The pieces of a state (:meth:`pieces`), each with the key of its residuals."""
        immobile = (present & fixed).tobytes()
        return [((piece.tobytes(), immobile, mu), piece) for piece in self.pieces(present, fixed)]

    def _solve_pieces(
        self,
        keyed: Sequence[tuple[NDArray[np.bool_], list[tuple[ResidualKey, NDArray[np.bool_]]]]],
        mu: float,
        memory: EquilibriumMemory,
    ) -> None:
        """Solve the slack programs of the pieces (``keyed``, per state its parts and its
        :meth:`_keyed_pieces`) that ``memory`` lacks, each once, those of
        :data:`THREADED_PARTS` or more on threads (:func:`solve_all`: a piece's program
        is a function of the piece alone, whichever thread solves it), and keep their
        residuals in the order met."""
        missing: dict[ResidualKey, partial[NDArray[np.float64]]] = {}
        large: list[ResidualKey] = []
        for present, pieces in keyed:
            for key, piece in pieces:
                if key not in memory.residuals and key not in missing:
                    missing[key] = partial(self._piece_residuals, present, piece, mu)
                    if int(piece.sum()) >= THREADED_PARTS:
                        large.append(key)
        solved = dict(zip(large, solve_all([missing[key] for key in large]), strict=True))
        for key, program in missing.items():
            memory.residuals.keep(key, solved[key] if key in solved else program())

    def _piece_residuals(
        self, present: NDArray[np.bool_], piece: NDArray[np.bool_], mu: float
    ) -> NDArray[np.float64]:
        """The residuals of one piece's parts at the slack program's optimum, on the
        corners of its points (they span the same wrenches as every point: the same least
        residual and the same parts left unbalanced, :data:`SLACK_ACCURACY`); a piece
        that touches nothing keeps its whole weight as residual."""
        rows = self._rows(piece)
        points = self._touching(present) & self._acting_on(piece)
        if not points.any():
            weights: NDArray[np.float64] = np.abs(self.load[rows]).reshape(-1, 6).max(axis=1)
            return weights
        corners = self._matrix(rows, points & self.corners, mu)
        residual = np.abs(least_residuals(corners, -self.load[rows]))
        largest: NDArray[np.float64] = residual.reshape(-1, 6).max(axis=1)
        return largest

    def falling(
        self,
        present: NDArray[np.bool_],
        fixed: NDArray[np.bool_],
        friction: float | None = None,
        *,
        memory: EquilibriumMemory | None = None,
    ) -> NDArray[np.bool_]:
        """The parts of ``present`` that cannot be in equilibrium with ``fixed`` immobile."""
        return self.residuals(present, fixed, friction, memory=memory) > self.threshold

    def check(
        self,
        parts: Iterable[str] | None = None,
        held: Iterable[str] = (),
        *,
        memory: EquilibriumMemory | None = None,
    ) -> Equilibrium:
        """Whether ``parts`` (default: all) stand, with the model's fixed parts among them
        and ``held`` immobile."""
        present = self.mask(parts)
        fixed = present & (self.mask(self.fixed) | self.mask(held))
        residual = self.residuals(present, fixed, memory=memory)
        free = np.flatnonzero(present & ~fixed)
        return Equilibrium(
            parts=tuple(self.names[i] for i in np.flatnonzero(present)),
            fixed=tuple(self.names[i] for i in np.flatnonzero(fixed)),
            would_fall=tuple(self.names[i] for i in free if residual[i] > self.threshold),
            residuals=tuple(float(residual[i]) for i in free),
        )

    def friction_needed(
        self,
        present: NDArray[np.bool_],
        fixed: NDArray[np.bool_],
        falls: NDArray[np.bool_] | None = None,
        *,
        memory: EquilibriumMemory | None = None,
    ) -> float | None:
        """A friction coefficient with which ``present`` is shown to stand, less than
        ``friction / 2**FRICTION_STEPS`` (:attr:`resolution`) above the least one and
        never above the least multiple of the resolution with which it stands; ``None``
        when ``friction`` itself does not suffice. ``falls``: :meth:`falling` at
        ``friction``, when already known.

        Standing is monotone in the friction coefficient (a larger pyramid holds every
        force a smaller one does), so a bracket of multiples of the resolution holds the
        least one: a probe that falls raises its lower end; one that stands lowers its
        upper end to the multiple just above what the balance that showed it needs
        (:meth:`_carrying`), and keeps that need. The search ends when the bracket is
        one step wide, and answers what the last balance found needs once its
        tangential forces are spread (:meth:`_spread_friction`, one more program): a
        balance stands with it, and the least one is above the lower end; 0 when the
        state stands without friction. It starts at the upper end of the last bracket:
        consecutive states of a plan mostly need the same friction, which two programs
        then confirm (a probe there, mostly decided by the balance the state's own
        verdict found there, :meth:`stands`, and one a step below what its balance
        needs); else it gallops away from it, then bisects (docs/planning.md, "Under
        gravity"). ``memory`` keeps that upper end for the next search."""
        memory = _own(memory)
        if (self.falling(present, fixed, memory=memory) if falls is None else falls).any():
            return None
        free = present & ~fixed
        if not free.any() or self.friction == 0:
            return 0.0
        grid, step = 2**FRICTION_STEPS, self.resolution
        low, high = -1, grid
        shown: list[float] = []

        def stands(k: int) -> bool:
            """Probe ``k`` steps: narrow the bracket, keep what a balance needs, and say
            whether the state stands. With ``friction`` it stands (``falls`` names no
            part there) even should the first program find no balance within its
            tolerance."""
            nonlocal low, high
            mu = k * step
            if self.stands(present, fixed, mu, memory=memory):
                shown[:] = [min(mu, self._carrying(free, memory)[1])]
                # the least multiple not below what the balance needs
                above = math.ceil(shown[0] / step)
                high = min(high, above + (above * step < shown[0]))
                return True
            if k < grid:
                low = k
                return False
            return True

        reach = 1
        if stands(grid if memory.bracket_end is None else memory.bracket_end):
            while high - low > 1 and stands(max(high - reach, 0)):
                reach *= 2
        else:
            while high - low > 1 and not stands(min(low + reach, grid)):
                reach *= 2
        while high - low > 1:
            stands((low + high) // 2)
        memory.bracket_end = high
        if not shown:
            return self.friction
        return min(shown[0], self._spread_friction(free, memory)) if shown[0] > 0 else 0.0

    def _carrying(
        self, free: NDArray[np.bool_], memory: EquilibriumMemory
    ) -> tuple[NDArray[np.bool_], float]:
        """The points of the balance :meth:`stands` found last (the first kept, after it
        answers that the state stands) that carry force on a ``free`` part (normal
        force beyond :data:`LP_FEASIBILITY` of the largest), and the friction
        coefficient that balance needs: the largest ratio of their pyramid gauge to
        their normal force."""
        latest = memory.latest_balance()
        normal, gauge = latest.forces[:, 0], latest.gauge
        carrying = self._acting_on(free) & (normal > LP_FEASIBILITY * normal.max(initial=0.0))
        return carrying, float(np.max(gauge[carrying] / normal[carrying], initial=0.0))

    def _spread_friction(self, free: NDArray[np.bool_], memory: EquilibriumMemory) -> float:
        """The least friction coefficient of a balance of the ``free`` parts with the
        normal forces of the one :meth:`stands` found last (:meth:`_carrying`), its
        tangential forces spread over the points carrying force so that the largest
        ratio of gauge to normal force is least: with the normal forces fixed, the
        linear program "minimise ``s`` with every gauge at most ``s N``, the equations
        of the free parts balanced", solved by Clarabel. Its balance, checked
        (residuals within :data:`LP_FEASIBILITY`, the ratio read again from its
        forces), is kept first in place of the one it improves (it fits every
        coefficient that one fits, and more); should it not check out, what the balance
        found needs is the answer. A block on a slope of ``tan 20° = 0.364`` balanced
        with ``mu = 0.5`` needs 0.41 at its lower corners, where the weight presses
        most; spread evenly, every corner needs 0.364."""
        import clarabel

        carrying, found = self._carrying(free, memory)
        if found == 0.0:
            return found
        forces = memory.latest_balance().forces
        normal = forces[:, 0]
        rows = self._rows(free)
        wrench_n, wrench_u, wrench_v = (m[rows] for m in self._point_wrenches)
        rest = forces * ~carrying[:, None]
        rhs = -self.load[rows] - wrench_n @ normal - wrench_u @ rest[:, 1] - wrench_v @ rest[:, 2]
        count = int(carrying.sum())
        half = np.pi / CONE_SIDES
        cos, sin = cone_directions(half)
        # unknowns: u and v of each carrying point's tangential force, then s; per point
        # and pyramid side, (side normal . tangent) / cos(pi / S) - s N <= 0
        constraints = sp.bmat(
            [
                [wrench_u[:, carrying], wrench_v[:, carrying], None],
                [
                    sp.kron(sp.identity(count), cos[:, None] / math.cos(half)),
                    sp.kron(sp.identity(count), sin[:, None] / math.cos(half)),
                    -np.repeat(normal[carrying], CONE_SIDES)[:, None],
                ],
            ],
            format="csc",
        )
        settings = clarabel.DefaultSettings()
        settings.verbose = False
        settings.time_limit = LP_TIME_LIMIT
        solved = clarabel.DefaultSolver(
            sp.csc_matrix((2 * count + 1, 2 * count + 1)),
            np.r_[np.zeros(2 * count), 1.0],
            constraints,
            np.r_[rhs, np.zeros(count * CONE_SIDES)],
            [clarabel.ZeroConeT(len(rows)), clarabel.NonnegativeConeT(count * CONE_SIDES)],
            settings,
        ).solve()
        spread = forces.copy()
        spread[carrying, 1:] = np.asarray(solved.x[: 2 * count]).reshape(2, count).T
        spread_gauge = pyramid_gauge(spread[:, 1:])
        least = float(np.max(spread_gauge[carrying] / normal[carrying], initial=0.0))
        # NaN where the solver gave up: not less
        if not least < found or self._unbalanced(spread, free).any():
            return found
        memory.improve_latest_balance(KeptBalance(spread, spread_gauge))
        return least

    def tips(self, present: NDArray[np.bool_], fixed: NDArray[np.bool_]) -> bool:
        """Whether ``present`` falls with ``fixed`` immobile even with unbounded friction:
        whether no compressive normal forces (``N >= 0``) with free tangential forces,
        at the corners of its points (:meth:`stands`), balance every free part (one
        program, :func:`balance`: columns the normal wrench of each point and its ``u``
        and ``v`` wrenches of both signs). A state that falls but not then needs more
        friction than it has (it slides); one that falls even then tips over, as does
        one with free parts and no contact (docs/planning.md, "Under gravity")."""
        free = present & ~fixed
        if not free.any():
            return False
        selected = self._touching(present) & self.corners
        if not selected.any():
            return True
        rows = self._rows(free)
        normal, along_u, along_v = (m[rows][:, selected] for m in self._point_wrenches)
        matrix = sp.hstack([normal, along_u, -along_u, along_v, -along_v], format="csc")
        return not balance(matrix, -self.load[rows]).found


def equilibrium_model(
    assembly: Assembly,
    direction: ArrayLike = DOWN,
    friction: float = FRICTION,
    fixed: Sequence[str] | None = None,
    densities: Mapping[str, float] | None = None,
    tol: Tolerance | None = None,
) -> EquilibriumModel:
    """The equilibrium equations of ``assembly`` under gravity along ``direction``
    (module docstring), assembled with numpy into sparse matrices. ``fixed`` defaults to
    :func:`lowest_parts`; ``densities`` (default 1) scale each part's weight."""
    tol = assembly.tolerance(tol)
    down = gravity_direction(direction)
    names = tuple(assembly.names)
    for name in (*(fixed or ()), *(densities or {})):
        assembly.part(name)
    if not math.isfinite(friction) or friction < 0:
        raise InputError(
            f"expected a friction coefficient >= 0, got {friction}", where="--friction"
        )
    density = np.array([(densities or {}).get(n, 1.0) for n in names], dtype=np.float64)
    weight = density * np.array([assembly.parts[n].volume for n in names])
    centres = np.array([assembly.parts[n].mesh.center_mass for n in names], dtype=np.float64)
    origin = assembly.bounds.mean(axis=0)
    scale = assembly.scale
    found = contact_points(assembly, down, tol)

    cos, sin = cone_directions()
    # per point and generator: the force's normal and tangential parts (P x S x 3)
    normal_force = np.repeat(found.normals[:, None, :], CONE_SIDES, axis=1)
    tangent_force = (
        cos[None, :, None] * found.u[:, None, :] + sin[None, :, None] * found.v[:, None, :]
    )
    arm = (found.points - origin) / scale
    ends = np.stack([found.second, found.first], axis=1)
    signs = np.array([1.0, -1.0])
    total_columns = len(found.points) * CONE_SIDES
    columns = np.arange(total_columns).reshape(-1, CONE_SIDES)

    def matrix(force: NDArray[np.float64]) -> sp.csr_matrix:
        moment = np.cross(arm[:, None, :], force)
        wrench = np.concatenate([force, moment], axis=2)  # P x S x 6
        # P x 2 (pushed, pushing) x S x 6, each row divided by its part's weight
        data = signs[None, :, None, None] * wrench[:, None] / weight[ends][:, :, None, None]
        rows = 6 * ends[:, :, None, None] + np.arange(6)[None, None, None, :]
        cols = np.broadcast_to(columns[:, None, :, None], data.shape)
        return sp.csr_matrix(
            (data.ravel(), (np.broadcast_to(rows, data.shape).ravel(), cols.ravel())),
            shape=(6 * len(names), total_columns),
        )

    load = np.concatenate(
        [np.tile(down, (len(names), 1)), np.cross((centres - origin) / scale, down)], axis=1
    )
    return EquilibriumModel(
        names=names,
        normal_part=matrix(normal_force),
        tangent_part=matrix(tangent_force),
        load=load.ravel(),
        point_parts=ends,
        corners=found.corners,
        heights=centres @ down,
        offsets=np.linalg.norm(np.cross(centres - origin, down), axis=1),
        fixed=tuple(fixed) if fixed is not None else lowest_parts(assembly, down, tol),
        friction=float(friction),
        threshold=max(tol.rel_length, LP_FEASIBILITY),
    )


def equilibrium(
    assembly: Assembly,
    direction: ArrayLike = DOWN,
    friction: float = FRICTION,
    fixed: Sequence[str] | None = None,
    held: Iterable[str] = (),
    densities: Mapping[str, float] | None = None,
    tol: Tolerance | None = None,
) -> Equilibrium:
    """Whether every part of ``assembly`` stands under gravity along ``direction``, with
    ``fixed`` (default: :func:`lowest_parts`) and ``held`` parts immobile."""
    model = equilibrium_model(assembly, direction, friction, fixed, densities, tol)
    return model.check(held=held)
