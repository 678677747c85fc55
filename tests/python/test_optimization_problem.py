"""OptimizationProblem: Python measurement functions (per measurement and
vectorised), compounds, user-defined manifolds, errors, interruption."""

import traceback
from pathlib import Path

import boxplus as bp
import numpy as np
import pytest
from boxplus.calib import add_board, add_projection
from conftest import POINTS, delta_for
from hypothesis import given
from scipy.spatial.transform import Rotation

DATA = Path(__file__).resolve().parents[2] / "data" / "calib" / "opencv_stereo_corners.npz"

intrinsic_t = bp.make_compound("intrinsic_t", focal_length=bp.Rn(1), offset=bp.Rn(2), distortion=bp.Rn(1))
pose_t = bp.make_compound("pose_t", position=bp.Rn(3), orientation=bp.SO3())


# ---- values ----------------------------------------------------------------------------


def test_values_interoperate_with_scipy():
    r = Rotation.from_rotvec([0.3, -0.2, 1.0])
    R = bp.SO3.from_scipy(r)
    assert np.allclose(R.R, r.as_matrix())
    assert np.allclose(R.as_scipy().as_matrix(), r.as_matrix())
    assert np.allclose(bp.SE3(r.as_matrix(), [1, 2, 3]).transform()[:3, 3], [1, 2, 3])


def test_compound_members_and_indices():
    i = intrinsic_t(focal_length=[530.0], offset=[320, 240], distortion=[0.0])
    assert i.offset.vec.tolist() == [320.0, 240.0]
    assert intrinsic_t.idx_of("offset") == 1 and i.idx_of("distortion") == 3
    assert i.dof == len(i) == 4
    j = i + np.array([1.0, 2.0, 3.0, 0.5])
    assert j.focal_length.vec[0] == 531.0 and j.distortion.vec[0] == 0.5
    assert np.allclose(j - i, [1, 2, 3, 0.5])
    assert intrinsic_t().focal_length.vec[0] == 0.0  # prototypes are defaults
    with pytest.raises(ValueError, match="offset: expected 2 numbers"):
        intrinsic_t(offset=[1, 2, 3])
    with pytest.raises(TypeError, match="unknown member"):
        intrinsic_t(skew=[0.0])
    with pytest.raises(TypeError, match="must be a intrinsic_t"):
        i - pose_t()
    with pytest.raises(KeyError):
        intrinsic_t.idx_of("skew")


@given(POINTS["SO3"], delta_for("SE3", np.pi))
def test_compound_boxplus_axioms(R, d):
    x = pose_t(position=[1.0, -2.0, 3.0], orientation=R)
    assert np.allclose((x + d) - x, d, atol=1e-7 * max(1, np.abs(d[:3]).max()))
    y = pose_t(position=[0.5, 0.5, 0.5], orientation=R + d[3:])
    back = x + (y - x)
    assert np.allclose(back.position.vec, y.position.vec)
    assert np.linalg.norm(back.orientation - y.orientation) < 1e-9


def test_compound_solver_manifold_matches_python_boxplus():
    x = pose_t(position=[1.0, 2.0, 3.0], orientation=bp.SO3.exp([0.1, 0.2, 0.3]))
    d = np.array([0.1, 0.2, 0.3, -0.4, 0.5, 0.1])
    c = bp.codec_of(x)
    assert np.allclose(c.manifold.plus(x.ambient, d), (x + d).ambient)


class Plane(bp.ManifoldValue):
    """A plane {p : n·p = d} as a unit normal (S²) and a distance: 3 DOF."""

    dof = 3

    def __init__(self, normal, d):
        self.normal, self.d = bp.S2(normal), float(d)

    def boxplus(self, delta):
        return Plane((self.normal + delta[:2]).vec, self.d + delta[2])

    def boxminus(self, other):
        return np.r_[self.normal - other.normal, self.d - other.d]

    def to_ambient(self):
        return np.r_[self.normal.vec, self.d]

    @classmethod
    def from_ambient(cls, a):
        return cls(a[:3], a[3])


def point_to_plane(plane, p):
    return [plane.normal.vec @ p - plane.d]


def test_user_defined_manifold_fits_a_plane_like_svd():
    rng = np.random.default_rng(3)
    n_true = np.array([0.2, -0.3, 1.0]) / np.linalg.norm([0.2, -0.3, 1.0])
    u = np.cross(n_true, [1.0, 0, 0])
    u /= np.linalg.norm(u)
    v = np.cross(n_true, u)
    pts = 2.0 * n_true + rng.uniform(-5, 5, (60, 1)) * u + rng.uniform(-5, 5, (60, 1)) * v
    pts += rng.normal(0, 0.05, pts.shape)
    p = bp.OptimizationProblem()
    plane = p.add_random_var(Plane([0.0, 0.0, 1.0], 0.0))
    for q in pts:
        p.add_measurement([0.0], point_to_plane, [plane], constants=(q,), sigma=0.05)
    r = p.solve()
    assert r.usable
    est = p[plane]
    # Closed form: total least squares = smallest right singular vector.
    c = pts.mean(axis=0)
    n_svd = np.linalg.svd(pts - c)[2][-1]
    n_svd *= np.sign(n_svd @ est.normal.vec)
    assert np.allclose(est.normal.vec, n_svd, atol=1e-7)
    assert np.isclose(est.d, n_svd @ c, atol=1e-7)
    assert p.covariance(plane).shape == (3, 3)


# ---- Python measurements vs C++ factors ------------------------------------------------


def test_python_measurement_matches_cpp_prior_including_covariance():
    rng = np.random.default_rng(4)
    zs = [bp.SE3.from_ambient(np.r_[rng.normal(0, 1, 3), Rotation.random(random_state=k).as_quat()])
          for k in range(3)]
    zs = [zs[0] + rng.normal(0, 0.2, 6) for _ in range(8)]
    Sigma = np.diag([0.1, 0.2, 0.3, 0.05, 0.06, 0.07]) ** 2
    a, b = bp.OptimizationProblem(), bp.OptimizationProblem()
    xa, xb = a.add_random_var(bp.SE3()), b.add_random_var(bp.SE3())
    for z in zs:
        a.add_measurement(z, lambda x: x, [xa], covariance=Sigma)
        b.add_prior(xb, z, covariance=Sigma)
    a.solve(function_tolerance=1e-14)
    b.solve(function_tolerance=1e-14)
    assert np.linalg.norm(a[xa] - b[xb]) < 1e-8
    assert np.allclose(a.covariance(xa), b.covariance(xb), rtol=1e-5, atol=1e-12)


def project_points(intrinsic, world_from_cam, p_in_world):
    x = world_from_cam.tolocal(p_in_world)
    uv = x[..., :2] / x[..., 2:3]
    r2 = np.sum(uv**2, axis=-1, keepdims=True)
    return intrinsic.focal_length.vec * uv * (1 + intrinsic.distortion.vec * r2) + intrinsic.offset.vec


def project_point(intrinsic, world_from_cam, p_in_world):
    return project_points(intrinsic, world_from_cam, p_in_world)


def _calibration(form, n_images=5):
    from boxplus.calib import init_camera

    d = np.load(DATA)
    obj, imgs, size = d["object_points"], list(d["image_points_left"][:n_images]), tuple(d["image_size"])
    K, poses = init_camera(obj, imgs, size)
    o = bp.OptimizationProblem()
    iid = o.add_random_var(intrinsic_t(focal_length=[K[0, 0]], offset=K[:2, 2], distortion=[0.0]))
    ident = o.add_random_var(bp.SE3(), fixed=True)
    for p_img, pose in zip(imgs, poses):
        cid = o.add_random_var(pose.inverse())
        if form == "per_point":
            for j in range(len(obj)):
                o.add_measurement(p_img[j], project_point, [iid, cid], constants=(obj[j],))
        elif form == "vectorised":
            ids = np.tile([iid, cid], (len(obj), 1))
            o.add_measurements(p_img, project_points, ids, constants=(obj,))
        else:
            for j in range(len(obj)):
                add_projection(o, p_img[j], iid, cid, ident, obj[j], model="simple_radial")
    r = o.solve(function_tolerance=1e-14, parameter_tolerance=1e-14)
    assert r.usable, r
    return o, iid, r


def test_per_point_vectorised_and_cpp_calibrations_agree():
    results = {form: _calibration(form) for form in ("per_point", "vectorised", "cpp")}
    ref = results["cpp"][0][results["cpp"][1]].ambient
    for form, (o, iid, r) in results.items():
        assert np.allclose(o[iid].ambient, ref, rtol=1e-6, atol=1e-7), form
        assert np.isclose(r.final_cost, results["cpp"][2].final_cost, rtol=1e-8), form
    o, iid, _ = results["vectorised"]
    cov_py = o.covariance(iid)
    o_cpp, iid_cpp, _ = results["cpp"]
    assert np.allclose(cov_py, o_cpp.covariance(iid_cpp), rtol=1e-4)


def test_calibration_matches_opencv():
    cv2 = pytest.importorskip("cv2")
    o, iid, _ = _calibration("vectorised", n_images=13)
    d = np.load(DATA)
    obj = d["object_points"].astype(np.float32)
    imgs = [p.astype(np.float32) for p in d["image_points_left"]]
    flags = (cv2.CALIB_FIX_ASPECT_RATIO | cv2.CALIB_ZERO_TANGENT_DIST | cv2.CALIB_FIX_K2
             | cv2.CALIB_FIX_K3 | cv2.CALIB_USE_INTRINSIC_GUESS)
    K0 = np.array([[500.0, 0, 320], [0, 500.0, 240], [0, 0, 1]])
    rms_cv, K, dist, _, _ = cv2.calibrateCamera([obj] * len(imgs), imgs, (640, 480), K0, np.zeros(5),
                                                flags=flags)
    e = o.errors()["project_points"]
    rms = np.sqrt(np.mean(np.sum(e**2, axis=1)))
    assert abs(rms - rms_cv) < 1e-6
    assert np.allclose(o[iid].ambient, [K[0, 0], K[0, 2], K[1, 2], dist.ravel()[0]], rtol=1e-5)


def test_residuals_and_rms_are_grouped_by_function():
    o, _, _ = _calibration("vectorised", n_images=2)
    res = o.residuals()
    assert set(res) == {"project_points"} and res["project_points"].shape == (108, 2)
    rms = o.rms()
    assert 0.05 < rms["project_points"] < 0.5


# ---- solver options, losses, mixing ----------------------------------------------------


@pytest.mark.parametrize("method", ["lm", "gn", "gn_ls", "dogleg", "gn_lm"])
def test_methods_reach_the_same_optimum(method):
    p = bp.OptimizationProblem()
    x = p.add_random_var(bp.SO3())
    centre = bp.SO3.exp([0.5, -1.0, 0.4])
    p.add_measurement(centre + [0.1, 0.0, -0.2], lambda r: r, [x], sigma=0.1)
    p.add_prior(x, centre + [-0.1, 0.0, 0.2], sigma=0.1)  # C++ and Python mixed
    r = p.solve(method=method, function_tolerance=1e-14)
    assert r.termination == "convergence"
    assert np.linalg.norm(p[x] - centre) < 1e-6


@pytest.mark.parametrize("method", ["lm", "gn_ls"])
def test_huber_loss_limits_an_outlier(method):
    zs = [0.0, 0.1, -0.1, 0.05, 10.0]  # the last is an outlier

    def mean(loss):
        p = bp.OptimizationProblem()
        x = p.add_random_var(bp.Rn(1))
        for z in zs:
            p.add_measurement([z], lambda v: v.vec, [x], sigma=0.1, loss=loss)
        p.solve(method=method)
        return p[x].vec[0]

    assert mean(None) == pytest.approx(np.mean(zs), abs=1e-6)
    assert abs(mean(("huber", 1.0))) < 0.1


def test_fixed_variables_do_not_move():
    p = bp.OptimizationProblem()
    a = p.add_random_var(bp.Rn([1.0]), fixed=True)
    b = p.add_random_var(bp.Rn([0.0]))
    p.add_measurement([2.0], lambda u, v: u.vec + v.vec, [a, b])
    p.solve()
    assert p[a].vec[0] == 1.0 and np.isclose(p[b].vec[0], 1.0)
    p.unfix(a)
    assert not p.is_fixed(a)


# ---- errors ----------------------------------------------------------------------------


def test_add_measurement_validates_inputs():
    p = bp.OptimizationProblem()
    x = p.add_random_var(bp.Rn(2))
    with pytest.raises(ValueError, match="'bad size'.*expected a vector of 3"):
        p.add_measurement([0, 0, 0], lambda v: v.vec, [x], name="bad size")
    with pytest.raises(TypeError, match="'bad type'.*expected a SO3"):
        p.add_measurement(bp.SO3(), lambda v: v.vec, [x], name="bad type")
    with pytest.raises(ValueError, match="'bad sigma'.*not positive definite"):
        p.add_measurement([0, 0], lambda v: v.vec, [x], covariance=np.array([[1.0, 2], [2, 1]]), name="bad sigma")
    with pytest.raises(ValueError, match="not symmetric"):
        p.add_measurement([0, 0], lambda v: v.vec, [x], covariance=np.array([[1.0, 0.5], [0, 1]]))
    with pytest.raises(IndexError, match="'bad id'.*unknown variable id 7"):
        p.add_measurement([0, 0], lambda v: v.vec, [7], name="bad id")
    with pytest.raises(ValueError, match="constant 0 must have first dimension N = 3"):
        p.add_measurements(np.zeros((3, 2)), lambda v, c: v.vec + c, [[x]] * 3, constants=(np.zeros((2, 2)),))
    with pytest.raises(ValueError, match="returned shape"):
        p.add_measurements(np.zeros((3, 2)), lambda v: v.vec[:, :1], [[x]] * 3)


@pytest.mark.parametrize("method", ["lm", "gn_ls"])
def test_exception_inside_f_reaches_the_caller_with_its_traceback(method):
    calls = []

    def flaky(v):
        calls.append(1)
        if len(calls) > 3:
            raise ZeroDivisionError("deep inside the model")
        return v.vec

    p = bp.OptimizationProblem()
    x = p.add_random_var(bp.Rn([1.0, 2.0]))
    p.add_measurement([0.0, 0.0], flaky, [x])
    with pytest.raises(ZeroDivisionError, match="deep inside the model") as info:
        p.solve(method=method)
    frames = [f.name for f in traceback.extract_tb(info.value.__traceback__)]
    assert "flaky" in frames


def test_non_finite_residual_stops_the_solve_naming_measurement_and_values():
    def sqrt_model(v):
        return np.sqrt(v.vec)  # NaN once the solver steps below zero

    p = bp.OptimizationProblem()
    x = p.add_random_var(bp.Rn([1.0]), name="depth")
    p.add_measurement([-3.0], sqrt_model, [x], name="range")
    with pytest.warns(RuntimeWarning):
        with pytest.raises(bp.EvaluationError, match="'range'.*non-finite.*depth=Rn"):
            p.solve()


@pytest.mark.parametrize("method", ["lm", "gn_ls"])
def test_keyboard_interrupt_returns_the_best_estimate_so_far(method):
    calls = []

    def slow(v):
        calls.append(1)
        if len(calls) == 12:
            raise KeyboardInterrupt
        return v.vec**3

    p = bp.OptimizationProblem()
    x = p.add_random_var(bp.Rn([3.0]))
    p.add_measurement([1.0], slow, [x])
    initial = p.cost()
    r = p.solve(method=method, max_iterations=1000, function_tolerance=0, gradient_tolerance=0,
                parameter_tolerance=0)
    assert r.termination == "interrupted" and r.usable
    assert 0 < p.cost() < initial


def test_callback_can_stop_the_solve():
    p = bp.OptimizationProblem()
    x = p.add_random_var(bp.Rn([3.0]))
    p.add_measurement([1.0], lambda v: v.vec**3, [x])
    r = p.solve(callback=lambda info: info.iteration < 2)
    assert r.termination == "interrupted" and r.iterations == 2


def test_rms_of_every_group_is_in_the_measurements_units():
    """add_projection used to report its RMS whitened: now every group is in pixels."""
    p = bp.OptimizationProblem()
    k = p.add_random_var(bp.Rn([500.0, 500.0, 320.0, 240.0]), fixed=True, name="k")
    world_from_rig = p.add_random_var(bp.SE3(), fixed=True)
    cam_from_rig = p.add_random_var(bp.SE3(), fixed=True)
    add_projection(p, [323.0, 244.0], k, world_from_rig, cam_from_rig, [0.0, 0.0, 5.0], sigma=2.0,
                     model="pinhole")
    add_board(p, np.array([[320.0, 240.0], [326.0, 248.0]]), k, world_from_rig, cam_from_rig,
                np.array([[0.0, 0.0, 5.0], [0.0, 0.0, 5.0]]), covariance=np.diag([4.0, 9.0]),
                model="pinhole")
    x = p.add_random_var(bp.Rn([1.0]))
    p.add_prior(x, bp.Rn([4.0]), sigma=0.5)
    p.add_measurement([7.0], lambda v: v.vec, [x], information=[[16.0]], name="direct")
    rms = p.rms()
    assert rms["projection[pinhole]"] == pytest.approx(5.0)
    assert rms["board[pinhole]"] == pytest.approx(np.sqrt((0 + 100) / 2))
    assert rms["prior"] == pytest.approx(3.0)
    assert rms["<lambda>"] == pytest.approx(6.0)
    white = p.rms(whitened=True)
    assert white["projection[pinhole]"] == pytest.approx(2.5)
    assert white["prior"] == pytest.approx(6.0) and white["<lambda>"] == pytest.approx(24.0)
    assert np.allclose(p.measurement_errors(0), [[-3.0, -4.0]])


def test_one_noise_vocabulary_for_every_add():
    p = bp.OptimizationProblem()
    x = p.add_random_var(bp.Rn([0.0, 0.0]))
    S = np.array([[4.0, 1.0], [1.0, 2.0]])
    forms = [dict(sigma=[2.0, np.sqrt(2.0)]), dict(covariance=S), dict(information=np.linalg.inv(S)),
             dict(noise=bp.NoiseModel.covariance(S))]
    mids = [p.add_measurement([1.0, 2.0], lambda v: v.vec, x, **kw) for kw in forms]
    mids += list(p.add_measurements(np.tile([1.0, 2.0], (3, 1)), lambda v: v.vec, [[x]] * 3,
                                    covariance=np.stack([S] * 3)))
    mids.append(p.add_prior(x, bp.Rn([1.0, 2.0]), covariance=S))
    e = np.array([-1.0, -2.0])  # x ⊟ z at x = 0
    for mid in mids[1:]:  # every form of the same Σ gives r with ‖r‖² = eᵀ Σ⁻¹ e
        r = p.residual(mid)
        assert r @ r == pytest.approx(e @ np.linalg.solve(S, e)), mid
    assert np.allclose(p.residual(mids[0]), e / [2.0, np.sqrt(2.0)])
    with pytest.raises(ValueError, match="sigma is a 2×2 matrix; a full covariance is given as covariance="):
        p.add_measurement([1.0, 2.0], lambda v: v.vec, x, sigma=S)
    with pytest.raises(ValueError, match="give one of sigma, covariance"):
        p.add_prior(x, bp.Rn([1.0, 2.0]), sigma=1.0, covariance=S)
    with pytest.raises(ValueError, match=r"per-measurement covariance must have shape \(3, 2, 2\)"):
        p.add_measurements(np.ones((3, 2)), lambda v: v.vec, [[x]] * 3, covariance=np.stack([S] * 2))


def test_solve_returns_the_bound_summary_and_the_estimates_stay_in_the_problem():
    p = bp.OptimizationProblem()
    x = p.add_random_var(bp.Rn([3.0]))
    p.add_measurement([8.0], lambda v: v.vec**3, [x])
    s = p.solve(bp.SolverOptions(method="dogleg"), function_tolerance=1e-14)
    assert isinstance(s, bp.SolveSummary) and not hasattr(s, "X")
    assert p.X[x].vec == pytest.approx([2.0])


def test_codec_and_labels_are_public():
    p = bp.OptimizationProblem()
    T = p.add_random_var(bp.SE3())
    assert p.codec(T).dof == 6 and p.labels(T)[:3] == ["p.x", "p.y", "p.z"]
    with pytest.raises(IndexError, match="unknown variable id 5"):
        p.codec(5)
    X = np.array([[1.0, -30.0, 0.01], [0.0, 2.0, -5.0]])
    assert np.allclose(bp.codec_of(bp.Rn(3)).tangent_scale(X), np.maximum(1.0, np.abs(X)))
    assert np.allclose(bp.codec_of(bp.SO3()).tangent_scale(np.tile(bp.SO3().ambient, (2, 1))), 1.0)


def test_a_python_measurement_keeps_its_noise_in_cpp_and_errors_take_one_path():
    """The NoiseModel of a Python measurement lives in C++ with it: the problem's noise
    is the one given, the residual is W e, and errors() un-whitens it on the path of
    every C++ factor, to e = f(Y) ⊟ z."""
    p = bp.OptimizationProblem()
    R = p.add_random_var(bp.SO3.exp([0.3, -0.2, 0.1]))
    S = np.array([[0.04, 0.01, 0.0], [0.01, 0.09, 0.0], [0.0, 0.0, 0.01]])
    z = bp.SO3.exp([0.1, 0.2, 0.3])
    one = p.add_measurement(z, lambda r: r, [R], covariance=S, name="single")
    many = p.add_measurements([z, z], lambda r: r, [[R], [R]], covariance=S)
    e = p[R] - z
    W = np.linalg.inv(np.linalg.cholesky(S))
    for mid in [one, *many]:
        assert np.allclose(p._core.noise(mid).covariance_matrix, S)
        assert np.allclose(p.residual(mid), W @ e, atol=1e-12)
        assert np.allclose(p.measurement_errors(mid), e, atol=1e-12)
    assert np.allclose(p.errors()["<lambda>"], np.tile(e, (3, 1)), atol=1e-12)
    assert np.allclose(p.residuals()["<lambda>"], np.tile(W @ e, (3, 1)), atol=1e-12)


def test_a_group_of_two_widths_splits_by_width():
    """errors() stacks a group's rows: a prior on an Rn(2) and one on an SE3 (6 wide)
    share the group name 'prior' and are reported as 'prior' and 'prior[6]'."""
    p = bp.OptimizationProblem()
    x = p.add_random_var(bp.Rn([1.0, 2.0]))
    T = p.add_random_var(bp.SE3())
    p.add_prior(x, bp.Rn([0.0, 0.0]))
    p.add_prior(T, bp.SE3(t=[3.0, 4.0, 0.0]))
    rms = p.rms()
    assert rms["prior"] == pytest.approx(np.sqrt(5.0)) and rms["prior[6]"] == pytest.approx(5.0)
    assert p.groups() == {"prior": [0], "prior[6]": [1]}
