"""The point, disparity and DH-marker factors from Python: residuals against
independent numpy references, and recovery of known parameters by the solver."""

import boxplus as bp
import numpy as np
import pytest
from boxplus.calib import add_board, add_dh_marker, add_disparity, add_projection


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
    world_from_rig = bp.SE3(bp.SO3.exp([0.3, -0.5, 1.2]), [1.0, -2.0, 0.5])
    cam_from_rig = bp.SE3(bp.SO3.exp([0.0, 0.2, 0.0]), [0.1, 0.0, 0.0])
    P = rng.uniform(-2, 2, (12, 3))
    # p_in_cam = cam_from_rig ∘ world_from_rig⁻¹ p, in matrix form and with the value methods
    Z = (cam_from_rig.transform() @ np.linalg.inv(world_from_rig.transform()) @ np.c_[P, np.ones(12)].T).T[:, :3]
    Z_ref = cam_from_rig.fromlocal(world_from_rig.tolocal(P))
    assert np.allclose(Z, Z_ref)
    o = bp.OptimizationProblem()
    xw = o.add_random_var(bp.SE3())  # unknown sensor pose, from the identity
    xc = o.add_random_var(cam_from_rig, fixed=True)
    sigma = np.array([0.01, 0.02, 0.03])
    mids = [o.add_point(z + [0.5, 0, 0], xw, xc, p, sigma=sigma) for z, p in zip(Z_ref, P)]
    W = np.diag(1 / sigma)
    x0 = bp.SE3()
    assert np.allclose(o.residual(mids[3]), W @ (cam_from_rig.fromlocal(x0.tolocal(P[3])) - Z_ref[3] - [0.5, 0, 0]))
    r = o.solve(function_tolerance=1e-14, parameter_tolerance=1e-14)
    assert r.usable
    # Measurements offset by a constant in the sensor frame: the pose absorbs it exactly.
    est = o[xw]
    assert np.allclose(cam_from_rig.fromlocal(est.tolocal(P)), Z_ref + [0.5, 0, 0], atol=1e-8)


def test_point_with_unknown_landmark():
    world_from_rig = bp.SE3(bp.SO3.exp([0.1, 0.2, 0.3]), [0.0, 1.0, 2.0])
    o = bp.OptimizationProblem()
    xw = o.add_random_var(world_from_rig, fixed=True)
    xc = o.add_random_var(bp.SE3(), fixed=True)
    landmark = o.add_random_var(bp.Rn([0.0, 0.0, 0.0]))
    truth = np.array([1.5, -0.5, 3.0])
    o.add_point(world_from_rig.tolocal(truth), xw, xc, landmark, sigma=0.01)
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
        world_from_rig = bp.SE3(bp.SO3.exp(rng.normal(0, 0.1, 3)), [0.0, 0.0, -1.0 - 0.5 * k])
        xw = o.add_random_var(world_from_rig, fixed=True)
        for p in rng.uniform(-0.3, 0.3, (6, 2)):
            p_in_world = np.r_[p, 0.0]
            Zdepth = o[xc].fromlocal(world_from_rig.tolocal(p_in_world))[2]
            d = a / Zdepth + b
            mids.append(add_disparity(o, d, xw, xc, ab, p_in_world, sigma=0.5))
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
    base_from_rig = bp.SE3(bp.SO3.exp([np.pi - 0.3, 0.0, 0.1]), [0.2, 0.0, 1.2])  # camera on the head
    p_hand = np.array([0.02, 0.03, 0.05])
    return dh, k, base_from_rig, p_hand


def test_dh_marker_residual_matches_numpy_forward_kinematics(arm):
    dh, k, base_from_rig, p_hand = arm
    o = bp.OptimizationProblem()
    ki = o.add_random_var(bp.Rn(k), fixed=True)
    xb = o.add_random_var(base_from_rig, fixed=True)
    ph = o.add_random_var(bp.Rn(p_hand))
    xc = o.add_random_var(bp.SE3(), fixed=True)
    dhi = o.add_random_var(bp.Rn(dh))
    q = np.array([0.3, -0.7, 1.1])
    p_base = (dh_chain(dh, q) @ np.r_[p_hand, 1])[:3]
    uv = pinhole_opencv(k, base_from_rig.tolocal(p_base))
    mid = add_dh_marker(o, uv + [1.0, -2.0], ki, xb, ph, xc, dhi, q, sigma=0.5)
    assert np.allclose(o.residual(mid), [-2.0, 4.0], atol=1e-9)


def test_dh_parameters_are_recovered_from_many_arm_poses(arm):
    dh, k, base_from_rig, p_hand = arm
    rng = np.random.default_rng(2)
    o = bp.OptimizationProblem()
    ki = o.add_random_var(bp.Rn(k), fixed=True)
    xb = o.add_random_var(base_from_rig, fixed=True)
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
        p_in_cam = base_from_rig.tolocal((dh_chain(dh, q) @ np.r_[p_hand, 1])[:3])
        if p_in_cam[2] < 0.2:
            continue
        add_dh_marker(o, pinhole_opencv(k, p_in_cam), ki, xb, ph, xc, dhi, q, sigma=0.3)
        n_used += 1
    assert n_used > 20
    r = o.solve(function_tolerance=1e-15, parameter_tolerance=1e-15, max_iterations=200)
    assert r.usable
    # Noise-free readings: joint offsets and link lengths come back exactly.
    assert np.allclose(o[dhi].vec, dh, atol=1e-7)


def test_noise_keywords_give_one_model_and_errors_are_in_pixels():
    """sigma, covariance, information and noise describe the same Σ; the problem keeps
    the factor's NoiseModel, so errors()/rms() of C++ factors (projection included,
    issue 10) are in pixels, not whitened."""
    from boxplus.synthetic.cameras import TRUE_K, board_points, observe, random_views

    rng = np.random.default_rng(4)
    p = board_points()
    T = random_views(1, rng, p.mean(axis=0))[0]
    z, _ = observe(TRUE_K, T, p, 0.0, rng, image_size=None)
    z = z + [1.0, -2.0]  # every corner 1 px right of and 2 px above the prediction: e = [-1, 2]
    S = np.array([[0.25, 0.1], [0.1, 0.5]])
    forms = [dict(covariance=S), dict(information=np.linalg.inv(S)),
             dict(noise=bp.NoiseModel.covariance(S, "board"))]
    o = bp.OptimizationProblem()
    k = o.add_random_var(bp.Rn(TRUE_K), fixed=True)
    pose = o.add_random_var(T, fixed=True)
    ident = o.add_random_var(bp.SE3(), fixed=True)
    boards = [add_board(o, z, k, pose, ident, p, **f) for f in forms]
    # Any W with WᵀW = Σ⁻¹ whitens: the residuals differ, their norms per corner do not.
    for m in boards[1:]:
        assert np.allclose(np.linalg.norm(o.residual(m).reshape(-1, 2), axis=1),
                           np.linalg.norm(o.residual(boards[0]).reshape(-1, 2), axis=1))
    L = np.linalg.cholesky(S)
    assert np.allclose(o.residual(boards[0]).reshape(-1, 2), np.linalg.solve(L, np.tile([-1.0, 2.0], (len(p), 1)).T).T)
    for m in boards:
        assert np.allclose(o.measurement_errors(m), [-1.0, 2.0])
    mid = add_projection(o, z[0], k, pose, ident, p[0], sigma=[0.5, 0.25], model="opencv5")
    assert np.allclose(o.residual(mid), [-2.0, 8.0])
    rms = o.rms()
    assert np.isclose(rms["projection[opencv5]"], np.sqrt(5.0))
    assert np.isclose(rms["board[opencv5]"], np.sqrt(5.0))
    with pytest.raises(ValueError, match="give one of sigma, covariance"):
        add_board(o, z, k, pose, ident, p, sigma=0.5, covariance=S)
    with pytest.raises(ValueError, match="noise of dimension 3"):
        add_disparity(o, 1.0, pose, ident, k, p[0], noise=bp.NoiseModel.unit(3))


def test_a_term_takes_the_model_its_camera_was_added_with():
    # add_camera labels the intrinsics with the model's parameters; add_board and
    # add_projection without model= take that model, with it they take the one given,
    # and an unlabelled variable of the wrong size is named with the hint.
    from boxplus.calib import add_camera
    from boxplus.calib.models import project

    o = bp.OptimizationProblem()
    K = np.array([[300.0, 0, 320], [0, 300.0, 240], [0, 0, 1]])
    fish = add_camera(o, "fish", K, "kannala_brandt", dist=[0.01, -0.002, 0.0, 0.0])
    pose = o.add_random_var(bp.SE3(t=[0.0, 0.0, -1.0]), fixed=True)
    ident = o.add_random_var(bp.SE3(), fixed=True)
    p = np.array([[0.3, -0.2, 0.0], [0.1, 0.4, 0.0], [-0.5, 0.1, 0.0]])
    z = project(o[fish].vec, p - [0.0, 0.0, -1.0], "kannala_brandt")
    m = add_board(o, z, fish, pose, ident, p)
    assert np.allclose(o.residual(m), 0.0, atol=1e-9)
    assert "board[kannala_brandt]" in o.rms()
    q = add_projection(o, z[0], fish, pose, ident, p[0])
    assert np.allclose(o.residual(q), 0.0, atol=1e-9)
    plain = o.add_random_var(bp.Rn(np.ones(4)))
    with pytest.raises(ValueError, match="'opencv5' needs 9 intrinsics.*give the term's model="):
        add_board(o, z, plain, pose, ident, p)
    assert add_board(o, z, plain, pose, ident, p, model="pinhole") >= 0
