"""A physical replay of translation plans, independent of the planner's bookkeeping.

Every part starts in place. Step ``s`` (of ``n``) translates its parts rigidly from
where they are along its direction by ``D_s = 4 diag 3^(n - s)`` (``diag``: the
assembly's bounding diagonal), so that they go to "infinity" and stay there:

* the distances shrink by 3 per step, so everything a set goes on to do after it left
  (all later steps add at most ``D_s / 2 - 2 diag`` to any offset) keeps it more than
  ``2 diag`` from where the others are: a set moved away is taken apart on its own
  (up to about 640 steps, where ``D_1`` leaves the floats);
* parts moved at one step stay together (and so do the parts no step moved): each is an
  obstacle to whatever moves near it later, whether or not the planner counts it as
  part of the step's ``rest``.

(Distances that grow from step to step would not do: a part lifted after the one on
top of it, along the same direction, would overtake it and pass through it.)

The volume a part sweeps is exact for a closed mesh: the part at its start and end and
the prism each triangle facing forward sweeps (the convex hull of the triangle and its
translate); for a convex part, the hull of the part and its translate. The sweep of a
moved part may share with every part the step does not move, where that part is, no more
volume than ``threshold`` beyond what the two shared before the step (parts modelled
interfering keep their overlap). Offsets are kept as the steps that made them and
subtracted step by step, so two parts that moved together are exactly together however
far they went. Volumes are manifold3d booleans; nothing here asks the planner's
blocking code.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import manifold3d
import numpy as np
import trimesh
from numpy.typing import NDArray

from assemblykit.geometry.interference import solid
from assemblykit.model.assembly import Assembly
from assemblykit.planning.sequence import Plan, Step

SHRINK = 3.0
"""Each step's distance is this many times the next one's (module docstring)."""


@dataclass(frozen=True)
class Clash:
    """A step (from 1) whose ``moved`` part sweeps ``volume`` of ``obstacle`` where it
    is, ``allowed`` being the threshold plus what the two shared before the step."""

    step: int
    moved: str
    obstacle: str
    volume: float
    allowed: float

    def __str__(self) -> str:
        return (
            f"step {self.step}: {self.moved} sweeps {self.volume:.6g} of {self.obstacle}"
            f" (allowed {self.allowed:.3g})"
        )


class _Replay:
    """Parts, their solids and their offsets (as the steps that moved them)."""

    def __init__(self, assembly: Assembly, steps: Sequence[Step]) -> None:
        self.assembly = assembly
        self.names = tuple(assembly.names)
        meshes = [assembly.parts[name].mesh for name in self.names]
        low = np.min([m.bounds[0] for m in meshes], axis=0)
        high = np.max([m.bounds[1] for m in meshes], axis=0)
        self.diagonal = float(np.linalg.norm(high - low))
        self.tol_length = assembly.tolerance().length
        count = len(steps)
        self.distances = [4.0 * self.diagonal * SHRINK ** (count - s) for s in range(1, count + 1)]
        if count and not np.isfinite(self.distances[0]):
            raise ValueError(f"{count} steps: the first one's distance is not a float")
        self.moves: list[NDArray[np.float64]] = []
        self.history: dict[str, list[int]] = {name: [] for name in self.names}
        self.solids: dict[str, manifold3d.Manifold] = {}

    def mesh(self, name: str) -> trimesh.Trimesh:
        return self.assembly.parts[name].mesh

    def solid(self, name: str) -> manifold3d.Manifold:
        if name not in self.solids:
            self.solids[name] = solid(self.mesh(name), name)
        return self.solids[name]

    def relative(self, name: str, to: str) -> NDArray[np.float64]:
        """The offset of ``name`` minus that of ``to``: the moves one made and not the
        other, so parts that moved together are exactly 0 apart."""
        mine, theirs = set(self.history[name]), set(self.history[to])
        total = np.zeros(3)
        for s in sorted(mine - theirs):
            total += self.moves[s]
        for s in sorted(theirs - mine):
            total -= self.moves[s]
        return total

    def threshold(self, a: str, b: str, threshold: float | None) -> float:
        """The volume counted as touching: the length tolerance over the smaller
        surface (the interference policy of docs/geometry.md) unless given."""
        if threshold is not None:
            return threshold
        return self.tol_length * min(float(self.mesh(a).area), float(self.mesh(b).area))


def _sphere(mesh: trimesh.Trimesh) -> tuple[NDArray[np.float64], float]:
    """A sphere holding ``mesh``: its bounding box's centre and half diagonal."""
    bounds = np.asarray(mesh.bounds, dtype=np.float64)
    return bounds.mean(axis=0), float(np.linalg.norm(bounds[1] - bounds[0])) / 2


class Sweep:
    """The volume a closed mesh sweeps translated by ``shift``, to be intersected with
    other solids: the hull of both copies when the mesh is convex; else both copies and
    the prism of every triangle facing forward (the hull of the triangle and its
    translate), each prism intersected on its own with a solid whose box it meets and
    the pieces joined (a union of thousands of long prisms is the slow part)."""

    def __init__(self, mesh: trimesh.Trimesh, shift: NDArray[np.float64]) -> None:
        vertices = np.asarray(mesh.vertices, dtype=np.float64)
        self.convex = bool(mesh.is_convex)
        if self.convex:
            self.hull = manifold3d.Manifold.hull_points(np.vstack([vertices, vertices + shift]))
            return
        self.ends = [solid(mesh), solid(mesh).translate(tuple(shift))]
        # the prisms with a volume (a sliver's is none: the two ends cover it, and a
        # flat hull is no solid for manifold3d to intersect)
        volume = np.asarray(mesh.area_faces) * (np.asarray(mesh.face_normals) @ shift)
        length = float(np.linalg.norm(shift))
        triangles = vertices[np.asarray(mesh.faces)[volume > 1e-12 * length * mesh.scale**2]]
        self.triangles = triangles
        self.low = np.minimum(triangles.min(axis=1), (triangles + shift).min(axis=1))
        self.high = np.maximum(triangles.max(axis=1), (triangles + shift).max(axis=1))
        self.shift = shift

    def shared(self, other: manifold3d.Manifold) -> float:
        """The volume the sweep shares with ``other``."""
        if self.convex:
            return float((self.hull ^ other).volume())
        low, high = (
            np.asarray(x, dtype=np.float64) for x in np.reshape(other.bounding_box(), (2, 3))
        )
        meets = np.all(self.low <= high, axis=1) & np.all(low <= self.high, axis=1)
        pieces = [end ^ other for end in self.ends]
        for triangle in self.triangles[meets]:
            prism = manifold3d.Manifold.hull_points(np.vstack([triangle, triangle + self.shift]))
            piece = prism ^ other
            if not piece.is_empty():
                pieces.append(piece)
        return float(manifold3d.Manifold.batch_boolean(pieces, manifold3d.OpType.Add).volume())


def step_clashes(
    assembly: Assembly, plan: Plan | Sequence[Step], threshold: float | None = None
) -> list[Clash]:
    """Every moved part's sweep that takes more than allowed of a part left where it is
    (module docstring), over every step of ``plan``, feasible or not."""
    steps = tuple(plan.steps if isinstance(plan, Plan) else plan)
    replay = _Replay(assembly, steps)
    clashes: list[Clash] = []
    for s, step in enumerate(steps):
        if step.motion != "translation":
            raise ValueError(f"step {s + 1} is a {step.motion}, not a translation")
        direction = np.asarray(step.direction, dtype=np.float64)
        direction = direction / np.linalg.norm(direction)
        moved = set(step.parts)
        still = [name for name in replay.names if name not in moved]
        for name in step.parts:
            clashes.extend(_clashes_of(replay, s, name, direction, still, threshold))
        replay.moves.append(replay.distances[s] * direction)
        for name in step.parts:
            replay.history[name].append(s)
    return clashes


def _clashes_of(
    replay: _Replay,
    s: int,
    name: str,
    direction: NDArray[np.float64],
    still: list[str],
    threshold: float | None,
) -> list[Clash]:
    """The clashes of part ``name`` moved at step ``s``, in the frame where it starts."""
    mesh = replay.mesh(name)
    centre, radius = _sphere(mesh)
    near: list[tuple[str, NDArray[np.float64]]] = []
    for other in still:
        offset = replay.relative(other, name)
        their_centre, their_radius = _sphere(replay.mesh(other))
        # the bounding sphere swept along the segment against the other's sphere
        gap = their_centre + offset - centre
        along = float(np.clip(gap @ direction, 0.0, replay.distances[s]))
        if np.linalg.norm(gap - along * direction) <= radius + their_radius:
            near.append((other, offset))
    # a part wholly behind the moved one's back (along the direction) is never met,
    # nor anything beyond the far side of the last part ahead
    behind = float(np.min(np.asarray(mesh.vertices) @ direction))
    reach = {
        other: float(np.max((np.asarray(replay.mesh(other).vertices) + offset) @ direction))
        for other, offset in near
    }
    near = [(other, offset) for other, offset in near if reach[other] > behind]
    if not near:
        return []
    ahead = max(reach[other] for other, _ in near)
    length = min(replay.distances[s], ahead - behind + 0.01 * replay.diagonal)
    sweep = Sweep(mesh, length * direction)
    start = replay.solid(name)
    found = []
    for other, offset in near:
        obstacle = replay.solid(other).translate(tuple(offset))
        before = float((start ^ obstacle).volume())
        volume = sweep.shared(obstacle)
        allowed = before + replay.threshold(name, other, threshold)
        if volume > allowed:
            found.append(Clash(s + 1, name, other, volume, allowed))
    return found


def assert_steps_clear(
    assembly: Assembly, plan: Plan | Sequence[Step], threshold: float | None = None
) -> None:
    """Every step of ``plan`` clear of every part not moved with it, where that part is
    (:func:`step_clashes`); the clashes listed otherwise."""
    clashes = step_clashes(assembly, plan, threshold)
    assert not clashes, "\n".join(str(c) for c in clashes)
