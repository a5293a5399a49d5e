"""The one tolerance policy of assemblykit (docs/architecture.md, "Tolerances"; docs/algebra.md §1).

* **Lengths** are compared relative to the model's size: ``length = rel_length x scale``
  where ``scale`` is the bounding-box diagonal of the model (1 when unknown).
* **Angles** are compared absolutely, in radians.
* **One knob, both kinds**: a relative length error ``e`` over the model's size turns a
  direction by about ``e`` radians, so when only the relative length tolerance is given
  (``--tolerance``) the angle tolerance follows it (``angle = rel_length``); an explicit
  angle tolerance (``--angle-tolerance``) overrides that (:meth:`Tolerance.relative`).
* **Mixed residuals** (the numeric residue solver) weigh an angle θ as the length
  ``θ x arm`` with ``arm = length / angle`` (the model's size when the angle follows the
  length), so one threshold, ``length``, holds lengths and angles to their own tolerance.
* **Monotone answers**: a looser tolerance only ever accepts more; numeric solvers stop on
  :attr:`Tolerance.precision`, never looser than the default, so loosening the
  acceptance never stops a solver short of a solution it found before; numerical
  decisions (regular or singular systems) use it too, and a numeric solution's dof is
  measured against its own residual (:meth:`Tolerance.rank`), not the tolerance.
* **Near misses**: a mismatch within ``NEARLY_CONSISTENT`` times the tolerance is reported
  with the tolerance that accepts it (:meth:`Tolerance.needed`).
* **Defaults from real data**: 1e-6 of the model's size and 1e-6 rad, the precision of
  numbers written to six decimals, so that rounded, rotated and slightly perturbed
  input keeps its answers (task files and STEP surfaces alike). Triangle meshes and
  fitted surfaces use ``mesh_rel_length`` / ``mesh_angle`` as a floor (coordinates in
  OBJ/STL files carry about seven significant digits), raised to the precision measured
  in the input itself (:mod:`assemblykit.geometry.precision`).

Every geometric predicate takes its tolerance from a :class:`Tolerance` value: either
passed explicitly or the *current* one, set for a block of code with :func:`using`.
No other module defines its own epsilon.
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
import math
from collections.abc import Iterator
from dataclasses import dataclass, replace

DEFAULT_REL_LENGTH = 1e-6
"""The default relative length tolerance: numbers as real data writes them, to six
decimals (CAD exports, hand-written tasks, float32 meshes resolve about 6e-8), so that a
model rounded, rotated or perturbed at that precision keeps its answers while a misfit
of 1e-4 of the model is still one."""

DEFAULT_ANGLE = 1e-6
"""The default angle tolerance (radians): a unit vector written to six decimals points
within about 1e-6 rad of the one meant."""

SOLVER_PRECISION = 1e-9
"""Where numeric solvers stop and what counts as a singular system
(:attr:`Tolerance.precision`): far below any tolerance, so that loosening one never stops a
solver short of a solution it found before."""
DEFAULT_MESH_REL_LENGTH = 1e-6
DEFAULT_MESH_ANGLE = 1e-5

MAX_MAGNITUDE = 1e100
"""Largest coordinate, length or radius accepted from a file: sums of squares (norms) and
products of three (volumes) of such numbers stay finite in float64 (at most 1.8e308)."""

MIN_REL_LENGTH = 1e-15
"""Smallest relative length tolerance a user may ask for: below float64's resolution
(2.2e-16 relative) no two computed lengths could ever be told equal."""

MAX_REL_LENGTH = 0.1
"""Largest relative length tolerance a user may ask for: a tenth of the model's size.
Beyond it whole parts coincide and every answer (contact, blocking, fit) is meaningless."""

MIN_ANGLE = MIN_REL_LENGTH
"""Smallest angle tolerance (radians) a user may ask for: float64's resolution, as for
lengths (a unit vector's entries resolve about 1e-16 rad)."""

MAX_ANGLE = MAX_REL_LENGTH
"""Largest angle tolerance (radians, about 5.7 degrees) a user may ask for: the angle a
relative length error of ``MAX_REL_LENGTH`` turns a direction by."""

RANK_MARGIN = 10.0
"""How far above the relative residual of a numeric solution a Jacobian's singular value
must be to count as a constraint (:meth:`Tolerance.rank`)."""

NEARLY_CONSISTENT = 1000.0
"""A conflict whose mismatch is within this factor of the tolerance in force is reported
as *nearly consistent*, with the tolerance that would accept it."""

ORDER_RESOLUTION = 1e-9
"""Where a choice follows an order of computed numbers (which candidate part or direction
first, which part is the heaviest), they are compared after rounding to this fraction
of their scale (:func:`order_key`), and the equal ones by index. A centroid's height or
a volume is computed to about 1e-15 of the model's size, in an order of summation that
the versions of numpy and trimesh and the machine's vector instructions decide; mirror
images differ by that much alone (166 of the cross vault's 183 pairs of neighbouring
heights), while real data is written to 1e-6. Without the rounding such ties were broken
by the last bits, and a plan differed between installs."""


ROUNDED_DIGITS = range(5, 10)
"""A number written with this many significant digits (5 to 9) is taken as rounded at its
last digit (:func:`written_resolution`): a value typed from a drawing or exported to a
fixed count of digits (``0.86603``, ``12.3457``). Fewer digits (``12.5``, ``0.25``) are
values as designed, more (``0.8660254037844386``) are computed to full precision."""

ROUNDING_MARGIN = 10.0
"""How many times the resolution of a task's written numbers its tolerance is at least
(docs/inference.md, "Tolerances and rounded numbers"): rounding errors add up over the
coordinates of a point and the two features of a relation, and ten times the rounding is
what the bundled tasks need to keep their answers."""


def written_resolution(value: float) -> float:
    """Half a unit in the last place of ``value`` as its shortest text writes it
    (``repr``, which gives back the digits a file wrote), when it has
    :data:`ROUNDED_DIGITS` significant digits and is not a whole number; 0 otherwise
    (docs/architecture.md, "Tolerances").

    >>> written_resolution(0.86603), written_resolution(12.5), written_resolution(math.sqrt(3) / 2)
    (5e-06, 0.0, 0.0)
    """
    if not math.isfinite(value) or value == round(value):
        return 0.0  # whole numbers are exact, as a drawing's dimensions in whole units
    digits = repr(abs(float(value))).lower()
    mantissa, _, exponent = digits.partition("e")
    whole, _, fraction = mantissa.partition(".")
    fraction = fraction.rstrip("0")
    significant = (whole + fraction).lstrip("0")
    if len(significant) not in ROUNDED_DIGITS:
        return 0.0
    return 0.5 * 10.0 ** (int(exponent or 0) - len(fraction))


def order_key(value: float, scale: float) -> int:
    """``value`` as the integer that orders it (:data:`ORDER_RESOLUTION` of ``scale``)."""
    return round(value / (ORDER_RESOLUTION * scale)) if scale > 0 else 0


@dataclass(frozen=True, eq=False)
class Tolerance:
    """A tolerance policy: a length scale and relative/absolute thresholds.

    A tolerance goes through three stages (docs/architecture.md, "Tolerances"): the
    policy asked for (``--tolerance``, :meth:`relative`, or :data:`DEFAULT`), that policy
    scaled to a model (:meth:`with_scale`), and the :class:`ModelTolerance` a model's
    geometry is compared with. Two tolerances with the same numbers are equal, whatever
    their stage, since every predicate gives them the same answers."""

    scale: float = 1.0
    rel_length: float = DEFAULT_REL_LENGTH
    angle: float = DEFAULT_ANGLE
    mesh_rel_length: float = DEFAULT_MESH_REL_LENGTH
    mesh_angle: float = DEFAULT_MESH_ANGLE

    def __post_init__(self) -> None:
        for name in ("scale", "rel_length", "angle", "mesh_rel_length", "mesh_angle"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"tolerance {name} must be a positive number, got {value!r}")

    def _numbers(self) -> tuple[float, float, float, float, float]:
        return (self.scale, self.rel_length, self.angle, self.mesh_rel_length, self.mesh_angle)

    @functools.cached_property
    def _hash(self) -> int:
        """The hash of the numbers, found once: a tolerance keys the stores of derived
        data, so its hash is asked for very often."""
        return hash(self._numbers())

    def __eq__(self, other: object) -> bool:
        if self is other:
            return True
        if not isinstance(other, Tolerance):
            return NotImplemented
        return self._hash == other._hash and self._numbers() == other._numbers()

    def __hash__(self) -> int:
        return self._hash

    @property
    def length(self) -> float:
        """Absolute length tolerance for exact geometry, in model units."""
        return self.rel_length * self.scale

    @property
    def mesh_length(self) -> float:
        """Absolute length tolerance for mesh (approximate) geometry, in model units."""
        return self.mesh_rel_length * self.scale

    @property
    def arm(self) -> float:
        """The length an angle of one radian weighs in mixed residuals: ``length / angle``
        (the model's size when the angle follows the relative length)."""
        return self.length / self.angle

    @property
    def precision(self) -> float:
        """The threshold of numerical decisions: the relative step and cost change at which
        numeric solvers stop, the conditioning below which a small linear system counts as
        singular. The tighter of the tolerances and the default, so a looser tolerance
        never stops a solver earlier nor calls a regular system singular (which would make
        answers depend on the coordinates, not only on the geometry)."""
        return min(self.rel_length, self.angle, SOLVER_PRECISION)

    def rank(self, residual: float = 0.0) -> float:
        """Relative singular value below which a Jacobian direction counts as free at a
        numeric solution whose worst residual is ``residual`` (model units): the mesh
        angle (the numeric solvers' own precision), or ``RANK_MARGIN`` times the relative
        residual when larger (rounded data perturbs the Jacobian by about as much as it
        leaves in the residual). It does not depend on the tolerance asked for, so
        loosening the tolerance never changes a measured dof."""
        return max(self.mesh_angle, RANK_MARGIN * residual / self.scale)

    @classmethod
    def relative(cls, rel_length: float | None = None, angle: float | None = None) -> Tolerance:
        """The policy of the command line's ``--tolerance`` (``rel_length``) and
        ``--angle-tolerance`` (``angle``, radians): the angle follows the relative length
        unless given (module docstring); the defaults for what is not given."""
        base = cls() if rel_length is None else cls(rel_length=rel_length, angle=rel_length)
        return base if angle is None else replace(base, angle=angle)

    def needed(self, kind: str, value: float) -> float | None:
        """The relative tolerance (``--tolerance``, the angle following it) at which a
        mismatch of ``kind`` and size ``value`` is accepted: the mismatch measured (an angle
        in radians as it is, a length over the model's size) rounded up to two significant
        digits; ``None`` when it is not within ``NEARLY_CONSISTENT`` times the tolerance in
        force or beyond ``MAX_REL_LENGTH``."""
        if kind == "angle":
            relative, limit = value, self.angle
        elif kind in LENGTH_MISMATCHES:
            relative, limit = value / self.scale, self.rel_length
        else:
            return None
        if not (math.isfinite(relative) and 0 < relative <= NEARLY_CONSISTENT * limit):
            return None
        suggested = round_up(relative)
        return suggested if suggested <= MAX_REL_LENGTH else None

    def with_scale(self, scale: float) -> Tolerance:
        """The same policy for a model whose bounding-box diagonal is ``scale``."""
        return replace(self, scale=scale if scale > 0 else 1.0)

    def for_mesh(self) -> Tolerance:
        """The policy applied to approximate geometry: mesh thresholds become the exact ones."""
        return replace(self, rel_length=self.mesh_rel_length, angle=self.mesh_angle)


class ModelTolerance(Tolerance):
    """The tolerance one model's geometry is compared with (docs/architecture.md,
    "Tolerances"): a policy scaled to the model's size and, for mesh input, raised to the
    mesh thresholds and to the precision measured in the input. The entry points of the
    library (``plan``, ``blocking_graph``, ``motion``, ``Task.solve``, ...) resolve the
    policy they are given once (``assembly.tolerance(tol)``); the functions below them
    take a :class:`ModelTolerance` and use it as it is, and a model given its own
    tolerance back returns it unchanged."""

    @classmethod
    def of(cls, tol: Tolerance) -> ModelTolerance:
        """``tol``'s numbers as the tolerance of a model (no change when it is one)."""
        if isinstance(tol, ModelTolerance):
            return tol
        return cls(tol.scale, tol.rel_length, tol.angle, tol.mesh_rel_length, tol.mesh_angle)


LENGTH_MISMATCHES = frozenset({"distance", "radius", "size", "residual", "loop"})
"""Mismatch kinds measured in model units (numeric residuals weigh angles as lengths)."""


def round_up(value: float) -> float:
    """``value`` (positive) rounded up to two significant digits, strictly above it, so
    that a tolerance of the result accepts a mismatch of ``value``."""
    step = 10.0 ** (math.floor(math.log10(value)) - 1)
    # printed with two digits, so that the result reads as the number it is
    rounded = float(f"{(math.floor(value / step) + 1) * step:.1e}")
    return rounded if rounded > value else float(f"{rounded + step:.1e}")


DEFAULT = Tolerance()

_current: contextvars.ContextVar[Tolerance] = contextvars.ContextVar(
    "assemblykit_tolerance", default=DEFAULT
)


def current() -> Tolerance:
    """The tolerance in force (set by :func:`using`; the defaults otherwise)."""
    return _current.get()


@contextlib.contextmanager
def using(tol: Tolerance) -> Iterator[Tolerance]:
    """Make ``tol`` the current tolerance inside a ``with`` block."""
    token = _current.set(tol)
    try:
        yield tol
    finally:
        _current.reset(token)
