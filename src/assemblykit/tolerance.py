"""The one tolerance policy of assemblykit (DESIGN.md §4, ALGEBRA.md §1).

* **Lengths** are compared relative to the model's size: ``length = rel_length x scale``
  where ``scale`` is the bounding-box diagonal of the model (1 when unknown).
* **Angles** are compared absolutely, in radians.
* Exact input (task files, STEP surfaces) uses the tight defaults (1e-9).
  Approximate input (triangle meshes, fitted surfaces) uses the looser
  ``mesh_rel_length`` / ``mesh_angle``, because coordinates in OBJ/STL files carry only
  about seven significant digits.

Every geometric predicate takes its tolerance from a :class:`Tolerance` value: either
passed explicitly or the *current* one, set for a block of code with :func:`using`.
No other module defines its own epsilon.
"""

from __future__ import annotations

import contextlib
import contextvars
import math
from collections.abc import Iterator
from dataclasses import dataclass, replace

DEFAULT_REL_LENGTH = 1e-9
DEFAULT_ANGLE = 1e-9
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


@dataclass(frozen=True)
class Tolerance:
    """Tolerances for one model: a length scale and relative/absolute thresholds."""

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

    @property
    def length(self) -> float:
        """Absolute length tolerance for exact geometry, in model units."""
        return self.rel_length * self.scale

    @property
    def mesh_length(self) -> float:
        """Absolute length tolerance for mesh (approximate) geometry, in model units."""
        return self.mesh_rel_length * self.scale

    def with_scale(self, scale: float) -> Tolerance:
        """The same policy for a model whose bounding-box diagonal is ``scale``."""
        return replace(self, scale=scale if scale > 0 else 1.0)

    def for_mesh(self) -> Tolerance:
        """The policy applied to approximate geometry: mesh thresholds become the exact ones."""
        return replace(self, rel_length=self.mesh_rel_length, angle=self.mesh_angle)


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
