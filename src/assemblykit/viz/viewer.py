"""The self-contained HTML report of a disassembly plan (DESIGN.md §6).

One file holds everything: plotly's JavaScript is embedded (``include_plotlyjs=True``,
about 5 MB), so the report opens offline. It shows the assembly in 3D (one ``mesh3d``
trace per part), an exploded disassembly animated with a step slider (plotly frames),
the plan as a table and, per step, the blocking relations of seed 004 along the step's
direction: which of the remaining parts the moved ones were holding in place.
"""

from __future__ import annotations

import html
import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import plotly.graph_objects as go
from plotly.colors import qualitative

from assemblykit.io.outputs import atomic_output
from assemblykit.planning.sequence import format_direction

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly
    from assemblykit.planning.sequence import Plan, Step

EXPLODE_FRACTION = 0.35
"""Distance of one exploding step, as a fraction of the assembly's bounding-box diagonal."""

PALETTE = qualitative.Plotly + qualitative.Dark24  # hex strings: valid for matplotlib too
FRAME_ARGS = {
    "mode": "immediate",
    "frame": {"duration": 0, "redraw": True},
    "transition": {"duration": 0},
}

STYLE = """
body { font-family: system-ui, sans-serif; margin: 1.5em; color: #222; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
th { background: #f2f2f2; }
.infeasible { color: #b00020; }
pre { background: #f7f7f7; padding: 0.8em; overflow-x: auto; }
"""


def part_colors(names: Sequence[str]) -> dict[str, str]:
    """A colour per part, cycling through plotly's qualitative palettes."""
    return {name: PALETTE[i % len(PALETTE)] for i, name in enumerate(names)}


def figure(assembly: Assembly, plan: Plan) -> go.Figure:
    """The 3D view: one ``mesh3d`` per part and one animation frame per plan step, with a
    slider over the frames (frame k shows the exploded state after step k)."""
    names = list(assembly.names)
    colors = part_colors(names)
    frames_offsets = plan.exploded(EXPLODE_FRACTION * assembly.scale)
    meshes = {name: assembly.parts[name].mesh for name in names}
    traces = [
        _mesh_trace(name, meshes[name], frames_offsets[0][name], colors[name]) for name in names
    ]
    frames = [
        go.Frame(
            name=str(k),
            data=[go.Mesh3d(**_coords(meshes[name], offsets[name])) for name in names],
            traces=list(range(len(names))),
        )
        for k, offsets in enumerate(frames_offsets)
    ]
    fig = go.Figure(data=traces, frames=frames)
    lo, hi = _extent(meshes, frames_offsets)
    axis = {"visible": False}
    fig.update_layout(
        scene={
            "xaxis": {**axis, "range": [lo[0], hi[0]]},
            "yaxis": {**axis, "range": [lo[1], hi[1]]},
            "zaxis": {**axis, "range": [lo[2], hi[2]]},
            "aspectmode": "manual",
            "aspectratio": dict(zip("xyz", (hi - lo) / float(np.max(hi - lo)), strict=True)),
        },
        height=640,
        margin={"l": 0, "r": 0, "t": 30, "b": 0},
        legend={"itemsizing": "constant"},
        sliders=[
            {
                "active": 0,
                "currentvalue": {"prefix": "step: "},
                "pad": {"t": 10},
                "steps": [
                    {
                        "label": "assembled" if k == 0 else str(k),
                        "method": "animate",
                        "args": [[str(k)], FRAME_ARGS],
                    }
                    for k in range(len(frames))
                ],
            }
        ],
    )
    return fig


def _mesh_trace(name: str, mesh: Any, offset: np.ndarray, color: str) -> go.Mesh3d:
    faces = np.asarray(mesh.faces)
    return go.Mesh3d(
        **_coords(mesh, offset),
        i=faces[:, 0],
        j=faces[:, 1],
        k=faces[:, 2],
        name=name,
        color=color,
        flatshading=True,
        showlegend=True,
        hovertemplate=f"{html.escape(name)}<extra></extra>",
    )


def _coords(mesh: Any, offset: np.ndarray) -> dict[str, np.ndarray]:
    # float32 keeps the embedded (base64) arrays small; it is only for display
    vertices = (np.asarray(mesh.vertices, dtype=np.float64) + offset).astype(np.float32)
    return {"x": vertices[:, 0], "y": vertices[:, 1], "z": vertices[:, 2]}


def _extent(
    meshes: Mapping[str, Any], frames: Sequence[Mapping[str, np.ndarray]]
) -> tuple[np.ndarray, np.ndarray]:
    """Bounds enclosing every part in every frame, so the camera never jumps."""
    lows, highs = [], []
    for offsets in frames:
        for name, mesh in meshes.items():
            lows.append(mesh.bounds[0] + offsets[name])
            highs.append(mesh.bounds[1] + offsets[name])
    return np.min(lows, axis=0), np.max(highs, axis=0)


def _step_rows(plan: Plan) -> str:
    rows = []
    for number, step in enumerate(plan.steps, start=1):
        rows.append(
            "<tr>"
            + "".join(
                f"<td>{html.escape(cell)}</td>"
                for cell in (
                    str(number),
                    ", ".join(step.parts),
                    format_direction(step.direction),
                    step.motion,
                    ", ".join(step.rest),
                    _held(step),
                )
            )
            + "</tr>"
        )
    return "\n".join(rows)


def _held(step: Step) -> str:
    """The blocking arcs into the moved parts: who was held in place by them."""
    moved = set(step.parts)
    held = sorted({i for i, j in step.blocking if j in moved and i not in moved})
    return ", ".join(held) if held else "-"


def _interlock_rows(plan: Plan) -> str:
    return "\n".join(
        "<tr>"
        + "".join(
            f"<td>{html.escape(cell)}</td>"
            for cell in (
                ", ".join(lock.parts),
                "yes" if lock.translation_locked else "no",
                "yes" if lock.rigid_may_free else "no",
            )
        )
        + "</tr>"
        for lock in plan.interlocked
    )


def report_html(
    assembly: Assembly,
    plan: Plan,
    *,
    title: str | None = None,
    extra: Mapping[str, Any] | None = None,
) -> str:
    """The report page as one HTML string (plotly.js embedded).

    ``extra`` maps section titles to JSON-ready values shown verbatim (e.g. the motion
    analysis of seed 003).
    """
    name = title or (Path(assembly.source).name if assembly.source else "assembly")
    verdict = (
        f"feasible: {len(plan.steps)} step(s) by extended translations"
        if plan.feasible
        else f"infeasible: interlocked parts {', '.join(plan.stuck)}"
    )
    counts = plan.and_or.to_dict() if plan.and_or is not None else None
    body = [
        f"<h1>Disassembly plan: {html.escape(name)}</h1>",
        f'<p class="{"feasible" if plan.feasible else "infeasible"}">'
        f"{len(plan.parts)} parts; {html.escape(verdict)}; "
        f"{plan.directions} candidate directions.</p>",
        figure(assembly, plan).to_html(
            full_html=False, include_plotlyjs=True, div_id="assembly-view", auto_play=False
        ),
        "<h2>Steps</h2>",
        "<p>Each step translates the moved parts along the direction, away from the parts "
        "listed as the rest. Held in place: parts of the rest that the moved parts block "
        "along that direction (so they can only follow afterwards).</p>",
        "<table><tr><th>step</th><th>move</th><th>direction</th><th>motion</th>"
        "<th>away from</th><th>held in place</th></tr>",
        _step_rows(plan),
        "</table>",
    ]
    if counts is not None:
        body.append(
            f"<p>AND/OR graph: {counts['subassemblies']} subassemblies, "
            f"{counts['partitions']} feasible partitions, {counts['plans']} plans.</p>"
        )
    if plan.interlocked:
        body += [
            "<h2>Interlocked</h2>",
            "<table><tr><th>parts</th><th>locked for infinitesimal translations</th>"
            "<th>a rigid motion may free them</th></tr>",
            _interlock_rows(plan),
            "</table>",
        ]
    for section, value in (extra or {}).items():
        body += [
            f"<h2>{html.escape(section)}</h2>",
            f"<pre>{html.escape(json.dumps(value, indent=2))}</pre>",
        ]
    return (
        '<!DOCTYPE html>\n<html><head><meta charset="utf-8">'
        f"<title>{html.escape(name)}: disassembly plan</title>"
        f"<style>{STYLE}</style></head><body>\n" + "\n".join(body) + "\n</body></html>\n"
    )


def write_report(
    assembly: Assembly,
    plan: Plan,
    path: str | Path,
    *,
    title: str | None = None,
    extra: Mapping[str, Any] | None = None,
) -> Path:
    """Write :func:`report_html` to ``path`` (UTF-8) and return the path."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    page = report_html(assembly, plan, title=title, extra=extra)
    with atomic_output(target) as temporary:
        temporary.write_text(page, encoding="utf-8")
    return target
