"""End-to-end smoke tests of the solver through the bindings."""

import boxplus as bp
import numpy as np
import pytest


def test_symmetric_rotation_average_is_the_centre():
    rng = np.random.default_rng(1)
    truth = bp.SO3.exp([0.4, -1.2, 2.5])
    p = bp.Problem()
    x = p.add_variable(bp.SO3.manifold(), bp.SO3().ambient, "R")
    for _ in range(10):
        d = rng.normal(0, 0.3, 3)
        for s in (1, -1):
            p.add_factor(bp._core.prior_factor(p, x, (truth + s * d).ambient, bp.NoiseModel.unit(3)))
    s = p.solve(function_tolerance=1e-16, gradient_tolerance=1e-16, parameter_tolerance=1e-16)
    assert s.usable and s.termination == "convergence"
    assert np.linalg.norm(bp.SO3.from_ambient(p.value(x)) - truth) < 1e-7


def test_weighted_se3_mean_matches_closed_form_and_covariance():
    rng = np.random.default_rng(2)
    truth = bp.SE3(bp.SO3.exp([-0.5, 0.2, 1.0]), [1.0, 2.0, 3.0])
    p = bp.Problem()
    x = p.add_variable(bp.SE3.manifold(), bp.SE3().ambient)
    zs, ws = [], []
    for k in range(25):
        sigma = 0.1 + 0.1 * k
        z = truth + np.concatenate([rng.normal(0, 0.5, 3), rng.normal(0, 0.2, 3)])
        zs.append(z)
        ws.append(1 / sigma**2)
        p.add_factor(bp._core.prior_factor(p, x, z.ambient, bp.NoiseModel.isotropic(6, sigma)))
    p.solve(function_tolerance=1e-16, gradient_tolerance=1e-16, parameter_tolerance=1e-16)
    est = bp.SE3.from_ambient(p.value(x))
    ws = np.array(ws)
    assert np.allclose(est.pos, sum(w * z.pos for w, z in zip(ws, zs)) / ws.sum(), atol=1e-9)
    karcher = sum(w * (z.rot - est.rot) for w, z in zip(ws, zs))
    assert np.linalg.norm(karcher) / ws.sum() < 1e-9
    C = p.covariance(x)
    assert C.shape == (6, 6)
    assert np.allclose(C[:3, :3], np.eye(3) / ws.sum(), atol=1e-9)


def test_bad_input_names_the_culprit():
    p = bp.Problem()
    x = p.add_variable(bp.SO3.manifold(), bp.SO3().ambient, "R")
    with pytest.raises(IndexError, match="unknown variable id 5"):
        p.value(5)
    with pytest.raises(ValueError, match="'gyro'"):
        p.add_factor(bp._core.prior_factor(p, x, np.zeros(3), bp.NoiseModel.unit(3), "prior 'gyro'"))
    with pytest.raises(ValueError, match="initial value has 3 entries"):
        p.add_variable(bp.SO3.manifold(), np.zeros(3), "R2")
    with pytest.raises(ValueError, match="non-finite"):
        p.add_variable(bp.SO3.manifold(), np.array([0, 0, 0, np.nan]), "R3")
    with pytest.raises(ValueError, match="unknown method"):
        p.solve(method="newton")


def test_callback_can_stop_and_errors_propagate():
    p = bp.Problem()
    x = p.add_variable(bp.SO3.manifold(), bp.SO3().ambient)
    p.add_factor(bp._core.prior_factor(p, x, bp.SO3.exp([2.0, 0.5, -0.3]).ambient, bp.NoiseModel.unit(3)))
    seen = []
    s = p.solve(callback=lambda info: seen.append(info.cost) or False)
    assert s.termination == "interrupted" and s.usable and len(seen) == 1

    def boom(info):
        raise RuntimeError("from the callback")

    with pytest.raises(RuntimeError, match="from the callback"):
        p.solve(callback=boom)


def test_sigint_during_a_solve_returns_the_best_estimate(tmp_path):
    """A real SIGINT (Ctrl-C) while Python measurement functions run."""
    import os
    import signal
    import threading
    import time

    p = bp.OptimizationProblem()
    # far from the root, so the solve needs ~20 iterations (≥ 40 ms each): a timer
    # thread delayed by a loaded machine still lands before convergence
    x = p.add_random_var(bp.Rn([1000.0, -1000.0]))

    def slow_cube(v):
        time.sleep(0.002)
        return v.vec**3

    for _ in range(20):
        p.add_measurement([1.0, -1.0], slow_cube, [x])
    initial = p.cost()
    # The signal is sent once a step has been accepted (a fixed delay would
    # depend on the machine's load), and lands while the measurements run.
    timer = threading.Timer(0.02, os.kill, (os.getpid(), signal.SIGINT))

    def arm(info):
        if info.iteration == 1:
            timer.start()

    try:
        r = p.solve(max_iterations=10_000, function_tolerance=0, gradient_tolerance=0,
                    parameter_tolerance=0, callback=arm)
    finally:
        timer.cancel()
    assert r.termination == "interrupted" and r.usable
    assert p.cost() < initial
