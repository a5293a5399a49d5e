"""A rigid body of a task: a name, its named features in body coordinates, fixed or not."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from assemblykit.errors import SchemaError, UnknownNameError
from assemblykit.features import Feature, feature_from_dict


@dataclass(frozen=True, eq=False)
class Body:
    """A rigid body (DESIGN §5.1 ``bodies``): ``features`` by name, in body coordinates;
    a ``fixed`` body is the world (its pose is the identity)."""

    name: str
    features: Mapping[str, Feature] = field(default_factory=dict)
    fixed: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "features", MappingProxyType(dict(self.features)))

    def feature(self, name: str) -> Feature:
        """The feature called ``name``; :class:`UnknownNameError` names body and feature."""
        try:
            return self.features[name]
        except KeyError:
            known = ", ".join(self.features) or "none"
            raise UnknownNameError(
                f"body '{self.name}' has no feature '{name}' (it has: {known})",
                where=f"{self.name}.{name}",
            ) from None

    def transformed(self, transform: NDArray[np.float64]) -> Body:
        """The body with every feature moved by ``transform`` (a change of body frame)."""
        moved = {key: feature.transformed(transform) for key, feature in self.features.items()}
        return Body(self.name, moved, self.fixed)

    @classmethod
    def from_dict(cls, name: str, data: Mapping[str, Any], where: str | None = None) -> Body:
        """Build a body from its task-file mapping ``{fixed: bool, features: {name: {...}}}``
        (DESIGN §5.1); errors name ``where`` (default ``bodies.<name>``) and the feature."""
        where = where or f"bodies.{name}"
        if not isinstance(data, Mapping):
            raise SchemaError(f"a body must be a mapping, got {data!r}", where=where)
        if unknown := sorted(set(data) - {"fixed", "features"}):
            raise SchemaError(
                f"unknown key(s) {', '.join(map(str, unknown))} for a body", where=where
            )
        fixed = data.get("fixed", False)
        if not isinstance(fixed, bool):
            raise SchemaError(f"fixed must be true or false, got {fixed!r}", where=f"{where}.fixed")
        features = data.get("features") or {}
        if not isinstance(features, Mapping):
            raise SchemaError("features must be a mapping of names", where=f"{where}.features")
        built = {
            str(key): feature_from_dict(str(key), value, f"{where}.features.{key}")
            for key, value in features.items()
        }
        return cls(name, built, fixed)
