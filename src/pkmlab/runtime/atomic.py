"""Atomic file output: a reader (or a crash) never sees a half-written file or folder.

:func:`write_text` / :func:`write_bytes` write a sibling temporary file and rename it over the
target; :func:`staged` stages several outputs in a scratch folder inside the destination and
moves them in only when all were written.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

__all__ = ["write_text", "write_bytes", "staged"]


def _file_mode() -> int:
    """The mode ``open()`` would give a new file (0o666 less the umask): a temporary file is
    created 0o600, which would make every result readable by its owner only."""
    mask = os.umask(0o022)
    os.umask(mask)
    return 0o666 & ~mask


def write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically (temporary sibling, fsync, rename), with the
    permissions a plain write would give."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".part")
    try:
        os.fchmod(fd, _file_mode())
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return path


def write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    return write_bytes(path, text.encode("utf-8"))


@contextlib.contextmanager
def staged(out_dir: str | Path) -> Iterator[Path]:
    """A scratch folder inside ``out_dir``; on success every file in it is moved into
    ``out_dir`` (replacing files of the same name), on failure nothing is."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=out_dir, prefix=".partial-") as tmp:
        yield Path(tmp)
        for f in sorted(Path(tmp).iterdir()):
            target = out_dir / f.name
            if target.is_dir() and not target.is_symlink():
                shutil.rmtree(target)
            os.replace(f, target)
