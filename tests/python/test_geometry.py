"""boxplus.geometry against independent references: scipy's Rotation, OpenCV's
projectPoints, the C++ pinhole factors, and degenerate cases that must raise."""

import boxplus as bp
import numpy as np
import pytest
from boxplus import geometry as g
from boxplus.calib import add_projection, models
from scipy.spatial.transform import Rotation

SEEDS = range(5)


def _nearest_rotation_by_scipy(M):
    # max tr(Rᵀ M) with M = Σ_i M[:, i] e_iᵀ is Wahba's problem for a_i = M[:, i], b_i = e_i.
    R, _ = Rotation.align_vectors(M.T, np.eye(3))
    return R.as_matrix()


@pytest.mark.parametrize("seed", SEEDS)
def test_project_to_so3_is_the_nearest_rotation(seed):
    rng = np.random.default_rng(seed)
    M = rng.normal(size=(3, 3))
    R = g.project_to_so3(M)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)
    assert np.isclose(np.linalg.det(R), 1.0)
    np.testing.assert_allclose(R, _nearest_rotation_by_scipy(M), atol=1e-9)
    # and nothing nearer among perturbed rotations
    d0 = np.linalg.norm(R - M)
    for _ in range(20):
        Q = R @ Rotation.from_rotvec(rng.normal(0, 0.05, 3)).as_matrix()
        assert np.linalg.norm(Q - M) >= d0 - 1e-12


@pytest.mark.parametrize("seed", SEEDS)
def test_project_to_so3_of_a_reflection_returns_a_rotation(seed):
    rng = np.random.default_rng(seed)
    Q = Rotation.random(random_state=seed).as_matrix()
    M = Q @ np.diag([3.0, 2.0, -1.0]) @ Rotation.random(random_state=seed + 10).as_matrix()
    M = M + 1e-3 * rng.normal(size=(3, 3))
    assert np.linalg.det(M) < 0
    R = g.project_to_so3(M)
    assert np.isclose(np.linalg.det(R), 1.0)
    np.testing.assert_allclose(R, _nearest_rotation_by_scipy(M), atol=1e-9)


def test_project_to_so3_keeps_rotations_and_works_on_stacks():
    Rs = Rotation.random(4, random_state=1).as_matrix()
    np.testing.assert_allclose(g.project_to_so3(Rs), Rs, atol=1e-12)
    np.testing.assert_allclose(g.project_to_so3(2.5 * Rs[0]), Rs[0], atol=1e-12)


def test_project_to_so3_rejects_degenerate_input():
    with pytest.raises(ValueError, match="rank < 2"):
        g.project_to_so3(np.outer([1.0, 2, 3], [0.5, 0, 1]))
    with pytest.raises(ValueError, match="non-finite"):
        g.project_to_so3(np.full((3, 3), np.nan))
    with pytest.raises(ValueError, match=r"\(\.\.\., 3, 3\)"):
        g.project_to_so3(np.eye(2))


@pytest.mark.parametrize("seed", SEEDS)
def test_absolute_orientation_matches_scipy_and_recovers_exact_transforms(seed):
    rng = np.random.default_rng(seed)
    R0 = Rotation.random(random_state=seed)
    t0 = rng.normal(size=3)
    a = rng.normal(size=(12, 3))
    b = R0.apply(a) + t0
    T = g.absolute_orientation(a, b)
    np.testing.assert_allclose(T.rot.R, R0.as_matrix(), atol=1e-10)
    np.testing.assert_allclose(T.pos, t0, atol=1e-10)
    # with noise: the same rotation as scipy's Kabsch on the centred points
    bn = b + rng.normal(0, 0.05, b.shape)
    w = rng.uniform(0.5, 2.0, len(a))
    Tn = g.absolute_orientation(a, bn, weights=w)
    ref, _ = Rotation.align_vectors(bn - w @ bn / w.sum(), a - w @ a / w.sum(), weights=w)
    np.testing.assert_allclose(Tn.rot.R, ref.as_matrix(), atol=1e-9)


@pytest.mark.parametrize("seed", SEEDS)
def test_absolute_orientation_with_scale_and_without_translation(seed):
    rng = np.random.default_rng(seed)
    R0 = Rotation.random(random_state=seed)
    a = rng.normal(size=(8, 3))
    T, s = g.absolute_orientation(a, 2.5 * R0.apply(a) + [1.0, -2, 3], scale=True)
    assert np.isclose(s, 2.5)
    np.testing.assert_allclose(T.rot.R, R0.as_matrix(), atol=1e-10)
    np.testing.assert_allclose(T.pos, [1.0, -2, 3], atol=1e-10)
    d = rng.normal(size=(5, 3))
    Td = g.absolute_orientation(d, R0.apply(d), translation=False)
    np.testing.assert_allclose(Td.rot.R, R0.as_matrix(), atol=1e-10)
    assert np.all(Td.pos == 0)


def test_absolute_orientation_rejects_degenerate_input():
    line = np.outer(np.arange(5.0), [1.0, 2, 3]) + [0.0, 1, 0]
    with pytest.raises(ValueError, match="one line"):
        g.absolute_orientation(line, line + 1)
    with pytest.raises(ValueError, match="parallel"):
        g.absolute_orientation(np.array([[0, 0, 1.0], [0, 0, -2]]), np.array([[0, 1, 0.0], [0, -2, 0]]),
                               translation=False)
    with pytest.raises(ValueError, match="at least 3"):
        g.absolute_orientation(np.eye(3)[:2], np.eye(3)[:2])
    with pytest.raises(ValueError, match="weights"):
        g.absolute_orientation(np.eye(3), np.eye(3), weights=[1.0, -1, 1])
    with pytest.raises(ValueError, match="non-finite"):
        g.absolute_orientation(np.full((3, 3), np.nan), np.eye(3))


@pytest.mark.parametrize("seed", SEEDS)
def test_triangulate_midpoint_meets_intersecting_rays_and_halves_skew_ones(seed):
    rng = np.random.default_rng(seed)
    P = rng.normal(size=(6, 3)) + [0, 0, 4]
    c1, c2 = np.zeros(3), np.array([0.3, -0.1, 0.05])
    d1, d2 = 2.0 * (P - c1), 0.5 * (P - c2)
    np.testing.assert_allclose(g.triangulate_midpoint(c1, d1, c2, d2), P, atol=1e-12)
    # x axis and the line (t, 0, 1) + λ (0, 1, 0): closest points (0, 0, 0) and (0, 0, 1)
    np.testing.assert_allclose(g.triangulate_midpoint([0, 0, 0], [1.0, 0, 0], [0, 0, 1.0], [0, 1.0, 0]),
                               [[0, 0, 0.5]], atol=1e-15)


def test_triangulate_midpoint_rejects_parallel_rays():
    with pytest.raises(ValueError, match=r"row\(s\) \[1\] are parallel"):
        g.triangulate_midpoint(np.zeros((2, 3)), [[0, 0, 1.0], [0, 0, 1.0]],
                               [[1.0, 0, 0], [1.0, 0, 0]], [[0, 1.0, 1], [0, 0, 3.0]])


def test_look_at_points_the_optical_axis_at_the_target():
    eye, target = np.array([1.0, 2, 3]), np.array([0.0, 0.5, -1])
    T = g.look_at(eye, target, up=(0, 0, 1))
    R = T.rot.R
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
    assert np.isclose(np.linalg.det(R), 1.0)
    p = T.tolocal(target)
    np.testing.assert_allclose(p[:2], 0, atol=1e-12)
    assert p[2] > 0
    assert R[:, 1] @ [0, 0, 1] < 0  # image y (down) against up
    assert abs(R[:, 0] @ [0, 0, 1]) < 1e-12  # no roll: x horizontal
    with pytest.raises(ValueError, match="parallel"):
        g.look_at(np.zeros(3), [0, 0, 2.0], up=(0, 0, 1))
    with pytest.raises(ValueError, match="coincide"):
        g.look_at(np.ones(3), np.ones(3))


K_BY_MODEL = {
    "simple_radial": [500.0, 320, 240, -0.2],
    "pinhole": [500.0, 510, 320, 240],
    "radial1": [500.0, 510, 320, 240, -0.2],
    "radial2": [500.0, 510, 320, 240, -0.2, 0.05],
    "opencv5": [500.0, 510, 320, 240, -0.2, 0.05, 0.001, -0.002, 0.01],
}


def _points(seed, n=20):
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.uniform(-0.4, 0.4, (n, 2)), rng.uniform(0.8, 2.0, n)])


@pytest.mark.parametrize("seed", SEEDS)
def test_project_matches_opencv(seed):
    cv2 = pytest.importorskip("cv2")
    P = _points(seed)
    k = np.array(K_BY_MODEL["opencv5"])
    K, d = models.camera_matrix(k, "opencv5")
    uv, _ = cv2.projectPoints(P, np.zeros(3), np.zeros(3), K, d)
    np.testing.assert_allclose(models.project(k, P), uv.reshape(-1, 2), atol=1e-9)
    np.testing.assert_allclose(models.rays(k, uv.reshape(-1, 2)), P / P[:, 2:3], atol=1e-9)


@pytest.mark.parametrize("model", sorted(K_BY_MODEL))
def test_project_matches_the_cpp_factor(model):
    P = _points(7, 8)
    k = np.array(K_BY_MODEL[model])
    o = bp.OptimizationProblem()
    kid = o.add_random_var(bp.Rn(k))
    pose = o.add_random_var(bp.SE3())
    cam = o.add_random_var(bp.SE3())
    for p in P:
        add_projection(o, np.zeros(2), kid, pose, cam, p, model=model)
    (r,) = o.residuals().values()
    np.testing.assert_allclose(models.project(k, P, model), r, atol=1e-9)


def test_project_pinhole_broadcasts_per_row_intrinsics():
    P = _points(3, 4)
    f = np.array([[400.0], [500], [600], [700]])
    c = np.tile([320.0, 240], (4, 1))
    k1 = np.full((4, 1), -0.1)
    row = [models.project(np.r_[f[i], c[i], k1[i]], P[i : i + 1], "simple_radial")[0] for i in range(4)]
    np.testing.assert_allclose(models.project_pinhole(P, f, c, k1=k1), row, atol=1e-12)


def test_camera_matrix_names_bad_models_and_sizes():
    with pytest.raises(ValueError, match="unknown camera model 'fisheye'"):
        models.camera_matrix(np.ones(4), "fisheye")
    with pytest.raises(ValueError, match="has 9 intrinsics"):
        models.camera_matrix(np.ones(4), "opencv5")
