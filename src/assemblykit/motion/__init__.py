"""Motion analysis (Liu 1997): the motion group of every part and subassembly
(:mod:`~assemblykit.motion.freedom`), its push-only reading
(:mod:`~assemblykit.motion.unilateral`), separable subassemblies
(:mod:`~assemblykit.motion.separation`), gear trains
(:mod:`~assemblykit.motion.articulation`) and the motion of a task's bodies from its
relations (:mod:`~assemblykit.motion.relational`).

``assemblykit.motion`` is both this package and the public function of docs/tutorial.md §4:
once the package is imported its module object is what ``assemblykit.motion`` names,
so the package itself is callable: on a :class:`~assemblykit.model.task.Task` it forwards
to :func:`assemblykit.motion.relational.task_motion`, on an assembly to
:func:`assemblykit.motion.freedom.motion`.
"""

from __future__ import annotations

import sys
import types
from typing import Any


class _CallablePackage(types.ModuleType):
    def __call__(self, source: Any, *args: Any, **kwargs: Any) -> Any:
        from assemblykit.model.task import Task

        if isinstance(source, Task):
            from assemblykit.motion.relational import task_motion

            return task_motion(source, *args, **kwargs)
        from assemblykit.motion.freedom import motion

        return motion(source, *args, **kwargs)


sys.modules[__name__].__class__ = _CallablePackage
