"""The maximum-likelihood joint solution through the joint API equals the one written
directly on OptimizationProblem (issue #13), on the simulated Le & Ng rig.

The direct problem uses the engine's own DH marker factor (add_dh_marker) for the
board corners and NumPy measurement functions (an independent implementation of
light-sheet triangulation, stereo reprojection and coplanarity) for the rest.
"""

import importlib.util
from pathlib import Path

import boxplus as bp
import numpy as np
import pytest
from boxplus.calib import add_dh_marker
from boxplus.joint import Plane
from boxplus.synthetic.joint_rigs import make_rig

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "joint_calibration_robot.py"
TIGHT = {"function_tolerance": 1e-14, "gradient_tolerance": 1e-14, "parameter_tolerance": 1e-14,
         "max_iterations": 200}


def _example():
    spec = importlib.util.spec_from_file_location("joint_calibration_robot", EXAMPLE)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _fk(tables, Q, end_from_board):
    """Standard-DH base_from_board for rows of tables (N, n, 4) and readings Q (N, n):
    (R (N,3,3), t (N,3)) — an independent FK by rotation matrices."""
    N = len(Q)
    R = np.tile(np.eye(3), (N, 1, 1))
    t = np.zeros((N, 3))
    for j in range(tables.shape[1]):
        th0, d, a, al = tables[:, j].T
        th = Q[:, j] + th0
        c, s = np.cos(th), np.sin(th)
        ca, sa = np.cos(al), np.sin(al)
        A = np.zeros((N, 3, 3))
        A[:, 0, 0], A[:, 0, 1], A[:, 0, 2] = c, -s * ca, s * sa
        A[:, 1, 0], A[:, 1, 1], A[:, 1, 2] = s, c * ca, -c * sa
        A[:, 2, 1], A[:, 2, 2] = sa, ca
        p = np.column_stack([a * c, a * s, d])
        t = t + np.einsum("nij,nj->ni", R, p)
        R = np.einsum("nij,njk->nik", R, A)
    t = t + R @ end_from_board.pos
    R = R @ end_from_board.R
    return R, t


def _project(K, p):
    """simple_radial π for rows of intrinsics K (N, 4) [f, cx, cy, k1] and points p (N, 3)."""
    x = p[:, :2] / p[:, 2:]
    s = 1.0 + K[:, 3:4] * np.sum(x * x, 1, keepdims=True)
    return K[:, :1] * x * s + K[:, 1:3]


def _ray(K, uv):
    """[x, y, 1] with _project(K, [x, y, 1]) = uv: Newton on the radius (an independent inverse)."""
    xd = (uv - K[:, 1:3]) / K[:, :1]
    rd = np.linalg.norm(xd, axis=1, keepdims=True)
    r = rd.copy()
    for _ in range(30):
        r = r - (r * (1 + K[:, 3:4] * r * r) - rd) / (1 + 3 * K[:, 3:4] * r * r)
    x = xd * np.where(rd > 0, r / np.where(rd > 0, rd, 1), 1)
    return np.column_stack([x, np.ones(len(x))])


def _sheet_in_root(k, sheet, L, uv, model):
    """Stripe pixels triangulated on the sheet, in the root frame (N, 3); rows of batches."""
    assert model == "simple_radial"
    r = _ray(k.vec, uv)
    n, d = sheet.normal.vec, sheet.distance.vec[:, 0]
    p = r * (d / np.sum(n * r, 1))[:, None]
    return np.einsum("nij,nj->ni", L.R, p) + L.pos


def _direct(ex, data, split, rig):
    """The same objective written on OptimizationProblem; start values copied from ``rig``."""
    o = bp.OptimizationProblem()
    v = {name: rig.problem.value(i) for name, i in rig.ids.items()}
    ids = {}
    for name in ("cam1", "cam2", "stereo.cam2_from_cam1", "arm.dh", "pose:stereo", "laser.sheet", "pose:laser"):
        ids[name] = o.add_random_var(v[name], name=name)
    nominal = data.dh_nominal.ravel()
    sig = np.tile([ex.DH_PRIOR[1], ex.DH_PRIOR[0], ex.DH_PRIOR[0], ex.DH_PRIOR[1]], len(data.dh_nominal))
    o.add_prior(ids["arm.dh"], bp.Rn(nominal), sigma=sig)
    for cam in ("cam1", "cam2"):
        o.add_prior(ids[cam], bp.Rn(data.k_nominal), sigma=ex.K_PRIOR)
    eye = o.add_random_var(bp.SE3(), fixed=True)
    corners = [o.add_random_var(bp.Rn(c), fixed=True) for c in data.board]
    model, s_px = data.model, data.sigma_px
    for b in (data.boards[i] for i in split["boards"]):
        for j, cid in enumerate(corners):
            add_dh_marker(o, b.z1[j], ids["cam1"], ids["pose:stereo"], cid, eye, ids["arm.dh"], b.joints,
                            flange_from_hand=data.end_from_board, sigma=s_px, model=model)
            add_dh_marker(o, b.z2[j], ids["cam2"], ids["pose:stereo"], cid, ids["stereo.cam2_from_cam1"],
                            ids["arm.dh"], b.joints, flange_from_hand=data.end_from_board, sigma=s_px, model=model)

    def stripe_on_board(k, sheet, L, dh, uv, Q):
        P = _sheet_in_root(k, sheet, L, uv, model)
        R, t = _fk(dh.vec.reshape(len(uv), -1, 4), Q, data.end_from_board)
        n = R[:, :, 2]
        return np.sum(n * (P - t), 1, keepdims=True)

    UV = np.vstack([data.boards[i].stripe for i in split["boards"]])
    Q = np.vstack([np.tile(data.boards[i].joints, (len(data.boards[i].stripe), 1)) for i in split["boards"]])
    rows = np.tile([ids["cam2"], ids["laser.sheet"], ids["pose:laser"], ids["arm.dh"]], (len(UV), 1))
    o.add_measurements(np.zeros((len(UV), 1)), stripe_on_board, rows, constants=(UV, Q), sigma=ex.SIGMA_SHEET)

    def reproject1(k, X, z):
        return _project(k.vec, X.vec) - z

    def reproject2(k, X, c21, z):
        return _project(k.vec, np.einsum("nij,nj->ni", c21.R, X.vec) + c21.pos) - z

    def on_plane(X, S, plane):
        P = np.einsum("nij,nj->ni", S.R, X.vec) + S.pos
        return np.sum(plane.normal.vec * P, 1, keepdims=True) - plane.distance.vec

    def stripe_on_plane(k, sheet, L, plane, uv):
        P = _sheet_in_root(k, sheet, L, uv, model)
        return np.sum(plane.normal.vec * P, 1, keepdims=True) - plane.distance.vec

    for i in split["planes"]:
        pv = data.planes[i]
        pid = o.add_random_var(v[f"plane:plane{i}"], name=f"plane{i}")
        xs = [o.add_random_var(v[n], name=n) for n in rig.ids if n.startswith(f"stereo.plane{i}.X")]
        assert len(xs) == len(pv.z1)
        n = len(xs)
        o.add_measurements(np.zeros((n, 2)), lambda k, X, z: reproject1(k, X, z),
                           np.column_stack([np.full(n, ids["cam1"]), xs]), constants=(pv.z1,), sigma=s_px)
        o.add_measurements(np.zeros((n, 2)), lambda k, X, c, z: reproject2(k, X, c, z),
                           np.column_stack([np.full(n, ids["cam2"]), xs, np.full(n, ids["stereo.cam2_from_cam1"])]),
                           constants=(pv.z2,), sigma=s_px)
        o.add_measurements(np.zeros((n, 1)), on_plane,
                           np.column_stack([xs, np.full(n, ids["pose:stereo"]), np.full(n, pid)]), sigma=ex.SIGMA_FLAT)
        m = len(pv.stripe)
        o.add_measurements(np.zeros((m, 1)), stripe_on_plane,
                           np.tile([ids["cam2"], ids["laser.sheet"], ids["pose:laser"], pid], (m, 1)),
                           constants=(pv.stripe,), sigma=ex.SIGMA_SHEET)
    return o


def test_ml_through_the_joint_api_equals_ml_written_on_the_problem():
    ex = _example()
    data = make_rig(0, n_boards=4, n_planes=2, n_folds=2, cols=5, rows=4, square=0.04)
    split = {"boards": np.arange(4), "planes": np.arange(2)}
    rig = ex.build(data, split, "full ML", encoder=False)
    direct = _direct(ex, data, split, rig)
    # the same objective: equal costs at the common start and at a perturbed point
    assert direct.cost() == pytest.approx(rig.problem.cost(), rel=1e-10)
    r = rig.solve(**TIGHT)
    d = direct.solve(method="auto", **TIGHT)  # JointRig.solve's default method: the same path to the optimum
    assert r.termination == "convergence" and d.termination == "convergence"
    assert direct.cost() == pytest.approx(rig.problem.cost(), rel=1e-8)
    # and the same solution (within what the numeric Jacobians of the direct terms allow)
    for name in ("cam1", "cam2", "arm.dh"):
        a = rig.value(name).vec
        b = direct.value([i for i in range(direct.num_variables) if direct.variable_name(i) == name][0]).vec
        assert np.allclose(a, b, rtol=1e-5, atol=1e-7), name
    # held-out sanity: the ML fit reprojects the arm-predicted corners to the noise level
    v = {n: rig.value(n) for n in ("cam1", "cam2", "stereo.cam2_from_cam1", "laser.sheet", "arm.dh",
                                   "pose:stereo", "pose:laser")}
    e = ex.metrics(data, v, split)
    assert e[1] < 1.5 * np.sqrt(2) * data.sigma_px
    assert isinstance(rig.value("plane:plane0"), Plane)
