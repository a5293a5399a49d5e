"""Assemblies from COMPAS JSON (docs/geometry.md, "Loaders and their conventions"):
``compas_assembly`` assemblies and plain lists of block meshes.

Accepted layouts (those of the files published with ``compas_assembly``):

* an assembly: ``data.graph.data.node[id].block.data`` (COMPAS 2) or
  ``value.data.node[id].block.value.data`` (COMPAS 1) holds each block's mesh;
* a list of meshes: ``[{dtype: compas.datastructures/Mesh, value|data: ...}, ...]``.

A mesh is a ``vertex`` dict ``{key: {x, y, z}}`` and a ``face`` dict
``{key: [vertex keys]}`` of planar convex polygons (masonry blocks), triangulated as fans.
Parts are named by node key (assemblies) or list index (lists). COMPAS stores no unit.

The blocks' joints need not match exactly; the assembly records their largest mismatch
as its measured precision (:func:`assemblykit.geometry.precision.joint_mismatch`).
The blocks a node declares ``is_support`` are the assembly's supports, the ground it
stands on; where none is declared, the blocks resting on its lowest plane are
(:attr:`~assemblykit.model.assembly.Assembly.supports`, docs/planning.md, "The ground").
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import trimesh

from assemblykit.errors import GeometryError, SchemaError
from assemblykit.geometry.precision import joint_mismatch
from assemblykit.io.documents import read_json, read_text
from assemblykit.io.meshes import DEFAULT_UNITS, repaired
from assemblykit.model.assembly import Assembly, Part, lowest_parts
from assemblykit.tolerance import Tolerance

DOWN = (0.0, 0.0, -1.0)
"""Down for masonry blocks (+Z up, compas_assembly's convention): the ground a block
assembly stands on, when it declares no support, is its lowest plane across it."""

DTYPES = frozenset(
    {
        "compas_assembly.datastructures/Assembly",
        "compas.datastructures/Graph",
        "compas_assembly.datastructures/Block",
        "compas.datastructures/Mesh",
    }
)
"""The COMPAS types whose payload holds blocks; any other ``dtype`` on the way to a mesh is
a misspelling or another kind of document, refused rather than read as geometry."""


def _payload(obj: Any, source: str | None = None, where: str | None = None) -> Any:
    """Unwrap COMPAS' ``{dtype, data}`` (COMPAS 2) or ``{dtype, value}`` (COMPAS 1);
    :class:`SchemaError` for a ``dtype`` not in :data:`DTYPES`."""
    while isinstance(obj, Mapping) and "dtype" in obj and ("data" in obj or "value" in obj):
        if not isinstance(obj["dtype"], str) or obj["dtype"] not in DTYPES:
            raise SchemaError(
                f"unknown COMPAS type {obj['dtype']!r} "
                f"(expected one of {', '.join(sorted(DTYPES))})",
                source=source,
                where=where,
            )
        obj = obj["data"] if "data" in obj else obj["value"]
    if isinstance(obj, Mapping) and "vertex" not in obj and "node" not in obj and "data" in obj:
        return _payload(obj["data"], source, where)
    return obj


def _coordinate(vertex: Any, axis: str) -> float:
    """The ``axis`` coordinate of a COMPAS vertex; a ``TypeError`` when it is not a number
    (``true`` or ``"1"`` are not coordinates; ``float`` would accept both)."""
    value = vertex[axis]
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise TypeError(f"coordinate {axis} is {value!r}, not a number")
    return float(value)


def mesh_from_compas(
    data: Any, source: str, where: str, notes: list[str] | None = None
) -> trimesh.Trimesh:
    """The triangle mesh of a COMPAS mesh payload (``vertex`` and ``face`` dicts),
    repaired (:func:`~assemblykit.io.meshes.repaired`, which says in ``notes`` what it
    closed)."""
    vertices = data.get("vertex") if isinstance(data, Mapping) else None
    faces = data.get("face") if isinstance(data, Mapping) else None
    if not isinstance(vertices, Mapping) or not isinstance(faces, Mapping) or not faces:
        raise SchemaError(
            "a block mesh needs 'vertex' and 'face' dicts", source=source, where=where
        )
    keys = {str(k): i for i, k in enumerate(vertices)}
    try:
        xyz = np.array(
            [[_coordinate(v, axis) for axis in "xyz"] for v in vertices.values()],
            dtype=np.float64,
        )
        triangles = [
            (keys[str(f[0])], keys[str(f[i])], keys[str(f[i + 1])])
            for f in faces.values()
            for i in range(1, len(f) - 1)
        ]
    except (KeyError, TypeError, ValueError) as bad:
        raise SchemaError(f"malformed vertex or face: {bad}", source=source, where=where) from None
    if not triangles:
        raise SchemaError("no face has three vertices", source=source, where=where)
    mesh = trimesh.Trimesh(vertices=xyz, faces=np.array(triangles, dtype=np.int64), process=False)
    return repaired(mesh, f"{source}: {where}", notes)


def _blocks(data: Any, source: str) -> list[tuple[str, Any, str, bool]]:
    """``(name, mesh payload, field path, is_support)`` for every block in a COMPAS
    document (a list of meshes declares no support)."""
    if isinstance(data, list):
        return [
            (str(i), _payload(item, source, f"[{i}]"), f"[{i}]", False)
            for i, item in enumerate(data)
        ]
    body = _payload(data, source)
    graph = (
        _payload(body.get("graph"), source, "graph")
        if isinstance(body, Mapping) and "graph" in body
        else body
    )
    nodes = graph.get("node") if isinstance(graph, Mapping) else None
    if not isinstance(nodes, Mapping):
        raise SchemaError("neither a COMPAS assembly nor a list of meshes", source=source)
    blocks = []
    for key, node in nodes.items():
        block = node.get("block") if isinstance(node, Mapping) else None
        if block is None:
            raise SchemaError("node has no block", source=source, where=f"node.{key}")
        where = f"node.{key}.block"
        support = node.get("is_support")
        if support is not None and not isinstance(support, bool):
            raise SchemaError(
                f"is_support is {support!r}, not true or false", source=source, where=f"node.{key}"
            )
        blocks.append((str(key), _payload(block, source, where), where, bool(support)))
    return blocks


def load_compas(path: str | Path, tol: Tolerance | None = None) -> Assembly:
    """An assembly of the blocks of a COMPAS JSON file (module docstring)."""
    path = Path(path)
    source = str(path)
    data = read_json(read_text(path, "COMPAS file"), source)
    notes: list[str] = []
    blocks = _blocks(data, source)
    parts = [
        Part(name, mesh_from_compas(mesh, source, where, notes), source=source)
        for name, mesh, where, _ in blocks
    ]
    if not parts:
        raise GeometryError("no blocks", source=source)
    assembly = Assembly(
        parts,
        units=DEFAULT_UNITS,
        units_source="default",
        source=source,
        policy=tol,
        warnings=notes,
    )
    assembly.precision = joint_mismatch(assembly, tol)
    declared = [name for name, *_, support in blocks if support]
    assembly.supports = tuple(declared) or lowest_parts(assembly, DOWN, assembly.tolerance())
    return assembly
