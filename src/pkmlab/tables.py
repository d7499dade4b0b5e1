"""Numeric CSV tables read from users' files: one reader, with bounded size and safe messages.

Every CSV input of pkmlab (recorded motions, trajectory files, task point lists) goes through
:func:`read_table`. It

* reads at most :data:`~pkmlab.limits.CSV_MAX_BYTES` bytes and
  :data:`~pkmlab.limits.CSV_MAX_ROWS` data rows (a larger file is refused before it is parsed);
* accepts UTF-8, UTF-8 with a byte-order mark (Excel's "CSV UTF-8") and UTF-16 with a byte-order
  mark; anything else is refused as "not UTF-8" with the byte offset;
* skips blank lines and lines starting with ``#``; the first other line is the header;
* never shows the file's contents in an error: a header name or a cell is quoted only when it is
  a short plain token (:func:`shown`), otherwise its length is given. A path such as
  ``/proc/self/environ`` cannot leak into a CI log through an error message.

Errors are :class:`~pkmlab.errors.ParameterError` naming the caller's field, with the file and
line in ``where``.
"""

from __future__ import annotations

import codecs
import csv
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import ParameterError, Shown
from .limits import CSV_MAX_BYTES, CSV_MAX_ROWS

__all__ = ["Table", "read_table", "shown"]

_PLAIN = re.compile(r"[A-Za-z0-9_.+\-]{1,32}")


def shown(text: str) -> Shown:
    """A cell or header name as an error may show it: quoted when it is a short plain token
    (letters, digits, ``_ . + -``), else only its length."""
    text = text.strip()
    if _PLAIN.fullmatch(text):
        return Shown(repr(text))
    return Shown(f"a {len(text)}-character text (not shown)" if text else "an empty cell")


_NUMERIC = re.compile(r"[0-9eE.+\-]{1,32}|[+-]?(?i:nan|inf|infinity)")


def shown_cell(text: str) -> Shown:
    """A data cell as an error may show it: only when it is made of number characters
    (digits, sign, point, exponent; nan, inf), else its length — a data cell is file
    content, and a word there may be a secret (a token, a password)."""
    text = text.strip()
    if _NUMERIC.fullmatch(text):
        return Shown(repr(text))
    return Shown(f"a {len(text)}-character text (not shown)" if text else "an empty cell")


@dataclass(frozen=True)
class Table:
    """A numeric CSV table: the header names, the values ``(rows, columns)`` and each data
    row's line number in the file (for messages)."""

    path: Path
    header: tuple[str, ...]
    values: np.ndarray
    lines: np.ndarray
    header_line: int

    def column(self, name: str) -> np.ndarray:
        return self.values[:, self.header.index(name)]

    def where(self, row: int | None = None) -> str:
        """``"<file>, line N"`` of data row ``row`` (of the header when None)."""
        line = self.header_line if row is None else int(self.lines[row])
        return f"{self.path}, line {line}"


def _decode(raw: bytes, path: Path, field: str) -> str:
    if raw.startswith(codecs.BOM_UTF8):
        raw, encoding = raw[len(codecs.BOM_UTF8):], "utf-8"
    elif raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        encoding = "utf-16"
    else:
        encoding = "utf-8"
    try:
        text = raw.decode(encoding)
    except UnicodeDecodeError as exc:
        raise ParameterError(field, "a UTF-8 text file (or UTF-8/UTF-16 with a byte-order "
                             "mark)", Shown(f"bytes that are not {encoding.upper()} at byte "
                                            f"offset {exc.start}"), where=str(path)) from None
    if "\x00" in text:
        raise ParameterError(field, "a text file", Shown("a file with NUL characters"),
                             where=str(path))
    return text


def read_table(path: str | Path, field: str, *, what: str = "a CSV file") -> Table:
    """Read a numeric CSV table (see the module docstring). Every data cell must be a finite
    number and every row as long as the header; the header's names are checked by the caller.

    Args:
        path: the file.
        field: the input that named the file (shown in every error).
        what: how to describe the expected file in errors ("a CSV file with the header ...").
    """
    path = Path(path)
    if not path.is_file():
        raise ParameterError(field, f"an existing file: {what}", str(path))
    with path.open("rb") as fh:
        raw = fh.read(CSV_MAX_BYTES + 1)
    if len(raw) > CSV_MAX_BYTES:
        raise ParameterError(field, f"{what} of at most {CSV_MAX_BYTES // 2**20} MiB",
                             Shown("a larger file"), where=str(path))
    text = _decode(raw, path, field)
    numbered = [(n, line) for n, line in enumerate(text.splitlines(), start=1)
                if line.strip() and not line.lstrip().startswith("#")]
    if not numbered:
        raise ParameterError(field, what, Shown("an empty file"), where=str(path))
    if len(numbered) - 1 > CSV_MAX_ROWS:
        raise ParameterError(field, f"{what} of at most {CSV_MAX_ROWS:,} data rows",
                             Shown(f"{len(numbered) - 1:,} rows"), where=str(path))
    reader = csv.reader(line for _, line in numbered)
    header: list[str] = []
    values = np.empty((len(numbered) - 1, 0))
    k = 0
    try:
        for k, row in enumerate(reader):
            if k == 0:
                header = [h.strip() for h in row]
                values = np.empty((len(numbered) - 1, len(header)))
                continue
            line = numbered[k][0]
            if len(row) != len(header):
                raise ParameterError(field, f"{len(header)} comma-separated fields per row "
                                     "(as the header)", Shown(f"{len(row)} fields"),
                                     where=f"{path}, line {line}")
            for j, cell in enumerate(row):
                try:
                    v = float(cell)
                except ValueError:
                    raise ParameterError(f"{field} column {shown(header[j])}",
                                         "a finite number", shown_cell(cell),
                                         where=f"{path}, line {line}") from None
                if not math.isfinite(v):
                    raise ParameterError(f"{field} column {shown(header[j])}",
                                         "a finite number", shown_cell(cell),
                                         where=f"{path}, line {line}")
                values[k - 1, j] = v
    except csv.Error:
        raise ParameterError(field, "well-formed CSV rows (fields of at most "
                             f"{csv.field_size_limit():,} characters, quotes closed)",
                             Shown("a row that is not"),
                             where=f"{path}, line {numbered[k][0]}") from None
    dupes = sorted({h for h in header if header.count(h) > 1})
    if dupes:
        raise ParameterError(f"{field} header", "each column named once",
                             Shown("duplicate " + ", ".join(shown(h) for h in dupes)),
                             where=f"{path}, line {numbered[0][0]}")
    return Table(path, tuple(header), values,
                 np.array([n for n, _ in numbered[1:]], dtype=np.int64), numbered[0][0])
