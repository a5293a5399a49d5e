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

if TYPE_CHECKING:
    from assemblykit.geometry.contacts import Contact
    from assemblykit.model.assembly import Assembly


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
    path = Path(path)
    figure.savefig(path, dpi=dpi, bbox_inches="tight")
    plt.close(figure)
    return path


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
    figure.savefig(target, dpi=dpi)
    plt.close(figure)
    return target
