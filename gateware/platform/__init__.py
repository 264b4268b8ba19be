"""The board the projector builds for: the one place to change it.

``Board`` is the platform class every build uses. The core never imports vendor primitives;
they live here and in the platform top.
"""

from .atlys import AtlysProjectorPlatform

__all__ = ["Board"]

#: The target board. Another board: a platform class like :class:`AtlysProjectorPlatform`.
Board = AtlysProjectorPlatform
