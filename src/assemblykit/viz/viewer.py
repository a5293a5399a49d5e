"""The self-contained HTML report of a disassembly plan.

One file holds everything: plotly's JavaScript is embedded by default (about 5 MB, opens
offline; ``plotlyjs="cdn"`` links it instead for a small file that needs the network).
The 3D view is one ``mesh3d`` trace holding every part (each face in its part's colour,
the colour of the part list below: :func:`part_colors`), one for the arrow of the shown
step and an axis triad (X, Y, Z, labelled) beside the assembly; a slider and a play
button walk through the steps. A few lines of JavaScript move the vertices and recolour
the faces for each step, so the file carries the geometry once whatever the number of
steps. The camera is fitted to the assembled state (:func:`view_box`). Step k shows the
parts still assembled in one neutral grey and the parts of step k in their colours,
moved along the step's direction (:mod:`.explode`, as far as the view allows) with an
arrow that starts on them (:func:`arrow_anchor`) and a caption in words; parts removed
in earlier steps have left the view (docs/planning.md, "The HTML report"). Below the
view: the steps as a table (the parts the moved ones leave are counted, the list behind
a toggle), the parts grouped by step, and the blocking relations of the step's direction
(Wilson & Latombe 1992, §3: which of the remaining parts the moved ones were holding in
place).
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
from plotly.colors import qualitative

from assemblykit import formatting as fmt
from assemblykit.algebra import se3
from assemblykit.outputs import atomic_output
from assemblykit.viz.explode import Explosion, explosion

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly
    from assemblykit.planning.plan_values import Plan, Step
    from assemblykit.tolerance import Tolerance

PALETTE = qualitative.Plotly + qualitative.Dark24  # hex strings: valid for matplotlib too
DIM_COLOR = "#c8c8c8"
"""Every part that does not move in the shown step, whatever its own colour: one neutral
grey, so that the parts of the step are the only colours in the view."""
ARROW_COLOR = "#111111"
ARROW_FRACTION = 0.12
"""Length of the arrow of a step, as a fraction of the assembly's size."""
ARROW_RADIUS_FRACTION = 0.008
ARROW_SECTIONS = 12
LIGHTING = {"ambient": 0.6, "diffuse": 0.55, "specular": 0.05, "fresnel": 0.1}
"""The parts' shading: faces towards the light a little brighter than their colour,
faces away from it darker, never far from the colour of the legend."""
LIGHT_POSITION = {"x": 40_000, "y": -60_000, "z": 100_000}
"""The light comes from above the camera (front right, high up), so the faces the view
shows are lit (plotly's default light is level, from the back left of this view)."""
TRIAD_COLORS = ("#d62728", "#2ca02c", "#1f77b4")
"""The X, Y and Z arrows of the axis triad (red, green, blue, as CAD programs draw them)."""
TRIAD_FRACTION = 0.1
"""Length of each arrow of the axis triad, as a fraction of the assembly's size."""
AXES_NAMES = ("X", "Y", "Z")
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
      k === 0 || P.stepOf[p] === k ? P.colors[p] : P.dim);
    Plotly.restyle(gd, {x: [x], y: [y], z: [z], facecolor: [colour], text: [hover]}, [0]);
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
    """A colour per part, cycling through plotly's qualitative palettes: the one colour
    of the part in the report's legend, its 3D view, the PNG storyboard and the glTF
    scene (docs/planning.md, "The HTML report")."""
    return {name: PALETTE[i % len(PALETTE)] for i, name in enumerate(names)}


def frame_colors(colors: Sequence[str], step_of: Sequence[int], frame: int) -> list[str]:
    """Each part's colour in ``frame`` (0 is the assembly): its own colour (``colors``)
    in the assembled state and when its step (``step_of``, 0 for a part no step moves)
    is the one shown, else ``DIM_COLOR``.

    >>> frame_colors(["#ff0000", "#00ff00"], [1, 2], 2)
    ['#c8c8c8', '#00ff00']
    """
    return [
        color if frame == 0 or step == frame else DIM_COLOR
        for color, step in zip(colors, step_of, strict=True)
    ]


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


def ray_exit(
    origin: NDArray[np.float64], direction: NDArray[np.float64], triangles: NDArray[np.float64]
) -> float | None:
    """How far along ``direction`` from ``origin`` the ray last crosses ``triangles``
    (``n x 3 x 3``): the largest ``t >= 0`` with ``origin + t direction`` on one of them
    (Möller & Trumbore 1997), where the ray leaves a closed mesh it starts inside; None
    when it meets none. Points on a triangle's edge count as on it.

    >>> square = np.array([[[0, 0, 1], [1, 0, 1], [0, 1, 1]], [[1, 0, 1], [1, 1, 1], [0, 1, 1]]])
    >>> ray_exit(np.array([0.5, 0.5, 0.0]), np.array([0.0, 0.0, 1.0]), square.astype(float))
    1.0
    """
    corners = np.asarray(triangles, dtype=np.float64).reshape(-1, 3, 3)
    if not len(corners):
        return None
    first, second = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    normal = np.cross(direction, second)
    det = np.einsum("ij,ij->i", first, normal)
    crossed = det != 0  # the ray is not parallel to the triangle's plane
    first, second, normal = first[crossed], second[crossed], normal[crossed]
    offset = origin - corners[crossed, 0]
    q = np.cross(offset, first)
    with np.errstate(over="ignore", invalid="ignore"):  # nearly parallel: huge, then dropped
        inverse = 1.0 / det[crossed]
        u = np.einsum("ij,ij->i", offset, normal) * inverse
        v = (q @ direction) * inverse
        t = np.einsum("ij,ij->i", second, q) * inverse
    slack = 1e-9  # barycentric: a ray through an edge meets the triangles on both sides
    hit = (u >= -slack) & (v >= -slack) & (u + v <= 1 + slack) & (t >= 0) & np.isfinite(t)
    return float(t[hit].max()) if hit.any() else None


def arrow_anchor(
    meshes: Sequence[trimesh.Trimesh], direction: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Where the arrow of a step starts: on the surface of the moved parts (``meshes``,
    in place), where the ray from the centre of their bounding box along the unit
    ``direction`` leaves them. When that ray misses them (parts apart from one another,
    the centre between them), the ray from the centre of the part nearest it; when that
    misses too (an open mesh), that part's furthest point along the direction, level
    with its centre (docs/planning.md, "The HTML report")."""
    d = np.asarray(direction, dtype=np.float64)
    boxes = np.array([m.bounds for m in meshes], dtype=np.float64)
    centre = (boxes[:, 0].min(axis=0) + boxes[:, 1].max(axis=0)) / 2
    out = ray_exit(centre, d, np.concatenate([m.triangles for m in meshes]))
    if out is not None:
        return centre + out * d
    centres = boxes.mean(axis=1)
    nearest = int(np.argmin(np.linalg.norm(centres - centre, axis=1)))
    own = centres[nearest]
    mesh = meshes[nearest]
    out = ray_exit(own, d, np.asarray(mesh.triangles, dtype=np.float64))
    if out is None:
        out = max(float(((np.asarray(mesh.vertices) - own) @ d).max()), 0.0)
    return own + out * d


def arrow_shape(length: float, radius: float) -> trimesh.Trimesh:
    """An arrow from the origin along +z: a shaft of ``radius`` and a cone, ``length``
    long in all."""
    head = min(0.35 * length, 6 * radius)
    shaft = trimesh.creation.cylinder(radius=radius, height=length - head, sections=ARROW_SECTIONS)
    shaft.apply_translation((0, 0, (length - head) / 2))
    cone = trimesh.creation.cone(radius=2.5 * radius, height=head, sections=ARROW_SECTIONS)
    cone.apply_translation((0, 0, length - head))
    arrow = trimesh.util.concatenate([shaft, cone])
    assert isinstance(arrow, trimesh.Trimesh)  # meshes concatenate to a mesh
    return arrow


def placed(
    shape: trimesh.Trimesh, start: NDArray[np.float64], direction: NDArray[np.float64]
) -> trimesh.Trimesh:
    """``shape`` (an :func:`arrow_shape`) moved to start at ``start`` along the unit
    ``direction``."""
    frame = se3.frame(start, direction)
    vertices = np.asarray(shape.vertices) @ frame[:3, :3].T + frame[:3, 3]
    return trimesh.Trimesh(vertices, np.asarray(shape.faces), process=False)


def _arrow_mesh(
    start: NDArray[np.float64], direction: NDArray[np.float64], length: float, radius: float
) -> trimesh.Trimesh:
    """A shaft and a cone from ``start`` along the unit ``direction``."""
    return placed(arrow_shape(length, radius), start, direction)


def step_arrows(assembly: Assembly, plan: Plan, frames: Explosion) -> list[trimesh.Trimesh]:
    """One arrow per step, ``ARROW_FRACTION`` of the assembly's size long, from the moved
    parts' surface (:func:`arrow_anchor`, where they are in the step's frame) along the
    step's direction."""
    arrows = []
    shape = arrow_shape(ARROW_FRACTION * assembly.scale, ARROW_RADIUS_FRACTION * assembly.scale)
    for number, step in enumerate(plan.steps, start=1):
        d = frames.directions[number - 1]
        meshes = [assembly.parts[name].mesh for name in step.parts]
        arrows.append(placed(shape, arrow_anchor(meshes, d) + d * frames.distance(number), d))
    return arrows


def triad_origin(assembly: Assembly) -> NDArray[np.float64]:
    """Where the axis triad stands: halfway between the assembly's lowest corner and the
    view box's (:func:`view_box`), outside the assembly and inside the view."""
    low = np.asarray(assembly.bounds, dtype=np.float64)[0]
    return (low + view_box(assembly)[0]) / 2


def triad(assembly: Assembly) -> tuple[trimesh.Trimesh, list[str]]:
    """The axis triad: three arrows along +X, +Y and +Z from :func:`triad_origin`,
    ``TRIAD_FRACTION`` of the assembly's size long, as one mesh, and the colour
    (``TRIAD_COLORS``) of each of its faces."""
    origin, length = triad_origin(assembly), TRIAD_FRACTION * assembly.scale
    radius = ARROW_RADIUS_FRACTION * assembly.scale
    arrows = [_arrow_mesh(origin, axis, length, radius) for axis in np.eye(3)]
    colors = [c for arrow, c in zip(arrows, TRIAD_COLORS, strict=True) for _ in arrow.faces]
    mesh = trimesh.util.concatenate(arrows)
    assert isinstance(mesh, trimesh.Trimesh)  # meshes concatenate to a mesh
    return mesh, colors


def triad_labels(assembly: Assembly) -> NDArray[np.float64]:
    """Where the labels ``X``, ``Y`` and ``Z`` of the axis triad stand: a little beyond
    the tip of each arrow (one row per axis)."""
    return triad_origin(assembly) + 1.3 * TRIAD_FRACTION * assembly.scale * np.eye(3)


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


def face_colors(assembly: Assembly, drawn: Scene, frame: int = 0) -> list[str]:
    """The colour of every face of the parts' trace in ``frame`` (:func:`frame_colors`,
    each part's repeated over its faces)."""
    colors = list(part_colors(assembly.names).values())
    step_of = [drawn.frames.step_of[name] for name in assembly.names]
    counts = np.diff(drawn.face_start)
    shown = frame_colors(colors, step_of, frame)
    return [color for color, n in zip(shown, counts, strict=True) for _ in range(n)]


def _triad_traces(assembly: Assembly) -> list[go.Mesh3d | go.Scatter3d]:
    """The axis triad (:func:`triad`) as a mesh trace and a trace of its labels."""
    mesh, colors = triad(assembly)
    vertices, faces = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    labels = triad_labels(assembly)
    return [
        go.Mesh3d(
            x=vertices[:, 0],
            y=vertices[:, 1],
            z=vertices[:, 2],
            i=faces[:, 0],
            j=faces[:, 1],
            k=faces[:, 2],
            facecolor=colors,
            flatshading=True,
            name="axes",
            hoverinfo="skip",
        ),
        go.Scatter3d(
            x=labels[:, 0],
            y=labels[:, 1],
            z=labels[:, 2],
            mode="text",
            text=list(AXES_NAMES),
            textfont={"color": list(TRIAD_COLORS), "size": 15},
            name="axis names",
            hoverinfo="skip",
        ),
    ]


def figure(assembly: Assembly, plan: Plan, drawn: Scene | None = None) -> go.Figure:
    """The 3D view in its assembled state: trace 0 holds every part (one colour per face,
    :func:`face_colors`), trace 1 the arrow of the shown step (hidden in the assembled
    state), traces 2 and 3 the axis triad and its labels. The page's script moves and
    recolours traces 0 and 1 per step."""
    drawn = scene(assembly, plan) if drawn is None else drawn
    vertices, faces = drawn.vertices, drawn.faces
    arrow_faces = np.asarray(drawn.arrows[0].faces) if drawn.arrows else np.zeros((0, 3), np.int32)
    parts = go.Mesh3d(
        x=vertices[:, 0],
        y=vertices[:, 1],
        z=vertices[:, 2],
        i=faces[:, 0],
        j=faces[:, 1],
        k=faces[:, 2],
        facecolor=face_colors(assembly, drawn),
        flatshading=True,
        name="parts",
        hoverinfo="text",
        lighting=LIGHTING,
        lightposition=LIGHT_POSITION,
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
    fig = go.Figure(data=[parts, arrow, *_triad_traces(assembly)])
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
        f"along {fmt.direction(step.direction, tol)} ({step.summary()}){away}."
    )


def _step_table(plan: Plan, tol: Tolerance | None) -> str:
    """The steps; under gravity also the parts held, those that would fall unheld and
    the friction needed, after a step 0 when the assembly as given does not stand."""
    headers = ["step", "move", "direction", "motion", "away from", "held in place"]
    if plan.gravity is not None:
        headers += ["held", "would fall unheld", "friction needed"]
    head = "".join(f"<th>{h}</th>" for h in headers)
    rows = []
    if plan.gravity is not None and not plan.gravity.whole.stands:
        start = ["0", "-", "-", "as given", "-", "-", *plan.gravity.cells()]
        rows.append("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in start) + "</tr>")
    for number, step in enumerate(plan.steps, start=1):
        cells = [
            str(number),
            _names_cell(step.parts),
            html.escape(fmt.direction(step.direction, tol)),
            html.escape(step.summary()),
            _names_cell(step.rest, folded=True),
            _names_cell(_held(step)),
        ]
        if step.stability is not None:
            cells += [html.escape(c) for c in step.stability.cells()]
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
        "colors": list(part_colors(assembly.names).values()),
        "dim": DIM_COLOR,
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
        # extended translations (docs/planning.md, "How a plan is found"), in words
        f"feasible in {fmt.count(len(plan.steps), 'step')}, each a straight move"
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
        f"{fmt.count(plan.directions, 'direction')} tried{html.escape(units)}.</p>",
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
    """Write the plan's self-contained HTML report (docs/planning.md, "The HTML report";
    :func:`report_html`): the assembly in 3D, the disassembly animated step by step, the
    steps, the assembly order and the interlocked sets.

    Parameters
    ----------
    assembly : Assembly
        The assembly planned.
    plan : Plan
        Its plan (:func:`assemblykit.plan`).
    path : str or Path
        The HTML file to write (UTF-8); its folder is made when missing.
    title : str, optional
        The page's title (the assembly's file name when ``None``).
    extra : sequence of ReportTable, default ()
        More sections (e.g. the motion of each part).
    plotlyjs : {"inline", "cdn"}, default "inline"
        Embed plotly.js (the page opens offline) or link it from its CDN (a small file
        that needs the network).

    Returns
    -------
    Path
        ``path``, written whole: a failed write leaves no partial file.

    Raises
    ------
    OSError
        The file cannot be written.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import trimesh
    >>> import assemblykit
    >>> lower = trimesh.creation.box(bounds=[[0, 0, 0], [1, 1, 1]])
    >>> upper = trimesh.creation.box(bounds=[[0, 0, 1], [1, 1, 2]])
    >>> parts = [assemblykit.Part("lower", lower), assemblykit.Part("upper", upper)]
    >>> boxes = assemblykit.Assembly(parts)
    >>> plan = assemblykit.plan(boxes)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "boxes.html"
    ...     page = assemblykit.write_report(boxes, plan, path, plotlyjs="cdn")
    ...     page.name, "<html" in page.read_text(encoding="utf-8")
    ('boxes.html', True)
    """
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    page = report_html(assembly, plan, title=title, extra=extra, plotlyjs=plotlyjs)
    with atomic_output(target) as temporary:
        temporary.write_text(page, encoding="utf-8")
    return target
