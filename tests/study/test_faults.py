"""Faults and hostile input: every one ends in one line and exit 2 (or is data with a reason),
never a traceback. Kill -9, Ctrl-C, concurrent runs, damaged stores, read-only and missing
folders, a full disk, memory budgets, thin and singular workspaces."""

from __future__ import annotations

import errno
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest
from clihelp import GS, HW, LUZI, cli, error_lines, mech_file, one_line, small_study

from pkmlab.study import SerialRunner, load_study, run_study

# ---- 1. memory budget --------------------------------------------------------------------------

def test_a_grid_over_the_memory_budget_is_refused_with_a_coarser_suggestion(capsys, tmp_path):
    code, _, err = cli(capsys, "workspace", LUZI, "--resolution", "0.05", "--out", tmp_path)
    line = one_line(code, err, "resolution", "fit in", "try >=", "needing")
    assert "GiB" in line and not any(tmp_path.iterdir())


def test_memory_limit_env_applies_to_every_grid(capsys, tmp_path, monkeypatch):
    code, _, err = cli(capsys, "workspace", LUZI, "--resolution", "2.5", "--out", tmp_path,
                       env={"PKMLAB_MEMORY_LIMIT": "1GiB"}, monkeypatch=monkeypatch)
    one_line(code, err, "resolution", "fit in 1 GiB", "try >=")
    # a budget below the command's own fixed memory: no resolution would do (issue 27)
    code, _, err = cli(capsys, "workspace", HW, "--resolution", "2.5", "--out", tmp_path,
                       env={"PKMLAB_MEMORY_LIMIT": "1MiB"}, monkeypatch=monkeypatch)
    one_line(code, err, "PKMLAB_MEMORY_LIMIT", "fit in 1 MiB", "workspace alone needs")
    code, _, err = cli(capsys, "workspace", HW, "--out", tmp_path,
                       env={"PKMLAB_MEMORY_LIMIT": "lots"}, monkeypatch=monkeypatch)
    one_line(code, err, "PKMLAB_MEMORY_LIMIT")


def test_a_huge_nsga2_population_is_refused_at_validate(capsys, tmp_path):
    p = small_study(tmp_path, optimizer={"method": "nsga2", "population": 100000,
                                         "generations": 2})
    code, _, err = cli(capsys, "validate", p)
    one_line(code, err, "optimizer.population", "try <=", "GiB")


def test_sampled_workspace_is_streamed_into_column_runs():
    """The sampled method keeps (nx, ny, K) runs, not a dense grid, and crops to the kept
    footprint: the arrays scale with the footprint."""
    import pkmlab
    from pkmlab.workspaces import workspace

    m = pkmlab.load_mechanism(LUZI)
    res = workspace(m, "constant", resolution=20.0)
    assert res.method == "sampled voxels" and res.lo is not None and res.voxel_field is None
    assert res.lo.shape[:2] == (len(res.xs), len(res.ys)) and res.lo.shape[2] <= 8
    assert res.volume == pytest.approx(res.occupancy.sum() * 20.0 ** 3)


def test_luzi_at_default_resolution_size_estimate_fits_two_gib():
    """The Luzi grid at 2.5 mm (674 × 689 columns) is estimated well under 2 GiB (the dense
    float grid it used to allocate was 3.7 GiB); the measured peak is in the report."""
    from pkmlab.workspaces.engine import estimate_bytes

    assert estimate_bytes(674, 689, 961, 1, False, False) < 1.0 * 2**30


# ---- 2. thin workspaces ------------------------------------------------------------------------

def test_thin_workspace_has_no_mesh_but_a_reason(capsys, tmp_path):
    code, out, err = cli(capsys, "workspace", HW, "--kind", "dexterous", "--box", "23,23,23",
                         "--resolution", "2.5", "--out", tmp_path / "w")
    assert code == 0, err
    assert "no mesh written" in " ".join(out.split())
    assert not (tmp_path / "w" / "workspace.stl").exists()
    code, out, err = cli(capsys, "dexterity", HW, "--box", "23,23,23", "--resolution", "2.5",
                         "--out", tmp_path / "d")
    assert code == 0, err
    assert "no aggregates" in out


# ---- 3. unreachable nominal pose, absurd values -------------------------------------------------

@pytest.mark.parametrize("command", [["inspect"], ["fk", "--actuators", "1,1,1,1,1,1"],
                                     ["dexterity"], ["compare"]])
def test_unreachable_nominal_pose_is_one_line(capsys, tmp_path, command):
    bad = mech_file(tmp_path, GS, stroke="[1 mm, 2 mm]")
    extra = ["--out", tmp_path / "o"] if command[0] in ("dexterity", "compare") else []
    code, _, err = cli(capsys, command[0], bad, *command[1:], *extra)
    one_line(code, err, "stroke", "mid-point is reachable")


@pytest.mark.parametrize("field,value", [("link_length", "1e308"), ("stroke", "[0, 1e300]")])
def test_absurd_lengths_name_their_field(capsys, tmp_path, field, value):
    bad = mech_file(tmp_path, HW, **{field: value})
    code, _, err = cli(capsys, "inspect", bad)
    one_line(code, err, field, "at most 1e+06 mm")


@pytest.mark.parametrize("option,value", [("--segment-time", "1e-300"), ("--payload", "-1"),
                                          ("--max-speed", "-5"), ("--max-force", "nan")])
def test_absurd_trajectory_options_name_the_option_typed(capsys, tmp_path, option, value):
    """The error names the option the user typed, not the library's argument name."""
    code, _, err = cli(capsys, "trajectory", HW, "--paper-motion", option, value,
                       "--out", tmp_path)
    line = one_line(code, err, f"error: {option}: must be", f"got {value}")
    assert "_" not in line.split(":")[1], line


@pytest.mark.parametrize("args,field", [
    (["workspace", "--link-diameter", "-1"], "--link-diameter"),
    (["workspace", "--joint-limit", "1,x"], "--joint-limit[1]"),
    (["workspace", "--kappa-max", "0"], "--kappa-max"),
    (["workspace", "--stroke", "5,1"], "--stroke"),
    (["workspace", "--resolution", "1e-300"], "--resolution"),
    (["compare", "--resolution", "-3"], "--resolution"),
    (["dexterity", "--metric", "foo"], "--metric")])
def test_bad_options_name_the_option_typed(capsys, tmp_path, args, field):
    code, _, err = cli(capsys, args[0], HW, *args[1:], "--out", tmp_path)
    one_line(code, err, f"error: {field}: must be")


def test_unreachable_dask_scheduler_is_one_line_quickly(capsys, tmp_path):
    pytest.importorskip("distributed")
    p = small_study(tmp_path)
    t = time.perf_counter()
    code, _, err = cli(capsys, "run", p, "--backend", "dask", "--scheduler", "tcp://127.0.0.1:9")
    one_line(code, err, "--scheduler", "reachable")
    assert time.perf_counter() - t < 25


# ---- 5. paths ----------------------------------------------------------------------------------

def test_study_name_cannot_climb_out(capsys, tmp_path):
    for name in ("..", ".", ".hidden"):
        code, _, err = cli(capsys, "validate", small_study(tmp_path, study=name))
        one_line(code, err, "study")


@pytest.mark.parametrize("where", ["cwd", "study dir", "parent", "root"])
def test_output_cannot_be_a_folder_holding_other_things(tmp_path, monkeypatch, where):
    from pkmlab.errors import ParameterError

    work = tmp_path / "a" / "b"
    work.mkdir(parents=True)
    (work / "precious.txt").write_text("keep me")
    monkeypatch.chdir(work)
    out = {"cwd": str(work), "study dir": ".", "parent": "..", "root": "/"}[where]
    p = small_study(work, output=out)
    with pytest.raises(ParameterError, match="output"):
        run_study(load_study(p), SerialRunner(), overwrite=True)
    assert (work / "precious.txt").read_text() == "keep me"


# ---- 4. file-system faults ---------------------------------------------------------------------

def test_a_file_in_place_of_the_output_folder(capsys, tmp_path):
    (tmp_path / "out").write_text("not a folder")
    code, _, err = cli(capsys, "run", small_study(tmp_path))
    one_line(code, err)


def test_a_full_disk_while_storing_is_one_line(capsys, tmp_path, monkeypatch):
    from pkmlab.study import store as store_mod

    def full(*a, **k):
        raise sqlite3.OperationalError("database or disk is full")

    monkeypatch.setattr(store_mod.Store, "put", full)
    code, _, err = cli(capsys, "run", small_study(tmp_path))
    one_line(code, err, "disk is full")


def test_a_full_disk_while_writing_the_report_is_one_line(capsys, tmp_path, monkeypatch):
    from pkmlab.study import report as report_mod

    def full(*a, **k):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(tmp_path / "out"))

    monkeypatch.setattr(report_mod, "write_report", full)
    monkeypatch.setattr("pkmlab.cli.study.write_report", full, raising=False)
    code, _, err = cli(capsys, "run", small_study(tmp_path))
    one_line(code, err, "No space left on device")


@pytest.fixture(scope="module")
def finished(tmp_path_factory) -> Path:
    tmp = tmp_path_factory.mktemp("finished")
    store = run_study(load_study(small_study(tmp)), SerialRunner())
    store.close()
    return tmp / "out"


def test_wal_is_checkpointed_so_the_sqlite_file_alone_holds_everything(finished, tmp_path):
    import shutil

    shutil.copy(finished / "evaluations.sqlite", tmp_path / "copy.sqlite")
    con = sqlite3.connect(tmp_path / "copy.sqlite")
    n = con.execute("SELECT COUNT(*) FROM evaluations").fetchone()[0]
    con.close()
    assert n == 5            # baseline + 4 samples, none left behind in -wal


@pytest.mark.parametrize("damage", ["truncated", "garbage", "schema", "empty"])
def test_damaged_store_is_diagnosed(capsys, finished, tmp_path, damage):
    import shutil

    folder = tmp_path / "copy"
    shutil.copytree(finished, folder)
    db = folder / "evaluations.sqlite"
    data = db.read_bytes()
    if damage == "truncated":
        db.write_bytes(data[: len(data) // 3])
    elif damage == "garbage":
        db.write_bytes(data[:4096] + os.urandom(len(data) - 4096))
    elif damage == "schema":
        con = sqlite3.connect(db)
        con.execute("DROP TABLE evaluations")
        con.execute("CREATE TABLE evaluations (x)")
        con.commit()
        con.close()
    else:
        db.write_bytes(b"")
    runs = [["report", folder], ["run", small_study(tmp_path, output=str(folder)), "--resume"]]
    for args in runs:
        code, _, err = cli(capsys, *args)
        assert code == 2, (args, err)
        assert "Traceback" not in err and len(error_lines(err)) == 1, err


def test_report_works_on_a_read_only_finished_folder(capsys, finished, tmp_path):
    import shutil

    folder = tmp_path / "ro"
    shutil.copytree(finished, folder)
    for f in folder.rglob("*"):
        if f.is_file():
            f.chmod(0o444)
    # the store is opened read-only: nothing is written into the database or a -wal file
    before = (folder / "evaluations.sqlite").read_bytes()
    code, _, err = cli(capsys, "report", folder)
    assert code == 0, err
    assert not (folder / "evaluations.sqlite-wal").exists()
    assert (folder / "evaluations.sqlite").read_bytes() == before


def test_read_only_output_folder_is_one_line(capsys, tmp_path, monkeypatch):
    real_open = open

    def ro_mkdir(self, *a, **k):
        raise PermissionError(errno.EROFS, os.strerror(errno.EROFS), str(self))

    monkeypatch.setattr(Path, "mkdir", ro_mkdir)
    code, _, err = cli(capsys, "run", small_study(tmp_path))
    one_line(code, err, "file system")
    del real_open


# ---- 4b. real file-system faults on a small tmpfs ------------------------------------------------

@pytest.fixture
def tmpfs(tmp_path):
    """A real 16 MiB tmpfs, mounted for the test and unmounted after it. Needs root and a
    mount permitted by the container; otherwise skipped (the simulated tests above still run)."""
    import shutil

    mnt = tmp_path / "mnt"
    mnt.mkdir()
    if os.geteuid() != 0 or shutil.which("mount") is None:
        pytest.skip("a real full disk / read-only mount needs root and mount(8)")
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=16m", "tmpfs", str(mnt)],
                       capture_output=True, text=True)
    if r.returncode:
        pytest.skip(f"mount not permitted here: {r.stderr.strip()}")
    try:
        yield mnt
    finally:
        subprocess.run(["umount", "-l", str(mnt)], capture_output=True)


def _fill(folder: Path) -> Path:
    """Write zeros into ``folder`` until the file system is full (ENOSPC)."""
    filler = folder / "filler"
    with open(filler, "wb") as fh:
        try:
            while True:
                fh.write(b"\0" * 65536)
                fh.flush()
        except OSError as exc:
            assert exc.errno == errno.ENOSPC
    return filler


def test_real_full_disk_mid_run_keeps_what_was_committed(capsys, tmp_path, tmpfs, monkeypatch):
    """The disk fills after the third commit: one line naming the full disk, exit 2; the
    committed evaluations survive and, once space is freed, --resume finishes the study."""
    from pkmlab.study import store as store_mod

    out = tmpfs / "out"
    p = small_study(tmp_path, optimizer={"method": "sobol", "samples": 16}, output=str(out))
    real_put, state = store_mod.Store.put, {"n": 0}

    def put_then_fill(self, *a, **k):
        row = real_put(self, *a, **k)
        state["n"] += 1
        if state["n"] == 3:
            state["filler"] = _fill(tmpfs)
        return row

    monkeypatch.setattr(store_mod.Store, "put", put_then_fill)
    code, _, err = cli(capsys, "run", p)
    one_line(code, err, "No space left on device", str(out))
    monkeypatch.setattr(store_mod.Store, "put", real_put)
    state["filler"].unlink()
    con = sqlite3.connect(out / "evaluations.sqlite")
    assert con.execute("SELECT COUNT(*) FROM evaluations").fetchone()[0] >= 3
    con.close()
    store = run_study(load_study(p), SerialRunner(), resume=True)
    assert len(store.all()) == 17
    store.close()


def test_real_full_disk_while_writing_the_report(capsys, tmp_path, tmpfs, monkeypatch):
    """Every evaluation is stored, then the disk fills as the report is written: one line
    naming the folder; once space is freed, `report` rebuilds it from the complete store."""
    from pkmlab.study import report as report_mod

    out = tmpfs / "out"
    real = report_mod.write_report
    state = {}

    def fill_then_write(*a, **k):
        state["filler"] = _fill(tmpfs)
        return real(*a, **k)

    monkeypatch.setattr(report_mod, "write_report", fill_then_write)
    code, _, err = cli(capsys, "run", small_study(tmp_path, output=str(out)))
    one_line(code, err, "No space left on device", str(out))
    monkeypatch.setattr(report_mod, "write_report", real)
    state["filler"].unlink()
    code, _, err = cli(capsys, "report", out)
    assert code == 0, err


def test_real_full_disk_before_the_store_exists(capsys, tmp_path, tmpfs):
    _fill(tmpfs)
    code, _, err = cli(capsys, "run", small_study(tmp_path, output=str(tmpfs / "out")))
    one_line(code, err, "No space left on device")


def test_real_read_only_mount(capsys, tmp_path, tmpfs, finished):
    """A read-only file system: a new run and a resumed run refuse in one line; report reads
    the store (opened read-only) and stops in one line at the first file it cannot write."""
    import shutil

    shutil.copytree(finished, tmpfs / "done")
    r = subprocess.run(["mount", "-o", "remount,ro", str(tmpfs)], capture_output=True,
                       text=True)
    if r.returncode:
        pytest.skip(f"remount read-only not permitted: {r.stderr.strip()}")
    before = (tmpfs / "done" / "evaluations.sqlite").read_bytes()
    code, _, err = cli(capsys, "run", small_study(tmp_path, output=str(tmpfs / "new")))
    one_line(code, err, "Read-only file system", str(tmpfs / "new"))
    code, _, err = cli(capsys, "run", small_study(tmp_path, output=str(tmpfs / "done")),
                       "--resume")
    one_line(code, err, "Read-only file system")
    code, _, err = cli(capsys, "report", tmpfs / "done")
    one_line(code, err, "Read-only file system", str(tmpfs / "done"))
    assert (tmpfs / "done" / "evaluations.sqlite").read_bytes() == before


# ---- 6. singular mechanisms --------------------------------------------------------------------

def test_architecturally_singular_mechanism_is_reported(capsys, tmp_path):
    text = GS.read_text()
    base = text.split("base_points:")[1].split("platform_points:")[0].split("\n", 1)[1]
    head = text.split("platform_points:")[0]
    p = tmp_path / "same.yaml"
    p.write_text(head + "platform_points:\n" + base + "stroke: [390 mm, 950 mm]\n"
                 "tool_offset: [0 mm, 0 mm, 0 mm]\n")
    code, out, err = cli(capsys, "inspect", p, "--json")
    assert code == 0, err
    assert '"nominal_reason": "singular' in out
    code, out, err = cli(capsys, "workspace", p, "--resolution", "20", "--out", tmp_path / "w")
    assert code == 0, err
    assert "singular at the nominal pose" in " ".join(out.split())


# ---- 7. kill -9, Ctrl-C, concurrent runs --------------------------------------------------------

def _children(pid: int) -> set[int]:
    out = set()
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                ppid = int((d / "stat").read_text().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            if ppid == pid:
                out.add(int(d.name))
    return out


def _alive(pid: int) -> bool:
    try:
        state = (Path("/proc") / str(pid) / "stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def _start(tmp_path, *extra, samples=64):
    p = small_study(tmp_path, optimizer={"method": "sobol", "samples": samples})
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    proc = subprocess.Popen([sys.executable, "-m", "pkmlab.cli", "run", str(p), *extra],
                            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True)
    return p, proc


def _wait_rows(db: Path, n: int, timeout=120) -> int:
    deadline = time.time() + timeout
    while time.time() < deadline:
        if db.exists():
            try:
                con = sqlite3.connect(db)
                k = con.execute("SELECT COUNT(*) FROM evaluations").fetchone()[0]
                con.close()
                if k >= n:
                    return k
            except sqlite3.Error:
                pass
        time.sleep(0.05)
    return 0


@pytest.mark.parametrize("when", ["early", "mid", "late"])
def test_kill_9_leaves_no_workers_and_resume_finishes(capsys, tmp_path, when):
    """kill -9 before the store exists (early), while evaluating (mid) and once every
    evaluation is stored, while the report is being written (late)."""
    n = 16 if when == "late" else 64
    p, proc = _start(tmp_path, *(() if when == "late" else ("--jobs", "2")), samples=n)
    db = tmp_path / "out" / "evaluations.sqlite"
    if when == "early":
        time.sleep(1.0)
    else:
        assert _wait_rows(db, 3 if when == "mid" else n + 1)
    workers = set()
    deadline = time.time() + 20
    while time.time() < deadline and not workers and when != "early":
        workers = {c for c in _children(proc.pid)}
        if when == "late":
            break
        time.sleep(0.1)
    assert workers or when != "mid", "no loky workers seen"
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    deadline = time.time() + 15
    while time.time() < deadline and any(_alive(w) for w in workers):
        time.sleep(0.2)
    assert not any(_alive(w) for w in workers), "workers outlived the killed run"
    store = run_study(load_study(p), SerialRunner(), resume=(tmp_path / "out" / "evaluations"
                                                             ".sqlite").exists(),
                      overwrite=not db.exists())
    assert len(store.all()) == n + 1
    store.close()
    if when == "late":
        code, _, err = cli(capsys, "report", tmp_path / "out")
        assert code == 0, err


def test_ctrl_c_after_the_report_is_not_a_signal_death(tmp_path):
    """Ctrl-C pressed again and again once the report is written, while the interpreter
    shuts down (its module teardown takes about half a second): the run ends with its own
    status (0, everything written) or 130 with one "interrupted", never killed by the signal
    (status -2 before)."""
    p = small_study(tmp_path, optimizer={"method": "sobol", "samples": 8})
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    proc = subprocess.Popen([sys.executable, "-m", "pkmlab.cli", "run", str(p)], env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    lines = []
    for line in proc.stderr:
        lines.append(line)
        if "report.html written" in line:
            break
    while proc.poll() is None:
        proc.send_signal(signal.SIGINT)
        time.sleep(0.05)
    lines += proc.stderr.readlines()
    err = "".join(lines)
    assert proc.returncode in (0, 130), err
    assert "Traceback" not in err
    assert (error_lines(err) == ["interrupted"]) == (proc.returncode == 130), err
    assert (tmp_path / "out" / "report.html").exists()


@pytest.mark.parametrize("when", ["mid", "late"])
def test_ctrl_c_stops_the_run_cleanly_and_resume_finishes(capsys, tmp_path, when):
    """Ctrl-C while evaluating (mid) and once every evaluation is stored, while the designs
    are exported and the report written (late)."""
    n = 64 if when == "mid" else 16
    p, proc = _start(tmp_path, samples=n)
    db = tmp_path / "out" / "evaluations.sqlite"
    assert _wait_rows(db, 2 if when == "mid" else n + 1)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert error_lines(err) == ["interrupted"], err
    assert "Traceback" not in err and len(error_lines(err)) <= 1, err
    store = run_study(load_study(p), SerialRunner(), resume=True)
    assert len(store.all()) == n + 1
    store.close()
    if when == "late":
        code, _, err = cli(capsys, "report", tmp_path / "out")
        assert code == 0, err


def test_two_concurrent_runs_one_is_refused(tmp_path):
    """A run holds its folder for as long as it runs: a second run into it is refused."""
    p = small_study(tmp_path, optimizer={"method": "sobol", "samples": 64})
    out = tmp_path / "out"
    holder = subprocess.Popen(      # the first run's lock, held without racing its evaluations
        [sys.executable, "-c", "import time; from pkmlab.study.run import OutputLock; "
         f"lock = OutputLock({str(out)!r}).__enter__(); print('held', flush=True); "
         "time.sleep(60)"],
        stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        for extra in ([], ["--resume"], ["--overwrite"]):
            second = subprocess.run([sys.executable, "-m", "pkmlab.cli", "run", str(p), *extra],
                                    capture_output=True, text=True, timeout=120)
            assert second.returncode == 2, second.stderr
            assert f"in use by pid {holder.pid}" in second.stderr
            assert len(error_lines(second.stderr)) == 1, second.stderr
    finally:
        holder.kill()
        holder.wait()
    assert not (out / "evaluations.sqlite").exists()


def test_mesh_in_slabs_is_the_same_watertight_mesh(monkeypatch):
    import pkmlab
    import pkmlab.workspaces.output.mesh as mesh_mod
    from pkmlab.workspaces import workspace

    res = workspace(pkmlab.load_mechanism(HW), "constant", resolution=4.0)
    whole = res.mesh()
    monkeypatch.setattr(mesh_mod, "_MESH_SLAB", 5_000)
    slabs = res.mesh()
    assert slabs.is_watertight and len(slabs.faces) == len(whole.faces)
    assert slabs.volume == pytest.approx(whole.volume, rel=1e-9)


def test_a_study_of_thin_workspaces_finishes_its_report_and_resumes(capsys, tmp_path):
    """Designs whose dexterous workspace is a sliver (Hopkins at ±23°, 2.5 mm, where marching
    cubes used to raise after every evaluation was stored): the run exports them without a
    mesh, with the reason, writes its report and exits 0; --resume does the same."""
    p = small_study(tmp_path, design={"link_length": {"low": "224 mm", "high": "226 mm"}},
                    evaluate={"workspace": {"kind": "dexterous", "box": ["23 deg"] * 3,
                                            "samples": 3, "resolution": "2.5 mm"}},
                    objectives=[{"maximize": "dexterous_volume"}],
                    optimizer={"method": "sobol", "samples": 2})
    for extra in ([], ["--resume"]):
        code, _, err = cli(capsys, "run", p, *extra)
        assert code == 0, err
        assert (tmp_path / "out" / "report.html").exists()
    import json

    designs = tmp_path / "out" / "designs"
    assert json.loads((designs / "index.json").read_text())["problems"] == []
    infos = [json.loads((d / "design.json").read_text()) for d in designs.iterdir()
             if d.is_dir()]
    assert infos and all("thinner than one grid cell" in i["mesh"] for i in infos), infos
