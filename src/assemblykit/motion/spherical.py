"""The region where a ball touches its socket, for the unilateral reading.

A spherical contact (:class:`~assemblykit.geometry.contacts.CurvedPatch` of kind
``spherical``) carries the vertices of *both* spherical surfaces. The fit (seed 003: a
ball in a socket keeps S(c)) does not depend on where they touch, but the push-only
reading does: the ball is pushed only where the socket's surface is, so a cup shallower
than a hemisphere lets it lift out. The two surfaces are concentric with equal radii,
so a point of one lies on the other iff its direction from the centre lies in the other
surface's *direction region*: the union of the spherical triangles that the centre
projects its triangles to. The contact region is the vertices of each surface inside
the other's region (for a whole ball in a cup: the cup, bounded by its rim cone).

Membership of a unit direction d in the spherical triangle (a, b, c): d is on the
inner side of the three great circles through its edges, det(a, b, d), det(b, c, d),
det(c, a, d) having the sign of det(a, b, c), and d · (a + b + c) > 0 (the triangle's
hemisphere, which rules out the antipodal triangle).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Sequence

import numpy as np
from numpy.typing import NDArray

from assemblykit.geometry.contacts import Contact, CurvedPatch
from assemblykit.model.assembly import Assembly
from assemblykit.tolerance import Tolerance

# directions tested against all triangles at once; bounds the temporary arrays
CHUNK = 256


def _unit(vectors: NDArray[np.float64]) -> NDArray[np.float64]:
    return vectors / np.linalg.norm(vectors, axis=-1, keepdims=True)


def in_region(
    directions: NDArray[np.float64], corners: NDArray[np.float64], tol: Tolerance
) -> NDArray[np.bool_]:
    """For each unit direction (n x 3), whether it lies in one of the spherical triangles
    with unit ``corners`` (t x 3 x 3), boundaries included within the angle tolerance
    (module docstring). Triangles of zero spherical area cover nothing and are dropped."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    orientation = np.einsum("ij,ij->i", np.cross(a, b), c)
    kept = np.abs(orientation) > tol.angle**2
    a, b, c, sign = a[kept], b[kept], c[kept], np.sign(orientation[kept])
    planes = np.stack([np.cross(a, b), np.cross(b, c), np.cross(c, a)]) * sign[None, :, None]
    middle = a + b + c
    inside = np.zeros(len(directions), dtype=bool)
    for start in range(0, len(directions), CHUNK):
        d = directions[start : start + CHUNK]
        sides = np.einsum("ktj,nj->knt", planes, d)
        ahead = d @ middle.T > 0
        inside[start : start + CHUNK] = np.any(np.all(sides >= -tol.angle, axis=0) & ahead, axis=1)
    return inside


def _sphere_triangles(
    assembly: Assembly, name: str, patch: CurvedPatch, convex: bool, tol: Tolerance
) -> NDArray[np.float64]:
    """The triangles (t x 3 x 3, world) of part ``name``'s spherical surfaces on the
    patch's sphere with the given side (a split sphere is several surfaces)."""
    mesh = assembly.part(name).mesh
    faces = [
        s.faces
        for s in assembly.surfaces(name, tol)
        if s.kind == "sphere"
        and s.convex == convex
        and np.linalg.norm(s.point - patch.center) <= tol.length
        and abs(s.radius - patch.radius) <= tol.length
    ]
    if not faces:
        return np.zeros((0, 3, 3))
    triangles = np.asarray(mesh.faces, dtype=np.int64)[np.concatenate(faces)]
    return np.asarray(mesh.vertices, dtype=np.float64)[triangles]


def sphere_contact_points(
    assembly: Assembly, contact: Contact, patch: CurvedPatch, tol: Tolerance
) -> NDArray[np.float64] | None:
    """The vertices of the two spherical surfaces of ``patch`` that lie on both (module
    docstring), in world coordinates; ``None`` when a side's surface is not found."""
    sides = [
        _sphere_triangles(assembly, name, patch, name == patch.inner, tol)
        for name in (contact.a, contact.b)
    ]
    if any(len(t) == 0 for t in sides):
        return None
    found = []
    for mine, other in (sides, sides[::-1]):
        points = np.unique(mine.reshape(-1, 3), axis=0)
        inside = in_region(_unit(points - patch.center), _unit(other - patch.center), tol)
        found.append(points[inside])
    return np.vstack(found)


def with_sphere_regions(
    assembly: Assembly, contacts: Iterable[Contact], tol: Tolerance
) -> list[Contact]:
    """The contacts with every spherical patch's ``points`` narrowed to the contact
    region (:func:`sphere_contact_points`); other patches are kept as they are."""

    def narrowed(contact: Contact) -> Sequence[CurvedPatch]:
        patches = []
        for patch in contact.curved:
            if patch.kind == "spherical":
                region = sphere_contact_points(assembly, contact, patch, tol)
                if region is not None:
                    patch = dataclasses.replace(patch, points=region)
            patches.append(patch)
        return tuple(patches)

    return [
        dataclasses.replace(contact, curved=narrowed(contact))
        if any(p.kind == "spherical" for p in contact.curved)
        else contact
        for contact in contacts
    ]
