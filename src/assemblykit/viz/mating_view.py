"""A PNG of a mating problem's two-layer constraint graph (networkx + matplotlib, Agg
canvas), after Liu & Popplestone 1990, step one.

The top layer has the bodies as nodes and the goals (``b1 fits b4``) as arcs; the
bottom layer has the compound features as nodes, each under its body, and the candidate
mating pairs of every goal as arcs in the goal's colour. A pair deleted by a law is
drawn faded, in the line style of that law (node consistency, mandatory request,
equivalent feature, arc and path consistency: :data:`~assemblykit.mating.search.LAWS`);
the pairs of the first configuration found are drawn bold. Every pair's artist carries a
``gid`` (:func:`pair_gid`) naming the goal, the two compounds and its state.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import matplotlib

matplotlib.use("Agg")

import networkx as nx
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from assemblykit import formatting as fmt
from assemblykit.mating.search import LAWS
from assemblykit.viz.plots import save_png

if TYPE_CHECKING:
    from assemblykit.mating.graph import Candidate
    from assemblykit.mating.problem import MatingProblem
    from assemblykit.mating.search import MatingResult

CHOSEN = "first configuration"
KEPT = "kept"
LAW_STYLES: Mapping[str, Any] = {
    "node consistency": ":",
    "mandatory request": "--",
    "equivalent feature": "-.",
    "arc consistency": (0, (4, 1, 1, 1, 1, 1)),
    "path consistency": (0, (8, 3)),
}
"""The line style of the pairs each law deleted."""
FADED = 0.45
GOAL_COLORS = "tab10"
TOP, BOTTOM = 1.0, 0.0
"""Heights of the two layers."""
COMPOUND_STEP = 1.0
BODY_GAP = 0.6
"""Room between compounds of one body, and the extra gap between bodies."""
ARC_BEND = 0.25
"""Curvature of an arc (matplotlib ``arc3`` ``rad``); parallel arcs bend further."""


@dataclass(frozen=True)
class PairView:
    """One candidate pair as drawn: its ``goal`` number, the two compound features as
    (body, compound), the law that deleted it (``None`` when no law did) and whether it
    belongs to the first configuration found."""

    goal: int
    first: tuple[str, str]
    second: tuple[str, str]
    pruned_by: str | None
    chosen: bool

    @property
    def state(self) -> str:
        """:data:`CHOSEN`, :data:`KEPT` or the law that deleted the pair."""
        return self.pruned_by or (CHOSEN if self.chosen else KEPT)


def pair_gid(view: PairView) -> str:
    """``pair 1 b1.comp1 b4.comp13 first configuration``: the ``gid`` of a pair's arc."""
    (a, ca), (b, cb) = view.first, view.second
    return f"pair {view.goal} {a}.{ca} {b}.{cb} {view.state}"


def _same(c: Candidate) -> tuple[Any, ...]:
    """What identifies a candidate across the laws' domains: the equivalent feature law
    replaces a candidate by a copy with more ``copies`` but the same coset object."""
    return (c.goal.number, c.first, c.second, c.pairing, id(c.coset))


def pair_views(result: MatingResult) -> list[PairView]:
    """Every candidate pair of every goal (the first of ``result.stages``), with the law
    that deleted it and whether the first configuration uses it."""
    if not result.stages:
        return []
    chosen = {_same(c) for c in result.configurations[0].pairs} if result.configurations else set()
    later = [{_same(c) for domain in stage.values() for c in domain} for stage in result.stages]
    views = []
    for goal, domain in result.stages[0].items():
        for c in domain:
            key = _same(c)
            law = next((LAWS[k] for k in range(1, len(later)) if key not in later[k]), None)
            views.append(
                PairView(
                    goal,
                    (c.goal.first, c.first),
                    (c.goal.second, c.second),
                    law,
                    key in chosen,
                )
            )
    return views


def body_order(problem: MatingProblem) -> list[str]:
    """The bodies left to right: the one in most goals in the middle, so that its arcs
    reach both sides, the others in file order around it.

    >>> from assemblykit.mating.problem import Goal, MatingProblem
    >>> goals = tuple(Goal(k, "fit", f"b{k}", "b4") for k in (1, 2, 3))
    >>> body_order(MatingProblem("mm", dict.fromkeys(["b1", "b2", "b3", "b4"]), goals))
    ['b1', 'b2', 'b4', 'b3']
    """
    names = list(problem.bodies)
    degree = {name: sum(name in (g.first, g.second) for g in problem.goals) for name in names}
    hub = max(names, key=lambda name: degree[name])
    others = [name for name in names if name != hub]
    middle = (len(others) + 1) // 2
    return [*others[:middle], hub, *others[middle:]]


def layout(problem: MatingProblem) -> dict[Any, tuple[float, float]]:
    """Positions of the nodes: ``(name,)`` for a body on the top layer, each body's
    ``(name, compound)`` nodes side by side under it on the bottom layer."""
    pos: dict[Any, tuple[float, float]] = {}
    x = 0.0
    for name in body_order(problem):
        compounds = list(problem.bodies[name].compounds)
        xs = [x + k * COMPOUND_STEP for k in range(len(compounds))]
        pos.update({(name, c): (cx, BOTTOM) for c, cx in zip(compounds, xs, strict=True)})
        pos[(name,)] = (sum(xs) / len(xs) if xs else x, TOP)
        x += max(len(compounds), 1) * COMPOUND_STEP + BODY_GAP
    return pos


def _arc(
    axes: Any, pos: Mapping[Any, tuple[float, float]], u: Any, v: Any, bend: float, **style: Any
) -> Any:
    """One arc between nodes ``u`` and ``v`` drawn by networkx, bent by ``bend``: up when
    negative, down when positive, whichever node is on the left."""
    if pos[u][0] > pos[v][0]:
        u, v = v, u
    graph = nx.DiGraph([(u, v)])
    (patch,) = nx.draw_networkx_edges(
        graph,
        pos,
        ax=axes,
        arrows=True,
        arrowstyle="-",
        connectionstyle=f"arc3,rad={bend}",
        node_size=0,
        **style,
    )
    return patch


def mating_figure(problem: MatingProblem, result: MatingResult) -> Figure:
    """The two-layer graph (module docstring), not yet written."""
    from matplotlib import colormaps

    pos = layout(problem)
    views = pair_views(result)
    palette = colormaps[GOAL_COLORS]
    color = {g.number: palette(k % palette.N) for k, g in enumerate(problem.goals)}
    compounds = sum(len(b.compounds) for b in problem.bodies.values())
    figure = Figure(figsize=(max(8.0, 1.1 * compounds + 2.0), 5.5))
    axes = figure.add_subplot()
    bodies = [(name,) for name in problem.bodies]
    features = [node for node in pos if len(node) == 2]
    for node in features:  # which body each compound feature belongs to
        top = pos[node[:1]]
        axes.plot(*zip(top, pos[node], strict=True), color="0.85", linewidth=0.8, zorder=0)
    for k, goal in enumerate(problem.goals):
        u, v = (goal.first,), (goal.second,)
        _arc(axes, pos, u, v, -ARC_BEND * (1 + k), edge_color=[color[goal.number]], width=2.0)
    # parallel pairs between the same two compounds bend further apart
    seen: dict[frozenset[Any], int] = {}
    for view in sorted(views, key=lambda v: (v.pruned_by is None, v.chosen)):
        ends = frozenset((view.first, view.second))
        bend = ARC_BEND * (1 + seen.get(ends, 0))
        seen[ends] = seen.get(ends, 0) + 1
        faded = view.pruned_by is not None
        patch = _arc(
            axes,
            pos,
            view.first,
            view.second,
            bend,
            edge_color=[color[view.goal]],
            width=3.2 if view.chosen else 1.0 if faded else 1.6,
            alpha=FADED if faded else 1.0,
            style="-" if view.pruned_by is None else LAW_STYLES[view.pruned_by],
        )
        patch.set_gid(pair_gid(view))
    nx.draw_networkx_nodes(
        nx.Graph(), pos, nodelist=bodies, ax=axes, node_color="0.9", node_size=900, edgecolors="0.3"
    )
    nx.draw_networkx_nodes(
        nx.Graph(),
        pos,
        nodelist=features,
        ax=axes,
        node_color="white",
        node_size=1000,
        edgecolors="0.3",
    )
    nx.draw_networkx_labels(
        nx.Graph(), pos, labels={b: b[0] for b in bodies}, ax=axes, font_size=11
    )
    nx.draw_networkx_labels(
        nx.Graph(), pos, labels={f: f[1] for f in features}, ax=axes, font_size=7
    )
    left = min(x for x, _ in pos.values()) - 1.2
    for height, text in (
        (TOP, "bodies\nand goals"),
        (BOTTOM, "compound\nfeatures and\ncandidate pairs"),
    ):
        axes.text(left, height, text, ha="right", va="center", fontsize=9, color="0.35")
    axes.set_xlim(left - 1.6, max(x for x, _ in pos.values()) + 0.8)
    axes.set_ylim(BOTTOM - 0.75, TOP + 0.55)
    axes.set_axis_off()
    axes.legend(
        handles=_legend(problem, views, color),
        loc="lower center",
        ncol=3,
        fontsize=8,
        frameon=False,
        bbox_to_anchor=(0.5, -0.12),
    )
    source = fmt.file_name(problem.source) or "mating problem"
    found = len(result.configurations)
    verdict = (
        f"{fmt.count(result.count, 'configuration')} ({found} found)" if found else "no solution"
    )
    figure.suptitle(f"Two-layer constraint graph of {source}: {verdict}")
    figure.subplots_adjust(left=0.01, right=0.99, top=0.92, bottom=0.14)
    return figure


def _legend(
    problem: MatingProblem, views: Sequence[PairView], color: Mapping[int, Any]
) -> list[Line2D]:
    """The goals' colours, then the line style of each state that occurs."""
    handles = [
        Line2D(
            [],
            [],
            color=color[g.number],
            linewidth=2.0,
            label=f"goal {g.number}: {g.relation} {g.first} {g.second}",
        )
        for g in problem.goals
    ]
    states = {view.state for view in views}
    if CHOSEN in states:
        handles.append(
            Line2D([], [], color="0.2", linewidth=3.2, label="pair of the first configuration")
        )
    if KEPT in states:
        handles.append(Line2D([], [], color="0.2", linewidth=1.6, label="pair kept by every law"))
    handles += [
        Line2D(
            [],
            [],
            color="0.2",
            linewidth=1.0,
            alpha=FADED,
            linestyle=style,
            label=f"deleted by {law}",
        )
        for law, style in LAW_STYLES.items()
        if law in states
    ]
    return handles


def write_mating_png(
    problem: MatingProblem, result: MatingResult, path: str | Path, *, dpi: int = 120
) -> Path:
    """Write :func:`mating_figure` as a PNG of the figure's size times ``dpi``; returns
    ``path``."""
    return save_png(mating_figure(problem, result), path, dpi, crop=False)
