"""A task that solves itself (docs/tutorial.md §4; :mod:`assemblykit.api`)."""

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
    """Read and validate a task file (docs/tutorial.md §1, §2): bodies with their
    features, and situations with their relations and actions
    (:func:`assemblykit.io.tasks.load_task`).

    Parameters
    ----------
    path : str or Path
        The task file: ``.yaml``/``.yml`` or ``.json``, or ``.rapt`` text.

    Returns
    -------
    Task
        The validated task; ``solve()`` reduces its relational network to every body's
        poses (Corner, Ambler & Popplestone 1983, §III; docs/tutorial.md §3).

    Raises
    ------
    InputError
        The file is missing, unreadable or of another type; its text does not parse
        (``TaskSyntaxError``, with the line and column); or it names a body, feature or
        relation kind it does not define (with the line, or the field path in YAML).

    Examples
    --------
    >>> from pathlib import Path
    >>> import assemblykit
    >>> tasks = Path(assemblykit.__file__).parent / "examples" / "tasks"
    >>> task = assemblykit.load_task(tasks / "w4_pin.yaml")
    >>> task
    Task(2 bodies, 1 situation, mm, w4_pin.yaml)
    >>> task.solve()["pin@s1"]
    BodyInstanceResult(pin@s1, revolute, 1 dof)
    """
    loaded = task_files.load_task(path)
    return Task(**{f.name: getattr(loaded, f.name) for f in fields(loaded)})
