"""Profile-likelihood intervals: what the data say about one coordinate when σ is not enough.

The σ of :meth:`OptimizationProblem.std` linearises the problem at the estimate: the
cost is taken as a quadratic, ½ χ² = ½ δᵀ Σ⁻¹ δ. Where parameters trade along a
curved valley (a double-sphere lens's f, ξ and α; a camera's focal length against
its distance in a few views), that quadratic is too narrow on one side, and the
likelihood may even hold a second minimum. The profile likelihood does not
linearise: for a value c of one coordinate θ it minimises the cost over every
other variable,

    p(c) = min over the rest of ½ χ²(θ = c, rest),

and the interval at ``level`` k spans the set of c where 2 (p(c) − p(θ̂)) ≤ k², the
likelihood-ratio confidence set. For a linear problem it is θ̂ ± k σ exactly; in
general it is asymmetric and follows the valley (Venzon & Moolgavkar 1988; the
signed root r(c) = sign(θ̂ − c) √(2 (p(θ̂) − p(c))) is the profile's z). Where the
likelihood has a second basin along θ, the set is not connected: the interval is
its hull over the walk, which goes on past the first crossing of k² to where Δχ²
passes the square of ``search`` (3 by default), so a basin behind a rise is inside
the interval when its floor is below k².

Each p(c) is one solve of a copy of the problem with θ held at c by a stiff prior
(σ 10⁻⁴ of θ's linear σ, its own cost taken off), warm-started from the previous
point of the scan, so the user's problem is never touched. The scan walks out in
steps growing by 1.5 from ¼ linear σ, finds the floor of any dip it strode over, and
bisects at the outermost crossing. When a
point of the scan has a *lower* cost than the estimate, the estimate was not the
lowest minimum along θ: the result says so (``lower_minimum``) and holds the values
there, so the user can move to it (``problem.set_value``) and solve again. Ctrl-C
stops the scan (KeyboardInterrupt); the user's problem is as it was.

Δχ² is in the problem's own units, so the interval uses the given noise, like
:meth:`OptimizationProblem.std` (not the residual-rescaled σ).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from boxplus.problem import OptimizationProblem

# The stiff prior's σ relative to θ's linear σ: small enough that θ sits at c to
# 10⁻⁸ σ, large enough that the constrained normal equations stay well conditioned.
_STIFF = 1e-4
# The scan gives up on a side at this many linear σ (the bound is then ±inf).
_MAX_SIGMA = 1e3
# The walk's step factor: fine enough not to stride over a second basin along a valley.
_STEP = 1.5
# Golden-section steps to a dip's floor (0.618⁸ ≈ 2 % of the bracket).
_GOLDEN = 8
# Bisection steps between the last point inside and the first outside (2⁻⁸ of a step).
_BISECTIONS = 8


@dataclass
class ProfileInterval:
    """The profile-likelihood interval of one coordinate (see :mod:`boxplus.profile`)."""

    variable: str
    coordinate: str
    estimate: float
    lower: float
    upper: float
    level: float
    sigma: float  # the linearised σ, for comparison
    points: list[tuple[float, float]] = field(default_factory=list)  # (c, Δχ²), sorted
    lower_minimum: tuple[float, float] | None = None  # (c, Δχ² < 0) of the lowest point
    values_at_lower_minimum: list[Any] | None = field(default=None, repr=False)
    solves: int = 0

    def half_widths(self) -> tuple[float, float]:
        """(estimate − lower, upper − estimate): the σ-like distances on either side."""
        return self.estimate - self.lower, self.upper - self.estimate

    def z(self, value: float) -> float:
        """How far ``value`` lies from the estimate in units of the interval's half-width
        on its side (for ``level`` 1, the asymmetric counterpart of (θ̂ − value)/σ)."""
        lo, hi = self.half_widths()
        d = self.estimate - value
        return float(d / lo * self.level if d > 0 else d / hi * self.level)

    def __str__(self) -> str:
        lo, hi = self.half_widths()
        text = (f"{self.variable}.{self.coordinate} = {self.estimate:.6g} −{lo:.3g} +{hi:.3g} "
                f"(profile, {self.level:g}σ; linear σ {self.sigma:.3g})")
        if self.lower_minimum is not None:
            c, d = self.lower_minimum
            text += f"; a lower minimum at {self.coordinate} = {c:.6g} (Δχ² = {d:.3g})"
        return text


def _coordinate(problem: OptimizationProblem, vid: int, coordinate: int | str) -> tuple[int, str]:
    (k,) = problem._coordinate_indices(vid, [coordinate], "profile")
    if problem.is_fixed(vid):
        name = problem.variable_name(vid) or str(vid)
        raise ValueError(f"profile: variable '{name}' is held fixed, so it has no interval")
    return k, problem.labels(vid)[k]


class _Scan:
    """p(c) along one coordinate, each point warm-started from a neighbouring one."""

    def __init__(self, problem: OptimizationProblem, vid: int, k: int, sigma: float, options: Any):
        self.problem, self.vid, self.k = problem, vid, k
        self.stiff = _STIFF * sigma
        self.options = options
        self.f0 = problem.cost()
        self.solves = 0
        self.lowest: tuple[float, float, list[Any]] | None = None

    def delta(self, c: float, start: list[Any] | None) -> tuple[float, list[Any]]:
        """(Δχ² of the profile at c, the values there)."""
        from boxplus.manifolds import Rn

        q = self.problem.copy()
        if start is not None:
            for i, v in enumerate(start):
                q.set_value(i, v)
        q.add_prior(self.vid, Rn([c]), sigma=self.stiff, coordinates=[self.k], group="profile")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # a point far out may warn; the scan judges it
            summary = q.solve(self.options, check_determined=False)
        if summary.termination == "interrupted":
            raise KeyboardInterrupt  # Ctrl-C in a point's solve stops the whole scan
        self.solves += 1
        x = float(q.value(self.vid).vec[self.k])
        f = q.cost() - 0.5 * ((x - c) / self.stiff) ** 2
        values = [q.value(i) for i in range(q.num_variables)]
        d = 2.0 * (f - self.f0)
        if d < 0 and (self.lowest is None or d < self.lowest[1]):
            self.lowest = (c, d, values)
        return d, values

    def bound(self, estimate: float, sigma: float, side: int, level: float, search: float,
              points: list[tuple[float, float]]) -> float:
        """The farthest c towards ``side`` with Δχ² ≤ level², among the points of a walk
        out to where Δχ² passes search² (so a second basin below level² beyond a rise
        is inside), refined by bisection against the next point out."""
        def at(t: float, start: list[Any] | None) -> tuple[float, list[Any]]:
            c = estimate + side * t * sigma
            d, values = self.delta(c, start)
            points.append((c, d))
            return d, values

        walk: list[tuple[float, float, list[Any] | None]] = [(0.0, 0.0, None)]
        t = 0.25
        while True:
            d, values = at(t, walk[-1][2])  # from the last point: the walk follows the valley
            walk.append((t, d, values))
            if not np.isfinite(d) or d > search * search or t >= _MAX_SIGMA:
                break
            t *= _STEP
        # a dip between three points of the walk is a basin the steps may have strode
        # over: its floor, by golden-section search, joins the walk
        for i in range(2, len(walk) - 1):
            (ta, da, _), (_, db, vb), (tc, dc, _) = walk[i - 1], walk[i], walk[i + 1]
            if db < da and db <= dc and np.isfinite(dc):
                walk.append(self._floor(at, ta, tc, vb))
        walk.sort(key=lambda w: w[0])
        ins = [i for i, (_, d, _) in enumerate(walk) if np.isfinite(d) and d <= level * level]
        last = ins[-1]
        if last == len(walk) - 1:
            return side * np.inf  # still inside at 1000 linear σ
        inside, inside_values = walk[last][0], walk[last][2]
        outside = walk[last + 1][0]
        for _ in range(_BISECTIONS):
            m = 0.5 * (inside + outside)
            d, values = at(m, inside_values)
            if np.isfinite(d) and d <= level * level:
                inside, inside_values = m, values
            else:
                outside = m
        return estimate + side * 0.5 * (inside + outside) * sigma

    @staticmethod
    def _floor(at: Any, a: float, c: float, start: list[Any] | None) -> tuple[float, float, list[Any]]:
        """The lowest point of p between a and c (golden-section search)."""
        g = (np.sqrt(5.0) - 1) / 2
        x1, x2 = c - g * (c - a), a + g * (c - a)
        (f1, v1), (f2, v2) = at(x1, start), at(x2, start)
        for _ in range(_GOLDEN):
            if f1 <= f2:
                c, x2, f2, v2 = x2, x1, f1, v1
                x1 = c - g * (c - a)
                f1, v1 = at(x1, v2)
            else:
                a, x1, f1, v1 = x1, x2, f2, v2
                x2 = a + g * (c - a)
                f2, v2 = at(x2, v1)
        return (x1, f1, v1) if f1 <= f2 else (x2, f2, v2)


def profile_interval(problem: OptimizationProblem, vid: int, coordinate: int | str,
                     level: float = 1.0, options: Any = None, search: float = 3.0) -> ProfileInterval:
    """The profile-likelihood interval of one coordinate of an Rn variable at the
    current values, which should be a solved minimum (:mod:`boxplus.profile`).

    ``coordinate`` is an index or a label; ``level`` is in σ (Δχ² ≤ level²: 1 for the
    counterpart of ±σ, 3 for a 99.7 % interval); ``options`` are the solver's
    settings for each point (default: the problem's defaults); ``search`` is how far
    (in σ, at least ``level``) the walk looks for a further basin. Raises TypeError for a
    variable that is not Rn, ValueError for a fixed one, and what
    :meth:`OptimizationProblem.std` raises when the data do not determine it. A side
    the scan cannot close within 1000 linear σ is ±inf."""
    if not (np.isfinite(level) and level > 0):
        raise ValueError(f"profile: level must be a positive number of σ, got {level}")
    vid = problem.check_ids([vid], "profile")[0]
    k, label = _coordinate(problem, vid, coordinate)
    estimate = float(problem.value(vid).vec[k])
    sigma = float(problem.std(vid)[k])
    scan = _Scan(problem, vid, k, sigma, options)
    points: list[tuple[float, float]] = [(estimate, 0.0)]
    search = max(float(search), float(level))
    lower = scan.bound(estimate, sigma, -1, level, search, points)
    upper = scan.bound(estimate, sigma, +1, level, search, points)
    result = ProfileInterval(problem.variable_name(vid) or str(vid), label, estimate, lower, upper,
                             float(level), sigma, sorted(points), solves=scan.solves)
    # a point "below" the estimate by no more than the solver's own tolerance is the same minimum
    if scan.lowest is not None and scan.lowest[1] < -1e-6 * max(1.0, 2.0 * scan.f0):
        result.lower_minimum = (scan.lowest[0], scan.lowest[1])
        result.values_at_lower_minimum = scan.lowest[2]
    return result
