"""The results store: one SQLite file per study, one row per evaluated candidate.

Every evaluation is committed as soon as it finishes, so a killed run loses nothing finished;
rows are keyed by a hash of the study's evaluation definition and the candidate's parameters,
so a resumed run finds them instead of evaluating again.
"""

from __future__ import annotations

import hashlib
import json
import math
import sqlite3
from pathlib import Path

from ..errors import ParameterError

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


class Store:
    """SQLite store of evaluations (``evaluations.sqlite`` in the study's output folder)."""

    def __init__(self, path: str | Path, *, read_only: bool = False):
        self.path = Path(path)
        self.read_only = read_only
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
            raise ParameterError("store", "a readable pkmlab results store",
                                 f"{self.path}: {exc}") from None
        if version != SCHEMA:
            self.conn.close()
            raise ParameterError("store", f"a results store of layout {SCHEMA} (made by this "
                                 "pkmlab version)", f"{self.path} has layout {version}")

    # ---- metadata --------------------------------------------------------------------------
    def get_meta(self, key: str):
        row = self.conn.execute("SELECT value FROM meta WHERE key = ?", (key,)).fetchone()
        return None if row is None else json.loads(row[0])

    def set_meta(self, key: str, value) -> None:
        self.conn.execute("INSERT OR REPLACE INTO meta VALUES (?, ?)", (key, _canon(value)))
        self.conn.commit()

    # ---- evaluations -----------------------------------------------------------------------
    def get(self, key: str) -> dict | None:
        row = self.conn.execute(f"SELECT {_COLUMNS} FROM evaluations WHERE key = ?",
                                (key,)).fetchone()
        return None if row is None else self._row(row)

    def put(self, key: str, role: str, params: dict, result: dict) -> dict:
        """Commit one finished evaluation (ignored if the key is already stored)."""
        self.conn.execute(
            "INSERT OR IGNORE INTO evaluations (key, role, params, metrics, status, reason, "
            "seconds, notes) VALUES (?, ?, ?, ?, ?, ?, ?, ?)",
            (key, role, _canon(params), _canon(_clean(result["metrics"])), result["status"],
             result["reason"], float(result["seconds"]), _canon(result.get("notes", {}))))
        self.conn.commit()
        return self.get(key)

    def all(self) -> list[dict]:
        rows = self.conn.execute(f"SELECT {_COLUMNS} FROM evaluations ORDER BY seq").fetchall()
        return [self._row(r) for r in rows]

    @staticmethod
    def _row(r) -> dict:
        return {"seq": r[0], "key": r[1], "role": r[2], "params": json.loads(r[3]),
                "metrics": json.loads(r[4]), "status": r[5], "reason": r[6], "seconds": r[7],
                "notes": json.loads(r[8] or "{}")}

    def close(self) -> None:
        self.conn.close()
