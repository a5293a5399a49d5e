"""Motion analysis (seed 003): the motion group of every part and subassembly
(:mod:`~assemblykit.motion.freedom`), its push-only reading
(:mod:`~assemblykit.motion.unilateral`), separable subassemblies
(:mod:`~assemblykit.motion.separation`) and gear trains
(:mod:`~assemblykit.motion.articulation`).

``assemblykit.motion`` is both this package and the public function of DESIGN.md §5.4:
once the package is imported its module object is what ``assemblykit.motion`` names,
so the package itself is callable and forwards to :func:`assemblykit.motion.freedom.motion`.
"""

from __future__ import annotations

import sys
import types
from typing import Any


class _CallablePackage(types.ModuleType):
    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        from assemblykit.motion.freedom import motion

        return motion(*args, **kwargs)


sys.modules[__name__].__class__ = _CallablePackage
