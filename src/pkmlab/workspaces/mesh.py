"""Boundary meshes of workspaces by marching cubes on the stored signed field."""

from __future__ import annotations

import numpy as np

__all__ = ["boundary_mesh"]


def boundary_mesh(result):
    """Watertight triangle mesh (``trimesh.Trimesh``, mm) of ``result``'s kept workspace.

    The field is padded by one outside layer so that every surface closes. Marching cubes
    places the surface at the field's zero crossing: exactly at the column interval ends in z
    (the field is the z distance there) and half-way between an inside and an outside column
    in x and y, which is the same footprint the column volume integrates.
    """
    import trimesh
    from skimage.measure import marching_cubes

    from ..errors import NumericalError

    problem = result.mesh_problem
    if problem is not None:           # marching cubes needs a grid point inside
        raise NumericalError("mesh", problem)
    h = result.resolution
    f = np.pad(result.field, 1, constant_values=-h)
    verts, faces, _, _ = marching_cubes(f, level=0.0, spacing=(h, h, h))
    origin = np.array([result.xs[0], result.ys[0], result.zs[0]]) - h
    mesh = trimesh.Trimesh(vertices=verts + origin, faces=faces, process=True)
    if mesh.volume < 0:
        mesh.invert()
    return mesh
