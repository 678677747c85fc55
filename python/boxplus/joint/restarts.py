"""Random restarts around the best solution so far (Le & Ng, Sec. X).

Levenberg–Marquardt converges to a local minimum. After each convergence the
best-so-far estimate is perturbed with ⊞ on every free variable,
x ⊞ δ with δ ~ N(0, diag(s²)), and solved again; the lowest cost wins. The
random numbers come from ``numpy.random.default_rng(seed)``: the same seed
gives the same restarts.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from boxplus._core import SolveSummary
from boxplus.manifolds import S2, SE3, SO3, Rn, _CompoundBase
from boxplus.problem import EvaluationError, OptimizationProblem

__all__ = ["RestartResult", "default_perturbation", "solve_with_restarts"]


def default_perturbation(value: Any) -> np.ndarray:
    """Standard deviations (dof,) of a restart's ⊞-perturbation of ``value``.

    Rⁿ: 1 % of each coordinate plus 10⁻³; SO3 and S2: 0.01 rad; SE3:
    [5 mm (in metres) × 3, 0.01 rad × 3]; compounds: their members'; other
    manifolds: 0.01.
    """
    if isinstance(value, Rn):
        return 0.01 * np.abs(value.vec) + 1e-3
    if isinstance(value, (SO3, S2)):
        return np.full(value.dof, 0.01)
    if isinstance(value, SE3):
        return np.r_[np.full(3, 0.005), np.full(3, 0.01)]
    if isinstance(value, _CompoundBase):
        return np.concatenate([default_perturbation(getattr(value, m)) for m in value.members()])
    return np.full(len(value), 0.01)


@dataclass
class RestartResult:
    """Outcome of :func:`solve_with_restarts`.

    Attributes
    ----------
    best : SolveSummary
        The solve that reached the lowest cost (its values are in the problem).
    best_cost : float
        ½ Σ ρ(‖r‖²) at the returned estimate.
    costs : list of float
        Final cost of every solve, the first being the plain single solve.
    """

    best: SolveSummary
    best_cost: float
    costs: list[float] = field(default_factory=list)

    @property
    def single_solve_cost(self) -> float:
        return self.costs[0]

    @property
    def improvements(self) -> int:
        """How many restarts lowered the best cost."""
        best, n = self.costs[0], 0
        for c in self.costs[1:]:
            if c < best:
                best, n = c, n + 1
        return n


def solve_with_restarts(
    problem: OptimizationProblem,
    restarts: int,
    seed: int | None = 0,
    perturbation: Callable[[Any], np.ndarray] | None = None,
    **solve_kw: Any,
) -> RestartResult:
    """Solves, then ``restarts`` times perturbs the best estimate and solves again.

    Parameters
    ----------
    problem : OptimizationProblem
        Solved in place; on return it holds the best estimate found.
    restarts : int
        Number of extra solves (0: a single solve).
    seed : int, optional
        Seed of the perturbations.
    perturbation : callable, optional
        ``perturbation(value) -> (dof,) standard deviations`` per variable
        (default :func:`default_perturbation`).
    **solve_kw
        Passed to :meth:`OptimizationProblem.solve`.

    Returns
    -------
    RestartResult
        Never a higher cost than the first (single) solve.
    """
    if restarts < 0:
        raise ValueError(f"restarts must be >= 0, got {restarts}")
    scale = perturbation or default_perturbation
    rng = np.random.default_rng(seed)
    result = problem.solve(**solve_kw)
    best_cost, best = problem.cost(), result
    best_X = problem.X
    costs = [best_cost]
    free = [v for v in range(problem.num_variables) if not problem.is_fixed(v)]
    for _ in range(restarts):
        for v in free:
            x = best_X[v]
            problem.set_value(v, x + rng.normal(0.0, 1.0, len(x)) * scale(x))
        try:
            r = problem.solve(**solve_kw)
            cost = problem.cost()
        except EvaluationError:  # the perturbation left the model's domain: skip it
            r, cost = None, np.inf
        costs.append(cost)
        if np.isfinite(cost) and cost < best_cost:
            assert r is not None  # a solve that raised has cost inf
            best_cost, best, best_X = cost, r, problem.X
    for v in free:
        problem.set_value(v, best_X[v])
    return RestartResult(best, best_cost, costs)
