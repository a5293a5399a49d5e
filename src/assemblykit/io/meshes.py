"""Assemblies from triangle meshes: mesh folders and YAML manifests (docs/geometry.md,
"Loaders and their conventions").

* A **mesh folder** holds one part per file (``*.obj, *.stl, *.ply, *.glb``), named
  after the file's stem. If the folder has a ``config.json`` with a per-part
  ``final_state`` ``[x, y, z, rx, ry, rz]`` (the ASAP / Assemble-Them-All convention),
  the part is placed by the 4x4 transform with that translation and rotation
  ``Rotation.from_euler('xyz', [rx, ry, rz])`` (radians), applied to the mesh as read:
  ``p_world = R @ p_file + t``.
* A **manifest** (YAML or JSON) lists ``parts: [{name, mesh, pose}]``; ``pose`` is a 4x4
  matrix or ``{translation: [...], rotation_xyz_deg: [...]}`` (same Euler convention, in
  degrees); mesh paths are relative to the manifest's folder; ``units`` is optional.

The assembly records the input's measured precision
(:mod:`assemblykit.geometry.precision`): the float precision of the coordinates as read,
and for ``final_state`` poses the displacement their rounding allows.

Rounded poses leave parts designed to touch sharing thin layers (ASAP's beam: 2.5e-6
to 4.3e-6 of a part's volume). With ``settle`` (the default) the loader moves them
apart by the least translations that close the layers
(:mod:`assemblykit.geometry.settling`), provided no part moves further than its pose's
rounding allows: the settled poses are then as true to the file as the written ones.
Otherwise the poses stay as written. Each part records its ``settled`` translation.

Every mesh is checked and repaired with trimesh (merged vertices, degenerate and
duplicate faces dropped, normals made consistent and outward, holes filled); solids that
meet along an edge or at a vertex only (voxel pieces) get their own vertices there, so
each is closed; a mesh that is empty, has non-finite vertices or stays open is rejected
with a :class:`GeometryError` naming the file.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import trimesh
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from assemblykit.errors import GeometryError, SchemaError
from assemblykit.geometry.booleans import manifold3d
from assemblykit.geometry.broad_phase import candidate_pairs
from assemblykit.geometry.interference import keep_solids, solid
from assemblykit.geometry.precision import combined, mesh_precision, pose_precision
from assemblykit.geometry.settling import settle as settle_parts
from assemblykit.geometry.solids import placed
from assemblykit.io.documents import MAX_COORDINATE, read_json, read_text, read_yaml
from assemblykit.model.assembly import Assembly, Part, Precision
from assemblykit.tolerance import Tolerance, current

MESH_SUFFIXES = (".obj", ".stl", ".ply", ".glb")
DEFAULT_UNITS = "mm"

MAX_MESH_COORDINATE = MAX_COORDINATE
"""Largest mesh coordinate accepted (:data:`~assemblykit.io.documents.MAX_COORDINATE`)."""


def read_mesh(path: str | Path, notes: list[str] | None = None) -> trimesh.Trimesh:
    """Read one mesh file (scenes are flattened into one mesh), repaired and checked
    (:func:`repaired`, which says in ``notes`` what it closed).

    Raises :class:`GeometryError` naming the file if it is missing, unreadable, empty,
    has non-finite vertices, or cannot be made watertight."""
    path = Path(path)
    source = str(path)
    if not path.is_file():
        raise GeometryError("mesh file not found", source=source)
    try:
        loaded = trimesh.load(path, force="mesh", process=False)
    except Exception as bad:  # trimesh raises many unrelated types on bad files
        raise GeometryError(f"cannot read mesh: {bad}", source=source) from None
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise GeometryError("no triangles in mesh", source=source)
    return repaired(loaded, source, notes)


def repaired(
    mesh: trimesh.Trimesh, source: str | None = None, notes: list[str] | None = None
) -> trimesh.Trimesh:
    """``mesh`` with trimesh's repairs applied, or :class:`GeometryError` naming ``source``.
    An open mesh is closed only where every hole is flat (its border in one plane, to
    the mesh tolerance: the missing faces were flat too) and trimesh's ``fill_holes``
    fills it, which ``notes`` is told with the number of edges that bordered holes;
    any other open mesh is refused."""
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    if not np.all(np.isfinite(vertices)):
        bad = int(np.count_nonzero(~np.all(np.isfinite(vertices), axis=1)))
        raise GeometryError(f"{bad} vertices are NaN or infinite", source=source)
    if np.any(np.abs(vertices) > MAX_MESH_COORDINATE):
        raise GeometryError(f"coordinates beyond {MAX_MESH_COORDINATE:g}", source=source)
    faces = np.asarray(mesh.faces)
    if vertices.ndim != 2 or vertices.shape[1] != 3 or faces.ndim != 2 or faces.shape[1] != 3:
        raise GeometryError("faces must be triangles of 3D vertices", source=source)
    if faces.size and (faces.min() < 0 or faces.max() >= len(vertices)):
        raise GeometryError("a face refers to a vertex that does not exist", source=source)
    fixed = trimesh.Trimesh(vertices=vertices, faces=mesh.faces, process=True)
    fixed.update_faces(fixed.nondegenerate_faces())
    fixed.update_faces(fixed.unique_faces())
    fixed.remove_unreferenced_vertices()
    if len(fixed.faces) == 0:
        raise GeometryError("all triangles are degenerate", source=source)
    if not fixed.is_watertight:
        fixed = _split_at_shared_edges(fixed)
    if not fixed.is_watertight:
        edges = fixed.edges_sorted[trimesh.grouping.group_rows(fixed.edges_sorted, require_count=1)]
        border = len(edges)
        if not _flat_holes(fixed, edges):
            raise GeometryError(
                f"mesh is not closed (watertight): {border} edges border holes that are "
                "not flat, which no exact repair closes",
                source=source,
            )
        trimesh.repair.fill_holes(fixed)
        if not fixed.is_watertight:
            raise GeometryError(
                f"mesh is not closed (watertight): {border} edges border holes that "
                "trimesh's fill_holes cannot close",
                source=source,
            )
        if notes is not None:
            notes.append(
                f"{source}: the mesh was open ({border} edges bordered holes); "
                "its holes were filled (trimesh fill_holes)"
            )
    with np.errstate(invalid="ignore", divide="ignore"):  # trimesh divides by the volume
        trimesh.repair.fix_normals(fixed)
        volume = float(fixed.volume)
    # a closed but flat surface (coplanar vertices) encloses nothing: contacts, blocking
    # and interference all divide by or compare volumes (measured once the normals
    # agree, so that no two pieces cancel)
    scale = float(np.linalg.norm(fixed.extents))
    if abs(volume) <= current().mesh_rel_length * scale**3:
        raise GeometryError("mesh encloses no volume (flat)", source=source)
    return fixed


def _flat_holes(mesh: trimesh.Trimesh, edges: NDArray[np.int64]) -> bool:
    """Whether each hole of ``mesh``, bordered by the connected ``edges`` (met by one face
    each), lies in one plane within the mesh tolerance of its size."""
    scale = float(np.linalg.norm(mesh.extents))
    for loop in trimesh.graph.connected_components(edges):
        points = np.asarray(mesh.vertices)[np.asarray(loop, dtype=np.int64)]
        if len(points) > 3:
            spread = np.linalg.svd(points - points.mean(axis=0), compute_uv=False)[-1]
            if spread > current().mesh_rel_length * scale * np.sqrt(len(points)):
                return False
    return True


def _split_at_shared_edges(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    """``mesh`` with its vertices duplicated where closed solids meet along an edge or at
    a vertex only (voxel pieces whose cubes touch along an edge: four faces on one edge),
    when that makes every solid watertight; else ``mesh`` unchanged.

    Faces are grouped across the edges that exactly two faces share; each group becomes
    a body with vertices of its own, so an edge where two solids meet counts once per
    solid. The union of solids touching along a line is still one solid (its volume is
    the sum), so the part keeps its mesh as one."""
    edges = mesh.edges_sorted
    _, inverse, counts = np.unique(edges, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.ravel()
    if not np.any(counts > 2):
        return mesh  # an open mesh, not solids meeting along an edge: nothing to split
    manifold = counts[inverse] == 2
    # faces sharing a manifold edge are neighbours (edges_face gives each edge's face)
    order = np.argsort(inverse, kind="stable")
    faces_of = mesh.edges_face[order]
    groups = inverse[order]
    keep = manifold[order]
    pairs = [
        (int(faces_of[k]), int(faces_of[k + 1]))
        for k in range(len(order) - 1)
        if keep[k] and groups[k] == groups[k + 1]
    ]
    labels = trimesh.graph.connected_component_labels(pairs, node_count=len(mesh.faces))
    bodies: list[trimesh.Trimesh] = []
    for label in np.unique(labels):
        body = mesh.submesh([np.flatnonzero(labels == label)], append=True, only_watertight=False)
        assert isinstance(body, trimesh.Trimesh)  # append=True joins the faces in one mesh
        bodies.append(body)
    if not all(body.is_watertight for body in bodies):
        return mesh
    vertices = np.vstack([body.vertices for body in bodies])
    offsets = np.cumsum([0] + [len(body.vertices) for body in bodies[:-1]])
    faces = np.vstack([body.faces + offset for body, offset in zip(bodies, offsets, strict=True)])
    # no processing: merging the duplicated vertices would join the solids again
    return trimesh.Trimesh(vertices=vertices, faces=faces, process=False)


def pose_from_state(state: Sequence[float]) -> NDArray[np.float64]:
    """The 4x4 pose of an ASAP ``[x, y, z, rx, ry, rz]`` state (translation, then
    ``Rotation.from_euler('xyz', ...)`` in radians): ``p_world = R @ p + t``."""
    pose = np.eye(4)
    pose[:3, :3] = Rotation.from_euler("xyz", np.asarray(state[3:6], dtype=np.float64)).as_matrix()
    pose[:3, 3] = np.asarray(state[:3], dtype=np.float64)
    return pose


def _file_units(meshes: Sequence[trimesh.Trimesh]) -> str | None:
    """The unit the files declare (glTF is metres; OBJ/STL/PLY usually say nothing)."""
    units = {m.units for m in meshes}
    if len(units) == 1 and None not in units:
        return str(units.pop())
    return None


def _assembly(
    parts: list[Part],
    units: str | None,
    declared: bool,
    source: str,
    tol: Tolerance | None,
    precision: Precision | None,
    warnings: Sequence[str] = (),
) -> Assembly:
    file_units = _file_units([p.mesh for p in parts])
    if units is not None:
        unit, how = units, "declared" if declared else "file"
    elif file_units is not None:
        unit, how = file_units, "file"
    else:
        unit, how = DEFAULT_UNITS, "default"
    return Assembly(
        parts,
        units=unit,
        units_source=how,
        source=source,
        policy=tol,
        precision=precision,
        warnings=warnings,
    )


def load_mesh_folder(
    folder: str | Path, tol: Tolerance | None = None, settle: bool = True
) -> Assembly:
    """An assembly of the mesh files in ``folder`` (sorted by name), placed by the
    ``final_state`` poses of ``config.json`` when present, settled if ``settle``
    (module docstring)."""
    folder = Path(folder)
    try:
        files = sorted(f for f in folder.iterdir() if f.suffix.lower() in MESH_SUFFIXES)
    except OSError as error:
        reason = error.strerror or type(error).__name__
        raise GeometryError(f"cannot list the folder: {reason}", source=str(folder)) from None
    if not files:
        raise GeometryError(
            f"no mesh files ({', '.join(MESH_SUFFIXES)}) in folder", source=str(folder)
        )
    states = _final_states(folder / "config.json")
    notes: list[str] = []
    parts: list[Part] = []
    measured: list[Precision] = []
    reach: list[float] = []
    for file in files:
        state = states.get(file.stem)
        pose = np.eye(4) if state is None else pose_from_state(state)
        mesh = read_mesh(file, notes)
        measured.append(mesh_precision(mesh))
        rounding = None
        if state is not None:
            radius = float(np.linalg.norm(mesh.vertices, axis=1).max())
            rounding = pose_precision(list(states.values()), radius)
        if rounding is not None:
            measured.append(rounding)
        reach.append(0.0 if rounding is None else rounding.length)
        parts.append(Part(file.stem, placed(mesh, pose), pose, source=str(file)))
    solids: dict[str, manifold3d.Manifold] = {}
    if settle and any(reach):
        parts, solids = _settled(parts, reach)
    assembly = _assembly(parts, None, False, str(folder), tol, combined(measured), notes)
    keep_solids(assembly, solids)
    return assembly


def _settled(
    parts: list[Part], reach: Sequence[float]
) -> tuple[list[Part], dict[str, manifold3d.Manifold]]:
    """``parts`` moved apart by the least translations that close the layers they share
    (:func:`assemblykit.geometry.settling.settle`) when each stays within its ``reach``
    (what its pose's rounding allows); else ``parts`` as they are. With them, by name,
    the solids made to settle them, moved as they were (what blocking and interference
    ask of them next)."""
    pairs = [
        (int(i), int(j)) for i, j in candidate_pairs(np.array([p.mesh.bounds for p in parts]), 0.0)
    ]
    if not pairs:
        return parts, {}
    made = [solid(p.mesh, p.name) for p in parts]
    result = settle_parts([p.mesh for p in parts], pairs, made)
    lengths = np.linalg.norm(result.shifts, axis=1)
    if not lengths.any() or np.any(lengths > np.asarray(reach)):
        return parts, {p.name: body for p, body in zip(parts, made, strict=True)}
    settled = []
    solids = {}
    for part, shift, body in zip(parts, result.shifts, made, strict=True):
        pose = part.pose.copy()
        pose[:3, 3] += shift
        mesh = part.mesh.copy()
        mesh.apply_translation(shift)
        x, y, z = shift.tolist()
        settled.append(Part(part.name, mesh, pose, part.surfaces, part.source, (x, y, z)))
        solids[part.name] = body.translate((x, y, z))
    return settled, solids


def _final_states(config: Path) -> dict[str, list[float]]:
    if not config.is_file():
        return {}
    source = str(config)
    data = read_json(read_text(config, "config.json"), source)
    if not isinstance(data, dict):
        raise SchemaError("expected an object keyed by part name", source=source)
    states = {}
    for name, entry in data.items():
        if not isinstance(entry, dict) or "final_state" not in entry:
            continue
        state = entry["final_state"]
        if not (isinstance(state, list) and len(state) == 6 and _numbers(state)):
            raise SchemaError(
                "final_state must be 6 finite numbers [x, y, z, rx, ry, rz] of size at most "
                f"{MAX_MESH_COORDINATE:g}",
                source=source,
                where=f"{name}.final_state",
            )
        states[str(name)] = [float(v) for v in state]
    return states


def _numbers(values: Sequence[Any]) -> bool:
    """Whether every value is a finite number of magnitude at most ``MAX_MESH_COORDINATE``
    (NaN or infinity would place a part nowhere; a larger translation would move its mesh
    beyond the coordinates a mesh may have)."""
    return all(
        isinstance(v, int | float)
        and not isinstance(v, bool)
        and math.isfinite(v)
        and abs(v) <= MAX_MESH_COORDINATE
        for v in values
    )


def pose_from_spec(
    spec: Any, *, source: str | None = None, where: str = "pose", tol: Tolerance
) -> NDArray[np.float64]:
    """The 4x4 pose of a manifest ``pose``: a 4x4 matrix (rigid, last row ``0 0 0 1``,
    checked with the mesh angle tolerance) or ``{translation, rotation_xyz_deg}``."""
    if spec is None:
        return np.eye(4)
    if isinstance(spec, Mapping):
        unknown = set(spec) - {"translation", "rotation_xyz_deg"}
        if unknown:
            raise SchemaError(f"unknown pose keys {sorted(unknown)}", source=source, where=where)
        pose = np.eye(4)
        for key in ("translation", "rotation_xyz_deg"):
            value = spec.get(key, [0.0, 0.0, 0.0])
            if not (isinstance(value, list) and len(value) == 3 and _numbers(value)):
                raise SchemaError(
                    f"expected 3 finite numbers of size at most {MAX_MESH_COORDINATE:g}",
                    source=source,
                    where=f"{where}.{key}",
                )
        rotation = Rotation.from_euler("xyz", spec.get("rotation_xyz_deg", [0, 0, 0]), degrees=True)
        pose[:3, :3] = rotation.as_matrix()
        pose[:3, 3] = spec.get("translation", [0.0, 0.0, 0.0])
        return pose
    rows = spec if isinstance(spec, list) else None
    if not (rows and len(rows) == 4 and all(isinstance(r, list) and len(r) == 4 for r in rows)):
        raise SchemaError(
            "expected a 4x4 matrix or {translation, rotation_xyz_deg}", source=source, where=where
        )
    if not all(_numbers(r) for r in rows):
        raise SchemaError(
            f"matrix entries must be finite numbers of size at most {MAX_MESH_COORDINATE:g}",
            source=source,
            where=where,
        )
    pose = np.array(rows, dtype=np.float64)
    rotation = pose[:3, :3]
    rigid = np.allclose(rotation.T @ rotation, np.eye(3), atol=tol.mesh_angle, rtol=0)
    if not (rigid and np.linalg.det(rotation) > 0 and np.allclose(pose[3], [0, 0, 0, 1])):
        raise SchemaError("matrix is not a rigid transform", source=source, where=where)
    return pose


def load_manifest(path: str | Path, tol: Tolerance | None = None) -> Assembly:
    """An assembly from a YAML/JSON manifest ``{units?, parts: [{name, mesh, pose?}]}``."""
    path = Path(path)
    source = str(path)
    data = read_yaml(read_text(path, "manifest"), source)
    if not isinstance(data, dict) or not isinstance(data.get("parts"), list) or not data["parts"]:
        raise SchemaError("expected a non-empty list", source=source, where="parts")
    units = data.get("units")
    if units is not None and not isinstance(units, str):
        raise SchemaError("expected a unit name such as mm", source=source, where="units")
    parts: list[Part] = []
    measured: list[Precision] = []
    notes: list[str] = []
    for i, entry in enumerate(data["parts"]):
        where = f"parts[{i}]"
        if not isinstance(entry, dict) or not isinstance(entry.get("mesh"), str):
            raise SchemaError("expected {name, mesh, pose}", source=source, where=where)
        name = entry.get("name", Path(entry["mesh"]).stem)
        if isinstance(name, bool) or not isinstance(name, str | int) or not str(name).strip():
            raise SchemaError(
                f"a part name must be a non-empty text or a number, got {name!r}",
                source=source,
                where=f"{where}.name",
            )
        name = str(name)
        if any(p.name == name for p in parts):
            raise SchemaError(f"duplicate part name {name!r}", source=source, where=where)
        pose = pose_from_spec(
            entry.get("pose"), source=source, where=f"{where}.pose", tol=tol or current()
        )
        mesh_path = path.parent / entry["mesh"]
        mesh = read_mesh(mesh_path, notes)
        measured.append(mesh_precision(mesh))
        parts.append(Part(name, placed(mesh, pose), pose, source=str(mesh_path)))
    return _assembly(parts, units, units is not None, source, tol, combined(measured), notes)
