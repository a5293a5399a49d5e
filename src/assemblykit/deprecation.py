"""Public names that moved: the old name keeps working, with a :class:`DeprecationWarning`
naming the new home (docs/architecture.md, "Deprecated names")."""

from __future__ import annotations

import functools
import importlib
import warnings
from collections.abc import Callable, Mapping
from typing import Any


def moved(module: str, homes: Mapping[str, str]) -> Callable[[str], Any]:
    """A module-level ``__getattr__`` for ``module``: a name of ``homes`` is looked up in
    the module it moved to, imported when asked for (a higher layer, which ``module`` may
    not import), after a :class:`DeprecationWarning`; any other name is missing. A home
    written ``"package.module:new_name"`` is a name that moved and was renamed; a dotted
    ``new_name`` (``"Class.method"``) is an attribute of a name there: a function that
    became a method is the method of its first argument's class."""

    def __getattr__(name: str) -> Any:
        home = homes.get(name)
        if home is None:
            raise AttributeError(f"module {module!r} has no attribute {name!r}")
        place, _, renamed = home.partition(":")
        new = renamed or name
        warnings.warn(
            f"{module}.{name} is deprecated; use {place}.{new}", DeprecationWarning, stacklevel=2
        )
        return functools.reduce(getattr, new.split("."), importlib.import_module(place))

    return __getattr__
