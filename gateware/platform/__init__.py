"""The boards the projector builds for.

``Board`` is the platform class every build uses (the DLP7000's, the Atlys); ``BOARDS`` names
every board's platform class, the DLP9500's SVEC among them. The core never imports vendor
primitives; they live here and in the platform top.
"""

from .atlys import AtlysProjectorPlatform
from .svec import SvecProjectorPlatform

__all__ = ["Board", "BOARDS"]

#: The target board. Another board: a platform class like :class:`AtlysProjectorPlatform`.
Board = AtlysProjectorPlatform

#: Every board by name: the Atlys (two buses, the DLP7000) and the SVEC (four buses, the DLP9500).
BOARDS = {"atlys": AtlysProjectorPlatform, "svec": SvecProjectorPlatform}
