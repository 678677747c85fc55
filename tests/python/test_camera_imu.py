"""Camera–IMU calibration in motion (#28): the spline trajectory, the gyroscope,
accelerometer and reprojection terms with a time offset, several cameras, rolling
shutters and several IMUs, on simulated recordings with known truth (the true
trajectory a spline on the same knot grid, or a sum of sinusoids no spline follows
exactly)."""

import warnings

import numpy as np
import pytest
from boxplus import SE3, SO3
from boxplus.calib.camera_imu import CameraFrames, CameraImuData, ImuSamples, calibrate_camera_imu
from boxplus.synthetic.camera_imu import SimulatedCamera, SimulatedImu, simulate_camera_imu


@pytest.mark.parametrize("seed, offset", [(0, 0.007), (1, -0.031)])
def test_recovers_extrinsics_time_offset_biases_and_gravity_within_their_sigma(seed, offset):
    rng = np.random.default_rng(seed)
    ic = SE3(SO3.exp(np.array([0.1, -0.05, 1.2])), np.array([0.05, 0.02, -0.03]))
    data, truth, K = simulate_camera_imu(rng, time_offset=offset, imu_from_cam=ic)
    cal = calibrate_camera_imu(data, K, "pinhole", pixel_sigma=0.3, gyro_sigma=0.005, accel_sigma=0.05)
    assert cal.summary.termination == "convergence"
    # the start needs no hand tuning: aligning the angular velocities places the offset
    # within a few ms (finite differences of 20 Hz poses), the solve does the rest
    assert abs(cal.initial["time_offset"] - offset) < 5e-3
    # the user's quantities, against the truth
    err = np.r_[cal.imu_from_cam.pos - ic.pos, (ic.rot.inverse() * cal.imu_from_cam.rot).log()]
    assert np.linalg.norm(err[:3]) < 2e-3          # metres
    assert np.degrees(np.linalg.norm(err[3:])) < 0.1
    assert abs(cal.time_offset - offset) < 2e-4     # seconds
    # and within their σ
    assert np.all(np.abs(err) < 4 * cal.std("imu_from_cam"))
    assert abs(cal.time_offset - offset) < 4 * cal.std("time_offset")[0]
    assert np.all(np.abs(cal.gyro_bias - truth["gyro_bias"]) < 4 * cal.std("gyro_bias"))
    assert np.all(np.abs(cal.accel_bias - truth["accel_bias"]) < 4 * cal.std("accel_bias"))
    assert np.linalg.norm(cal.gravity - truth["gravity"]) < 0.05
    # the residuals are the noise that went in
    rms = cal.problem.rms()
    assert rms["gyroscope"] == pytest.approx(0.005 * np.sqrt(3), rel=0.1)
    assert rms["accelerometer"] == pytest.approx(0.05 * np.sqrt(3), rel=0.1)
    assert rms["reprojection"] == pytest.approx(0.3 * np.sqrt(2), rel=0.1)


def test_bad_recordings_are_refused_with_the_reason():
    rng = np.random.default_rng(2)
    data, _, K = simulate_camera_imu(rng, duration=3.0)
    few = CameraImuData(data.frame_times[:5], data.corners[:5], data.imu_times, data.gyro, data.accel)
    with pytest.raises(ValueError, match="5 frames with the target; need at least 10"):
        calibrate_camera_imu(few, K)
    back = CameraImuData(data.frame_times, data.corners, data.imu_times[::-1], data.gyro, data.accel)
    with pytest.raises(ValueError, match="IMU times must increase"):
        calibrate_camera_imu(back, K)
    with pytest.raises(ValueError, match="pinhole has 4 intrinsics, got 3"):
        calibrate_camera_imu(data, K[:3])
    # clocks 0.5 s apart, beyond max_offset: a loud failure, not a silently wrong answer
    late = CameraImuData(data.frame_times, data.corners, data.imu_times + 0.5, data.gyro, data.accel)
    with pytest.raises(ValueError, match="did not reach a plausible answer.*timestamps"):
        calibrate_camera_imu(late, K, pixel_sigma=0.3)


def test_angular_velocity_is_what_the_gyroscope_term_predicts():
    rng = np.random.default_rng(4)
    data, truth, K = simulate_camera_imu(rng, duration=4.0)
    cal = calibrate_camera_imu(data, K, pixel_sigma=0.3)
    # the gyroscope term's error is ω_imu(t) + b_g − z, one row per sample the spline covers
    e = cal.problem.errors()["gyroscope"]
    covered = [i for i, t in enumerate(data.imu_times)
               if cal.t0 <= t < cal.t0 + (cal.n_knots - 3) * cal.knot_spacing]
    assert len(covered) == len(e)
    predicted = np.array([cal.angular_velocity(data.imu_times[i]) for i in covered]) + cal.gyro_bias
    np.testing.assert_allclose(predicted - data.gyro[covered], e, atol=1e-9)
    # and near the truth's body rate (the noise is 0.005 rad/s per sample)
    assert np.sqrt(np.mean((predicted - data.gyro[covered]) ** 2)) < 0.007


def test_drifting_biases_are_followed_when_the_random_walks_are_given():
    # Biases that drift as Wiener processes (Kalibr's random-walk densities, strong here:
    # over 8 s about 6e-3 rad/s and 0.1 m/s²). Held constant they make σ overconfident
    # (on 10 seeds the worst direction of imu_from_cam sat 6.3σ off, median); with the
    # random walks (bias segments of 0.1 s, the default chosen on those seeds: 0.5 s gave
    # 2.0σ, 0.25 s 1.5σ, 0.1 s 1.3σ) the errors are within their σ and the bias track
    # follows the truth.
    grw, arw = 2e-3, 4e-2
    rng = np.random.default_rng(101)
    ic = SE3(SO3.exp(np.array([0.4, -1.1, 0.3])), np.array([0.03, -0.02, 0.05]))
    data, truth, K = simulate_camera_imu(rng, imu_from_cam=ic, gyro_random_walk=grw,
                                         accel_random_walk=arw)
    cal = calibrate_camera_imu(data, K, pixel_sigma=0.3, gyro_random_walk=grw, accel_random_walk=arw)
    err = np.r_[cal.imu_from_cam.pos - ic.pos, (ic.rot.inverse() * cal.imu_from_cam.rot).log()]
    assert np.all(np.abs(err) < 4 * cal.std("imu_from_cam"))
    assert abs(cal.time_offset - truth["time_offset"]) < 4 * cal.std("time_offset")[0]
    assert len(cal.gyro_biases) == len(cal.bias_times) - 1 >= 70
    # each segment's bias against the truth's mean over that segment
    k = np.clip(np.searchsorted(cal.bias_times, data.imu_times, side="right") - 1, 0,
                len(cal.gyro_biases) - 1)
    for s in (5, len(cal.gyro_biases) // 2, len(cal.gyro_biases) - 5):
        true_g = truth["gyro_bias_track"][k == s].mean(axis=0)
        true_a = truth["accel_bias_track"][k == s].mean(axis=0)
        assert np.all(np.abs(cal.gyro_biases[s] - true_g) < 4 * cal.std(f"gyro_bias[{s}]"))
        assert np.all(np.abs(cal.accel_biases[s] - true_a) < 4 * cal.std(f"accel_bias[{s}]"))
    # the drift is real: the first and last segments differ by more than their σ allows
    assert np.any(np.abs(cal.accel_biases[-1] - cal.accel_biases[0]) > 4 * cal.std("accel_bias[0]"))
    with pytest.raises(ValueError, match="give both random walks"):
        calibrate_camera_imu(data, K, gyro_random_walk=grw)


def test_a_rig_of_two_cameras_and_an_imu_on_one_trajectory():
    # A pinhole camera and a Kannala–Brandt fisheye 15 cm beside it, turned 20° away,
    # each with its own clock (offsets +7 and −15 ms, frames 21 ms apart): one spline,
    # one set of biases and gravity, and per camera imu_from_cam and its time offset.
    rng = np.random.default_rng(0)
    ic0 = SE3(SO3.exp(np.array([0.1, -0.05, 1.2])), np.array([0.05, 0.02, -0.03]))
    ic1 = ic0 * SE3(SO3.exp(np.array([0.0, 0.35, 0.0])), np.array([0.15, 0.01, 0.0]))
    kb = np.array([230.0, 230.0, 320.0, 240.0, 0.01, -0.005, 0.001, 0.0])
    data, truth, K = simulate_camera_imu(rng, time_offset=0.007, imu_from_cam=ic0, other_cameras=[
        SimulatedCamera(ic1, -0.015, "kannala_brandt", kb, phase=0.021, name="fisheye")])
    cal = calibrate_camera_imu(data, [K, kb], ["pinhole", "kannala_brandt"], pixel_sigma=0.3)
    assert cal.summary.termination == "convergence"
    assert cal.camera_names == ["cam0", "fisheye"]
    for c in range(2):
        true_ic, est = truth["imu_from_cams"][c], cal.imu_from_cams[c]
        err = np.r_[est.pos - true_ic.pos, (true_ic.rot.inverse() * est.rot).log()]
        assert np.all(np.abs(err) < 4 * cal.std(f"imu_from_cam[{c}]")), c
        assert np.linalg.norm(err[:3]) < 2e-3 and np.degrees(np.linalg.norm(err[3:])) < 0.1
        d = cal.time_offsets[c] - truth["time_offsets"][c]
        assert abs(d) < 4 * cal.std(f"time_offset[{c}]")[0] and abs(d) < 2e-4
    assert cal.imu_from_cam is cal.imu_from_cams[0] and cal.time_offset == cal.time_offsets[0]
    # the rig's own extrinsics (Kalibr's T_cn_cnm1) and their σ from the joint covariance
    true_rel = truth["imu_from_cams"][1].inverse() * truth["imu_from_cams"][0]
    sigma = cal.cam_from_cam_std(1)
    assert np.all(np.abs(cal.cam_from_cam(1) - true_rel) < 4 * sigma)
    assert np.all(sigma[:3] < 2e-4) and np.all(sigma[:3] > 1e-6)
    rms = cal.problem.rms()
    assert rms["reprojection fisheye"] == pytest.approx(0.3 * np.sqrt(2), rel=0.1)
    # cameras triggered together share one offset: one variable, one σ
    same, truth2, _ = simulate_camera_imu(np.random.default_rng(1), duration=5.0, imu_from_cam=ic0,
                                          other_cameras=[SimulatedCamera(ic1, 0.007)])
    one = calibrate_camera_imu(same, [K, K], pixel_sigma=0.3, common_clock=True)
    assert one.ids["time_offset[1]"] == one.ids["time_offset"]
    assert one.time_offsets[0] == one.time_offsets[1]
    assert abs(one.time_offset - 0.007) < 4 * one.std("time_offset")[0]
    assert "imu_from_cam[1]" in one.todict()["std"]
    # each camera's failures name it
    few = CameraImuData(data.frame_times, data.corners, data.imu_times, data.gyro, data.accel,
                        [CameraFrames(data.other_cameras[0].frame_times[:5],
                                      data.other_cameras[0].corners[:5], "fisheye")])
    with pytest.raises(ValueError, match="5 frames with the target in camera fisheye"):
        calibrate_camera_imu(few, [K, kb], ["pinhole", "kannala_brandt"])
    with pytest.raises(ValueError, match="camera fisheye: pinhole has 4 intrinsics, got 8"):
        calibrate_camera_imu(data, [K, kb])
    with pytest.raises(ValueError, match="2 cameras .*one intrinsics vector per camera"):
        calibrate_camera_imu(data, K)


def test_a_rolling_shutter_is_modelled_and_named_when_it_is_not():
    # Rows read 30 µs apart (14 ms for 480 rows) while the rig swings: fitted as a global
    # shutter the answer is plausible but wrong (the offset moves by about half the
    # readout, imu_from_cam by millimetres) and the warning says what may be missing;
    # with rolling_shutter=True the line delay is estimated and everything is within σ.
    rng = np.random.default_rng(0)
    ic = SE3(SO3.exp(np.array([0.1, -0.05, 1.2])), np.array([0.05, 0.02, -0.03]))
    data, truth, K = simulate_camera_imu(rng, time_offset=0.007, imu_from_cam=ic, line_delay=30e-6)
    assert truth["line_delays"] == [30e-6]
    with pytest.warns(UserWarning, match=r"reprojection RMS .* px is .*× what pixel_sigma = 0.3 px "
                                         r"predicts.*rolling_shutter=True"):
        wrong = calibrate_camera_imu(data, K, pixel_sigma=0.3)
    assert abs(wrong.time_offset - 0.007) > 3e-3 and wrong.line_delays == [None]
    cal = calibrate_camera_imu(data, K, pixel_sigma=0.3, rolling_shutter=True)
    err = np.r_[cal.imu_from_cam.pos - ic.pos, (ic.rot.inverse() * cal.imu_from_cam.rot).log()]
    assert np.all(np.abs(err) < 4 * cal.std("imu_from_cam"))
    assert abs(cal.time_offset - 0.007) < 4 * cal.std("time_offset")[0]
    ell, sigma = cal.line_delays[0], cal.std("line_delay")[0]
    assert abs(ell - 30e-6) < 4 * sigma and abs(ell - 30e-6) < 1e-6
    assert cal.problem.rms()["reprojection"] == pytest.approx(0.3 * np.sqrt(2), rel=0.1)
    assert "line_delay[0]" in cal.todict()["std"]


def test_a_second_imu_is_placed_by_its_lever_arm_and_rotation():
    # A second IMU 10 cm from the first, turned, sampled half a period later on the same
    # clock: it reads the body's rotation in its own axes and its own position's
    # acceleration (the lever arm's α × r + ω × (ω × r)); its pose in the first IMU's
    # frame and its biases come out within σ and within a millimetre / 0.05°.
    rng = np.random.default_rng(0)
    ic = SE3(SO3.exp(np.array([0.1, -0.05, 1.2])), np.array([0.05, 0.02, -0.03]))
    i01 = SE3(SO3.exp(np.array([0.3, -1.2, 0.5])), np.array([0.08, -0.03, 0.05]))
    bg, ba = np.array([0.02, 0.01, -0.01]), np.array([0.2, -0.1, 0.05])
    data, truth, K = simulate_camera_imu(rng, time_offset=0.007, imu_from_cam=ic,
                                         other_imus=[SimulatedImu(i01, bg, ba, phase=0.0025)])
    cal = calibrate_camera_imu(data, K, pixel_sigma=0.3)
    assert cal.imu_names == ["imu0", "imu1"] and truth["imu0_from_imus"][1] is i01
    est = cal.imu0_from_imus[1]
    err = np.r_[est.pos - i01.pos, (i01.rot.inverse() * est.rot).log()]
    assert np.all(np.abs(err) < 4 * cal.std("imu0_from_imu[1]"))
    assert np.linalg.norm(err[:3]) < 1e-3 and np.degrees(np.linalg.norm(err[3:])) < 0.05
    assert np.all(np.abs(cal.imu_gyro_biases[1] - bg) < 4 * cal.std("imu_gyro_bias[1]"))
    assert np.all(np.abs(cal.imu_accel_biases[1] - ba) < 4 * cal.std("imu_accel_bias[1]"))
    rms = cal.problem.rms()
    assert rms["accelerometer imu1"] == pytest.approx(0.05 * np.sqrt(3), rel=0.1)
    assert "imu0_from_imu[1]" in cal.todict()["std"]
    # the camera's calibration is as good as with one IMU
    err0 = np.r_[cal.imu_from_cam.pos - ic.pos, (ic.rot.inverse() * cal.imu_from_cam.rot).log()]
    assert np.all(np.abs(err0) < 4 * cal.std("imu_from_cam"))
    late = CameraImuData(data.frame_times, data.corners, data.imu_times, data.gyro, data.accel,
                         other_imus=[ImuSamples(data.other_imus[0].imu_times + 100.0, data.other_imus[0].gyro,
                                                data.other_imus[0].accel, "late")])
    with pytest.raises(ValueError, match="IMU late: 0 samples inside the spline's time span"):
        calibrate_camera_imu(late, K, pixel_sigma=0.3)


def test_a_second_imu_on_its_own_clock_gets_its_time_offset():
    # The second IMU's clock runs 4 ms behind the first one's (Kalibr estimates such an
    # offset per IMU): started from the alignment of the two gyroscopes, the offset comes
    # out within σ and 0.2 ms, its pose as on a shared clock; on one clock (the earlier
    # test's rig) the estimate is 0 within σ.
    rng = np.random.default_rng(1)
    i01 = SE3(SO3.exp(np.array([0.3, -1.2, 0.5])), np.array([0.08, -0.03, 0.05]))
    data, truth, K = simulate_camera_imu(rng, time_offset=0.007,
                                         other_imus=[SimulatedImu(i01, phase=0.0025, time_offset=0.004)])
    assert truth["imu_time_offsets"] == [0.0, 0.004]
    cal = calibrate_camera_imu(data, K, pixel_sigma=0.3)
    d, s = cal.imu_time_offsets[1], cal.std("imu_time_offset[1]")[0]
    assert abs(d - 0.004) < max(4 * s, 1e-5) and abs(d - 0.004) < 2e-4 and s < 1e-4
    est = cal.imu0_from_imus[1]
    err = np.r_[est.pos - i01.pos, (i01.rot.inverse() * est.rot).log()]
    assert np.all(np.abs(err) < 4 * cal.std("imu0_from_imu[1]"))
    assert "imu_time_offset[1]" in cal.todict()["std"]
    # told that the clocks are one, the fit has no offset to estimate and the second IMU's
    # residuals show the 4 ms it cannot explain
    shared = calibrate_camera_imu(data, K, pixel_sigma=0.3, imu_time_offsets=False)
    assert shared.imu_time_offsets == [0.0, 0.0] and "imu_time_offset[1]" not in shared.ids
    assert shared.problem.rms()["gyroscope imu1"] > 1.2 * cal.problem.rms()["gyroscope imu1"]


def test_the_knot_spacing_follows_a_motion_faster_than_the_default_spline():
    # A rig waved at up to 3 Hz (no spline: sums of sinusoids): a spline with knots every
    # 50 ms cannot follow it (IMU residuals 8× the noise, or a refused fit); the default
    # halves the spacing until the IMU residuals are the noise, and the answer is within σ.
    from boxplus.calib.camera_imu import _imu_misfit

    ic = SE3(SO3.exp(np.array([0.1, -0.05, 1.2])), np.array([0.05, 0.02, -0.03]))
    data, truth, K = simulate_camera_imu(np.random.default_rng(0), duration=5.0, imu_from_cam=ic,
                                         motion="sines", bandwidth=3.0)
    coarse = calibrate_camera_imu(data, K, pixel_sigma=0.3, knot_spacing=0.05)
    assert _imu_misfit(coarse, 0.005, 0.05) > 5
    cal = calibrate_camera_imu(data, K, pixel_sigma=0.3)
    assert cal.knot_spacing < 0.05 and _imu_misfit(cal, 0.005, 0.05) < 1.5
    err = np.r_[cal.imu_from_cam.pos - ic.pos, (ic.rot.inverse() * cal.imu_from_cam.rot).log()]
    assert np.all(np.abs(err) < 4 * cal.std("imu_from_cam"))
    assert abs(cal.time_offset - truth["time_offset"]) < 4 * cal.std("time_offset")[0]
    # a slow motion keeps the 50 ms knots
    slow, _, _ = simulate_camera_imu(np.random.default_rng(0), duration=5.0, imu_from_cam=ic,
                                     motion="sines", bandwidth=1.0)
    assert calibrate_camera_imu(slow, K, pixel_sigma=0.3).knot_spacing == 0.05


def test_a_direction_the_motion_did_not_excite_is_named():
    # The rig turned almost only about the camera's x axis: the translation of
    # imu_from_cam along x is seen through no rotation and is known to centimetres
    # (σ says so, and the warning names the axis); turned about every axis, no warning.
    ic = SE3(SO3.exp(np.array([0.1, -0.05, 1.2])), np.array([0.05, 0.02, -0.03]))
    data, truth, K = simulate_camera_imu(np.random.default_rng(0), duration=6.0, imu_from_cam=ic,
                                         rotation_scale=(1.0, 0.02, 0.02))
    with pytest.warns(UserWarning, match=r"camera cam0: imu_from_cam's translation along \(\+(1\.00|0\.9\d), "
                                         r".*hardly rotated about that axis"):
        cal = calibrate_camera_imu(data, K, pixel_sigma=0.3)
    err = cal.imu_from_cam.pos - ic.pos
    assert np.all(np.abs(err) < 4 * cal.std("imu_from_cam")[:3])  # σ is honest about it
    assert cal.std("imu_from_cam")[:3].max() > 5e-3
    data, _, _ = simulate_camera_imu(np.random.default_rng(0), duration=6.0, imu_from_cam=ic)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        calibrate_camera_imu(data, K, pixel_sigma=0.3)


def test_the_imus_scale_and_misalignment():
    # An IMU whose gyroscope reads 2 % high on x and 1.5 % low on z, with misalignments of
    # 3–6 mrad, and whose accelerometer has its own: with imu_intrinsics both matrices
    # come out within 4σ and 0.3 %, the extrinsics within 4σ, the gyroscope's residuals at
    # the noise.
    rng = np.random.default_rng(2)
    Mg = np.array([[1.02, 0, 0], [0.004, 0.995, 0], [-0.006, 0.003, 0.985]])
    Ma = np.array([[0.99, 0, 0], [0.005, 1.01, 0], [0.002, -0.004, 1.005]])
    data, truth, K = simulate_camera_imu(rng, time_offset=0.007, gyro_intrinsics=Mg, accel_intrinsics=Ma)
    cal = calibrate_camera_imu(data, K, pixel_sigma=0.3, imu_intrinsics=True)
    for kind, M in (("gyro_intrinsics", Mg), ("accel_intrinsics", Ma)):
        est = getattr(cal, kind)
        truth_vec = np.r_[np.diag(M), M[1, 0], M[2, 0], M[2, 1]]
        err = cal.problem[cal.ids[kind]].vec - truth_vec
        assert np.all(np.abs(err) < 4 * cal.std(kind)), (kind, err, cal.std(kind))
        assert np.abs(err).max() < 3e-3 and np.allclose(np.triu(est, 1), 0)
    err0 = np.r_[cal.imu_from_cam.pos - truth["imu_from_cam"].pos,
                 (truth["imu_from_cam"].rot.inverse() * cal.imu_from_cam.rot).log()]
    assert np.all(np.abs(err0) < 4 * cal.std("imu_from_cam"))
    assert cal.problem.rms()["gyroscope"] == pytest.approx(0.005 * np.sqrt(3), rel=0.1)
    assert "gyro_intrinsics" in cal.todict()["std"]
    # without them the IMU's scale errors bend imu_from_cam (26σ in rotation in this seed)
    plain = calibrate_camera_imu(data, K, pixel_sigma=0.3)
    assert plain.gyro_intrinsics is None
    err_plain = np.r_[plain.imu_from_cam.pos - truth["imu_from_cam"].pos,
                      (truth["imu_from_cam"].rot.inverse() * plain.imu_from_cam.rot).log()]
    assert np.abs(err_plain / plain.std("imu_from_cam")).max() > 8


def test_a_second_imus_own_scale_and_misalignment():
    # Two IMUs, each with its own scale and misalignment, the second on its own clock:
    # with imu_intrinsics every matrix comes out within 4σ and 0.3 %, the second IMU's
    # pose and clock as without them, its residuals at the noise; the report lists its
    # matrices by name.
    rng = np.random.default_rng(4)
    i01 = SE3(SO3.exp(np.array([0.3, -1.2, 0.5])), np.array([0.08, -0.03, 0.05]))
    Mg0 = np.array([[1.01, 0, 0], [0.003, 0.99, 0], [-0.004, 0.002, 1.0]])
    Mg1 = np.array([[0.985, 0, 0], [-0.005, 1.02, 0], [0.004, 0.006, 1.01]])
    Ma1 = np.array([[1.015, 0, 0], [0.006, 0.99, 0], [-0.003, 0.005, 0.995]])
    data, truth, K = simulate_camera_imu(
        rng, time_offset=0.007, gyro_intrinsics=Mg0,
        other_imus=[SimulatedImu(i01, phase=0.0025, time_offset=0.004, gyro_intrinsics=Mg1,
                                 accel_intrinsics=Ma1)])
    cal = calibrate_camera_imu(data, K, pixel_sigma=0.3, imu_intrinsics=True)
    for k, kind, M in ((0, "gyro", Mg0), (0, "accel", np.eye(3)), (1, "gyro", Mg1), (1, "accel", Ma1)):
        name = f"{kind}_intrinsics" if k == 0 else f"imu_{kind}_intrinsics[{k}]"
        truth_vec = np.r_[np.diag(M), M[1, 0], M[2, 0], M[2, 1]]
        err = cal.problem[cal.ids[name]].vec - truth_vec
        assert np.all(np.abs(err) < 4 * cal.std(name)), (name, err, cal.std(name))
        assert np.abs(err).max() < 3e-3, (name, err)
        assert np.allclose(getattr(cal, f"imu_{kind}_intrinsics")[k], np.tril(getattr(cal, f"imu_{kind}_intrinsics")[k]))
    assert np.allclose(cal.imu_gyro_intrinsics[0], cal.gyro_intrinsics)
    est = cal.imu0_from_imus[1]
    err = np.r_[est.pos - i01.pos, (i01.rot.inverse() * est.rot).log()]
    assert np.all(np.abs(err) < 4 * cal.std("imu0_from_imu[1]"))
    d = cal.imu_time_offsets[1]
    assert abs(d - 0.004) < max(4 * cal.std("imu_time_offset[1]")[0], 1e-5)
    rms = cal.problem.rms()
    assert rms["gyroscope imu1"] == pytest.approx(0.005 * np.sqrt(3), rel=0.1)
    assert {"imu_gyro_intrinsics[1]", "imu_accel_intrinsics[1]"} <= set(cal.todict()["std"])
    from boxplus.calib.camera_imu_cli import _report
    from boxplus.calib.io import CalibratedCamera

    text = _report(cal, [CalibratedCamera("cam0", "pinhole", K, (640, 480), SE3())], data, 0.005, 0.05)
    assert "imu1 gyroscope scale and misalignment (reading M x + b), value ± σ: s_x" in text
    # Kalibr's imu YAML of each IMU: ω = M C_gyro_i ω_imu + A a + b, a = M a_imu + b, read
    # back as Kalibr reads it, predicts what boxplus' model predicts
    from boxplus.calib.camera_imu_cli import _kalibr_imu_model

    doc = _kalibr_imu_model(cal, 1)
    assert doc["model"] == "scale-misalignment"
    w, f = np.array([0.3, -1.1, 0.4]), np.array([0.5, 9.7, -1.2])
    M, C, A = (np.array(doc["gyroscopes"][key]) for key in ("M", "C_gyro_i", "A"))
    np.testing.assert_allclose(M @ C @ w + A @ f, cal.imu_gyro_intrinsics[1] @ w, rtol=1e-15)
    np.testing.assert_allclose(np.array(doc["accelerometers"]["M"]) @ f, cal.imu_accel_intrinsics[1] @ f,
                               rtol=1e-15)
    assert np.allclose(np.triu(M, 1), 0)
    # without them the second IMU's scale errors show in its gyroscope's residuals
    plain = calibrate_camera_imu(data, K, pixel_sigma=0.3, knot_spacing=cal.knot_spacing)
    assert plain.imu_gyro_intrinsics == [] and "imu_gyro_intrinsics[1]" not in plain.ids
    assert plain.problem.rms()["gyroscope imu1"] > 1.5 * rms["gyroscope imu1"]


def test_the_accelerometers_size_effect():
    # Its y and z sensing elements 1–2 cm from the x element (Kalibr's size effect): with
    # accel_size_effect both offsets come out within 4σ, the accelerometer's residuals at
    # the noise; asked without imu_intrinsics, the call says what it needs.
    rng = np.random.default_rng(3)
    Ma = np.array([[0.99, 0, 0], [0.005, 1.01, 0], [0.002, -0.004, 1.005]])
    sizes = np.array([[0.012, -0.006, 0.004], [-0.005, 0.015, 0.02]])
    data, truth, K = simulate_camera_imu(rng, time_offset=0.007, accel_intrinsics=Ma, accel_size_effect=sizes)
    cal = calibrate_camera_imu(data, K, pixel_sigma=0.3, imu_intrinsics=True, accel_size_effect=True)
    err = (cal.accel_size_effect - sizes).ravel()
    assert np.all(np.abs(err) < 4 * cal.std("accel_size_effect")), (err, cal.std("accel_size_effect"))
    assert cal.problem.rms()["accelerometer"] == pytest.approx(0.05 * np.sqrt(3), rel=0.1)
    with pytest.raises(ValueError, match="accel_size_effect needs imu_intrinsics"):
        calibrate_camera_imu(data, K, pixel_sigma=0.3, accel_size_effect=True)
    # the command line's report lists the IMU's own model with σ
    from boxplus.calib.camera_imu_cli import _report
    from boxplus.calib.io import CalibratedCamera

    text = _report(cal, [CalibratedCamera("cam0", "pinhole", K, (640, 480), SE3())], data, 0.005, 0.05)
    assert "accelerometer scale and misalignment (reading M x + b), value ± σ: s_x" in text
    assert "accelerometer size effect (y, z elements from x, m), value ± σ: r_y.x" in text
    from boxplus.calib.camera_imu_cli import _kalibr_imu_model

    doc = _kalibr_imu_model(cal, 0)
    assert doc["model"] == "scale-misalignment-size-effect" and doc["accelerometers"]["rx_i"] == [0, 0, 0]
    np.testing.assert_allclose([doc["accelerometers"]["ry_i"], doc["accelerometers"]["rz_i"]],
                               cal.accel_size_effect, rtol=1e-15)
