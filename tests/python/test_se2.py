"""SE(2) as first-class as SE(3): relative poses, priors and 2-D landmarks in the
same add_* calls, and SE2Batch's group operations for batched Python measurements."""

import boxplus as bp
import numpy as np
import pytest
from boxplus.batch import SE2Batch, SO2Batch


def _se2(rng):
    return bp.SE2(rng.normal(0, 2, 2), rng.uniform(-np.pi, np.pi))


def test_relative_pose_on_se2_is_the_compound_boxminus():
    rng = np.random.default_rng(1)
    o = bp.OptimizationProblem()
    a_true, b_true = _se2(rng), _se2(rng)
    a = o.add_random_var(a_true)
    b = o.add_random_var(b_true)
    z = a_true.inverse() * b_true + np.array([0.1, -0.2, 0.05])
    mid = o.add_relative_pose(z, a, b, sigma=[0.5, 0.5, 0.1])
    e = (a_true.inverse() * b_true) - z
    assert np.allclose(o.measurement_errors(mid), e, atol=1e-12)
    assert np.allclose(o.residual(mid), e / [0.5, 0.5, 0.1], atol=1e-12)
    with pytest.raises(TypeError, match="a_from_b is an SE2, variable .* is a SE3"):
        o.add_relative_pose(z, a, o.add_random_var(bp.SE3()))


def test_an_se2_odometry_loop_with_priors_and_landmarks_solves_to_the_truth():
    rng = np.random.default_rng(2)
    truth = [bp.SE2([np.cos(t) * 3, np.sin(t) * 3], t + np.pi / 2) for t in np.linspace(0, 5, 8)]
    marks = [rng.normal(0, 3, 2) for _ in range(4)]
    o = bp.OptimizationProblem()
    x = [o.add_random_var(p + rng.normal(0, 0.3, 3), name=f"x{i}") for i, p in enumerate(truth)]
    m = [o.add_random_var(bp.Rn(p + rng.normal(0, 0.3, 2)), name=f"l{j}") for j, p in enumerate(marks)]
    o.add_prior(x[0], truth[0], sigma=1e-3)
    for i in range(len(truth) - 1):
        o.add_relative_pose(truth[i].inverse() * truth[i + 1], x[i], x[i + 1], sigma=0.01)
    o.add_relative_pose(truth[0].inverse() * truth[-1], x[0], x[-1], sigma=0.01)
    for i, p in enumerate(truth):
        for j, lm in enumerate(marks):
            o.add_point(p.tolocal(lm), x[i], None, m[j], sigma=0.01)
    s = o.solve()
    assert s.usable and s.final_chi2 < 1e-12
    for i, p in enumerate(truth):
        assert np.linalg.norm(o[x[i]] - p) < 1e-7
    for j, lm in enumerate(marks):
        assert np.allclose(o[m[j]].vec, lm, atol=1e-7)
    with pytest.raises(TypeError, match="without cam_from_rig"):
        o.add_point([0.0, 0.0], m[0], None, x[0])


def test_se2_batch_group_operations_match_the_values():
    rng = np.random.default_rng(3)
    A = [_se2(rng) for _ in range(5)]
    B = [_se2(rng) for _ in range(5)]
    bA = SE2Batch(np.array([a.pos for a in A]), np.array([a.phi for a in A]))
    bB = SE2Batch(np.array([b.pos for b in B]), np.array([b.phi for b in B]))
    for i, (a, b) in enumerate(zip(A, B)):
        ab = (bA * bB).ambient[i]
        assert np.allclose(ab[:2], (a * b).pos) and np.isclose(ab[2], (a * b).phi)
        inv = bA.inverse().ambient[i]
        assert np.allclose(inv[:2], a.inverse().pos) and np.isclose(inv[2], a.inverse().phi)
        assert np.allclose(bA.transform()[i] @ [1.0, 2.0, 1.0], [*(a * np.array([1.0, 2.0])), 1.0])
        one = (bA * b).ambient[i]  # a batch times one value
        assert np.allclose(one[:2], (a * b).pos)
    r = SO2Batch(np.array([3.0, -3.0])) * SO2Batch(np.array([1.0, -1.0]))
    assert np.all((r.phi >= -np.pi) & (r.phi < np.pi))
    assert np.allclose((SO2Batch(np.array([0.3])) * SO2Batch(np.array([0.3])).inverse()).phi, 0.0)


def test_batched_se2_odometry_as_a_python_measurement():
    """The measurement of the MTKM style with SE2Batch: f(a, b) = a⁻¹ b, Z SE2 values."""
    rng = np.random.default_rng(4)
    truth = [_se2(rng) for _ in range(6)]
    o = bp.OptimizationProblem()
    ids = [o.add_random_var(p + rng.normal(0, 0.2, 3)) for p in truth]
    o.fix(ids[0])
    o.set_value(ids[0], truth[0])
    Z = [truth[i].inverse() * truth[i + 1] for i in range(5)]
    o.add_measurements(Z, lambda a, b: a.inverse() * b, [[ids[i], ids[i + 1]] for i in range(5)],
                       sigma=0.01)
    assert o.solve().final_chi2 < 1e-10
    assert max(np.linalg.norm(o[v] - p) for v, p in zip(ids, truth)) < 1e-6


def test_solve_summary_repr_is_one_short_line_and_todict_has_everything():
    o = bp.OptimizationProblem()
    x = o.add_random_var(bp.SE2())
    o.add_prior(x, bp.SE2([1.0, 2.0], 0.3))
    s = o.solve()
    text = repr(s)
    assert len(text) < 250 and "\n" not in text and "termination='convergence'" in text
    d = s.todict()
    assert "report" in d and len(d["report"]) > len(text)
