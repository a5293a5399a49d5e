"""The Assembly model: scale, tolerance, subsets and part changes; its memo, one store per
kind of derived data, and the contacts and surfaces the geometry layer keeps there."""

from __future__ import annotations

from collections.abc import Set
from dataclasses import dataclass, field

import numpy as np
import pytest

from assemblykit.errors import UnknownNameError
from assemblykit.geometry.contacts import (
    GeometryMemo,
    assembly_contacts,
    assembly_surfaces,
    memo_of,
)
from assemblykit.model.assembly import Assembly, Memo, Part, Precision
from assemblykit.model.packings import box_mesh as box
from assemblykit.tolerance import ModelTolerance, Tolerance, using


@pytest.fixture
def tower() -> Assembly:
    return Assembly(
        [
            Part("a", box([0, 0, 0], [1, 1, 1])),
            Part("b", box([0, 0, 1], [1, 1, 2])),
            Part("c", box([0, 0, 2], [1, 1, 3])),
        ],
        source="tower",
    )


def test_scale_is_the_bounding_box_diagonal(tower):
    assert tower.scale == pytest.approx(np.sqrt(11))
    np.testing.assert_allclose(tower.bounds, [[0, 0, 0], [1, 1, 3]])


def test_tolerance_uses_mesh_thresholds_scaled_to_the_model(tower):
    tol = tower.tolerance()
    assert tol.length == pytest.approx(1e-6 * np.sqrt(11))
    with using(Tolerance(mesh_rel_length=1e-3)):
        assert tower.tolerance().length == pytest.approx(1e-3 * np.sqrt(11))
    exact = Assembly(tower.parts, exact=True)
    assert exact.tolerance().length == pytest.approx(1e-6 * np.sqrt(11))
    with using(Tolerance.relative(1e-9)):
        assert exact.tolerance().length == pytest.approx(1e-9 * np.sqrt(11))
        assert tower.tolerance().length == pytest.approx(1e-6 * np.sqrt(11))


def test_a_model_resolves_a_policy_once_and_keeps_its_own_tolerance(tower):
    policy = Tolerance.relative(1e-5)
    resolved = tower.tolerance(policy)
    assert isinstance(resolved, ModelTolerance) and not isinstance(policy, ModelTolerance)
    # mesh input: the policy's length, at least the mesh floor, over the model's size
    assert resolved.length == pytest.approx(1e-5 * np.sqrt(11))
    assert resolved.angle == pytest.approx(1e-5)
    # given back, to the model or to a part of it (the same scale), it stays as it is
    assert tower.tolerance(resolved) is resolved
    assert tower.subset(["a", "b"]).tolerance(resolved) is resolved
    # a model of another size resolves it again, to its own scale
    tall = Assembly([Part("t", box([0, 0, 0], [1, 1, 30]))])
    assert tall.tolerance(resolved).scale == pytest.approx(np.sqrt(902))
    # a measured precision coarser than the policy raises the length, once
    rounded = Assembly(tower.parts, precision=Precision(1e-3, "rounded poses"))
    raised = rounded.tolerance(policy)
    assert raised.length == pytest.approx(1e-3)
    assert rounded.tolerance(raised) is raised
    assert rounded.tolerance_summary(policy)["from"] == "measured"
    assert tower.tolerance_summary(policy)["from"] == "policy"


def test_tolerances_with_the_same_numbers_are_equal_at_every_stage():
    policy = Tolerance(scale=2.0, rel_length=1e-5)
    model = ModelTolerance.of(policy)
    assert model == policy and hash(model) == hash(policy)
    assert ModelTolerance.of(model) is model
    assert {policy: "kept"}[model] == "kept"
    assert model != Tolerance(scale=3.0, rel_length=1e-5)
    assert (policy == "tolerance") is False


@dataclass
class Mentioned:
    """A store that keeps part names, all of which hold for a subset that has them."""

    names: set[str] = field(default_factory=set)

    def restricted(self, names: Set[str]) -> Mentioned:
        return Mentioned(self.names & names)


class Whole:
    """A store of what holds for the whole assembly alone."""

    def restricted(self, names: Set[str]) -> None:
        return None


def test_memo_of_makes_one_store_per_kind():
    memo = Memo()
    assert len(memo) == 0 and Mentioned not in memo
    first = memo.of(Mentioned)
    assert isinstance(first, Mentioned) and first.names == set()
    assert memo.of(Mentioned) is first
    other = memo.of(Whole)
    assert isinstance(other, Whole) and memo.of(Whole) is other
    assert memo.kinds() == (Mentioned, Whole) and len(memo) == 2


def test_every_assembly_starts_with_its_own_empty_memo(tower):
    again = Assembly(tower.parts)
    assert len(tower.memo) == 0 and again.memo is not tower.memo
    tower.memo.of(Mentioned).names.add("a")
    assert Mentioned not in again.memo


def test_restricted_memo_keeps_what_holds_for_the_parts_left():
    memo = Memo()
    memo.of(Mentioned).names.update({"a", "b", "c"})
    memo.of(Whole)
    kept = memo.restricted({"a", "c"})
    assert kept.kinds() == (Mentioned,)
    assert kept.of(Mentioned).names == {"a", "c"}
    assert memo.of(Mentioned).names == {"a", "b", "c"}
    assert kept.of(Whole) is not memo.of(Whole)


def test_contacts_are_kept_in_the_memo_per_tolerance(tower):
    assert GeometryMemo not in tower.memo
    first = assembly_contacts(tower)
    assert [c.pair for c in first] == [("a", "b"), ("b", "c")]
    assert assembly_contacts(tower) is first
    assert tower.memo.kinds() == (GeometryMemo,)
    assert memo_of(tower) is tower.memo.of(GeometryMemo)
    assert list(memo_of(tower).contacts) == [tower.tolerance()]


def test_subset_keeps_scale_and_cached_contacts(tower):
    assembly_contacts(tower)
    sub = tower.subset(["c", "b"])
    assert sub.names == ["b", "c"]
    assert sub.scale == tower.scale
    assert GeometryMemo in sub.memo and memo_of(sub) is not memo_of(tower)
    ((covered, kept),) = memo_of(sub).contacts.values()
    assert covered == {"b", "c"} and [c.pair for c in kept] == [("b", "c")]
    assert assembly_contacts(sub) is kept
    assert [c.pair for c in assembly_contacts(tower.without_part("b"))] == []


def test_with_part_adds_only_the_new_contacts(tower):
    assembly_contacts(tower)
    grown = tower.without_part("c").with_part(Part("c", box([0, 0, 2], [1, 1, 3])))
    assert GeometryMemo in grown.memo
    ((covered, _),) = memo_of(grown).contacts.values()
    assert covered == {"a", "b"}
    assert sorted(c.pair for c in assembly_contacts(grown)) == [("a", "b"), ("b", "c")]
    outside = tower.with_part(Part("d", box([0, 0, 3], [1, 1, 4])))
    assert outside.scale == pytest.approx(np.sqrt(18))
    assert [c.pair for c in assembly_contacts(outside)] == [("a", "b"), ("b", "c"), ("c", "d")]


def test_unknown_part_is_named(tower):
    with pytest.raises(UnknownNameError, match="'z'"):
        tower.part("z")


def test_features_of_a_box_are_its_six_faces(tower):
    features = [s.feature() for s in assembly_surfaces(tower, "a")]
    assert len(features) == 6
    normals = sorted(tuple(np.round(f.normal, 12)) for f in features)
    assert normals == sorted([(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)])


def test_to_dict_summarises_parts(tower):
    summary = tower.to_dict()
    assert summary["units"] == "mm" and summary["source"] == "tower"
    assert summary["parts"]["b"]["triangles"] == 12
    assert summary["parts"]["b"]["volume"] == pytest.approx(1.0)


def test_a_part_s_size_is_its_volume_in_part_order():
    model = Assembly(
        [Part("long", box([0, 0, 0], [3, 1, 1])), Part("cube", box([3, 0, 0], [5, 2, 2]))]
    )
    assert model.sizes() == pytest.approx({"long": 3.0, "cube": 8.0})
    assert list(model.sizes()) == ["long", "cube"]
