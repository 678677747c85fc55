"""The rational, Kannala–Brandt and double-sphere camera models: the C++
projection equals the numpy one and OpenCV's, the factors' Jacobians equal
central differences, and calibration reaches OpenCV's RMS (within 1e-6 px) on
simulated data and on OpenCV's stereo sample."""

from pathlib import Path

import numpy as np
import pytest
from boxplus import SE3, SO3, OptimizationProblem, Rn
from boxplus.calib import add_board, calibrate_mono
from boxplus.calib.models import CAMERA_LABELS, camera_matrix, intrinsics_vector, project, rays
from boxplus.geometry import look_at
from boxplus.synthetic.cameras import board_points, numeric_jacobian, observe, random_views

cv2 = pytest.importorskip("cv2")

NEW = ["rational", "kannala_brandt", "double_sphere"]
K_TRUE = {
    "rational": np.array([520.0, 515.0, 322.0, 245.0, -0.2, 0.05, 0.001, -0.0005, 0.01,
                          0.1, -0.02, 0.005]),
    "kannala_brandt": np.array([300.0, 302.0, 321.0, 242.0, 0.02, -0.01, 0.004, -0.001]),
    "double_sphere": np.array([250.0, 252.0, 320.0, 240.0, -0.15, 0.58]),
}
DATA = Path(__file__).resolve().parents[2] / "data" / "calib" / "opencv_stereo_corners.npz"


def _points(rng, n=50):
    p = np.column_stack([rng.uniform(-1, 1, (n, 2)), rng.uniform(0.6, 2.0, n)])
    p[0] = [0.0, 0.0, 1.0]  # the optical axis: Kannala–Brandt's r = 0 branch
    return p


def _cpp_pixels(k, p_in_cam, model):
    """Pixels from the C++ factor: the error of a board measurement with z = 0."""
    o = OptimizationProblem()
    cam = o.add_random_var(Rn(k))
    world = o.add_random_var(SE3(), fixed=True)
    rig = o.add_random_var(SE3(), fixed=True)
    mid = add_board(o, np.zeros((len(p_in_cam), 2)), cam, world, rig, p_in_cam, model=model)
    return o.measurement_errors(mid)


@pytest.mark.parametrize("model", NEW)
def test_cpp_projection_equals_numpy_and_rays_invert_it(model):
    rng = np.random.default_rng(1)
    p = _points(rng)
    uv = project(K_TRUE[model], p, model)
    assert np.abs(_cpp_pixels(K_TRUE[model], p, model) - uv).max() < 1e-9
    r = rays(K_TRUE[model], uv, model)
    cosang = np.sum(r * p, axis=1) / np.linalg.norm(r, axis=1) / np.linalg.norm(p, axis=1)
    assert np.all(cosang > 1 - 1e-12)


def test_projection_equals_opencv():
    rng = np.random.default_rng(2)
    p = _points(rng)
    K, d = camera_matrix(K_TRUE["rational"], "rational")
    uv, _ = cv2.projectPoints(p, np.zeros(3), np.zeros(3), K, d)
    assert np.abs(uv.reshape(-1, 2) - project(K_TRUE["rational"], p, "rational")).max() < 1e-9
    K, d = camera_matrix(K_TRUE["kannala_brandt"], "kannala_brandt")
    uv, _ = cv2.fisheye.projectPoints(p[None], np.zeros(3), np.zeros(3), K, d)
    assert np.abs(uv.reshape(-1, 2) - project(K_TRUE["kannala_brandt"], p, "kannala_brandt")).max() < 1e-9
    assert np.allclose(intrinsics_vector(K, "kannala_brandt", d), K_TRUE["kannala_brandt"])


@pytest.mark.parametrize("model", NEW)
def test_jacobians_equal_central_differences(model):
    rng = np.random.default_rng(3)
    o = OptimizationProblem()
    cam = o.add_random_var(Rn(K_TRUE[model]))
    world_from_rig = SE3.exp(np.r_[0.1, -0.05, -1.0, 0.1, -0.2, 0.05])
    cam_from_rig = SE3.exp(np.r_[0.02, 0.01, 0.0, 0.01, 0.02, -0.03])
    pose = o.add_random_var(world_from_rig)
    rig = o.add_random_var(cam_from_rig)
    # the last point on the camera's axis: the r = 0 branch of Kannala–Brandt
    on_axis = world_from_rig.fromlocal(cam_from_rig.inverse().fromlocal([0.0, 0.0, 0.8]))
    obj = np.vstack([board_points(4, 3, 0.1), on_axis])
    z = rng.normal(320, 50, (len(obj), 2))
    mids = [add_board(o, z, cam, pose, rig, obj, model=model, sigma=[0.7, 1.3])]
    J, num = numeric_jacobian(o, mids)
    scale = np.maximum(1.0, np.abs(num).max(axis=0))
    assert np.all(np.abs(J - num).max(axis=0) < 1e-5 * scale), np.abs(J - num).max(axis=0) / scale


def _simulate(model, rng, n_views=14, sigma=0.2):
    obj = board_points(9, 6, 0.04)
    views = random_views(n_views, rng, obj.mean(axis=0), distance=0.45 if model == "rational" else 0.3,
                         spread=0.45, roll=0.5)
    pts = []
    for v in views:
        z, vis = observe(K_TRUE[model], v, obj, sigma, rng, model=model)
        assert vis.all()
        pts.append(z)
    return obj, pts


def test_rational_matches_opencv_on_simulated_data():
    obj, pts = _simulate("rational", np.random.default_rng(4))
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 500, 1e-15)
    rms_cv, K, d, _, _ = cv2.calibrateCamera([obj.astype(np.float32)] * len(pts),
                                             [p.astype(np.float32) for p in pts], (640, 480),
                                             None, None, flags=cv2.CALIB_RATIONAL_MODEL, criteria=crit)
    from boxplus.calib.fold import LensFoldWarning, fold_angle, observed_field

    # the 12-parameter fit (OpenCV's as well as ours) turns back just inside the field
    # the corners covered: named, not silent
    with pytest.warns(LensFoldWarning, match="rational model folds over"):
        cal = calibrate_mono([p.astype(np.float32).astype(float) for p in pts], obj, (640, 480),
                             "rational", regularize=False)  # OpenCV's problem, without the prior
    assert fold_angle(intrinsics_vector(K, "rational", d.ravel()), "rational",
                      observed_field(cal, "camera")) is not None
    assert abs(cal.rms() - rms_cv) < 1e-6, (cal.rms(), rms_cv)
    k = cal.problem[cal.ids["camera"]].vec
    assert np.all(np.abs(k - intrinsics_vector(K, "rational", d.ravel())) < cal.report(rescale=True).std("camera"))


def test_kannala_brandt_matches_opencv_fisheye_on_simulated_data():
    obj, pts = _simulate("kannala_brandt", np.random.default_rng(5))
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 500, 1e-15)
    flags = cv2.fisheye.CALIB_RECOMPUTE_EXTRINSIC | cv2.fisheye.CALIB_FIX_SKEW
    rms_cv, K, d, _, _ = cv2.fisheye.calibrate([obj[None].astype(np.float64)] * len(pts),
                                               [p[None].astype(np.float64) for p in pts], (640, 480),
                                               np.zeros((3, 3)), np.zeros(4), flags=flags, criteria=crit)
    cal = calibrate_mono(pts, obj, (640, 480), "kannala_brandt")
    assert abs(cal.rms() - rms_cv) < 1e-6, (cal.rms(), rms_cv)
    k = cal.problem[cal.ids["camera"]].vec
    rep = cal.report(rescale=True)
    assert np.all(np.abs(k - intrinsics_vector(K, "kannala_brandt", d.ravel())) < rep.std("camera"))
    # and the truth within 4σ
    assert np.all(np.abs(k - K_TRUE["kannala_brandt"]) < 4 * rep.std("camera"))


def _wide_views(k, model, rng, n=16, sigma=0.3):
    """Views of the board close to a wide-angle camera, off its axis: corners up to
    ~90° from the axis."""
    obj = board_points(9, 6, 0.04)
    c = obj.mean(axis=0)
    pts = []
    while len(pts) < n:
        d = np.array([rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5), -1.0])
        pose = look_at(c + 0.15 * d / np.linalg.norm(d), c + np.r_[rng.uniform(-0.3, 0.3, 2), 0],
                       up=np.array([0.0, 1.0, 0.0]))
        pose = SE3(SO3(pose.rot.R @ SO3.exp(np.array([0, 0, rng.uniform(-0.5, 0.5)])).R), pose.pos)
        z, vis = observe(k, pose, obj, sigma, rng, model=model)
        if vis.all():
            pts.append(z)
    return obj, pts


def test_double_sphere_fits_a_wide_angle_lens():
    """The double sphere on corners up to ~90° off the axis: the fit is as good as the
    true intrinsics (with the poses solved) and projects every observed ray where the
    true lens does. (ξ, α and f are nearly interchangeable below 180°: the estimate
    moves along that valley, so the test checks the projection, not the numbers.)"""
    k_true = np.array([160.0, 161.0, 320.0, 240.0, -0.2, 0.6])
    obj, pts = _wide_views(k_true, "double_sphere", np.random.default_rng(6))
    r = rays(k_true, np.concatenate(pts), "double_sphere")
    assert np.degrees(np.arccos(r[:, 2].min())) > 80
    cal = calibrate_mono(pts, obj, (640, 480), "double_sphere", sigma=0.3)
    assert cal.result.termination == "convergence"
    k = cal.problem[cal.ids["camera"]].vec
    rms = cal.rms()
    gap = np.abs(project(k, r, "double_sphere") - project(k_true, r, "double_sphere"))
    assert gap.max() < 1.0, gap.max()
    o = cal.problem
    o.set_value(cal.ids["camera"], Rn(k_true))
    o.fix(cal.ids["camera"])
    o.solve()
    assert rms <= cal.rms() * (1 + 1e-9)


@pytest.mark.parametrize("model", ["rational", "kannala_brandt"])
def test_opencv_sample_matches_opencv(model):
    with np.load(DATA) as f:
        d = {k: f[k] for k in f.files}
    obj, pts, size = d["object_points"], list(d["image_points_left"]), tuple(int(s) for s in d["image_size"])
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 1000, 1e-15)
    if model == "rational":
        rms_cv, *_ = cv2.calibrateCamera([obj.astype(np.float32)] * len(pts),
                                         [p.astype(np.float32) for p in pts], size, None, None,
                                         flags=cv2.CALIB_RATIONAL_MODEL, criteria=crit)
    else:
        flags = cv2.fisheye.CALIB_RECOMPUTE_EXTRINSIC | cv2.fisheye.CALIB_FIX_SKEW
        rms_cv, *_ = cv2.fisheye.calibrate([obj[None].astype(np.float64)] * len(pts),
                                           [p[None].astype(np.float64) for p in pts], size,
                                           np.zeros((3, 3)), np.zeros(4), flags=flags, criteria=crit)
    # OpenCV's problem: without boxplus' distortion prior (on by default for rational)
    cal = calibrate_mono(pts, obj, size, model, name="left", regularize=False)
    assert abs(cal.rms() - rms_cv) < 1e-6, (cal.rms(), rms_cv)


def test_unknown_model_and_wrong_size_raise():
    o = OptimizationProblem()
    cam = o.add_random_var(Rn(np.zeros(6)))
    a = o.add_random_var(SE3(), fixed=True)
    b = o.add_random_var(SE3(), fixed=True)
    with pytest.raises(ValueError, match="kannala_brandt.*needs 8"):
        add_board(o, np.zeros((1, 2)), cam, a, b, np.zeros((1, 3)) + [0, 0, 1], model="kannala_brandt")
    with pytest.raises(ValueError, match="unknown camera model 'equi'"):
        add_board(o, np.zeros((1, 2)), cam, a, b, np.zeros((1, 3)) + [0, 0, 1], model="equi")
    assert set(NEW) <= set(CAMERA_LABELS)


def test_one_list_of_camera_models_in_both_languages():
    # the C++ camera terms (camera/models.h) and the numpy twins know the same models, with
    # the same number of intrinsics each
    from boxplus import _core
    from boxplus.calib.models import CAMERA_LABELS

    names = _core.camera_model_names()
    assert sorted(names) == sorted(CAMERA_LABELS) and len(names) == 8
    for name in names:
        assert _core.camera_model_size(name) == len(CAMERA_LABELS[name])
