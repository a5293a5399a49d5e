"""The self-contained HTML view of a motion report (Liu 1997; docs/motion.md).

Every part is drawn as a ``mesh3d`` trace with its bilateral motion on top: the axis of
a revolute, cylindrical or helical motion as a line with a turning arc, the direction
of a prismatic motion as a double arrow, the normal of a planar motion with an arc in
its plane, the centre of a spherical motion with three arcs. The unilateral lift-off
directions are red arrows from the part's centre. plotly's JavaScript is embedded
(``include_plotlyjs=True``) so the file opens offline.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import plotly.graph_objects as go
from numpy.typing import NDArray

from assemblykit import formatting as fmt
from assemblykit.algebra import se3
from assemblykit.model.assembly import Assembly
from assemblykit.motion.articulation import Articulation
from assemblykit.motion.freedom import Motion, MotionReport
from assemblykit.outputs import atomic_output
from assemblykit.tolerance import Tolerance
from assemblykit.viz.viewer import ReportTable, part_colors

GLYPH_FRACTION = 0.12
"""Size of arcs and arrows, as a fraction of the assembly's bounding-box diagonal."""

ARC_POINTS = 48
GLYPH_ZORDER = 3
"""Drawing order of the PNG's axes, arrows and labels: above the parts (zorder 1)."""
LIFT_OFF_COLOR = "#d62728"


def _basis(u: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Two unit vectors completing ``u`` to a right-handed orthonormal frame."""
    frame = se3.frame(np.zeros(3), u)
    return frame[:3, 0], frame[:3, 1]


def _arc(center: NDArray, axis: NDArray, radius: float, color: str, name: str) -> go.Scatter3d:
    """Three quarters of a circle about ``axis``: the picture of a rotation."""
    e1, e2 = _basis(axis)
    angles = np.linspace(0.0, 1.5 * np.pi, ARC_POINTS)
    pts = center + radius * (np.outer(np.cos(angles), e1) + np.outer(np.sin(angles), e2))
    return go.Scatter3d(
        x=pts[:, 0],
        y=pts[:, 1],
        z=pts[:, 2],
        mode="lines",
        line={"color": color, "width": 6},
        name=name,
        showlegend=False,
        hoverinfo="name",
    )


def _arrow(start: NDArray, vector: NDArray, color: str, name: str, dash: str) -> list[Any]:
    """A line from ``start`` along ``vector`` with a cone at its tip."""
    tip = start + vector
    line = go.Scatter3d(
        x=[start[0], tip[0]],
        y=[start[1], tip[1]],
        z=[start[2], tip[2]],
        mode="lines",
        line={"color": color, "width": 6, "dash": dash},
        name=name,
        showlegend=False,
        hoverinfo="name",
    )
    head = go.Cone(
        x=[tip[0]],
        y=[tip[1]],
        z=[tip[2]],
        u=[vector[0]],
        v=[vector[1]],
        w=[vector[2]],
        sizemode="absolute",
        sizeref=0.3 * float(np.linalg.norm(vector)),
        anchor="tip",
        colorscale=[[0, color], [1, color]],
        showscale=False,
        name=name,
        hoverinfo="name",
    )
    return [line, head]


def motion_glyphs(motion: Motion, center: NDArray, size: float, color: str) -> list[Any]:
    """The traces drawing one part's bilateral motion and its lift-off directions."""
    data = motion.to_dict()
    name = f"{motion.key}: {data['description']}"
    traces: list[Any] = []
    if "axis" in data:
        point = np.asarray(data["axis"]["point"], dtype=np.float64)
        u = np.asarray(data["axis"]["direction"], dtype=np.float64)
        foot = point + ((center - point) @ u) * u
        traces += _arrow(foot - 1.5 * size * u, 3.0 * size * u, color, name, "solid")
        traces.append(_arc(foot, u, 0.5 * size, color, name))
    if "center" in data:
        point = np.asarray(data["center"], dtype=np.float64)
        traces += [_arc(point, axis, 0.6 * size, color, name) for axis in np.eye(3)]
    if "direction" in data:
        u = np.asarray(data["direction"], dtype=np.float64)
        traces += _arrow(center, size * u, color, name, "solid")
        traces += _arrow(center, -size * u, color, name, "solid")
    if "normal" in data:
        n = np.asarray(data["normal"], dtype=np.float64)
        for e in _basis(n):
            traces += _arrow(center, size * e, color, name, "solid")
        if data["motion"] == "planar":
            traces.append(_arc(center, n, 0.5 * size, color, name))
    for ray in motion.unilateral.lift_off:
        traces += _arrow(center, size * ray, LIFT_OFF_COLOR, f"{motion.key}: lifts off", "dash")
    return traces


def motion_figure(assembly: Assembly, report: MotionReport) -> go.Figure:
    """The assembly's parts with each single part's motion drawn on it."""
    colors = part_colors(assembly.names)
    size = GLYPH_FRACTION * assembly.scale
    traces: list[Any] = []
    for name, part in assembly.parts.items():
        mesh = part.mesh
        traces.append(
            go.Mesh3d(
                x=mesh.vertices[:, 0],
                y=mesh.vertices[:, 1],
                z=mesh.vertices[:, 2],
                i=mesh.faces[:, 0],
                j=mesh.faces[:, 1],
                k=mesh.faces[:, 2],
                color=colors[name],
                opacity=0.45,
                name=name,
                showlegend=True,
                flatshading=True,
            )
        )
        if name in report.motions:
            center = np.asarray(mesh.bounds.mean(axis=0), dtype=np.float64)
            traces += motion_glyphs(report[name], center, size, colors[name])
    figure = go.Figure(traces)
    figure.update_layout(
        title=f"Motion of each part of {assembly.source or 'the assembly'}",
        scene={"aspectmode": "data"},
        margin={"l": 0, "r": 0, "t": 40, "b": 0},
    )
    return figure


def _lift_off(motion: Motion, tol: Tolerance) -> str:
    """The push-only reading in words: the directions it lifts off along, if any."""
    reading = motion.unilateral
    if reading.lift_off:
        return ", ".join(fmt.direction(ray, tol) for ray in reading.lift_off)
    if reading.can_lift_off:
        return "by turning"
    return "held" if not reading.free else "keeps every contact"


def motion_table(result: Articulation, tol: Tolerance, units: str | None = None) -> ReportTable:
    """The motion of each part in words (Liu 1997): its motion and degrees of freedom,
    the direction and a point of its axis, the directions it lifts off along and, for a
    gear, its speed relative to the first gear of its train (Liu, §4)."""
    ratios = {
        gear: f"{fmt.number(ratio, tol)} x {train.gears[0]}"
        for train in result.trains
        for gear, ratio in train.ratios.items()
        if ratio is not None
    }
    rows = []
    for key, moved in result.report.motions.items():
        data = moved.to_dict()
        kind = f"{data['motion']} ({fmt.count(int(data['dof']), 'dof', 'dof')})"
        if data.get("components", 1) > 1:
            kind += f", {data['components']} positions"
        axis = data.get("axis") or {}
        line = data.get("direction") or axis.get("direction") or data.get("normal")
        point = axis.get("point", data.get("center"))
        rows.append(
            (
                key,
                kind,
                "-" if line is None else fmt.direction(line, tol),
                "-" if point is None else fmt.vector(point, tol),
                _lift_off(moved, tol),
                ratios.get(key, "-"),
            )
        )
    return ReportTable(
        "Motion of each part",
        ("part", "motion", "axis", fmt.header("through", units), "lifts off", "speed ratio"),
        tuple(rows),
        "How each part can still move while the others stay in place: its bilateral motion "
        "(keeping every contact), the directions along which it can lift off its contacts, "
        "and for meshing gears the speed relative to the first gear of the train.",
    )


def write_motion_html(assembly: Assembly, report: MotionReport, path: str | Path) -> Path:
    """Write the self-contained HTML view to ``path`` and return it."""
    path = Path(path)
    figure = motion_figure(assembly, report)
    with atomic_output(path) as temporary:
        figure.write_html(temporary, include_plotlyjs=True, full_html=True)
    return path


def write_motion_png(
    assembly: Assembly, report: MotionReport, path: str | Path, *, dpi: int = 120
) -> Path:
    """Write a PNG (matplotlib, Agg canvas) of the parts, each drawn translucent in its
    colour, with the invariants of its motion: the axis line of a revolute, cylindrical
    or helical motion (through the part, 3 glyph sizes long) with its label, the double
    arrow of a prismatic one, the centre of a spherical one, drawn over the parts.
    Returns ``path``."""
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    colors = part_colors(assembly.names)
    size = GLYPH_FRACTION * assembly.scale
    figure = Figure(figsize=(7.0, 5.5))
    # the glyphs go over every part: sorted by depth, they would be drawn behind the
    # translucent faces in front of them and come out pale
    ax = figure.add_subplot(projection="3d", computed_zorder=False)
    for name, part in assembly.parts.items():
        mesh = part.mesh
        triangles = np.asarray(mesh.vertices, dtype=np.float64)[np.asarray(mesh.faces)]
        ax.add_collection3d(
            Poly3DCollection(triangles, facecolor=colors[name], edgecolor="none", alpha=0.25)
        )
        if name not in report.motions:
            continue
        data = report[name].to_dict()
        center = np.asarray(mesh.bounds.mean(axis=0), dtype=np.float64)
        if "axis" in data:
            point = np.asarray(data["axis"]["point"], dtype=np.float64)
            u = np.asarray(data["axis"]["direction"], dtype=np.float64)
            foot = point + ((center - point) @ u) * u
            line = np.array([foot - 1.5 * size * u, foot + 1.5 * size * u])
            ax.plot(*line.T, color="black", linewidth=2.0, zorder=GLYPH_ZORDER)
            ax.text(*line[1], f"{name}: {data['motion']}", fontsize=8, zorder=GLYPH_ZORDER)
        elif "direction" in data:
            u = np.asarray(data["direction"], dtype=np.float64)
            for sign in (1.0, -1.0):
                ax.quiver(
                    *center, *(sign * size * u), color="black", linewidth=2.0, zorder=GLYPH_ZORDER
                )
            ax.text(
                *(center + size * u), f"{name}: {data['motion']}", fontsize=8, zorder=GLYPH_ZORDER
            )
        elif "center" in data:
            ax.scatter(
                *np.asarray(data["center"], dtype=np.float64),
                color="black",
                s=30,
                zorder=GLYPH_ZORDER,
            )
            ax.text(*center, f"{name}: {data['motion']}", fontsize=8, zorder=GLYPH_ZORDER)
    lo, hi = np.asarray(assembly.bounds, dtype=np.float64)
    for setter, a, b in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), lo, hi, strict=True):
        setter(a, b)
    ax.set_aspect("equal")
    source = Path(assembly.source).name if assembly.source else "the assembly"
    ax.set_title(f"Motion of each part of {source}")
    path = Path(path)
    with atomic_output(path) as temporary:
        figure.savefig(temporary, dpi=dpi, bbox_inches="tight")
    return path
