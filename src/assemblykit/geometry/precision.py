"""The input's own precision, measured from the data (extends the policy of tolerance.py).

The tolerance policy fixes how precisely geometry is *compared*; the data fixes how
precisely it was *given*. A loader measures the second (a
:class:`~assemblykit.model.assembly.Precision`) and records it on the
:class:`~assemblykit.model.assembly.Assembly`, whose length tolerance is then
``max(policy, measured)``: a comparison never asks for more precision than the input has.

* **Coordinates.** Vertices that are all exactly representable in float32 carry the
  precision of float32 (half a float32 spacing at the largest coordinate); float64
  coordinates carry half a float64 spacing.
* **Faces out of plane.** Coordinates may carry more digits than they are precise to: a
  mesh processed in float32, written by a program that rounds, or jittered. Its flat
  faces then come as triangles slightly out of one plane. A *flat* is a group of
  triangles joined by edges across which the surface turns by less than
  :data:`FLAT_ANGLE`, every triangle's normal within that angle of the group's mean
  (a curved surface, however finely tessellated, turns by more over its whole extent);
  its *warp* is the largest distance of its vertices from its mean plane. Two warped
  faces in contact may cross each other by both warps, so the precision is twice the
  largest warp (rounded up to two significant digits).
* **Poses** (``final_state`` of a mesh folder's ``config.json``). A number written with
  ``k >= 1`` decimals is taken as rounded to ``k`` decimals; integers are exact. With
  ``k_t`` the most decimals among the translations and ``k_r`` among the angles, a
  vertex at distance ``r`` from its part's origin may be misplaced by up to
  ``sqrt(3) (0.5 x 10^-k_t + r x 0.5 x 10^-k_r)``.
* **Block joints** (COMPAS block assemblies). Blocks designed to meet face to face may
  be given with faces that do not quite match: the dome of ``compas_assembly`` has
  joints tilted by up to 5.6 degrees and 2.9 cm out of each other's plane. A *joint* is
  a pair of faces of two blocks, with opposed normals within :data:`MAX_JOINT_TILT`,
  whose planes cross inside their common outline (the faces touch along a line or
  coincide); its *mismatch* is the largest distance of the vertices of one face from
  the other's plane (the smaller of the two ways). Parallel faces with a gap, and faces
  sunk into each other, do not cross and are not joints. The precision is the largest
  mismatch, rounded up to two significant digits.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from decimal import Decimal

import numpy as np
import shapely
import trimesh
from numpy.typing import NDArray

from assemblykit.geometry.broad_phase import candidate_pairs, facing_groups, stack_parts
from assemblykit.geometry.narrow_phase import group_deviation, group_overlaps
from assemblykit.geometry.recognition import segment
from assemblykit.graphs import component_labels
from assemblykit.model.assembly import Assembly, Precision
from assemblykit.tolerance import Tolerance

MAX_JOINT_TILT = math.radians(10.0)

FLAT_ANGLE = 1e-3
"""Triangles whose normals are within this angle (radians, 0.057 degrees) of each
other and of their group's mean count as one flat face out of plane (module docstring):
well above the turn that noise of 1e-5 of a triangle's size gives, well below a draft
angle or the facets of a tessellated cylinder."""


def combined(precisions: Iterable[Precision]) -> Precision | None:
    """The coarsest of ``precisions`` (``None`` when there is none)."""
    return max(precisions, key=lambda p: p.length, default=None)


def round_up(value: float) -> float:
    """``value`` rounded up to two significant digits (0 stays 0)."""
    if value <= 0:
        return 0.0
    step = 10.0 ** (math.floor(math.log10(value)) - 1)
    return math.ceil(value / step) * step


def coordinate_precision(vertices: NDArray[np.float64]) -> Precision:
    """Half the float spacing at the largest coordinate: float32 when every coordinate
    is exactly a float32, float64 otherwise (module docstring)."""
    values = np.asarray(vertices, dtype=np.float64)
    largest = float(np.abs(values).max()) if values.size else 0.0
    single = bool(np.array_equal(values.astype(np.float32).astype(np.float64), values))
    kind = np.float32 if single else np.float64
    return Precision(
        float(np.spacing(kind(largest))) / 2,
        f"{'float32' if single else 'float64'} coordinates",
    )


ROUNDING_WARP = 16.0
"""A warp within this many times the coordinates' precision is the rounding of computed
heights (a few units in the last place), which the coordinates' precision already
covers."""


def surface_warp(mesh: trimesh.Trimesh) -> float:
    """The largest distance of a vertex of a flat face (module docstring, "Faces out of
    plane") from that face's mean plane; 0 when every flat face is exactly flat."""
    normals, areas = mesh.face_normals, mesh.area_faces
    if len(normals) < 2:
        return 0.0
    pairs = mesh.face_adjacency[mesh.face_adjacency_angles < FLAT_ANGLE]
    labels = component_labels(len(normals), pairs)
    counts = np.bincount(labels)
    mean = np.zeros((len(counts), 3))
    np.add.at(mean, labels, normals * areas[:, None])
    length = np.linalg.norm(mean, axis=1, keepdims=True)
    mean = np.divide(mean, length, out=np.zeros_like(mean), where=length > 0)
    # a group is a flat when it has two faces or more, none turned too far from its mean
    turned = np.zeros(len(counts), dtype=bool)
    np.logical_or.at(
        turned, labels, np.einsum("ij,ij->i", normals, mean[labels]) < math.cos(FLAT_ANGLE)
    )
    flat = (counts >= 2) & ~turned & (length[:, 0] > 0)
    faces = np.flatnonzero(flat[labels])
    if not len(faces):
        return 0.0
    group = np.repeat(labels[faces], 3)
    heights = np.einsum("ij,ij->i", mesh.vertices[mesh.faces[faces].ravel()], mean[group])
    top = np.full(len(counts), -np.inf)
    bottom = np.full(len(counts), np.inf)
    np.maximum.at(top, group, heights)
    np.minimum.at(bottom, group, heights)
    spread = (top - bottom)[flat]
    return float(spread.max() / 2)


def mesh_precision(mesh: trimesh.Trimesh) -> Precision:
    """How precise a mesh's geometry is: the coarser of its coordinates' float precision
    (:func:`coordinate_precision`) and twice the warp of its flat faces
    (:func:`surface_warp`; module docstring)."""
    coordinates = coordinate_precision(mesh.vertices)
    warp = round_up(2 * surface_warp(mesh))
    # a warp of a few units in the last place is the arithmetic's, not the data's
    if warp <= ROUNDING_WARP * coordinates.length:
        return coordinates
    return Precision(warp, f"flat faces out of plane by up to {warp / 2:.2g}")


def decimals(value: float) -> int:
    """How many decimals the shortest text of ``value`` has (0 for integers)."""
    exponent = Decimal(repr(float(value))).normalize().as_tuple().exponent
    return max(-int(exponent), 0) if isinstance(exponent, int) else 0


def pose_precision(states: Sequence[Sequence[float]], radius: float) -> Precision | None:
    """How far rounding the ``[x, y, z, rx, ry, rz]`` ``states`` to their written decimals
    may move a vertex at distance ``radius`` from its part's origin (module docstring);
    ``None`` when every number is an integer."""
    k_t = max((decimals(v) for s in states for v in s[:3]), default=0)
    k_r = max((decimals(v) for s in states for v in s[3:6]), default=0)
    shift = 0.5 * 10.0**-k_t if k_t else 0.0
    turn = 0.5 * 10.0**-k_r if k_r else 0.0
    if shift == 0 and turn == 0:
        return None
    return Precision(
        math.sqrt(3) * (shift + radius * turn),
        f"final_state rounded to {k_t} decimals (translations), {k_r} (angles)",
    )


def joint_mismatch(assembly: Assembly, tol: Tolerance | None = None) -> Precision:
    """The largest mismatch of the block joints of ``assembly`` (module docstring), with
    faces and joints judged at the assembly's policy tolerance."""
    tol = assembly.policy_tolerance(tol)
    floor = tol.length
    names = list(assembly.parts)
    stack = stack_parts(p.mesh for p in assembly)
    seg = segment(stack.vertices, stack.faces, tol)
    part_lo = np.array([p.mesh.bounds[0] for p in assembly.parts.values()])
    part_hi = np.array([p.mesh.bounds[1] for p in assembly.parts.values()])
    pairs = candidate_pairs(np.stack([part_lo, part_hi], axis=1), floor)
    group_part = stack.part[seg.order[seg.start[:-1]]]
    g, h = facing_groups(seg, group_part, seg.flat, part_lo, part_hi, pairs, floor)
    opposed = np.einsum("ij,ij->i", seg.normal[g], seg.normal[h]) < -math.cos(MAX_JOINT_TILT)
    g, h = g[opposed], h[opposed]
    owner, pieces, u, v = group_overlaps(stack, seg, g, h, floor)
    coords, which = shapely.get_coordinates(pieces, return_index=True)
    pair = owner[which]
    n_g, n_h = seg.normal[g][pair], seg.normal[h][pair]
    points = coords[:, :1] * u[pair] + coords[:, 1:] * v[pair]
    # height of h's plane above g's plane, along g's normal, at each overlap vertex
    gap = np.einsum("ij,ij->i", n_h, seg.point[h][pair] - points) / np.einsum(
        "ij,ij->i", n_h, n_g
    ) - np.einsum("ij,ij->i", n_g, seg.point[g][pair] - points)
    lowest = np.full(len(g), np.inf)
    highest = np.full(len(g), -np.inf)
    np.minimum.at(lowest, pair, gap)
    np.maximum.at(highest, pair, gap)
    mismatch = np.minimum(group_deviation(stack, seg, g, h), group_deviation(stack, seg, h, g))
    reach, joint = floor, np.zeros(len(g), dtype=bool)
    while True:
        within = (lowest <= reach) & (highest >= -reach)
        if np.array_equal(within, joint):
            break
        joint = within
        reach = max(floor, float(mismatch[joint].max()))
    if not joint.any():
        return Precision(0.0, "no block joints")
    joined = {
        frozenset((names[a], names[b]))
        for a, b in zip(group_part[g[joint]], group_part[h[joint]], strict=True)
    }
    return Precision(
        round_up(float(mismatch[joint].max())),
        f"largest mismatch of the block joints ({len(joined)} block pairs, "
        f"tilted by at most {math.degrees(MAX_JOINT_TILT):g} deg)",
    )
