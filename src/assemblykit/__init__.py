"""assemblykit: geometric reasoning about mechanical assemblies.

The public API (docs/tutorial.md §4) is imported lazily so that ``import assemblykit`` stays
cheap and optional extras are only needed by the functions that use them; ``dir()``
lists it. Results print as one line and show as tables in notebooks; results indexed by
name behave as mappings.

A task: where every body is in every situation (RAPT network reduction).

>>> from pathlib import Path
>>> import assemblykit
>>> examples = Path(assemblykit.__file__).parent / "examples"
>>> task = assemblykit.load_task(examples / "tasks" / "peg_in_block.rapt")
>>> task
Task(3 bodies, 2 situations, mm, peg_in_block.rapt)
>>> solution = task.solve()
>>> solution
Solution(underconstrained, 6 body instances, 0 conflicts)
>>> "peg@s1" in solution, list(solution)[:3]
(True, ['table@s1', 'block@s1', 'peg@s1'])

An assembly: how each part can move, and a disassembly plan.

>>> hinge = assemblykit.load_assembly(examples / "motion" / "hinge" / "hinge.yaml")
>>> hinge
Assembly(2 parts, mm, hinge.yaml)
>>> "door" in hinge
True
>>> motions = assemblykit.motion(hinge)
>>> motions["door"]
Motion(door, revolute, 1 dof)
>>> sorted(motions)
['door', 'frame']
>>> gearbox = assemblykit.load_assembly(examples / "gearbox_demo" / "gearbox.yaml")
>>> plan = assemblykit.plan(gearbox)
>>> plan
Plan(feasible, 5 steps, 14 parts)
>>> plan.steps[0]
Step(cover, pin_1, pin_2, pin_3 and 1 more along +Z)
>>> plan.order[0]  # assembly order: the plan reversed
('housing',)

Which parts block which along a direction (Wilson & Latombe 1992, §3):

>>> blocking = assemblykit.blocking_graph(hinge)
>>> blocking
NonDirectionalBlockingGraph(infinitesimal, 2 parts, 1 contact, 26 regions)
>>> blocking.dbg([0, 0, 1])
DirectionalBlockingGraph(+Z, 2 parts, 1 arc)

Where a peg can sit in a bore (Liu & Popplestone 1990): one configuration, the peg
free to slide and turn along the bore's axis.

>>> problem = assemblykit.load_problem(examples / "mating" / "shaft_fit.yaml")
>>> found = assemblykit.mate(problem)
>>> len(found.configurations), found.configurations[0].motions["peg"].kind
(1, 'cylindrical')

The algebra: symmetry groups and their cosets (Liu & Popplestone 1994). A pin in a hole
(cylindrical) whose head rests on a plane (planar) can only turn about its axis.

>>> import numpy as np
>>> from assemblykit.algebra import Coset, SymmetryGroup
>>> in_hole = Coset(SymmetryGroup.cylindrical((0, 0, 0), (0, 0, 1)), np.eye(4))
>>> on_plane = Coset(SymmetryGroup.planar((0, 0, 1)), np.eye(4))
>>> both = in_hole.intersect(on_plane)
>>> both.group
SymmetryGroup<revolute about line through (0, 0, 0) along +Z>
>>> lifted = np.eye(4)
>>> lifted[2, 3] = 5.0
>>> in_hole.contains(lifted), on_plane.contains(lifted), both.dof
(True, False, 1)
"""

from __future__ import annotations

import importlib as _importlib
import typing as _typing

from assemblykit.errors import AssemblyKitError

__version__ = "0.1.0"

_PUBLIC = {
    "load_task": "assemblykit.api.task",
    "load_assembly": "assemblykit.api.assembly",
    "Task": "assemblykit.api.task",
    "Assembly": "assemblykit.api.assembly",
    "motion": "assemblykit.motion.freedom",
    "blocking_graph": "assemblykit.blocking.graphs",
    "plan": "assemblykit.planning.planner",
    "interlocking": "assemblykit.planning.interlocking",
    "Interlocking": "assemblykit.planning.interlocking",
    "load_problem": "assemblykit.io.problem",
    "mate": "assemblykit.mating.search",
    "Tolerance": "assemblykit.tolerance",
    "write_report": "assemblykit.viz.viewer",
    "write_plan": "assemblykit.io.exports",
    "write_gltf": "assemblykit.io.exports",
    # what users build inputs from and read outputs as
    "InputError": "assemblykit.errors",
    "Part": "assemblykit.model.assembly",
    "PolygonAssembly": "assemblykit.api.assembly",
    "Gravity": "assemblykit.planning.stability",
    "Contact": "assemblykit.geometry.contacts",
    "Contacts": "assemblykit.geometry.contacts",
    "Solution": "assemblykit.inference.solution",
    "Motion": "assemblykit.motion.freedom",
    "MotionReport": "assemblykit.motion.freedom",
    "DirectionalBlockingGraph": "assemblykit.blocking.dbg",
    "NonDirectionalBlockingGraph": "assemblykit.blocking.ndbg",
    "Plan": "assemblykit.planning.plan_values",
    "Step": "assemblykit.planning.plan_values",
    "MatingProblem": "assemblykit.mating.problem",
    "MatingResult": "assemblykit.mating.search",
}

__all__ = ["AssemblyKitError", "__version__", *_PUBLIC]


def __getattr__(name: str) -> _typing.Any:
    """A name of the public API, imported from its module when first asked for."""
    module = _PUBLIC.get(name)
    if module is None:
        raise AttributeError(f"module 'assemblykit' has no attribute {name!r}")
    return getattr(_importlib.import_module(module), name)


def __dir__() -> list[str]:
    """The public API (``__all__``): no helper names and no submodules."""
    return sorted(__all__)


del annotations
