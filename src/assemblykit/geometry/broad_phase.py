"""The broad phase of finding contacts: which parts, and which of their faces, may touch.

The contacts of an assembly (:mod:`assemblykit.geometry.contacts`) are looked for only
where they may be. A broad phase over the parts' bounding boxes (an R-tree, boxes
inflated by the length tolerance: :func:`candidate_pairs`) keeps only pairs that may
touch, so the cost grows with the number of touching pairs (docs/geometry.md, "The
contact model"). All parts' triangles are stacked in one array (:class:`PartStack`), so
that what follows runs over all candidate pairs at once; per pair of parts,
:func:`facing_groups` keeps the coplanar groups of facets
(:func:`~assemblykit.geometry.recognition.segment`) of each part whose boxes meet the
other part's box and each other: the only ones compared for planar contacts.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
import trimesh
from numpy.typing import NDArray
from rtree import index

from assemblykit.geometry.recognition import Segmentation
from assemblykit.ragged import group_of, group_starts


def candidate_pairs(
    bounds: NDArray[np.float64], margin: float, only: int | None = None
) -> NDArray[np.int64]:
    """Pairs ``(i, j)``, ``i < j``, of boxes (``n x 2 x 3``) that overlap once inflated by
    ``margin`` (one bulk R-tree query); with ``only``, just the pairs involving it."""
    lo, hi = bounds[:, 0] - margin, bounds[:, 1] + margin
    tree = index.Index(
        ((i, tuple(box), None) for i, box in enumerate(np.hstack([lo, hi]))),
        properties=index.Property(dimension=3),
    )
    queries = np.arange(len(bounds)) if only is None else np.array([only])
    if len(bounds) == 0:
        return np.zeros((0, 2), dtype=np.int64)
    found, counts = tree.intersection_v(
        np.ascontiguousarray(lo[queries]), np.ascontiguousarray(hi[queries])
    )
    pairs = np.column_stack([np.repeat(queries, counts.astype(np.int64)), found.astype(np.int64)])
    pairs = np.sort(pairs[pairs[:, 0] != pairs[:, 1]], axis=1)
    return np.unique(pairs, axis=0) if len(pairs) else np.zeros((0, 2), dtype=np.int64)


def boxes_overlap(
    lo_a: NDArray[np.float64],
    hi_a: NDArray[np.float64],
    lo_b: NDArray[np.float64],
    hi_b: NDArray[np.float64],
    margin: float,
) -> NDArray[np.bool_]:
    """Whether the boxes ``(lo_a, hi_a)`` and ``(lo_b, hi_b)`` meet once inflated by
    ``margin`` (corners along the last axis, the others broadcast)."""
    return np.all((lo_a <= hi_b + margin) & (lo_b <= hi_a + margin), axis=-1)


@dataclass(frozen=True)
class PartStack:
    """All parts' triangles in one array (vertex indices offset per part): ``part`` is
    each face's part index, ``face_start`` each part's first face."""

    vertices: NDArray[np.float64]
    faces: NDArray[np.int64]
    part: NDArray[np.int64]
    face_start: NDArray[np.int64]


def stack_parts(meshes: Iterable[trimesh.Trimesh]) -> PartStack:
    """The triangles of ``meshes`` (the parts of an assembly, in order) in one
    :class:`PartStack`."""
    meshes = list(meshes)
    n_vertices = np.array([len(m.vertices) for m in meshes], dtype=np.int64)
    n_faces = np.array([len(m.faces) for m in meshes], dtype=np.int64)
    vertex_start = group_starts(n_vertices)
    faces = np.concatenate(
        [np.asarray(m.faces, dtype=np.int64) + s for m, s in zip(meshes, vertex_start, strict=True)]
    )
    vertices = np.concatenate([np.asarray(m.vertices, dtype=np.float64) for m in meshes])
    return PartStack(vertices, faces, group_of(n_faces), group_starts(n_faces))


def facing_groups(
    seg: Segmentation,
    group_part: NDArray[np.int64],
    usable: NDArray[np.bool_],
    part_lo: NDArray[np.float64],
    part_hi: NDArray[np.float64],
    pairs: NDArray[np.int64],
    margin: float,
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Usable group pairs ``(g, h)``, ``g`` of the first part of a pair and ``h`` of the
    second, whose bounding boxes overlap each other's part and each other (inflated by
    ``margin``), in the order of the pairs, then of ``g``, then of ``h``. Per pair of
    parts, only the groups whose box meets the other part's box are compared, all of
    one side against all of the other at once: the work follows the groups near the
    other part (a threaded screw's thousands of facets against a plate's hole), not
    every group of either part."""
    candidates = np.flatnonzero(usable)
    owners = group_part[candidates]
    order = np.argsort(owners, kind="stable")
    candidates, owners = candidates[order], owners[order]
    count = len(part_lo)
    starts = np.searchsorted(owners, np.arange(count + 1))
    firsts, seconds = [np.zeros(0, dtype=np.int64)], [np.zeros(0, dtype=np.int64)]
    for p, q in pairs.tolist():
        g = _near_box(seg, candidates[starts[p] : starts[p + 1]], part_lo[q], part_hi[q], margin)
        h = _near_box(seg, candidates[starts[q] : starts[q + 1]], part_lo[p], part_hi[p], margin)
        if not len(g) or not len(h):
            continue
        for lo in range(0, len(g), max(1, _BOX_BLOCK // len(h))):
            rows = g[lo : lo + max(1, _BOX_BLOCK // len(h))]
            meets = boxes_overlap(
                seg.lo[rows, None], seg.hi[rows, None], seg.lo[None, h], seg.hi[None, h], margin
            )
            i, j = np.nonzero(meets)
            firsts.append(rows[i])
            seconds.append(h[j])
    return np.concatenate(firsts), np.concatenate(seconds)


_BOX_BLOCK = 1 << 21
"""How many pairs of group boxes :func:`facing_groups` compares in one array."""


def _near_box(
    seg: Segmentation,
    groups: NDArray[np.int64],
    lo: NDArray[np.float64],
    hi: NDArray[np.float64],
    margin: float,
) -> NDArray[np.int64]:
    """The groups whose box (inflated by ``margin``) meets the box ``lo, hi``."""
    return groups[boxes_overlap(seg.lo[groups], seg.hi[groups], lo, hi, margin)]
