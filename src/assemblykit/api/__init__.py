"""The objects of the public API (docs/tutorial.md §4): a task that solves itself, an
assembly that finds its own contacts, and a planar assembly of polygons.

:mod:`assemblykit.model` holds plain values and every algorithm is a function of the
package that implements it (network reduction in :mod:`assemblykit.inference`, contacts
and surfaces in :mod:`assemblykit.geometry.contacts`). As trimesh's ``Trimesh`` sits
above its algorithm modules, the classes here extend those values with methods that
call the functions, above every other layer: :class:`~assemblykit.api.task.Task`
(returned by :func:`~assemblykit.api.task.load_task`) and
:class:`~assemblykit.api.assembly.Assembly` (returned by
:func:`~assemblykit.api.assembly.load_assembly`). They are still the model values: every
function of the package takes them. The two live in separate modules so that reading
and solving a task never imports the mesh geometry.
"""
