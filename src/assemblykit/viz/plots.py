"""PNG plots (matplotlib, Agg backend): what a picture says better than a table.

:func:`plot_contacts` draws the parts of an assembly in light grey with their contact
patches highlighted: planar patches filled, curved contacts as their boundary samples.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

from assemblykit import formatting as fmt
from assemblykit.outputs import atomic_output

if TYPE_CHECKING:
    from matplotlib.cm import ScalarMappable
    from matplotlib.figure import Figure

    from assemblykit.geometry.contact_values import Contact
    from assemblykit.model.assembly import Assembly


def save_png(figure: Figure, path: str | Path, dpi: int, *, crop: bool = True) -> Path:
    """Write ``figure`` as a PNG (cropped to its content unless ``crop`` is false, when
    it keeps the figure's size times ``dpi``), close it and return the path."""
    path = Path(path)
    try:
        with atomic_output(path) as temporary:
            figure.savefig(temporary, dpi=dpi, bbox_inches="tight" if crop else None)
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
    return save_png(figure, path, dpi)


if TYPE_CHECKING:
    from assemblykit.planning.plan_values import Plan


STORYBOARD_PANELS = 6
"""Most panels :func:`exploded_view_png` draws (the assembly and steps spread evenly)."""
STORYBOARD_COLUMNS = 3
STORYBOARD_ZOOM = 1.5
"""matplotlib leaves wide margins around 3D axes; this fills a panel with its box."""


def storyboard_frames(steps: int, panels: int = STORYBOARD_PANELS) -> list[int]:
    """The frames a storyboard shows: all of them when they fit, else ``panels`` frames
    spread evenly from the assembly (0) to the last step.

    >>> storyboard_frames(3)
    [0, 1, 2, 3]
    >>> storyboard_frames(78)
    [0, 16, 31, 47, 62, 78]
    """
    if steps + 1 <= panels:
        return list(range(steps + 1))
    return sorted(set(np.rint(np.linspace(0, steps, panels)).astype(int).tolist()))


def _draw_triad(axes: Any, assembly: Assembly) -> None:
    """The report's axis triad (:func:`~assemblykit.viz.viewer.triad_origin`): X, Y and Z
    arrows in their colours, each with its label."""
    from assemblykit.viz.viewer import (
        AXES_NAMES,
        TRIAD_COLORS,
        TRIAD_FRACTION,
        triad_labels,
        triad_origin,
    )

    origin, length = triad_origin(assembly), TRIAD_FRACTION * assembly.scale
    labels = triad_labels(assembly)
    for axis, name, color, label in zip(np.eye(3), AXES_NAMES, TRIAD_COLORS, labels, strict=True):
        axes.quiver(*origin, *(axis * length), color=color, linewidth=1.5, zorder=9)
        axes.text(*label, name, color=color, fontsize=8, ha="center", va="center", zorder=9)


def exploded_view_png(
    assembly: Assembly,
    plan: Plan,
    path: str | Path,
    *,
    dpi: int = 120,
    panels: int = STORYBOARD_PANELS,
) -> Path:
    """A storyboard of a disassembly plan (matplotlib Agg): the assembly, then steps
    spread evenly over the plan, each panel fitted to the assembled state as in the HTML
    report (:func:`~assemblykit.viz.viewer.view_box`): the parts of the step in their
    colours (those of the report's legend), moved along its direction with an arrow
    starting on them, the parts still assembled in one neutral grey, the parts removed
    earlier gone, and the axis triad of the report (docs/planning.md, "The HTML
    report"). Returns the PNG's path."""
    from assemblykit.viz.viewer import (
        ARROW_COLOR,
        ARROW_FRACTION,
        DIM_COLOR,
        VIEW_DIRECTION,
        part_colors,
        scene,
        view_box,
    )

    drawn = scene(assembly, plan)
    frames = drawn.frames
    colors = part_colors(assembly.names)
    shown = storyboard_frames(len(plan.steps), panels)
    columns = min(STORYBOARD_COLUMNS, len(shown))
    rows = -(-len(shown) // columns)
    figure = plt.figure(figsize=(4.6 * columns, 4.2 * rows))
    lo, hi = view_box(assembly)
    eye = np.asarray(VIEW_DIRECTION, dtype=np.float64)
    azimuth = float(np.degrees(np.arctan2(eye[1], eye[0])))
    elevation = float(np.degrees(np.arctan2(eye[2], np.linalg.norm(eye[:2]))))
    for panel, k in enumerate(shown, start=1):
        axes = figure.add_subplot(rows, columns, panel, projection="3d")
        triangles, faces = [], []
        for name in assembly.names:
            step = frames.step_of[name]
            if 0 < step < k:
                continue  # removed in an earlier step: out of the picture
            mesh = assembly.parts[name].mesh
            moving = k == 0 or step == k
            triangles.append(np.asarray(mesh.triangles, dtype=np.float64) + frames.offset(name, k))
            color = colors[name] if moving else DIM_COLOR
            faces += [color] * len(mesh.faces)
        axes.add_collection3d(
            Poly3DCollection(np.concatenate(triangles), facecolor=faces, edgecolor="none")
        )
        _draw_triad(axes, assembly)
        if k == 0:
            title = f"assembled: {fmt.count(len(assembly.names), 'part')}"
        else:
            removal = plan.steps[k - 1]
            d = frames.directions[k - 1]
            start = (
                drawn.arrows[k - 1].bounds.mean(axis=0) - d * ARROW_FRACTION * assembly.scale / 2
            )
            axes.computed_zorder = False  # the arrow is drawn over the parts, never hidden
            axes.quiver(
                *start,
                *(d * ARROW_FRACTION * assembly.scale),
                color=ARROW_COLOR,
                linewidth=2.5,
                zorder=10,
            )
            title = (
                f"step {k} of {len(plan.steps)}: {fmt.count(len(removal.parts), 'part')} "
                f"along {fmt.direction(removal.direction, assembly.tolerance())}"
            )
        for setter, low, high in zip(
            (axes.set_xlim, axes.set_ylim, axes.set_zlim), lo, hi, strict=True
        ):
            setter(low, high)
        axes.set_box_aspect(tuple(hi - lo), zoom=STORYBOARD_ZOOM)
        axes.view_init(elev=elevation, azim=azimuth)
        axes.set_axis_off()
        axes.set_title(title, fontsize=10)
    verdict = fmt.count(len(plan.steps), "step") if plan.feasible else "infeasible"
    figure.suptitle(f"Disassembly plan ({verdict})")
    figure.tight_layout()
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
DBG_LABELLED_PARTS = 30
"""Largest DBG drawn with part names (beyond, the names would cover each other)."""


def _count_colors(top: int) -> Any:
    """A discrete colour map for the counts 0..top, 0 in light grey so that directions
    where no part is free read as background."""
    from matplotlib.colors import ListedColormap

    steps = plt.get_cmap("viridis_r", max(top, 1))(np.linspace(0, 1, max(top, 1)))
    return ListedColormap(np.vstack([[0.9, 0.9, 0.9, 1.0], steps]))


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
    """Write a PNG of an NDBG (Wilson & Latombe 1992): the arrangement on the direction
    sphere as two Lambert equal-area hemispheres (S¹ as a circle for planar assemblies),
    coloured by the number of parts free to move alone in each direction (the scale spans
    the counts that occur, 0 in grey), and the DBG of one region (``region``, else the
    region where most parts are free; names shown up to ``DBG_LABELLED_PARTS`` parts);
    returns the path."""
    import networkx as nx
    from matplotlib.ticker import MaxNLocator

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
    score = (n + 1) * arrangement.dims.astype(np.int64) - moving_blocked(slots).sum(axis=1)
    chosen = int(np.argmax(score)) if region is None else region
    figure = plt.figure(figsize=(15, 5))
    maps: list[ScalarMappable] = []
    if arrangement.dimension == 2:
        axes = figure.add_subplot(1, 3, (1, 2))
        theta = np.linspace(0, 2 * np.pi, 720)
        dirs = np.column_stack([np.cos(theta), np.sin(theta), np.zeros_like(theta)])
        counts = free_count(dirs)
        top = max(int(counts.max()), 1)
        cmap = _count_colors(top)
        maps.append(
            axes.scatter(dirs[:, 0], dirs[:, 1], c=counts, cmap=cmap, vmin=-0.5, vmax=top + 0.5)
        )
        points = arrangement.directions[arrangement.dims == 0]
        axes.scatter(points[:, 0], points[:, 1], color="black", s=12, zorder=3)
        axes.set_aspect("equal")
        axes.set_title("S¹: free parts by direction")
    else:
        grids = []
        for upper in (True, False):
            dirs, inside = _lambert_grid(NDBG_MAP_RESOLUTION, upper)
            counts = np.full(len(dirs), np.nan)
            counts[inside] = free_count(dirs[inside])
            grids.append(counts.reshape(NDBG_MAP_RESOLUTION, NDBG_MAP_RESOLUTION))
        # the colours span the counts that occur: with hundreds of parts only a few are
        # ever free alone, and a scale up to n would paint every direction the same
        top = max(int(np.nanmax(grids)), 1)
        cmap = _count_colors(top)
        for k, upper in enumerate((True, False)):
            axes = figure.add_subplot(1, 3, k + 1)
            extent = (-np.sqrt(2), np.sqrt(2), -np.sqrt(2), np.sqrt(2))
            maps.append(
                axes.imshow(
                    grids[k], origin="lower", extent=extent, cmap=cmap, vmin=-0.5, vmax=top + 0.5
                )
            )
            side = arrangement.directions[:, 2] >= 0 if upper else arrangement.directions[:, 2] <= 0
            verts = arrangement.directions[(arrangement.dims == 0) & side]
            if len(verts):
                xy = _lambert(verts)
                axes.scatter(xy[:, 0], xy[:, 1], color="white", edgecolor="black", s=10)
            axes.set_aspect("equal")
            axes.set_axis_off()
            axes.set_title(f"{'upper' if upper else 'lower'} hemisphere (equal-area)")
    bar = figure.colorbar(maps[-1], ax=figure.axes, label="parts free alone", shrink=0.8)
    bar.ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    axes = figure.add_subplot(1, 3, 3)
    dbg = ndbg.region_dbg(chosen)
    labelled = n <= DBG_LABELLED_PARTS
    nx.draw_networkx(
        dbg.graph,
        pos=nx.circular_layout(dbg.graph),
        ax=axes,
        with_labels=labelled,
        node_color="0.85",
        node_size=300 if labelled else 12,
        font_size=7,
        arrowsize=10 if labelled else 4,
        width=1.0 if labelled else 0.3,
    )
    axes.set_title(f"DBG of region {chosen}: d = {fmt.direction(dbg.direction, ndbg.tol, 3)}")
    axes.set_axis_off()
    return save_png(figure, path, dpi)
