"""What a mechanism's platform can do: its free pose coordinates, declared as data.

Every mechanism carries a :class:`Mobility` (``Mechanism.mobility``, :data:`SPATIAL` unless the
family says otherwise). Its coordinates are a subset of pkmlab's six pose coordinates
:data:`POSE` (``x, y, z`` in mm and the Z-Y-X Euler angles ``theta_x, theta_y, theta_z`` in rad);
the others are fixed at the mechanism's nominal pose. So

* :data:`SPATIAL` — all six (hexapods);
* :data:`TRANSLATIONAL` — ``x, y, z`` (delta robots, 3-UPU translational platforms);
* :data:`PLANAR` — ``x, y, theta_z`` (3-RPR, five-bar mechanisms with their orientation).

A coordinate that is free in the Euler pose maps to one column of the base-frame twist
``[v; ω]`` (``x, y, z`` to ``v``, ``theta_z`` to ``ω_z`` at any pose, and all three angles
together to ``ω``): :attr:`Mobility.twist_columns` selects the columns of the full ``(L, 6)``
velocity Jacobian that act on the free motion.

**Dependent coordinates.** A mechanism may also declare coordinates that are not fixed but
follow from the free ones (``Mobility.dependent``; a 3-PRS: ``z, theta_x, theta_y`` free,
``x, y, theta_z`` dependent — the parasitic motions). Then:

* the family completes poses itself: ``mech.complete(poses)`` gives six-coordinate poses with
  the dependent coordinates computed from the free ones, and ``mech.parasitic(poses)`` gives
  the dependent coordinates alone, ``(N, len(dependent))``; :meth:`Mobility.full` cannot (it
  fills them from ``fixed``), so ``Mechanism._free_to_full`` is the family's;
* the inverse kinematics reads the free coordinates only (a given pose's dependent coordinates
  are replaced by their values);
* the free twist columns are the base-frame twist components of the free coordinates' (3-PRS:
  ``v_z, ω_x, ω_y``), and the Jacobian ``(L, width)`` is the derivative of the actuator values
  along them with the dependent twist components following (the constraint solved for them):
  what the protocol's finite-difference check measures, since the inverse kinematics depends on
  the free coordinates alone;
* a tilt angle may be free without ``theta_z`` when ``theta_z`` is dependent.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..poses import POSE, POSE_SIZE

__all__ = ["POSE", "Mobility", "SPATIAL", "TRANSLATIONAL", "PLANAR", "require_spatial"]



@dataclass(frozen=True)
class Mobility:
    """The free pose coordinates of a mechanism.

    Attributes:
        name: ``"spatial"``, ``"translational"``, ``"planar"`` or a family's own.
        coordinates: the free coordinates, a subset of :data:`POSE` in its order.
        dependent: coordinates that follow from the free ones (module docstring), in the
            order of :data:`POSE`; the others are fixed at the nominal pose.
    """

    name: str
    coordinates: tuple[str, ...]
    dependent: tuple[str, ...] = ()

    def __post_init__(self):
        for what, names in (("coordinates", self.coordinates), ("dependent", self.dependent)):
            unknown = [c for c in names if c not in POSE]
            if unknown or len(set(names)) != len(names) \
                    or list(names) != sorted(names, key=POSE.index):
                raise ValueError(f"{what} must be distinct names of {POSE} in that order, "
                                 f"got {names}")
        if set(self.coordinates) & set(self.dependent):
            raise ValueError(f"a coordinate is free or dependent, not both: {self.coordinates}"
                             f" and {self.dependent}")
        tilts = {"theta_x", "theta_y"} & set(self.coordinates)
        known = set(self.coordinates) | set(self.dependent)
        if tilts and ("theta_z" not in known or len({"theta_x", "theta_y"} & known) == 1):
            raise ValueError("a free tilt angle needs all three angles free or dependent, got "
                             f"{self.coordinates} (dependent {self.dependent})")

    @property
    def width(self) -> int:
        """Number of free coordinates (and of free twist components)."""
        return len(self.coordinates)

    @property
    def index(self) -> np.ndarray:
        """Positions of the free coordinates in the six-coordinate pose."""
        return np.array([POSE.index(c) for c in self.coordinates], dtype=np.intp)

    #: the free columns of the base-frame twist [v; ω] (the same positions as the pose's)
    twist_columns = index

    @property
    def is_spatial(self) -> bool:
        return self.width == len(POSE)

    @property
    def rotations(self) -> bool:
        """True when an orientation coordinate is free (orientation sets make sense)."""
        return any(c.startswith("theta") for c in self.coordinates)

    @property
    def units(self) -> tuple[str, ...]:
        """Unit of each free coordinate (``mm`` or ``rad``)."""
        return tuple("rad" if c.startswith("theta") else "mm" for c in self.coordinates)

    def full(self, X, fixed) -> np.ndarray:
        """Poses in the free coordinates ``(N, width)`` → six-coordinate poses ``(N, 6)``,
        the other coordinates taken from ``fixed (6,)`` (the nominal pose)."""
        X = np.asarray(X, dtype=float)
        if X.ndim > 2 or X.shape[-1] != self.width:
            raise ParameterError("poses", f"an array of shape ({self.width},) or (N, "
                                 f"{self.width}) ({', '.join(self.coordinates)})", X.shape)
        X = X.reshape(-1, self.width)
        out = np.repeat(np.asarray(fixed, dtype=float).reshape(1, POSE_SIZE), len(X), axis=0)
        out[:, self.index] = X
        return out

    def free(self, poses) -> np.ndarray:
        """Six-coordinate poses ``(N, 6)`` → their free coordinates ``(N, width)``."""
        poses = np.asarray(poses, dtype=float)
        return poses if self.is_spatial else poses[..., self.index]


SPATIAL = Mobility("spatial", POSE)
TRANSLATIONAL = Mobility("translational", ("x", "y", "z"))
PLANAR = Mobility("planar", ("x", "y", "theta_z"))


def require_spatial(mech, what: str, field: str = "mechanism") -> None:
    """Refuse, naming ``field``, a mechanism whose mobility is not spatial for an analysis that
    still assumes six free coordinates (workspaces, dexterity, studies: lower-mobility
    mechanisms have their kinematics, contract suite and plugins; these layers come next)."""
    mob = mech.mobility
    if not mob.is_spatial:
        raise ParameterError(field, f"a mechanism with six free pose coordinates for {what} "
                             "(not yet available for lower-mobility mechanisms)",
                             f"family {mech.family!r} with {mob.name} mobility "
                             f"({', '.join(mob.coordinates)})")
