"""Camera–IMU calibration in motion: imu_from_cam, the clocks' offset, the IMU biases
and gravity, from a camera and an IMU waved in front of a target (Kalibr's job;
Furgale, Rehder & Siegwart, IROS 2013).

The IMU's trajectory world_from_imu(t) is a cubic B-spline on R³ × SO(3) with
control points every ``knot_spacing`` seconds (``factors/imu/se3_spline.h``;
world = the target's frame; by default 50 ms, halved while the IMU residuals exceed
1.5× the noise: ``bench/bench_camera_imu.py``). The terms (``factors/imu/spline_terms.h``): every
gyroscope sample (ω_imu(t) + b_g), every accelerometer sample (R(t)ᵀ(a(t) − g ĝ)
+ b_a, g = ``gravity_magnitude``, ĝ the direction of gravity in the target frame, an S² variable), and every
target corner a camera saw at its timestamp t_c, reprojected from the pose at IMU
time t_c + d (d, the time offset, a variable) through imu_from_cam and any camera
model of :mod:`boxplus.calib.models`. Each is whitened by its noise: the IMU's
white-noise densities (Kalibr's ``imu.yaml``: σ_discrete = density · √rate) and the
corner σ. The biases are constant over the data, or, given the random-walk
densities (Kalibr's ``gyroscope_random_walk``, ``accelerometer_random_walk``),
piecewise constant over segments of ``bias_spacing`` seconds, consecutive segments
tied by the random walk: (b_{k+1} − b_k) / (q √Δ) is one unit of noise per axis
(the variance of a Wiener process of density q over Δ; of two segment means it would
be ⅔ of that, so this is the looser tie).

Initialisation needs no hand tuning:

1. each image's camera pose from its corners (PnP, the camera calibrated before);
2. the time offset d and the rotation of imu_from_cam together: the camera's angular
   velocities (from consecutive poses) aligned with the gyroscope's at t + d (Wahba
   at each d over ±``max_offset``, the d of least misfit; the speeds' correlation
   alone peaked 39 ms off on a swinging rig), the translation 0;
3. the spline from the camera's poses carried to the IMU (those whose rotation to
   the next frame agrees with the gyroscope: a PnP from a few corners can be far off),
   gravity from the mean specific force in the target frame, biases 0;

then a solve of the trajectory, biases and gravity with the offset and the
extrinsics held, and the maximum-likelihood solve of everything. An answer whose
residuals are 10× the noise, or whose offset moved by more than a knot spacing, is
a ValueError, not a result. Several cameras on the rig (a stereo pair, N cameras:
``CameraImuData.other_cameras``) share the one trajectory, biases and gravity; each
has its own imu_from_cam, intrinsics and, unless ``common_clock`` (cameras triggered
together), its own time offset (as Kalibr's camchain-imucam has ``T_cam_imu`` and
``timeshift_cam_imu`` per camera); steps 1–2 run per camera, and the spline starts
from every camera's consistent poses. A rolling-shutter camera (``rolling_shutter``)
reads row v at its frame's timestamp + ℓ·v: each corner is reprojected from the pose
at t_c + d + ℓ·v (v its measured row), ℓ per camera a variable, held with the
extrinsics and offsets in the first solve. More IMUs (``other_imus``) are placed in
the first IMU's frame (imu0_from_imu, started by aligning their gyroscopes with the
first one's): their gyroscope reads R_kᵀ ω + b, their accelerometer R_kᵀ (f + α × r +
ω × (ω × r)) + b, f the body's specific force and α the spline's angular
acceleration (``spline_terms.h``); they share the first IMU's clock. Each corner's spline segment is chosen at the start's
offset; the solve's offset may move it by a fraction of a knot spacing (the segment's
polynomials extrapolate). :func:`boxplus.synthetic.camera_imu.simulate_camera_imu` makes data with known truth.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from boxplus import _core
from boxplus._plain import fields_todict
from boxplus.calib.init import pose_from_rays, rotation_between
from boxplus.calib.models import model_labels, rays
from boxplus.manifolds import S2, SE3, SO3, Rn
from boxplus.noise import NoiseModel
from boxplus.problem import OptimizationProblem

__all__ = ["CameraFrames", "CameraImuCalibration", "CameraImuData", "ImuSamples", "calibrate_camera_imu",
           "intrinsics_matrix", "spline_segment"]


@dataclass
class CameraFrames:
    """One camera's view of the target: frame_times (F,) (s, the camera's clock) and,
    per frame, the corners (pixels (N, 2), target points (N, 3)) or None."""

    frame_times: np.ndarray
    corners: list[Any]
    name: str = ""


@dataclass
class ImuSamples:
    """Another IMU on the rig: its samples, time-stamped on the first IMU's clock
    (imu_times (M,) s, gyro (M, 3) rad/s, accel (M, 3) m/s²)."""

    imu_times: np.ndarray
    gyro: np.ndarray
    accel: np.ndarray
    name: str = ""


@dataclass
class CameraImuData:
    """What a camera–IMU recording holds.

    frame_times: (F,) camera timestamps (s, the camera's clock); corners: per frame
    (pixels (N, 2), target points (N, 3)) or None; imu_times (M,) (s, the IMU's clock);
    gyro (M, 3) rad/s; accel (M, 3) m/s². A rig of several cameras lists the others in
    ``other_cameras`` (each with its own frame times); ``camera_name`` names the first.
    A rig of several IMUs lists the others in ``other_imus`` (:class:`ImuSamples`; the
    first IMU is the body whose trajectory is estimated)."""

    frame_times: np.ndarray
    corners: list[Any]
    imu_times: np.ndarray
    gyro: np.ndarray
    accel: np.ndarray
    other_cameras: list[CameraFrames] = field(default_factory=list)
    camera_name: str = "cam0"
    other_imus: list[ImuSamples] = field(default_factory=list)

    @property
    def cameras(self) -> list[CameraFrames]:
        """Every camera's frames, the first one's first; unnamed ones are "cam<i>"."""
        first = CameraFrames(self.frame_times, self.corners, self.camera_name or "cam0")
        return [first, *(CameraFrames(c.frame_times, c.corners, c.name or f"cam{i + 1}")
                         for i, c in enumerate(self.other_cameras))]


@dataclass
class CameraImuCalibration:
    """The solved calibration: estimates, their σ (given-noise, tangent order) and the
    problem (ids in ``ids``: "imu_from_cam", "time_offset", "gyro_bias",
    "accel_bias", "gravity", "intrinsics", knots "knot0" …). With several cameras
    ``imu_from_cam``/``time_offset`` are the first camera's, ``imu_from_cams`` /
    ``time_offsets`` every camera's, and ids "imu_from_cam[c]", "time_offset[c]",
    "intrinsics[c]" camera c's (one shared offset when ``common_clock``)."""

    problem: OptimizationProblem
    ids: dict[str, int]
    t0: float
    knot_spacing: float
    imu_from_cam: SE3
    time_offset: float
    gyro_bias: np.ndarray
    accel_bias: np.ndarray
    gravity: np.ndarray
    summary: Any = None
    initial: dict[str, Any] = field(default_factory=dict)
    # the bias segments: boundaries (K + 1, IMU time) and each segment's biases (K, 3);
    # K = 1 when the biases are constant, and gyro_bias/accel_bias are their means
    bias_times: np.ndarray = field(default_factory=lambda: np.zeros(0))
    gyro_biases: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    accel_biases: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    camera_names: list[str] = field(default_factory=list)
    imu_from_cams: list[SE3] = field(default_factory=list)
    time_offsets: list[float] = field(default_factory=list)
    # per camera: the rolling shutter's line delay (s per row), None for a global shutter
    line_delays: list[float | None] = field(default_factory=list)
    # per IMU (the first, the body, first): its pose in the first IMU's frame (the lever
    # arm and rotation) and its biases' means
    imu_names: list[str] = field(default_factory=list)
    imu0_from_imus: list[SE3] = field(default_factory=list)
    imu_gyro_biases: list[np.ndarray] = field(default_factory=list)
    imu_accel_biases: list[np.ndarray] = field(default_factory=list)
    # per IMU: its clock's offset d (s; its stamp + d is the first IMU's time; 0 for the
    # first, and for all with imu_time_offsets=False)
    imu_time_offsets: list[float] = field(default_factory=list)
    # the first IMU's scale and misalignment (imu_intrinsics=True; 3 × 3 lower triangular,
    # the reading M x + b), None when not estimated
    gyro_intrinsics: np.ndarray | None = None
    accel_intrinsics: np.ndarray | None = None
    # per IMU (the first first): its scale and misalignment as above; empty when not
    # estimated
    imu_gyro_intrinsics: list[np.ndarray] = field(default_factory=list)
    imu_accel_intrinsics: list[np.ndarray] = field(default_factory=list)
    # the accelerometer's size effect (accel_size_effect=True): rows r_y, r_z (m)
    accel_size_effect: np.ndarray | None = None

    def cam_from_cam(self, c: int, ref: int = 0) -> SE3:
        """cam_c_from_cam_ref: camera ``ref``'s coordinates into camera c's (Kalibr's
        ``T_cn_cnm1`` for ref = c − 1)."""
        return self.imu_from_cams[c].inverse() * self.imu_from_cams[ref]

    def cam_from_cam_std(self, c: int, ref: int = 0) -> np.ndarray:
        """σ of :meth:`cam_from_cam` in SE3's tangent order (translation m, rotation
        rad), from the joint covariance of both cameras' imu_from_cam (first order)."""
        a, b = self.ids[f"imu_from_cam[{c}]"], self.ids[f"imu_from_cam[{ref}]"]
        cov = self.problem.joint_covariance([a, b])
        A, B = self.imu_from_cams[c], self.imu_from_cams[ref]
        rel = A.inverse() * B
        J = np.zeros((6, 12))
        h = 1e-6
        for k in range(12):
            e = np.zeros(6)
            e[k % 6] = h
            moved = ((A + e).inverse() * B) if k < 6 else (A.inverse() * (B + e))
            J[:, k] = (moved - rel) / h
        return np.sqrt(np.diag(J @ cov @ J.T))

    def std(self, name: str) -> np.ndarray:
        """σ of a variable of ``ids`` (tangent order); "gyro_bias"/"accel_bias" are the
        first bias segment's, "gyro_bias[k]" the k-th's."""
        return self.problem.std(self.ids[name])

    def todict(self) -> dict[str, Any]:
        """Plain Python values (``json.dumps`` takes them): the estimates (imu_from_cam as
        [p, q], q = [x, y, z, w]), their σ in tangent order, the spline's knot grid and
        the solve summary."""
        names = ["imu_from_cam", "time_offset", "gyro_bias", "accel_bias", "gravity"]
        names += [f"{v}[{c}]" for c in range(1, len(self.imu_from_cams))
                  for v in ("imu_from_cam", "time_offset")]
        names += [f"line_delay[{c}]" for c, ell in enumerate(self.line_delays) if ell is not None]
        names += [v for v in ("gyro_intrinsics", "accel_intrinsics", "accel_size_effect") if v in self.ids]
        names += [f"{v}[{k}]" for k in range(1, len(self.imu0_from_imus))
                  for v in ("imu0_from_imu", "imu_gyro_bias", "imu_accel_bias", "imu_time_offset",
                            "imu_gyro_intrinsics", "imu_accel_intrinsics")
                  if f"{v}[{k}]" in self.ids]
        return {**fields_todict(self, skip=("problem", "ids")),
                "std": {n: self.std(n).tolist() for n in names},
                "knots": self.n_knots}

    @property
    def n_knots(self) -> int:
        """Control points of the trajectory spline (``ids`` "knot0" … ); it covers IMU
        times t0 … t0 + (n_knots − 3)·knot_spacing."""
        return sum(1 for n in self.ids if n.startswith("knot"))

    def _state(self, t: float) -> tuple:
        """(p, q, v, a, ω_body) of the spline at IMU time t (clamped to its segments)."""
        i, u = spline_segment(t, self.t0, self.knot_spacing, self.n_knots)
        k = np.array([self.problem[self.ids[f"knot{i + j}"]].ambient for j in range(4)])
        return _core.spline_evaluate(k, u, self.knot_spacing)

    def pose(self, t: float) -> SE3:
        """world_from_imu at IMU time t."""
        p, q, *_ = self._state(t)
        return SE3(SO3(q), p)

    def angular_velocity(self, t: float) -> np.ndarray:
        """ω_imu at IMU time t (rad/s, IMU frame): what an unbiased, noise-free gyroscope
        would read (the gyroscope term's prediction before its bias)."""
        return np.asarray(self._state(t)[4]).ravel()


def spline_segment(t: float, t0: float, dt: float, n_knots: int) -> tuple[int, float]:
    """(i, u) of the segment covering time t (clamped to the spline's segments)."""
    x = (t - t0) / dt
    i = int(np.clip(np.floor(x), 0, n_knots - 4))
    return i, float(x - i)


def _angular_velocities(times: np.ndarray, poses: list[SE3]) -> tuple[np.ndarray, np.ndarray]:
    """(mid times, angular velocity in the camera frame (K, 3)) between consecutive poses."""
    mid, w = [], []
    period = float(np.median(np.diff(times)))
    for k in range(len(poses) - 1):
        dt = times[k + 1] - times[k]
        if not 0 < dt <= 1.5 * period:  # a frame without the target between them
            continue
        mid.append(0.5 * (times[k] + times[k + 1]))
        w.append((poses[k].rot.inverse() * poses[k + 1].rot).log() / dt)
    return np.array(mid), np.array(w)


def _consistent_frames(t_cam: np.ndarray, poses: list[SE3], t_imu: np.ndarray, gyro: np.ndarray,
                       d: float, R_ic: np.ndarray, tol: float = 0.5) -> np.ndarray:
    """Frames whose rotation to a neighbour agrees with the integrated gyroscope (within
    ``tol`` rad/s on the mean rate); all frames when fewer than half would be kept."""
    ok = np.zeros(len(poses), dtype=bool)
    for k in range(len(poses) - 1):
        dt = t_cam[k + 1] - t_cam[k]
        if dt <= 0:
            continue
        w_cam = (poses[k].rot.inverse() * poses[k + 1].rot).log() / dt
        sel = (t_imu >= t_cam[k] + d) & (t_imu <= t_cam[k + 1] + d)
        if not sel.any():
            continue
        w_imu = gyro[sel].mean(axis=0)
        if np.linalg.norm(R_ic @ w_cam - w_imu) < tol:
            ok[k] = ok[k + 1] = True
    return ok if ok.sum() >= len(poses) // 2 else np.ones(len(poses), dtype=bool)


def _offset_and_rotation(t_cam: np.ndarray, w_cam: np.ndarray, t_imu: np.ndarray, gyro: np.ndarray,
                         max_offset: float) -> tuple[float, np.ndarray]:
    """(d, R) minimising the mean ‖ω_imu(t + d) − R ω_cam(t)‖² over d ∈ ±max_offset: the
    camera's angular velocities (from consecutive poses) aligned with the gyroscope's,
    the rotation by Wahba at each d. The vectors, not only the speeds, are compared:
    on a swinging rig the speed alone varies too little to place the peak."""
    # a pose from a few corners can be far off: rates beyond the gyroscope's are dropped,
    # and the misfit is the mean of the best 80 % (trimmed), then Wahba on those again
    plausible = np.linalg.norm(w_cam, axis=1) <= 1.5 * np.linalg.norm(gyro, axis=1).max()
    t_cam, w_cam = t_cam[plausible], w_cam[plausible]

    def misfit(d: float) -> tuple[float, np.ndarray]:
        t = t_cam + d
        ok = (t >= t_imu[0]) & (t <= t_imu[-1])
        if ok.sum() < 10:
            return np.inf, np.eye(3)
        w_i = np.stack([np.interp(t[ok], t_imu, gyro[:, j]) for j in range(3)], axis=1)
        R = rotation_between(w_cam[ok], w_i)
        r = np.sum((w_i - w_cam[ok] @ R.T) ** 2, axis=1)
        keep = r <= np.quantile(r, 0.8)
        R = rotation_between(w_cam[ok][keep], w_i[keep])
        r = np.sum((w_i[keep] - w_cam[ok][keep] @ R.T) ** 2, axis=1)
        return float(np.mean(r)), R

    coarse = np.arange(-max_offset, max_offset + 1e-9, 2e-3)
    d = float(coarse[int(np.argmin([misfit(x)[0] for x in coarse]))])
    fine = np.arange(d - 2e-3, d + 2e-3 + 1e-9, 1e-4)
    d = float(fine[int(np.argmin([misfit(x)[0] for x in fine]))])
    return d, misfit(d)[1]


def calibrate_camera_imu(data: CameraImuData, intrinsics: Any, model: str | list[str] = "pinhole",
                         pixel_sigma: float = 0.5, gyro_sigma: float = 0.005,
                         accel_sigma: float = 0.05, knot_spacing: float | None = None,
                         max_offset: float = 0.1, gravity_magnitude: float = 9.81,
                         estimate_intrinsics: bool = False, gyro_random_walk: float | None = None,
                         accel_random_walk: float | None = None,
                         bias_spacing: float = 0.1, common_clock: bool = False,
                         rolling_shutter: bool | list[bool] = False,
                         line_delay: float | list[float] = 0.0,
                         other_imu_sigmas: list[tuple[float, float]] | None = None,
                         imu_time_offsets: bool = True,
                         imu_intrinsics: bool = False,
                         accel_size_effect: bool = False) -> CameraImuCalibration:
    """Calibrates imu_from_cam, the time offset d (IMU time = camera time + d), the
    gyroscope and accelerometer biases and gravity (module docstring).

    ``knot_spacing`` (s): the trajectory spline's; None (the default) starts at 0.05 s
    and halves it while the IMU residuals' RMS exceed 1.5× the noise (or the fit is
    implausible), down to 2.5 IMU samples per knot: a hand-waved rig moves faster than
    a coarse spline follows (module docstring).

    ``intrinsics`` in ``model``'s order (from ``boxplus-calib``); held fixed unless
    ``estimate_intrinsics``. With several cameras (``data.other_cameras``) give one
    intrinsics vector per camera (a list) and one model, or a list of models;
    ``common_clock``: the cameras are triggered together, one time offset for all.
    ``rolling_shutter`` (one flag, or one per camera): the camera reads its rows one
    after the other, row v at its timestamp + ℓ·v; the line delay ℓ (s per row) is
    estimated from ``line_delay`` (default 0; one value or one per camera).
    Several IMUs (``data.other_imus``): each gets its pose in the first IMU's frame
    (imu0_from_imu, the lever arm included) and its own biases (segments as the first
    IMU's); ``other_imu_sigmas`` gives their (gyro σ, accel σ) per sample, else the
    first IMU's. Each IMU's clock offset d_k (its stamp + d_k is the first IMU's time,
    Kalibr's per-IMU ``time_offset``) is estimated, started from the alignment of its
    gyroscope with the first one's over ±``max_offset``; ``imu_time_offsets=False``
    when all IMUs share the first one's clock. ``imu_intrinsics``: every IMU's
    gyroscope and accelerometer also get a scale and misalignment each (Kalibr's
    scale-misalignment model: the reading M x + b in the IMU's own axes, M lower
    triangular, started at the identity; the first IMU's ``cal.gyro_intrinsics``,
    ``cal.accel_intrinsics``, ids "gyro_intrinsics", "accel_intrinsics" labelled s_x s_y
    s_z m_yx m_zx m_zy; every IMU's ``cal.imu_gyro_intrinsics[k]``,
    ``cal.imu_accel_intrinsics[k]``, ids "imu_gyro_intrinsics[k]",
    "imu_accel_intrinsics[k]" for k ≥ 1). ``accel_size_effect`` (with
    ``imu_intrinsics``; the first IMU's): the accelerometer's y and z sensing elements
    sit at r_y, r_z from its x element (Kalibr's size effect; ``cal.accel_size_effect``
    (2 × 3), id "accel_size_effect"), each reading its own point's specific force.
    ``gyro_sigma``/``accel_sigma``: the per-sample noise
    (rad/s, m/s²; Kalibr's density × √rate). ``gyro_random_walk``/``accel_random_walk``
    (rad/s²/√Hz, m/s³/√Hz, Kalibr's imu.yaml): biases that drift, one value per
    ``bias_spacing`` seconds (module docstring); both or neither. Raises ValueError
    naming what is missing (too few frames with corners, IMU samples not covering the
    frames), and the camera when there are several."""
    if accel_size_effect and not imu_intrinsics:
        raise ValueError("calibrate_camera_imu: accel_size_effect needs imu_intrinsics=True")
    args = dict(locals())
    if knot_spacing is not None:
        cal = _fit(**args)
    else:
        t = np.asarray(data.imu_times, float)
        span = float(t[-1] - t[0]) if len(t) > 1 else 0.0
        floor = 2.5 * span / (len(t) - 1) if span > 0 else ADAPTIVE_START_SPACING
        spacing = ADAPTIVE_START_SPACING
        offsets: list[float] | None = None
        while True:
            finer = spacing / 2 >= floor
            try:
                cal = _fit(**{**args, "knot_spacing": spacing, "offsets_start": offsets})
            except _ImplausibleFit as e:
                if not (finer and e.imu_only):
                    raise
                spacing /= 2
                continue
            if not finer or _imu_misfit(cal, gyro_sigma, accel_sigma) <= ADAPTIVE_IMU_MISFIT:
                break
            spacing /= 2
            offsets = cal.time_offsets
    _warn_reprojection(cal, pixel_sigma)
    _warn_excitation(cal)
    return cal


def _fit(data: CameraImuData, intrinsics: Any, model: str | list[str], *, pixel_sigma: float,
         gyro_sigma: float, accel_sigma: float, knot_spacing: float, max_offset: float,
         gravity_magnitude: float, estimate_intrinsics: bool, gyro_random_walk: float | None,
         accel_random_walk: float | None, bias_spacing: float, common_clock: bool,
         rolling_shutter: bool | list[bool], line_delay: float | list[float],
         other_imu_sigmas: list[tuple[float, float]] | None, imu_time_offsets: bool = True,
         imu_intrinsics: bool = False, accel_size_effect: bool = False,
         offsets_start: list[float] | None = None
         ) -> CameraImuCalibration:
    """One fit at one knot spacing (calibrate_camera_imu); ``offsets_start``: the cameras'
    time offsets to start from instead of the angular-velocity alignment's."""
    if (gyro_random_walk is None) != (accel_random_walk is None):
        raise ValueError("calibrate_camera_imu: give both random walks (gyro_random_walk, "
                         "accel_random_walk) or neither")
    walks: tuple[float, float] | None = None
    if gyro_random_walk is not None and accel_random_walk is not None:
        walks = (float(gyro_random_walk), float(accel_random_walk))
        if not all(np.isfinite(w) and w > 0 for w in walks):
            raise ValueError(f"calibrate_camera_imu: random walks must be positive, got {walks}")
    if not (np.isfinite(bias_spacing) and bias_spacing > 0):
        raise ValueError(f"calibrate_camera_imu: bias_spacing must be positive, got {bias_spacing}")
    cameras = data.cameras
    n_cam = len(cameras)
    several = n_cam > 1
    if several and not (isinstance(intrinsics, (list, tuple)) and len(intrinsics) == n_cam):
        raise ValueError(f"calibrate_camera_imu: {n_cam} cameras ({', '.join(c.name for c in cameras)}): "
                         f"give one intrinsics vector per camera")
    models = list(model) if isinstance(model, (list, tuple)) else [model] * n_cam
    if len(models) != n_cam:
        raise ValueError(f"calibrate_camera_imu: {len(models)} models for {n_cam} cameras")
    ks = [np.asarray(k, dtype=float) for k in (intrinsics if several else [intrinsics])]
    for cam, k, m in zip(cameras, ks, models):
        if k.size != len(model_labels(m)):
            raise ValueError(f"calibrate_camera_imu: {'camera ' + cam.name + ': ' if several else ''}"
                             f"{m} has {len(model_labels(m))} intrinsics, got {k.size}")
    rolling = [bool(r) for r in (rolling_shutter if isinstance(rolling_shutter, (list, tuple))
                                 else [rolling_shutter] * n_cam)]
    ells = [float(x) for x in (line_delay if isinstance(line_delay, (list, tuple)) else [line_delay] * n_cam)]
    if len(rolling) != n_cam or len(ells) != n_cam or not all(np.isfinite(ells)):
        raise ValueError(f"calibrate_camera_imu: rolling_shutter and line_delay: one finite value, "
                         f"or one per camera ({n_cam})")
    t_imu = np.asarray(data.imu_times, dtype=float)
    gyro, accel = np.asarray(data.gyro, float), np.asarray(data.accel, float)
    if not (len(t_imu) == len(gyro) == len(accel)) or np.any(np.diff(t_imu) <= 0):
        raise ValueError("calibrate_camera_imu: IMU times must increase, one gyro and accel row each")

    # per camera: 1. its poses (world = target) by PnP on the corners' rays (any lens
    # model); 2.–3. its time offset and rotation: ω_imu(t + d) = R ω_cam(t)
    frames: list[list[tuple[float, Any]]] = []
    d0s: list[float] = []
    R_ics: list[np.ndarray] = []
    carried: list[tuple[float, SE3]] = []   # (IMU time, world_from_imu) starts for the spline
    for cam, k, m in zip(cameras, ks, models):
        fr = [(float(t), c) for t, c in zip(cam.frame_times, cam.corners) if c is not None and len(c[0]) >= 4]
        if len(fr) < 10:
            raise ValueError(f"calibrate_camera_imu: {len(fr)} frames with the target"
                             f"{' in camera ' + cam.name if several else ''}; need at least 10")
        t_cam = np.array([t for t, _ in fr])
        world_from_cam = [pose_from_rays(rays(k, np.asarray(uv, float), m), pts).inverse()
                          for _, (uv, pts) in fr]
        mid, w_cam = _angular_velocities(t_cam, world_from_cam)
        d0, R_ic = _offset_and_rotation(mid, w_cam, t_imu, gyro, max_offset)
        if offsets_start is not None:  # a previous fit's, more accurate
            d0 = offsets_start[len(frames)]
        # the spline starts from the poses whose rotation agrees with the gyroscope's
        # between frames (a PnP from a few corners can be far off, and one bad start
        # made the whole solve diverge)
        good = _consistent_frames(t_cam, world_from_cam, t_imu, gyro, d0, R_ic)
        cam_from_imu0 = SE3(SO3(R_ic), np.zeros(3)).inverse()
        carried += [(t_cam[i] + d0, world_from_cam[i] * cam_from_imu0) for i in np.flatnonzero(good)]
        frames.append(fr)
        d0s.append(d0)
        R_ics.append(R_ic)
    if common_clock:  # one offset: the frames' weighted mean (each camera's own search)
        d_common = float(np.average(d0s, weights=[len(f) for f in frames]))
        d0s = [d_common] * n_cam
    carried.sort(key=lambda x: x[0])
    t_good = np.array([t for t, _ in carried])
    poses_good = [p for _, p in carried]

    def nearest(t: float) -> SE3:
        return poses_good[int(np.clip(np.searchsorted(t_good, t), 0, len(t_good) - 1))]

    # 4. the spline: knots covering the IMU samples and the frames (at t_c + d)
    dt = float(knot_spacing)
    t_lo = max(t_imu[0], min(f[0][0] + d for f, d in zip(frames, d0s)) - max_offset)
    t_hi = min(t_imu[-1], max(f[-1][0] + d for f, d in zip(frames, d0s)) + max_offset)
    # knots at multiples of the spacing (a grid that does not depend on the data's start)
    t0 = dt * np.floor(t_lo / dt) - dt
    n_knots = int(np.floor((t_hi + 0.5 * dt - t0) / dt)) + 4
    inside = (t_imu >= t0) & (t_imu <= t0 + (n_knots - 3) * dt)
    # only the knots some measurement touches (an untouched one is undetermined)
    used = [spline_segment(t, t0, dt, n_knots)[0] for t in t_imu[inside]]
    used += [spline_segment(t + d, t0, dt, n_knots)[0] for f, d in zip(frames, d0s) for t, _ in f]
    first, last = min(used), max(used)
    t0 += first * dt
    n_knots = last - first + 4
    o = OptimizationProblem()
    ids: dict[str, int] = {}
    for j in range(n_knots):
        # control point j sits near time t0 + (j − 1) dt (the B-spline's centre)
        ids[f"knot{j}"] = o.add_random_var(nearest(t0 + (j - 1) * dt), name=f"knot{j}")
    inside = (t_imu >= t0) & (t_imu < t0 + (n_knots - 3) * dt)
    # bias segments over the IMU samples the spline covers (one segment: constant biases)
    t_in = t_imu[inside]
    n_seg = 1 if walks is None else max(1, int(np.ceil((t_in[-1] - t_in[0]) / bias_spacing)))
    bias_times = np.linspace(t_in[0], t_in[-1], n_seg + 1)
    segment = np.clip(np.searchsorted(bias_times, t_in, side="right") - 1, 0, n_seg - 1)
    _add_biases(o, ids, "", "", bias_times, walks)
    # gravity: the mean specific force in the world is −|g| ĝ when the motion averages out
    f_world = [nearest(t).rot.R @ a for t, a in zip(t_imu, accel)]
    g_dir = -np.mean(f_world, axis=0)
    ids["gravity"] = o.add_random_var(S2(g_dir / np.linalg.norm(g_dir)), name="gravity")
    for c in range(n_cam):
        suffix = f"[{c}]" if c else ""
        ids["imu_from_cam" + suffix] = o.add_random_var(SE3(SO3(R_ics[c]), np.zeros(3)),
                                                        name="imu_from_cam" + suffix)
        if c == 0 or not common_clock:
            ids["time_offset" + suffix] = o.add_random_var(Rn([d0s[c]]), name="time_offset" + suffix,
                                                           labels=["d"])
        else:
            ids["time_offset" + suffix] = ids["time_offset"]
        ids["intrinsics" + suffix] = o.add_random_var(Rn(ks[c]), name="intrinsics" + suffix,
                                                      labels=model_labels(models[c]),
                                                      fixed=not estimate_intrinsics)
        for v in ("imu_from_cam", "time_offset", "intrinsics"):
            ids[f"{v}[{c}]"] = ids[v + suffix]
        if rolling[c]:
            ids[f"line_delay[{c}]"] = o.add_random_var(Rn([ells[c]]), name=f"line_delay[{c}]",
                                                       labels=["ℓ"])
            if c == 0:
                ids["line_delay"] = ids["line_delay[0]"]
    knots = [ids[f"knot{j}"] for j in range(n_knots)]
    if imu_intrinsics:
        for kind in ("gyro_intrinsics", "accel_intrinsics"):
            ids[kind] = o.add_random_var(Rn(_IDENTITY_INTRINSICS), name=kind, labels=_INTRINSICS_LABELS)
    if accel_size_effect:
        ids["accel_size_effect"] = o.add_random_var(Rn(np.zeros(6)), name="accel_size_effect",
                                                    labels=["r_y.x", "r_y.y", "r_y.z", "r_z.x", "r_z.y", "r_z.z"])
    gn = NoiseModel.isotropic(3, gyro_sigma)
    an = NoiseModel.isotropic(3, accel_sigma)
    pn = NoiseModel.isotropic(2, pixel_sigma)
    for t, w, a, s in zip(t_in, gyro[inside], accel[inside], segment):
        i, u = spline_segment(t, t0, dt, n_knots)
        kn = knots[i:i + 4]
        o.add_factor(_core.spline_gyro_factor(kn, ids[f"gyro_bias[{s}]"], u, dt, w, gn,
                                              ids.get("gyro_intrinsics")),
                     group="gyroscope")
        o.add_factor(_core.spline_accel_factor(kn, ids[f"accel_bias[{s}]"], ids["gravity"], u, dt, a, an,
                                               gravity_magnitude, ids.get("accel_intrinsics"),
                                               ids.get("accel_size_effect")),
                     group="accelerometer")
    imus = _add_other_imus(o, ids, data, knots, t0, dt, bias_times, walks, gyro_sigma, accel_sigma,
                           other_imu_sigmas, gravity_magnitude, t_imu, gyro,
                           max_offset if imu_time_offsets else None, imu_intrinsics)
    groups = [f"reprojection {cam.name}" if several else "reprojection" for cam in cameras]
    for c, fr in enumerate(frames):
        ell_id = ids.get(f"line_delay[{c}]")
        for t, (uv, pts) in fr:
            for z, p in zip(uv, pts):
                # a rolling shutter's row is read ℓ·v after the frame's timestamp
                t_row = t + (ells[c] * z[1] if rolling[c] else 0.0)
                i, u = spline_segment(t_row + d0s[c], t0, dt, n_knots)
                o.add_factor(_core.spline_reprojection_factor(models[c], knots[i:i + 4],
                                                              ids[f"imu_from_cam[{c}]"],
                                                              ids[f"time_offset[{c}]"],
                                                              ids[f"intrinsics[{c}]"], t - (t0 + i * dt),
                                                              dt, z, pn, p, ell_id),
                             group=groups[c])
    # first the trajectory, biases and gravity with the offsets and the extrinsics held
    # at their start, then everything
    held = sorted({ids[f"{v}[{c}]"] for c in range(n_cam) for v in ("imu_from_cam", "time_offset")}
                  | {ids[f"line_delay[{c}]"] for c in range(n_cam) if rolling[c]}
                  | {ids[f"{v}[{k}]"] for k in range(1, len(imus) + 1)
                     for v in ("imu0_from_imu", "imu_time_offset", "imu_gyro_intrinsics",
                               "imu_accel_intrinsics") if f"{v}[{k}]" in ids}
                  | {ids[v] for v in ("gyro_intrinsics", "accel_intrinsics", "accel_size_effect") if v in ids})
    for vid in held:
        o.fix(vid)
    o.solve(method="auto", max_iterations=50, check_determined=False)
    for vid in held:
        o.unfix(vid)
    summary = o.solve(method="auto", max_iterations=200)
    offsets = [float(o[ids[f"time_offset[{c}]"]].vec[0]) for c in range(n_cam)]
    rms = o.rms()
    bad = [f"{g} RMS {rms[g]:.3g} (noise {s:.3g})" for g, s in
           [("gyroscope", gyro_sigma * np.sqrt(3)), ("accelerometer", accel_sigma * np.sqrt(3))]
           + [(g, sg * np.sqrt(3)) for name, gs, as_ in imus for g, sg in
              ((f"gyroscope {name}", gs), (f"accelerometer {name}", as_))]
           + [(g, pixel_sigma * np.sqrt(2)) for g in groups] if g in rms and not rms[g] < 10 * s]
    moved = [f"{'camera ' + cam.name + ': ' if several else ''}time offset {d:.4g} s from a start "
             f"of {d0:.4g} s" for cam, d, d0 in zip(cameras, offsets, d0s) if abs(d - d0) > knot_spacing]
    if moved or bad:
        error = _ImplausibleFit(f"calibrate_camera_imu: the solve did not reach a plausible answer "
                                f"({'; '.join(moved + bad)}): check the IMU and camera timestamps, "
                                f"the noise σ and the intrinsics")
        # only the IMU's residuals too large: a finer spline may follow the motion
        error.imu_only = not moved and all(b.startswith(("gyroscope", "accelerometer")) for b in bad)
        raise error
    gyro_biases = np.array([o[ids[f"gyro_bias[{s}]"]].vec for s in range(n_seg)])
    accel_biases = np.array([o[ids[f"accel_bias[{s}]"]].vec for s in range(n_seg)])
    imu_from_cams = [o[ids[f"imu_from_cam[{c}]"]] for c in range(n_cam)]
    return CameraImuCalibration(
        o, ids, t0, dt, imu_from_cams[0], offsets[0],
        gyro_biases.mean(axis=0), accel_biases.mean(axis=0),
        gravity_magnitude * np.asarray(o[ids["gravity"]].ambient), summary,
        {"time_offset": d0s[0], "imu_from_cam": SE3(SO3(R_ics[0]), np.zeros(3)),
         "time_offsets": d0s}, bias_times, gyro_biases, accel_biases,
        [cam.name for cam in cameras], imu_from_cams, offsets,
        [float(o[ids[f"line_delay[{c}]"]].vec[0]) if rolling[c] else None for c in range(n_cam)],
        ["imu0", *(name for name, _, _ in imus)],
        [SE3(), *(o[ids[f"imu0_from_imu[{k}]"]] for k in range(1, len(imus) + 1))],
        [_bias_means(o, ids, f"imu{k}." if k else "", "gyro_bias", n_seg) for k in range(len(imus) + 1)],
        [_bias_means(o, ids, f"imu{k}." if k else "", "accel_bias", n_seg) for k in range(len(imus) + 1)],
        [0.0, *(float(o[ids[f"imu_time_offset[{k}]"]].vec[0]) if f"imu_time_offset[{k}]" in ids else 0.0
                for k in range(1, len(imus) + 1))],
        gyro_intrinsics=intrinsics_matrix(o[ids["gyro_intrinsics"]].vec) if imu_intrinsics else None,
        accel_intrinsics=intrinsics_matrix(o[ids["accel_intrinsics"]].vec) if imu_intrinsics else None,
        accel_size_effect=o[ids["accel_size_effect"]].vec.reshape(2, 3) if accel_size_effect else None,
        imu_gyro_intrinsics=[intrinsics_matrix(o[ids[n]].vec) for n in
                             ["gyro_intrinsics", *(f"imu_gyro_intrinsics[{k}]" for k in range(1, len(imus) + 1))]]
        if imu_intrinsics else [],
        imu_accel_intrinsics=[intrinsics_matrix(o[ids[n]].vec) for n in
                              ["accel_intrinsics", *(f"imu_accel_intrinsics[{k}]" for k in range(1, len(imus) + 1))]]
        if imu_intrinsics else [])


# The adaptive knot spacing (calibrate_camera_imu with knot_spacing=None), chosen on
# bench/bench_camera_imu.py's motions of 1–3 Hz: from 0.05 s, halved while the IMU
# residuals exceed 1.5× the noise (at 3 Hz, 0.05 s left them 7.5× and refused one fit
# in four, 0.01 s brought them to 1.0×; at 1 Hz, 0.05 s gave 0.98× and 0.01 s 0.73×,
# a spline fitting the noise itself).
ADAPTIVE_START_SPACING = 0.05
ADAPTIVE_IMU_MISFIT = 1.5


class _ImplausibleFit(ValueError):
    """A fit whose residuals or offsets are implausible; ``imu_only`` when only the IMU's
    residuals were (a finer spline may follow the motion)."""

    imu_only = False


def _warn_reprojection(cal: CameraImuCalibration, pixel_sigma: float) -> None:
    """A camera's reprojection RMS above twice what pixel_sigma predicts: plausible but
    worse than the noise, so every σ is too small, and a model that misses something
    (a rolling shutter fitted as a global one: 2.8× on simulated recordings, the offset
    5–8 ms and imu_from_cam 15 mm off) should be named."""
    rms = cal.problem.rms()
    groups = [g for g in rms if g.startswith("reprojection")]
    for g, ell in zip(groups, cal.line_delays):
        if rms[g] > 2 * pixel_sigma * np.sqrt(2):
            hint = ("" if ell is not None else "; a rolling-shutter camera fitted as a global shutter "
                    "(rolling_shutter=True)")
            warnings.warn(f"calibrate_camera_imu: {g} RMS {rms[g]:.3g} px is "
                          f"{rms[g] / (pixel_sigma * np.sqrt(2)):.1f}× what pixel_sigma = "
                          f"{pixel_sigma:g} px predicts, so every σ is too small: the corners are "
                          f"noisier than that, or the model misses something (intrinsics of "
                          f"another focus or resolution{hint})", UserWarning, stacklevel=3)


# An unexcited direction: the worst-known direction of a camera's translation has a σ
# this many times the best-known one's, and above EXCITATION_MIN_SIGMA. On simulated
# recordings the ratio was 1.5–2.2 with rotation about every axis, 2.6–3.1 with a
# tenth of it about one axis, 10–17 (σ 4–6 mm) with a tenth about two, 20–50 (σ 14–25
# mm, the errors as large) with a fiftieth about two.
EXCITATION_RATIO = 5.0
EXCITATION_MIN_SIGMA = 1e-3  # m


def _warn_excitation(cal: CameraImuCalibration) -> None:
    """Names a translation direction of imu_from_cam the motion did not excite: it is
    seen through the rotation about the other axes (the lever arm R(t)·r), so a rig that
    hardly turned about an axis leaves the translation along it undetermined."""
    for c, (name, pose) in enumerate(zip(cal.camera_names, cal.imu_from_cams)):
        C = cal.problem.covariance(cal.ids[f"imu_from_cam[{c}]"])[:3, :3]
        ev, V = np.linalg.eigh(0.5 * (C + C.T))
        worst, best = np.sqrt(max(ev[-1], 0.0)), np.sqrt(max(ev[0], 0.0))
        if worst > EXCITATION_MIN_SIGMA and worst > EXCITATION_RATIO * best:
            axis = pose.rot.R.T @ V[:, -1]  # in the camera's frame
            axis = np.round(axis * np.sign(axis[np.argmax(np.abs(axis))]), 2) + 0.0  # no "-0.00"
            warnings.warn(f"calibrate_camera_imu: camera {name}: imu_from_cam's translation along "
                          f"({axis[0]:+.2f}, {axis[1]:+.2f}, {axis[2]:+.2f}) in the camera's frame is "
                          f"known to ±{worst * 1e3:.3g} mm, the best-known direction to ±{best * 1e3:.2g} mm: "
                          f"the recording hardly rotated about that axis (a translation is seen "
                          f"through the rotations about the others); record again turning the rig "
                          f"about every axis", UserWarning, stacklevel=3)


def _imu_misfit(cal: CameraImuCalibration, gyro_sigma: float, accel_sigma: float) -> float:
    """The first IMU's residual RMS over its noise, the larger of gyroscope and
    accelerometer (1: the spline follows the motion as closely as the noise allows)."""
    rms = cal.problem.rms()
    return max(rms["gyroscope"] / (gyro_sigma * np.sqrt(3)), rms["accelerometer"] / (accel_sigma * np.sqrt(3)))


def _add_other_imus(o: OptimizationProblem, ids: dict[str, int], data: CameraImuData, knots: list[int],
                    t0: float, dt: float, bias_times: np.ndarray, walks: tuple[float, float] | None,
                    gyro_sigma: float, accel_sigma: float, sigmas: list[tuple[float, float]] | None,
                    gravity_magnitude: float, t_body: np.ndarray, gyro_body: np.ndarray,
                    max_offset: float | None, intrinsics: bool = False) -> list[tuple[str, float, float]]:
    """The terms of every IMU after the first (calibrate_camera_imu's docstring): its pose
    imu0_from_imu (ids "imu0_from_imu[k]", the rotation started by aligning its gyroscope
    with the first one's, Wahba; the lever arm at 0), its clock's offset
    ("imu_time_offset[k]", started where the two gyroscopes align best within
    ±``max_offset``; none when None), its biases ("imu{k}.gyro_bias[s]",
    "imu{k}.accel_bias[s]", on the first IMU's segments), with ``intrinsics`` its own
    scale and misalignment ("imu_gyro_intrinsics[k]", "imu_accel_intrinsics[k]", started
    at the identity) and its samples inside the spline. Returns (name, gyro σ, accel σ)
    per IMU."""
    imus = data.other_imus
    if sigmas is not None and len(sigmas) != len(imus):
        raise ValueError(f"calibrate_camera_imu: {len(sigmas)} other_imu_sigmas for {len(imus)} other IMUs")
    n_knots = len(knots)
    n_seg = len(bias_times) - 1
    out = []
    for k, imu in enumerate(imus, start=1):
        name = imu.name or f"imu{k}"
        t = np.asarray(imu.imu_times, float)
        g, a = np.asarray(imu.gyro, float), np.asarray(imu.accel, float)
        if not (len(t) == len(g) == len(a)) or len(t) < 10 or np.any(np.diff(t) <= 0):
            raise ValueError(f"calibrate_camera_imu: IMU {name}: times must increase, one gyro and "
                             f"accel row each (at least 10)")
        gs, acs = sigmas[k - 1] if sigmas is not None else (gyro_sigma, accel_sigma)
        # ω_body(t + d) = R_k ω_k(t): the offset and the rotation of imu0_from_imu from both
        # gyroscopes
        if max_offset is None:
            d0 = 0.0
            w_body = np.stack([np.interp(t, t_body, gyro_body[:, j]) for j in range(3)], axis=1)
            R = rotation_between(g, w_body)
        else:
            d0, R = _offset_and_rotation(t, g, t_body, gyro_body, max_offset)
            ids[f"imu_time_offset[{k}]"] = o.add_random_var(Rn(np.array([d0])), name=f"time_offset_{name}")
        offset = ids.get(f"imu_time_offset[{k}]")
        ids[f"imu0_from_imu[{k}]"] = o.add_random_var(SE3(SO3(R), np.zeros(3)), name=f"imu0_from_{name}")
        t = t + d0  # on the first IMU's clock
        inside = (t >= t0) & (t < t0 + (n_knots - 3) * dt)
        if inside.sum() < 10:
            raise ValueError(f"calibrate_camera_imu: IMU {name}: {inside.sum()} samples inside the "
                             f"spline's time span; need at least 10 (its clock must be within max_offset of the first IMU's)")
        segment = np.clip(np.searchsorted(bias_times, t[inside], side="right") - 1, 0, n_seg - 1)
        _add_biases(o, ids, f"imu{k}.", name, bias_times, walks)
        for kind in ("gyro_bias", "accel_bias"):
            ids[f"imu_{kind}[{k}]"] = ids[f"imu{k}.{kind}"]
        if intrinsics:
            for kind in ("gyro_intrinsics", "accel_intrinsics"):
                ids[f"imu_{kind}[{k}]"] = o.add_random_var(Rn(_IDENTITY_INTRINSICS), name=f"{name}.{kind}",
                                                          labels=_INTRINSICS_LABELS)
        m_g, m_a = ids.get(f"imu_gyro_intrinsics[{k}]"), ids.get(f"imu_accel_intrinsics[{k}]")
        gn, an = NoiseModel.isotropic(3, gs), NoiseModel.isotropic(3, acs)
        pose = ids[f"imu0_from_imu[{k}]"]
        for ti, w, f, seg in zip(t[inside], g[inside], a[inside], segment):
            i, u = spline_segment(ti, t0, dt, n_knots)
            kn = knots[i:i + 4]
            o.add_factor(_core.spline_offset_gyro_factor(kn, pose, ids[f"imu{k}.gyro_bias[{seg}]"], u, dt, w, gn,
                                                         offset, d0, m_g),
                         group=f"gyroscope {name}")
            o.add_factor(_core.spline_offset_accel_factor(kn, pose, ids[f"imu{k}.accel_bias[{seg}]"],
                                                          ids["gravity"], u, dt, f, an, gravity_magnitude,
                                                          offset, d0, m_a),
                         group=f"accelerometer {name}")
        out.append((name, gs, acs))
    return out


def _add_biases(o: OptimizationProblem, ids: dict[str, int], key: str, imu: str,
                bias_times: np.ndarray, walks: tuple[float, float] | None) -> None:
    """An IMU's gyroscope and accelerometer biases, one per segment of ``bias_times``
    (ids "<key>gyro_bias[s]", "<key>gyro_bias" the first; variables named after ``imu``
    unless it is the first IMU, ""), consecutive segments tied by the random walks."""
    n_seg = len(bias_times) - 1
    for kind in ("gyro_bias", "accel_bias"):
        for s in range(n_seg):
            name = (f"{imu}." if imu else "") + (kind if s == 0 else f"{kind}[{s}]")
            ids[f"{key}{kind}[{s}]"] = o.add_random_var(Rn(np.zeros(3)), name=name, labels=["x", "y", "z"])
        ids[f"{key}{kind}"] = ids[f"{key}{kind}[0]"]
    if walks is not None and n_seg > 1:
        for kind, q in (("gyro_bias", walks[0]), ("accel_bias", walks[1])):
            # one vectorised measurement group: a Python call per evaluation, not per pair
            pairs = np.array([[ids[f"{key}{kind}[{s}]"], ids[f"{key}{kind}[{s + 1}]"]] for s in range(n_seg - 1)])
            o.add_measurements(np.zeros((n_seg - 1, 3)), bias_walk, pairs,
                               sigma=q * np.sqrt(bias_times[1] - bias_times[0]),
                               name=(f"{imu} " if imu else "") + f"{kind} walk")


def _bias_means(o: OptimizationProblem, ids: dict[str, int], key: str, kind: str, n_seg: int) -> np.ndarray:
    """The mean of an IMU's bias over its segments."""
    return np.mean([o[ids[f"{key}{kind}[{s}]"]].vec for s in range(n_seg)], axis=0)


def bias_walk(b0: Any, b1: Any) -> np.ndarray:
    """The changes of biases from one segment to the next (the random-walk terms; batches
    of Rn, one row per pair)."""
    return b1.vec - b0.vec


# The scale-misalignment model's 6 numbers (spline_terms.h): the identity, and their names.
_IDENTITY_INTRINSICS = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
_INTRINSICS_LABELS = ["s_x", "s_y", "s_z", "m_yx", "m_zx", "m_zy"]


def intrinsics_matrix(m: Any) -> np.ndarray:
    """The lower-triangular M of an IMU's [s_x, s_y, s_z, m_yx, m_zx, m_zy] (the reading
    is M x + b)."""
    s_x, s_y, s_z, m_yx, m_zx, m_zy = np.asarray(m, dtype=float).ravel()
    return np.array([[s_x, 0.0, 0.0], [m_yx, s_y, 0.0], [m_zx, m_zy, s_z]])
