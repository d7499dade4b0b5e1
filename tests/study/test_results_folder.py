"""A study's results folder: locked until everything is written; --overwrite deletes only what
pkmlab wrote and never follows a symbolic link."""

from __future__ import annotations

import sqlite3

import pytest
from clihelp import cli, small_study

from pkmlab.errors import ParameterError
from pkmlab.study import SerialRunner, load_study, run_study
from pkmlab.study import report as report_mod
from pkmlab.study.folder import MARKER, foreign


def _evaluations(out) -> int:
    with sqlite3.connect(out / "evaluations.sqlite") as conn:
        return conn.execute("SELECT COUNT(*) FROM evaluations").fetchone()[0]


def test_the_folder_stays_locked_while_the_run_exports(capsys, tmp_path, monkeypatch):
    """A second run (--overwrite or --resume) and a report rebuild started while the first run
    writes its designs are refused; the first run's evaluations survive (deleted before)."""
    p = small_study(tmp_path)
    out = tmp_path / "out"
    real, tries = report_mod.export_designs, {}

    def export_while_others_try(*args, **kw):
        for what, call in (("overwrite", lambda: run_study(load_study(p), SerialRunner(),
                                                           overwrite=True)),
                           ("resume", lambda: run_study(load_study(p), SerialRunner(),
                                                        resume=True))):
            try:
                call()
                tries[what] = "ran"
            except ParameterError as exc:
                tries[what] = str(exc)
        tries["report"] = cli(capsys, "report", out)
        return real(*args, **kw)

    monkeypatch.setattr(report_mod, "export_designs", export_while_others_try)
    code, _, err = cli(capsys, "run", p)
    assert code == 0, err
    assert "in use by pid" in tries["overwrite"] and "in use by pid" in tries["resume"], tries
    code, _, err = tries["report"]
    assert code == 2 and "in use by pid" in err, err
    assert _evaluations(out) == 5          # the baseline and the 4 Sobol candidates
    assert (out / "report.html").is_file() and (out / "designs" / "index.json").is_file()


def _unrelated(tmp_path):
    other = tmp_path / "someone-elses"
    (other / "sub").mkdir(parents=True)
    (other / "thesis.tex").write_text("keep me")
    (other / "sub" / "data.csv").write_text("1,2\n")
    return other


def _intact(other) -> bool:
    return ((other / "thesis.tex").read_text() == "keep me"
            and (other / "sub" / "data.csv").read_text() == "1,2\n")


def test_overwrite_through_a_symlinked_folder_of_other_files_is_refused(capsys, tmp_path):
    other = _unrelated(tmp_path)
    (tmp_path / "out").symlink_to(other, target_is_directory=True)
    code, _, err = cli(capsys, "run", small_study(tmp_path))
    assert code == 2 and "files pkmlab did not write" in err, err
    assert sorted(p.name for p in other.iterdir()) == ["sub", "thesis.tex"]   # not even a lock
    code, _, err = cli(capsys, "run", small_study(tmp_path), "--overwrite")
    assert code == 2 and err.count("error:") == 1 and err.endswith("marker)'\n"), err
    assert "--overwrite" in err and "only what pkmlab wrote" in err and "sub" in err, err
    assert _intact(other) and sorted(p.name for p in other.iterdir()) == ["sub", "thesis.tex"]


@pytest.mark.parametrize("plant", ["top-level file", "file in a design", "link in designs",
                                   "folder in designs"])
def test_overwrite_refuses_a_run_folder_holding_other_files(capsys, tmp_path, plant):
    p = small_study(tmp_path)
    out = tmp_path / "out"
    code, _, err = cli(capsys, "run", p)
    assert code == 0, err
    assert (out / MARKER).is_file() and foreign(out) is None
    design = next(d for d in (out / "designs").iterdir() if d.is_dir())
    other = _unrelated(tmp_path)
    planted = {"top-level file": out / "notes.txt", "file in a design": design / "notes.txt",
               "link in designs": out / "designs" / "mine", "folder in designs":
               out / "designs" / "drafts"}[plant]
    if plant == "link in designs":
        planted.symlink_to(other, target_is_directory=True)
    elif plant == "folder in designs":
        planted.mkdir()
    else:
        planted.write_text("mine")
    before = _evaluations(out)
    code, _, err = cli(capsys, "run", p, "--overwrite")
    assert code == 2 and planted.name in err and "only what pkmlab wrote" in err, err
    assert planted.exists() or planted.is_symlink()
    assert _intact(other) and _evaluations(out) == before      # nothing was deleted


def test_overwrite_replaces_a_run_folder_including_an_interrupted_export(capsys, tmp_path):
    p = small_study(tmp_path)
    out = tmp_path / "out"
    assert cli(capsys, "run", p)[0] == 0
    # what a killed run leaves: atomic writes' scratch files (tempfile's 8 random characters)
    (out / ".summary.md.x1y2_9zq.part").write_text("half")
    (out / "designs" / ".index.json.abcdefgh.part").write_text("half")
    (out / "designs" / "07-0123abcd").mkdir()
    code, _, err = cli(capsys, "run", p, "--overwrite")
    assert code == 0, err
    assert not (out / ".summary.md.x1y2_9zq.part").exists()
    assert not (out / "designs" / "07-0123abcd").exists()
    assert not (out / "designs" / ".index.json.abcdefgh.part").exists()
    assert _evaluations(out) == 5 and foreign(out) is None


@pytest.mark.parametrize("plant", [".partial-mydata/thesis.tex", ".mine.part",
                                   ".notes.txt.abcdefgh.part", "designs/.partial-x/a.png"])
def test_overwrite_refuses_user_files_named_like_scratch_files(capsys, tmp_path, plant):
    """Only the scratch files pkmlab's own atomic writes leave count as pkmlab's (any
    '.partial-*' folder or '*.part' file was taken, and deleted, before)."""
    p = small_study(tmp_path)
    out = tmp_path / "out"
    assert cli(capsys, "run", p)[0] == 0
    planted = out / plant
    planted.parent.mkdir(parents=True, exist_ok=True)
    planted.write_text("precious")
    code, _, err = cli(capsys, "run", p, "--overwrite")
    assert code == 2 and "only what pkmlab wrote" in err, err
    assert planted.read_text() == "precious"


def test_overwrite_accepts_meshes_of_a_registered_format(capsys, tmp_path):
    """A study writes every registered mesh format; --overwrite must know them as pkmlab's."""
    from clihelp import off_bytes as _off

    from pkmlab.export import EXPORTERS, Exporter, register_exporter

    register_exporter(Exporter("off", "mesh", "Object File Format text in mm", _off,
                               trimesh=False))
    try:
        p = small_study(tmp_path)
        assert cli(capsys, "run", p)[0] == 0
        assert list((tmp_path / "out" / "designs").glob("*/workspace.off"))
        code, _, err = cli(capsys, "run", p, "--overwrite")
        assert code == 0, err
    finally:
        EXPORTERS.pop("off")
