"""What the blocking analysis of one assembly computes once and reuses while the
assembly lives: contacts and pairwise obstacles serve every direction and every
sub-assembly, since blocking is pairwise (Wilson & Latombe 1992, "Incremental
modification").

A :class:`BlockingCache` is a store of the assembly's own
:class:`~assemblykit.model.assembly.Memo`, made on first use by
:meth:`BlockingCache.of`: it goes when the assembly goes, and no module global refers to
it. It holds the assembly weakly (``owner``), and so do its obstacles; a graph it keeps
may refer to the assembly (a sampled Γ_e computes its exact DBGs from the meshes), a
cycle through the assembly's own memo that the garbage collector frees with it. What it
holds and what each part is keyed on:

* ``obstacles``: convex bodies and bounding spheres per part, cones and back-outs per
  ordered pair of parts and tolerance (:class:`~assemblykit.blocking.obstacles.Obstacles`,
  read by :mod:`~assemblykit.blocking.extended` and :mod:`~assemblykit.blocking.free_cones`);
* ``terms``: the blocking terms of the whole assembly, per motion kind and tolerance
  (:func:`assemblykit.blocking.graphs.blocking_terms`);
* ``graphs``: the NDBGs, per motion kind, parts and tolerance
  (:func:`assemblykit.blocking.graphs.blocking_graph`);
* ``blocked``: exact blocked sets, per moving parts, blocker and tolerance
  (:func:`assemblykit.blocking.free_cones.blocked_by`, ``None`` when too large to compute).

All of it is of the whole assembly (its terms, its tolerance, its meshes), so a
sub-assembly starts without it (:meth:`BlockingCache.restricted`). The graphs and
blocked sets are defined above this module: they are stored as objects and the module
that fills a store checks the type of what it reads back. A cache is kept for any
assembly the blocking graphs take (meshes, polygons, given contacts: every
:class:`~assemblykit.model.assembly.AssemblyLike` carries a memo); only an
:class:`~assemblykit.model.assembly.Assembly` of meshes has ``obstacles``.
"""

from __future__ import annotations

import weakref
from collections.abc import Set
from dataclasses import dataclass, field
from typing import Any

from assemblykit.blocking.constraints import BlockingTerm
from assemblykit.blocking.obstacles import Obstacles, of_meshes
from assemblykit.model.assembly import AssemblyLike
from assemblykit.tolerance import Tolerance

TermsKey = tuple[str, Tolerance]
"""Motion kind and tolerance."""
GraphKey = tuple[str, tuple[str, ...], Tolerance]
"""Motion kind, the parts (in the assembly's order) and tolerance."""
BlockedKey = tuple[tuple[str, ...], str, Tolerance]
"""Moving parts (sorted), blocker and tolerance."""


@dataclass(eq=False)
class BlockingCache:
    """The blocking data of one assembly, a store of its memo (module docstring)."""

    terms: dict[TermsKey, list[BlockingTerm]] = field(default_factory=dict)
    graphs: dict[GraphKey, object] = field(default_factory=dict)
    blocked: dict[BlockedKey, object] = field(default_factory=dict)
    owner: weakref.ref[Any] | None = field(default=None, repr=False)
    """The assembly whose memo holds this cache (weakly), set by :meth:`of`."""
    _obstacles: Obstacles | None = field(default=None, repr=False)

    @classmethod
    def of(cls, assembly: AssemblyLike) -> BlockingCache:
        """The cache of ``assembly``: the store of this kind in its memo, created empty
        the first time."""
        found = assembly.memo.of(cls)
        if found.owner is None:
            found.owner = weakref.ref(assembly)
        return found

    def restricted(self, names: Set[str]) -> None:
        """Nothing of it holds for a sub-assembly (module docstring): it is dropped."""
        return None

    @property
    def obstacles(self) -> Obstacles:
        """The obstacles of the assembly's parts (made on first use, then computed part
        by part and pair by pair as asked); asked of an assembly of meshes only."""
        if self._obstacles is None:
            assembly = None if self.owner is None else self.owner()
            assert assembly is not None, "the assembly of this cache is gone"
            self._obstacles = Obstacles(of_meshes(assembly))
        return self._obstacles
