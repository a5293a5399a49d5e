"""The disassembly planner (Wilson & Latombe 1992): the greedy search over the candidate directions
of :mod:`assemblykit.planning.search`, in the plane for polygons
(:mod:`assemblykit.planning.planar`), under gravity
(:mod:`assemblykit.planning.stability`), and the plan it gives: the sets left
interlocked, classified with Γ_t and Γ_g, the AND/OR graph of a small assembly and the
hands that take the stopped sets apart (:mod:`assemblykit.planning.hands`).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from assemblykit.blocking.directions import DirectionTable
from assemblykit.blocking.graphs import blocking_graph
from assemblykit.blocking.rigid import RigidBlockingGraph
from assemblykit.blocking.tables import translation_slots, translation_table, with_obstacles
from assemblykit.errors import InputError, UnknownNameError
from assemblykit.geometry.interference import enclosures, interferences
from assemblykit.model.assembly import Assembly
from assemblykit.model.polygons import PolygonAssembly
from assemblykit.part_sets import bits, mask_of, union_of
from assemblykit.planning.candidates import exact_candidates, fit_axes
from assemblykit.planning.equilibrium import equilibrium_model
from assemblykit.planning.equilibrium_memory import EquilibriumMemory
from assemblykit.planning.extended_directions import ExtendedDirections
from assemblykit.planning.fasteners import bolts_after_nuts, step_fastener
from assemblykit.planning.free_sets import separable
from assemblykit.planning.gravity import Gravity, GravityReport, gravity_direction
from assemblykit.planning.hands import hands_needed
from assemblykit.planning.interlocked_sets import least_interlocked
from assemblykit.planning.judge import StateJudge
from assemblykit.planning.multimove import moving_groups
from assemblykit.planning.plan_values import Hands, Interlock, Plan, Step, and_or_graph
from assemblykit.planning.planar import planar_rigid_may_free, planar_search
from assemblykit.planning.search import FirstAdmitted, Progress, Search, base_part, one_set
from assemblykit.tolerance import ModelTolerance, Tolerance

UP = (0.0, 0.0, 1.0)
"""Up for an assembly planned on the ground (+Z, the convention of block assemblies):
no step moves a part along a direction with a component against it."""


def rigid_may_free(
    assembly: Assembly | PolygonAssembly, parts: Iterable[str], tol: Tolerance | None = None
) -> bool:
    """Whether some DBG of Γ_g (infinitesimal rigid motions) of the sub-assembly
    ``parts`` frees a proper part of it: the necessary condition of Wilson & Latombe
    1992, "Extension and Variant" ("a necessary condition for a subassembly S to be
    directly removable")."""
    if assembly.dimension == 2:
        # polygons move in their plane: lifting off it would free every part
        return planar_rigid_may_free(assembly, parts, assembly.tolerance(tol))
    graph = blocking_graph(assembly, motion="rigid", parts=parts, tol=tol)
    assert isinstance(graph, RigidBlockingGraph)
    return graph.frees_some()


def plan(
    assembly: Assembly | PolygonAssembly,
    tol: Tolerance | None = None,
    max_and_or_parts: int = 8,
    progress: Progress | None = None,
    max_hands: int = 4,
    *,
    gravity: Gravity | None = None,
    one_at_a_time: bool = False,
    max_steps: int | None = None,
    fixed: Iterable[str] | None = None,
    ground: bool = True,
) -> Plan:
    """Plan the disassembly of ``assembly`` by extended translations (Wilson & Latombe
    1992, "Extension and Variant"; docs/planning.md, "How a plan is found"): in what
    order the parts come apart, along which directions, and which sets are interlocked;
    read backwards, the assembly order.

    ``progress(stage, done, total)`` is called as the work advances. The result is
    feasible when every part is separated; otherwise ``interlocked`` holds the minimal
    sets that no candidate direction separates, each classified with Γ_t and Γ_g
    (module doc), and ``hands`` whether up to ``max_hands`` hands take them apart
    (:mod:`assemblykit.planning.hands`). A polygon assembly is planned in the plane
    (:mod:`assemblykit.planning.planar`).

    ``one_at_a_time`` moves one free set per step. Under ``gravity``
    (:mod:`assemblykit.planning.stability`) every step moves one free set too, the
    fixed parts stay (declared ones are never moved; the default ones, resting on the
    lowest plane, are taken off it last), and a step is taken only when what remains (and the
    moved set, held at its base) stands with at most ``gravity.holds`` parts held; when
    no step does, the one leaving the fewest parts falling is taken and reported as not
    standing.

    ``max_steps`` stops the search after that many steps: the parts not yet taken
    apart are the plan's ``unfinished`` ones, and the plan is not feasible.

    ``fixed`` parts never move, in every mode (docs/planning.md, "Fixed parts"): no
    step moves a set holding one, they stay together as one immovable base, and the
    plan stops when only they (and what cannot leave them) are left; ``order`` starts
    on them. Under gravity they are added to ``gravity.fixed``.

    With ``ground``, an assembly that stands on the ground (its
    :attr:`~assemblykit.model.assembly.Assembly.supports`: blocks declared supports, or
    resting on the lowest plane of a block assembly) is planned on it (docs/planning.md,
    "The ground"): the supports are fixed parts, and no step moves a part down through
    the plane under them (no direction with a component along -Z; sliding along the
    ground is allowed). Without, the assembly floats free. Under gravity the ground is
    the lowest plane across gravity whatever this says.

    Parameters
    ----------
    assembly : Assembly or PolygonAssembly
        The parts in assembled position (:func:`assemblykit.load_assembly`); polygons are
        planned in their plane.
    tol : Tolerance, optional
        The tolerance policy (the assembly's own when ``None``).
    max_and_or_parts : int, default 8
        Up to this many parts, every two-handed partition is enumerated (``and_or``).
    progress : callable, optional
        Called as ``progress(stage, done, total)``.
    max_hands : int, default 4
        How many hands may take a stuck set apart (2: none beyond the two of every step).
    gravity : Gravity, optional
        Keep only steps after which everything stands (docs/planning.md, "Under
        gravity: plans that stand").
    one_at_a_time : bool, default False
        Move one free set per step.
    max_steps : int, optional
        Stop after this many steps.
    fixed : iterable of str, optional
        Parts that never move (a fixture, the ground).
    ground : bool, default True
        Plan an assembly that stands on the ground on it; ``False``: free-floating.

    Returns
    -------
    Plan
        ``steps`` (the parts each moves, its direction and the parts it leaves),
        ``feasible``, ``stuck`` and ``interlocked`` when a set does not come apart,
        ``order`` and ``assembly_steps`` (the assembly order), and the JSON of
        docs/planning.md, "JSON" (``to_dict()``).

    Raises
    ------
    UnknownNameError
        ``fixed`` or ``gravity.fixed`` names a part the assembly does not have.

    Examples
    --------
    >>> import trimesh
    >>> import assemblykit
    >>> lower = trimesh.creation.box(bounds=[[0, 0, 0], [1, 1, 1]])
    >>> upper = trimesh.creation.box(bounds=[[0, 0, 1], [1, 1, 2]])
    >>> parts = [assemblykit.Part("lower", lower), assemblykit.Part("upper", upper)]
    >>> boxes = assemblykit.Assembly(parts)
    >>> plan = assemblykit.plan(boxes, gravity=assemblykit.Gravity())
    >>> plan
    Plan(feasible, 1 step, 2 parts)
    >>> plan.steps[0], plan.gravity.stable
    (Step(upper along +Z), True)
    """
    if max_steps is not None and max_steps < 0:
        raise InputError(f"max_steps must be 0 or more, not {max_steps}")
    tol = assembly.tolerance(tol)
    names = tuple(assembly.names)
    supports: tuple[str, ...] = ()
    if ground and gravity is None and assembly.dimension == 3:
        supports = assembly.supports
    declared = fixed_parts(assembly, [*(fixed or ()), *supports], gravity)
    if gravity is not None and declared:
        gravity = replace(gravity, fixed=declared)
    report: Progress = progress or (lambda stage, done, total: None)
    report("blocking graph (infinitesimal translations)", 0, len(names))
    if assembly.dimension == 2:
        if gravity is not None or one_at_a_time:
            raise InputError("--gravity and --one-at-a-time need 3D parts, not 2D polygons")

        planar = planar_search(assembly, tol, report, max_steps, declared)
        result = finish_plan(assembly, planar, tol, max_and_or_parts, max_hands, report)
        return replace(result, fixed=declared)
    index = {name: k for k, name in enumerate(names)}
    contacting = translation_table(assembly, tol)
    translations, add_translations = with_obstacles(
        contacting,
        translation_slots(assembly, contacting, tol),
        [
            (index[o.a], index[o.b])
            for o in assembly.overlaps
            if not o.resolution and o.a in index and o.b in index
        ],
    )
    extended = ExtendedDirections(assembly, translations.directions, tol)
    volumes = anchored_volumes(
        names, tuple(assembly.parts[name].volume for name in names), declared
    )
    search = Search(
        translations=translations,
        extended=extended,
        volumes=volumes,
        progress=report,
        exact=exact_candidates(assembly, tol),
        axes=fit_axes(assembly, tol),
        add_translations=add_translations,
        narrowers=(one_set,) if one_at_a_time else (),
        max_steps=max_steps,
        fixed=mask_of(k for k, name in enumerate(names) if name in declared),
        up=np.array(UP) if supports else None,
    )
    if gravity is None:
        search.disassemble(mask_of(range(len(names))))
        result = finish_plan(assembly, search, tol, max_and_or_parts, max_hands, report)
    else:
        result = _plan_under_gravity(assembly, search, gravity, tol, max_and_or_parts, max_hands)
    return replace(result, fixed=declared, ground=supports)


def fixed_parts(
    assembly: Assembly | PolygonAssembly,
    fixed: Iterable[str] | None,
    gravity: Gravity | None,
) -> tuple[str, ...]:
    """The declared fixed parts of :func:`plan`: ``fixed`` and ``gravity.fixed``, in the
    assembly's order (docs/planning.md, "Fixed parts"). Raises ``UnknownNameError`` for
    a name the assembly does not have."""
    wanted = {*(fixed or ()), *((gravity.fixed or ()) if gravity is not None else ())}
    for name in sorted(wanted):
        if assembly.dimension == 3:
            assembly.part(name)
        elif name not in assembly.names:
            raise UnknownNameError(f"no part named {name!r} (parts: {', '.join(assembly.names)})")
    return tuple(name for name in assembly.names if name in wanted)


def anchored_volumes(
    names: Sequence[str], volumes: Sequence[float], fixed: Iterable[str]
) -> tuple[float, ...]:
    """``volumes`` with every ``fixed`` part's raised by the total, so that the base
    (:func:`~assemblykit.planning.search.base_part`) of a set holding one is a fixed
    part (docs/planning.md, "Fixed parts")."""
    anchored = set(fixed)
    total = sum(volumes)
    return tuple(
        v + total if name in anchored else v for name, v in zip(names, volumes, strict=True)
    )


def _plan_under_gravity(
    assembly: Assembly,
    search: Search,
    gravity: Gravity,
    tol: ModelTolerance,
    max_and_or_parts: int,
    max_hands: int,
) -> Plan:
    """:func:`plan` under gravity: ``search`` (not yet run) configured for it before it
    runs, as a new search: the fixed parts outweigh every other so that one of them is
    the base that stays, :class:`~assemblykit.planning.judge.StateJudge` picks and
    judges the steps, with one memory of what the equilibrium programs found for the
    whole search (from the start, the whole assembly's balance as its reference), and no
    step goes down (docs/planning.md, "Under gravity")."""
    search.progress("equilibrium equations", 0, 1)
    model = equilibrium_model(
        assembly,
        gravity.direction,
        gravity.friction,
        gravity.fixed,
        dict(gravity.densities),
        tol,
    )
    volumes = anchored_volumes(model.names, search.volumes, model.fixed)
    supports = mask_of(k for k, name in enumerate(model.names) if name in set(model.fixed))
    everything = mask_of(range(len(model.names)))
    memory = EquilibriumMemory()
    memory.reference = model.reference(model.mask(None), model.mask(model.fixed))
    judge = StateJudge(
        model,
        memory,
        gravity.holds,
        search.translations.vector,
        lambda members: base_part(members, volumes),
        base_part(everything, volumes),
    )
    # declared fixed parts (a fixture) never move; the default supports leave last
    declared = gravity.fixed is not None
    search = replace(
        search,
        volumes=volumes,
        narrowers=(
            FirstAdmitted(judge.ordered, judge.stands_without, judge.known_to_fall),
            judge.fewest_falling,
        ),
        judge=judge.judge,
        up=-gravity_direction(gravity.direction),
        fixed=supports,
        ground=supports if declared else 0,
    )
    if declared:
        search.disassemble(everything)
    else:
        search = _supports_last(search, everything)
    result = finish_plan(assembly, search, tol, max_and_or_parts, max_hands, search.progress)
    whole = model.check(memory=memory)
    present = model.mask(None)
    needed = model.friction_needed(
        present, present & judge.fixed, model.mask(whole.would_fall), memory=memory
    )
    return replace(
        result,
        gravity=GravityReport(
            settings=gravity,
            fixed=model.fixed,
            whole=whole,
            friction_needed=needed,
            tips=needed is None and model.tips(present, present & judge.fixed),
            stable=whole.stands
            and all(step.stability is None or step.stability.stands for step in search.steps),
        ),
    )


def _supports_last(search: Search, members: int) -> Search:
    """Run ``search``, whose fixed parts are the default supports (the parts on the
    lowest plane), on ``members`` with those taken off last (docs/planning.md, "Fixed
    parts"): first as if they were fixed, then, on what is left (the supports, and any
    set that could not leave them), with every part free to move. The search of that
    second part, returned, goes on with the first's steps and sets (the same lists)."""
    search.disassemble(members)
    if search.unfinished:
        return search
    moved = mask_of(i for step in search.steps for i in _indices(search, step.parts))
    left = members & ~moved
    search.locked[:] = [lock for lock in search.locked if lock != left]
    rest = replace(search, fixed=0)
    rest.disassemble(left)
    return rest


def _indices(search: Search, parts: Iterable[str]) -> list[int]:
    """The indices of the part names ``parts`` in ``search``."""
    names = search.translations.names
    return [names.index(name) for name in parts]


def finish_plan(
    assembly: Assembly | PolygonAssembly,
    search: Search,
    tol: ModelTolerance,
    max_and_or_parts: int,
    max_hands: int,
    report: Progress,
) -> Plan:
    """The plan of a finished search: each set where it stopped, reported whole (its
    minimal interlocked subset and the parts that subset holds), the AND/OR graph of a
    small assembly, and the hands that take the stopped sets apart."""
    names = search.translations.names
    translations = search.translations
    # ExtendedDirections, or PlanarExtended for polygons: both give table and evaluated
    extended: Any = search.extended
    interlocks = tuple(
        _interlock(
            assembly,
            names,
            least_interlocked(translations, extended, members),
            members,
            translations,
            tol,
        )
        for members in search.locked
    )
    and_or = None
    if 1 < len(names) <= max_and_or_parts:
        # one direction per distinct DBG of Γ_t, and those the search already swept
        directions = set(translations.distinct_directions()) | extended.evaluated
        and_or = and_or_graph(extended.table(directions))
    hands = Hands(min(2, len(names)), max_hands)
    if search.locked and max_hands > 2:
        report("hands", 0, len(search.locked))
        # each stopped set on its own: its groups never need the parts already removed
        found = [
            hands_needed(assembly, [names[i] for i in bits(members)], max_hands, tol, locked=True)
            for members in search.locked
        ]
        needed = [h.needed for h in found]
        hands = Hands(
            None if None in needed else max(n for n in needed if n is not None),
            max_hands,
            tuple(move for h in found for move in h.moves),
            more_may_free=any(h.needed is None and h.more_may_free for h in found),
        )
    elif search.locked:
        largest = max(members.bit_count() for members in search.locked)
        hands = Hands(None, max_hands, more_may_free=largest > max_hands)
    report("done", len(names), len(names))
    unfinished = tuple(names[i] for i in bits(union_of(search.unfinished)))
    steps = tuple(search.steps)
    if assembly.dimension == 3:
        steps = _with_fasteners(assembly, steps, tol)
    return Plan(
        names,
        steps,
        interlocks,
        and_or,
        len(translations.directions),
        hands,
        overlaps=assembly.overlaps,
        joined=assembly.joined,
        unfinished=unfinished,
    )


def _with_fasteners(
    assembly: Assembly, steps: Sequence[Step], tol: ModelTolerance
) -> tuple[Step, ...]:
    """``steps`` with the fasteners each draws out of the parts it leaves: the fastener
    of each of its moves of one part (:func:`step_fastener`), a pin that a nut came
    off earlier read as a bolt (:func:`bolts_after_nuts`), and the step's own when it
    moves one part only."""
    found = [
        [
            step_fastener(assembly, group, step.direction, step.rest, tol)
            for group in moving_groups(step.parts, step.blocking)
            if len(group) == 1
        ]
        for step in steps
    ]
    drawn = bolts_after_nuts([[f for f in fasteners if f is not None] for fasteners in found])
    return tuple(
        replace(step, fastener=own[0] if len(step.parts) == 1 and own else None, fasteners=own)
        for step, own in zip(steps, drawn, strict=True)
    )


def _interlock(
    assembly: Assembly | PolygonAssembly,
    names: Sequence[str],
    members: int,
    locked: int,
    translations: DirectionTable,
    tol: ModelTolerance,
) -> Interlock:
    parts = tuple(names[i] for i in bits(members))
    held = tuple(names[i] for i in bits(locked & ~members))
    interfering: tuple[tuple[str, str, float], ...] = ()
    enclosed: tuple[tuple[str, str], ...] = ()
    if assembly.dimension == 3:
        stopped = assembly.subset([*parts, *held])
        interfering = tuple(interferences(stopped, tol))
        enclosed = tuple(enclosures(stopped))
    return Interlock(
        parts=parts,
        translation_locked=not separable(translations, members),
        rigid_may_free=rigid_may_free(assembly, parts, tol),
        held=held,
        interfering=interfering,
        enclosed=enclosed,
    )


def separable_by_translations(
    assembly: Assembly | PolygonAssembly,
    parts: Iterable[str] | None = None,
    tol: Tolerance | None = None,
) -> bool:
    """Whether the assembly comes completely apart with extended translations, one
    subassembly moving at a time (Wilson & Latombe 1992, "Conclusion"). Removing parts
    only removes obstacles, so any removable subassembly can be taken first and a greedy
    disassembly decides it: this is the planner's search
    (:func:`plan`), with its candidate directions (Γ_t
    regions, then the faces of the exact free sets), so the two always agree."""
    names = list(assembly.names) if parts is None else list(parts)
    if len(names) <= 1:
        return True
    whole = assembly if len(names) == len(assembly.names) else assembly.subset(names)
    return plan(whole, tol, max_and_or_parts=0).feasible
