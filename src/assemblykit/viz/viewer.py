"""The self-contained HTML report of a disassembly plan.

One file holds everything: plotly's JavaScript is embedded by default (about 5 MB, opens
offline; ``plotlyjs="cdn"`` links it instead for a small file that needs the network).
The 3D view is one ``mesh3d`` trace holding every part (per-face colours) and one for the
arrow of the shown step; a slider and a play button walk through the steps. A few lines
of JavaScript move the vertices and recolour the faces for each step, so the file carries
the geometry once whatever the number of steps. The camera is fitted to the assembled
state (:func:`view_box`). Step k shows the parts still assembled, dimmed, and the parts
of step k in their colours, moved along the step's direction (:mod:`.explode`, as far
as the view allows) with an arrow and a caption in words; parts removed in earlier steps
have left the view. Below the view: the steps as a table (the parts the moved ones leave
are counted, the list behind a toggle), the parts grouped by step, and the blocking
relations of the step's direction (Wilson & Latombe 1992, §3: which of the remaining
parts the moved ones were holding in place).
"""

from __future__ import annotations

import base64
import html
import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import plotly.graph_objects as go
import plotly.io as pio
import trimesh
from numpy.typing import NDArray
from plotly.colors import hex_to_rgb, qualitative

from assemblykit import formatting as fmt
from assemblykit.algebra import se3
from assemblykit.outputs import atomic_output
from assemblykit.viz.explode import Explosion, explosion

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly
    from assemblykit.planning.sequence import Plan, Step
    from assemblykit.tolerance import Tolerance

PALETTE = qualitative.Plotly + qualitative.Dark24  # hex strings: valid for matplotlib too
DIM_TOWARDS = (0.88, 0.88, 0.88)
"""Parts that do not move in the shown step are blended this far towards light grey."""
DIM_AMOUNT = 0.75
ARROW_COLOR = "#111111"
ARROW_FRACTION = 0.12
"""Length of the arrow of a step, as a fraction of the assembly's size."""
ARROW_RADIUS_FRACTION = 0.008
ARROW_SECTIONS = 12
LIST_OPEN_PARTS = 30
"""Part lists and "away from" cells longer than this start folded."""
SHOWN_NAMES = 6
"""Names written out in a table cell before the rest goes behind a toggle."""
PLAY_MILLISECONDS = 1200
VIEW_DIRECTION = (1.25, -1.25, 0.95)
"""The camera looks from this side (front right, a little above)."""
EYE_DISTANCE = 1.3
"""Distance of the camera from the centre of the scene box (largest side 1; plotly's
default view is at 2.17)."""
VIEW_MARGIN = 1.5
"""The scene box's half-sides, in half-extents of the assembled state."""
FLATTEST = 0.8
"""The scene box's thinnest side, as a fraction of its largest."""
MIN_BOX_FRACTION = 0.01
"""Smallest half-side of the scene box, as a fraction of the assembly's size."""
PlotlyJs = Literal["inline", "cdn"]

STYLE = """
body { font-family: system-ui, sans-serif; margin: 1.5em; color: #222; max-width: 72em; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; display: block; max-width: 100%;
  overflow-x: auto; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
th { background: #f2f2f2; }
tr.current td { background: #fff6d5; }
.infeasible { color: #b00020; }
#assembly-view { max-width: 56em; }
@media (max-width: 40em) { body { margin: 0.6em; } #step-label { min-width: 6em; } }
.controls { display: flex; align-items: center; gap: 0.8em; margin: 0.4em 0; max-width: 56em; }
.controls input[type=range] { flex: 1; }
#step-label { min-width: 9em; font-variant-numeric: tabular-nums; }
#caption { min-height: 2.6em; margin: 0.2em 0 1em; }
.swatch { display: inline-block; width: 0.8em; height: 0.8em; margin-right: 0.3em;
  border: 1px solid #888; vertical-align: baseline; }
details > summary { cursor: pointer; }
ul.parts { columns: 16em; margin: 0.3em 0 0.8em; }
"""

SCRIPT = """
(function () {
  const P = %(data)s;
  const gd = document.getElementById("assembly-view");
  const bytes = (s) => Uint8Array.from(atob(s), (c) => c.charCodeAt(0)).buffer;
  const base = new Float32Array(bytes(P.vertices));
  const nv = base.length / 3, nf = P.faceStart[P.faceStart.length - 1];
  const partOfVertex = new Int32Array(nv), partOfFace = new Int32Array(nf);
  P.names.forEach((_, p) => {
    partOfVertex.fill(p, P.vertexStart[p], P.vertexStart[p + 1]);
    partOfFace.fill(p, P.faceStart[p], P.faceStart[p + 1]);
  });
  const hover = Array.from(partOfVertex, (p) => P.names[p]);
  const slider = document.getElementById("step-slider");
  const play = document.getElementById("play");
  let timer = null;
  function show(k) {
    const x = new Float32Array(nv), y = new Float32Array(nv), z = new Float32Array(nv);
    const shift = P.names.map((_, p) => {
      const s = P.stepOf[p];
      if (s === 0 || s > k) return [0, 0, 0];
      const t = P.travel[k] - P.travel[s - 1] + (s < k ? P.away : 0), d = P.directions[s - 1];
      return [d[0] * t, d[1] * t, d[2] * t];
    });
    for (let v = 0; v < nv; v++) {
      const o = shift[partOfVertex[v]];
      x[v] = base[3 * v] + o[0]; y[v] = base[3 * v + 1] + o[1]; z[v] = base[3 * v + 2] + o[2];
    }
    const colour = Array.from(partOfFace, (p) =>
      k === 0 || P.stepOf[p] === k ? P.slot[p] : P.slot[p] + P.palette);
    Plotly.restyle(gd, {x: [x], y: [y], z: [z], intensity: [colour], text: [hover]}, [0]);
    const arrow = k === 0 ? null : P.arrows[k - 1];
    Plotly.restyle(gd, arrow === null ? {visible: false} :
      {visible: true, x: [arrow[0]], y: [arrow[1]], z: [arrow[2]]}, [1]);
    slider.value = k;
    document.getElementById("step-label").textContent = P.labels[k];
    document.getElementById("caption").textContent = P.captions[k];
    document.querySelectorAll("tr.step").forEach((row) =>
      row.classList.toggle("current", Number(row.dataset.step) === k));
    gd.dataset.step = String(k);
  }
  function stop() { clearInterval(timer); timer = null; play.textContent = "\\u25B6 play"; }
  slider.addEventListener("input", () => { stop(); show(Number(slider.value)); });
  play.addEventListener("click", () => {
    if (timer !== null) { stop(); return; }
    if (Number(slider.value) >= P.labels.length - 1) show(0);
    play.textContent = "\\u275A\\u275A pause";
    timer = setInterval(() => {
      const k = Number(slider.value) + 1;
      if (k >= P.labels.length) { stop(); return; }
      show(k);
    }, %(interval)d);
  });
  window.assemblyReport = {show: show, data: P};
  show(0);
})();
"""


@dataclass(frozen=True)
class ReportTable:
    """A section of the report: a title, column headers and rows of text cells."""

    title: str
    headers: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    note: str = ""

    def to_html(self) -> str:
        """The section as a heading, its note and the table."""
        note = f"<p>{html.escape(self.note)}</p>" if self.note else ""
        return f"<h2>{html.escape(self.title)}</h2>{note}{fmt.html_table(self.headers, self.rows)}"


def part_colors(names: Sequence[str]) -> dict[str, str]:
    """A colour per part, cycling through plotly's qualitative palettes."""
    return {name: PALETTE[i % len(PALETTE)] for i, name in enumerate(names)}


def dimmed(color: str) -> str:
    """``color`` blended towards light grey: a part that does not move in this step."""
    rgb = np.asarray(hex_to_rgb(color), dtype=np.float64) / 255
    mixed = (1 - DIM_AMOUNT) * rgb + DIM_AMOUNT * np.asarray(DIM_TOWARDS)
    return "#" + "".join(f"{round(255 * c):02x}" for c in mixed)


def _colorscale() -> list[list[Any]]:
    """A discrete colour scale: slot i < len(PALETTE) is palette colour i, slot
    len(PALETTE) + i its dimmed version (face intensities are slot numbers)."""
    colors = [*PALETTE, *(dimmed(c) for c in PALETTE)]
    n = len(colors)
    scale: list[list[Any]] = []
    for i, color in enumerate(colors):
        scale += [[i / n, color], [(i + 1) / n, color]]
    return scale


@dataclass(frozen=True)
class Scene:
    """What the 3D view draws, computed once: every part's mesh in one array
    (``vertices`` float32 in assembled position, ``faces`` indexing them, where each
    part's vertices and faces start, plus the totals), the exploded ``frames`` and one
    arrow mesh per step."""

    vertices: NDArray[np.float32]
    faces: NDArray[np.int32]
    vertex_start: tuple[int, ...]
    face_start: tuple[int, ...]
    frames: Explosion
    arrows: tuple[trimesh.Trimesh, ...]


def scene(assembly: Assembly, plan: Plan) -> Scene:
    """The parts' meshes concatenated in the assembly's order (one trace for all), the
    plan's exploded frames and arrows."""
    vertices, faces, vertex_start, face_start = [], [], [0], [0]
    for part in assembly:
        mesh = part.mesh
        faces.append(np.asarray(mesh.faces, dtype=np.int64) + vertex_start[-1])
        vertices.append(np.asarray(mesh.vertices, dtype=np.float64))
        vertex_start.append(vertex_start[-1] + len(mesh.vertices))
        face_start.append(face_start[-1] + len(mesh.faces))
    within = view_box(assembly)
    frames = explosion(assembly, plan, within, ARROW_FRACTION * assembly.scale)
    return Scene(
        np.concatenate(vertices).astype(np.float32) if vertices else np.zeros((0, 3), np.float32),
        np.concatenate(faces).astype(np.int32) if faces else np.zeros((0, 3), np.int32),
        tuple(vertex_start),
        tuple(face_start),
        frames,
        tuple(step_arrows(assembly, plan, frames)),
    )


def _moved_bounds(assembly: Assembly, names: Sequence[str]) -> NDArray[np.float64]:
    boxes = np.array([assembly.parts[n].mesh.bounds for n in names], dtype=np.float64)
    return np.array([boxes[:, 0].min(axis=0), boxes[:, 1].max(axis=0)])


def _arrow_mesh(
    start: NDArray[np.float64], direction: NDArray[np.float64], length: float, radius: float
) -> trimesh.Trimesh:
    """A shaft and a cone from ``start`` along the unit ``direction``."""
    head = min(0.35 * length, 6 * radius)
    shaft = trimesh.creation.cylinder(radius=radius, height=length - head, sections=ARROW_SECTIONS)
    shaft.apply_translation((0, 0, (length - head) / 2))
    cone = trimesh.creation.cone(radius=2.5 * radius, height=head, sections=ARROW_SECTIONS)
    cone.apply_translation((0, 0, length - head))
    arrow = trimesh.util.concatenate([shaft, cone])
    assert isinstance(arrow, trimesh.Trimesh)  # meshes concatenate to a mesh
    arrow.apply_transform(se3.frame(start, direction))
    return arrow


def step_arrows(assembly: Assembly, plan: Plan, frames: Explosion) -> list[trimesh.Trimesh]:
    """One arrow per step, from the leading face of the moved parts (where they are in
    the step's frame) along the step's direction, ``ARROW_FRACTION`` of the assembly's
    size long."""
    arrows = []
    radius = ARROW_RADIUS_FRACTION * assembly.scale
    for number, step in enumerate(plan.steps, start=1):
        d = frames.directions[number - 1]
        lo, hi = _moved_bounds(assembly, step.parts)
        corners = np.array(np.meshgrid(*zip(lo, hi, strict=True))).reshape(3, -1).T
        centre = (lo + hi) / 2 + d * frames.distance(number)
        start = centre + d * ((corners - (lo + hi) / 2) @ d).max()
        arrows.append(_arrow_mesh(start, d, ARROW_FRACTION * assembly.scale, radius))
    return arrows


def view_box(assembly: Assembly) -> NDArray[np.float64]:
    """The box the view shows, ``[lo, hi]``: ``VIEW_MARGIN`` times the assembly's
    half-extents around its centre, no side thinner than ``FLATTEST`` of the largest (so
    parts lifted off a flat assembly stay in view)."""
    lo, hi = np.asarray(assembly.bounds, dtype=np.float64)
    centre = (lo + hi) / 2
    half = np.maximum((hi - lo) / 2, MIN_BOX_FRACTION * assembly.scale)
    reach = VIEW_MARGIN * np.maximum(half, FLATTEST * half.max())
    return np.array([centre - reach, centre + reach])


def _view(assembly: Assembly) -> dict[str, Any]:
    """Scene axes on :func:`view_box`, fitted to the assembled state, seen from
    ``VIEW_DIRECTION``. plotly draws only what lies inside the axes, so parts removed in
    earlier steps leave the view instead of shrinking the assembly to a dot."""
    lo, hi = view_box(assembly)
    size = hi - lo
    eye = EYE_DISTANCE * np.asarray(VIEW_DIRECTION) / np.linalg.norm(VIEW_DIRECTION)
    axis = {"visible": False}
    return {
        **{f"{c}axis": {**axis, "range": [lo[i], hi[i]]} for i, c in enumerate("xyz")},
        "aspectmode": "manual",
        "aspectratio": dict(zip("xyz", (size / size.max()).tolist(), strict=True)),
        "camera": {"eye": dict(zip("xyz", eye.tolist(), strict=True))},
    }


def figure(assembly: Assembly, plan: Plan, drawn: Scene | None = None) -> go.Figure:
    """The 3D view in its assembled state: trace 0 holds every part (face intensities are
    colour slots of :func:`_colorscale`), trace 1 the arrow of the shown step (hidden in
    the assembled state). The page's script moves and recolours them per step."""
    drawn = scene(assembly, plan) if drawn is None else drawn
    slots = [i % len(PALETTE) for i in range(len(assembly.names))]
    face_slots = np.repeat(np.asarray(slots, dtype=np.uint8), np.diff(drawn.face_start))
    vertices, faces = drawn.vertices, drawn.faces
    arrow_faces = np.asarray(drawn.arrows[0].faces) if drawn.arrows else np.zeros((0, 3), np.int32)
    parts = go.Mesh3d(
        x=vertices[:, 0],
        y=vertices[:, 1],
        z=vertices[:, 2],
        i=faces[:, 0],
        j=faces[:, 1],
        k=faces[:, 2],
        intensity=face_slots,
        intensitymode="cell",
        colorscale=_colorscale(),
        cmin=0,
        cmax=2 * len(PALETTE),
        showscale=False,
        flatshading=True,
        name="parts",
        hoverinfo="text",
        lighting={"ambient": 0.55, "diffuse": 0.8, "specular": 0.1},
    )
    arrow = go.Mesh3d(
        x=[],
        y=[],
        z=[],
        i=arrow_faces[:, 0],
        j=arrow_faces[:, 1],
        k=arrow_faces[:, 2],
        color=ARROW_COLOR,
        flatshading=True,
        name="direction",
        hoverinfo="name",
        visible=False,
    )
    fig = go.Figure(data=[parts, arrow])
    fig.update_layout(
        scene=_view(assembly),
        height=620,
        margin={"l": 0, "r": 0, "t": 0, "b": 0},
        showlegend=False,
        uirevision="report",
    )
    return fig


def _names_cell(names: Sequence[str], *, folded: bool = False) -> str:
    """HTML for a list of names: written out when short (and not ``folded``), else a
    count with the list behind a toggle."""
    if not names:
        return "-"
    escaped = ", ".join(html.escape(n) for n in names)
    if len(names) <= SHOWN_NAMES and not folded:
        return escaped
    return f"<details><summary>{fmt.count(len(names), 'part')}</summary>{escaped}</details>"


def _held(step: Step) -> list[str]:
    """The blocking arcs into the moved parts: who was held in place by them."""
    moved = set(step.parts)
    return sorted({i for i, j in step.blocking if j in moved and i not in moved})


def caption(number: int, plan: Plan, tol: Tolerance | None = None) -> str:
    """What frame ``number`` shows, in words (0 is the assembly)."""
    total = len(plan.steps)
    if number == 0:
        return (
            f"Assembled: {fmt.count(len(plan.parts), 'part')}. Press play or move the slider "
            f"to take it apart in {fmt.count(total, 'step')}."
        )
    step = plan.steps[number - 1]
    moved = fmt.name_list(step.parts)
    away = f" away from {fmt.count(len(step.rest), 'part')}" if step.rest else ""
    return (
        f"Step {number} of {total}: {moved} {'move' if len(step.parts) > 1 else 'moves'} "
        f"along {fmt.direction(step.direction, tol)} ({step.motion}){away}."
    )


def _step_table(plan: Plan, tol: Tolerance | None) -> str:
    headers = ("step", "move", "direction", "motion", "away from", "held in place")
    head = "".join(f"<th>{h}</th>" for h in headers)
    rows = []
    for number, step in enumerate(plan.steps, start=1):
        cells = (
            str(number),
            _names_cell(step.parts),
            html.escape(fmt.direction(step.direction, tol)),
            html.escape(step.motion),
            _names_cell(step.rest, folded=True),
            _names_cell(_held(step)),
        )
        rows.append(
            f'<tr class="step" data-step="{number}">'
            + "".join(f"<td>{c}</td>" for c in cells)
            + "</tr>"
        )
    return f"<table><tr>{head}</tr>{''.join(rows)}</table>"


def _assembly_table(plan: Plan, tol: Tolerance | None) -> str:
    """The assembly order: each step inserts parts along minus the removal direction
    while the parts listed are held; under gravity, whether its states stand."""
    headers = ["step", "insert", "direction", "onto", "held"]
    if plan.gravity is not None:
        headers.append("stands")
    head = "".join(f"<th>{h}</th>" for h in headers)
    rows = []
    for number, step in enumerate(plan.assembly_steps, start=1):
        cells = [
            str(number),
            _names_cell(step.parts),
            html.escape(fmt.direction(step.direction, tol)),
            _names_cell(step.onto, folded=True),
            _names_cell(step.held),
        ]
        stability = plan.steps[step.reverses - 1].stability
        if stability is not None:
            fall = ", ".join(stability.would_fall)
            cells.append("yes" if stability.stands else f"no: {html.escape(fall)} fall")
        rows.append("<tr>" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>")
    return f"<table><tr>{head}</tr>{''.join(rows)}</table>"


def _part_list(assembly: Assembly, plan: Plan) -> str:
    """The parts with their colours, grouped by the step that removes them."""
    colors = part_colors(assembly.names)

    def items(names: Sequence[str]) -> str:
        return "".join(
            f'<li><span class="swatch" style="background:{colors[n]}"></span>{html.escape(n)}</li>'
            for n in names
        )

    moved = {n for step in plan.steps for n in step.parts}
    groups = [(f"Step {k}", step.parts) for k, step in enumerate(plan.steps, start=1)]
    left = [n for n in assembly.names if n not in moved]
    if left:
        groups.append(("Not moved" if plan.feasible else "Not separated", tuple(left)))
    is_open = " open" if len(assembly.names) <= LIST_OPEN_PARTS else ""
    inner = "".join(
        f'<p>{html.escape(title)}:</p><ul class="parts">{items(names)}</ul>'
        for title, names in groups
    )
    return (
        f"<details{is_open}><summary>{fmt.count(len(assembly.names), 'part')}, "
        f"by step</summary>{inner}</details>"
    )


def _interlock_table(plan: Plan) -> str:
    return fmt.html_table(
        (
            "parts",
            "locked for infinitesimal translations",
            "a rigid motion may free them",
            "interfering pairs (shared volume)",
        ),
        [
            (
                ", ".join(lock.parts),
                "yes" if lock.translation_locked else "no",
                "yes" if lock.rigid_may_free else "no",
                "; ".join(f"{a} / {b} ({v:.3g})" for a, b, v in lock.interfering) or "none",
            )
            for lock in plan.interlocked
        ],
    )


def _b64(array: NDArray[Any]) -> str:
    return base64.b64encode(np.ascontiguousarray(array).tobytes()).decode("ascii")


def _script(assembly: Assembly, plan: Plan, drawn: Scene, tol: Tolerance | None) -> str:
    frames = drawn.frames
    total = len(plan.steps)
    data = {
        "names": list(assembly.names),
        "vertices": _b64(drawn.vertices),
        "vertexStart": list(drawn.vertex_start),
        "faceStart": list(drawn.face_start),
        "slot": [i % len(PALETTE) for i in range(len(assembly.names))],
        "palette": len(PALETTE),
        "stepOf": [frames.step_of[n] for n in assembly.names],
        "directions": np.round(frames.directions, 6).tolist(),
        "travel": [float(f"{t:.6g}") for t in frames.travel],
        "away": float(f"{2 * np.linalg.norm(np.subtract(*view_box(assembly))):.6g}"),
        "arrows": [np.round(a.vertices.T, 5).tolist() for a in drawn.arrows],
        "labels": ["assembled"] + [f"step {k} of {total}" for k in range(1, total + 1)],
        "captions": [caption(k, plan, tol) for k in range(total + 1)],
    }
    return SCRIPT % {"data": json.dumps(data, separators=(",", ":")), "interval": PLAY_MILLISECONDS}


def report_html(
    assembly: Assembly,
    plan: Plan,
    *,
    title: str | None = None,
    extra: Sequence[ReportTable] = (),
    plotlyjs: PlotlyJs = "inline",
) -> str:
    """The report page as one HTML string (module docstring). ``extra`` adds sections
    (e.g. the motion of each part); ``plotlyjs`` embeds plotly.js (``inline``, works
    offline) or links it from its CDN (``cdn``, a small file that needs the network)."""
    name = title or (Path(assembly.source).name if assembly.source else "assembly")
    tol = assembly.tolerance()
    drawn = scene(assembly, plan)
    verdict = (
        f"feasible in {fmt.count(len(plan.steps), 'step')} by extended translations"
        if plan.feasible
        else f"infeasible: interlocked parts {', '.join(plan.stuck)}"
    )
    units = f"; lengths in {assembly.units}" if assembly.units_source != "default" else ""
    plot = pio.to_html(
        figure(assembly, plan, drawn),
        full_html=False,
        include_plotlyjs=True if plotlyjs == "inline" else "cdn",
        div_id="assembly-view",
        auto_play=False,
        validate=False,
        config={"displaylogo": False},
    )
    last = len(plan.steps)
    body = [
        f"<h1>Disassembly plan: {html.escape(name)}</h1>",
        f'<p class="{"feasible" if plan.feasible else "infeasible"}">'
        f"{fmt.count(len(plan.parts), 'part')}; {html.escape(verdict)}; "
        f"{fmt.count(plan.directions, 'candidate direction')}{html.escape(units)}.</p>",
        plot,
        '<div class="controls"><button id="play" type="button">&#9654; play</button>'
        f'<input id="step-slider" type="range" min="0" max="{last}" step="1" value="0"'
        ' aria-label="step">'
        '<span id="step-label">assembled</span></div>',
        f'<p id="caption">{html.escape(caption(0, plan, tol))}</p>',
        f"<script>{_script(assembly, plan, drawn, tol)}</script>",
        "<h2>Steps</h2>",
        "<p>Each step translates the moved parts along the direction, away from the other "
        "parts still assembled. Held in place: parts that the moved ones block along that "
        "direction (so they can only follow afterwards).</p>",
        _step_table(plan, tol),
        "<h2>Assembly order</h2>",
        "<p>The steps reversed: each inserts its parts along the direction while the "
        "parts listed are held.</p>",
        _assembly_table(plan, tol),
        "<h2>Parts</h2>",
        _part_list(assembly, plan),
    ]
    if plan.and_or is not None:
        counts = plan.and_or.to_dict()
        body.append(
            f"<p>AND/OR graph: {counts['subassemblies']} subassemblies, "
            f"{counts['partitions']} feasible partitions, {counts['plans']} plans.</p>"
        )
    if plan.interlocked:
        body += ["<h2>Interlocked</h2>", _interlock_table(plan)]
    body += [table.to_html() for table in extra]
    return (
        '<!DOCTYPE html>\n<html><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>{html.escape(name)}: disassembly plan</title>"
        f"<style>{STYLE}</style></head><body>\n" + "\n".join(body) + "\n</body></html>\n"
    )


def write_report(
    assembly: Assembly,
    plan: Plan,
    path: str | Path,
    *,
    title: str | None = None,
    extra: Sequence[ReportTable] = (),
    plotlyjs: PlotlyJs = "inline",
) -> Path:
    """Write :func:`report_html` to ``path`` (UTF-8) and return the path."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    page = report_html(assembly, plan, title=title, extra=extra, plotlyjs=plotlyjs)
    with atomic_output(target) as temporary:
        temporary.write_text(page, encoding="utf-8")
    return target
