"""Synthetic rigs with known ground truth for the calibration workflows in
examples/: the estimates lie within 3σ of the truth (σ as boxplus reports it),
at several noise levels; undeterminable parameters are named."""

import importlib.util
import sys
from pathlib import Path

import boxplus as bp
import numpy as np
import pytest
from boxplus.calib import report

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _example(name):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod


def _within(est, truth, std, k=3.0, what=""):
    err = np.abs(np.asarray(est) - np.asarray(truth))
    assert np.all(err < k * np.asarray(std)), f"{what}: |error|/σ = {err / std}"


def _pose_within(o, rep, vid, truth, what):
    est = o[vid]
    d = np.concatenate([est.pos - truth.pos, (truth.rot.inverse() * est.rot).log()])
    std = rep.std(o.variable_name(vid))
    _within(d, 0, std, what=what)


@pytest.mark.parametrize("noise", [0.2, 0.5, 1.0])
def test_camera_imu_within_3_sigma(noise):
    ex = _example("camera_imu_calibration")
    data = ex.simulate(np.random.default_rng(int(noise * 10)), pixel_sigma=noise)
    o, ids, result = ex.calibrate(data)
    assert result.usable
    rep = report(o)
    assert not rep.undetermined
    _within(o[ids["camera"]].vec, ex.TRUTH["k"], rep.std("camera"), what="intrinsics")
    _pose_within(o, rep, ids["imu_from_cam"], ex.TRUTH["imu_from_cam"], "imu_from_cam")
    _within(o[ids["accel"]].vec, ex.TRUTH["accel"], rep.std("accel"), what="accel")
    assert abs(rep.rms["camera"] / (np.sqrt(2) * noise) - 1) < 0.15


def test_imu_yaw_from_one_gravity_reading_is_named_undetermined():
    ex = _example("camera_imu_calibration")
    data = ex.simulate(np.random.default_rng(1))
    with pytest.warns(bp.UndeterminedWarning, match="'imu_from_cam': .*θ.z"):
        o, ids, _ = ex.calibrate(data, gravity_views=[0], estimate_accel=False)
    rep = report(o)
    named = {n for _, names in rep.undetermined for n in names}
    assert any(n.startswith("imu_from_cam.θ") for n in named), rep.warnings
    assert any("NOT DETERMINED" in w for w in rep.warnings)
    assert np.isinf(rep.std("imu_from_cam")[3:]).any()


def test_hand_eye_ml_beats_every_opencv_closed_form():
    pytest.importorskip("cv2")
    ex = _example("hand_eye_calibration")
    rms = ex.compare(trials=8, seed=3)
    ml = rms.pop("boxplus ML")
    assert len(rms) == 7  # 5 calibrateHandEye + 2 calibrateRobotWorldHandEye methods
    for name, (et, _er) in rms.items():
        assert ml[0] <= et, f"{name}: translation {et} < boxplus {ml[0]}"
    assert ml[0] < 0.75 * min(et for et, _ in rms.values())


@pytest.mark.parametrize("noise", [0.3, 1.0])
def test_hand_eye_within_3_sigma(noise):
    ex = _example("hand_eye_calibration")
    o, ids, X = ex.calibrate(ex.simulate(np.random.default_rng(5), pixel_sigma=noise))
    rep = report(o)
    assert not rep.undetermined
    _pose_within(o, rep, ids["cam_from_gripper"], ex.TRUTH["gripper_from_cam"].inverse(), "cam_from_gripper")
    _pose_within(o, rep, ids["board_from_base"], ex.TRUTH["base_from_board"].inverse(), "board_from_base")


def test_figures_are_written(tmp_path):
    from boxplus.calib.plot import plot_reprojection_errors, plot_rig

    ex = _example("camera_imu_calibration")
    data = ex.simulate(np.random.default_rng(2), n_views=4)
    o, ids, _ = ex.calibrate(data)
    plot_reprojection_errors(o, str(tmp_path / "errors.png"))
    frames = {"imu": o[ids["imu_from_cam"]].inverse()}
    frames.update({f"cam{i}": o[v] for i, v in enumerate(range(o.num_variables))
                   if o.variable_name(v).startswith("world_from_cam")})
    plot_rig(str(tmp_path / "rig.png"), frames, [(bp.SE3(), data["p_in_world"])],
             {"marker": np.zeros((1, 3))}, length=0.05)
    for f in ("errors.png", "rig.png"):
        assert (tmp_path / f).read_bytes()[:4] == b"\x89PNG"


def _max_z_and_rms(ex, o, rep, ids):
    z = np.concatenate(list(ex.errors_in_sigma(o, rep, ids).values()))
    return z.max(), np.sqrt(np.mean(z**2))


# Seeds are fixed; with ~45–90 parameters a 3σ bound per parameter is exceeded by
# chance in some data sets (a 20-seed Monte Carlo of the known-kinematics head at
# 0.5 px: 5 of 20 had max |error|/σ in 3.0–3.3, RMS of error/σ 0.8–1.4 per
# parameter). The RMS check guards against σ that are merely loose.
@pytest.mark.parametrize("kinematics", ["known", "dh"])
@pytest.mark.parametrize("noise", [0.3, 1.0])
def test_humanoid_head_within_3_sigma(kinematics, noise):
    ex = _example("humanoid_head_calibration")
    data = ex.simulate(np.random.default_rng(1), pixel_sigma=noise)
    o, ids, result = ex.calibrate(data, kinematics)
    assert result.usable
    rep = report(o)
    assert not rep.undetermined, rep.warnings
    zmax, zrms = _max_z_and_rms(ex, o, rep, ids)
    assert zmax < 3.0, ex.errors_in_sigma(o, rep, ids)
    assert 0.6 < zrms < 1.5
    for g in ("board left", "board right"):
        assert abs(rep.rms[g] / (np.sqrt(2) * noise) - 1) < 0.15
    for g in ("marker l", "marker r"):
        assert abs(rep.rms[g] / (np.sqrt(2) * 2 * noise) - 1) < 0.3
    if kinematics == "dh":  # the markers tighten the CAD prior of most DH parameters
        ratio = rep.std("dh_l") / ex.DH_SIGMA
        assert np.sum(ratio < 0.7) >= 10, ratio


def test_humanoid_head_dh_without_prior_names_the_redundant_last_link():
    ex = _example("humanoid_head_calibration")
    data = ex.simulate(np.random.default_rng(1), pixel_sigma=0.5)
    with pytest.warns(bp.UndeterminedWarning, match="'dh_l': .*d6"):
        o, ids, _ = ex.calibrate(data, "dh", dh_prior=False)
    rep = report(o)
    named = {n for _, names in rep.undetermined for n in names}
    # the last link's [θ6, d6, a6, α6] and the marker on the hand are one point: redundant
    assert {"dh_l.d6", "dh_r.d6"} <= named and any(n.startswith("p_hand_l") for n in named)
    assert not any(n.startswith(("left.", "right.", "head_from_left")) for n in named)


def test_triangulate_and_marker_hand_eye_are_exact_without_noise():
    from boxplus.calib import marker_hand_eye, triangulate
    from boxplus.calib.models import project
    from boxplus.synthetic.cameras import TRUE_K

    rng = np.random.default_rng(0)
    b_from_a = bp.SE3(bp.SO3.exp(np.array([0.01, -0.02, 0.03])), [-0.1, 0.002, 0.001])
    P = rng.uniform([-0.2, -0.2, 0.4], [0.2, 0.2, 0.9], (20, 3))
    z_a, z_b = project(TRUE_K, P), project(TRUE_K, b_from_a.fromlocal(P))
    np.testing.assert_allclose(triangulate(z_a, z_b, TRUE_K, TRUE_K, b_from_a), P, atol=1e-9)

    base_from_rig = bp.SE3(bp.SO3.exp(np.array([1.0, -0.5, 0.3])), [0.1, 0.05, 0.2])
    p_hand = [np.array([0.02, 0.05, 0.1]), np.array([-0.03, 0.01, 0.07])]
    poses = [[bp.SE3(bp.SO3.exp(rng.normal(0, 1, 3)), rng.normal(0, 0.3, 3)) for _ in range(8)]
             for _ in p_hand]
    p_in_rig = [base_from_rig.tolocal(np.array([H.fromlocal(p) for H in hs])) for p, hs in zip(p_hand, poses)]
    X, (p0, p1) = marker_hand_eye(p_in_rig, poses)
    np.testing.assert_allclose(X.matrix(), base_from_rig.matrix(), atol=1e-9)
    np.testing.assert_allclose(p0, p_hand[0], atol=1e-9)
    np.testing.assert_allclose(p1, p_hand[1], atol=1e-9)


@pytest.mark.parametrize("noise", [0.3, 1.0])
def test_rgbd_within_3_sigma(noise):
    ex = _example("rgbd_calibration")
    data = ex.simulate(np.random.default_rng(1), pixel_sigma=noise)
    o, ids, result = ex.calibrate(data)
    assert result.usable
    rep = report(o)
    assert not rep.undetermined, rep.warnings
    zmax, zrms = _max_z_and_rms(ex, o, rep, ids)
    assert zmax < 3.0, ex.errors_in_sigma(o, rep, ids)
    assert 0.5 < zrms < 1.5
    for g in ("rgb", "ir"):
        assert abs(rep.rms[g] / (np.sqrt(2) * noise) - 1) < 0.15
    assert abs(rep.rms["disparity"] / noise - 1) < 0.15


# Seed 0 (the example's default). Seed 1 puts bottom.cx at 3.3σ at both noise levels:
# in a 30-seed Monte Carlo at 0.5 px, 1 of 30 data sets exceeded 3σ somewhere
# (test_vertical_stereo_sigma_is_calibrated checks the σ themselves).
@pytest.mark.parametrize("noise", [0.3, 1.0])
def test_vertical_stereo_within_3_sigma(noise):
    ex = _example("vertical_stereo_calibration")
    data = ex.simulate(np.random.default_rng(0), pixel_sigma=noise)
    # each camera sees only part of the board in every stereo pair
    assert all(s["vis_top"].mean() < 0.7 and s["vis_bottom"].mean() < 0.7 for s in data["stereo"])
    o, ids, result = ex.calibrate(data)
    assert result.usable
    rep = report(o)
    assert not rep.undetermined, rep.warnings
    zmax, zrms = _max_z_and_rms(ex, o, rep, ids)
    assert zmax < 3.0, ex.errors_in_sigma(o, rep, ids)
    assert 0.4 < zrms < 1.6
    assert abs(rep.rms["stereo top"] / (np.sqrt(2) * noise) - 1) < 0.15


def test_vertical_stereo_is_worse_determined_without_the_mono_images():
    ex = _example("vertical_stereo_calibration")
    data = ex.simulate(np.random.default_rng(2), pixel_sigma=0.5)
    with_mono, without = (report(ex.calibrate(data, use_mono=m)[0]) for m in (True, False))
    for cam in ("top", "bottom"):
        ratio = without.std(cam) / with_mono.std(cam)
        assert np.all(ratio > 1.0) and ratio.max() > 1.5, ratio  # every intrinsic, focal ×1.5+
    assert without.condition > 1.5 * with_mono.condition


def test_vertical_stereo_sigma_is_calibrated():
    """Over 10 data sets the errors divided by the reported σ have an RMS near 1."""
    ex = _example("vertical_stereo_calibration")
    Z = []
    for seed in range(10):
        o, ids, _ = ex.calibrate(ex.simulate(np.random.default_rng(100 + seed), pixel_sigma=0.5))
        Z.append(np.concatenate(list(ex.errors_in_sigma(o, report(o), ids).values())))
    assert 0.8 < np.sqrt(np.mean(np.square(Z))) < 1.2


def test_calibrate_mono_refuses_views_of_one_orientation():
    """Issue 17 item 14: four identical views gave fx = 1262 ± 157 (truth 520) without
    a word. Views of the board in one orientation do not determine the intrinsics:
    calibrate_mono names them and refuses."""
    from boxplus.calib import calibrate_mono
    from boxplus.synthetic.cameras import TRUE_K, board_points, observe, random_views

    rng = np.random.default_rng(3)
    p = board_points()
    centre = p.mean(axis=0)
    views = random_views(2, rng, centre)
    z, vis = observe(TRUE_K, views[0], p, 0.3, rng, image_size=None)
    with pytest.raises(ValueError, match=r"camera: the board has the same orientation .* \(0, 1, 2, 3\)"):
        calibrate_mono([z] * 4, p, (640, 480))
    # A second orientation among repeated views is enough (zero skew): fx within 3σ.
    Z2 = [z, z, observe(TRUE_K, views[1], p, 0.3, rng, image_size=None)[0]]
    cal = calibrate_mono(Z2, p, (640, 480))
    k = cal.problem[cal.ids["camera"]].vec
    std = cal.report().std("camera")
    _within(k, TRUE_K, std, what="intrinsics")
