"""``pkmlab export``: a mechanism file, or any evaluated candidate of a study, in a simulator
or CAD format of the exporter registry (the formats of subject ``mechanism``)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape

from ..errors import ParameterError
from .common import JsonOpt, _emit, _fail, _load, app, out


@app.command("export")
def export_cmd(
    source: Annotated[Path, typer.Argument(help="a mechanism YAML file or a study's results "
                                                "folder (then --seq)")],
    fmt: Annotated[str, typer.Option("--format", "-f", help="mjcf, urdf, joints or step (the "
                                     "mechanism formats of the exporter registry)")],
    seq: Annotated[int | None, typer.Option(help="the candidate's number in a results folder "
                                            "(evaluations.csv 'seq'), feasible or not")] = None,
    output: Annotated[Path | None, typer.Option("--out", "-o", help="output folder (default: "
                                                "the current folder)")] = None,
    as_json: JsonOpt = False,
) -> None:
    """Write a mechanism (or a study's candidate) as MJCF, URDF, joint frames or STEP."""
    from ..export import export_mechanism
    from ..runtime.memory import FORMAT_BYTES, format_bytes, require

    # the CAD kernel (OCP) that writes STEP: the bulk of a step export's memory
    require("--format", FORMAT_BYTES.get(fmt, 0), "an export whose memory would",
            f"{fmt} ({format_bytes(FORMAT_BYTES.get(fmt, 0))} beside the command's own)")
    mass, stem, extra = None, None, []
    if source.is_dir():
        from ..study.candidates import candidate, candidate_mechanism, mass_model
        from .study import _open_results

        if seq is None:
            _fail(ParameterError("--seq", "a candidate's number with a results folder", None))
        study, records = _open_results(source)
        try:
            rec = candidate(records, seq)
        except ParameterError as exc:
            _fail(exc)
        stem = f"{study.name}-seq{seq}"
        mech = candidate_mechanism(study, rec, stem)
        mass = mass_model(study)
        extra.append(_candidate_yaml(study, rec, stem, output or Path(".")))
    else:
        if seq is not None:
            _fail(ParameterError("--seq", "only with a results folder", seq))
        mech = _load(source)
    try:
        paths = export_mechanism(mech, fmt, output or Path("."), stem=stem, mass=mass)
    except ParameterError as exc:
        _fail(exc)
    files = [str(p) for p in extra + paths]
    if as_json:
        _emit({"format": fmt, "files": files, "mechanism": mech.name, "family": mech.family})
        return
    for f in files:
        out.print(escape(f"wrote {f}"), highlight=False)


def _candidate_yaml(study, rec, stem: str, folder: Path) -> Path:
    """The candidate's mechanism YAML beside the export (mm and degrees)."""
    import json

    import yaml

    from ..config import to_display
    from ..runtime.atomic import write_text
    from ..study.candidates import mechanism_spec

    spec = mechanism_spec(study, rec, stem)
    status = rec["status"] + (f" ({rec['reason']})" if rec.get("reason") else "")
    folder.mkdir(parents=True, exist_ok=True)
    plain = json.loads(json.dumps(to_display(spec), default=float))
    return write_text(folder / f"{stem}.yaml",
                      f"# Candidate {rec['seq']} of study {study.name} (key {rec['key']}), "
                      f"status {status}. Lengths in mm, angles in degrees.\n"
                      + yaml.safe_dump(plain, sort_keys=False, allow_unicode=True))
