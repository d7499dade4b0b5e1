"""The mechanism formats (subject ``"mechanism"``), registered as any exporter is, and
:func:`export_mechanism`, which writes one of them for a mechanism.

* ``mjcf`` — MuJoCo MJCF, closed loops (:mod:`.mjcf`);
* ``urdf`` — URDF spanning tree with loop-closure frames (:mod:`.urdf`);
* ``joints`` — joint frames as CSV and JSON (:mod:`.jointframes`);
* ``step`` — CAD skeleton, STEP in mm (:mod:`.step`; the optional extra ``cad``).

Each writer takes ``(mech, pose=None, mass=None)``: the pose to export at (default the
nominal pose) and a :class:`.model.MassModel`.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import ParameterError
from .registry import Exporter, exporters, register_exporter

__all__ = ["export_mechanism", "mechanism_formats"]


def _mjcf(mech, pose=None, mass=None) -> bytes:
    from .mjcf import mjcf_text

    return mjcf_text(mech, pose, mass).encode()


def _urdf(mech, pose=None, mass=None) -> bytes:
    from .urdf import urdf_text

    return urdf_text(mech, pose, mass).encode()


def _joints(mech, pose=None, mass=None) -> dict[str, bytes]:
    from .jointframes import joints_files

    return joints_files(mech, pose, mass)


def _step(mech, pose=None, mass=None) -> bytes:
    from .step import step_bytes

    return step_bytes(mech, pose, mass)


_OPTIONS = {"pose", "mass"}
for _ex in (
        Exporter("mjcf", "mechanism", "MuJoCo model (MJCF XML, m/kg/s): closed loops by "
                 "connect/weld equalities, position servos, a tool site", _mjcf,
                 options=_OPTIONS, files=(".mjcf.xml",)),
        Exporter("urdf", "mechanism", "URDF spanning tree (m/kg) with loop-closure frames "
                 "(<pkmlab:loop_closure>)", _urdf, options=_OPTIONS, files=(".urdf",)),
        Exporter("joints", "mechanism", "joint frames at the exported pose (mm, unit axes), "
                 "CSV and JSON", _joints, options=_OPTIONS,
                 files=(".joints.csv", ".joints.json")),
        Exporter("step", "mechanism", "CAD skeleton (STEP AP214, mm): plates, joint spheres, "
                 "link cylinders", _step, options=_OPTIONS, files=(".step",),
                 requires="build123d")):
    register_exporter(_ex)


def mechanism_formats(study: bool | None = None) -> dict[str, Exporter]:
    return exporters("mechanism", study=study)


def export_mechanism(mech, fmt: str, out: str | Path, *, stem: str | None = None, pose=None,
                     mass=None) -> list[Path]:
    """Write ``mech`` in format ``fmt`` into the folder ``out`` as ``<stem><suffix>`` for
    each of the format's files (``stem`` default: the mechanism's name or family); returns
    the paths. A format whose optional extra is missing raises a ParameterError saying so."""
    from ..runtime.atomic import write_bytes

    ex = mechanism_formats().get(fmt)
    if ex is None:
        raise ParameterError("format", f"one of {', '.join(mechanism_formats())}", fmt)
    ok, why = ex.available()
    if not ok:
        raise ParameterError("format", "a format whose package is installed", why)
    data = ex.write(mech, pose=pose, mass=mass)
    if isinstance(data, bytes):
        data = {ex.suffix: data}
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    stem = stem or mech.name or mech.family
    return [write_bytes(out / f"{stem}{sfx}", blob) for sfx, blob in data.items()]
