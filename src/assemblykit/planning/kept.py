"""What a search keeps from one question for the next: values by key, at most a given
number of them, the most recently kept first.

Keeping a value puts it first, again when its key is already there (with the value
given); beyond the capacity the last one goes. Reading never reorders, so what goes is
the entry kept longest ago: with nothing kept again, the oldest (first in, first out);
with the useful entries kept again, the least recently useful (docs/planning.md,
"Under gravity": the states a plan asks about).
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Iterator
from typing import Generic, TypeVar

K = TypeVar("K", bound=Hashable)
V = TypeVar("V")


class Kept(Generic[K, V]):
    """Values by key, the most recently kept first, at most ``capacity`` of them
    (``None``: every one)."""

    def __init__(self, capacity: int | None = None) -> None:
        self.capacity = capacity
        self._entries: dict[K, V] = {}
        """The entries, the most recently kept last (a dict keeps its insertion order)."""

    def __len__(self) -> int:
        return len(self._entries)

    def __contains__(self, key: K) -> bool:
        return key in self._entries

    def __getitem__(self, key: K) -> V:
        return self._entries[key]

    def keep(self, key: K, value: V) -> None:
        """Keep ``value`` under ``key``, first; forget the last entry beyond the
        capacity."""
        self._entries.pop(key, None)
        self._entries[key] = value
        if self.capacity is not None and len(self._entries) > self.capacity:
            del self._entries[next(iter(self._entries))]

    def recall(self, key: K, make: Callable[[], V]) -> V:
        """The value kept under ``key``; when there is none, ``make()``, kept."""
        if key not in self._entries:
            self.keep(key, make())
        return self._entries[key]

    def get(self, key: K, default: V) -> V:
        """The value kept under ``key``, else ``default``."""
        return self._entries.get(key, default)

    def items(self) -> Iterator[tuple[K, V]]:
        """The keys and values, the most recently kept first."""
        return reversed(self._entries.items())

    def values(self) -> Iterator[V]:
        """The values, the most recently kept first."""
        return reversed(self._entries.values())

    def first(self) -> tuple[K, V]:
        """The key and value kept most recently (:class:`IndexError` when none is)."""
        for entry in self.items():
            return entry
        raise IndexError("nothing is kept")
