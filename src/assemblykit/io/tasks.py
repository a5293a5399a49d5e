"""Task files by their suffix (docs/tutorial.md §1): ``.yaml``/``.yml`` and ``.json`` read by
:mod:`assemblykit.io.spec`, ``.rapt`` text by :mod:`assemblykit.io.rapt`; both give the
same validated :class:`~assemblykit.model.task.Task`.
"""

from __future__ import annotations

from pathlib import Path

from assemblykit.collector import collector_paused
from assemblykit.errors import InputError
from assemblykit.io.documents import read_json, read_text, read_yaml
from assemblykit.io.rapt import parse_rapt
from assemblykit.io.spec import parse_task
from assemblykit.model.task import Task


def load_task(path: str | Path) -> Task:
    """Read and validate a task file: ``.yaml``/``.yml``, ``.json`` or ``.rapt`` (with the
    garbage collector paused, :func:`~assemblykit.collector.collector_paused`: a file of
    a thousand bodies makes tens of thousands of objects that all stay alive)."""
    path = Path(path)
    source = path.name
    text = read_text(path, "task file")
    with collector_paused():
        return _parsed(text, path, source)


def _parsed(text: str, path: Path, source: str) -> Task:
    """The task of a task file's ``text``, read by the parser of its suffix."""
    suffix = path.suffix.lower()
    if suffix == ".rapt":
        return parse_rapt(text, source)
    if suffix in (".yaml", ".yml"):
        return parse_task(read_yaml(text, source), source)
    if suffix == ".json":
        return parse_task(read_json(text, source), source)
    raise InputError(
        f"unknown task file type {path.suffix!r} (expected .yaml, .yml, .json or .rapt)",
        source=source,
    )
