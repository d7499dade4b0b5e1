"""The metrics a design study can optimise or constrain: one registry, read by everyone.

Each evaluator (:mod:`.evaluators`) declares the metrics it writes here, with their unit, what
they mean and what kind of number they are. The study validator, ``pkmlab schema``, ``pkmlab
metrics`` and the README table all read this registry, so a metric is defined exactly once.

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
* ``guaranteed`` — a proven bound over the *continuous* orientation set and x-y plane
  (:mod:`pkmlab.workspaces.bracket`): ``*_volume_lower`` never exceeds the true volume,
  ``*_volume_upper`` never falls below it. An objective that maximises a volume should use
  ``*_volume_lower`` (a design is credited only with volume it certainly has); a constraint
  "volume ≤ limit" should use ``*_volume_upper``.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Metric", "METRICS", "KIND_VOLUMES", "metric", "metrics_of", "metrics_markdown",
           "STATISTICS"]

STATISTICS = ("exact", "grid", "worst-case", "bound", "sampled", "flag", "guaranteed")


@dataclass(frozen=True)
class Metric:
    """One study metric: ``name`` written by ``evaluator`` in ``unit``."""

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


_ALL = [
    # geometry: always available
    Metric("base_outer_radius", "geometry", "mm", "exact",
           "footprint: largest horizontal distance of a base joint from the base z axis"),
    Metric("platform_outer_radius", "geometry", "mm", "exact",
           "largest distance of a platform joint from the platform joints' centroid"),
    Metric("stroke_length", "geometry", "mm", "exact",
           "prismatic actuator travel (max - min); null for rotary actuators (servo_range)"),
    Metric("servo_range", "geometry", "deg", "exact",
           "rotary actuator travel (max - min of the servo angle); null for prismatic "
           "actuators (stroke_length)"),
    # workspace
    Metric("workspace_volume", "workspace", "cm³", "grid",
           "volume of the requested workspace (exact in z, x-y grid and sampled orientation "
           "set; error in workspace_volume_error)"),
    Metric("workspace_volume_error", "workspace", "cm³", "grid",
           "error estimate of workspace_volume: content of the boundary columns"),
    Metric("constant_volume", "workspace", "cm³", "grid",
           "workspace_volume when the requested kind is 'constant'"),
    Metric("reachable_volume", "workspace", "cm³", "grid",
           "workspace_volume when the requested kind is 'reachable'"),
    Metric("dexterous_volume", "workspace", "cm³", "grid",
           "workspace_volume when the requested kind is 'dexterous'"),
    Metric("workspace_empty", "workspace", "", "flag", "1 if the requested workspace is empty"),
    # guaranteed volume bracket (evaluate.volume_bracket)
    Metric("workspace_volume_lower", "volume_bracket", "cm³", "guaranteed",
           "proven lower bound of the requested workspace's volume over the continuous "
           "orientation set and positions (stroke and connectivity; psu6, ups6, luzi3, rss6): "
           "the one to maximise"),
    Metric("workspace_volume_upper", "volume_bracket", "cm³", "guaranteed",
           "proven upper bound of the same volume: the one to constrain from above"),
    Metric("workspace_volume_bracket_width", "volume_bracket", "%", "guaranteed",
           "100·(upper − lower)/upper when the bracket stopped (target or budget; which one "
           "is in the notes)"),
    *[Metric(f"{k}_volume_{b}", "volume_bracket", "cm³", "guaranteed",
             f"workspace_volume_{b} when the requested kind is '{k}'")
      for k in ("constant", "reachable", "dexterous") for b in ("lower", "upper")],
    Metric("z_span", "workspace", "mm", "grid", "height of the workspace (0 when empty)"),
    # inscribed shapes
    Metric("inscribed_box_volume", "inscribed", "cm³", "grid",
           "largest inscribed axis-aligned box found (verified by sampling)"),
    Metric("inscribed_box_edge", "inscribed", "mm", "grid", "shortest edge of that box"),
    Metric("inscribed_cylinder_radius", "inscribed", "mm", "grid",
           "largest inscribed vertical cylinder found (verified by sampling)"),
    Metric("inscribed_cylinder_volume", "inscribed", "cm³", "grid", "volume of that cylinder"),
    # orientation capability
    Metric("orientation_capability", "orientation_capability", "deg", "bound",
           "largest a such that the ±a simultaneous Euler box has a non-empty dexterous "
           "workspace: lower end of the bracket, a position certified for the continuous "
           "box (psu6, ups6, stroke only; other families: the largest grid level verified "
           "by bisection)"),
    Metric("orientation_capability_upper", "orientation_capability", "deg", "bound",
           "upper end of the bracket: the box's orientation grid and the orientations of "
           "the box that refuted candidate points admit no position, proved by branch and "
           "bound over continuous positions (other families: the first grid level found "
           "empty)"),
    Metric("orientation_capability_bracket", "orientation_capability", "deg", "bound",
           "orientation_capability_upper - orientation_capability (psu6, ups6: the search "
           "stops within 0.01° or notes why not; grid: the bisection runs to 0.01°)"),
    # needed stroke (continuous optimum, psu6 / ups6)
    Metric("needed_stroke", "needed_stroke", "mm", "bound",
           "smallest actuator travel (upper limit − lower limit, the lower limit kept) at "
           "which the workspace's simultaneous Euler box has a dexterous position: upper end "
           "of the bracket, a position certified for the continuous box (psu6, ups6, stroke "
           "only; null with a note otherwise): the one to minimise"),
    Metric("needed_stroke_lower", "needed_stroke", "mm", "bound",
           "lower end of the bracket: below it a sample of the box (grid plus binding "
           "orientations found by local optimisation) admits no position, proved by branch "
           "and bound over continuous positions"),
    Metric("needed_stroke_bracket", "needed_stroke", "mm", "bound",
           "needed_stroke - needed_stroke_lower (the search stops at 0.01 mm, or says in a "
           "note why it stopped wider)"),
    # dexterity
    Metric("nominal_kappa", "dexterity", "", "exact",
           "κ of the homogenised Jacobian at the nominal pose"),
    Metric("characteristic_length", "dexterity", "mm", "exact",
           "length L homogenising the Jacobian (Angeles' or the one given)"),
    Metric("worst_kappa", "dexterity", "", "worst-case",
           "largest κ over every voxel of the workspace and every end of its exact columns × "
           "every orientation sample (inf when a singular pose is found inside or on the "
           "boundary: stored as null with a note)"),
    Metric("min_force", "dexterity", "N", "worst-case",
           "smallest force held in every direction over every voxel and column end × "
           "orientation sample"),
    Metric("singularity_free", "dexterity", "", "flag",
           "0 when a singular pose is certified in the workspace or on its boundary (a "
           "singular voxel or column end, or a sign change of det J between neighbours); 1 "
           "when none was found — a search, not a proof: a singularity between samples is "
           "not excluded"),
    Metric("gci", "dexterity", "", "sampled",
           "global conditioning index: Monte-Carlo mean of 1/κ over the workspace "
           "(singular poses count 0); standard error in gci_std_error"),
    Metric("gci_std_error", "dexterity", "", "sampled", "standard error of gci"),
    Metric("sampled_max_kappa", "dexterity", "", "sampled",
           "largest κ among the GCI's random poses (a sample statistic, ≤ worst_kappa)"),
    Metric("sampled_min_force", "dexterity", "N", "sampled",
           "smallest all-direction force among the GCI's random poses (≥ min_force)"),
    # trajectory
    Metric("paper_motion_fits", "trajectory", "", "flag",
           "1 if Hopkins & Williams' ±2 in / ±30° motion stays within the stroke"),
    Metric("paper_motion_margin", "trajectory", "mm", "exact",
           "smallest stroke margin along that motion (negative: the overshoot)"),
    # requirements: the task (a required workspace)
    Metric("task_contained", "task", "", "flag",
           "1 if every position of the task region works at every orientation of its set "
           "(psu6/ups6: proved over the continuous region and the continuous orientation set, "
           "0 with a note if undecided; luzi3: sampled, see notes)"),
    Metric("task_margin", "task", "mm", "bound",
           "largest growth of the task region that stays contained (a lower bound of its "
           "distance to the workspace boundary, bracket 0.01 mm); negative: the erosion needed"),
    Metric("task_orientation_margin", "task", "deg", "bound",
           "largest widening of the task's orientation set that stays contained (bracket "
           "0.01°); negative: the narrowing needed"),
    # requirements: required motions with the payload (inverse dynamics)
    Metric("motions_feasible", "motions", "", "flag",
           "1 if every sample of every required motion is within the stroke and not singular"),
    Metric("peak_actuator_force", "motions", "N", "worst-case",
           "largest |actuator force| over every sample of every required motion (Newton–Euler "
           "of platform + payload + legs, f = J⁻ᵀ·w); linear actuators only, null for rotary "
           "ones (peak_actuator_torque)"),
    Metric("rms_actuator_force", "motions", "N", "worst-case",
           "largest RMS actuator force (time-weighted, per actuator and motion); linear "
           "actuators only"),
    Metric("peak_actuator_speed", "motions", "mm/s", "worst-case",
           "largest |actuator speed| over every sample of every required motion; linear "
           "actuators only, null for rotary ones (peak_actuator_angular_speed)"),
    Metric("peak_actuator_torque", "motions", "N·mm", "worst-case",
           "largest |servo torque| over every sample of every required motion (τ = J⁻ᵀ·w); "
           "rotary actuators only, null for linear ones"),
    Metric("rms_actuator_torque", "motions", "N·mm", "worst-case",
           "largest RMS servo torque (time-weighted, per actuator and motion); rotary "
           "actuators only"),
    Metric("peak_actuator_angular_speed", "motions", "rad/s", "worst-case",
           "largest |servo angular speed| over every sample of every required motion; rotary "
           "actuators only"),
    Metric("peak_actuator_power", "motions", "W", "worst-case",
           "largest |actuator force × speed| (rotary: torque × angular speed) over every "
           "sample of every required motion"),
    # requirements: the payload held at rest over the workspace
    Metric("peak_servo_torque", "payload", "N·mm", "worst-case",
           "largest |servo torque| holding the payload at rest (τ = J⁻ᵀ·w, w the gravity "
           "wrench of payload + platform + leg-end masses) over every voxel × orientation "
           "sample of the workspace; rotary actuators only (null for prismatic)"),
    # requirements: actuators
    Metric("actuators_fit", "actuators", "", "flag",
           "1 if the chosen actuator meets force, speed, torque–speed and stroke along every "
           "required motion"),
    Metric("actuator_force_margin", "actuators", "%", "worst-case",
           "100·(1 − peak |force| / force limit); negative: exceeded"),
    Metric("actuator_speed_margin", "actuators", "%", "worst-case",
           "100·(1 − peak |speed| / speed limit); negative: exceeded"),
    Metric("actuator_torque_speed_margin", "actuators", "%", "worst-case",
           "100·min over samples of (available − required motor torque) / peak curve torque"),
    Metric("actuator_stroke_margin", "actuators", "mm", "worst-case",
           "actuator travel − the largest travel an actuator uses over the motions (rotary "
           "actuators: angle range, in deg)"),
    Metric("actuator_force_rating", "actuators", "N", "exact",
           "force limit of the chosen actuator (its size; rotary: torque limit in N·mm)"),
]

#: name → :class:`Metric`
METRICS: dict[str, Metric] = {m.name: m for m in _ALL}

#: ``<kind>_volume`` → the workspace kind it requires
KIND_VOLUMES = {f"{k}_volume{b}": k for k in ("constant", "reachable", "dexterous")
                for b in ("", "_lower", "_upper")}


def metric(name: str) -> Metric:
    return METRICS[name]


def metrics_of(evaluator: str) -> tuple[str, ...]:
    """Names of the metrics ``evaluator`` writes."""
    return tuple(m.name for m in _ALL if m.evaluator == evaluator)


def metrics_markdown() -> str:
    """The README's metric table."""
    rows = ["| metric | unit | evaluate block | kind | meaning |", "|---|---|---|---|---|"]
    for m in _ALL:
        block = "(always)" if m.evaluator == "geometry" else m.evaluator
        rows.append(f"| `{m.name}` | {m.unit or '—'} | {block} | {m.statistic} | "
                    f"{m.description} |")
    return "\n".join(rows) + "\n"
