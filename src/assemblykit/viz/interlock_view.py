"""The self-contained HTML page of an interlocking test (docs/interlocking.md): the
verdict in words, the 3D view of the assembly with an arrow per subset that moves, and
tables of what moves, the keys in order and the blocking graphs (one row per distinct
directional blocking graph, Wilson & Latombe 1992). plotly's JavaScript is embedded so the
file opens offline.
"""

from __future__ import annotations

import html as markup

import numpy as np
import plotly.graph_objects as go
import plotly.io as pio

from assemblykit import formatting as fmt
from assemblykit.model.assembly import Assembly
from assemblykit.planning.interlocking import Interlocking
from assemblykit.planning.plan_values import Plan
from assemblykit.viz.viewer import ARROW_COLOR, STYLE, ReportTable, figure


def interlock_page(loaded: Assembly, result: Interlocking) -> str:
    """A self-contained HTML page of an interlocking test: the verdict in words, the 3D
    view of the assembly (:func:`assemblykit.viz.viewer.figure`) with an arrow per
    subset that moves, and tables of what moves, the keys in order and the blocking
    graphs."""
    tol = result.tol
    view = figure(loaded, Plan(tuple(loaded.names), (), (), None, 0))
    size = 0.15 * loaded.scale
    for freedom in result.freedoms:
        d = np.asarray(freedom.direction, dtype=np.float64)
        if len(d) != 3:
            continue  # a twist: shown in the table only
        bounds = np.array([loaded.parts[n].mesh.bounds for n in freedom.parts])
        centre = (bounds[:, 0].min(axis=0) + bounds[:, 1].max(axis=0)) / 2
        tip = centre + size * d
        view.add_trace(
            go.Scatter3d(
                x=[centre[0], tip[0]],
                y=[centre[1], tip[1]],
                z=[centre[2], tip[2]],
                mode="lines",
                line={"color": ARROW_COLOR, "width": 6},
                name=", ".join(freedom.parts),
                hoverinfo="name",
            )
        )
        view.add_trace(
            go.Cone(
                x=[tip[0]],
                y=[tip[1]],
                z=[tip[2]],
                u=[d[0]],
                v=[d[1]],
                w=[d[2]],
                sizemode="absolute",
                sizeref=0.3 * size,
                anchor="tip",
                showscale=False,
                colorscale=[[0, ARROW_COLOR], [1, ARROW_COLOR]],
                name=", ".join(freedom.parts),
                hoverinfo="name",
            )
        )
    plot = pio.to_html(
        view,
        full_html=False,
        include_plotlyjs=True,
        div_id="assembly-view",
        validate=False,
        config={"displaylogo": False},
    )
    moving = ReportTable(
        "What moves",
        ("moves", "e.g. along", "free along", "to block it"),
        tuple(
            (
                ", ".join(f.parts),
                fmt.direction(f.direction, tol),
                ", ".join(d.words(tol) for d in f.free_along) or "-",
                f.advice(tol),
            )
            for f in result.freedoms
        ),
        "Each subset that moves relative to the rest, one direction that frees it, where it "
        "is free (regions of the blocking graph) and the contacts that would block it.",
    )
    order = ReportTable(
        "Keys in order",
        ("step", "keys", "along", "rest"),
        tuple(
            (str(k), ", ".join(r.keys), fmt.direction(r.direction, tol), fmt.name_list(r.rest, 8))
            for k, r in enumerate(result.order, start=1)
        ),
    )
    cells = ReportTable(
        "Blocking graphs",
        ("direction", "regions", "strong components", "free"),
        tuple(
            (
                fmt.direction(c.direction, tol),
                str(c.regions),
                "; ".join(fmt.name_list(g.parts, 6) for g in c.components),
                "; ".join(fmt.name_list(g.parts, 6) for g in c.components if g.free) or "-",
            )
            for c in result.cells
        ),
        "One row per distinct directional blocking graph: a subset moves along its directions "
        "iff it is a union of strong components that no arc leaves.",
    )
    name = markup.escape(fmt.file_name(loaded.source) or "assembly")
    lines = "".join(f"<p>{markup.escape(line)}</p>" for line in result.summary().splitlines())
    sections = [moving.to_html()] + ([order.to_html()] if result.order else []) + [cells.to_html()]
    return (
        '<!DOCTYPE html>\n<html><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>{name}: {markup.escape(result.verdict)}</title><style>{STYLE}</style>"
        f"</head><body>\n<h1>{name}: {markup.escape(result.verdict)}</h1>{lines}\n{plot}\n"
        + "\n".join(sections)
        + "\n</body></html>\n"
    )
