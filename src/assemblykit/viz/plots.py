"""PNG plots (matplotlib, Agg backend): what a picture says better than a table.

:func:`plot_contacts` draws the parts of an assembly in light grey with their contact
patches highlighted: planar patches filled, curved contacts as their boundary samples.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

from assemblykit.io.outputs import atomic_output

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from assemblykit.geometry.contacts import Contact
    from assemblykit.model.assembly import Assembly


def _save_png(figure: Figure, path: str | Path, dpi: int) -> Path:
    """Write ``figure`` as a PNG cropped to its content, close it and return the path."""
    path = Path(path)
    try:
        with atomic_output(path) as temporary:
            figure.savefig(temporary, dpi=dpi, bbox_inches="tight")
    finally:
        plt.close(figure)
    return path


def plot_contacts(
    assembly: Assembly, contacts: list[Contact], path: str | Path, *, dpi: int = 120
) -> Path:
    """Write a PNG of ``assembly`` with its ``contacts`` highlighted; returns the path."""
    figure = plt.figure(figsize=(8, 8))
    axes = figure.add_subplot(projection="3d")
    for part in assembly:
        triangles = np.asarray(part.mesh.triangles)
        axes.add_collection3d(
            Poly3DCollection(triangles, facecolor="0.85", edgecolor="none", alpha=0.25)
        )
    patches = [p.polygon for c in contacts for p in c.planar]
    if patches:
        axes.add_collection3d(
            Poly3DCollection(patches, facecolor="tab:red", edgecolor="darkred", alpha=0.9)
        )
    for contact in contacts:
        for curved in contact.curved:
            if curved.points is not None and len(curved.points):
                axes.scatter(*curved.points.T, s=4, color="tab:blue")
    lo, hi = assembly.bounds
    centre, half = (lo + hi) / 2, max(float(np.max(hi - lo)) / 2, np.finfo(float).tiny)
    axes.set_xlim(centre[0] - half, centre[0] + half)
    axes.set_ylim(centre[1] - half, centre[1] + half)
    axes.set_zlim(centre[2] - half, centre[2] + half)
    axes.set_box_aspect((1, 1, 1))
    axes.set_title(f"{len(assembly)} parts, {len(contacts)} contacts")
    axes.set_axis_off()
    return _save_png(figure, path, dpi)


if TYPE_CHECKING:
    from assemblykit.planning.sequence import Plan


def exploded_view_png(assembly: Assembly, plan: Plan, path: str | Path, *, dpi: int = 120) -> Path:
    """A static exploded view of a disassembly plan (matplotlib Agg): every part drawn
    at its offset after the last step (:meth:`~assemblykit.planning.sequence.Plan.exploded`),
    coloured as in the HTML report; returns the PNG's path."""
    from assemblykit.viz.viewer import EXPLODE_FRACTION, part_colors

    offsets = plan.exploded(EXPLODE_FRACTION * assembly.scale)[-1]
    colors = part_colors(assembly.names)
    figure = plt.figure(figsize=(8, 7))
    axes = figure.add_subplot(projection="3d")
    lows, highs = [], []
    for name in assembly.names:
        mesh = assembly.parts[name].mesh
        triangles = np.asarray(mesh.triangles, dtype=np.float64) + offsets[name]
        axes.add_collection3d(
            Poly3DCollection(
                triangles, facecolor=colors[name], edgecolor="none", alpha=0.9, label=name
            )
        )
        lows.append(triangles.reshape(-1, 3).min(axis=0))
        highs.append(triangles.reshape(-1, 3).max(axis=0))
    lo, hi = np.min(lows, axis=0), np.max(highs, axis=0)
    for setter, low, high in zip(
        (axes.set_xlim, axes.set_ylim, axes.set_zlim), lo, hi, strict=True
    ):
        setter(low, high)
    axes.set_box_aspect(tuple(hi - lo))
    axes.set_axis_off()
    verdict = f"{len(plan.steps)} steps" if plan.feasible else "infeasible"
    axes.set_title(f"Exploded view ({verdict})")
    if len(assembly.names) <= 20:
        axes.legend(loc="upper left", fontsize="small")
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    try:
        with atomic_output(target) as temporary:
            figure.savefig(temporary, dpi=dpi)
    finally:
        plt.close(figure)
    return target


if TYPE_CHECKING:
    from assemblykit.blocking.ndbg import NonDirectionalBlockingGraph

NDBG_MAP_RESOLUTION = 240


def _lambert_grid(resolution: int, upper: bool) -> tuple[np.ndarray, np.ndarray]:
    """Directions of a hemisphere on a square grid of its Lambert azimuthal equal-area
    map (disc of radius sqrt 2), and the mask of grid points inside the disc."""
    axis = np.linspace(-np.sqrt(2), np.sqrt(2), resolution)
    x, y = np.meshgrid(axis, axis)
    r2 = x**2 + y**2
    inside = r2 <= 2
    scale = np.sqrt(np.clip(1 - r2 / 4, 0, None))
    z = (1 - r2 / 2) * (1 if upper else -1)
    dirs = np.stack([x * scale, y * scale, z], axis=-1).reshape(-1, 3)
    return dirs, inside.ravel()


def _lambert(points: np.ndarray) -> np.ndarray:
    """Equal-area map coordinates of unit vectors of one hemisphere (z sign ignored)."""
    factor = np.sqrt(2 / (1 + np.abs(points[:, 2])))
    return points[:, :2] * factor[:, None]


def plot_ndbg(
    ndbg: NonDirectionalBlockingGraph,
    path: str | Path,
    *,
    region: int | None = None,
    dpi: int = 120,
) -> Path:
    """Write a PNG of an NDBG (seed 004): the arrangement on the direction sphere as two
    Lambert equal-area hemispheres (S¹ as a circle for planar assemblies), coloured by
    the number of parts free to move alone in each direction, and the DBG of one region
    (``region``, else the region where most parts are free); returns the path."""
    import networkx as nx

    table, arrangement = ndbg.table, ndbg.arrangement
    n = len(ndbg.parts)

    def free_count(dirs: np.ndarray) -> np.ndarray:
        return n - moving_blocked(table.direct_arcs(dirs, ndbg.tol)).sum(axis=1)

    def moving_blocked(slots: np.ndarray) -> np.ndarray:
        blocked = np.zeros((len(slots), n), dtype=bool)
        for s, moving in enumerate(table.slot_moving):
            blocked[:, moving] |= slots[:, s]
        return blocked

    slots = np.unpackbits(ndbg.packed, axis=1, count=len(table.starts)).astype(bool)
    # most free parts among the regions of the highest dimension
    score = (n + 1) * arrangement.dims - moving_blocked(slots).sum(axis=1)
    chosen = int(np.argmax(score)) if region is None else region
    figure = plt.figure(figsize=(15, 5))
    cmap = plt.get_cmap("viridis", max(n, 1) + 1)
    maps = []
    if arrangement.dimension == 2:
        axes = figure.add_subplot(1, 3, (1, 2))
        theta = np.linspace(0, 2 * np.pi, 720)
        dirs = np.column_stack([np.cos(theta), np.sin(theta), np.zeros_like(theta)])
        counts = free_count(dirs)
        maps.append(axes.scatter(dirs[:, 0], dirs[:, 1], c=counts, cmap=cmap, vmin=0, vmax=n))
        points = arrangement.directions[arrangement.dims == 0]
        axes.scatter(points[:, 0], points[:, 1], color="black", s=12, zorder=3)
        axes.set_aspect("equal")
        axes.set_title("S¹: free parts by direction")
    else:
        for k, upper in enumerate((True, False)):
            axes = figure.add_subplot(1, 3, k + 1)
            dirs, inside = _lambert_grid(NDBG_MAP_RESOLUTION, upper)
            counts = np.full(len(dirs), np.nan)
            counts[inside] = free_count(dirs[inside])
            grid = counts.reshape(NDBG_MAP_RESOLUTION, NDBG_MAP_RESOLUTION)
            extent = (-np.sqrt(2), np.sqrt(2), -np.sqrt(2), np.sqrt(2))
            maps.append(axes.imshow(grid, origin="lower", extent=extent, cmap=cmap, vmin=0, vmax=n))
            side = arrangement.directions[:, 2] >= 0 if upper else arrangement.directions[:, 2] <= 0
            verts = arrangement.directions[(arrangement.dims == 0) & side]
            if len(verts):
                xy = _lambert(verts)
                axes.scatter(xy[:, 0], xy[:, 1], color="white", edgecolor="black", s=10)
            axes.set_aspect("equal")
            axes.set_axis_off()
            axes.set_title(f"{'upper' if upper else 'lower'} hemisphere (equal-area)")
    figure.colorbar(maps[-1], ax=figure.axes, label="parts free alone", shrink=0.8)
    axes = figure.add_subplot(1, 3, 3)
    dbg = ndbg.region_dbg(chosen)
    nx.draw_networkx(
        dbg.graph,
        pos=nx.circular_layout(dbg.graph),
        ax=axes,
        node_color="0.85",
        node_size=300,
        font_size=7,
        arrowsize=10,
    )
    axes.set_title(f"DBG of region {chosen}: d = {np.array2string(dbg.direction, precision=2)}")
    axes.set_axis_off()
    return _save_png(figure, path, dpi)
