"""Lazily computed attributes of immutable algebra values.

``functools.cached_property`` takes a lock on every first access in Python 3.11, which
costs more than the closed-form coset intersections it caches for (docs/algebra.md §2.5).
The values here are immutable, so a plain descriptor without a lock is enough: a
concurrent first access at worst computes the same value twice.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Generic, TypeVar, overload

__all__ = ["cached"]

T = TypeVar("T")


class cached(Generic[T]):
    """A non-data descriptor that stores the computed value in the instance ``__dict__``
    (later reads are plain attribute lookups)."""

    def __init__(self, func: Callable[[Any], T]) -> None:
        self.func = func
        self.name = func.__name__
        self.__doc__ = func.__doc__

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    @overload
    def __get__(self, instance: None, owner: type | None = None) -> cached[T]: ...

    @overload
    def __get__(self, instance: object, owner: type | None = None) -> T: ...

    def __get__(self, instance: object | None, owner: type | None = None) -> T | cached[T]:
        if instance is None:
            return self
        value = self.func(instance)
        instance.__dict__[self.name] = value
        return value
