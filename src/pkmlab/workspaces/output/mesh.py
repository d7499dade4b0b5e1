"""Boundary meshes of workspaces by marching cubes on the stored signed field; their files are
written by the exporter registry (:mod:`pkmlab.export`), in each format's unit convention."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...export.meshes import STL_HEADER, TO_GLTF, stl_bytes
from ...runtime.atomic import write_bytes

__all__ = ["merged_mesh", "boundary_triangles", "stl_bytes", "write_mesh", "write_scene",
           "STL_HEADER"]

#: voxels per marching-cubes slab
_MESH_SLAB = 4_000_000


def boundary_triangles(result) -> tuple[np.ndarray, np.ndarray]:
    """Vertices ``(n, 3)`` (mm) and faces ``(m, 3)`` of ``result``'s kept workspace boundary,
    oriented outward (positive enclosed volume); vertices shared between the marching-cubes
    slabs are not merged (:func:`merged_mesh` merges them).

    The field is padded by one outside layer so that every surface closes. Marching cubes
    places the surface at the field's zero crossing: exactly at the column interval ends in z
    (the field is the z distance there) and half-way between an inside and an outside column
    in x and y, which is the same footprint the column volume integrates.
    """
    from skimage.measure import marching_cubes

    from ...errors import NumericalError

    problem = result.mesh_problem
    if problem is not None:           # marching cubes needs a grid point inside
        raise NumericalError("mesh", problem)
    h = result.resolution
    field = result.field
    nx, ny, nz = field.shape
    # x slabs of the padded field, one plane of overlap: bounded memory; the shared planes'
    # vertices coincide exactly
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
    vertices = np.concatenate(verts).astype(np.float64) + origin
    faces = np.concatenate(faces).astype(np.int64)
    if _signed_volume(vertices, faces) < 0:
        faces = np.ascontiguousarray(faces[:, ::-1])
    return vertices, faces


def _signed_volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    """Enclosed volume by the divergence theorem (positive for outward faces)."""
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    return float(np.einsum("ij,ij->", a, np.cross(b, c)) / 6.0)


def merged_mesh(vertices: np.ndarray, faces: np.ndarray):
    """Watertight ``trimesh.Trimesh`` (mm) of :func:`boundary_triangles`' output, the slabs'
    shared vertices merged."""
    import trimesh

    return trimesh.Trimesh(vertices=vertices, faces=faces, process=True)


def write_mesh(mesh, path, colors=None, values: dict | None = None) -> Path:
    """Write ``mesh`` (mm) to ``path`` atomically, in the registered format of its suffix
    (:mod:`pkmlab.export`: .stl, .ply, .glb built in), each in its own unit convention;
    ``colors`` and ``values`` go to the formats that take them."""
    from ...export import write

    return write(mesh, path, colors=colors, values=values)


def write_scene(parts: dict, path) -> Path:
    """Several meshes (mm) in one glTF binary scene, metres and +y up as :func:`write_mesh`:
    ``parts`` is ``{name: (trimesh.Trimesh, (r, g, b, a) uint8 colour)}`` (e.g. a workspace
    and a required task region inside it)."""
    import trimesh

    scene = trimesh.Scene()
    for name, (mesh, colour) in parts.items():
        m = mesh.copy()
        m.visual = trimesh.visual.ColorVisuals(m, face_colors=np.tile(colour, (len(m.faces), 1)))
        m.apply_transform(TO_GLTF)
        scene.add_geometry(m, node_name=name, geom_name=name)
    return write_bytes(Path(path), scene.export(file_type="glb"))
