"""The results store: one SQLite file per study, one row per evaluated candidate.

Every evaluation is committed as soon as it finishes, so a killed run loses nothing finished;
rows are keyed by a hash of the study's evaluation definition and the candidate's parameters,
so a resumed run finds them instead of evaluating again.
"""

from __future__ import annotations

import errno
import hashlib
import json
import math
import sqlite3
from pathlib import Path

from ..errors import ParameterError, Shown

__all__ = ["Store", "candidate_key"]

#: Version of the table layout; a store of another version is refused, not misread.
SCHEMA = 2


_COLUMNS = "seq, key, role, params, metrics, status, reason, seconds, notes"


def _canon(obj) -> str:
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), default=str)


def candidate_key(fp: str, params: dict) -> str:
    return hashlib.sha256((fp + _canon(params)).encode()).hexdigest()[:24]


def _clean(obj):
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, dict):
        return {k: _clean(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_clean(v) for v in obj]
    return obj


#: A write-ahead-log checkpoint every this many commits (and on close): evaluations since the
#: last checkpoint live only in ``evaluations.sqlite-wal`` until then.
CHECKPOINT_EVERY = 50


def diagnose(path: str | Path) -> str:
    """What can be read from a damaged store: SQLite's integrity check, the metadata entries
    that are not JSON and the number of evaluation rows that still decode (one line)."""
    if Path(path).is_file() and Path(path).stat().st_size == 0:
        return ("the file is empty (0 bytes): no evaluation can be recovered; rerun the "
                "study with --overwrite")
    try:
        conn = sqlite3.connect(f"file:{Path(path)}?mode=ro", uri=True)
    except sqlite3.Error as exc:
        return f"cannot be opened ({exc})"
    try:
        try:
            check = conn.execute("PRAGMA integrity_check").fetchone()[0]
        except sqlite3.Error as exc:
            check = str(exc)
        readable, bad_meta = 0, []
        try:
            for key, value in conn.execute("SELECT key, value FROM meta"):
                try:
                    json.loads(value)
                except (ValueError, TypeError):
                    bad_meta.append(str(key)[:40])
        except sqlite3.Error:
            pass
        try:
            for row in conn.execute(f"SELECT {_COLUMNS} FROM evaluations"):
                try:
                    Store._row(row)
                    readable += 1
                except (ValueError, TypeError):
                    pass
        except sqlite3.Error:
            pass
    finally:
        conn.close()
    meta = (f"metadata not JSON: {', '.join(bad_meta[:5])}; " if bad_meta else "")
    return (f"sqlite integrity_check: {check}; {meta}{readable} evaluations readable (copy "
            "them out with the sqlite3 tool's .recover, or rerun the study with --overwrite)")


def _damaged(path: Path, exc: Exception) -> Exception:
    """The error for a store that cannot be read or written: a full disk is a file-system
    error (nothing is damaged), anything else a damaged store with what can be recovered."""
    if getattr(exc, "sqlite_errorcode", None) == sqlite3.SQLITE_FULL:
        return OSError(errno.ENOSPC, "No space left on device (the results store cannot "
                       "grow; free space, then run --resume)", str(path))
    return ParameterError("store", f"a readable pkmlab results store ({diagnose(path)})",
                          Shown(f"{path}: {exc}"))


class Store:
    """SQLite store of evaluations (``evaluations.sqlite`` in the study's output folder).

    The file is in WAL mode: commits go to ``evaluations.sqlite-wal`` and are folded into the
    main file every :data:`CHECKPOINT_EVERY` commits; :meth:`close` switches the file back to a
    rollback journal, so a finished (or interrupted but closed) run is one self-contained
    file. While a run is going on, copy the folder (or all three files), not
    ``evaluations.sqlite`` alone.
    """

    def __init__(self, path: str | Path, *, read_only: bool = False):
        self.path = Path(path)
        self.read_only = read_only
        if self.path.is_file() and self.path.stat().st_size == 0:
            # SQLite would take an empty file for a new store: a resumed run would silently
            # evaluate everything again
            raise ParameterError("store", f"a readable pkmlab results store ("
                                 f"{diagnose(self.path)})", Shown(f"{self.path}: empty"))
        try:
            if read_only:
                self.conn = sqlite3.connect(f"file:{self.path}?mode=ro", uri=True)
                version = self.get_meta("schema")
            else:
                self.path.parent.mkdir(parents=True, exist_ok=True)
                self.conn = sqlite3.connect(self.path)
                self.conn.execute("PRAGMA journal_mode=WAL")
                self.conn.execute("CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, "
                                  "value TEXT)")
                self.conn.execute(
                    "CREATE TABLE IF NOT EXISTS evaluations (seq INTEGER PRIMARY KEY "
                    "AUTOINCREMENT, key TEXT UNIQUE, role TEXT, params TEXT, metrics TEXT, "
                    "status TEXT, reason TEXT, seconds REAL, notes TEXT)")
                self.conn.commit()
                version = self.get_meta("schema")
                if version is None:
                    self.set_meta("schema", SCHEMA)
                    version = SCHEMA
        except sqlite3.DatabaseError as exc:
            raise _damaged(self.path, exc) from None
        self._commits = 0
        if version != SCHEMA:
            self.conn.close()
            raise ParameterError("store", f"a results store of layout {SCHEMA} (made by this "
                                 "pkmlab version)", f"{self.path} has layout {version}")

    # ---- metadata --------------------------------------------------------------------------
    def get_meta(self, key: str):
        row = self.conn.execute("SELECT value FROM meta WHERE key = ?", (key,)).fetchone()
        try:
            return None if row is None else json.loads(row[0])
        except (ValueError, TypeError):
            raise ParameterError("store", f"a readable pkmlab results store "
                                 f"({diagnose(self.path)})",
                                 Shown(f"{self.path}: metadata {key!r} is not JSON")) from None

    def set_meta(self, key: str, value) -> None:
        self.conn.execute("INSERT OR REPLACE INTO meta VALUES (?, ?)", (key, _canon(value)))
        self.conn.commit()

    # ---- evaluations -----------------------------------------------------------------------
    def get(self, key: str) -> dict | None:
        try:
            row = self.conn.execute(f"SELECT {_COLUMNS} FROM evaluations WHERE key = ?",
                                    (key,)).fetchone()
            return None if row is None else self._row(row)
        except (sqlite3.DatabaseError, ValueError, TypeError) as exc:
            raise _damaged(self.path, exc) from None

    def put(self, key: str, role: str, params: dict, result: dict) -> dict:
        """Commit one finished evaluation (ignored if the key is already stored)."""
        try:
            self._put(key, role, params, result)
        except sqlite3.OperationalError as exc:
            if getattr(exc, "sqlite_errorcode", None) == sqlite3.SQLITE_FULL:
                raise _damaged(self.path, exc) from None
            raise
        return self.get(key)

    def _put(self, key: str, role: str, params: dict, result: dict) -> None:
        self.conn.execute(
            "INSERT OR IGNORE INTO evaluations (key, role, params, metrics, status, reason, "
            "seconds, notes) VALUES (?, ?, ?, ?, ?, ?, ?, ?)",
            (key, role, _canon(params), _canon(_clean(result["metrics"])), result["status"],
             result["reason"], float(result["seconds"]), _canon(result.get("notes", {}))))
        self.conn.commit()
        self._commits += 1
        if self._commits % CHECKPOINT_EVERY == 0:
            self.checkpoint()

    def update(self, key: str, **fields) -> dict:
        """Rewrite fields (``metrics``, ``notes``, ``status``, ``reason``, ``seconds``) of a
        stored evaluation (the tolerance ladder's re-certification) → the record."""
        enc = {"metrics": lambda v: _canon(_clean(v)), "notes": _canon, "status": str,
               "reason": str, "seconds": float}
        sets = ", ".join(f"{k} = ?" for k in fields)
        self.conn.execute(f"UPDATE evaluations SET {sets} WHERE key = ?",
                          (*(enc[k](v) for k, v in fields.items()), key))
        self.conn.commit()
        return self.get(key)

    def checkpoint(self) -> None:
        """Fold the write-ahead log into ``evaluations.sqlite``."""
        if not self.read_only:
            self.conn.execute("PRAGMA wal_checkpoint(TRUNCATE)")

    def all(self) -> list[dict]:
        try:
            rows = self.conn.execute(f"SELECT {_COLUMNS} FROM evaluations "
                                     "ORDER BY seq").fetchall()
            return [self._row(r) for r in rows]
        except (sqlite3.DatabaseError, ValueError, TypeError) as exc:
            raise _damaged(self.path, exc) from None

    @staticmethod
    def _row(r) -> dict:
        return {"seq": r[0], "key": r[1], "role": r[2], "params": json.loads(r[3]),
                "metrics": json.loads(r[4]), "status": r[5], "reason": r[6], "seconds": r[7],
                "notes": json.loads(r[8] or "{}")}

    def close(self) -> None:
        if not self.read_only:
            try:        # fold the log in and leave one self-contained file behind
                self.conn.execute("PRAGMA journal_mode=DELETE")
            except sqlite3.Error:   # busy (another reader): the log stays, nothing is lost
                pass
        self.conn.close()
