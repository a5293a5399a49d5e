"""A PNG of a solved RAPT task (matplotlib, Agg canvas): where every body is and how it
can still move (Corner, Ambler & Popplestone 1983, §II-§III).

One 3D panel per situation (only the last one when there are more than
:data:`MAX_PANELS`). Every body is drawn through its features, placed at the body's
solved pose and coloured as in the other pictures (:func:`~assemblykit.viz.viewer.part_colors`):
a plane as a translucent square with its normal, a shaft as a cylinder and a hole as
its two rims and axis, a ball as a sphere and a socket as a wire sphere, a cone, a
torus, a thread as a helix, a prism as its side faces, a point as a dot, an axis as a
dashed line and a frame as its three axes. The freedom that remains to an
under-constrained instance is drawn in black from the invariants its
:class:`~assemblykit.inference.solution.BodyInstanceResult` carries: the axis line of a
turn with a curved arrow about it, a double arrow along a slide, a square in the plane
of a planar motion and three rings about the centre of a spherical one.

Every artist carries a ``gid`` naming what it draws (:func:`feature_gid`,
:func:`freedom_gid`), so that a picture can be checked against the solution.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import matplotlib

matplotlib.use("Agg")

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection
from numpy.typing import ArrayLike, NDArray

from assemblykit import formatting as fmt
from assemblykit.algebra import se3
from assemblykit.features import (
    Axis,
    Ball,
    Cone,
    Feature,
    Frame,
    Hole,
    Plane,
    Point,
    Prism,
    Shaft,
    Socket,
    Thread,
    Torus,
)
from assemblykit.inference.reduction import model_scale
from assemblykit.viz.motion_view import ARC_POINTS, GLYPH_FRACTION
from assemblykit.viz.plots import save_png
from assemblykit.viz.viewer import part_colors

if TYPE_CHECKING:
    from matplotlib.artist import Artist
    from mpl_toolkits.mplot3d.axes3d import Axes3D

    from assemblykit.inference.solution import BodyInstanceResult, Solution
    from assemblykit.model.task import Task

MAX_PANELS = 4
"""Most situations drawn side by side; a longer task shows its last situation."""
FEATURE_FRACTION = 0.3
"""Size of a feature's picture (a plane's square, a cylinder's length), as a fraction of
the model's size (:func:`~assemblykit.inference.reduction.model_scale`)."""
FEATURE_ALPHA = 0.35
GLYPH_COLOR = "black"
SURFACE_STEPS = 24
"""Facets around a drawn cylinder, sphere, cone or torus."""
PANEL_SIZE = (5.2, 5.0)
"""Inches per panel; the legend takes a band below."""
LEGEND_HEIGHT = 0.7
PANEL_ZOOM = 1.15
"""matplotlib leaves wide margins around 3D axes; this fills a panel with its box."""

FREEDOM_PARTS: Mapping[str, tuple[str, ...]] = {
    "revolute": ("axis", "turn"),
    "helical": ("axis", "turn"),
    "cylindrical": ("axis", "turn", "slide"),
    "prismatic": ("slide",),
    "planar": ("plane", "turn"),
    "pseudo-planar": ("plane", "turn"),
    "translation2": ("plane",),
    "spherical": ("ball",),
    "schoenflies": ("slides", "turn"),
    "translation3": ("slides",),
    "free": ("slides", "ball"),
    "point-in-plane": ("plane", "ball"),
    "point-on-line": ("slide", "ball"),
    "planar-point-on-line": ("slide", "turn"),
    "line-on-plane": ("plane", "turn"),
}
"""The pieces of the freedom glyph of each motion (or named mechanism): ``axis`` the
axis line, ``turn`` a curved arrow about the axis (or normal), ``slide`` a double arrow
along the direction, ``slides`` double arrows along x, y and z, ``plane`` a square in the
plane normal to ``normal``, ``ball`` three rings about the centre."""


def feature_gid(instance: str, feature: str) -> str:
    """The ``gid`` of the artists drawing ``feature`` of the body instance ``instance``."""
    return f"feature {instance} {feature}"


def freedom_gid(instance: str, part: str) -> str:
    """The ``gid`` of the artists drawing one piece (:data:`FREEDOM_PARTS`) of the
    freedom of ``instance``."""
    return f"freedom {instance} {part}"


def _ring(center: NDArray, axis: NDArray, radius: float, sweep: float = 2 * math.pi) -> NDArray:
    """Points of an arc of ``sweep`` radians about ``axis`` (the whole circle by default)."""
    frame = se3.frame(np.zeros(3), axis)
    angles = np.linspace(0.0, sweep, ARC_POINTS)
    return center + radius * (
        np.outer(np.cos(angles), frame[:3, 0]) + np.outer(np.sin(angles), frame[:3, 1])
    )


def _tube(
    center: NDArray, axis: NDArray, radii: NDArray, heights: NDArray
) -> tuple[NDArray, NDArray, NDArray]:
    """A surface of revolution about ``axis`` through ``center``: the profile (radius,
    height) swept once around, as plot_surface's X, Y, Z grids."""
    frame = se3.frame(np.zeros(3), axis)
    turn = np.linspace(0.0, 2 * math.pi, SURFACE_STEPS + 1)
    across = np.cos(turn)[None, :, None] * frame[:3, 0] + np.sin(turn)[None, :, None] * frame[:3, 1]
    grid = (
        center
        + radii[:, None, None] * across
        + heights[:, None, None] * np.asarray(axis, dtype=np.float64)
    )
    return grid[..., 0], grid[..., 1], grid[..., 2]


class _Pen:
    """Draws on one panel under one ``gid`` and one colour, and keeps every point drawn
    (the panel's box is fitted to them)."""

    def __init__(self, axes: Axes3D, seen: list[NDArray]) -> None:
        self.axes = axes
        self.seen = seen
        self.gid = ""
        self.color = GLYPH_COLOR

    def use(self, gid: str, color: str) -> _Pen:
        self.gid, self.color = gid, color
        return self

    def _keep(self, artist: Artist, points: ArrayLike) -> Artist:
        artist.set_gid(self.gid)
        self.seen.append(np.asarray(points, dtype=np.float64).reshape(-1, 3))
        return artist

    def line(self, points: NDArray, **style: Any) -> Artist:
        points = np.asarray(points, dtype=np.float64)
        (drawn,) = self.axes.plot(*points.T, color=self.color, **style)
        return self._keep(drawn, points)

    def lines(self, segments: NDArray | Sequence[NDArray], **style: Any) -> Artist:
        drawn = Line3DCollection(segments, colors=self.color, **style)
        self.axes.add_collection3d(drawn)
        return self._keep(drawn, segments)

    def faces(self, polygons: Sequence[NDArray], **style: Any) -> Artist:
        drawn = Poly3DCollection(
            list(polygons), facecolor=self.color, edgecolor=self.color, **style
        )
        self.axes.add_collection3d(drawn)
        return self._keep(drawn, np.concatenate(polygons))

    def surface(self, grids: tuple[NDArray, NDArray, NDArray], wire: bool = False) -> Artist:
        if wire:
            drawn = self.axes.plot_wireframe(*grids, color=self.color, linewidth=0.6)
        else:
            drawn = self.axes.plot_surface(
                *grids, color=self.color, alpha=FEATURE_ALPHA, linewidth=0, shade=True
            )
        return self._keep(drawn, np.stack(grids, axis=-1))

    def dot(self, point: NDArray) -> Artist:
        drawn = self.axes.scatter(*point, color=self.color, s=36, depthshade=False)
        return self._keep(drawn, point)

    def arrow(self, start: NDArray, vector: NDArray, **style: Any) -> Artist:
        drawn = self.axes.quiver(
            *start, *vector, color=self.color, arrow_length_ratio=0.25, **style
        )
        return self._keep(drawn, np.array([start, start + vector]))

    def label(self, point: NDArray, text: str) -> Artist:
        drawn = self.axes.text(*point, text, fontsize=8, color=self.color)
        return self._keep(drawn, point)


def draw_feature(pen: _Pen, feature: Feature, size: float) -> list[Artist]:
    """The artists of one feature in world coordinates, ``size`` long where the feature
    itself has no length (a plane's square, a cylinder's length)."""
    if isinstance(feature, Plane):
        frame = se3.frame(feature.point, feature.normal)
        half = 0.5 * size * (frame[:3, :2] @ np.array([[1, 1, -1, -1], [1, -1, -1, 1]])).T
        return [
            pen.faces([feature.point + half], alpha=FEATURE_ALPHA),
            pen.arrow(feature.point, 0.5 * size * feature.normal, linewidth=1.2),
        ]
    if isinstance(feature, Ball | Socket):
        angle = np.linspace(0.0, math.pi, SURFACE_STEPS // 2 + 1)
        grids = _tube(
            feature.point,
            np.array([0.0, 0.0, 1.0]),
            feature.radius * np.sin(angle),
            -feature.radius * np.cos(angle),
        )
        return [pen.surface(grids, wire=isinstance(feature, Socket))]
    if isinstance(feature, Point):
        return [pen.dot(feature.point)]
    point, axis = feature.frame()[:3, 3], feature.frame()[:3, 2]
    if isinstance(feature, Shaft):
        length = max(size, 2 * feature.radius)
        ends = np.array([0.0, length])
        return [pen.surface(_tube(point, axis, np.full(2, feature.radius), ends))]
    if isinstance(feature, Hole):
        length = max(size, 2 * feature.radius)
        rims = [_ring(point + h * axis, axis, feature.radius) for h in (0.0, length)]
        return [
            pen.lines(rims, linewidths=1.2),
            pen.line(np.array([point, point + length * axis]), linestyle="--", linewidth=0.8),
        ]
    if isinstance(feature, Cone):
        heights = np.array([0.0, size])
        return [pen.surface(_tube(point, axis, heights * math.tan(feature.half_angle), heights))]
    if isinstance(feature, Torus):
        angle = np.linspace(0.0, 2 * math.pi, SURFACE_STEPS + 1)
        radii = feature.major_radius + feature.minor_radius * np.cos(angle)
        return [pen.surface(_tube(point, axis, radii, feature.minor_radius * np.sin(angle)))]
    if isinstance(feature, Thread):
        turns = max(size / feature.lead, 1.0)
        angle = np.linspace(0.0, 2 * math.pi * turns, int(ARC_POINTS * turns))
        frame = feature.frame()
        hand = 1.0 if feature.hand == "right" else -1.0
        helix = (
            point
            + feature.radius * np.outer(np.cos(angle), frame[:3, 0])
            + feature.radius * hand * np.outer(np.sin(angle), frame[:3, 1])
            + np.outer(angle * feature.lead / (2 * math.pi), axis)
        )
        return [pen.line(helix, linewidth=1.2)]
    if isinstance(feature, Prism):
        frame = feature.frame()
        angle = 2 * math.pi * np.arange(feature.sides + 1) / feature.sides
        rim = point + feature.size * (
            np.outer(np.cos(angle), frame[:3, 0]) + np.outer(np.sin(angle), frame[:3, 1])
        )
        sides = [
            np.array([rim[k], rim[k + 1], rim[k + 1] + size * axis, rim[k] + size * axis])
            for k in range(feature.sides)
        ]
        return [pen.faces(sides, alpha=FEATURE_ALPHA)]
    if isinstance(feature, Axis):
        line = np.array([point - size * axis, point + size * axis])
        return [pen.line(line, linestyle="--", linewidth=1.2)]
    if isinstance(feature, Frame):
        segments = np.array(
            [[point, point + 0.5 * size * feature.frame()[:3, k]] for k in range(3)]
        )
        return [pen.lines(segments, linewidths=1.5)]
    raise TypeError(f"no picture for a {feature.type_name} feature")


def _centre(world: Sequence[Feature]) -> NDArray:
    """Where a body's glyph sits: the mean of its features' origins."""
    return np.mean([f.frame()[:3, 3] for f in world], axis=0)


def draw_freedom(
    pen: _Pen, result: BodyInstanceResult, centre: NDArray, size: float
) -> list[Artist]:
    """The glyph of the freedom left to one instance (:data:`FREEDOM_PARTS`), placed by
    the invariants of ``result`` (world coordinates) near ``centre``; nothing for a fixed
    instance or a mechanism the reduction does not name."""
    if result.dof == 0:
        return []
    parts = FREEDOM_PARTS.get(result.mechanism or result.motion, ())
    inv = {k: np.asarray(v, dtype=np.float64) for k, v in result.invariants.items()}
    line = inv.get("direction")
    if "point" in inv and line is not None:
        # the line through the invariant point, at the foot of the body's centre
        origin = inv["point"] + ((centre - inv["point"]) @ line) * line
    else:
        origin = inv.get("center", inv.get("point", centre))
    turn_axis = inv.get("normal", line)
    key = result.key
    drawn: list[Artist] = []
    for part in parts:
        pen.use(freedom_gid(key, part), GLYPH_COLOR)
        if part == "axis" and line is not None:
            ends = np.array([origin - 1.5 * size * line, origin + 1.5 * size * line])
            drawn.append(pen.line(ends, linewidth=2.0))
        elif part == "turn" and turn_axis is not None:
            arc = _ring(origin + 0.6 * size * turn_axis, turn_axis, 0.5 * size, 1.5 * math.pi)
            drawn.append(pen.line(arc, linewidth=1.6))
            drawn.append(pen.arrow(arc[-2], 0.3 * size * _unit(arc[-1] - arc[-2]), linewidth=1.6))
        elif part == "slide" and line is not None:
            # arrowheads beyond the ends of the axis line, pointing both ways
            drawn += [
                pen.arrow(origin + s * size * line, s * 0.9 * size * line, linewidth=2.0)
                for s in (1.0, -1.0)
            ]
        elif part == "slides":
            drawn += [
                pen.arrow(origin, s * size * e, linewidth=1.4) for e in np.eye(3) for s in (1, -1)
            ]
        elif part == "plane" and "normal" in inv:
            frame = se3.frame(origin, inv["normal"])
            corners = (
                0.7 * size * (frame[:3, :2] @ np.array([[1, 1, -1, -1, 1], [1, -1, -1, 1, 1]]))
            )
            drawn.append(pen.line(origin + corners.T, linewidth=1.6, linestyle="--"))
        elif part == "ball":
            drawn += [pen.line(_ring(origin, e, 0.4 * size), linewidth=1.2) for e in np.eye(3)]
    if drawn:
        pen.use(freedom_gid(key, "label"), GLYPH_COLOR)
        drawn.append(pen.label(origin + 0.8 * size * _across(turn_axis), result.body))
    return drawn


def freedom_caption(result: BodyInstanceResult) -> str:
    """One line for the panel's caption: ``peg: cylindrical, 2 dof``, ``peg: 4 poses``;
    empty for an instance with one pose."""
    if result.dof > 0:
        return f"{result.body}: {result.mechanism or result.motion}, {result.dof} dof"
    if result.solutions != 1:
        poses = "infinitely many" if result.solutions is None else str(result.solutions)
        return f"{result.body}: {poses} poses"
    return ""


def _unit(v: NDArray) -> NDArray:
    return v / np.linalg.norm(v)


def _across(axis: NDArray | None) -> NDArray:
    """A unit vector across ``axis`` (any one when there is no axis)."""
    return np.array([1.0, 0.0, 0.0]) if axis is None else se3.frame(np.zeros(3), axis)[:3, 0]


def shown_situations(task: Task, panels: int = MAX_PANELS) -> list[str]:
    """The situations drawn: all of them up to ``panels``, else the last one.

    >>> from assemblykit.model.task import Situation, Task
    >>> shown_situations(Task("mm", {}, tuple(Situation(f"s{k}") for k in range(6))))
    ['s5']
    """
    names = [s.name for s in task.situations]
    return names if len(names) <= panels else names[-1:]


def task_figure(task: Task, solution: Solution, *, panels: int = MAX_PANELS) -> Figure:
    """The figure (not yet written): a 3D panel per shown situation
    (:func:`shown_situations`), the bodies' features at their solved poses, the freedom
    glyphs, and a legend of the bodies' colours."""
    situations = shown_situations(task, panels)
    colors = part_colors(list(task.bodies))
    scale = model_scale(task)
    size, glyph = FEATURE_FRACTION * scale, GLYPH_FRACTION * scale
    width, height = PANEL_SIZE
    figure = Figure(figsize=(width * len(situations), height + LEGEND_HEIGHT))
    seen: list[NDArray] = []
    panes = []
    for index, situation in enumerate(situations, start=1):
        axes = figure.add_subplot(1, len(situations), index, projection="3d")
        axes.computed_zorder = False  # glyphs are drawn over the features, never hidden
        pen = _Pen(axes, seen)
        captions = []
        for name, body in task.bodies.items():
            key = f"{name}@{situation}"
            if key not in solution:
                continue
            result = solution[key]
            pose = np.asarray(result.pose, dtype=np.float64)
            world = {fname: f.transformed(pose) for fname, f in body.features.items()}
            for fname, feature in world.items():
                draw_feature(pen.use(feature_gid(key, fname), colors[name]), feature, size)
            if world:
                draw_freedom(pen, result, _centre(list(world.values())), glyph)
            captions.append(freedom_caption(result))
        axes.set_title(f"situation {situation}", fontsize=10)
        caption = "\n".join(c for c in captions if c) or "every body has one pose"
        axes.text2D(0.02, 0.97, caption, transform=axes.transAxes, fontsize=9, va="top")
        panes.append(axes)
    cloud = np.concatenate(seen) if seen else np.zeros((1, 3))
    lo, hi = cloud.min(axis=0), cloud.max(axis=0)
    centre, half = (lo + hi) / 2, max(float(np.max(hi - lo)) / 2, np.finfo(float).tiny)
    for axes in panes:
        for setter, c in zip((axes.set_xlim, axes.set_ylim, axes.set_zlim), centre, strict=True):
            setter(c - half, c + half)
        axes.set_box_aspect((1, 1, 1), zoom=PANEL_ZOOM)
        for setter, letter in zip(
            (axes.set_xlabel, axes.set_ylabel, axes.set_zlabel), "xyz", strict=True
        ):
            setter(fmt.header(letter, task.units), fontsize=8, labelpad=-2)
        axes.tick_params(labelsize=7, pad=0)
    handles = [
        Patch(color=colors[name], label=f"{name} (fixed)" if body.fixed else name)
        for name, body in task.bodies.items()
    ]
    figure.legend(handles=handles, loc="lower center", ncol=min(len(handles), 6), frameon=False)
    source = fmt.file_name(task.source) or "task"
    figure.suptitle(f"{source}: {solution.status}")
    figure.subplots_adjust(
        left=0.02,
        right=0.98,
        top=0.9,
        bottom=LEGEND_HEIGHT / (height + LEGEND_HEIGHT) + 0.02,
        wspace=0.08,
    )
    return figure


def write_task_png(task: Task, solution: Solution, path: str | Path, *, dpi: int = 120) -> Path:
    """Write :func:`task_figure` as a PNG of the figure's size times ``dpi``; returns
    ``path``."""
    return save_png(task_figure(task, solution), path, dpi, crop=False)
