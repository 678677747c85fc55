"""boxplus: least squares on manifolds (the ⊞-method) for calibration and SLAM.

Manifold values behave like vectors from outside: ``x + delta`` is ⊞ and
``y - x`` is ⊟. Poses use the tangent order [translation, rotation];
quaternions are [x, y, z, w].
"""

from boxplus._core import (
    SE2,
    SE3,
    SO2,
    SO3,
    S2,
    BoxplusError,
    BoxplusIndexError,
    Manifold,
    ParseError,
    Problem,
    Rn,
    SolveSummary,
    __version__,
    make_manifold,
    make_product_manifold,
)

__all__ = [
    "SE2",
    "SE3",
    "SO2",
    "SO3",
    "S2",
    "Rn",
    "BoxplusError",
    "BoxplusIndexError",
    "Manifold",
    "ParseError",
    "Problem",
    "SolveSummary",
    "__version__",
    "make_manifold",
    "make_product_manifold",
]
