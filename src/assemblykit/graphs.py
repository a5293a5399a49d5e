"""Connected components of the graphs that pairs of indices make: parts that touch,
faces that share an edge, contact points joined by a joint (docs/architecture.md,
"Layers": the bottom layer, numpy and scipy only)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components


def component_labels(count: int, pairs: NDArray[np.int64]) -> NDArray[np.int64]:
    """Per node ``0 .. count - 1``, the label of its connected component in the
    undirected graph whose edges are the rows of ``pairs`` (``E x 2``), as
    :func:`scipy.sparse.csgraph.connected_components` numbers them.

    >>> component_labels(4, np.array([[0, 2], [3, 2]])).tolist()
    [0, 1, 0, 0]
    """
    edges = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(count, count))
    return connected_components(graph, directed=False)[1].astype(np.int64)
