"""The point, disparity and DH-marker factors from Python: residuals against
independent numpy references, and recovery of known parameters by the solver."""

import numpy as np
import pytest

import boxplus as bp


def rot(axis, angle):
    c, s = np.cos(angle), np.sin(angle)
    i, j = (axis + 1) % 3, (axis + 2) % 3
    R = np.eye(3)
    R[i, i] = R[j, j] = c
    R[j, i], R[i, j] = s, -s
    return R


def homogeneous(R, t):
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, t
    return T


def test_point_residual_matches_numpy_and_registration_recovers_the_pose():
    rng = np.random.default_rng(0)
    x2world = bp.SE3(bp.SO3.exp([0.3, -0.5, 1.2]), [1.0, -2.0, 0.5])
    x2cam = bp.SE3(bp.SO3.exp([0.0, 0.2, 0.0]), [0.1, 0.0, 0.0])
    P = rng.uniform(-2, 2, (12, 3))
    # p_in_cam = x2cam ∘ x2world⁻¹ p, in matrix form and with the value methods
    Z = (x2cam.transform() @ np.linalg.inv(x2world.transform()) @ np.c_[P, np.ones(12)].T).T[:, :3]
    Z_ref = x2cam.fromlocal(x2world.tolocal(P))
    assert np.allclose(Z, Z_ref)
    o = bp.OptimizationProblem()
    xw = o.add_random_var(bp.SE3())  # unknown sensor pose, from the identity
    xc = o.add_random_var(x2cam, fixed=True)
    sigma = np.array([0.01, 0.02, 0.03])
    mids = [o.add_point(z + [0.5, 0, 0], xw, xc, p, sigma=sigma) for z, p in zip(Z_ref, P)]
    W = np.diag(1 / sigma)
    x0 = bp.SE3()
    assert np.allclose(o.residual(mids[3]), W @ (x2cam.fromlocal(x0.tolocal(P[3])) - Z_ref[3] - [0.5, 0, 0]))
    r = o.solve(function_tolerance=1e-14, parameter_tolerance=1e-14)
    assert r.usable
    # Measurements offset by a constant in the sensor frame: the pose absorbs it exactly.
    est = o[xw]
    assert np.allclose(x2cam.fromlocal(est.tolocal(P)), Z_ref + [0.5, 0, 0], atol=1e-8)


def test_point_with_unknown_landmark():
    x2world = bp.SE3(bp.SO3.exp([0.1, 0.2, 0.3]), [0.0, 1.0, 2.0])
    o = bp.OptimizationProblem()
    xw = o.add_random_var(x2world, fixed=True)
    xc = o.add_random_var(bp.SE3(), fixed=True)
    landmark = o.add_random_var(bp.Rn([0.0, 0.0, 0.0]))
    truth = np.array([1.5, -0.5, 3.0])
    o.add_point(x2world.tolocal(truth), xw, xc, landmark, sigma=0.01)
    o.solve()
    assert np.allclose(o[landmark].vec, truth, atol=1e-9)


def test_disparity_residual_matches_the_model_and_a_b_are_recovered():
    rng = np.random.default_rng(1)
    a, b = 350.0, 1090.0 / 8  # disparity = a / Z + b
    o = bp.OptimizationProblem()
    ab = o.add_random_var(bp.Rn([300.0, 100.0]))
    xc = o.add_random_var(bp.SE3(bp.SO3.exp([0.0, 0.01, 0.0]), [-0.025, 0.0, 0.0]), fixed=True)
    mids, expected = [], []
    for k in range(5):
        x2world = bp.SE3(bp.SO3.exp(rng.normal(0, 0.1, 3)), [0.0, 0.0, -1.0 - 0.5 * k])
        xw = o.add_random_var(x2world, fixed=True)
        for p in rng.uniform(-0.3, 0.3, (6, 2)):
            p_world = np.r_[p, 0.0]
            Zdepth = o[xc].fromlocal(x2world.tolocal(p_world))[2]
            d = a / Zdepth + b
            mids.append(o.add_disparity(d, xw, xc, ab, p_world, sigma=0.5))
            expected.append((300.0 / Zdepth + 100.0 - d) / 0.5)
    assert np.allclose([o.residual(m)[0] for m in mids], expected)
    o.solve(function_tolerance=1e-15)
    assert np.allclose(o[ab].vec, [a, b], rtol=1e-8)
    assert np.all(o.std(ab) > 0)


def dh_chain(dh, q):
    T = np.eye(4)
    for (theta, d, a, alpha), qi in zip(dh.reshape(-1, 4), q):
        T = T @ homogeneous(rot(2, qi + theta), [0, 0, 0]) @ homogeneous(np.eye(3), [0, 0, d]) \
            @ homogeneous(np.eye(3), [a, 0, 0]) @ homogeneous(rot(0, alpha), [0, 0, 0])
    return T


def pinhole_opencv(k, p):
    fx, fy, cx, cy, k1, k2, p1, p2, k3 = k
    x, y = p[0] / p[2], p[1] / p[2]
    r2 = x * x + y * y
    rad = 1 + r2 * (k1 + r2 * (k2 + r2 * k3))
    xd = x * rad + 2 * p1 * x * y + p2 * (r2 + 2 * x * x)
    yd = y * rad + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y
    return np.array([fx * xd + cx, fy * yd + cy])


@pytest.fixture
def arm():
    dh = np.array([[0.1, 0.3, 0.0, np.pi / 2], [-0.05, 0.0, 0.4, 0.0], [0.02, 0.0, 0.35, 0.0]]).ravel()
    k = np.array([500.0, 505.0, 320.0, 240.0, -0.1, 0.02, 0.001, -0.002, 0.0])
    x2base = bp.SE3(bp.SO3.exp([np.pi - 0.3, 0.0, 0.1]), [0.2, 0.0, 1.2])  # camera on the head
    p_hand = np.array([0.02, 0.03, 0.05])
    return dh, k, x2base, p_hand


def test_dh_marker_residual_matches_numpy_forward_kinematics(arm):
    dh, k, x2base, p_hand = arm
    o = bp.OptimizationProblem()
    ki = o.add_random_var(bp.Rn(k), fixed=True)
    xb = o.add_random_var(x2base, fixed=True)
    ph = o.add_random_var(bp.Rn(p_hand))
    xc = o.add_random_var(bp.SE3(), fixed=True)
    dhi = o.add_random_var(bp.Rn(dh))
    q = np.array([0.3, -0.7, 1.1])
    p_base = (dh_chain(dh, q) @ np.r_[p_hand, 1])[:3]
    uv = pinhole_opencv(k, x2base.tolocal(p_base))
    mid = o.add_dh_marker(uv + [1.0, -2.0], ki, xb, ph, xc, dhi, q, sigma=0.5)
    assert np.allclose(o.residual(mid), [-2.0, 4.0], atol=1e-9)


def test_dh_parameters_are_recovered_from_many_arm_poses(arm):
    dh, k, x2base, p_hand = arm
    rng = np.random.default_rng(2)
    o = bp.OptimizationProblem()
    ki = o.add_random_var(bp.Rn(k), fixed=True)
    xb = o.add_random_var(x2base, fixed=True)
    ph = o.add_random_var(bp.Rn(p_hand), fixed=True)
    xc = o.add_random_var(bp.SE3(), fixed=True)
    dh0 = dh + np.tile([0.02, 0.0, -0.01, 0.0], 3)  # perturbed joint offsets and link lengths
    dhi = o.add_random_var(bp.Rn(dh0))
    # d and α from CAD (d of parallel joints is not identifiable separately).
    cad = np.tile([False, True, False, True], 3)
    o.add_measurement(dh[cad], lambda v: v.vec[cad], [dhi], sigma=1e-6, name="CAD")
    n_used = 0
    for _ in range(60):
        q = rng.uniform(-0.8, 0.8, 3)
        p_cam = x2base.tolocal((dh_chain(dh, q) @ np.r_[p_hand, 1])[:3])
        if p_cam[2] < 0.2:
            continue
        o.add_dh_marker(pinhole_opencv(k, p_cam), ki, xb, ph, xc, dhi, q, sigma=0.3)
        n_used += 1
    assert n_used > 20
    r = o.solve(function_tolerance=1e-15, parameter_tolerance=1e-15, max_iterations=200)
    assert r.usable
    # Noise-free readings: joint offsets and link lengths come back exactly.
    assert np.allclose(o[dhi].vec, dh, atol=1e-7)
