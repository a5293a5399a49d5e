"""Files a disassembly plan is exported to (``plan --out``, ``plan --gltf``).

* ``.json``: the plan's documented JSON (DESIGN.md §5.3: ``steps``, ``order`` (the
  assembly order), ``stuck``, ...), numbers rounded by :func:`assemblykit.io.report.jsonable`.
* ``.csv``: the step table, one row per step: the moved parts, the direction in words and
  as components, the motion, how many parts they leave and which, the parts held in place,
  and the step's place in the assembly order (the plan reversed).
* ``.glb`` / ``.gltf``: the exploded view (:mod:`assemblykit.viz.explode`, after the last
  step) as a glTF scene written by trimesh: one node per part, named after it, each
  mesh stored once; the plan's JSON rides along in the scene's ``extras``.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import trimesh

from assemblykit import formatting as fmt
from assemblykit.io.report import json_number, jsonable
from assemblykit.outputs import atomic_output
from assemblykit.viz.explode import explosion

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly
    from assemblykit.planning.sequence import Plan, Step
    from assemblykit.tolerance import Tolerance

PLAN_SUFFIXES = (".json", ".csv")
"""What ``plan --out`` writes."""

GLTF_SUFFIXES = (".glb", ".gltf")
"""What ``plan --gltf`` writes."""

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
    >>> from assemblykit.planning.sequence import Plan, Step
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


def write_plan(plan: Plan, path: str | Path, tol: Tolerance | None = None) -> Path:
    """Write the plan as JSON or as the CSV step table, by ``path``'s suffix."""
    target = Path(path)
    with atomic_output(target) as temporary:
        if target.suffix.lower() == ".csv":
            with temporary.open("w", newline="", encoding="utf-8") as handle:
                writer = csv.DictWriter(handle, fieldnames=CSV_COLUMNS)
                writer.writeheader()
                writer.writerows(step_rows(plan, tol))
        else:
            text = json.dumps(jsonable(plan.to_dict(), tol), indent=2)
            temporary.write_text(text + "\n", encoding="utf-8")
    return target


def exploded_scene(assembly: Assembly, plan: Plan, tol: Tolerance | None = None) -> trimesh.Scene:
    """The exploded view after the last step as a trimesh scene: one node per part (named
    after it, translated by its offset), the plan's JSON in ``metadata``."""
    frames = explosion(assembly, plan)
    offsets = frames.offsets(frames.frames - 1)
    scene = trimesh.Scene()
    for part in assembly:
        transform = np.eye(4)
        transform[:3, 3] = offsets[part.name]
        scene.add_geometry(
            part.mesh.copy(), node_name=part.name, geom_name=part.name, transform=transform
        )
    scene.metadata["plan"] = jsonable(plan.to_dict(), tol)
    return scene


def write_gltf(
    assembly: Assembly, plan: Plan, path: str | Path, tol: Tolerance | None = None
) -> Path:
    """Write :func:`exploded_scene` as binary glTF (``.glb``) or as ``.gltf`` with its
    buffers embedded, by ``path``'s suffix."""
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
