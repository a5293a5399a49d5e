"""What the blocking analysis of one assembly computes once and reuses while the
assembly lives: contacts and pairwise obstacles serve every direction and every
sub-assembly, since blocking is pairwise (Wilson & Latombe 1992, "Incremental
modification").

One :class:`BlockingCache` per assembly, held weakly by :meth:`BlockingCache.of` (it
goes when the assembly goes). Its stores and what each is keyed on:

* ``obstacles``: convex bodies and bounding spheres per part, cones and back-outs per
  ordered pair of parts and tolerance (:class:`~assemblykit.blocking.obstacles.Obstacles`,
  read by :mod:`~assemblykit.blocking.extended` and :mod:`~assemblykit.blocking.free_cones`);
* ``terms``: the blocking terms of the whole assembly, per motion kind and tolerance
  (:func:`assemblykit.blocking.graphs.blocking_terms`);
* ``graphs``: the NDBGs, per motion kind, parts and tolerance
  (:func:`assemblykit.blocking.graphs.blocking_graph`);
* ``blocked``: exact blocked sets, per moving parts, blocker and tolerance
  (:func:`assemblykit.blocking.free_cones.blocked_by`, ``None`` when too large to compute).

The graphs and blocked sets are defined above this module: they are stored as objects
and the module that fills a store checks the type of what it reads back. A cache is
kept for any assembly the blocking graphs take (meshes, polygons, given contacts);
only an :class:`~assemblykit.model.assembly.Assembly` of meshes has ``obstacles``.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field
from functools import cached_property
from typing import ClassVar

from assemblykit.blocking.constraints import BlockingTerm
from assemblykit.blocking.obstacles import Obstacles, of_meshes
from assemblykit.tolerance import Tolerance

TermsKey = tuple[str, Tolerance]
"""Motion kind and tolerance."""
GraphKey = tuple[str, tuple[str, ...], Tolerance]
"""Motion kind, the parts (in the assembly's order) and tolerance."""
BlockedKey = tuple[tuple[str, ...], str, Tolerance]
"""Moving parts (sorted), blocker and tolerance."""


@dataclass(eq=False)
class BlockingCache:
    """The blocking data of one assembly (module docstring)."""

    assembly: weakref.ref[object]
    terms: dict[TermsKey, list[BlockingTerm]] = field(default_factory=dict)
    graphs: dict[GraphKey, object] = field(default_factory=dict)
    blocked: dict[BlockedKey, object] = field(default_factory=dict)

    _registry: ClassVar[weakref.WeakKeyDictionary[object, BlockingCache]] = (
        weakref.WeakKeyDictionary()
    )

    @classmethod
    def of(cls, assembly: object) -> BlockingCache:
        """The cache of ``assembly``, created empty the first time."""
        found = cls._registry.get(assembly)
        if found is None:
            found = cls._registry[assembly] = cls(weakref.ref(assembly))
        return found

    @cached_property
    def obstacles(self) -> Obstacles:
        """The obstacles of the assembly's parts (computed lazily, part by part and pair
        by pair); asked of an assembly of meshes only."""
        return Obstacles(of_meshes(self.assembly()))
