"""A task that solves itself (DESIGN.md §5.4; :mod:`assemblykit.api`)."""

from __future__ import annotations

from dataclasses import fields
from pathlib import Path

from assemblykit.inference import Solution, solve_task
from assemblykit.io import tasks as task_files
from assemblykit.model import task as task_model
from assemblykit.tolerance import Tolerance


class Task(task_model.Task):
    """A validated RAPT task (:class:`assemblykit.model.task.Task`) that solves itself."""

    def solve(
        self, tol: Tolerance | None = None, explain: bool = False, max_branches: int | None = None
    ) -> Solution:
        """Poses of every body in every situation by network reduction (Corner et al. 1983
        §III; :func:`assemblykit.inference.solve_task`); at most ``max_branches`` finite
        alternatives are followed (default ``inference.reduction.MAX_BRANCHES``;
        ``Solution.cut`` says when more were left)."""
        return solve_task(self, tol=tol, explain=explain, max_branches=max_branches)


def load_task(path: str | Path) -> Task:
    """Read and validate a task file: ``.yaml``/``.yml``, ``.json`` or ``.rapt``
    (:func:`assemblykit.io.tasks.load_task`)."""
    loaded = task_files.load_task(path)
    return Task(**{f.name: getattr(loaded, f.name) for f in fields(loaded)})
