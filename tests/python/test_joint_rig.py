"""JointRig and the C++ joint terms: values against the NumPy twins, Jacobians against
central differences, the simulated rig's ground truth, parallel = serial, and bad
input named."""

from concurrent.futures import ThreadPoolExecutor

import boxplus as bp
import numpy as np
import pytest
from boxplus.joint import (
    Beam,
    Camera,
    DHArm,
    JointRig,
    LightSheet,
    RangeSensor,
    Stereo,
    cross_validate,
    dh_labels,
)
from boxplus.joint.geometry import dh_pose, plane_in, project, ray, sheet_points, triangulate
from boxplus.synthetic.joint_rigs import NOMINAL_DH, make_rig

K1 = np.array([600.0, 322.0, 238.0, -0.10])
K2 = np.array([590.0, 318.0, 243.0, -0.08])


def _homogeneous(table, q, convention):
    """The chain as a product of 4×4 matrices (an independent FK)."""
    def rot(axis, t):
        H = np.eye(4)
        H[:3, :3] = bp.SO3.exp(t * np.eye(3)[axis]).R
        return H

    def trans(v):
        H = np.eye(4)
        H[:3, 3] = v
        return H

    H = np.eye(4)
    for (th0, d, a, al), qi in zip(table, q):
        th = qi + th0
        if convention == "standard":
            H = H @ rot(2, th) @ trans([0, 0, d]) @ trans([a, 0, 0]) @ rot(0, al)
        else:
            H = H @ rot(0, al) @ trans([a, 0, 0]) @ rot(2, th) @ trans([0, 0, d])
    return H


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_dh_pose_matches_homogeneous_matrices(convention):
    rng = np.random.default_rng(0)
    table = NOMINAL_DH + rng.normal(0, 0.05, NOMINAL_DH.shape)
    for _ in range(5):
        q = rng.uniform(-2, 2, 5)
        T = dh_pose(table, q, convention)
        H = _homogeneous(table, q, convention)
        assert np.allclose(T.R, H[:3, :3], atol=1e-12) and np.allclose(T.pos, H[:3, 3], atol=1e-12)


WIDE = {"kannala_brandt": [300, 302, 320, 240, 0.05, -0.01, 0.002, -0.0005],
        "double_sphere": [300, 302, 320, 240, -0.18, 0.59]}


@pytest.mark.parametrize("model,k", [("simple_radial", K1), ("pinhole", [600, 590, 320, 240]),
                                     ("opencv5", [600, 590, 320, 240, -0.1, 0.02, 1e-3, -1e-3, 0.001]),
                                     *WIDE.items()])
def test_ray_inverts_project(model, k):
    rng = np.random.default_rng(1)
    p = np.column_stack([rng.uniform(-0.3, 0.3, (20, 2)), rng.uniform(0.5, 1.0, 20)])
    r = ray(model, k, project(model, k, p))
    assert np.allclose(r / r[:, 2:], p / p[:, 2:], atol=1e-12)


@pytest.mark.parametrize("model", sorted(WIDE))
def test_wide_angle_cameras_serve_every_joint_term(model):
    # One camera-model home (camera/models.h): the joint terms take the fisheye and
    # double-sphere models too, points 60° off axis included; values against the
    # NumPy twins, Jacobians against central differences.
    k = WIDE[model]
    c21 = bp.SE3(bp.SO3.exp([0.01, -0.1, 0.02]), [-0.12, 0.003, 0.01])
    rig = JointRig(root="stereo")
    rig.add_camera("cam1", k, model)
    rig.add_camera("cam2", k, model)
    rig.add_system(Stereo("stereo", "cam1", "cam2", c21))
    sheet = np.r_[np.array([1.0, 0.0, -0.2]) / np.linalg.norm([1.0, 0.0, -0.2]), -0.14]
    rig.add_system(LightSheet("laser", "cam2", sheet), pose=c21.inverse())
    rig.add_system(RangeSensor("lidar"), pose=bp.SE3(bp.SO3.exp([0.1, 0, 0]), [0.1, 0, 0.05]))
    for p in ([0.05, -0.02, 0.7], [0.9, 0.3, 0.5]):  # the second 61° off camera 1's axis
        p = np.asarray(p)
        z1, z2 = project(model, k, p[None])[0], project(model, k, c21.fromlocal(p)[None])[0]
        x = rig.stereo_point("stereo", z1, z2, sigma=0.3)
        assert np.allclose(rig.evaluate(x), p, atol=1e-9)  # started at the two-view optimum
        r = rig.sensor_point("lidar", rig.pose("lidar").inverse().fromlocal(p + 0.01))
        rig.link(x, r, sigma=1e-3)
    s = rig.sheet_point("laser", [330.0, 200.0])
    s_cam = sheet_points(model, k, sheet, np.array([[330.0, 200.0]]))[0]
    assert np.allclose(rig.evaluate(s), c21.inverse().fromlocal(s_cam), atol=1e-12)
    m = rig.project(s, "stereo", [300.0, 250.0], camera=0, sigma=0.5)
    expected = project(model, k, rig.evaluate(s)[None])[0] - [300.0, 250.0]
    assert np.allclose(rig.problem.measurement_errors(m), expected, atol=1e-9)
    _numeric_jacobian_check(rig.problem, list(range(rig.problem.num_measurements)))


def _numeric_jacobian_check(o, mids, h=1e-6, rtol=1e-5, atol=1e-6):
    """The whitened Jacobian of the C++ terms against central differences in each tangent direction."""
    jac = o.jacobian()
    J = np.asarray(jac["jacobian"])
    rows = np.asarray(jac["row_offsets"])
    cols = np.asarray(jac["column_offsets"])
    for vi, vid in enumerate(jac["variables"]):
        x0 = o.value(vid)
        for t in range(o.codec(vid).dof):
            d = np.zeros(o.codec(vid).dof)
            d[t] = h
            o.set_value(vid, x0 + d)
            rp = np.concatenate([o.residual(m) for m in mids])
            o.set_value(vid, x0 + (-d))
            rm = np.concatenate([o.residual(m) for m in mids])
            o.set_value(vid, x0)
            num = (rp - rm) / (2 * h)
            ana = np.concatenate([J[rows[m]:rows[m] + len(o.residual(m)), cols[vi] + t] for m in mids])
            assert np.allclose(ana, num, rtol=rtol, atol=atol), (o.variable_name(vid), t, ana, num)


def _small_rig(convention="standard", encoder=True, mount_unknown=True):
    rng = np.random.default_rng(3)
    table = NOMINAL_DH + rng.normal(0, 0.01, NOMINAL_DH.shape)
    rig = JointRig(root="arm")
    rig.add_camera("cam1", K1, "simple_radial")
    rig.add_camera("cam2", K2, "simple_radial")
    mount = bp.SE3(bp.SO3.exp([0.1, 0.2, 0.3]), [0.01, 0.02, 0.03])
    rig.add_system(DHArm("arm", table, convention, unknown=["d1", "a2", "alpha3", "theta4", "a3"],
                         prior_sigma=(0.003, 0.02), encoder_sigma=2e-4 if encoder else None, mount=mount,
                         mount_unknown=mount_unknown))
    c21 = bp.SE3(bp.SO3.exp([0.01, -0.1, 0.02]), [-0.12, 0.003, 0.01])
    stereo_pose = bp.SE3(bp.SO3.exp([2.0, 0.1, -0.3]), [0.9, 0.1, 0.4])
    rig.add_system(Stereo("stereo", "cam1", "cam2", c21), pose=stereo_pose)
    sheet = np.r_[np.array([1.0, 0.0, -0.2]) / np.linalg.norm([1.0, 0.0, -0.2]), -0.14]
    rig.add_system(LightSheet("laser", "cam2", sheet), pose=stereo_pose * c21.inverse())
    rig.add_system(Beam("beam", "cam1", bp.SE3(bp.SO3.exp([0.0, 0.3, 0.0]), [0.2, 0.0, 0.0])), pose=stereo_pose)
    rig.add_system(RangeSensor("lidar"), pose=bp.SE3(bp.SO3.exp([0.1, 0, 0]), [1.0, 0, 0.5]))
    rig.add_system(Camera("mono", "cam1"), pose=stereo_pose)
    return rig, table, mount, stereo_pose, c21, sheet


def _stereo_pixels(p, c21):
    p = np.asarray(p, float)
    return (project("simple_radial", K1, p[None])[0], project("simple_radial", K2, c21.fromlocal(p)[None])[0])


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_every_term_matches_its_numpy_twin_and_central_differences(convention):
    rig, table, mount, S, c21, sheet = _small_rig(convention)
    q = np.array([0.1, 0.8, -0.9, 0.5, 0.2])
    corner = np.array([0.02, -0.03, 0.0])
    a = rig.arm_point("arm", q, corner, reading="r0")
    z = _stereo_pixels([0.02, 0.01, 0.7], c21)
    x = rig.stereo_point("stereo", z[0], z[1] + [0.5, -0.7], sigma=0.5)
    s = rig.sheet_point("laser", [330.0, 200.0])
    b = rig.beam_point("beam", [310.0, 260.0], 0.25)
    r = rig.sensor_point("lidar", [0.1, 0.2, 0.9])
    free = rig.plane("wall", init=[0.1, 0.2, 1.0, 0.7])
    owned = rig.plane("desk", owner="stereo", init=[0.0, 0.1, -1.0, -0.6])
    line = rig.line("edge", owner="lidar", init=[1.0, 0.1, 0.0, 0.0, 0.3, 0.8])
    m_xa = rig.link(x, a, covariance=np.diag([1e-6, 2e-6, 3e-6]))
    m_sr = rig.link(s, r, sigma=1e-3)
    rig.link(b, a, sigma=2e-3)
    m_wall = rig.coplanar([s, a, b], free, sigma=1e-3)
    rig.coplanar([r, x, a], owned, sigma=1e-3)
    m_board = rig.coplanar([s], rig.arm_plane("arm", q, reading="r0"), sigma=1e-3)
    rig.collinear([a, x], line, sigma=1e-3)
    m_proj = rig.project(a, "stereo", [310.0, 240.0], camera=1, sigma=0.5)
    rig.project(r, "mono", [300.0, 200.0], information=np.eye(2) * 4.0)
    z = _stereo_pixels([0.06, -0.02, 0.72], c21)
    rig.distance(x, rig.stereo_point("stereo", z[0], z[1], sigma=0.5), 0.05, sigma=1e-4)
    o = rig.problem
    all_mids = list(range(o.num_measurements))
    _numeric_jacobian_check(o, all_mids)
    # values against the NumPy twins, in the root (arm) frame
    e = rig.value("arm.encoder[r0]").vec
    T = dh_pose(rig.table("arm"), q + e, convention, None, rig.mount("arm"))
    assert np.allclose(rig.evaluate(a), T.fromlocal(corner), atol=1e-12)
    P = {k: rig.evaluate(p) for k, p in (("a", a), ("x", x), ("s", s), ("b", b), ("r", r))}
    assert np.allclose(o.measurement_errors(m_xa), P["x"] - P["a"], atol=1e-12)
    assert np.allclose(o.measurement_errors(m_sr), P["s"] - P["r"], atol=1e-12)
    pl_cam = np.r_[rig.value("laser.sheet").normal.vec, rig.value("laser.sheet").distance.vec]
    s_cam = sheet_points("simple_radial", K2, pl_cam, np.array([[330.0, 200.0]]))[0]
    assert np.allclose(P["s"], rig.pose("laser").fromlocal(s_cam), atol=1e-12)
    wall = rig.plane_in_root(free)
    assert np.isclose(o.measurement_errors(m_wall[0])[0], wall[:3] @ P["s"] - wall[3], atol=1e-12)
    board = plane_in(T, np.array([0.0, 0.0, 1.0, 0.0]))
    assert np.isclose(o.measurement_errors(m_board[0])[0], board[:3] @ P["s"] - board[3], atol=1e-12)
    pix = project("simple_radial", K2, c21.fromlocal(rig.pose("stereo").inverse().fromlocal(P["a"]))[None])[0]
    assert np.allclose(o.measurement_errors(m_proj), pix - [310.0, 240.0], atol=1e-9)


def test_stereo_point_starts_at_the_two_view_optimum_and_reprojects_in_both_images():
    rig, *_ = _small_rig()
    p = np.array([0.05, -0.02, 0.7])
    c21 = rig.value("stereo.cam2_from_cam1")
    z1 = project("simple_radial", K1, p[None])[0]
    z2 = project("simple_radial", K2, c21.fromlocal(p)[None])[0]
    x = rig.stereo_point("stereo", z1, z2, sigma=0.3)
    assert np.allclose(rig.problem.value(x.spec["var"]).vec, p, atol=1e-9)
    X = triangulate("simple_radial", K1, "simple_radial", K2, c21, z1 + [0, 2.0], z2 - [0, 2.0])
    # the optimum of the reprojection error is not the midpoint: both images share the gap
    e1 = project("simple_radial", K1, X) - (z1 + [0, 2.0])
    e2 = project("simple_radial", K2, X @ c21.R.T + c21.pos) - (z2 - [0, 2.0])
    assert np.linalg.norm(e1) > 0.5 and np.linalg.norm(e2) > 0.5


def test_synthetic_rig_truth_fits_the_data_to_the_noise():
    data = make_rig(0)
    assert len(data.boards) == 10 and len(data.planes) == 5 and len(data.folds) == 5
    dev = data.dh_true - data.dh_nominal
    assert 0.0005 < np.abs(dev[:, 1:3]).mean() < 0.006 and np.radians(0.2) < np.abs(dev[:, [0, 3]]).mean() < np.radians(2)
    e_px, e_sheet = [], []
    for b in data.boards:
        T = data.board_pose(b.joints_true)
        p1 = (data.board @ T.R.T + T.pos - data.arm_from_cam1.pos) @ data.arm_from_cam1.R
        e_px.append(project(data.model, data.k1_true, p1) - b.z1)
        P = sheet_points(data.model, data.k2_true, data.sheet_true, b.stripe)
        P = P @ data.arm_from_cam2.R.T + data.arm_from_cam2.pos
        e_sheet.append(P @ T.R[:, 2] - T.R[:, 2] @ T.pos)
    assert np.std(np.concatenate(e_px)) == pytest.approx(data.sigma_px, rel=0.15)
    assert np.abs(np.concatenate(e_sheet)).max() < 0.01  # stripe pixels lie on the board (m)
    for tr, va in data.folds:
        assert len(va["boards"]) == 2 and len(va["planes"]) == 1
        assert not set(tr["boards"]) & set(va["boards"])
    assert np.sort(np.concatenate([va["boards"] for _, va in data.folds])).tolist() == list(range(10))
    again = make_rig(0)
    assert np.array_equal(again.boards[3].z2, data.boards[3].z2)


def _restart_rig():
    data = make_rig(0, n_boards=2, n_planes=1, n_folds=2)
    rig2 = JointRig(root="arm")
    rig2.add_camera("cam1", data.k_nominal, "simple_radial")
    rig2.add_camera("cam2", data.k_nominal, "simple_radial")
    rig2.add_system(DHArm("arm", data.dh_nominal, unknown=["a2", "a3"], prior_sigma=(0.003, 0.02),
                          mount=data.end_from_board))
    rig2.add_system(Stereo("stereo", "cam1", "cam2", data.cam2_from_cam1), pose=data.arm_from_cam1)
    for b in data.boards:
        for j, c in enumerate(data.board[::4]):
            p = rig2.arm_point("arm", b.joints, c)
            rig2.project(p, "stereo", b.z1[4 * j], camera=0, sigma=0.3)
            rig2.project(p, "stereo", b.z2[4 * j], camera=1, sigma=0.3)
    return rig2


def test_parallel_restarts_equal_serial_restarts_bit_for_bit():
    a, b = _restart_rig(), _restart_rig()
    ra = a.solve(restarts=3, seed=5)
    with ThreadPoolExecutor(2) as ex:
        rb = b.solve(restarts=3, seed=5, executor=ex)
    assert ra.restarts.costs == rb.restarts.costs
    for va, vb in zip(a.problem.X, b.problem.X):
        assert np.array_equal(va.ambient, vb.ambient)


def test_cross_validate_with_given_folds_and_an_executor_equals_serial():
    data = make_rig(0, n_boards=4, n_planes=2, n_folds=2)

    def fit(split, n_corners):
        rig = JointRig(root="arm")
        rig.add_camera("cam1", data.k_nominal, "simple_radial")
        rig.add_camera("cam2", data.k_nominal, "simple_radial")
        rig.add_system(DHArm("arm", data.dh_nominal, unknown=["a2", "a3", "d5"], prior_sigma=(0.003, 0.02),
                             mount=data.end_from_board))
        rig.add_system(Stereo("stereo", "cam1", "cam2", data.cam2_from_cam1), pose=data.arm_from_cam1)
        for v in split["boards"]:
            b = data.boards[v]
            for j in range(0, len(data.board), n_corners):
                p = rig.arm_point("arm", b.joints, data.board[j])
                rig.project(p, "stereo", b.z1[j], camera=0, sigma=0.3)
                rig.project(p, "stereo", b.z2[j], camera=1, sigma=0.3)
        rig.solve()
        return rig.table("arm")

    def validate(table, split):
        return np.abs(table - data.dh_true)[:, 1:3].ravel()

    methods = {"every corner": lambda s: fit(s, 1), "every 3rd": lambda s: fit(s, 3)}
    serial = cross_validate(methods, validate, folds=data.folds)
    with ThreadPoolExecutor(2) as ex:
        parallel = cross_validate(methods, validate, folds=data.folds, executor=ex)
    assert serial.fold_errors == parallel.fold_errors
    with pytest.raises(ValueError, match="fold 0 trains and validates on items \\[1\\]"):
        cross_validate(methods, validate, folds=[({"boards": [0, 1]}, {"boards": [1]})])


# ---- bad input, named ----------------------------------------------------------------

def _two_systems():
    rig = JointRig()
    rig.add_system(RangeSensor("lidar"))
    rig.add_system(RangeSensor("tof"), pose=bp.SE3())
    return rig


def test_a_plane_group_with_fewer_than_three_points_is_named():
    rig = _two_systems()
    wall = rig.plane("wall")
    pts = [rig.sensor_point("lidar", p) for p in ([0, 0, 1.0], [1, 0, 1.0])]
    with pytest.raises(ValueError, match="plane group 'wall': 2 points cannot define a plane"):
        rig.coplanar(pts, wall, sigma=1e-3)
    rig = _two_systems()
    pts = [rig.sensor_point("lidar", p) for p in ([0, 0, 1.0], [1, 0, 1.0])]
    floor = rig.plane("floor", init=[0, 0, 1.0, 0])
    rig.coplanar(pts, floor, sigma=1e-3)
    rig.link(rig.sensor_point("lidar", [0, 0, 0]), rig.sensor_point("tof", [0, 0, 0]), sigma=1e-3)
    with pytest.raises(ValueError, match="plane group 'floor' has 2 points: a plane needs at least 3"):
        rig.solve()


def test_a_system_with_no_data_is_named():
    rig = _two_systems()
    rig.add_system(RangeSensor("radar"), pose=bp.SE3())
    rig.link(rig.sensor_point("lidar", [0, 0, 0]), rig.sensor_point("tof", [0, 0, 0]), sigma=1e-3)
    with pytest.raises(ValueError, match=r"system\(s\) \['radar'\] have no data"):
        rig.solve()


def test_a_disconnected_graph_of_systems_is_named():
    rig = _two_systems()
    rig.add_system(RangeSensor("radar"), pose=bp.SE3())
    rig.add_system(RangeSensor("sonar"), pose=bp.SE3())
    rng = np.random.default_rng(0)
    for _ in range(4):
        p = rng.normal(size=3)
        rig.link(rig.sensor_point("lidar", p), rig.sensor_point("tof", p), sigma=1e-3)
        rig.link(rig.sensor_point("radar", p), rig.sensor_point("sonar", p), sigma=1e-3)
    with pytest.raises(ValueError, match=r"not connected: \['radar', 'sonar'\] share no term with 'lidar'"):
        rig.solve()


def test_unknown_dh_parameters_the_data_cannot_determine_are_named():
    """Without priors, the offset of joint 1 is a rotation of the whole arm about the base z
    axis, which the stereo pair's pose absorbs: the degeneracy report names it."""
    data = make_rig(0, n_boards=3, n_planes=1, n_folds=3)
    rig = JointRig(root="arm")
    rig.add_camera("cam1", data.k1_true, "simple_radial", fixed=True)
    rig.add_camera("cam2", data.k2_true, "simple_radial", fixed=True)
    rig.add_system(DHArm("arm", data.dh_true, unknown=["theta1", "a2", "a3"], mount=data.end_from_board))
    rig.add_system(Stereo("stereo", "cam1", "cam2", data.cam2_from_cam1), pose=data.arm_from_cam1)
    rig.problem.fix(rig.ids["stereo.cam2_from_cam1"])
    for b in data.boards:
        for j, c in enumerate(data.board):
            p = rig.arm_point("arm", b.joints, c)
            rig.project(p, "stereo", b.z1[j], camera=0, sigma=0.3)
    names = sorted({n for _, ns in rig.degeneracy() for n in ns})
    assert "arm.dh.theta1" in names and "arm.dh.a2" not in names
    with pytest.raises(ValueError, match=r"cannot determine \[.*'arm.dh.theta1'"):
        rig.check_determined()
    # and a solve says so too (it used to report convergence, θ₁ moved 2.9°, silently)
    with pytest.warns(bp.UndeterminedWarning, match=r"'arm.dh': .*theta1"):
        rig.solve()


def test_bad_arm_and_term_input_is_named():
    with pytest.raises(ValueError, match="DHArm 'arm': unknown DH entries \\['b7'\\]"):
        DHArm("arm", NOMINAL_DH, unknown=["b7"])
    with pytest.raises(ValueError, match="convention must be 'standard' or 'modified'"):
        DHArm("arm", NOMINAL_DH, "craig")
    rig, *_ = _small_rig()
    with pytest.raises(ValueError, match="arm 'arm' needs 5 finite joint readings, got 4"):
        rig.arm_point("arm", np.zeros(4), [0, 0, 0], reading=1)
    with pytest.raises(ValueError, match="has encoder noise: name the reading"):
        rig.arm_point("arm", np.zeros(5), [0, 0, 0])
    with pytest.raises(KeyError, match="unknown system 'radar'"):
        rig.sensor_point("radar", [0, 0, 0])
    with pytest.raises(ValueError, match="a link ties two different systems"):
        p = rig.sensor_point("lidar", [0, 0, 1.0])
        rig.link(p, p, sigma=1.0)
    with pytest.raises(ValueError, match="camera must be 0 or 1"):
        rig.project(p, "stereo", [1.0, 2.0], camera=2)
    with pytest.raises(ValueError, match="link lidar–arm: covariance must be 3×3"):
        rig.link(p, rig.arm_point("arm", np.zeros(5), [0, 0, 0], 1), covariance=np.eye(2))
    with pytest.raises(ValueError, match="projection into 'mono': .*noise of dimension 3 for an error of 2"):
        rig.project(p, "mono", [1.0, 2.0], noise=bp.NoiseModel.isotropic(3, 1.0))
    assert dh_labels(2) == ["theta1", "d1", "a1", "alpha1", "theta2", "d2", "a2", "alpha2"]


def test_target_projection_equals_one_projection_per_point():
    rig, *_ = _small_rig()
    q = np.array([0.1, 0.8, -0.9, 0.5, 0.2])
    P = np.array([[0.0, 0.0, 0.0], [0.03, 0.0, 0.0], [0.0, 0.04, 0.0]])
    Z = np.array([[300.0, 240.0], [320.0, 250.0], [310.0, 230.0]])
    m_all = rig.project_targets("arm", q, P, "stereo", Z, camera=1, reading="r", covariance=np.diag([0.25, 0.5]))
    singles = [rig.project(rig.arm_point("arm", q, p, reading="r"), "stereo", z, camera=1,
                           covariance=np.diag([0.25, 0.5])) for p, z in zip(P, Z)]
    o = rig.problem
    assert np.allclose(o.measurement_errors(m_all), np.concatenate([o.measurement_errors(m) for m in singles]),
                       atol=1e-10)
    assert np.allclose(o.residual(m_all), np.concatenate([o.residual(m) for m in singles]), atol=1e-10)
    _numeric_jacobian_check(o, [m_all])
    with pytest.raises(ValueError, match="p_in_target must be \\(M, 3\\) and Z \\(M, 2\\)"):
        rig.project_targets("arm", q, P, "stereo", Z[:2], reading="r", sigma=1.0)


def _noise_free_rig(data, unknown, mount_unknown):
    rig = JointRig(root="arm")
    rig.add_camera("cam1", data.k1_true, "simple_radial", fixed=True)
    rig.add_camera("cam2", data.k2_true, "simple_radial", fixed=True)
    table = data.dh_true.copy()
    for lab in unknown:  # the other entries are known exactly
        j, c = int(lab[-1]) - 1, ("theta", "d", "a", "alpha").index(lab[:-1])
        table[j, c] = data.dh_nominal[j, c]
    mount0 = data.end_from_board * bp.SE3(bp.SO3.exp([0.01, -0.01, 0.02]), [0.002, -0.003, 0.001]) \
        if mount_unknown else data.end_from_board
    rig.add_system(DHArm("arm", table, unknown=unknown, mount=mount0, mount_unknown=mount_unknown))
    rig.add_system(Stereo("stereo", "cam1", "cam2", data.cam2_from_cam1),
                   pose=data.arm_from_cam1 * bp.SE3(bp.SO3.exp([0.01, 0.0, -0.01]), [0.003, 0.002, -0.004]))
    rig.problem.fix(rig.ids["stereo.cam2_from_cam1"])
    n, d = data.sheet_true[:3] + [0.01, -0.02, 0.0], data.sheet_true[3] + 0.004
    rig.add_system(LightSheet("laser", "cam2", np.r_[n, d]), pose=data.arm_from_cam2)
    for b in data.boards:
        for cam, z in ((0, b.z1), (1, b.z2)):
            rig.project_targets("arm", b.joints, data.board, "stereo", z, camera=cam, sigma=0.3)
        rig.coplanar([rig.sheet_point("laser", uv) for uv in b.stripe], rig.arm_plane("arm", b.joints), sigma=1e-3)
    return rig


@pytest.mark.parametrize("mount_unknown", [False, True])
def test_noise_free_views_recover_the_true_table_mount_and_light_sheet(mount_unknown):
    """ML on noise-free data from a start off by a few mm / degrees: the identifiable DH
    entries, the mount (when unknown), the stereo pose and the light sheet come back exactly.
    With the mount unknown, the last joint's offset and d are the mount's rotation and
    translation about its z axis: the degeneracy report names them first."""
    data = make_rig(2, n_boards=6, n_planes=1, n_folds=2, sigma_px=0.0, sigma_encoder=0.0)
    unknown = ["a2", "a3", "d5", "alpha2", "theta3", "theta5"]
    if mount_unknown:
        names = {n for _, ns in _noise_free_rig(data, unknown, True).degeneracy() for n in ns}
        assert {"arm.dh.theta5", "arm.dh.d5"} <= names and "arm.dh.a2" not in names
        unknown = unknown[:2] + unknown[3:5]
    rig = _noise_free_rig(data, unknown, mount_unknown)
    rig.check_determined()
    r = rig.solve(function_tolerance=1e-15, gradient_tolerance=1e-15, parameter_tolerance=1e-15)
    assert r.termination == "convergence"
    assert np.allclose(rig.table("arm"), data.dh_true, atol=1e-7)
    assert np.allclose(rig.pose("stereo").ambient[:3], data.arm_from_cam1.ambient[:3], atol=1e-7)
    if mount_unknown:
        assert np.allclose(rig.mount("arm").ambient[:3], data.end_from_board.ambient[:3], atol=1e-7)
    sheet = rig.value("laser.sheet")
    P = sheet_points(data.model, data.k2_true, np.r_[sheet.normal.vec, sheet.distance.vec], data.boards[0].stripe)
    P_true = sheet_points(data.model, data.k2_true, data.sheet_true, data.boards[0].stripe)
    L = rig.pose("laser")
    assert np.allclose(P @ L.R.T + L.pos, P_true @ data.arm_from_cam2.R.T + data.arm_from_cam2.pos, atol=1e-7)


def test_beam_is_a_light_sheet_at_fixed_angle_and_hits_the_ray_plane_intersection():
    """The angle-per-point projector (Le & Ng eq. 10): a Beam point is the camera ray of
    the pixel cut by the laser's plane at that angle, and a LightSheet holding the sheet
    of one angle gives the same points."""
    from boxplus.calib.models import rays

    cam_from_laser = bp.SE3(bp.SO3.exp([0.02, 0.3, -0.01]), [0.25, -0.01, 0.03])
    rig = JointRig()
    rig.add_camera("cam", K1, "simple_radial")
    rig.add_system(Beam("beam", "cam", cam_from_laser))
    beta = 0.2
    n = cam_from_laser.R @ [np.cos(beta), 0.0, -np.sin(beta)]
    rig.add_system(LightSheet("sheet", "cam", np.r_[n, n @ cam_from_laser.pos]), pose=bp.SE3())
    uv = np.array([[300.0, 200.0], [350.0, 260.0], [280.0, 300.0]])
    r = rays(K1, uv, "simple_radial")  # [x, y, 1] in the camera frame
    p_ray = r * ((n @ cam_from_laser.pos) / (r @ n))[:, None]
    p_beam = np.array([rig.evaluate(rig.beam_point("beam", u, beta)) for u in uv])
    p_sheet = np.array([rig.evaluate(rig.sheet_point("sheet", u)) for u in uv])
    assert np.allclose(p_beam, p_ray, atol=1e-9) and np.allclose(p_sheet, p_ray, atol=1e-9)
    # and the C++ terms agree with these NumPy values: a link between the two is zero
    for u in uv:
        m = rig.link(rig.beam_point("beam", u, beta), rig.sheet_point("sheet", u), sigma=1e-3)
        assert np.allclose(rig.problem.measurement_errors(m), 0.0, atol=1e-12)


def test_process_pool_restarts_of_a_rig_with_a_light_sheet_equal_serial():
    # The light sheet is a Plane compound (made at run time): its class must pickle
    # (it failed with "Can't pickle <class 'boxplus.manifolds.Plane'>"). Processes give
    # the serial run's numbers bit for bit: the restarts' starts travel pickled, and a
    # value unpickles its exact stored numbers (normalising them again moved the last
    # bit, and the restarts' costs by 1e-14 relative).
    from concurrent.futures import ProcessPoolExecutor

    data = make_rig(2, n_boards=6, n_planes=1, n_folds=2)  # with noise: costs of order 1
    unknown = ["a2", "a3", "d5", "alpha2", "theta3", "theta5"]
    a, b = _noise_free_rig(data, unknown, False), _noise_free_rig(data, unknown, False)
    ra = a.solve(restarts=2, seed=3)
    with ProcessPoolExecutor(2) as ex:
        rb = b.solve(restarts=2, seed=3, executor=ex)
    assert list(ra.restarts.costs) == list(rb.restarts.costs)
    for name, vid in a.ids.items():
        assert np.array_equal(a.problem.X[vid].ambient, b.problem.X[vid].ambient), name


def test_dh_unknowns_are_stored_in_table_order_and_read_by_label():
    data = make_rig(0, n_boards=3, n_planes=1, n_folds=3)
    rig = JointRig(root="arm")
    arm = DHArm("arm", data.dh_true, unknown=["a3", "theta1", "alpha2"], mount=data.end_from_board)
    rig.add_system(arm)
    assert arm.unknown_labels == ["theta1", "alpha2", "a3"]  # table order, not the list's
    values = rig.dh_values("arm")
    assert list(values) == ["theta1", "alpha2", "a3"]
    assert values["a3"] == data.dh_true[2, 2] and values["alpha2"] == data.dh_true[1, 3]
    with pytest.raises(KeyError, match="unknown system 'nope'"):
        rig.dh_values("nope")


def test_a_range_sensor_and_an_arm_recover_the_table_and_the_pose_jointly():
    """Noise-free points of the arm's target measured by a range sensor: the unknown DH
    entries and the sensor's pose come back exactly."""
    data = make_rig(1, n_boards=8, n_planes=1, n_folds=2, sigma_px=0.0, sigma_encoder=0.0)
    lidar_from_arm = bp.SE3(bp.SO3.exp([0.1, -0.2, 0.3]), [0.5, 0.1, -0.2])
    unknown = ["a2", "a3", "alpha2", "d4"]
    table = data.dh_true.copy()
    for lab in unknown:
        j, c = int(lab[-1]) - 1, ("theta", "d", "a", "alpha").index(lab[:-1])
        table[j, c] = data.dh_nominal[j, c]
    rig = JointRig(root="arm")
    rig.add_system(DHArm("arm", table, unknown=unknown, mount=data.end_from_board))
    rig.add_system(RangeSensor("lidar"), pose=bp.SE3(bp.SO3.exp([0.12, -0.18, 0.31]), [0.49, 0.11, -0.2]))
    for b in data.boards:
        for c in data.board[::6]:
            p_arm = geometry_point(data, b.joints, c)
            p_lidar = lidar_from_arm.fromlocal(p_arm)
            rig.link(rig.sensor_point("lidar", p_lidar), rig.arm_point("arm", b.joints, c), sigma=1e-4)
    r = rig.solve(function_tolerance=1e-15, gradient_tolerance=1e-15, parameter_tolerance=1e-15)
    assert r.termination == "convergence"
    got = rig.dh_values("arm")
    for lab in unknown:
        j, c = int(lab[-1]) - 1, ("theta", "d", "a", "alpha").index(lab[:-1])
        assert got[lab] == pytest.approx(data.dh_true[j, c], abs=1e-7), lab
    assert np.linalg.norm(rig.pose("lidar").inverse() - lidar_from_arm) < 1e-7


def geometry_point(data, joints, c):
    """The arm's target point c in the arm's frame, from the NumPy twin of the C++ term."""
    from boxplus.joint.geometry import dh_pose

    T = dh_pose(data.dh_true, joints, data.convention, None, data.end_from_board)
    return T.R @ c + T.pos


def test_coplanar_points_estimate_their_plane():
    """A wall seen by a range sensor: the plane variable converges to the wall."""
    rng = np.random.default_rng(3)
    n = np.array([0.2, 0.1, 1.0]) / np.linalg.norm([0.2, 0.1, 1.0])
    u = np.cross(n, [1.0, 0, 0])
    u /= np.linalg.norm(u)
    P = 1.5 * n + rng.uniform(-1, 1, (20, 1)) * u + rng.uniform(-1, 1, (20, 1)) * np.cross(n, u)
    rig = _two_systems()
    wall = rig.plane("wall")
    rig.coplanar([rig.sensor_point("lidar", p) for p in P], wall, sigma=1e-3)
    for p in P[:4]:
        rig.link(rig.sensor_point("lidar", p), rig.sensor_point("tof", p), sigma=1e-3)
    rig.solve()
    plane = rig.plane_in_root(wall)
    s = np.sign(plane[:3] @ n)
    assert np.allclose(s * plane[:3], n, atol=1e-9) and np.isclose(s * plane[3], 1.5)


def test_suggested_arm_pose_predicts_the_sigma_its_capture_gives():
    """suggest_arm_poses ranks candidate joint readings by the DH table's σ their view
    would leave; capturing the first and the last (noise-free pixels from the truth,
    re-solved) gives the σ each was predicted to give, the first the lower."""
    import importlib.util
    import warnings
    from pathlib import Path

    from boxplus.calib.models import project as project_lens
    from boxplus.synthetic.joint_rigs import HOME

    spec = importlib.util.spec_from_file_location(
        "joint_rig_tutorial", Path(__file__).resolve().parents[2] / "docs" / "tutorials" / "joint_rig.py")
    tutorial = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tutorial)
    data = make_rig(0, n_boards=6)
    rig = tutorial.build(data)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rig.solve()
    rng = np.random.default_rng(3)
    candidates = [HOME + rng.normal(0.0, [0.25, 0.15, 0.15, 0.25, 0.5]) for _ in range(8)]
    candidates.append(HOME + [np.pi, 0.0, 0.0, 0.0, 0.0])  # the board turned away: out of view
    n_terms = rig.problem.num_measurements
    ranked = rig.suggest_arm_poses("arm", candidates, data.board, "stereo", sigma=data.sigma_px,
                                   image_size=(640, 480))
    assert rig.problem.num_measurements == n_terms  # the rig itself is unchanged
    assert sorted(i for i, _ in ranked) == list(range(8))  # the turned-away one is left out
    scores = [s for _, s in ranked]
    assert scores == sorted(scores) and 0 < scores[0] < scores[-1] < 1
    dh = [rig.ids["arm.dh"]]
    before = np.sqrt(np.diag(rig.problem.joint_covariance(dh)))
    for index, predicted in (ranked[0], ranked[-1]):
        captured = rig._bound_to(rig.problem.copy())
        q = candidates[index]
        for camera, (k, arm_from_cam) in enumerate(((data.k1_true, data.arm_from_cam1),
                                                    (data.k2_true, data.arm_from_cam2))):
            cam_from_board = arm_from_cam.inverse() * data.board_pose(q)
            z = project_lens(k, data.board @ cam_from_board.R.T + cam_from_board.pos, data.model)
            captured.project_targets("arm", q, data.board, "stereo", z, camera=camera, reading="new",
                                     sigma=data.sigma_px)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            captured.problem.solve()
        after = np.sqrt(np.diag(captured.problem.joint_covariance(dh)))
        assert np.mean(after / before) == pytest.approx(predicted, rel=0.01)
    with pytest.raises(ValueError, match="no variable"):
        rig.suggest_arm_poses("arm", candidates[:1], data.board, "stereo", sigma=0.3, variables=["nope"])
