"""Random restarts about the first solution (Le & Ng, Sec. X).

Levenberg–Marquardt converges to a local minimum. After the first solve,
restart k perturbs its estimate with ⊞ on every free variable,
x ⊞ δ with δ ~ N(0, diag(s²)), solves again, and the lowest cost wins. Restart
k draws δ from ``numpy.random.default_rng([seed, k])``: the restarts are
independent of each other, so they can run in any order or in parallel
(``executor=``, any :class:`concurrent.futures.Executor`, with ``factory``
building a fresh copy of the problem per restart) and give the same answer,
bit for bit, as the serial loop.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from boxplus._core import SolveSummary
from boxplus._plain import fields_todict
from boxplus.manifolds import S2, SE3, SO3, Rn, _CompoundBase
from boxplus.parallel import map_values
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

    def todict(self) -> dict[str, Any]:
        """Plain Python values (``json.dumps`` takes them): the fields and ``improvements``."""
        return {**fields_todict(self), "improvements": self.improvements}

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


def _perturbed(x0: list[Any], free: list[int], scale: Callable[[Any], np.ndarray], seed: int,
               k: int) -> dict[int, Any]:
    rng = np.random.default_rng([seed, k])
    return {v: x0[v] + rng.normal(0.0, 1.0, len(x0[v])) * scale(x0[v]) for v in free}


def _restart(problem: OptimizationProblem, start: dict[int, Any],
             solve_kw: dict[str, Any]) -> tuple[float, Any, list[Any] | None]:
    """Solves ``problem`` from ``start``: (cost, summary, values); cost inf outside the domain."""
    for v, x in start.items():
        problem.set_value(v, x)
    try:
        # the first solve checked what the data determine; a restart changes only values
        r = problem.solve(**{**solve_kw, "check_determined": False})
        cost = problem.cost()
    except EvaluationError:  # the perturbation left the model's domain: skip it
        return np.inf, None, None
    return cost, r, problem.X


def _restart_fresh(factory: Callable[[], OptimizationProblem], start: dict[int, Any],
                   solve_kw: dict[str, Any]) -> tuple[float, Any, list[Any] | None]:
    return _restart(factory(), start, solve_kw)


def solve_with_restarts(
    problem: OptimizationProblem,
    restarts: int,
    seed: int | None = 0,
    perturbation: Callable[[Any], np.ndarray] | None = None,
    executor: Any = None,
    factory: Callable[[], OptimizationProblem] | None = None,
    **solve_kw: Any,
) -> RestartResult:
    """Solves, then ``restarts`` times perturbs the first solution and solves again.

    Parameters
    ----------
    problem : OptimizationProblem
        Solved in place; on return it holds the best estimate found.
    restarts : int
        Number of extra solves (0: a single solve).
    seed : int, optional
        Seed of the perturbations (None: drawn once from fresh entropy).
    perturbation : callable, optional
        ``perturbation(value) -> (dof,) standard deviations`` per variable
        (default :func:`default_perturbation`).
    executor : concurrent.futures.Executor, dask Client or pool, optional
        Runs the restarts in parallel through :func:`boxplus.parallel.map_values`
        (threads: the C++ solve releases the GIL; processes, Dask, Ray:
        ``factory`` and ``perturbation`` must be picklable; a worker that dies
        is retried). Needs ``factory``. A restart whose code raises ends the call
        with :class:`boxplus.parallel.TaskError` and its traceback.
    factory : callable, optional
        ``factory() -> OptimizationProblem``: a fresh problem with the same
        variables (same ids) and measurements as ``problem``; each restart is
        solved on its own copy (serially too, when given).
    **solve_kw
        Passed to :meth:`OptimizationProblem.solve`.

    Returns
    -------
    RestartResult
        Never a higher cost than the first (single) solve; the same for any
        executor and for none.
    """
    if restarts < 0:
        raise ValueError(f"restarts must be >= 0, got {restarts}")
    if executor is not None and factory is None:
        raise ValueError("solve_with_restarts: an executor needs factory= (a fresh problem per restart)")
    scale = perturbation or default_perturbation
    if seed is None:
        seed = int(np.random.default_rng().integers(2**62))
    result = problem.solve(**solve_kw)
    best_cost, best = problem.cost(), result
    if restarts == 0:  # nothing to compare: the solve's values stay as they are
        return RestartResult(best, best_cost, [best_cost])
    x0 = problem.X
    best_X = x0
    costs = [best_cost]
    free = [v for v in range(problem.num_variables) if not problem.is_fixed(v)]
    starts = [_perturbed(x0, free, scale, seed, k) for k in range(restarts)]
    if factory is not None:
        if executor is not None:
            outcomes = map_values(_restart_fresh, [(factory, st, solve_kw) for st in starts],
                                  executor, "solve_with_restarts")
        else:
            outcomes = [_restart_fresh(factory, st, solve_kw) for st in starts]
    else:
        outcomes = [_restart(problem, st, solve_kw) for st in starts]
    for cost, r, X in outcomes:
        costs.append(cost)
        if np.isfinite(cost) and cost < best_cost:
            assert r is not None and X is not None  # a solve that raised has cost inf
            best_cost, best, best_X = cost, r, X
    for v in free:
        problem.set_value(v, best_X[v])
    return RestartResult(best, best_cost, costs)
