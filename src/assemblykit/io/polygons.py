"""Files of planar assemblies (Wilson & Latombe 1992, "2D case"): ``parts: {name: [[x, y], ...]}``
in YAML, each part a simple polygon in assembled position, read into a
:class:`~assemblykit.model.polygons.PolygonAssembly`.

The text is read through :mod:`assemblykit.io.documents` (UTF-8, size and alias
limits); every polygon must be a list of at least three ``[x, y]`` points of finite
numbers (booleans and strings are not coordinates) forming a simple polygon of positive
area.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from assemblykit.errors import InputError, SchemaError
from assemblykit.geometry.polygons import counter_clockwise
from assemblykit.io.documents import MAX_COORDINATE, read_text, read_yaml
from assemblykit.model.polygons import PolygonAssembly


def _points(value: object) -> NDArray[np.float64]:
    """``value`` as an array of numbers, or an empty one when it is not a list of lists
    of numbers (booleans and strings are not coordinates)."""
    if not isinstance(value, list) or not all(
        isinstance(p, list)
        and all(isinstance(c, int | float) and not isinstance(c, bool) for c in p)
        for p in value
    ):
        return np.zeros(0)
    try:
        return np.asarray(value, dtype=np.float64)
    except (ValueError, OverflowError):  # ragged rows, an integer beyond a float
        return np.zeros(0)


def load_polygons(path: str | Path) -> PolygonAssembly:
    """Read ``parts: {name: [[x, y], ...]}`` from a YAML file."""
    path = Path(path)
    data = read_yaml(read_text(path, "polygon file"), str(path))
    if not isinstance(data, dict) or not isinstance(data.get("parts"), dict):
        raise SchemaError(
            "expected a mapping 'parts: {name: [[x, y], ...]}'", source=str(path), where="parts"
        )
    if not data["parts"]:
        raise SchemaError("expected at least one polygon", source=str(path), where="parts")
    polygons = {}
    for name, pts in data["parts"].items():
        arr = _points(pts)
        if arr.ndim != 2 or arr.shape[1] != 2 or len(arr) < 3 or not np.isfinite(arr).all():
            raise SchemaError(
                "a polygon is a list of at least three [x, y] points of finite numbers",
                source=str(path),
                where=f"parts.{name}",
            )
        if np.abs(arr).max() > MAX_COORDINATE:
            raise SchemaError(
                f"coordinates beyond {MAX_COORDINATE:g}",
                source=str(path),
                where=f"parts.{name}",
            )
        polygons[str(name)] = counter_clockwise(arr, str(name), str(path))
    return PolygonAssembly(polygons, str(path))


def is_polygon_file(path: str | Path) -> bool:
    """Whether ``path`` is a YAML file of polygons (``parts`` a mapping of point lists,
    where an assembly manifest has a list)."""
    path = Path(path)
    if path.suffix.lower() not in (".yaml", ".yml") or not path.is_file():
        return False
    try:
        data = read_yaml(read_text(path), str(path))
    except InputError:
        return False  # not readable as polygons: the assembly loaders name the fault
    return isinstance(data, dict) and isinstance(data.get("parts"), dict)
