"""What a search keeps (:class:`~assemblykit.planning.kept.Kept`): at most its capacity
of values, the most recently kept first; keeping a key again puts it first, reading
never reorders, and beyond the capacity the entry kept longest ago goes."""

from __future__ import annotations

from functools import partial

import pytest

from assemblykit.planning.kept import Kept


def test_the_most_recently_kept_come_first_and_the_last_goes_beyond_the_capacity():
    kept: Kept[str, int] = Kept(3)
    for number, key in enumerate("abcd"):
        kept.keep(key, number)
    assert list(kept.items()) == [("d", 3), ("c", 2), ("b", 1)]
    assert len(kept) == 3 and "a" not in kept


def test_reading_does_not_reorder_so_the_oldest_goes_first():
    kept: Kept[str, int] = Kept(2)
    kept.keep("a", 0)
    kept.keep("b", 1)
    assert kept["a"] == 0 and kept.get("a", -1) == 0 and kept.get("z", -1) == -1
    kept.keep("c", 2)
    assert list(kept.values()) == [2, 1]


def test_keeping_a_key_again_puts_it_first_with_its_new_value():
    kept: Kept[str, int] = Kept(3)
    for number, key in enumerate("abc"):
        kept.keep(key, number)
    kept.keep("a", 10)
    assert kept.first() == ("a", 10) and len(kept) == 3
    kept.keep("d", 3)
    # "b" was kept longest ago
    assert list(kept.items()) == [("d", 3), ("a", 10), ("c", 2)]


def test_recall_makes_and_keeps_only_what_is_missing():
    kept: Kept[int, int] = Kept(2)
    made: list[int] = []

    def make(key: int) -> int:
        made.append(key)
        return key * key

    found = [kept.recall(key, partial(make, key)) for key in (3, 3, 4, 3, 5, 3)]
    assert found == [9, 9, 16, 9, 25, 9]
    # 3 was made first and not kept again when read: 5 pushed it out, and it is made again
    assert made == [3, 4, 5, 3]


def test_without_a_capacity_everything_is_kept():
    kept: Kept[int, int] = Kept()
    for key in range(1000):
        kept.keep(key, key)
    assert len(kept) == 1000 and kept.first() == (999, 999)
    with pytest.raises(IndexError):
        Kept[int, int](1).first()
