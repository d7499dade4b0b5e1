"""One mechanism of every registered family for the export tests: the first shipped file of
each family (tests/conftest.py's instances), plus the three-leg test plugin ``tri3``
(registered here). A family added to the registry joins automatically; one without a shipped
file fails the export tests, naming it."""

from __future__ import annotations

import sys
from pathlib import Path

from pkmlab.mechanisms import REGISTRY, register_family

sys.path.insert(0, str(Path(__file__).parent / "data" / "plugin3"))
import pkmlab_tri3_family as tri3  # noqa: E402
from conftest import MECHANISMS  # noqa: E402

register_family(tri3.Tri3)


def sample(family: str):
    if family == "tri3":
        return tri3.reporters_tripod(name="tri3-tripod")
    for name in sorted(MECHANISMS):
        m = MECHANISMS[name]
        if m.family == family:
            return m
    raise AssertionError(f"family {family!r} has no shipped mechanism file to export")


FAMILIES = sorted(REGISTRY)
