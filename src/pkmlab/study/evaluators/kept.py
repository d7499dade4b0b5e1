"""What a tolerance ladder's coarse rung keeps for the re-certification (issue 28, session 6).

A candidate re-certified at the fine tolerance (:func:`pkmlab.study.ladder.refine_design`)
needs its decoded mechanism and its workspace again: the workspace does not depend on the
rung, and the mechanism memoises its nominal pose and Angeles' length on its instance. When
the process that evaluated the candidate on the coarse rung also re-certifies it (always in
one process; by chance among a pool's workers), it takes them from here instead of computing
them again: the same mechanism (equal by geometry, :meth:`Mechanism.__eq__`) under the same
workspace request (equal pickles) gives the same workspace, so the re-certification's values
are those it would compute. A miss recomputes them.

At most :data:`KEEP` candidates are kept (the least recently kept leave first); a kept one
leaves when it is taken.
"""

from __future__ import annotations

import pickle
from collections import OrderedDict

__all__ = ["KEEP", "keep", "take", "clear"]

#: candidates kept at most (a demo-sized workspace is 10–60 kB)
KEEP = 256

_KEPT: OrderedDict = OrderedDict()


def _key(mech, request) -> tuple:
    return mech, pickle.dumps(sorted(request.items()), protocol=pickle.HIGHEST_PROTOCOL)


def keep(mech, request: dict, result) -> None:
    """Keep ``mech`` (the instance the coarse rung evaluated) and its workspace ``result``
    computed with ``request``."""
    key = _key(mech, request)
    _KEPT[key] = (mech, result)
    _KEPT.move_to_end(key)
    while len(_KEPT) > KEEP:
        _KEPT.popitem(last=False)


def take(mech, request: dict):
    """``(mechanism, workspace)`` kept for a mechanism equal to ``mech`` under ``request``
    (removed from the store), or None."""
    return _KEPT.pop(_key(mech, request), None)


def clear() -> None:
    _KEPT.clear()
