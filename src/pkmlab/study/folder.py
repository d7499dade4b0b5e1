"""A study's results folder: who may write it, and what ``--overwrite`` may delete.

A run owns its folder through :class:`OutputLock` from before its first evaluation until its
last file (report, designs, page) is written; a second run, or ``pkmlab report``, into a
folder in use is refused, naming the holder.

``--overwrite`` deletes only what pkmlab wrote. A folder is pkmlab's when it holds the marker
:data:`MARKER` (written as a run starts) or a study store (``evaluations.sqlite``, for runs of
earlier versions), and every entry in it has the name of a pkmlab output (:func:`foreign`): the
store and its journals, the tables, pictures, summary, resolved study and report, the
``designs/`` folders with their design files (mesh files in any registered format), and the
scratch files an interrupted atomic write of one of these leaves. Anything
else, a symbolic link included (pkmlab writes none and never follows one), makes the whole
folder refused, naming the first such entry, and nothing is deleted.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import time
from pathlib import Path

from ..errors import ParameterError

__all__ = ["MARKER", "DESIGN_FOLDER", "OutputLock", "check_output", "foreign",
           "clear_for_overwrite", "claim"]

#: written into a results folder as a run starts: the folder is pkmlab's
MARKER = ".pkmlab-results"
_LOCK = ".lock"
_STORE = "evaluations.sqlite"
_TOP_FILES = frozenset({
    _LOCK, MARKER, _STORE, _STORE + "-wal", _STORE + "-shm", _STORE + "-journal",
    "evaluations.csv", "pareto.csv", "pareto.png", "summary.md", "study.resolved.yaml",
    "report.html"})
_DESIGNS = "designs"
#: an exported design's folder, ``NN-<8 hex digits of its key>`` (:mod:`.export` names them)
DESIGN_FOLDER = re.compile(r"^\d{2}-[0-9a-f]{8}$")
_DESIGN_FILE = re.compile(r"^[a-z0-9_.-]+\.([a-z0-9]+)$")
#: suffixes of a design's own files besides the registered mesh and mechanism formats
#: (pkmlab.export)
_DESIGN_SUFFIXES = frozenset({"json", "yaml", "png", "npz", "csv"})
#: ``atomic.write_bytes``'s scratch file of ``target``: ``.<target>.<8 random chars>.part``
_SCRATCH_FILE = re.compile(r"^\.(.+)\.[a-z0-9_]{8}\.part$")


class OutputLock:
    """An exclusive lock on a results folder (``.lock``, holding the owner's pid), released
    on exit and by the operating system when the process dies."""

    def __init__(self, folder: Path):
        self.path = Path(folder) / _LOCK
        self.fh = None

    def __enter__(self) -> OutputLock:
        import fcntl

        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.fh = open(self.path, "a+")
        try:
            fcntl.flock(self.fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            self.fh.seek(0)
            holder = self.fh.read().strip() or "another process"
            self.fh.close()
            raise ParameterError("output", "a results folder no other run is using",
                                 f"{self.path.parent} is in use by {holder}") from None
        self.fh.seek(0)
        self.fh.truncate()
        self.fh.write(f"pid {os.getpid()}")
        self.fh.flush()
        return self

    def __exit__(self, *exc) -> None:
        import fcntl

        fcntl.flock(self.fh, fcntl.LOCK_UN)
        self.fh.close()


def check_output(out: Path, source: Path | None = None, *, overwrite: bool = False) -> None:
    """Refuse a results folder that would hold (and on --overwrite delete) other files: the
    file system root, the working directory, the study file's folder or a parent of them; a
    folder holding files that is not pkmlab's; with ``overwrite``, a folder holding anything
    pkmlab did not write (:func:`foreign`). Nothing is written (not even the lock) into a
    folder refused."""
    target = Path(out).expanduser().resolve()
    protected = [Path.cwd().resolve()]
    if source is not None:
        protected.append(Path(source).resolve().parent)
    for p in protected:
        if target == p or target in p.parents or target == Path(target.anchor):
            raise ParameterError("output", "a results folder of its own (not the working "
                                 "directory, the study's folder, a parent of them or /)",
                                 str(out))
    if Path(out).is_dir():
        if overwrite:
            _check_overwrite(Path(out))
        elif not _marked(Path(out)) and any(p.name != _LOCK for p in Path(out).iterdir()):
            raise ParameterError("output", "a new or empty folder, or a pkmlab results folder",
                                 f"{out} holds files pkmlab did not write")


def _marked(out: Path) -> bool:
    return (out / MARKER).is_file() or (out / _STORE).is_file()


def _scratch(entry: os.DirEntry, allowed_files) -> bool:
    """A plain file an interrupted atomic write of an allowed file left behind."""
    m = _SCRATCH_FILE.match(entry.name)
    return (m is not None and entry.is_file(follow_symlinks=False)
            and bool(allowed_files(m.group(1))))


def _foreign_in(folder: Path, rel: str, allowed_files, allowed_dirs) -> str | None:
    with os.scandir(folder) as it:
        for e in sorted(it, key=lambda e: e.name):
            name = f"{rel}{e.name}"
            if e.is_symlink():
                return name + " (a symbolic link)"
            if _scratch(e, allowed_files):
                continue
            if e.is_dir(follow_symlinks=False):
                sub = allowed_dirs(e.name)
                if sub is None:
                    return name + "/"
                found = _foreign_in(Path(e.path), name + "/", *sub)
                if found is not None:
                    return found
            elif not (e.is_file(follow_symlinks=False) and allowed_files(e.name)):
                return name


def _design_folder(name: str):
    if DESIGN_FOLDER.match(name) is None:
        return None
    return _design_file, (lambda d: None)


def _design_file(name: str) -> bool:
    from ..export import exporters

    m = _DESIGN_FILE.match(name)
    if m is None:
        return False
    if m.group(1) in _DESIGN_SUFFIXES or m.group(1) in exporters("mesh"):
        return True
    return any(name.endswith(s) for e in exporters("mechanism").values() for s in e.files)


def _designs(name: str):
    if name != _DESIGNS:
        return None
    return (lambda f: f == "index.json"), _design_folder


def foreign(out: Path) -> str | None:
    """The first entry of ``out`` (a path relative to it) that pkmlab did not write, or None
    when every entry is a pkmlab output and the folder is marked as pkmlab's."""
    out = Path(out)
    if not _marked(out):
        entries = sorted(p.name for p in out.iterdir() if p.name != _LOCK)
        return f"{entries[0]} (and no {MARKER} marker)" if entries else None
    return _foreign_in(out, "", _TOP_FILES.__contains__, _designs)


def clear_for_overwrite(out: Path) -> int:
    """Delete the earlier run in ``out`` (all but the lock), after checking that everything in
    it is pkmlab's (:func:`foreign`); returns the number of entries deleted.

    Raises:
        ParameterError: the folder holds something pkmlab did not write (nothing is deleted).
    """
    out = Path(out)
    _check_overwrite(out)
    n = 0
    for p in sorted(out.iterdir()):
        if p.name in (_LOCK, MARKER):
            continue
        shutil.rmtree(p) if p.is_dir() and not p.is_symlink() else p.unlink()
        n += 1
    return n


def _check_overwrite(out: Path) -> None:
    found = foreign(out)
    if found is not None:
        raise ParameterError("--overwrite", "a results folder holding only what pkmlab wrote "
                             "(choose another output folder, or empty this one yourself)",
                             f"{out} holds {found}")


def claim(out: Path, study_name: str) -> None:
    """Mark ``out`` as a pkmlab results folder (:data:`MARKER`)."""
    from ..runtime import atomic

    atomic.write_text(Path(out) / MARKER, json.dumps(
        {"written_by": "pkmlab", "study": study_name,
         "time": time.strftime("%Y-%m-%dT%H:%M:%S%z")}) + "\n")
