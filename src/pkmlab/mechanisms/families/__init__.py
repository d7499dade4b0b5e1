"""The built-in families, one module each: the mechanism class with its kernels, its YAML
model (``spec_model``) and its named study variables (``design_aliases``).

They are registered by :func:`pkmlab.mechanisms.register_family`, exactly as plugin families
are. The generic six-leg family's YAML model builds through the paired-circle generators of the
other families, so it lives in :mod:`.sixleg_spec` and is given at registration.
"""

from .delta3 import Delta3
from .fivebar import FiveBar
from .ldelta3 import LDelta3
from .luzi3 import Luzi3
from .prs3 import Prs3
from .psu6 import PSU6
from .rpr3 import Rpr3
from .rss6 import RSS6
from .sixleg import SixLeg
from .sixleg_spec import SixLegSpec
from .ups6 import UPS6

__all__ = ["BUILTIN_FAMILIES", "PSU6", "UPS6", "Luzi3", "RSS6", "SixLeg", "Delta3", "LDelta3",
           "Rpr3", "FiveBar", "Prs3"]

#: ``(family class, YAML model given at registration or None)``, in registration order
BUILTIN_FAMILIES = ((PSU6, None), (UPS6, None), (Luzi3, None), (RSS6, None), (SixLeg, SixLegSpec),
                    (Delta3, None), (LDelta3, None), (Rpr3, None), (FiveBar, None), (Prs3, None))
