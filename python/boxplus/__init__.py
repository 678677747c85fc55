"""boxplus: least squares on manifolds (the ⊞-method) for calibration and SLAM.

Manifold values behave like vectors from outside: ``x + delta`` is ⊞ and
``y - x`` is ⊟. Poses use the tangent order [translation, rotation];
quaternions are [x, y, z, w].

The main entry point is :class:`OptimizationProblem`::

    p = boxplus.OptimizationProblem()
    x = p.add_random_var(boxplus.SE3())
    p.add_measurement(z, f, [x], constants=(...), sigma=0.5)
    summary = p.solve()          # a SolveSummary; the estimates are p.X
"""

from boxplus import batch, losses, measurements, noise, solver
from boxplus import blas_threads as blas_threads
from boxplus import parallel as parallel
from boxplus._core import (
    BoxplusError,
    BoxplusIndexError,
    IterationInfo,
    Loss,
    Manifold,
    NoiseModel,
    ParseError,
    Problem,
    SolverOptions,
    SolveSummary,
    __version__,
    make_manifold,
    make_product_manifold,
)
from boxplus.manifolds import (
    S2,
    SE2,
    SE3,
    SO2,
    SO3,
    Codec,
    ManifoldValue,
    Rn,
    codec_of,
    make_compound,
)
from boxplus.parallel import TaskResult as TaskResult
from boxplus.parallel import solve_many as solve_many
from boxplus.problem import EvaluationError, OptimizationProblem, UndeterminedWarning

__all__ = [
    "S2",
    "SE2",
    "SE3",
    "SO2",
    "SO3",
    "BoxplusError",
    "BoxplusIndexError",
    "Codec",
    "EvaluationError",
    "IterationInfo",
    "Loss",
    "Manifold",
    "ManifoldValue",
    "NoiseModel",
    "OptimizationProblem",
    "ParseError",
    "Problem",
    "Rn",
    "SolveSummary",
    "SolverOptions",
    "UndeterminedWarning",
    "__version__",
    "batch",
    "losses",
    "measurements",
    "noise",
    "solver",
    "codec_of",
    "make_compound",
    "make_manifold",
    "make_product_manifold",
]
