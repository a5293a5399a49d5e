"""Files a disassembly plan is exported to (``plan --out``, ``plan --gltf``).

* ``.json``: the plan's documented JSON (docs/planning.md, "JSON": ``steps``, ``order`` (the
  assembly order), ``stuck``, ...), numbers rounded by :func:`assemblykit.io.report.jsonable`.
* ``.csv``: the step table, one row per step: the moved parts, the direction in words and
  as components, the motion, how many parts they leave and which, the parts held in place,
  and the step's place in the assembly order (the plan reversed).
* ``.glb`` / ``.gltf``: the exploded view (:mod:`assemblykit.viz.explode`, after the last
  step) as a glTF scene written by trimesh: one node per part, named after it, each
  mesh stored once with a PBR material of the part's colour in the report
  (:func:`assemblykit.viz.viewer.part_colors`); the plan's JSON rides along in the
  scene's ``extras``, each step's direction also in words (``direction_label``).
"""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np
import trimesh
from trimesh.visual import TextureVisuals
from trimesh.visual.material import PBRMaterial

from assemblykit import formatting as fmt
from assemblykit.io.report import json_number, jsonable
from assemblykit.outputs import atomic_output
from assemblykit.viz.explode import explosion

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly
    from assemblykit.planning.plan_values import Plan, Step
    from assemblykit.tolerance import Tolerance

PLAN_SUFFIXES = (".json", ".csv")
"""What ``plan --out`` writes."""

GLTF_SUFFIXES = (".glb", ".gltf")
"""What ``plan --gltf`` writes."""

MATERIAL_ROUGHNESS = 0.8
"""The parts' glTF materials are matte, like the report's lighting."""

CSV_COLUMNS = (
    "step",
    "parts",
    "direction",
    "dx",
    "dy",
    "dz",
    "motion",
    "away_from_count",
    "away_from",
    "held_in_place",
    "assembly_order",
)
"""Columns of the CSV step table; lists of names are joined with ``;``."""


def held_in_place(step: Step) -> list[str]:
    """The parts the moved ones block along the step's direction (arcs into them)."""
    moved = set(step.parts)
    return sorted({i for i, j in step.blocking if j in moved and i not in moved})


def step_rows(plan: Plan, tol: Tolerance | None = None) -> list[dict[str, Any]]:
    """One dictionary per step with the :data:`CSV_COLUMNS` as keys.

    >>> import numpy as np
    >>> from assemblykit.planning.plan_values import Plan, Step
    >>> step = Step(("lid",), np.array([0.0, 0.0, 1.0]), ("base",), (("base", "lid"),))
    >>> row = step_rows(Plan(("base", "lid"), (step,), (), None, 1))[0]
    >>> row["parts"], row["direction"], row["held_in_place"], row["assembly_order"]
    ('lid', '+Z', 'base', 1)
    """
    total = len(plan.steps)
    rows = []
    for number, step in enumerate(plan.steps, start=1):
        d = np.r_[np.asarray(step.direction, dtype=np.float64), np.zeros(3)][:3]
        rows.append(
            {
                "step": number,
                "parts": ";".join(step.parts),
                "direction": fmt.direction(step.direction, tol),
                **{
                    axis: json_number(x, tol) for axis, x in zip(("dx", "dy", "dz"), d, strict=True)
                },
                "motion": step.motion,
                "away_from_count": len(step.rest),
                "away_from": ";".join(step.rest),
                "held_in_place": ";".join(held_in_place(step)),
                "assembly_order": total - number + 1,
            }
        )
    return rows


def plan_json(plan: Plan, tol: Tolerance | None = None) -> dict[str, Any]:
    """The plan's JSON (numbers rounded by :func:`jsonable`) with each step's and each
    assembly step's direction also in words, ``direction_label`` (``+Z`` or components:
    :func:`assemblykit.formatting.direction`) beside the exact ``direction``."""
    data = plan.to_dict()
    words = {
        "steps": [fmt.direction(step.direction, tol) for step in plan.steps],
        "assembly_steps": [fmt.direction(step.direction, tol) for step in plan.assembly_steps],
    }
    for key, labels in words.items():
        data[key] = [
            {**row, "direction_label": label} for row, label in zip(data[key], labels, strict=True)
        ]
    return cast(dict[str, Any], jsonable(data, tol))


def write_plan(plan: Plan, path: str | Path, tol: Tolerance | None = None) -> Path:
    """Write the plan's step table as CSV, or the plan as JSON (:func:`plan_json`), by
    ``path``'s suffix (docs/planning.md, "Reports, pictures and exports").

    Parameters
    ----------
    plan : Plan
        The plan (:func:`assemblykit.plan`).
    path : str or Path
        ``.csv`` for the step table (step, moved parts, direction as ``+Z`` or
        components, motion, the parts it leaves, the parts held in place, its place in
        the assembly order); any other suffix for JSON (``.json``).
    tol : Tolerance, optional
        Numbers are rounded by it (:func:`assemblykit.io.report.jsonable`; the current
        policy when ``None``).

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
    >>> import assemblykit
    >>> examples = Path(assemblykit.__file__).parent / "examples"
    >>> plan = assemblykit.plan(assemblykit.load_assembly(examples / "planar" / "hook.yaml"))
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     table = assemblykit.write_plan(plan, Path(folder) / "plan.csv")
    ...     print(table.read_text(encoding="utf-8").splitlines()[0])
    step,parts,direction,dx,dy,dz,motion,away_from_count,away_from,held_in_place,assembly_order
    """
    target = Path(path)
    with atomic_output(target) as temporary:
        if target.suffix.lower() == ".csv":
            with temporary.open("w", newline="", encoding="utf-8") as handle:
                writer = csv.DictWriter(handle, fieldnames=CSV_COLUMNS)
                writer.writeheader()
                writer.writerows(step_rows(plan, tol))
        else:
            text = json.dumps(plan_json(plan, tol), indent=2)
            temporary.write_text(text + "\n", encoding="utf-8")
    return target


def rgba(color: str) -> list[int]:
    """A ``#rrggbb`` colour as its 0-255 red, green, blue and (opaque) alpha.

    >>> rgba("#EF553B")
    [239, 85, 59, 255]
    """
    return [int(color[i : i + 2], 16) for i in (1, 3, 5)] + [255]


def part_material(name: str, color: str) -> PBRMaterial:
    """A glTF PBR material named ``name`` whose base colour is ``color`` (``#rrggbb``,
    opaque, not metallic)."""
    return PBRMaterial(
        name=name,
        baseColorFactor=rgba(color),
        metallicFactor=0.0,
        roughnessFactor=MATERIAL_ROUGHNESS,
    )


def exploded_scene(assembly: Assembly, plan: Plan, tol: Tolerance | None = None) -> trimesh.Scene:
    """The exploded view after the last step as a trimesh scene: one node per part (named
    after it, translated by its offset, its material the part's colour in the report),
    the plan's JSON (:func:`plan_json`) in ``metadata``."""
    from assemblykit.viz.viewer import part_colors

    frames = explosion(assembly, plan)
    offsets = frames.offsets(frames.frames - 1)
    colors = part_colors(assembly.names)
    scene = trimesh.Scene()
    for part in assembly:
        transform = np.eye(4)
        transform[:3, 3] = offsets[part.name]
        mesh = part.mesh.copy()
        mesh.visual = TextureVisuals(material=part_material(part.name, colors[part.name]))
        scene.add_geometry(mesh, node_name=part.name, geom_name=part.name, transform=transform)
    scene.metadata["plan"] = plan_json(plan, tol)
    return scene


def write_gltf(
    assembly: Assembly, plan: Plan, path: str | Path, tol: Tolerance | None = None
) -> Path:
    """Write the exploded view after the plan's last step (:func:`exploded_scene`: one node
    per part, named after it, the plan's JSON in the scene's extras) as binary glTF
    (``.glb``) or as ``.gltf`` with its buffers embedded, by ``path``'s suffix
    (docs/planning.md, "Reports, pictures and exports").

    Parameters
    ----------
    assembly : Assembly
        The assembly planned.
    plan : Plan
        Its plan (:func:`assemblykit.plan`).
    path : str or Path
        The ``.glb`` or ``.gltf`` file to write.
    tol : Tolerance, optional
        The plan's JSON numbers are rounded by it (the current policy when ``None``).

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
    ...     scene = assemblykit.write_gltf(boxes, plan, Path(folder) / "boxes.glb")
    ...     scene.read_bytes()[:4]
    b'glTF'
    """
    target = Path(path)
    scene = exploded_scene(assembly, plan, tol)
    kind = "glb" if target.suffix.lower() == ".glb" else "gltf"
    with atomic_output(target) as temporary:
        if kind == "glb":
            temporary.write_bytes(scene.export(file_type="glb"))
        else:
            text = trimesh.exchange.gltf.export_gltf(scene, embed_buffers=True)["model.gltf"]
            temporary.write_bytes(text)
    return target
