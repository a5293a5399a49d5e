"""manifold3d, the kernel of every boolean of meshes, and the threads it runs on.

Every module imports manifold3d from here (``from assemblykit.geometry.booleans import
manifold3d``), so that its thread policy is set before its first operation.
manifold3d runs its larger operations on oneTBB's thread pool, which takes as many
threads as the process may use cores when it first starts, and keeps them. The booleans
of assembly planning are many and small (a part against its neighbours): on them the
pool's threads gain no time, and spend CPU seconds waiting for work between one
boolean and the next. Unless ``ASSEMBLYKIT_BOOLEAN_THREADS`` is ``all``, the pool is
started on one thread (:func:`start_boolean_threads`): the calling thread is allowed
one core while a boolean of a few hundred triangles starts the pool, then every core again,
which the pool does not read twice. On the 144-part gripper of ``bench_step.py`` the
wall clock time is the same and the CPU time 3-6 s lower (docs/geometry.md, "The
threads of the booleans"). Set ``ASSEMBLYKIT_BOOLEAN_THREADS=all`` for large single
booleans (meshes of a million triangles), which do run faster on several cores. Where
the operating system does not let a thread choose its cores (``os.sched_setaffinity``:
macOS, Windows), or where manifold3d already ran before assemblykit was imported, the
pool is as manifold3d started it.
"""

from __future__ import annotations

import os

import manifold3d

BOOLEAN_THREADS_VARIABLE = "ASSEMBLYKIT_BOOLEAN_THREADS"
"""The environment variable that, set to ``all``, lets manifold3d's booleans use every
core (module docstring)."""

__all__ = ["BOOLEAN_THREADS_VARIABLE", "manifold3d", "start_boolean_threads"]


def start_boolean_threads(one_thread: bool) -> None:
    """Start manifold3d's thread pool, on one thread when ``one_thread`` (module
    docstring), else on every core the process may use."""
    set_cores = getattr(os, "sched_setaffinity", None)
    if not one_thread or set_cores is None:
        return
    cores = os.sched_getaffinity(0)
    try:
        set_cores(0, {min(cores)})
    except OSError:  # a sandbox that forbids it: the pool as manifold3d starts it
        return
    try:
        # a boolean, not a primitive alone: manifold3d 3.0 starts its pool on the first
        # boolean
        ball = manifold3d.Manifold.sphere(1.0, 16)
        (ball ^ ball.translate((0.5, 0.0, 0.0))).volume()
    finally:
        set_cores(0, cores)


start_boolean_threads(os.environ.get(BOOLEAN_THREADS_VARIABLE, "").strip().lower() != "all")
