"""The metrics a design study can optimise or constrain: one registry, read by everyone.

Each evaluator (:mod:`.evaluators`) declares the metrics it writes beside its computation, with
their unit, what they mean and what kind of number they are; registering the evaluator
(:func:`~pkmlab.study.evaluators.register_evaluator`) adds them to :data:`METRICS`. The study
validator, ``pkmlab schema``, ``pkmlab metrics`` and the README table all read this registry,
so a metric is defined exactly once.

Kinds of number (``statistic``):

* ``exact`` — computed exactly for the geometry (footprint, stroke);
* ``grid`` — exact in z, on the workspace's x-y grid and sampled orientation set (volumes:
  carry their error estimate in ``workspace_volume_error``);
* ``worst-case`` — the extreme over *every* voxel of the workspace grid and *every* sample of
  its orientation set (never a random sample's extreme), or over every sample of every
  required motion and every actuator;
* ``bound`` — a bracketed optimum: the value is the largest verified level, the bracket
  (``<name>_bracket``, and ``<name>_upper`` where given) how far above it the truth can be;
  for a smallest value (``needed_stroke``) the value is the certified level and the truth
  lies at most the bracket below it (``<name>_lower``);
* ``sampled`` — a Monte-Carlo statistic over random poses (its name says so, or it carries a
  standard error);
* ``flag`` — 1 or 0;
* ``search`` — the best value a stated search found (a scan and a local refinement), not a
  proven optimum (``task_centre_*`` with ``task.centre: auto``);
* ``guaranteed`` — a proven bound over the *continuous* orientation set and x-y plane
  (:mod:`pkmlab.workspaces.bracket.columns`): ``*_volume_lower`` never exceeds the true volume,
  ``*_volume_upper`` never falls below it. An objective that maximises a volume should use
  ``*_volume_lower`` (a design is credited only with volume it certainly has); a constraint
  "volume ≤ limit" should use ``*_volume_upper``.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Metric", "METRICS", "KIND_VOLUMES", "metric", "metrics_of", "STATISTICS"]

STATISTICS = ("exact", "grid", "worst-case", "bound", "sampled", "flag", "guaranteed",
              "search")


@dataclass(frozen=True)
class Metric:
    """One study metric: ``name`` written by ``evaluator`` in ``unit`` (an evaluator declares
    its metrics with ``evaluator=""``; registration fills in its name)."""

    name: str
    evaluator: str
    unit: str
    statistic: str
    description: str

    def __post_init__(self):
        if self.statistic not in STATISTICS:
            raise ValueError(f"unknown statistic {self.statistic!r}")

    @property
    def label(self) -> str:
        """``name (unit)`` for tables and axes."""
        return f"{self.name} ({self.unit})" if self.unit else self.name


#: name → :class:`Metric`, in evaluator registration order (filled by
#: :func:`pkmlab.study.evaluators.register_evaluator`; each evaluator module declares its own;
#: importing :mod:`pkmlab.study` registers the built-in ones)
METRICS: dict[str, Metric] = {}

#: ``<kind>_volume`` → the workspace kind it requires
KIND_VOLUMES = {f"{k}_volume{b}": k for k in ("constant", "reachable", "dexterous")
                for b in ("", "_lower", "_upper")}


def metric(name: str) -> Metric:
    return METRICS[name]


def metrics_of(evaluator: str) -> tuple[str, ...]:
    """Names of the metrics ``evaluator`` writes."""
    return tuple(m.name for m in METRICS.values() if m.evaluator == evaluator)
