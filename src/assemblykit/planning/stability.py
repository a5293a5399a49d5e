"""Static equilibrium of rigid parts under gravity, decided by linear programs, and the
stability of the planner's steps.

The model is the rigid-block equilibrium analysis of masonry (Whiting, Ochsendorf and
Durand 2009, "Procedural modeling of structurally-sound masonry buildings"; the RBE
of compas_cra), on the contacts the project already finds
(:mod:`assemblykit.geometry.contacts`). Planning assembly as reversed disassembly that
keeps every intermediate state standing, with temporary supports where it cannot, is
the approach of Kao et al. 2017 ("Assembly-aware design of masonry shell structures"),
who judged the states by rigid-body simulation instead (docs/planning.md, "Under
gravity").

The names of stability-aware planning, from the modules that compute them:

* :mod:`~assemblykit.planning.gravity`: the settings (:class:`Gravity`, whose fixed
  parts default to :func:`~assemblykit.model.assembly.lowest_parts`) and the verdicts of
  a state, a step and a plan;
* :mod:`~assemblykit.planning.force_points`: where the contacts transmit force;
* :mod:`~assemblykit.planning.equilibrium_programs`: the linear programs (a balance or a
  Farkas certificate that there is none; the least residuals);
* :mod:`~assemblykit.planning.equilibrium`: the equations of an assembly, assembled once
  (:class:`EquilibriumModel`), and the verdicts drawn from them;
* :mod:`~assemblykit.planning.equilibrium_memory`: what the programs found, kept from one
  state to the next by whoever asks (:class:`EquilibriumMemory`);
* :mod:`~assemblykit.planning.judge`: the planner's judge of candidate steps
  (:class:`StateJudge`).
"""

from __future__ import annotations

from assemblykit.model.assembly import lowest_parts
from assemblykit.planning.equilibrium import (
    FRICTION_STEPS,
    LOCAL_HOPS,
    EquilibriumModel,
    equilibrium,
    equilibrium_model,
)
from assemblykit.planning.equilibrium_memory import (
    KEPT,
    KEPT_CERTIFICATES,
    KEPT_RESIDUALS,
    EquilibriumMemory,
)
from assemblykit.planning.equilibrium_programs import (
    CONE_SIDES,
    LP_FEASIBILITY,
    LP_TIME_LIMIT,
    SLACK_ACCURACY,
    Balance,
    balance,
    least_residuals,
)
from assemblykit.planning.force_points import ContactPoints, contact_points
from assemblykit.planning.gravity import (
    DOWN,
    FRICTION,
    Equilibrium,
    Gravity,
    GravityReport,
    StepStability,
    gravity_direction,
)
from assemblykit.planning.judge import StateJudge

__all__ = [
    "CONE_SIDES",
    "DOWN",
    "FRICTION",
    "FRICTION_STEPS",
    "KEPT",
    "KEPT_CERTIFICATES",
    "KEPT_RESIDUALS",
    "LOCAL_HOPS",
    "LP_FEASIBILITY",
    "LP_TIME_LIMIT",
    "SLACK_ACCURACY",
    "Balance",
    "ContactPoints",
    "Equilibrium",
    "EquilibriumMemory",
    "EquilibriumModel",
    "Gravity",
    "GravityReport",
    "StateJudge",
    "StepStability",
    "balance",
    "contact_points",
    "equilibrium",
    "equilibrium_model",
    "gravity_direction",
    "least_residuals",
    "lowest_parts",
]
