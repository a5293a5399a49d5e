"""Ragged arrays: items stored one group after another, each group given by its size.

Contact patches by pair, triangles by part, constraint columns by term and incidences by
vertex are all kept so, in one flat array with the groups' sizes beside it. These are the
index arrays that walk such storage without a Python loop (the CSR layout of
:mod:`scipy.sparse`, whose ``indptr`` is :func:`group_starts` with the total appended).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray


def group_starts(sizes: ArrayLike) -> NDArray[np.int64]:
    """The index of each group's first item: the sizes summed before it.

    >>> group_starts([2, 0, 3]).tolist()
    [0, 2, 2]
    """
    counts = np.asarray(sizes, dtype=np.int64)
    return np.cumsum(counts) - counts


def group_of(sizes: ArrayLike) -> NDArray[np.int64]:
    """The group of each item.

    >>> group_of([2, 0, 3]).tolist()
    [0, 0, 2, 2, 2]
    """
    counts = np.asarray(sizes, dtype=np.int64)
    return np.repeat(np.arange(len(counts), dtype=np.int64), counts)


def ranges(starts: ArrayLike, sizes: ArrayLike) -> NDArray[np.int64]:
    """The ranges ``starts[k], ..., starts[k] + sizes[k] - 1`` one after another.

    >>> ranges([5, 0, 10], [2, 0, 3]).tolist()
    [5, 6, 10, 11, 12]
    """
    counts = np.asarray(sizes, dtype=np.int64)
    first = np.asarray(starts, dtype=np.int64)
    within = np.arange(int(counts.sum()), dtype=np.int64) - np.repeat(group_starts(counts), counts)
    return np.repeat(first, counts) + within
