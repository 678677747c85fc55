"""3D systems: I(α, u) against independent geometry, and the Jacobians the solver
takes by central differences against analytic or extrapolated references."""

import boxplus as bp
import numpy as np
import pytest
from boxplus.batch import view
from boxplus.joint import ActiveTriangulation, RangeFinder, RobotArm, StereoPair, camera, project
from boxplus.manifolds import codec_of
from boxplus.measurements import _REL_STEP

CAM1 = camera(610.0, 322.0, 236.0, -0.12)
CAM2 = camera(595.0, 317.0, 243.0, -0.09)
CAM2_FROM_CAM1 = bp.SE3(bp.SO3.exp([0.01, -0.2, 0.02]), [-0.12, 0.003, 0.02])
CAM_FROM_LASER = bp.SE3(bp.SO3.exp([0.02, 0.3, -0.01]), [0.25, -0.01, 0.03])


def _points(n=20, seed=0):
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.uniform(-0.2, 0.2, n), rng.uniform(-0.15, 0.15, n), rng.uniform(0.4, 0.8, n)])


def _pix(cam, p):
    return project(view(codec_of(cam), np.tile(cam.ambient, (len(p), 1))), p)


def _systems():
    p = _points()
    stereo = StereoPair("stereo", cam1=CAM1, cam2=CAM2, cam2_from_cam1=CAM2_FROM_CAM1)
    U_stereo = np.column_stack([_pix(CAM1, p), _pix(CAM2, p @ CAM2_FROM_CAM1.R.T + CAM2_FROM_CAM1.pos)])
    laser = ActiveTriangulation("laser", camera=CAM1, cam_from_laser=CAM_FROM_LASER)
    pl = (p - CAM_FROM_LASER.pos) @ CAM_FROM_LASER.R
    U_laser = np.column_stack([_pix(CAM1, p), np.arctan2(pl[:, 0], pl[:, 2])])
    arm = RobotArm("arm", [0.19, 0.14, 0.08, 0.05], [0.01, -0.02, 0.015, 0.03], base_height=0.2)
    U_arm = np.random.default_rng(1).uniform(-1.2, 1.2, (20, 5))
    return [(stereo, U_stereo, p), (laser, U_laser, p), (arm, U_arm, None), (RangeFinder("rf"), p, p)]


@pytest.mark.parametrize("k", range(4), ids=["stereo", "laser", "arm", "range_finder"])
def test_points_recover_the_true_points(k):
    system, U, p = _systems()[k]
    if p is None:  # the arm: against a chain of homogeneous transforms
        p = np.array([_fk_homogeneous(system, u) for u in U])
    assert np.allclose(system.evaluate(U), p, atol=1e-10)


def _fk_homogeneous(arm, e):
    a = arm.parameters["lengths"].vec
    th = e + np.r_[0.0, arm.parameters["offsets"].vec]

    def rot(axis, t):
        return np.eye(4) if t is None else np.block([[bp.SO3.exp(t * np.eye(3)[axis]).R, np.zeros((3, 1))],
                                                     [np.zeros((1, 3)), np.ones((1, 1))]])

    def trans(v):
        T = np.eye(4)
        T[:3, 3] = v
        return T

    T = (rot(2, th[0]) @ trans([0, 0, arm.base_height]) @ rot(1, th[1]) @ trans([a[0], 0, 0]) @ rot(1, th[2])
         @ trans([a[1], 0, 0]) @ rot(1, th[3]) @ trans([a[2], 0, 0]) @ rot(0, th[4]))
    return (T @ np.r_[0, 0, a[3], 1.0])[:3]


def _numeric_jacobian(system, U, name, step_scale):
    """∂I/∂δ of parameter ``name`` by central differences with the solver's step × step_scale."""
    x = system.parameters[name]
    c = codec_of(x)
    h = _REL_STEP * step_scale * c.tangent_scale(x.ambient[None, :])[0]
    J = np.empty((len(U), 3, c.dof))
    for j in range(c.dof):
        d = np.zeros(c.dof)
        d[j] = h[j]
        J[:, :, j] = (system.evaluate(U, {name: x + d}) - system.evaluate(U, {name: x + (-d)})) / (2 * h[j])
    return J


def _richardson(system, U, name):
    """Reference Jacobian: central differences at a large step, Richardson-extrapolated twice."""
    D = [_numeric_jacobian(system, U, name, s) for s in (4000.0, 2000.0, 1000.0)]
    D1 = [(4 * D[i + 1] - D[i]) / 3 for i in range(2)]
    return (16 * D1[1] - D1[0]) / 15


@pytest.mark.parametrize("k", range(3), ids=["stereo", "laser", "arm"])
def test_solver_jacobian_matches_a_reference(k):
    system, U, _ = _systems()[k]
    for name in system.parameter_names:
        J = _numeric_jacobian(system, U, name, 1.0)
        ref = _richardson(system, U, name)
        scale = np.abs(ref).max()
        assert np.allclose(J, ref, atol=1e-6 * scale), name


def test_arm_jacobian_is_the_analytic_one():
    arm, U, _ = _systems()[2]
    # FK is linear in the lengths: ∂p/∂a is p at unit length a minus p at zero
    J = _numeric_jacobian(arm, U, "lengths", 1.0)
    a = arm.parameters["lengths"].vec
    for i in range(4):
        e = a.copy()
        e[i] += 1.0
        analytic = arm.evaluate(U, {"lengths": bp.Rn(e)}) - arm.evaluate(U)
        assert np.allclose(J[:, :, i], analytic, atol=1e-8)
    # joint j (2..5) turns everything after it about its axis: ∂p/∂o = ω × (p − o_j);
    # check the last joint (x axis of the wrist, through the wrist centre).
    J = _numeric_jacobian(arm, U, "offsets", 1.0)
    p = arm.evaluate(U)
    wrist = arm.evaluate(U, {"lengths": bp.Rn(np.r_[a[:3], 0.0])})
    p5 = arm.evaluate(U, {"lengths": bp.Rn(np.r_[a[:3], 1.0])}) - wrist  # direction of the tool (unit)
    p6 = arm.evaluate(U + np.r_[0, 0, 0, 0, np.pi / 2], {"lengths": bp.Rn(np.r_[a[:3], 1.0])}) - wrist
    axis = np.cross(p5, p6)
    assert np.allclose(J[:, :, 3], np.cross(axis, p - wrist), atol=1e-7)


def test_systems_reject_bad_data_naming_the_system():
    stereo = _systems()[0][0]
    with pytest.raises(ValueError, match="'stereo'.*\\(N, 4\\)"):
        stereo.evaluate(np.zeros((3, 3)))
    with pytest.raises(TypeError, match="missing \\['cam2_from_cam1'\\]"):
        StereoPair("s", cam1=CAM1, cam2=CAM2)
