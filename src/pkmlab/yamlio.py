"""Reading YAML input safely and fast, keeping where each value was written.

:func:`load_yaml` reads one file into plain Python values (the YAML 1.1 types of
``yaml.safe_load``: mappings, lists, text, numbers, booleans, null, dates) and returns a
:class:`Locator` that gives the line and column of any field path. It is built on the event
stream of PyYAML's C parser (``yaml.CSafeLoader``; the pure-Python one when libyaml is missing)
and refuses hostile or broken input with one :class:`~pkmlab.errors.ParameterError`:

* files larger than :data:`MAX_BYTES` (1 MiB; pkmlab's files are a few kB);
* text that is not UTF-8 (a UTF-8 byte-order mark is allowed; UTF-16 and UTF-32 are accepted
  when the file starts with their byte-order mark, as the YAML specification allows);
* nesting deeper than :data:`MAX_DEPTH` levels (100), aliases included;
* aliases (``*name``) that together expand to more than :data:`MAX_ALIAS_NODES` values
  (the "billion laughs" bomb);
* duplicate keys in a mapping (naming both lines), more than one document, tags other than
  YAML's standard scalar ones, unhashable keys;
* syntax errors, with their line and column.

pkmlab's limits come first, whatever PyYAML is installed: libyaml applies limits of its own
(a nesting depth of 1,000 since PyYAML 6.0.4) and reads ahead of the events it has delivered,
so it can stop on its own rule before pkmlab's check sees the level that breaks pkmlab's. When
the C parser stops, the file is read again with PyYAML's pure-Python parser, which has no limits
of its own, and the first rule the file breaks is reported: pkmlab's, or the syntax error.

Merge keys (``<<: *defaults`` or ``<<: [*a, *b]``) follow the YAML 1.1 merge key specification
(https://yaml.org/type/merge.html): a key written in the mapping itself wins; otherwise a key
of a mapping earlier in the merge list wins over the same key of a later one. The mapping keeps
its own keys in their written order, followed by the merged keys it did not have, in the order
of the merge list and of each merged mapping.
"""

from __future__ import annotations

import codecs
import sys
import threading
from pathlib import Path
from typing import Any

import yaml
from yaml.events import AliasEvent, DocumentStartEvent, ScalarEvent
from yaml.events import MappingEndEvent as MapEnd
from yaml.events import MappingStartEvent as MapStart
from yaml.events import SequenceEndEvent as SeqEnd
from yaml.events import SequenceStartEvent as SeqStart

from .errors import ParameterError, Shown, format_field, parse_field

__all__ = ["MAX_BYTES", "MAX_DEPTH", "MAX_ALIAS_NODES", "Locator", "load_yaml", "remember",
           "where", "locate_error"]

#: largest YAML file read (bytes)
MAX_BYTES = 1 << 20
#: deepest nesting of mappings and lists
MAX_DEPTH = 100
#: most values that all aliases of one file may expand to
MAX_ALIAS_NODES = 10_000

_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
_CONSTRUCTOR = yaml.constructor.SafeConstructor()
_RESOLVER = yaml.resolver.Resolver()
_TAG = "tag:yaml.org,2002:"
_SCALAR_TAGS = {_TAG + t for t in ("null", "bool", "int", "float", "binary", "timestamp")}
_BOMS = ((codecs.BOM_UTF32_LE, "utf-32"), (codecs.BOM_UTF32_BE, "utf-32"),
         (codecs.BOM_UTF8, "utf-8-sig"), (codecs.BOM_UTF16_LE, "utf-16"),
         (codecs.BOM_UTF16_BE, "utf-16"))
_TEXT = "UTF-8 text (or UTF-16 with a byte-order mark)"
_MERGE = object()
_NO_KEY = object()
_ANY = object()


class Locator:
    """Line and column (both from 1) of the values of one YAML file, by field path.

    ``locate(("evaluate", "workspace", "resolution"))`` → ``(12, 5)``, the position of the key
    ``resolution`` (of the item, for list entries); a path that is not in the file gives the
    position of its deepest ancestor that is (``nearest=False`` gives None instead). ``name`` is
    the file's name, as shown in error messages.
    """

    def __init__(self, name: str, positions: dict[tuple, tuple[int, int]],
                 ids: dict[int, tuple]):
        self.name = name
        self.positions = positions
        self.ids = ids          # id() of each mapping and list read → its path

    def __call__(self, path, nearest: bool = True) -> tuple[int, int] | None:
        path = tuple(path)
        while True:
            pos = self.positions.get(path)
            if pos is not None or not nearest or not path:
                return pos
            path = path[:-1]

    def text(self, path) -> str:
        line, col = self(path) or (1, 1)
        return f"{self.name}, line {line}, column {col}"


def _fail(name: str, line: int, col: int, allowed: str, got: Any, field: str = "") -> None:
    """``<file> (line L, column C): …``, or ``<field> (<file name>, line L, column C): …``."""
    if field:
        raise ParameterError(field, allowed, got, f"{Path(name).name}, line {line}, column {col}")
    raise ParameterError(name, allowed, got, where=f"line {line}, column {col}")


def _decode(raw: bytes, name: str) -> str:
    encoding = next((enc for bom, enc in _BOMS if raw.startswith(bom)), None)
    if encoding is None:
        encoding = "utf-8"
        if b"\x00" in raw:
            i = raw.index(b"\x00")
            _fail(name, raw.count(b"\n", 0, i) + 1, i - raw.rfind(b"\n", 0, i), _TEXT,
                  Shown("a NUL byte (UTF-16 or binary without a byte-order mark?)"))
    try:
        return raw.decode(encoding)
    except UnicodeDecodeError as exc:
        i = exc.start
        enc = encoding.removesuffix("-sig").upper()
        _fail(name, raw.count(b"\n", 0, i) + 1, i - raw.rfind(b"\n", 0, i), _TEXT,
              Shown(f"the byte 0x{raw[i]:02x}, which is not {enc} ({exc.reason})"))


def _syntax(exc: yaml.YAMLError, text: str, name: str) -> None:
    mark = getattr(exc, "problem_mark", None)
    if isinstance(exc, yaml.reader.ReaderError):
        i = exc.position
        line, col = text.count("\n", 0, i) + 1, i - text.rfind("\n", 0, i)
        char = chr(exc.character) if isinstance(exc.character, int) else exc.character
        _fail(name, line, col, "YAML text (printable characters)",
              Shown(f"the character {char!r} ({exc.reason})"))
    problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
    context, cmark = getattr(exc, "context", None), getattr(exc, "context_mark", None)
    if context and cmark is not None:
        problem += f" ({context} at line {cmark.line + 1}, column {cmark.column + 1})"
    line, col = (mark.line + 1, mark.column + 1) if mark is not None else (1, 1)
    _fail(name, line, col, "valid YAML", Shown("a syntax error: " + problem))


class _Frame:
    __slots__ = ("value", "path", "start", "key", "key_pos", "anchor", "nodes", "height",
                 "merges")

    def __init__(self, value, path, start, anchor):
        self.value, self.path, self.start, self.anchor = value, path, start, anchor
        self.key, self.key_pos, self.nodes, self.height, self.merges = _NO_KEY, None, 1, 1, []


def _short(tag: str) -> str:
    return "!!" + tag.removeprefix(_TAG) if tag.startswith(_TAG) else tag


def _scalar(ev: ScalarEvent, name: str) -> Any:
    tag = ev.tag
    if tag is None or tag == "!":
        tag = _RESOLVER.resolve(yaml.ScalarNode, ev.value, ev.implicit)
    if tag == _TAG + "str" or tag == _TAG + "value":
        return ev.value
    if tag == _TAG + "merge":
        return _MERGE
    line, col = ev.start_mark.line + 1, ev.start_mark.column + 1
    if tag not in _SCALAR_TAGS:
        _fail(name, line, col, "a plain value (YAML's standard tags only)", Shown(_short(tag)))
    node = yaml.ScalarNode(tag, ev.value, ev.start_mark, ev.end_mark, style=ev.style)
    try:
        return _CONSTRUCTOR.yaml_constructors[tag](_CONSTRUCTOR, node)
    except Exception as exc:  # noqa: BLE001 - e.g. '!!int x' or an integer too long
        _fail(name, line, col, f"a valid {tag.removeprefix(_TAG)}",
              Shown(f"{ev.value[:40]!r} ({str(exc).splitlines()[-1][:80]})"))


def _build(text: str, name: str, max_depth: int, max_alias_nodes: int, loader):
    positions: dict[tuple, tuple[int, int]] = {}
    ids: dict[int, tuple] = {}
    anchors: dict[str, tuple[Any, int, int]] = {}
    stack: list[_Frame] = []
    root, documents, budget = None, 0, max_alias_nodes
    for ev in yaml.parse(text, Loader=loader):
        cls = type(ev)
        mark = getattr(ev, "start_mark", None)
        if cls is MapStart or cls is SeqStart:
            line, col = mark.line + 1, mark.column + 1
            if len(stack) >= max_depth:
                _fail(name, line, col, f"nested at most {max_depth} levels deep",
                      Shown(f"a level {max_depth + 1}"))
            default = _TAG + ("map" if cls is MapStart else "seq")
            if ev.tag not in (None, "!", default):
                _fail(name, line, col, "a plain mapping or list (YAML's standard tags only)",
                      Shown(_short(ev.tag)))
            path = _path(stack)
            positions.setdefault(path, (line, col))
            value = {} if cls is MapStart else []
            ids[id(value)] = path
            stack.append(_Frame(value, path, (line, col), ev.anchor))
            continue
        pos = (mark.line + 1, mark.column + 1) if mark is not None else (1, 1)
        if cls is ScalarEvent:
            value, nodes, height = _scalar(ev, name), 1, 0
            anchor = ev.anchor
        elif cls is AliasEvent:
            if ev.anchor not in anchors:
                _fail(name, mark.line + 1, mark.column + 1, "an alias of an anchor defined "
                      "before it (&name … *name)", Shown("*" + ev.anchor))
            value, nodes, height = anchors[ev.anchor]
            anchor = None
            budget -= nodes
            if budget < 0:
                _fail(name, mark.line + 1, mark.column + 1, f"at most {max_alias_nodes:,} "
                      "values expanded from aliases (*name) in all", Shown(
                          f"*{ev.anchor}, bringing them to {max_alias_nodes - budget:,}"))
            if len(stack) + height > max_depth:
                _fail(name, mark.line + 1, mark.column + 1, f"nested at most {max_depth} "
                      "levels deep", Shown(f"*{ev.anchor}, reaching level {len(stack) + height}"))
        elif cls is MapEnd or cls is SeqEnd:
            frame = stack.pop()
            if frame.merges:
                _merge(frame, positions, name)
            value, nodes, height, anchor = frame.value, frame.nodes, frame.height, frame.anchor
            pos = frame.start
        elif cls is DocumentStartEvent:
            documents += 1
            if documents > 1:
                _fail(name, mark.line + 1, mark.column + 1, "a single YAML document",
                      Shown("a second document ('---')"))
            continue
        else:
            continue
        if anchor is not None:
            anchors[anchor] = (value, nodes, height)
        if not stack:
            root = "<<" if value is _MERGE else value
            positions.setdefault((), pos)
            continue
        _add(stack[-1], value, nodes, height, pos, name, positions)
    return root, Locator(Path(name).name, positions, ids)


def _path(stack: list[_Frame]) -> tuple:
    if not stack:
        return ()
    top = stack[-1]
    if isinstance(top.value, list):
        return top.path + (len(top.value),)
    return top.path + (top.key,) if top.key is not _NO_KEY else top.path


def _add(frame: _Frame, value, nodes: int, height: int, pos, name: str, positions) -> None:
    frame.nodes += nodes
    frame.height = max(frame.height, height + 1)
    if value is _MERGE and (isinstance(frame.value, list) or frame.key is not _NO_KEY):
        value = "<<"            # '<<' is a merge only where a key is expected
    if isinstance(frame.value, list):
        positions.setdefault(frame.path + (len(frame.value),), pos)
        frame.value.append(value)
        return
    if frame.key is _NO_KEY:
        if isinstance(value, dict | list):
            _fail(name, *pos, "a plain key (text or a number)", Shown(
                "a mapping" if isinstance(value, dict) else "a list"),
                field=format_field(frame.path) or "(top level)")
        frame.key, frame.key_pos = value, pos
        return
    key, frame.key = frame.key, _NO_KEY
    if key is _MERGE:
        frame.merges.append((value, frame.key_pos))
        return
    path = frame.path + (key,)
    if key in frame.value:
        (l1, c1), (l2, c2) = positions.get(path, (0, 0)), frame.key_pos
        _fail(name, l2, c2, "a key given once in its mapping", Shown(
            f"it twice, on lines {l1} and {l2}" if l1 != l2
            else f"it twice on line {l1}, at columns {c1} and {c2}"), field=format_field(path))
    positions[path] = frame.key_pos
    frame.value[key] = value


def _merge(frame: _Frame, positions, name: str) -> None:
    """``<<: *a`` or ``<<: [*a, *b]``, by the YAML 1.1 merge key specification: each merged
    mapping, in the order of the list, adds the keys the mapping does not have yet, so the
    mapping's own keys win, then the earlier merged mappings over the later ones."""
    for value, pos in frame.merges:
        maps = value if isinstance(value, list) else [value]
        if not all(isinstance(m, dict) for m in maps):
            _fail(name, *pos, "a mapping or a list of mappings to merge", value,
                  field=format_field(frame.path + ("<<",)))
        for m in maps:
            for k, v in m.items():
                if k not in frame.value:    # in place: the mapping's identity is indexed
                    frame.value[k] = v
                    positions.setdefault(frame.path + (k,), pos)


def load_yaml(path: str | Path, *, max_bytes: int | None = None, max_depth: int | None = None,
              max_alias_nodes: int | None = None) -> tuple[Any, Locator]:
    """Read one YAML file → ``(data, locate)``; see the module docstring for what is refused.

    The limits default to the module constants :data:`MAX_BYTES`, :data:`MAX_DEPTH` and
    :data:`MAX_ALIAS_NODES` (read at call time, so they can be changed for a session).

    Raises:
        ParameterError: ``<file> (line L, column C): must be …; got …``, or for a duplicate
            key ``<field path> (<file name>, line L, column C): …``.
    """
    path = Path(path)
    max_bytes = MAX_BYTES if max_bytes is None else max_bytes
    max_depth = MAX_DEPTH if max_depth is None else max_depth
    max_alias_nodes = MAX_ALIAS_NODES if max_alias_nodes is None else max_alias_nodes
    name = str(path)
    try:
        size = path.stat().st_size
        if size <= max_bytes:
            with path.open("rb") as f:
                raw = f.read(max_bytes + 1)
            size = len(raw)
    except OSError as exc:
        raise ParameterError(name, "a readable YAML file", Shown(exc.strerror or str(exc))) \
            from None
    if size > max_bytes:
        raise ParameterError(name, f"at most {max_bytes:,} bytes (pkmlab.yamlio.MAX_BYTES)",
                             Shown(f"{size:,} bytes"))
    text = _decode(raw, name)
    limits = (max_depth, max_alias_nodes)
    try:
        return _build(text, name, *limits, loader=_LOADER)
    except yaml.YAMLError as exc:
        if _LOADER is yaml.SafeLoader:
            _syntax(exc, text, name)
    except RecursionError:  # not expected (the depth is limited); never a traceback
        _fail(name, 1, 1, f"nested at most {max_depth} levels deep", Shown("deeper nesting"))
    # the C parser stopped: the pure-Python one, without limits of its own, finds which rule
    # the file breaks first (pkmlab's, or a syntax error), as the module docstring says
    try:
        return _build(text, name, *limits, loader=yaml.SafeLoader)
    except yaml.YAMLError as exc:
        _syntax(exc, text, name)


# ---- errors that name the line and column of a field ------------------------------------------

class _Read:
    __slots__ = ("data", "locate", "frame")

    def __init__(self, data, locate, frame):
        self.data, self.locate, self.frame = data, locate, frame


_READS: list[_Read] = []
_LOCK = threading.Lock()


def remember(data: Any, locate: Locator, up: int = 2) -> Any:
    """Remember where the values of ``data`` (read by :func:`load_yaml`) are, for as long as
    the reading call runs; returns ``data``.

    The reading call is the function ``up`` frames above this one (the caller of the caller):
    :func:`where` only answers for files read by a call that is still running, or that the error
    passed through, so a mapping that merely looks like an older file's never gets its lines.
    """
    frame = sys._getframe(up)
    with _LOCK:
        live = _live(None)
        _READS[:] = [r for r in _READS if id(r.frame) in live][-15:]
        _READS.append(_Read(data, locate, frame))
    return data


def _live(tb) -> set[int]:
    ids, f = set(), sys._getframe(1)
    while f is not None:
        ids.add(id(f))
        f = f.f_back
    while tb is not None:
        ids.add(id(tb.tb_frame))
        tb = tb.tb_next
    return ids


def _resolve(data, path: tuple):
    node = data
    for p in path:
        if isinstance(node, dict) and p in node:
            node = node[p]
        elif isinstance(node, list) and isinstance(p, int) and 0 <= p < len(node):
            node = node[p]
        else:
            return _ANY
    return node


def where(path: tuple, value: Any = _ANY, show: tuple | None = None, tb=None) -> str | None:
    """``"<file>, line L, column C"`` of ``show`` (default ``path``) in a remembered file in
    which ``path`` holds ``value`` (this very object; any value if not given), or None.

    Files read by a call still running are searched, the latest first, then those read by a call
    the traceback ``tb`` went through. A mapping or list found under another path (e.g. a
    mechanism's overrides in a study file) is located there.
    """
    show = path if show is None else show
    live = _live(tb)
    with _LOCK:
        reads = [r for r in reversed(_READS) if id(r.frame) in live]
    for r in reads:
        node = _resolve(r.data, path)
        if node is not _ANY and (value is _ANY or node is value):
            return r.locate.text(show)
    if isinstance(value, dict | list):
        for r in reads:
            found = r.locate.ids.get(id(value))
            if found is not None and _resolve(r.data, found) is value:
                return r.locate.text(found + tuple(show[len(path):]))
    return None


def locate_error(exc: ParameterError) -> ParameterError:
    """Add the file position of ``exc.field`` to an error raised while reading a file.

    For errors without one (raised after validation, e.g. by a mechanism's constructor) whose
    field path is in a file read by a call the error passed through.
    """
    if exc.where is None:
        path = parse_field(exc.field)
        found = where(path, tb=exc.__traceback__) if path else None
        if found is not None:
            exc.locate(found)
    return exc
