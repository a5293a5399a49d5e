"""The blocking data of an assembly: a store of its memo, which goes with the assembly
(no global registry keeps it, or the assembly, alive) and is not carried to a
sub-assembly."""

from __future__ import annotations

import gc
import weakref
from pathlib import Path

import assemblykit
from assemblykit.api.assembly import load_assembly
from assemblykit.blocking.cache import BlockingCache
from assemblykit.blocking.graphs import blocking_graph
from assemblykit.planning.planner import plan

EXAMPLES = Path(assemblykit.__file__).parent / "examples"


def _planned_and_dropped(path: Path, *, extended: bool = False) -> weakref.ref[object]:
    """A weak reference to the assembly at ``path``, planned (and its Γ_e built when
    ``extended``), after its last strong reference was dropped and garbage collected."""
    assembly = load_assembly(path)
    assert plan(assembly).feasible
    if extended:
        blocking_graph(assembly, "extended")
    assert BlockingCache in assembly.memo
    gone = weakref.ref(assembly)
    del assembly
    gc.collect()
    return gone


def test_a_planned_mesh_assembly_is_freed_with_its_blocking_data():
    assert _planned_and_dropped(EXAMPLES / "motion" / "hinge" / "hinge.yaml")() is None


def test_an_assembly_whose_extended_graph_is_kept_is_freed():
    hinge = EXAMPLES / "motion" / "hinge" / "hinge.yaml"
    assert _planned_and_dropped(hinge, extended=True)() is None


def test_a_planned_polygon_assembly_is_freed():
    assert _planned_and_dropped(EXAMPLES / "planar" / "hook.yaml")() is None


def test_the_cache_is_the_store_in_the_assembly_memo():
    hinge = load_assembly(EXAMPLES / "motion" / "hinge" / "hinge.yaml")
    cache = BlockingCache.of(hinge)
    assert hinge.memo.of(BlockingCache) is cache and BlockingCache.of(hinge) is cache
    assert cache.owner is not None and cache.owner() is hinge
    assert cache.obstacles is cache.obstacles and cache.obstacles.assembly is hinge
    other = load_assembly(EXAMPLES / "motion" / "hinge" / "hinge.yaml")
    assert BlockingCache.of(other) is not cache


def test_a_sub_assembly_starts_without_the_blocking_data():
    hinge = load_assembly(EXAMPLES / "motion" / "hinge" / "hinge.yaml")
    blocking_graph(hinge, "infinitesimal")
    assert BlockingCache.of(hinge).graphs
    sub = hinge.subset(hinge.names[:1])
    assert BlockingCache not in sub.memo
    assert not BlockingCache.of(sub).graphs and BlockingCache.of(sub).owner() is sub
