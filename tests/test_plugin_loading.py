"""One entry-point loader for every registry: a broken plugin is logged and recorded, the
others are registered, a later success clears the record."""

from __future__ import annotations

import importlib.metadata

from pkmlab import export
from pkmlab.plugins import load_entry_points


class _EP:
    def __init__(self, name, obj):
        self.name, self.value, self._obj = name, f"fake:{name}", obj

    def load(self):
        if isinstance(self._obj, Exception):
            raise self._obj
        return self._obj


def test_entry_points_load_register_and_record_failures(monkeypatch, caplog):
    good = export.Exporter("fakefmt", "mesh", "a fake format", lambda mesh: b"")
    eps = [_EP("good", good), _EP("broken", ImportError("no module named nowhere")),
           _EP("clash", export.EXPORTERS["stl"].__class__("stl", "mesh", "x", lambda m: b""))]
    monkeypatch.setattr(importlib.metadata, "entry_points",
                        lambda group: eps if group == export.PLUGIN_GROUP else [])
    errors = {"good": "ImportError: an earlier failure"}
    try:
        loaded = export.registry.load_exporter_plugins()
        assert loaded == {"fakefmt": good} and export.EXPORTERS["fakefmt"] is good
        assert export.PLUGIN_ERRORS["broken"] == "ImportError: no module named nowhere"
        assert export.PLUGIN_ERRORS["clash"].startswith("ValueError: format 'stl' is already")
        assert "pkmlab exporter plugin 'broken' (fake:broken) not loaded" in caplog.text
        out = load_entry_points(export.PLUGIN_GROUP, lambda obj: obj, errors, "test",
                                skip={"broken", "clash"})
        assert out == {"good": good} and errors == {}          # success clears the record
    finally:
        export.EXPORTERS.pop("fakefmt", None)
        export.PLUGIN_ERRORS.clear()
