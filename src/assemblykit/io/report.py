"""JSON-ready values for every result type: the ``--json`` output (docs/architecture.md,
"Results and errors").

Results hold numpy arrays, numpy scalars, enums, paths, sets and nested dataclasses; the
command line needs plain lists, numbers, strings and dictionaries. Numbers are rounded so
that the output is readable (``6.123e-17`` from ``cos(pi/2)`` prints as ``0.0``) without
ever hiding a mismatch: a value is snapped to zero only when it is below the tolerance in
force (so the library itself would treat it as zero), and otherwise keeps
``SIGNIFICANT_DIGITS`` significant digits, which never turns a non-zero value into zero.
"""

from __future__ import annotations

import dataclasses
import enum
import functools
import math
from collections.abc import Mapping, Sequence
from collections.abc import Set as AbstractSet
from pathlib import PurePath
from typing import Any

import numpy as np

from assemblykit.errors import NumericError
from assemblykit.formatting import zero_threshold
from assemblykit.tolerance import Tolerance, current

SIGNIFICANT_DIGITS = 12

JsonValue = None | bool | int | float | str | list["JsonValue"] | dict[str, "JsonValue"]


def json_number(x: float, tol: Tolerance | None = None) -> float | str:
    """``x`` rounded for output: 0 below the tolerance, else 12 significant digits.

    The zero threshold is the smaller of the length and angle tolerances, so the value
    printed as 0 is one every predicate of the library already treats as 0. Infinite
    and NaN values become the strings ``"inf"``, ``"-inf"`` and ``"nan"`` because JSON
    has no literal for them and dropping them would hide a failure.
    """
    value = float(x)
    if not math.isfinite(value):
        return repr(value)
    if abs(value) <= zero_threshold(tol):
        return 0.0
    return float(f"{value:.{SIGNIFICANT_DIGITS}g}")


@functools.singledispatch
def jsonable(obj: object, tol: Tolerance | None = None) -> JsonValue:
    """``obj`` as a value :func:`json.dumps` accepts, numbers rounded by :func:`json_number`,
    dispatched on its type (:func:`functools.singledispatch`, beside
    :func:`assemblykit.render.render` for the readable form).

    Results (objects with a ``to_dict()`` method, docs/architecture.md, "Results and
    errors") are converted through it; other dataclasses become dictionaries of their
    fields; mappings get string keys; sets become sorted lists (so the output is
    deterministic); enums give their value; paths their text; arrays and sequences lists.
    """
    if hasattr(obj, "to_dict") and not isinstance(obj, type):
        return jsonable(obj.to_dict(), tol)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: jsonable(getattr(obj, f.name), tol) for f in dataclasses.fields(obj)}
    raise TypeError(f"cannot turn a {type(obj).__name__} into JSON")


@jsonable.register(type(None))
@jsonable.register(bool)
@jsonable.register(str)
def _as_it_is(obj: bool | str | None, tol: Tolerance | None = None) -> JsonValue:
    return obj


@jsonable.register
def _truth(obj: np.bool_, tol: Tolerance | None = None) -> JsonValue:
    return bool(obj)


@jsonable.register(int)
@jsonable.register(np.integer)
def _whole(obj: int | np.integer[Any], tol: Tolerance | None = None) -> JsonValue:
    return int(obj)


@jsonable.register(float)
@jsonable.register(np.floating)
def _real(obj: float | np.floating[Any], tol: Tolerance | None = None) -> JsonValue:
    return json_number(float(obj), current() if tol is None else tol)


@jsonable.register
def _member(obj: enum.Enum, tol: Tolerance | None = None) -> JsonValue:
    return jsonable(obj.value, tol)


@jsonable.register
def _path(obj: PurePath, tol: Tolerance | None = None) -> JsonValue:
    return str(obj)


@jsonable.register
def _array(obj: np.ndarray, tol: Tolerance | None = None) -> JsonValue:
    return [jsonable(item, tol) for item in obj.tolist()]


@jsonable.register(Mapping)
def _mapping(obj: Mapping[object, object], tol: Tolerance | None = None) -> JsonValue:
    return {str(key): jsonable(value, tol) for key, value in obj.items()}


@jsonable.register(set)
@jsonable.register(frozenset)
def _set(obj: AbstractSet[object], tol: Tolerance | None = None) -> JsonValue:
    return sorted((jsonable(item, tol) for item in obj), key=repr)


@jsonable.register(list)
@jsonable.register(tuple)
def _sequence(obj: Sequence[object], tol: Tolerance | None = None) -> JsonValue:
    return [jsonable(item, tol) for item in obj]


def pose_list(pose: Any, tol: Tolerance | None = None) -> list[list[float]]:
    """A 4x4 homogeneous pose (docs/architecture.md, "Conventions") as four rows of rounded
    floats."""
    matrix = np.asarray(pose, dtype=np.float64)
    if matrix.shape != (4, 4):
        raise NumericError(f"a pose must be a 4x4 matrix, got shape {matrix.shape}")
    if not np.all(np.isfinite(matrix)):
        raise NumericError("a pose has non-finite entries")
    return [[float(json_number(value, tol)) for value in row] for row in matrix]
