"""Boundary meshes of workspaces by marching cubes on the stored signed field."""

from __future__ import annotations

import numpy as np

__all__ = ["boundary_mesh"]

#: voxels per marching-cubes slab
_MESH_SLAB = 4_000_000


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
    field = result.field
    nx, ny, nz = field.shape
    # x slabs of the padded field, one plane of overlap: bounded memory; the shared planes'
    # vertices coincide exactly and are merged below
    per = max(2, _MESH_SLAB // ((ny + 2) * (nz + 2)))
    verts, faces, count, i0 = [], [], 0, -1
    while True:
        i1 = min(i0 + per, nx)                       # planes i0..i1 (x index; -1, nx: pad)
        block = np.full((i1 - i0 + 1, ny + 2, nz + 2), -h, dtype=np.float32)
        a, b = max(i0, 0), min(i1, nx - 1)
        if a <= b:
            block[a - i0:b - i0 + 1, 1:-1, 1:-1] = field[a:b + 1]
        if block.max() > 0:
            v, f, _, _ = marching_cubes(block, level=0.0, spacing=(h, h, h))
            v[:, 0] += i0 * h
            verts.append(v)
            faces.append(f + count)
            count += len(v)
        if i1 >= nx:
            break
        i0 = i1
    origin = np.array([result.xs[0], result.ys[0] - h, result.zs[0] - h])
    mesh = trimesh.Trimesh(vertices=np.concatenate(verts) + origin,
                           faces=np.concatenate(faces), process=True)
    if mesh.volume < 0:
        mesh.invert()
    return mesh
