"""Profile-likelihood intervals (boxplus.profile) against closed forms."""

from __future__ import annotations

import boxplus as bp
import numpy as np
import pytest


def test_linear_problem_gives_the_marginal_sigma_not_the_conditional():
    # a and b correlated through b − a: the profile of a lets b re-adjust, so its
    # half-width is a's marginal σ (√(σa² + …)), larger than a's σ with b held
    o = bp.OptimizationProblem()
    a = o.add_random_var(bp.Rn([0.0, 0.0]), name="a")
    b = o.add_random_var(bp.Rn([0.0]), name="b")
    o.add_measurement(bp.Rn([1.0]), lambda x, y: bp.Rn([x.vec[0] + y.vec[0]]), [a, b], sigma=0.5)
    o.add_measurement(bp.Rn([2.0]), lambda x, y: bp.Rn([y.vec[0] - 2 * x.vec[0]]), [a, b], sigma=0.2)
    o.add_prior(a, bp.Rn([0.3, 1.0]), sigma=[1.0, 0.1])
    o.add_prior(b, bp.Rn([1.5]), sigma=2.0)
    o.solve()
    for coord, k in ((0, 0), ("[1]", 1)):
        sigma = o.std(a)[k]
        for level in (1.0, 3.0):
            iv = o.profile(a, coord, level=level)
            lo, hi = iv.half_widths()
            assert lo == pytest.approx(level * sigma, rel=2e-3)
            assert hi == pytest.approx(level * sigma, rel=2e-3)
            assert iv.lower_minimum is None
    held = o.copy()
    held.fix(b)
    assert held.std(a)[0] < 0.9 * o.std(a)[0]  # the conditional σ is the narrower one


def test_nonlinear_problem_gives_the_closed_form_asymmetric_interval():
    # z_i = θ² + noise: Δχ²(θ) = n (θ² − z̄)² / σ², so θ = √(z̄ ± k σ/√n)
    rng = np.random.default_rng(3)
    z = 0.4 + 0.1 * rng.standard_normal(5)
    o = bp.OptimizationProblem()
    t = o.add_random_var(bp.Rn([1.0]), name="theta")
    for zi in z:
        o.add_measurement(bp.Rn([zi]), lambda x: bp.Rn([x.vec[0] ** 2]), [t], sigma=0.1)
    o.solve()
    zbar, half = z.mean(), 0.1 / np.sqrt(len(z))
    for level in (1.0, 2.0):
        iv = o.profile(t, 0, level=level)
        assert iv.lower == pytest.approx(np.sqrt(zbar - level * half), rel=1e-3)
        assert iv.upper == pytest.approx(np.sqrt(zbar + level * half), rel=1e-3)
        lo, hi = iv.half_widths()
        assert lo > hi  # the square root stretches the low side
        # the signed root at the bound is the level
        assert iv.z(iv.lower) == pytest.approx(level)
        assert iv.z(iv.upper) == pytest.approx(-level)
    assert o.value(t).vec[0] == pytest.approx(np.sqrt(zbar))  # the problem is untouched


def test_a_lower_minimum_along_the_coordinate_is_reported_with_its_values():
    # θ² = 1 with a weak prior towards +0.5: minima near ±1, the one at −1 higher
    o = bp.OptimizationProblem()
    t = o.add_random_var(bp.Rn([-1.2]), name="theta")
    o.add_measurement(bp.Rn([1.0]), lambda x: bp.Rn([x.vec[0] ** 2]), [t], sigma=1.0)
    o.add_prior(t, bp.Rn([0.5]), sigma=3.0)
    o.solve()
    assert o.value(t).vec[0] < 0
    iv = o.profile(t, 0, level=2.0)
    assert iv.lower_minimum is not None
    c, d = iv.lower_minimum
    assert c > 0.5 and d < 0
    assert "lower minimum" in str(iv)
    o.set_value(t, iv.values_at_lower_minimum[t])
    before = o.cost()
    o.solve()
    assert o.value(t).vec[0] == pytest.approx(1.0, abs=0.1)
    assert o.cost() <= before


def test_a_second_basin_below_the_level_behind_a_rise_is_inside_the_interval():
    # θ² = 1 (σ 0.7) with a prior towards −0.5: minima near ±1, the one at +1 higher by
    # Δχ² ≈ 0.5, a rise of Δχ² ≈ 2 between them. The likelihood-ratio set at 1σ holds
    # both basins: the interval spans them, unless the walk stops at the first rise.
    o = bp.OptimizationProblem()
    t = o.add_random_var(bp.Rn([-1.0]), name="theta")
    o.add_measurement(bp.Rn([1.0]), lambda x: bp.Rn([x.vec[0] ** 2]), [t], sigma=0.7)
    o.add_prior(t, bp.Rn([-0.5]), sigma=2.0)
    o.solve()
    assert o.value(t).vec[0] < -0.9
    iv = o.profile(t, 0)
    assert iv.upper > 1.0 and iv.lower_minimum is None
    floor = min(d for c, d in iv.points if c > 0.5)
    assert 0.3 < floor < 0.7
    assert o.profile(t, 0, search=1.0).upper < 0


def test_an_unbounded_side_is_infinite():
    # exp(−θ) = 0.5 with σ 1: as θ → ∞ the cost rises only by Δχ² = 0.25, never to 1
    o = bp.OptimizationProblem()
    t = o.add_random_var(bp.Rn([0.0]), name="theta")
    o.add_measurement(bp.Rn([0.5]), lambda x: bp.Rn([np.exp(-x.vec[0])]), [t], sigma=1.0)
    o.solve()
    assert o.value(t).vec[0] == pytest.approx(np.log(2.0), abs=1e-6)
    iv = o.profile(t, 0)
    assert np.isfinite(iv.lower) and iv.upper == np.inf


def test_bad_requests_name_the_variable():
    o = bp.OptimizationProblem()
    a = o.add_random_var(bp.Rn([0.0, 0.0]), name="a")
    r = o.add_random_var(bp.SO2(0.1), name="heading")
    o.add_prior(a, bp.Rn([1.0, 2.0]), sigma=1.0)
    o.add_prior(r, bp.SO2(0.2), sigma=0.1)
    o.solve()
    with pytest.raises(ValueError, match="'a' has no coordinate 'q'"):
        o.profile(a, "q")
    with pytest.raises(ValueError, match=r"labels: \[0\], \[1\]"):
        o.profile(a, "x")
    with pytest.raises(ValueError, match="coordinates 0..1, got 5"):
        o.profile(a, 5)
    with pytest.raises(TypeError, match="'heading' is a SO2"):
        o.profile(r, 0)
    with pytest.raises(ValueError, match="level"):
        o.profile(a, 0, level=0)
    o.fix(a)
    with pytest.raises(ValueError, match="'a' is held fixed"):
        o.profile(a, 0)


def test_double_sphere_profile_follows_the_valley():
    # a wide lens whose f, ξ and α trade along a curved valley: the profile of α is
    # asymmetric, and the truth lies within its 3σ interval (docs/guide/benchmarks.md
    # scores this over 100 captures)
    from boxplus.calib import calibrate_mono
    from boxplus.calib.targets import Target
    from boxplus.synthetic.cameras import observe
    from boxplus.synthetic.images import board_views

    k = np.array([250.0, 252.0, 320.0, 240.0, -0.15, 0.58])
    target = Target("chessboard", 9, 6, 0.04)
    poses = board_views(target, "double_sphere", k, (640, 480), 14, np.random.default_rng(5),
                        max_tilt_deg=45.0, fill=0.95)
    p = target.points()
    rng = np.random.default_rng(2)
    z = [observe(k, q.inverse(), p, 0.3, rng, model="double_sphere")[0] for q in poses]
    cal = calibrate_mono(z, p, (640, 480), model="double_sphere", sigma=0.3)
    iv = cal.profile("camera", "alpha", level=3.0)
    lo, hi = iv.half_widths()
    assert max(lo, hi) > 1.3 * min(lo, hi)
    assert iv.lower <= k[5] <= iv.upper
    assert "camera.alpha" in str(iv)
    with pytest.raises(ValueError, match="no variable 'left'"):
        cal.profile("left", "alpha")


def test_ctrl_c_stops_the_scan_and_leaves_the_problem_as_it_was():
    armed = []

    def square(x):
        if armed:
            armed.append(1)
            if len(armed) == 25:  # as Ctrl-C inside a point's solve (6 would hit its copy)
                raise KeyboardInterrupt
        return bp.Rn([x.vec[0] ** 2])

    o = bp.OptimizationProblem()
    t = o.add_random_var(bp.Rn([1.0]), name="theta")
    o.add_measurement(bp.Rn([0.5]), square, [t], sigma=0.1)
    o.solve()
    before = o.value(t).vec.copy()
    armed.append(1)
    with pytest.raises(KeyboardInterrupt):
        o.profile(t, 0)
    assert np.array_equal(o.value(t).vec, before)
