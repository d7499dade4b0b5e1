"""Command-line interface (typer). Speaks mm and degrees; the library speaks mm and radians.

JSON output (``--json``) uses these keys throughout:

* a pose is ``{"x": mm, "y": mm, "z": mm, "theta_x": deg, "theta_y": deg, "theta_z": deg}``
  (Z-Y-X Euler angles, R = Rz·Ry·Rx, of the tool frame in the base frame);
* actuator values are ``{"<name>": mm, ...}`` keyed by the family's actuator names
  (``q1``..``q6``, or ``l11``..``l32`` for ``luzi3``).

Errors in the input print one line naming the field, the allowed values and the value given,
and exit with status 2.
"""

from __future__ import annotations

import atexit
import logging
import os
import signal
import sys
import threading
from typing import Annotated

import typer

from . import (  # noqa: F401 - registers the commands
    analysis,
    export,
    kinematics,
    optimum,
    printer,
    study,
    workspace,
)
from .common import app

__all__ = ["app", "main", "run_cli"]


_DEBUG = {"on": False}
_INTERRUPTED = {"said": False}         # "interrupted" already written


def _version(value: bool) -> None:
    if value:
        from .. import __version__

        sys.stdout.write(f"pkmlab {__version__}\n")
        raise typer.Exit()


@app.callback()
def _root(
    ctx: typer.Context,
    debug: Annotated[bool, typer.Option(
        "--debug", help="show the full traceback of an unexpected error")] = False,
    version: Annotated[bool | None, typer.Option(
        "--version", callback=_version, is_eager=True, help="print the version and exit")]
    = None,
) -> None:
    """pkmlab: design-optimisation workbench for parallel manipulators."""
    from ..runtime.memory import COMMAND_BYTES, require_command, set_command

    _DEBUG["on"] = debug
    name = ctx.invoked_subcommand
    set_command(name)               # its fixed memory joins every budget check it makes
    if name in COMMAND_BYTES and "--help" not in sys.argv[2:]:
        require_command(f"pkmlab {name}")   # the command alone must fit the budget


def main() -> None:
    """Console entry point (``pkmlab``, ``python -m pkmlab.cli``): :func:`run_cli`, then the
    end of the process without the interpreter's module teardown (:func:`_end_process`). An
    exception other than ``SystemExit`` (``--debug``) ends the process the ordinary way, with
    its traceback."""
    try:
        run_cli()
        code: object = 0
    except SystemExit as exc:
        code = exc.code
    _end_process(code)


def _end_process(code: object) -> None:
    """End the process the way the interpreter would, less its module teardown: run the
    threading exit hooks (they stop executors' threads) and wait for the threads that are not
    daemons, run the exit handlers (worker pools, Dask clients, temporary folders, logging),
    flush the standard streams, then ``os._exit``. Freeing every module and compiled kernel
    took 0.25-0.45 s after a ``pkmlab workspace`` had written everything (a fifth of its run;
    measured in docs/validation.md), and nothing pkmlab writes depends on it: every file is
    closed by the command that wrote it. The same order as a ``multiprocessing`` child's end
    (threads, exit handlers, ``os._exit``). ``code``: the ``SystemExit`` code, with the
    interpreter's meaning (``None`` 0, an int itself, anything else printed and 1)."""
    if code is None:
        status = 0
    elif isinstance(code, int) and -2**31 <= code < 2**31:
        status = code
    else:                           # SystemExit("message") and other objects: printed, status 1
        sys.stderr.write(f"{code}\n")
        status = 1
    # the interpreter's own two exit steps, in its order: the threading exit hooks (which
    # stop executor threads) then waiting for the other threads; then the exit handlers
    threading._shutdown()
    atexit._run_exitfuncs()
    logging.shutdown()
    if not _flushed() and status == 0:     # a closed pipe: 120 as the interpreter's, without
        status = 120                        # its "Exception ignored" message
    os._exit(status)


def _flushed() -> bool:
    """Flush stdout and stderr; False if one could not be (a closed pipe, a closed file)."""
    ok = True
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            ok = False
    return ok


def run_cli() -> None:
    """Run one command from ``sys.argv`` and raise ``SystemExit`` with its status: input
    errors exit 2 (one line); a file-system error exits 2 with its path; a candidate's
    programming error exits 1 with its traceback and parameters; any other unexpected error
    exits 1 with one line (``--debug``: the traceback); Ctrl-C exits 130 with "interrupted",
    also afterwards while threads are waited for and the exit handlers registered after the
    command started run (worker pools, Dask clients); it is ignored during the handlers that
    libraries registered at import, which run last (for that, the process's SIGINT handling
    is left replaced: this is the program's entry, not a library call)."""
    import sqlite3

    from ..errors import CandidateError, NumericalError, ParameterError
    from ..yamlio import locate_error

    # registered before the command, so it runs after every exit handler the command adds
    # (pools, clients): what follows (the handlers libraries registered at import, and the
    # module teardown when not ended by main) cannot be interrupted halfway
    atexit.register(signal.signal, signal.SIGINT, signal.SIG_IGN)
    try:
        with _compile_notice(sys.argv[1:]):
            code = app(standalone_mode=False)  # click returns an Exit's code in this mode
        if code == 130:                        # typer turns Ctrl-C into Exit(130), silently
            sys.stderr.write("interrupted\n")
            _INTERRUPTED["said"] = True
        raise SystemExit(code if isinstance(code, int) else 0)
    except typer.Exit as exc:
        raise SystemExit(exc.exit_code) from None
    except typer.TyperException as exc:           # a usage error: one line, exit 2
        ctx = getattr(exc, "ctx", None)
        sys.stderr.write(f"error: {exc.format_message()}"
                         + (f" (see: {ctx.command_path} --help)" if ctx is not None
                            else "") + "\n")
        raise SystemExit(2) from None
    except (typer.Abort, KeyboardInterrupt):
        sys.stderr.write("interrupted\n")
        _INTERRUPTED["said"] = True
        raise SystemExit(130) from None
    except CandidateError as exc:
        sys.stderr.write(f"error: {exc}\n")
        raise SystemExit(1) from None
    except ParameterError as exc:                 # bad input found late: one line, exit 2
        locate_error(exc)
        sys.stderr.write("error: " + " ".join(str(exc).split()) + "\n")
        raise SystemExit(2) from None
    except NumericalError as exc:                 # the request has no defined answer
        sys.stderr.write("error: " + " ".join(str(exc).split()) + "\n")
        raise SystemExit(2) from None
    except MemoryError:
        sys.stderr.write("error: out of memory: use a coarser resolution, fewer samples or a "
                         "smaller population (PKMLAB_MEMORY_LIMIT sets the budget checked "
                         "before allocating)\n")
        raise SystemExit(2) from None
    except sqlite3.DatabaseError as exc:
        sys.stderr.write(f"error: results store: {exc}\n")
        raise SystemExit(2) from None
    except OSError as exc:
        if _DEBUG["on"]:
            raise
        where = f" ({exc.filename})" if getattr(exc, "filename", None) else ""
        sys.stderr.write(f"error: file system: {exc.strerror or exc}{where}\n")
        raise SystemExit(2) from None
    except Exception as exc:  # noqa: BLE001 - last resort: one line unless --debug
        if _DEBUG["on"]:
            raise
        sys.stderr.write(f"error: {type(exc).__name__}: {exc} (this is a bug in pkmlab; run "
                         "with --debug for the traceback)\n")
        raise SystemExit(1) from None
    finally:
        from ..runtime.memory import set_command

        set_command(None)       # library calls after the command count no command memory
        # the command is over; a Ctrl-C while the interpreter shuts down (joining worker
        # pools, a second or more after a study's report) ends it at once with status 130
        # instead of a signal death or a traceback from a library's exit handler
        signal.signal(signal.SIGINT, _interrupted_at_exit)


#: the kind of compile each command makes (:data:`pkmlab.runtime.compilenotice.ESTIMATES`)
_KINDS = {"ik": "kinematics", "fk": "kinematics", "inspect": "kinematics",
          "validate": "kinematics", "run": "study", "report": "study"}


def _compile_notice(argv: list[str]):
    """``pkmlab: compiling <family> kernels, one-off, about …`` on stderr when the command
    compiles numba kernels (none when they load from the cache)."""
    from ..runtime.compilenotice import compile_notice

    command = next((a for a in argv if not a.startswith("-")), "")
    family = _family_of(argv)

    def say(line: str) -> None:
        sys.stderr.write(f"pkmlab: {line}\n")
        sys.stderr.flush()

    return compile_notice(say, f"{family} " if family else "",
                          _KINDS.get(command, "analysis")) if command else _nothing()


def _nothing():
    import contextlib

    return contextlib.nullcontext()


def _family_of(argv: list[str]) -> str:
    """The family of the first mechanism or study file on the command line ('' if none)."""
    from pathlib import Path

    import yaml

    for a in argv:
        p = Path(a)
        if p.suffix not in (".yaml", ".yml") or not p.is_file():
            continue
        try:
            data = yaml.safe_load(p.read_text())
            if isinstance(data, dict) and isinstance(data.get("mechanism"), dict):
                m = data["mechanism"]
                if isinstance(m.get("inline"), dict):
                    data = m["inline"]
                elif isinstance(m.get("file"), str):
                    data = yaml.safe_load((p.parent / m["file"]).read_text())
            fam = data.get("family") if isinstance(data, dict) else None
            if isinstance(fam, str) and fam.isidentifier():
                return fam
        except (OSError, yaml.YAMLError):
            continue
    return ""


def _interrupted_at_exit(signum, frame) -> None:
    _flushed()
    if not _INTERRUPTED["said"]:
        os.write(2, b"interrupted\n")
    os._exit(130)
