"""The built-in mesh formats, each in its own unit convention, registered as any exporter is.

* ``stl`` — binary STL in mm, the unit stated in the 80-byte header (:data:`STL_HEADER`),
  written straight from the triangles (no trimesh import: part of a cold ``pkmlab workspace``);
* ``ply`` — binary PLY in mm (a ``comment units mm`` header line), vertex colours and named
  float32 vertex values (a metric per vertex);
* ``glb`` — glTF binary in glTF's convention, metres and +y up (x, y, z → x, z, −y), with
  vertex colours.
"""

from __future__ import annotations

import numpy as np

from .registry import Exporter, register_exporter

__all__ = ["STL_HEADER", "stl_bytes", "TO_GLTF"]

#: The 80-byte header of the binary STL files pkmlab writes (never starting with "solid").
STL_HEADER = b"pkmlab workspace boundary; units: mm"
#: mm, z up → glTF's metres, y up
TO_GLTF = [[1e-3, 0, 0, 0], [0, 0, 1e-3, 0], [0, -1e-3, 0, 0], [0, 0, 0, 1]]


def stl_bytes(vertices: np.ndarray, faces: np.ndarray) -> bytes:
    """Binary STL of a triangle mesh (mm, stated in the header): float32 unit normals (zero
    for a degenerate triangle) and vertices, as trimesh writes them, without importing trimesh
    (0.5 s of a cold ``pkmlab workspace``, scipy.spatial included)."""
    tri = np.asarray(vertices, dtype=np.float64)[np.asarray(faces)]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(normal, axis=1)
    ok = length > 0
    normal[ok] /= length[ok, None]
    normal[~ok] = 0.0
    rec = np.zeros(len(tri), dtype=[("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)),
                                    ("attributes", "<u2")])
    rec["normal"] = normal
    rec["vertices"] = tri
    return STL_HEADER.ljust(80, b" ") + np.uint32(len(tri)).tobytes() + rec.tobytes()


def _stl(mesh) -> bytes:
    return stl_bytes(mesh.vertices, mesh.faces)


def _coloured(mesh, colors):
    mesh = mesh.copy()
    if colors is not None:
        mesh.visual.vertex_colors = colors
    return mesh


def _ply(mesh, colors=None, values: dict | None = None) -> bytes:
    mesh = _coloured(mesh, colors)
    for name, v in (values or {}).items():
        v = np.asarray(v, dtype=np.float32)
        if v.shape != (len(mesh.vertices),):
            raise ValueError(f"vertex values {name!r}: shape {v.shape}, expected "
                             f"({len(mesh.vertices)},)")
        mesh.vertex_attributes[name] = v
    data = mesh.export(file_type="ply", encoding="binary")
    head, sep, rest = data.partition(b"\n")            # "ply"
    fmt, sep2, rest = rest.partition(b"\n")            # "format ..."
    return head + sep + fmt + sep2 + b"comment units mm\n" + rest


def _glb(mesh, colors=None) -> bytes:
    mesh = _coloured(mesh, colors)
    mesh.apply_transform(TO_GLTF)
    return mesh.export(file_type="glb")


for _ex in (
        Exporter("stl", "mesh", "binary STL in mm (the unit in its header)", _stl,
                 trimesh=False),
        Exporter("ply", "mesh", "binary PLY in mm, vertex colours and per-vertex metric values "
                 "as properties", _ply, options={"colors", "values"}),
        Exporter("glb", "mesh", "glTF binary in metres (y up), coloured by the metric", _glb,
                 options={"colors"})):
    register_exporter(_ex)
