"""N-camera rigs with partial overlap, outlier rejection, projection
uncertainty against Monte Carlo, coverage, ChArUco and AprilTag-grid
detection on rendered images, and the plots (optional ax, a Figure back)."""

import numpy as np
import pytest
from boxplus import SE3, SO3, Rn
from boxplus.calib import calibrate_mono, calibrate_rig
from boxplus.calib.models import project
from boxplus.calib.uncertainty import coverage, projection_sigma, projection_uncertainty
from boxplus.synthetic.cameras import TRUE_K, board_points, observe, random_views

CAM_FROM_REF = {
    "cam1": SE3(SO3.exp(np.array([0.0, -0.25, 0.02])), np.array([-0.12, 0.01, 0.02])),
    "cam2": SE3(SO3.exp(np.array([0.03, 0.3, -0.01])), np.array([0.15, -0.02, 0.03])),
}
K = {"cam0": TRUE_K, "cam1": TRUE_K * [1.01, 1.01, 0.98, 1.02, 0.9, 1.1, 0.5, 1.2, 0],
     "cam2": TRUE_K * [0.99, 0.99, 1.01, 0.99, 1.1, 0.8, -1.0, 0.7, 0]}


def _simulate_rig(rng, n_views=24, sigma=0.3):
    obj = board_points(9, 6, 0.04)
    views = random_views(n_views, rng, obj.mean(axis=0), distance=0.45, spread=0.7)
    det = {c: [] for c in K}
    # occlusions: cam1 misses every third view, cam2 the next one
    hidden = {"cam0": -1, "cam1": 0, "cam2": 1}
    for i, v in enumerate(views):
        for c in K:
            if i % 3 == hidden[c]:
                det[c].append(None)
                continue
            pose = v if c == "cam0" else v * CAM_FROM_REF[c].inverse()  # world_from_cam
            z, vis = observe(K[c], pose, obj, sigma, rng, image_size=None)
            # the corners well inside the image (noise must not push one out)
            vis &= np.all((z > 3) & (z < [636, 476]), axis=1)
            det[c].append((z[vis], obj[vis]) if vis.sum() >= 12 else None)
    return det


def test_three_camera_rig_with_partial_overlap_within_3_sigma():
    rng = np.random.default_rng(21)
    det = _simulate_rig(rng)
    seen = {c: [d is not None for d in det[c]] for c in det}
    # partial overlap: some views are not seen by every camera, some boards partially
    assert not all(all(s) for s in seen.values())
    assert any(d is not None and len(d[0]) < 54 for c in det for d in det[c])
    cal = calibrate_rig(det, (640, 480), "opencv5", sigma=0.3)
    assert cal.result.termination == "convergence"
    rep = cal.report()
    assert not rep.undetermined
    o = cal.problem
    for c in K:
        err = np.abs(o[cal.ids[c]].vec - K[c]) / rep.std(c)
        assert np.all(err < 3), (c, err)
    for c, truth in CAM_FROM_REF.items():
        est = o[cal.ids[f"{c}_from_cam0"]]
        d = np.concatenate([est.pos - truth.pos, (truth.rot.inverse() * est.rot).log()])
        assert np.all(np.abs(d) < 3 * rep.std(f"{c}_from_cam0")), (c, d / rep.std(f"{c}_from_cam0"))
    assert abs(cal.rms() / (0.3 * np.sqrt(2)) - 1) < 0.1


def test_rig_refuses_a_camera_without_shared_views():
    rng = np.random.default_rng(22)
    det = _simulate_rig(rng, n_views=12)
    det["cam3"] = [None] * 6 + det["cam0"][6:]
    for c in ("cam0", "cam1", "cam2"):
        det[c] = det[c][:6] + [None] * 6
    with pytest.raises(ValueError, match="camera.s. cam3 share no view with cam0"):
        calibrate_rig(det, (640, 480))


def test_robust_drops_the_outliers_and_names_them():
    rng = np.random.default_rng(23)
    obj = board_points()
    Z = [observe(TRUE_K, v, obj, 0.3, rng)[0] for v in random_views(10, rng, obj.mean(axis=0))]
    bad = [(2, 5), (7, 40), (7, 41)]
    for v, c in bad:
        Z[v][c] += [6.0, -5.0]
    names = [f"img{i:02d}.png" for i in range(10)]
    plain = calibrate_mono(Z, obj, (640, 480), sigma=0.3)
    cal = calibrate_mono(Z, obj, (640, 480), sigma=0.3, robust=True, view_names=names)
    assert sorted((d.view, d.corner) for d in cal.dropped) == bad
    assert {d.view_name for d in cal.dropped} == {"img02.png", "img07.png"}
    assert all(d.error_px > 5 for d in cal.dropped)
    assert abs(cal.rms() / (0.3 * np.sqrt(2)) - 1) < 0.1 < abs(plain.rms() / (0.3 * np.sqrt(2)) - 1)
    assert sum(len(cal.problem.measurement_errors(m)) for m in cal.view_ids["camera"]) == 540 - 3
    # no outliers: nothing dropped
    clean = calibrate_mono([observe(TRUE_K, v, obj, 0.3, rng)[0]
                            for v in random_views(10, rng, obj.mean(axis=0))], obj, (640, 480),
                           sigma=0.3, robust=True)
    assert clean.dropped == []


def test_projection_uncertainty_equals_monte_carlo():
    """The predicted σ (intrinsics and board poses, mrcal's method) against the
    spread of q̂ − q over repeated calibrations of fresh noise, at 3 pixels."""
    rng = np.random.default_rng(24)
    obj = board_points()
    views = random_views(8, rng, obj.mean(axis=0))
    sigma, dist = 0.5, 0.6
    pix = np.array([[320.0, 240.0], [200.0, 150.0], [450.0, 330.0]])

    def run(seed):
        r = np.random.default_rng(seed)
        return calibrate_mono([observe(TRUE_K, v, obj, sigma, r)[0] for v in views], obj, (640, 480),
                              sigma=sigma)

    from boxplus.calib.models import rays
    ray = rays(TRUE_K, pix, "opencv5")
    p_true = dist * ray / np.linalg.norm(ray, axis=1, keepdims=True)
    errs = []
    for seed in range(40):
        cal = run(1000 + seed)
        o = cal.problem
        pc = np.zeros_like(p_true)
        for i, vid in enumerate(cal.world_from_ref):
            pw = p_true @ views[i].rot.R.T + views[i].pos  # the point fixed in the board frame
            T = o[vid]  # the estimated world_from_cam of view i
            pc += (pw - T.pos) @ T.rot.R
        errs.append(project(o[cal.ids["camera"]].vec, pc / len(views), "opencv5") - pix)
    E = np.array(errs)  # (runs, 3, 2)
    sig = projection_sigma(cal, "camera", pix, dist)
    for j in range(len(pix)):
        emp = np.sqrt(np.linalg.eigvalsh(np.cov(E[:, j].T))[-1])
        pred = sig[j]
        assert 0.7 < emp / pred < 1.35, (j, emp, pred)
    # intrinsics only: a different (larger at the centre) figure, as mrcal explains
    only_k = projection_uncertainty(cal, "camera", dist, poses=False, grid=(5, 5))
    assert only_k.poses is False and np.all(np.isfinite(only_k.sigma))


def test_coverage_counts_every_corner():
    rng = np.random.default_rng(25)
    obj = board_points()
    Z = [observe(TRUE_K, v, obj, 0.3, rng)[0] for v in random_views(6, rng, obj.mean(axis=0))]
    cal = calibrate_mono(Z, obj, (640, 480), sigma=0.3)
    C = coverage(cal, "camera", grid=(8, 6))
    assert C.shape == (6, 8) and C.sum() == 6 * 54
    assert C[0, 0] == sum(np.sum((z[:, 0] < 80) & (z[:, 1] < 80)) for z in Z)


def test_plots_take_an_axes_and_return_the_figure(tmp_path):
    matplotlib = pytest.importorskip("matplotlib")
    backend = matplotlib.get_backend()
    from boxplus.calib import plot
    from matplotlib.figure import Figure

    rng = np.random.default_rng(26)
    cal = calibrate_rig(_simulate_rig(rng, n_views=12), (640, 480), sigma=0.3)
    fig = Figure()
    ax = fig.add_subplot()
    assert plot.plot_rms_per_image(cal.problem, cal.view_ids, ax=ax) is fig
    assert plot.plot_coverage(cal, "cam1", path=tmp_path / "cov.png").savefig is not None
    unc = projection_uncertainty(cal, "cam2", 0.6, grid=(8, 6))
    assert isinstance(plot.plot_projection_uncertainty(unc, path=tmp_path / "u.png"), Figure)
    field = plot.plot_residual_field(cal, "cam0", grid=(4, 3))
    arrows, bins = field.axes[:2]  # then their colour bars
    assert "coloured by length" in arrows.get_title() and "per image region" in bins.get_title()
    # each cell is the RMS length of the errors of the corners that fall in it (4 × 3 cells
    # of 160 × 160 px over 640 × 480)
    z, e = plot._camera_errors(cal, "cam0")
    rms = bins.images[0].get_array()
    cells = {(int(v // 160), int(u // 160)) for u, v in z}
    assert len(cells) >= 3
    for r, c in cells:
        inside = (z[:, 0] // 160 == c) & (z[:, 1] // 160 == r)
        assert rms[r, c] == pytest.approx(np.sqrt(np.mean(np.sum(e[inside] ** 2, axis=1))))
    assert np.nansum([float(tx.get_text()) for tx in bins.texts]) == len(z)
    ax3 = Figure().add_subplot(projection="3d")
    assert plot.plot_rig(frames={"cam0": SE3()}, boards=[(SE3(), board_points())], ax=ax3) is ax3.figure
    assert isinstance(plot.plot_reprojection_errors(cal.problem, tmp_path / "e.png"), Figure)
    for name in ("cov.png", "u.png", "e.png"):
        assert (tmp_path / name).stat().st_size > 1000
    assert matplotlib.get_backend() == backend


def test_double_sphere_reaches_the_truth_from_noise_free_corners():
    # From the pinhole start (ξ = α = 0) alone, the solve stopped at fx 554 (truth 300)
    # and ξ = +0.51 (truth −0.18) on these corners; the further starts find the truth.
    k = np.array([300.0, 300.0, 320.0, 240.0, -0.18, 0.59])
    rng = np.random.default_rng(0)
    p = board_points()
    z = []
    while len(z) < 20:
        v = random_views(1, rng, p.mean(axis=0), distance=0.35, spread=0.9, roll=1.0)[0]
        pc = np.stack([v.tolocal(q) for q in p])
        uv = project(k, pc, "double_sphere")
        if np.all(pc[:, 2] > 0) and np.all((uv > 5) & (uv < [635, 475])):
            z.append(uv)
    cal = calibrate_mono(z, p, (640, 480), model="double_sphere", sigma=0.2)
    np.testing.assert_allclose(cal.problem[cal.ids["camera"]].vec, k, rtol=1e-6, atol=1e-6)
    assert cal.rms() < 1e-6


def test_a_model_that_folds_over_inside_the_calibrated_field_is_named():
    import warnings

    import boxplus as bp
    from boxplus.calib.fold import LensFoldWarning, check_fold_over, fold_angle, observed_field

    # ρ ∝ r (1 + k1 r²) turns back where 1 + 3 k1 r² = 0: r = 0.816, θ = 39.2° for k1 = −0.5
    k = np.array([500.0, 500.0, 320.0, 240.0, -0.5, 0.0, 0.0, 0.0, 0.0])
    assert np.degrees(fold_angle(k, "opencv5", np.radians(60))) == pytest.approx(39.2, abs=0.2)
    assert fold_angle(k, "opencv5", np.radians(35)) is None
    assert fold_angle(TRUE_K, "opencv5", np.radians(60)) is None
    rng = np.random.default_rng(2)
    p = board_points()
    z = [observe(TRUE_K, v, p, 0.3, rng)[0] for v in random_views(8, rng, p.mean(axis=0))]
    with warnings.catch_warnings():
        warnings.simplefilter("error", LensFoldWarning)  # a good fit does not fold
        cal = calibrate_mono(z, p, (640, 480), sigma=0.3)
    field = observed_field(cal, "camera")
    assert np.radians(15) < field < np.radians(60)
    # the same views with a model that turns back at 0.6 of the field
    r = np.tan(0.6 * field)
    folding = np.array([500.0, 500.0, 320.0, 240.0, -1 / (3 * r * r), 0, 0, 0, 0])
    cal.problem.set_value(cal.ids["camera"], bp.Rn(folding))
    with pytest.warns(LensFoldWarning, match=r"camera: the fitted opencv5 model folds over at "):
        assert len(check_fold_over(cal)) == 1


def test_the_report_is_computed_once_per_state_of_the_problem():
    # projection_uncertainty of every camera and the printed report share one report
    # (one normal matrix, one rank test) until the problem changes
    rng = np.random.default_rng(31)
    cal = calibrate_rig(_simulate_rig(rng, n_views=8), (640, 480), sigma=0.3)
    first = cal.report(rescale=True)
    assert cal.report(rescale=True) is first
    assert cal.report() is not first and cal.report() is cal.report()
    projection_uncertainty(cal, "cam1", 0.6, grid=(4, 3), rescale=True)
    assert cal.report(rescale=True) is first
    cal.problem.set_value(cal.ids["cam1"], Rn(cal.problem[cal.ids["cam1"]].vec * 1.001))
    again = cal.report(rescale=True)
    assert again is not first
    assert not np.allclose(again.std("cam1"), first.std("cam1"), rtol=0, atol=0)
