"""What a tolerance ladder's coarse rung keeps for the re-certification (issue 28, session 6).

A candidate re-certified at the fine tolerance (:func:`pkmlab.study.ladder.refine_design`)
needs its decoded mechanism and its workspace again: the workspace does not depend on the
rung, and the mechanism memoises its nominal pose and Angeles' length on its instance. When
the process that evaluated the candidate on the coarse rung also re-certifies it (always in
one process; by chance among a pool's workers), it takes them from here instead of computing
them again: the same mechanism (equal by geometry, :meth:`Mechanism.__eq__`) under the same
workspace request (equal pickles) gives the same workspace, so the re-certification's values
are those it would compute. A miss recomputes them.

At most :data:`KEEP` candidates and :data:`KEEP_BYTES` of their workspaces' arrays are kept
(the least recently kept leave first; a larger workspace is not kept); a kept one leaves when
it is taken, and :func:`pkmlab.study.ladder.refine` clears the rest.
"""

from __future__ import annotations

import pickle
from collections import OrderedDict

import numpy as np

__all__ = ["KEEP", "keep", "take", "clear"]

#: candidates kept at most (a demo-sized workspace is 10–60 kB)
KEEP = 256
#: bytes of the kept workspaces' arrays at most
KEEP_BYTES = 64 << 20

_KEPT: OrderedDict = OrderedDict()      # key → (mechanism, workspace, bytes)


def _bytes(result) -> int:
    """The bytes of ``result``'s arrays (fields and computed properties)."""
    held = getattr(result, "__dict__", {}).values()
    return sum(v.nbytes for v in held if isinstance(v, np.ndarray))


def _key(mech, request) -> tuple:
    return mech, pickle.dumps(sorted(request.items()), protocol=pickle.HIGHEST_PROTOCOL)


def keep(mech, request: dict, result) -> None:
    """Keep ``mech`` (the instance the coarse rung evaluated) and its workspace ``result``
    computed with ``request``."""
    key = _key(mech, request)
    size = _bytes(result)
    _KEPT.pop(key, None)
    if size > KEEP_BYTES:
        return
    _KEPT[key] = (mech, result, size)
    while len(_KEPT) > KEEP or sum(v[2] for v in _KEPT.values()) > KEEP_BYTES:
        _KEPT.popitem(last=False)


def take(mech, request: dict):
    """``(mechanism, workspace)`` kept for a mechanism equal to ``mech`` under ``request``
    (removed from the store), or None."""
    hit = _KEPT.pop(_key(mech, request), None)
    return None if hit is None else hit[:2]


def clear() -> None:
    _KEPT.clear()
