"""A set of parts, as the planner and the blocking layer hold it: an ``int`` bit mask
over an assembly's parts in their order, bit ``i`` for part ``i`` (Python integers have
no size limit, so any number of parts fits, and union, intersection and difference are
``|``, ``&`` and ``& ~``). Where a set meets numpy, it becomes a boolean vector
(:func:`mask_vector`) or comes from one row of little-endian packed bits
(:func:`row_mask`: the rows of a direction table, docs/blocking.md); no other form of a
set of parts is passed between modules.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TypeVar, cast

import numpy as np
from numpy.typing import NDArray

PartSet = int
"""A set of parts: the bit mask over an assembly's parts in their order (module
docstring)."""

Rows = TypeVar("Rows", NDArray[np.uint8], NDArray[np.bool_])
"""A matrix of sets, one per row: packed bits (bytes) or booleans."""


def bits(mask: PartSet) -> Iterable[int]:
    """The indices of the set bits of ``mask``, in increasing order."""
    index = 0
    while mask:
        if mask & 1:
            yield index
        mask >>= 1
        index += 1


def mask_of(indices: Iterable[int]) -> PartSet:
    """The bit mask of a set of indices."""
    total = 0
    for i in indices:
        total |= 1 << int(i)  # numpy integers would overflow past 63 parts
    return total


def union_of(masks: Iterable[PartSet]) -> PartSet:
    """The union of bit masks."""
    total = 0
    for mask in masks:
        total |= mask
    return total


def mask_vector(mask: PartSet, count: int) -> NDArray[np.bool_]:
    """The bit mask ``mask`` as a boolean vector of its first ``count`` bits."""
    size = max(count, mask.bit_length(), 1)
    packed = np.frombuffer(mask.to_bytes((size + 7) // 8, "little"), dtype=np.uint8)
    return np.unpackbits(packed, count=count, bitorder="little").astype(bool)


def row_mask(row: NDArray[np.uint8]) -> PartSet:
    """The bit mask held by one row of little-endian packed bits (``np.packbits(...,
    bitorder="little")``)."""
    return int.from_bytes(row.tobytes(), "little")


def distinct_rows(rows: Rows) -> tuple[Rows, NDArray[np.int64]]:
    """The distinct rows of a matrix of bytes or booleans (packed or unpacked sets, one
    per row), in the order of ``np.unique(rows, axis=0)``, and the index of each row
    among them. Each row is compared as one byte string, a single sort of a vector,
    where ``np.unique`` with ``axis=0`` compares the rows column by column (on a
    direction table of 15,000 rows of 300 bytes, 8 ms against 0.31 s)."""
    whole = np.ascontiguousarray(rows)
    if whole.shape[1] == 0:
        return whole[: min(len(whole), 1)], np.zeros(len(whole), dtype=np.int64)
    strings = whole.view(np.dtype((np.void, whole.shape[1] * whole.itemsize))).ravel()
    found, inverse = np.unique(strings, return_inverse=True)
    distinct = found.view(whole.dtype).reshape(len(found), whole.shape[1])
    return cast(Rows, distinct), inverse.astype(np.int64).ravel()


def count_bits(mask: PartSet) -> int:
    """The number of set bits of ``mask``."""
    return bin(mask).count("1")


def several(mask: PartSet) -> bool:
    """Whether ``mask`` has more than one bit set."""
    return (mask & (mask - 1)) != 0
