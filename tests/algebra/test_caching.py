"""Lazily computed attributes of immutable values (src/assemblykit/algebra/caching.py)."""

from __future__ import annotations

from dataclasses import dataclass

from assemblykit.algebra.caching import cached


@dataclass(frozen=True)
class _Value:
    x: int

    @cached
    def doubled(self) -> list[int]:
        """Twice x, counted."""
        _CALLS.append(self.x)
        return [2 * self.x]


_CALLS: list[int] = []


def test_computed_once_per_instance_and_stored_on_frozen_values():
    _CALLS.clear()
    a, b = _Value(3), _Value(4)
    assert a.doubled == [6]
    assert a.doubled is a.doubled
    assert b.doubled == [8]
    assert _CALLS == [3, 4]
    assert a.__dict__["doubled"] == [6]


def test_class_access_returns_the_descriptor_with_its_docstring():
    assert isinstance(_Value.__dict__["doubled"], cached)
    assert _Value.doubled.__doc__ == "Twice x, counted."
