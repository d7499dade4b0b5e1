"""Numba kernels cached on disk whose machine code cannot be mistaken for another kernel's.

**The hazard.** numba caches a compiled function as an object file. Each function in it has a
symbol made of ``module.qualname``, a uid and the argument types, and the uid is a per-process
counter (``numba.core.bytecode.FunctionIdentity``). A process that loads cached objects links
all of them into one MCJIT engine, and there a symbol defined twice resolves to its first
definition. The functions a kernel links in (its helpers, the ``__numba_parfor_gufunc_<address>``
that holds a ``prange`` loop body) are even emitted as weak ``linkonce_odr`` symbols, so a later
object calls the first object's copy. Two kernels that share a qualname and argument types
(closures made by one factory for several families) or a gufunc name (an address and the
counter), compiled by two processes whose counters happened to agree, are therefore aliased:
whichever is loaded second runs the first one's code. The result can be NaN or plausible wrong
numbers, depending on which processes filled the cache. The same name also means the same
cache index file. Two processes that save different kernels under one index file at the same
time can leave it pointing to the other kernel's data file.

**The construction.** :func:`cached_kernel` builds every parallel or family-specific kernel:

1. *Identity*: a SHA-256 of the numba and Python versions, the kernel's name, signature and
   options, and the source of everything it can compile in. That is every Python function
   reachable from the kernel's function through globals, closure cells and module attributes,
   transitively, except in numba, numpy, llvmlite and scipy. The hash covers those functions'
   qualified names and their whole source files, so module constants count too; a function
   without a source file contributes its marshalled code.
2. *Name*: the kernel is compiled from a copy of its function renamed ``<name>_<id16>``, where
   ``id16`` is the identity's first 16 hex digits. Family-specific helpers that are compiled as
   functions of their own are renamed the same way (:func:`jitable`). A name therefore implies
   its source. The cache index file is named after it, so one index file only ever holds one
   kernel, and editing anything the kernel compiles in gives a new name: a fresh compile, never
   a stale hit.
3. *Uid namespace*: the kernel is compiled, eagerly, with numba's uid counter set to a range
   owned by its identity, ``[(2^63 | h)·2^32, (2^63 | h + 1)·2^32)``, where ``h`` is the
   identity's first 64 bits. Every function numba creates during that compile (the kernel, its
   gufuncs, helpers compiled for the first time) takes its uid from that range. No other
   identity's compile uses the range, and ordinary compiles count from 1 and stay below it.
   Compiling is then disabled (explicit signature), so the kernel never compiles again outside
   its namespace.

So two symbols with the same name, from any two processes, come from the same identity and hold
the same code: loading both is harmless. Ordinary module-level ``njit(cache=True)`` functions
without ``parallel=True`` need none of this. Their symbol is ``module.qualname`` + uid + types,
numba discards their cache entries when their file changes, and the only other objects that
contain a linked copy of one are kernels whose identity covers that file. Every ``parallel=True``
function in pkmlab goes through :func:`cached_kernel` (``tests/runtime/test_kernel_cache.py`` checks
this).

If this numba has no ``FunctionIdentity._unique_ids`` counter, kernels are compiled uncached. Each
process then compiles them itself, which is slow but safe, and a warning says so.

Stale entries (from earlier sources) stay in ``NUMBA_CACHE_DIR`` until it is cleared. They are
never loaded.
"""

from __future__ import annotations

import contextlib
import hashlib
import inspect
import itertools
import logging
import marshal
import sys
import threading
import time
import types as pytypes
import warnings

import numba
from numba import njit
from numba.core import event as _event
from numba.core.bytecode import FunctionIdentity
from numba.core.compiler_lock import global_compiler_lock
from numba.core.errors import NumbaIRAssumptionWarning
from numba.extending import register_jitable

from .threads import DEFAULTS as _OPENMP_DEFAULTS  # noqa: F401  (set before any kernel runs)

log = logging.getLogger(__name__)
#: seconds after which a kernel compile is announced (the progress rule: no silent step > 2 s)
COMPILE_NOTICE_S = 1.5

__all__ = ["cached_kernel", "identity", "jitable", "CACHE_SAFE", "CompileLog", "compile_log",
           "compile_lines", "kernel_group"]

#: True when kernels can be cached safely (numba's uid counter is where it is expected).
CACHE_SAFE = isinstance(getattr(FunctionIdentity, "_unique_ids", None), itertools.count)
if not CACHE_SAFE:  # pragma: no cover - depends on the numba version
    warnings.warn("pkmlab: this numba has no FunctionIdentity._unique_ids counter; numba "
                  "kernels are compiled in every process instead of being cached", stacklevel=1)

#: Packages whose functions are never part of a kernel's identity (the numba version is).
_SKIP = frozenset({"numba", "numpy", "llvmlite", "scipy", "builtins"})
_counters: dict[str, itertools.count] = {}


def _unwrap(obj):
    """The Python function behind ``obj`` (itself, a dispatcher's ``py_func``), or None."""
    obj = getattr(obj, "py_func", obj)
    return obj if isinstance(obj, pytypes.FunctionType) else None


def _names(code) -> set[str]:
    """Global and attribute names used by ``code`` and the code objects nested in it."""
    names = set(code.co_names)
    for c in code.co_consts:
        if isinstance(c, pytypes.CodeType):
            names |= _names(c)
    return names


def _source_part(fn) -> tuple[str, bytes]:
    """``(key, bytes)`` of ``fn``'s source: its whole file, or its code when it has none."""
    path = inspect.getsourcefile(fn)
    if path:
        try:
            with open(path, "rb") as f:
                return "file:" + (fn.__module__ or path), f.read()
        except OSError:
            pass
    consts = tuple(sorted((n, repr(fn.__globals__[n])) for n in _names(fn.__code__)
                          if isinstance(fn.__globals__.get(n), int | float | str | tuple)))
    return f"code:{fn.__module__}.{fn.__qualname__}", marshal.dumps(fn.__code__) + \
        repr(consts).encode()


def identity(*roots, extra=()) -> str:
    """Hex SHA-256 of everything the functions ``roots`` compile in (see the module notes),
    with the numba and Python versions and ``extra`` (a tuple of reprs)."""
    parts: dict[str, bytes] = {}
    reached: set[str] = set()
    seen: set = set()
    stack = list(roots)
    while stack:
        fn = _unwrap(stack.pop())
        if fn is None or fn in seen:
            continue
        seen.add(fn)
        if (fn.__module__ or "").split(".")[0] in _SKIP:
            continue
        key, data = _source_part(fn)
        parts[key] = data
        reached.add(f"{fn.__module__}.{fn.__qualname__}")
        names = _names(fn.__code__)
        for name in names:
            value = fn.__globals__.get(name)
            if isinstance(value, pytypes.ModuleType):
                if value.__name__.split(".")[0] not in _SKIP:
                    stack.extend(getattr(value, n, None) for n in names)
            else:
                stack.append(value)
        stack.extend(c.cell_contents for c in fn.__closure__ or ()
                     if c.cell_contents is not None)
    h = hashlib.sha256()
    h.update(repr((numba.__version__, sys.version_info[:2], extra, sorted(reached))).encode())
    for key in sorted(parts):
        h.update(key.encode() + b"\0" + hashlib.sha256(parts[key]).digest())
    return h.hexdigest()


def _renamed(fn, name: str):
    """A copy of the function ``fn`` named ``name`` (same code, globals and closure cells)."""
    new = pytypes.FunctionType(fn.__code__, fn.__globals__, name, fn.__defaults__,
                               fn.__closure__)
    new.__qualname__ = name
    new.__kwdefaults__ = fn.__kwdefaults__
    new.__doc__ = fn.__doc__
    return new


@contextlib.contextmanager
def _uid_namespace(ident: str):
    """Functions numba creates inside take uids from ``ident``'s own range (see module notes)."""
    with global_compiler_lock:
        saved = FunctionIdentity._unique_ids
        base = ((1 << 63) | int(ident[:16], 16)) << 32
        FunctionIdentity._unique_ids = _counters.setdefault(ident, itertools.count(base))
        try:
            yield
        finally:
            FunctionIdentity._unique_ids = saved


def jitable(fn, ident: str, **options):
    """``register_jitable(**options)`` of a copy of ``fn`` named after ``ident``: for a helper
    that a kernel calls as a function of its own (not inlined) and whose code depends on a
    family, so that its symbol is as unique as the kernels' (``ident`` must cover it)."""
    return register_jitable(**options)(_renamed(fn, f"{fn.__name__}_{ident[:16]}"))


#: seconds this process has spent compiling (or loading from the cache) kernels
_COMPILING = [0.0]


def compile_seconds() -> float:
    """Seconds this process has spent in :func:`cached_kernel` so far (compiles and cache
    loads): subtracted from a measured evaluation time before it is used for an estimate."""
    return _COMPILING[0]


def cached_kernel(fn, sig, *, roots=(), extra=(), **options):
    """``njit(sig, cache=True, **options)`` of ``fn``, compiled now, named and compiled in a
    uid namespace after its identity (see the module notes).

    Args:
        fn: the kernel's Python function (module-level or a closure).
        sig: its one signature; calls must match it exactly (C-contiguous, writeable arrays).
        roots: more functions whose source the kernel compiles in but that ``fn`` does not
            reach by itself.
        extra: more values (reprs) that the identity must cover.
    """
    ident = identity(fn, *roots, extra=(fn.__name__, str(sig), sorted(options.items()),
                                        tuple(extra)))
    kernel = _renamed(fn, f"{fn.__name__}_{ident[:16]}")
    # a compile takes seconds (a cache load, on a loaded machine, may too): said at DEBUG
    # after COMPILE_NOTICE_S, once per kernel, and afterwards which of the two it was; the
    # command line says what compiles in one line per group (compile_lines, compilenotice)
    notice = threading.Timer(COMPILE_NOTICE_S, log.debug, ("loading or compiling the numba "
                             "kernel %s (compiled on first use after an install or an edit; "
                             "cached for later runs)", fn.__name__))
    notice.daemon = True
    notice.start()
    t0 = time.perf_counter()
    try:
        with compile_log() as rec, \
                _uid_namespace(ident) if CACHE_SAFE else contextlib.nullcontext():
            with warnings.catch_warnings():
                # numba's "internal pedantic check" on closures of generated code: a page of
                # text on every first compile, about numba's IR, not about the user's input
                warnings.simplefilter("ignore", NumbaIRAssumptionWarning)
                compiled = njit(sig, cache=CACHE_SAFE, **options)(kernel)
    finally:
        notice.cancel()
    dt = time.perf_counter() - t0
    if rec.compiled:
        _COMPILING[0] += dt
        log.debug("compiled %s in %.1f s", fn.__name__, dt)
    elif dt > COMPILE_NOTICE_S:
        log.debug("loaded %s from the cache in %.1f s", fn.__name__, dt)
    return compiled


#: what a kernel's module computes, for the one line per group a first run prints
#: (:func:`compile_lines`); modules not listed are named by their subpackage
_GROUPS = (("pkmlab.mechanisms.kernels.ik", "kinematics"), ("pkmlab.mechanisms.families",
           "kinematics"), ("pkmlab.mechanisms.kernels.search", "capability search"),
           ("pkmlab.mechanisms.kernels", "workspace columns"), ("pkmlab.workspaces",
           "workspace"), ("pkmlab.dexterity", "dexterity"), ("pkmlab.motion", "motion"))


def kernel_group(module: str) -> str:
    """The group a function of ``module`` is reported in: ``kinematics``, ``workspace
    columns``, ``capability search``, ``dexterity`` ... (numba's own functions: ``numba``)."""
    for prefix, group in _GROUPS:
        if module == prefix or module.startswith(prefix + "."):
            return group
    parts = module.split(".")
    return parts[1] if parts[0] == "pkmlab" and len(parts) > 1 else parts[0] or "?"


def _short(name: str) -> str:
    """A kernel's name without the identity suffix :func:`cached_kernel` gives it."""
    head, _, tail = name.rpartition("_")
    if head and len(tail) == 16 and all(c in "0123456789abcdef" for c in tail):
        return head
    return name


class CompileLog(_event.Listener):
    """numba compiles (not cache loads) seen while :func:`compile_log` is active: numba fires
    its ``numba:compile`` event only after a cache miss. ``compiled`` holds ``(name, seconds)``
    of each outermost compile, in order (a function compiled while another compiles counts
    inside it), and ``entries`` the same with the function's group (:func:`kernel_group`);
    ``name`` is the function's name without the identity suffix of :func:`cached_kernel`."""

    def __init__(self):
        self.entries: list[tuple[str, float, str]] = []
        self._stack: list[float] = []

    @property
    def compiled(self) -> list[tuple[str, float]]:
        return [(n, s) for n, s, _ in self.entries]

    def on_start(self, event):
        self._stack.append(time.perf_counter())

    def on_end(self, event):
        t0 = self._stack.pop()
        if self._stack:
            return
        fn = getattr(event.data.get("dispatcher"), "py_func", None)
        self.entries.append((_short(getattr(fn, "__name__", "?")), time.perf_counter() - t0,
                             kernel_group(getattr(fn, "__module__", None) or "?")))

    @property
    def seconds(self) -> float:
        return sum(s for _, s, _ in self.entries)

    def summary(self, top: int = 8) -> str:
        """One line: how many functions were compiled, in how long, the slowest by name."""
        if not self.entries:
            return "no numba kernel compiled (all loaded from the cache)"
        by: dict[str, float] = {}
        for n, s, _ in self.entries:
            by[n] = by.get(n, 0.0) + s
        names = sorted(by, key=by.get, reverse=True)
        shown = ", ".join(f"{n} {by[n]:.1f} s" for n in names[:top])
        more = f", and {len(names) - top} more" if len(names) > top else ""
        return (f"compiled {len(self.entries)} numba function(s) in {self.seconds:.1f} s "
                f"({shown}{more})")


def compile_lines(entries, where: str) -> list[str]:
    """One line per group of the compiles ``entries`` (``(name, seconds, group)``, as in
    :attr:`CompileLog.entries`), slowest group first, e.g. ``compiled the dexterity kernels
    for the baseline in 128.0 s (cell_bounds_loop 78.6 s, fused_at_loop 27.7 s, ...)``;
    ``where`` says for what (``for the baseline``, ``in a worker``)."""
    groups: dict[str, dict[str, float]] = {}
    for name, seconds, group in entries:
        by = groups.setdefault(group, {})
        by[name] = by.get(name, 0.0) + seconds
    lines = []
    for group, by in sorted(groups.items(), key=lambda kv: -sum(kv[1].values())):
        names = sorted(by, key=by.get, reverse=True)
        shown = ", ".join(f"{n} {by[n]:.1f} s" for n in names[:4])
        more = f", and {len(names) - 4} more" if len(names) > 4 else ""
        lines.append(f"compiled the {group} kernels {where} in {sum(by.values()):.1f} s "
                     f"({shown}{more})")
    return lines


@contextlib.contextmanager
def compile_log():
    """``with compile_log() as c:`` records in ``c`` (:class:`CompileLog`) every numba compile
    made inside, in any thread of this process."""
    rec = CompileLog()
    with _event.install_listener("numba:compile", rec):
        yield rec
