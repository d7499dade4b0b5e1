"""A damaged results store (issue 27, item 10): metadata that is not JSON, a zero-length
store. Each is one line (exit 2) saying what is damaged and what can be recovered; an empty
store is never taken for a new one (a resumed run would evaluate everything again)."""

from __future__ import annotations

import shutil
import sqlite3
from pathlib import Path

import pytest
from clihelp import cli, one_line, small_study

from pkmlab.study import SerialRunner, load_study, run_study


@pytest.fixture(scope="module")
def finished(tmp_path_factory) -> Path:
    tmp = tmp_path_factory.mktemp("finished")
    store = run_study(load_study(small_study(tmp)), SerialRunner())
    store.close()
    return tmp / "out"


def _copy(finished, tmp_path) -> Path:
    folder = tmp_path / "copy"
    shutil.copytree(finished, folder)
    return folder


@pytest.mark.parametrize("key", ["fingerprint", "schema"])
def test_metadata_not_json_is_named_with_what_can_be_recovered(capsys, finished, tmp_path,
                                                               key):
    folder = _copy(finished, tmp_path)
    con = sqlite3.connect(folder / "evaluations.sqlite")
    con.execute("UPDATE meta SET value = ? WHERE key = ?", ("{not json", key))
    con.commit()
    con.close()
    code, _, err = cli(capsys, "run", small_study(tmp_path, output=str(folder)), "--resume")
    one_line(code, err, "store", f"metadata '{key}' is not JSON", "5 evaluations readable")


def test_a_zero_length_store_is_not_silently_recomputed(capsys, finished, tmp_path):
    folder = _copy(finished, tmp_path)
    (folder / "evaluations.sqlite").write_bytes(b"")
    for args in (["run", small_study(tmp_path, output=str(folder)), "--resume"],
                 ["report", folder]):
        code, _, err = cli(capsys, *args)
        one_line(code, err, "store", "empty (0 bytes)", "no evaluation can be recovered",
                 "--overwrite")
        assert (folder / "evaluations.sqlite").stat().st_size == 0
