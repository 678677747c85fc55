"""Camera–IMU recordings with known truth: a camera and an IMU waved in front of a
target, sampled at their own rates and clocks (the job of
:func:`boxplus.calib.camera_imu.calibrate_camera_imu`).

Frames and clocks as there: ``imu_from_cam`` maps camera coordinates into the IMU
frame; IMU time = camera time + ``time_offset``; the world is the target's frame.
Images of these recordings are rendered by :mod:`boxplus.synthetic.images`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from boxplus import _core
from boxplus.calib.camera_imu import CameraFrames, CameraImuData, ImuSamples, spline_segment
from boxplus.calib.models import project
from boxplus.manifolds import SE3, SO3

__all__ = ["SimulatedCamera", "SimulatedImu", "simulate_camera_imu"]


@dataclass
class SimulatedImu:
    """One more IMU on the simulated rig: its pose in the first IMU's frame (lever arm
    and rotation), its constant biases, the phase of its samples after the first IMU's
    (s) at the first IMU's rate, and its clock's ``time_offset`` d (s): a sample taken
    at the first IMU's time t is stamped t − d (stamp + d is the first IMU's time);
    ``gyro_intrinsics`` / ``accel_intrinsics`` (3 × 3 lower triangular, None: the
    identity) make it read M x + b in its own axes."""

    imu0_from_imu: SE3
    gyro_bias: Any = (0.0, 0.0, 0.0)
    accel_bias: Any = (0.0, 0.0, 0.0)
    phase: float = 0.0
    name: str = ""
    time_offset: float = 0.0
    gyro_intrinsics: Any = None
    accel_intrinsics: Any = None


@dataclass
class SimulatedCamera:
    """One more camera on the simulated rig: its pose in the IMU frame, its clock
    (IMU time = its time + ``time_offset``), its lens (``intrinsics`` in ``model``'s
    order; None: the first camera's pinhole) and the phase of its frames after the
    first camera's (s; 0 for cameras triggered together); ``line_delay`` > 0 makes it
    a rolling shutter (s per row)."""

    imu_from_cam: SE3
    time_offset: float = 0.007
    model: str = "pinhole"
    intrinsics: Any = None
    phase: float = 0.0
    name: str = ""
    line_delay: float = 0.0


def simulate_camera_imu(rng: np.random.Generator, duration: float = 8.0, camera_rate: float = 20.0,
                        imu_rate: float = 200.0, time_offset: float = 0.007,
                        imu_from_cam: SE3 | None = None, pixel_sigma: float = 0.3,
                        gyro_sigma: float = 0.005, accel_sigma: float = 0.05,
                        gyro_bias: Any = (0.01, -0.02, 0.015), accel_bias: Any = (0.1, -0.05, 0.08),
                        knot_spacing: float = 0.05, gyro_random_walk: float = 0.0,
                        accel_random_walk: float = 0.0,
                        other_cameras: Sequence[SimulatedCamera] = (), line_delay: float = 0.0,
                        other_imus: Sequence[SimulatedImu] = (), motion: str = "spline",
                        bandwidth: float = 2.0, rotation_scale: Any = (1.0, 1.0, 1.0),
                        gyro_intrinsics: Any = None, accel_intrinsics: Any = None,
                        accel_size_effect: Any = None
                        ) -> tuple[CameraImuData, dict[str, Any], np.ndarray]:
    """A camera and an IMU waved in front of a 7 × 6 target (6 cm squares): the IMU's
    true trajectory is a spline of smooth random control points (a rig swinging
    ±0.3 m and ±25° about a pose 0.8 m in front of the target), sampled by the IMU
    (with its biases and white noise) and seen by a pinhole camera at its own clock
    (IMU time = camera time + ``time_offset``); with ``gyro_random_walk`` /
    ``accel_random_walk`` (densities) the biases drift from the given values as Wiener
    processes (truth: ``*_bias_track`` per IMU sample, ``*_bias`` their means).
    Returns (data, truth, intrinsics); the
    truth holds the camera's pose at every frame (``world_from_cam``; the target's 42
    corners are those of ``chessboard:7x6:0.06`` shifted by (−0.18, −0.15, 0)), so
    that images can be rendered (:mod:`boxplus.synthetic.images`), and the IMU's pose
    at any IMU time (``world_from_imu_at(t)``), so that a rolling shutter's rows can be.

    ``other_cameras`` (:class:`SimulatedCamera`) add cameras to the rig, each seeing
    the target through its own lens at its own clock (``data.other_cameras``); the
    truth then also holds ``imu_from_cams``, ``time_offsets``, ``world_from_cams``
    (one per camera, the first camera's first) and ``intrinsics`` (per camera). They are
    drawn after the first camera's, so a seed gives the same first camera with or
    without them. ``line_delay`` > 0 (s per row) gives the first camera a rolling
    shutter: row v is seen at its frame's time + ℓ·v (each corner's row found by
    fixed-point iteration); truth ``line_delays`` per camera. ``other_imus``
    (:class:`SimulatedImu`) add IMUs that feel the body's rotation in their own axes and
    the acceleration of their own position (lever arm: α × r + ω × (ω × r)), with the
    same noise (``data.other_imus``; truth ``imu0_from_imus``), drawn last.

    ``motion="sines"``: the IMU's true motion is no spline at all but a sum of four
    sinusoids per axis with random frequencies up to ``bandwidth`` Hz (the same ±0.3 m
    and ±25° swing), its velocity and acceleration exact, its angular velocity and
    acceleration central differences of the rotation (errors ≪ the noise): what a
    hand-held rig does, so a fit with any knot spacing has a modelling error to show.
    ``rotation_scale`` scales the swing's rotation about each of the camera's axes
    (``(1, 1, 0)``: no rotation about the optical axis), for recordings that leave a
    direction unexcited. ``gyro_intrinsics`` / ``accel_intrinsics`` (3 × 3, lower
    triangular: scale on the diagonal, misalignment below) make the first IMU read
    M x + b instead of x + b (Kalibr's scale-misalignment model); ``accel_size_effect``
    (2 × 3: r_y, r_z) puts its accelerometer's y and z sensing elements there (from the x
    element, the IMU's origin): each reads its own point's specific force."""
    K = np.array([460.0, 460.0, 320.0, 240.0])
    imu_from_cam = imu_from_cam or SE3(SO3.exp(np.array([0.02, -0.03, 1.57])), np.array([0.04, -0.01, 0.02]))
    target = np.array([[0.06 * c - 0.18, 0.06 * r - 0.15, 0.0] for r in range(6) for c in range(7)])
    g_dir = np.array([0.05, -0.1, 1.0]) / np.linalg.norm([0.05, -0.1, 1.0])  # target frame
    dt = knot_spacing
    n = int(np.ceil(duration / dt)) + 6
    t0 = -2 * dt  # knots at multiples of dt, as calibrate_camera_imu places them
    # a smooth random swing: low-pass filtered noise at the knots
    smooth = np.ones(7) / 7

    def swing(scale: float, dims: int) -> np.ndarray:
        x = rng.normal(0, 1, (n + 12, dims))
        for _ in range(3):
            x = np.stack([np.convolve(x[:, j], smooth, "same") for j in range(dims)], axis=1)
        x = x[6:-6]
        return scale * x / np.abs(x).max(axis=0)

    # the camera looks at the target from z = −0.8 (target frame), the IMU follows it
    base_cam = SE3(SO3(), np.array([0.0, 0.0, -0.8]))
    scale = np.asarray(rotation_scale, float)
    pos, rot = swing(0.3, 3), swing(np.radians(25), 3) * scale
    knots = []
    for j in range(n):
        world_from_cam = SE3(base_cam.rot * SO3.exp(rot[j]), base_cam.pos + pos[j])
        knots.append((world_from_cam * imu_from_cam.inverse()).ambient)
    knots_a = np.array(knots)

    def on_spline(t: float) -> tuple:
        i, u = spline_segment(t, t0, dt, n)
        return _core.spline_evaluate(knots_a[i:i + 4], u, dt)

    state: Callable[[float], tuple] = on_spline
    if motion == "sines":
        state = _sines(rng, duration, bandwidth, base_cam, imu_from_cam, scale)
    elif motion != "spline":
        raise ValueError(f"simulate_camera_imu: motion must be 'spline' or 'sines', got {motion!r}")

    imu_t = np.arange(0.0, duration, 1.0 / imu_rate)
    # biases: the given values, drifting as Wiener processes of the given densities (drawn
    # only then, so that a seed gives the same recording as before drifts existed)
    bg = np.tile(np.asarray(gyro_bias, float), (len(imu_t), 1))
    ba = np.tile(np.asarray(accel_bias, float), (len(imu_t), 1))
    if gyro_random_walk > 0 or accel_random_walk > 0:
        steps = np.sqrt(1.0 / imu_rate) * rng.standard_normal((2, len(imu_t), 3))
        steps[:, 0] = 0.0
        bg += gyro_random_walk * np.cumsum(steps[0], axis=0)
        ba += accel_random_walk * np.cumsum(steps[1], axis=0)
    Mg = np.eye(3) if gyro_intrinsics is None else np.asarray(gyro_intrinsics, float)
    Ma = np.eye(3) if accel_intrinsics is None else np.asarray(accel_intrinsics, float)
    sizes = None if accel_size_effect is None else np.asarray(accel_size_effect, float).reshape(2, 3)
    gyro, accel = [], []
    for k, t in enumerate(imu_t):
        p, q, v, a, w, alpha = state(t)
        R = SO3(q).R
        f = R.T @ (a - 9.81 * g_dir)
        if sizes is not None:
            for axis, r in ((1, sizes[0]), (2, sizes[1])):
                f[axis] += (np.cross(alpha, r) + np.cross(w, np.cross(w, r)))[axis]
        gyro.append(Mg @ w + bg[k] + rng.normal(0, gyro_sigma, 3))
        accel.append(Ma @ f + ba[k] + rng.normal(0, accel_sigma, 3))
    def observe(ic: SE3, offset: float, k: np.ndarray, model: str, phase: float,
                ell: float = 0.0) -> tuple:
        frame_t = np.arange(0.2 + phase, duration - 0.2, 1.0 / camera_rate)
        corners, cam_poses = [], []

        def seen(t: float, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            p, q, *_ = state(t)
            world_from_cam = SE3(SO3(q), p) * ic
            pc = (points - world_from_cam.pos) @ world_from_cam.rot.R
            front = pc[:, 2] > 0
            uv = np.full((len(pc), 2), -1.0)
            uv[front] = project(k, pc[front], model)
            return uv, front

        for tc in frame_t:
            p, q, *_ = state(tc + offset)
            world_from_cam = SE3(SO3(q), p) * ic
            cam_poses.append(world_from_cam)
            uv, front = seen(tc + offset, target)
            if ell > 0:  # a rolling shutter: each corner at the time its row was read
                for j in np.flatnonzero(front):
                    for _ in range(6):  # ℓ·(row speed) ≪ 1: converges to 1e-12 px
                        uv_j, ok_j = seen(tc + offset + ell * uv[j, 1], target[j:j + 1])
                        uv[j], front[j] = uv_j[0], ok_j[0]
                        if not front[j]:
                            break
            ok = front & np.all((uv >= 0) & (uv < [640, 480]), axis=1)
            corners.append((uv[ok] + rng.normal(0, pixel_sigma, (ok.sum(), 2)), target[ok])
                           if ok.sum() >= 8 else None)
        return frame_t, corners, cam_poses

    frame_t, corners, cam_poses = observe(imu_from_cam, time_offset, K, "pinhole", 0.0, line_delay)
    others, poses_all = [], [cam_poses]
    for i, cam in enumerate(other_cameras):
        lens = K if cam.intrinsics is None else np.asarray(cam.intrinsics, float)
        ft, cs, ps = observe(cam.imu_from_cam, cam.time_offset, lens, cam.model, cam.phase,
                             cam.line_delay)
        others.append(CameraFrames(ft, cs, cam.name or f"cam{i + 1}"))
        poses_all.append(ps)
    def world_from_imu_at(t: float) -> SE3:
        p, q, *_ = state(t)
        return SE3(SO3(q), p)

    truth = {"imu_from_cam": imu_from_cam, "time_offset": time_offset, "gyro_bias": bg.mean(axis=0),
             "accel_bias": ba.mean(axis=0), "gyro_bias_track": bg, "accel_bias_track": ba,
             "gravity": 9.81 * g_dir, "world_from_cam": cam_poses,
             "imu_from_cams": [imu_from_cam, *(c.imu_from_cam for c in other_cameras)],
             "time_offsets": [time_offset, *(c.time_offset for c in other_cameras)],
             "world_from_cams": poses_all,
             "line_delays": [line_delay, *(c.line_delay for c in other_cameras)],
             "world_from_imu_at": world_from_imu_at,
             "intrinsics": [K, *(K if c.intrinsics is None else np.asarray(c.intrinsics, float)
                                 for c in other_cameras)]}
    more_imus = []
    for i, extra in enumerate(other_imus):
        R_k, r = extra.imu0_from_imu.rot.R, extra.imu0_from_imu.pos
        t_k = np.arange(extra.phase, duration, 1.0 / imu_rate)
        Mg_k = np.eye(3) if extra.gyro_intrinsics is None else np.asarray(extra.gyro_intrinsics, float)
        Ma_k = np.eye(3) if extra.accel_intrinsics is None else np.asarray(extra.accel_intrinsics, float)
        g_k, a_k = [], []
        for t in t_k:
            p, q, v, a, w, alpha = state(t)
            f = SO3(q).R.T @ (a - 9.81 * g_dir) + np.cross(alpha, r) + np.cross(w, np.cross(w, r))
            g_k.append(Mg_k @ R_k.T @ w + np.asarray(extra.gyro_bias, float) + rng.normal(0, gyro_sigma, 3))
            a_k.append(Ma_k @ R_k.T @ f + np.asarray(extra.accel_bias, float) + rng.normal(0, accel_sigma, 3))
        more_imus.append(ImuSamples(t_k - extra.time_offset, np.array(g_k), np.array(a_k),
                                    extra.name or f"imu{i + 1}"))
    truth["imu0_from_imus"] = [SE3(), *(x.imu0_from_imu for x in other_imus)]
    truth["imu_time_offsets"] = [0.0, *(x.time_offset for x in other_imus)]
    data = CameraImuData(frame_t, corners, imu_t, np.array(gyro), np.array(accel), others,
                         other_imus=more_imus)
    return data, truth, K


def _sines(rng: np.random.Generator, duration: float, bandwidth: float, base_cam: SE3,
           imu_from_cam: SE3, rotation_scale: np.ndarray) -> Callable[[float], tuple]:
    """state(t) = (p, q, v, a, ω, α) of world_from_imu(t) = (base.rot · Exp(θ(t)),
    base.pos + x(t)), base = base_cam · cam_from_imu, x and θ sums of four sinusoids per
    axis (frequencies uniform in [0.1, bandwidth] Hz, scaled to ±0.3 m and ±25° over
    the recording; θ about the camera's axes, times ``rotation_scale``)."""
    base = base_cam * imu_from_cam.inverse()
    R_ic = imu_from_cam.rot
    if not (np.isfinite(bandwidth) and bandwidth > 0.1):
        raise ValueError(f"simulate_camera_imu: bandwidth must exceed 0.1 Hz, got {bandwidth}")
    grid = np.linspace(0.0, duration, 2001)

    def draw(scale: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        w = 2 * np.pi * rng.uniform(0.1, bandwidth, (4, 3))
        amp = rng.normal(0, 1, (4, 3)) / w  # rougher at low frequencies, as a hand moves
        phase = rng.uniform(0, 2 * np.pi, (4, 3))
        peak = np.abs(np.sum(amp[None] * np.sin(w[None] * grid[:, None, None] + phase[None]), axis=1)).max(axis=0)
        return w, amp * scale / peak, phase

    pos, rot = draw(0.3), draw(np.radians(25))
    rot = (rot[0], rot[1] * rotation_scale, rot[2])

    def value(c: tuple, t: float, order: int) -> np.ndarray:
        w, amp, phase = c
        return np.sum(amp * w ** order * np.sin(w * t + phase + order * np.pi / 2), axis=0)

    def rotation(t: float) -> SO3:
        # θ about the camera's axes, carried into the IMU's
        return base.rot * SO3.exp(R_ic.R @ value(rot, t, 0))

    def omega(t: float, h: float = 1e-4) -> np.ndarray:
        return (rotation(t - h).inverse() * rotation(t + h)).log() / (2 * h)

    def state(t: float) -> tuple:
        h = 1e-3
        return (base.pos + value(pos, t, 0), rotation(t).ambient, value(pos, t, 1), value(pos, t, 2),
                omega(t), (omega(t + h) - omega(t - h)) / (2 * h))

    return state
