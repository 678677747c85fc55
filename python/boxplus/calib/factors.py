"""The built-in C++ sensor factors of calibration, as functions of a problem.

Each function takes an :class:`boxplus.OptimizationProblem` first
(``add_board(o, z, intrinsics, world_from_rig, cam_from_rig, p_in_world, ...)``),
validates its input, builds one :class:`boxplus.NoiseModel` from the noise
keywords (exactly one of ``sigma``, ``covariance``, ``information``,
``noise``; none: σ = 1; see :mod:`boxplus.noise`), makes the C++ factor and
adds it with :meth:`OptimizationProblem.add_factor`. The problem keeps the
same model, so ``errors()`` and ``rms()`` are in the measurement's units
(pixels, m/s², disparity units). Each function is journalled
(:func:`boxplus._journal.journalled`), so problems built with them pickle and
copy like any other.

Frames are named ``b_from_a`` (the pose that maps a-coordinates to b) and
points ``p_in_b``. "rig" is the reference camera of a rig (MTKM's x):
``world_from_rig`` is the reference camera's pose in the world (board) frame,
``cam_from_rig`` takes it to the camera that measured (fix it to the identity
for one camera). The maths, blocks and units of each factor are in its header
under ``cpp/include/boxplus/factors/<domain>/``. The generic factors (prior,
relative pose, observed point) are methods of the problem itself.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from boxplus import _core
from boxplus._journal import journalled
from boxplus.calib.models import CAMERA_LABELS
from boxplus.losses import LossSpec
from boxplus.manifolds import SE3
from boxplus.noise import NoiseModel, noise_model
from boxplus.problem import OptimizationProblem

__all__ = ["add_board", "add_disparity", "add_dh_marker", "add_gravity", "add_marker",
           "add_projection"]


# accel block size → the C++ gravity model (factors/imu/gravity.h)
_GRAVITY_MODELS = {1: "scale", 4: "scale_bias", 6: "axis_scale_bias",
                   9: "axis_scale_bias_misalignment"}


def _what(o: OptimizationProblem, name: str | None, kind: str) -> str:
    return f"measurement '{name}'" if name else f"{kind} #{o.num_measurements}"


def _vector(value: Any, n: int, keyword: str, what: str) -> np.ndarray:
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"{what}: {keyword} must be {n} numbers, got {type(value).__name__}") from None
    if a.size != n:
        raise ValueError(f"{what}: {keyword} must have {n} entries, got shape {a.shape}")
    return a.reshape(n)


def _pose(value: Any, keyword: str, what: str) -> np.ndarray:
    if not isinstance(value, SE3):
        raise TypeError(f"{what}: {keyword} must be an SE3, got {type(value).__name__}")
    return value.ambient


def _camera_model(o: OptimizationProblem, intrinsics: int, model: str | None, what: str) -> str:
    """The camera model of a term: the one given, else the one the intrinsics variable was
    added with (:func:`boxplus.calib.add_camera` labels it with the model's parameters),
    else OpenCV's ``opencv5`` (every ``add_camera``'s default); checked against the
    variable's size."""
    given = model is not None
    if model is None:
        labels = list(o.labels(int(intrinsics)))
        model = next((m for m, names in CAMERA_LABELS.items() if list(names) == labels), "opencv5")
    try:
        size = _core.camera_model_size(model)
    except (ValueError, RuntimeError) as e:
        raise ValueError(f"{what}: {e}") from None
    have = o.codec(intrinsics).ambient_size
    if have != size:
        raise ValueError(f"{what}: camera model '{model}' needs {size} intrinsics, variable "
                         f"'{o.variable_name(int(intrinsics))}' has {have}"
                         + ("" if given else " (give the term's model=)"))
    return model


# ---- camera ------------------------------------------------------------------------------
@journalled
def add_projection(
    o: OptimizationProblem, z: Any, intrinsics: int, world_from_rig: int, cam_from_rig: int,
    p_in_world: Any,
    sigma: Any = None, covariance: Any = None, information: Any = None,
    noise: NoiseModel | None = None, model: str | None = None, loss: LossSpec = None,
    name: str | None = None, group: str | None = None,
) -> int:
    """One known point seen by a camera (factors/camera/point_projection.h).

    r = W (π(k, cam_from_rig · world_from_rig⁻¹ · p_in_world) − z), z (2,) in
    pixels. ``intrinsics`` holds ``camera_model_size(model)`` numbers in the
    model's order (simple_radial: [f, cx, cy, k1]; pinhole: [fx, fy, cx, cy];
    radial2: + [k1, k2]; opencv5: + [k1, k2, p1, p2, k3]; rational: + [k1, k2, p1,
    p2, k3, k4, k5, k6]; kannala_brandt: + [k1, k2, k3, k4]; double_sphere: + [ξ, α];
    :data:`boxplus.calib.models.CAMERA_LABELS`; by default the model the intrinsics
    were added with, :func:`boxplus.calib.add_camera`, else ``opencv5``); ``world_from_rig``
    and ``cam_from_rig`` are SE3 variables. RMS reports group these as
    ``projection[model]``.
    """
    what = _what(o, name, "projection")
    ids = o.check_ids([intrinsics, world_from_rig, cam_from_rig], what)
    model = _camera_model(o, intrinsics, model, what)
    nm = noise_model(2, sigma, covariance, information, noise, what)
    f = _core.point_projection_factor(model, ids[0], ids[1], ids[2], _vector(z, 2, "z", what), nm,
                                      _vector(p_in_world, 3, "p_in_world", what))
    return o.add_factor(f, loss, name, group or f"projection[{model}]")


@journalled
def add_board(
    o: OptimizationProblem, z: Any, intrinsics: int, world_from_rig: int, cam_from_rig: int,
    p_in_world: Any,
    sigma: Any = None, covariance: Any = None, information: Any = None,
    noise: NoiseModel | None = None, model: str | None = None, loss: LossSpec = None,
    name: str | None = None, group: str | None = None,
) -> int:
    """All visible points of a board in one C++ factor (factors/camera/board.h).

    r_j = W (π(k, cam_from_rig · world_from_rig⁻¹ · p_in_world_j) − z_j);
    ``z`` (N, 2) pixels, ``p_in_world`` (N, 3) the same points in the board
    ("world") frame; the noise is that of one corner (2-dim), shared by the
    points. ``model`` is any camera model (:data:`boxplus.calib.models.CAMERA_LABELS`; by
    default the one the intrinsics were added with, :func:`boxplus.calib.add_camera`,
    else ``opencv5``).
    ``group`` names the measurement group in RMS reports (default ``board[model]``).
    """
    what = _what(o, name, "board")
    ids = o.check_ids([intrinsics, world_from_rig, cam_from_rig], what)
    zz = np.asarray(z, dtype=float)
    pw = np.asarray(p_in_world, dtype=float)
    if zz.ndim != 2 or zz.shape[1] != 2 or pw.shape != (len(zz), 3) or len(zz) == 0:
        raise ValueError(f"{what}: z must be (N, 2) and p_in_world (N, 3) with N >= 1, got "
                         f"{zz.shape} and {pw.shape}")
    if not (np.all(np.isfinite(zz)) and np.all(np.isfinite(pw))):
        raise ValueError(f"{what}: non-finite points (an undetected board?)")
    model = _camera_model(o, intrinsics, model, what)
    nm = noise_model(2, sigma, covariance, information, noise, what)
    f = _core.board_factor(model, ids[0], ids[1], ids[2], np.ascontiguousarray(zz), nm, np.ascontiguousarray(pw))
    return o.add_factor(f, loss, name, group or f"board[{model}]")


# ---- kinematics ------------------------------------------------------------------
@journalled
def add_marker(
    o: OptimizationProblem, z: Any, intrinsics: int, base_from_rig: int, p_in_hand: int, cam_from_rig: int,
    base_from_hand: Any, sigma: Any = None, covariance: Any = None, information: Any = None,
    noise: NoiseModel | None = None, model: str | None = None, loss: LossSpec = None,
    name: str | None = None, group: str | None = None,
) -> int:
    """A marker on a hand, ``base_from_hand`` (SE3) from forward kinematics
    (factors/kinematics/marker.h): r = W (π(k, cam_from_rig · base_from_rig⁻¹ ·
    base_from_hand · p_in_hand) − z), z in pixels."""
    what = _what(o, name, "marker")
    ids = o.check_ids([intrinsics, base_from_rig, p_in_hand, cam_from_rig], what)
    model = _camera_model(o, intrinsics, model, what)
    pose = _pose(base_from_hand, "base_from_hand", what)
    nm = noise_model(2, sigma, covariance, information, noise, what)
    f = _core.marker_factor(model, ids[0], ids[1], ids[2], ids[3], _vector(z, 2, "z", what), nm, pose)
    return o.add_factor(f, loss, name, group or "marker")


@journalled
def add_dh_marker(
    o: OptimizationProblem, z: Any, intrinsics: int, base_from_rig: int, p_in_hand: int, cam_from_rig: int,
    dh: int, joints: Any, base_from_chain: Any = None, flange_from_hand: Any = None,
    sigma: Any = None, covariance: Any = None, information: Any = None,
    noise: NoiseModel | None = None, model: str | None = None, loss: LossSpec = None,
    name: str | None = None, group: str | None = None,
) -> int:
    """A marker through a DH chain with unknown link parameters ``dh`` (an Rn(4n)
    variable: per joint [θ offset, d, a, α]) and joint readings ``joints`` (rad):
    base_from_hand = base_from_chain · A₁ … Aₙ · flange_from_hand
    (factors/kinematics/marker.h, dh.h); the constant ends default to the identity."""
    what = _what(o, name, "DH marker")
    ids = o.check_ids([intrinsics, base_from_rig, p_in_hand, cam_from_rig, dh], what)
    model = _camera_model(o, intrinsics, model, what)
    q = np.asarray(joints, float).reshape(-1)
    if o.codec(dh).ambient_size != 4 * len(q):
        raise ValueError(f"{what}: {len(q)} joint readings need a dh variable of {4 * len(q)} "
                         f"numbers, '{o.variable_name(int(dh))}' has "
                         f"{o.codec(dh).ambient_size}")
    pre = _pose(SE3() if base_from_chain is None else base_from_chain, "base_from_chain", what)
    post = _pose(SE3() if flange_from_hand is None else flange_from_hand, "flange_from_hand", what)
    nm = noise_model(2, sigma, covariance, information, noise, what)
    f = _core.dh_marker_factor(model, ids[0], ids[1], ids[2], ids[3], ids[4], _vector(z, 2, "z", what), nm, q, pre, post)
    return o.add_factor(f, loss, name, group or "marker")


# ---- IMU -------------------------------------------------------------------------
@journalled
def add_gravity(
    o: OptimizationProblem, z: Any, world_from_rig: int, imu_from_rig: int, accel: int | None = None,
    g_in_world: Any = (0.0, 0.0, -9.81), sigma: Any = None, covariance: Any = None,
    information: Any = None, noise: NoiseModel | None = None, loss: LossSpec = None,
    name: str | None = None, group: str = "gravity",
) -> int:
    """Gravity read by an accelerometer (factors/imu/gravity.h):
    r = W (T R(imu_from_rig) R(world_from_rig)ᵀ g_in_world + b − z), in the
    unit of z (m/s², or raw counts).

    ``imu_from_rig`` is an SO3 variable (only the rotation enters) or an SE3
    one (its translation is then undetermined by gravity). ``accel`` is the
    accelerometer model, chosen by its size:

    * None: T = I, b = 0 (rotation only);
    * Rn(1) [s]: T = s I;  Rn(4) [s, bx, by, bz]: T = s I;
    * Rn(6) [sx, sy, sz, bx, by, bz]: T = diag(s), per-axis scale and bias;
    * Rn(9) [sx, sy, sz, bx, by, bz, mxy, mxz, myz]: T = diag(s) U with the
      misalignment U = [[1, mxy, mxz], [0, 1, myz], [0, 0, 1]].

    For raw counts, s is in counts per unit of ``g_in_world`` and b in counts.
    """
    what = _what(o, name, "gravity")
    ids = o.check_ids([world_from_rig, imu_from_rig] + ([] if accel is None else [accel]),
                          what)
    if o.codec(world_from_rig).name != "SE3":
        raise TypeError(f"{what}: world_from_rig must be an SE3 variable, got "
                        f"{o.codec(world_from_rig).name}")
    imu_size = {"SO3": 4, "SE3": 7}.get(o.codec(imu_from_rig).name)
    if imu_size is None:
        raise TypeError(f"{what}: imu_from_rig must be an SO3 or SE3 variable, got "
                        f"{o.codec(imu_from_rig).name}")
    if accel is None:
        model = "rotation"
    else:
        n = o.codec(accel).ambient_size
        named = _GRAVITY_MODELS.get(n)
        if named is None or o.codec(accel).name != f"Rn({n})":
            raise ValueError(f"{what}: accel must be Rn(1) [s], Rn(4) [s, b], Rn(6) [s_xyz, "
                             f"b_xyz] or Rn(9) [s_xyz, b_xyz, mxy, mxz, myz], got "
                             f"{o.codec(accel).name}")
        model = named
    nm = noise_model(3, sigma, covariance, information, noise, what)
    f = _core.gravity_factor(model, ids[0], ids[1], ids[2] if accel is not None else -1,
                             _vector(z, 3, "z", what), nm, _vector(g_in_world, 3, "g_in_world", what),
                             imu_size)
    return o.add_factor(f, loss, name, group)


# ---- depth -----------------------------------------------------------------------
@journalled
def add_disparity(
    o: OptimizationProblem, d: float, world_from_rig: int, cam_from_rig: int, disparity_params: int,
    p_in_world: Any, sigma: Any = None, covariance: Any = None, information: Any = None,
    noise: NoiseModel | None = None, loss: LossSpec = None, name: str | None = None,
    group: str = "disparity",
) -> int:
    """Kinect-style disparity d = a / Z + b of a board point (factors/depth/disparity.h);
    ``disparity_params`` an Rn(2) variable [a, b]; 1-dim noise in disparity units."""
    what = _what(o, name, "disparity")
    ids = o.check_ids([world_from_rig, cam_from_rig, disparity_params], what)
    nm = noise_model(1, sigma, covariance, information, noise, what)
    f = _core.disparity_factor(ids[0], ids[1], ids[2], float(_vector(d, 1, "d", what)[0]), nm,
                               _vector(p_in_world, 3, "p_in_world", what))
    return o.add_factor(f, loss, name, group)
