"""Every camera model of the C++ factors in numpy: names of the intrinsics,
projection, the inverse (viewing rays), OpenCV's layout, and initial values.

The models and their maths are those of ``cpp/include/boxplus/factors/camera/models.h``:

* the pinhole family (``simple_radial`` [f, cx, cy, k1], ``pinhole`` [fx, fy,
  cx, cy], ``radial1`` [.., k1], ``radial2`` [.., k1, k2], ``opencv5`` [fx, fy,
  cx, cy, k1, k2, p1, p2, k3]): OpenCV's Brown–Conrady model with the missing
  coefficients 0 (``projectPoints``);
* ``rational`` [fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6]: OpenCV's
  ``CALIB_RATIONAL_MODEL``, the radial factor (1 + k1 r² + k2 r⁴ + k3 r⁶) /
  (1 + k4 r² + k5 r⁴ + k6 r⁶);
* ``kannala_brandt`` [fx, fy, cx, cy, k1, k2, k3, k4]: OpenCV's ``cv2.fisheye``
  (zero skew) and Kalibr's ``equidistant``, θ_d = θ (1 + k1 θ² + … + k4 θ⁸);
* ``double_sphere`` [fx, fy, cx, cy, ξ, α] (Usenko et al. 2018, eqs. 40–50).

Pixels are (N, 2) arrays, camera-frame points (N, 3).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from boxplus import _core

__all__ = ["CAMERA_LABELS", "OPENCV_DISTORTION", "camera_matrix", "distort", "initial_intrinsics",
           "intrinsics_vector", "is_fisheye", "model_labels", "project", "project_pinhole", "rays",
           "undistort"]

# The pinhole family: Brown–Conrady with some coefficients left out.
_PINHOLE_FAMILY: dict[str, list[str]] = {
    "simple_radial": ["f", "cx", "cy", "k1"],
    "pinhole": ["fx", "fy", "cx", "cy"],
    "radial1": ["fx", "fy", "cx", "cy", "k1"],
    "radial2": ["fx", "fy", "cx", "cy", "k1", "k2"],
    "opencv5": ["fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"],
}
_BROWN_CONRADY = ["k1", "k2", "p1", "p2", "k3"]

CAMERA_LABELS: dict[str, list[str]] = {
    **_PINHOLE_FAMILY,
    "rational": ["fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"],
    "kannala_brandt": ["fx", "fy", "cx", "cy", "k1", "k2", "k3", "k4"],
    "double_sphere": ["fx", "fy", "cx", "cy", "xi", "alpha"],
}

# One list of models, C++'s (camera/models.h): a model added there and not here fails
# at import, not in a user's calibration.
if sorted(CAMERA_LABELS) != sorted(_core.camera_model_names()):
    raise ImportError(f"boxplus.calib.models: labels for {sorted(CAMERA_LABELS)}, the C++ camera "
                      f"terms have {sorted(_core.camera_model_names())}")

# The distortion vector of each model in OpenCV's order (cv2.calibrateCamera's
# for the pinhole family, cv2.fisheye's for kannala_brandt); double_sphere has
# no OpenCV counterpart and lists its own two coefficients.
OPENCV_DISTORTION: dict[str, list[str]] = {
    **dict.fromkeys(_PINHOLE_FAMILY, _BROWN_CONRADY),
    "rational": ["k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"],
    "kannala_brandt": ["k1", "k2", "k3", "k4"],
    "double_sphere": ["xi", "alpha"],
}


def model_labels(model: str) -> list[str]:
    """The names of a camera model's intrinsics, in order (ValueError for unknown models)."""
    try:
        return CAMERA_LABELS[model]
    except KeyError:
        raise ValueError(f"unknown camera model '{model}' (expected one of {sorted(CAMERA_LABELS)})") from None


def is_fisheye(model: str) -> bool:
    """Whether the model is a wide-angle one (not a distorted pinhole)."""
    model_labels(model)
    return model in ("kannala_brandt", "double_sphere")


def _values(k: np.ndarray, model: str) -> dict[str, float]:
    labels = model_labels(model)
    k = np.asarray(k, dtype=float).reshape(-1)
    if k.size != len(labels):
        raise ValueError(f"camera model '{model}' has {len(labels)} intrinsics {labels}, got {k.size}")
    v = dict(zip(labels, k))
    v.setdefault("fx", v.get("f", np.nan))
    v.setdefault("fy", v.get("f", np.nan))
    return v


def camera_matrix(k: np.ndarray, model: str) -> tuple[np.ndarray, np.ndarray]:
    """(K 3×3, distortion in OpenCV's order, :data:`OPENCV_DISTORTION`) of a model's
    intrinsics vector: 5 numbers for the pinhole family (missing ones 0), 8 for
    ``rational``, cv2.fisheye's 4 for ``kannala_brandt``, [ξ, α] for ``double_sphere``."""
    v = _values(k, model)
    K = np.array([[v["fx"], 0, v["cx"]], [0, v["fy"], v["cy"]], [0, 0, 1.0]])
    return K, np.array([v.get(n, 0.0) for n in OPENCV_DISTORTION[model]])


def intrinsics_vector(K: np.ndarray, model: str, dist: Sequence[float] | np.ndarray = ()) -> np.ndarray:
    """The model's intrinsics vector from a 3×3 K and the distortion in OpenCV's order
    (:data:`OPENCV_DISTORTION`; missing trailing ones are 0)."""
    labels = model_labels(model)
    K = np.asarray(K, dtype=float)
    names = OPENCV_DISTORTION[model]
    d = np.asarray(dist, dtype=float).reshape(-1)
    if d.size > len(names) and np.any(d[len(names):] != 0):
        raise ValueError(f"camera model '{model}' has the distortion {names}, got {d.size} "
                         f"non-zero coefficients")
    v = dict(zip(names, list(d) + [0.0] * len(names)))
    v.update(f=(K[0, 0] + K[1, 1]) / 2, fx=K[0, 0], fy=K[1, 1], cx=K[0, 2], cy=K[1, 2])
    return np.array([v[n] for n in labels], dtype=float)


def initial_intrinsics(K: np.ndarray, model: str) -> np.ndarray:
    """Zhang-style initial intrinsics: the pinhole K of the closed form
    (:func:`boxplus.calib.zhang.init_camera`) in the model that equals the
    pinhole camera — zero distortion; for ``kannala_brandt`` θ_d = θ (an
    equidistant lens, cv2.fisheye's start); for ``double_sphere`` ξ = α = 0
    (exactly the pinhole)."""
    return intrinsics_vector(K, model)


# ---- the pinhole family (Brown–Conrady) -------------------------------------------

def distort(x: np.ndarray, k1=0.0, k2=0.0, p1=0.0, p2=0.0, k3=0.0) -> np.ndarray:
    """OpenCV's distortion of normalised coordinates x (..., 2).

    With r² = x² + y² and ρ = 1 + k1 r² + k2 r⁴ + k3 r⁶:
    x_d = x ρ + 2 p1 x y + p2 (r² + 2x²), y_d = y ρ + p1 (r² + 2y²) + 2 p2 x y.
    The coefficients broadcast against x[..., :1] (scalars or (N, 1) per row).
    """
    x0, x1 = x[..., 0:1], x[..., 1:2]
    r2 = x0 * x0 + x1 * x1
    # Terms whose coefficients are the scalar 0 are skipped: the radial-only
    # models are evaluated in solvers' inner loops.
    if _zero(k2) and _zero(k3):
        rad = 1.0 + k1 * r2
    else:
        rad = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
    if _zero(p1) and _zero(p2):
        return x * rad
    xd = x0 * rad + 2.0 * p1 * x0 * x1 + p2 * (r2 + 2.0 * x0 * x0)
    yd = x1 * rad + p1 * (r2 + 2.0 * x1 * x1) + 2.0 * p2 * x0 * x1
    return np.concatenate([xd, yd], axis=-1)


def _zero(c) -> bool:
    return np.ndim(c) == 0 and c == 0


def undistort(xd: np.ndarray, dist: Sequence[float] | np.ndarray, iters: int = 20) -> np.ndarray:
    """Normalised coordinates x (N, 2) with ``distort(x, *dist)`` ≈ xd (N, 2).

    Fixed-point iteration x ← (x_d − tangential(x)) / ρ(x) from x = x_d
    (OpenCV's ``undistortPoints``); converges for the moderate distortion of
    real lenses.
    """
    k1, k2, p1, p2, k3 = dist
    u = np.array(xd, dtype=float)
    for _ in range(iters):
        r2 = np.sum(u**2, axis=1)
        rad = 1 + r2 * (k1 + r2 * (k2 + r2 * k3))
        dx = 2 * p1 * u[:, 0] * u[:, 1] + p2 * (r2 + 2 * u[:, 0] ** 2)
        dy = p1 * (r2 + 2 * u[:, 1] ** 2) + 2 * p2 * u[:, 0] * u[:, 1]
        u = (xd - np.column_stack([dx, dy])) / rad[:, None]
    return u


def project_pinhole(p_in_cam: np.ndarray, f, c, k1=0.0, k2=0.0, p1=0.0, p2=0.0, k3=0.0) -> np.ndarray:
    """Pixels (..., 2) of camera-frame points (..., 3): f · distort(p_xy / p_z) + c.

    ``f`` is one focal length or [fx, fy], ``c`` = [cx, cy]; all broadcast,
    so batches of intrinsics ((N, 1), (N, 2)) project row by row.
    """
    p = np.asarray(p_in_cam, dtype=float)
    return f * distort(p[..., :2] / p[..., 2:3], k1, k2, p1, p2, k3) + c


# ---- every model ----------------------------------------------------------------------

def project(k: np.ndarray, p_in_cam: np.ndarray, model: str = "opencv5") -> np.ndarray:
    """Pixels (N, 2) of camera-frame points (N, 3) (the C++ factor's model)."""
    p = np.atleast_2d(np.asarray(p_in_cam, dtype=float))
    v = _values(k, model)
    f, c = np.array([v["fx"], v["fy"]]), np.array([v["cx"], v["cy"]])
    if model == "kannala_brandt":
        r = np.hypot(p[:, 0], p[:, 1])
        th = np.arctan2(r, p[:, 2])
        t2 = th * th
        poly = 1 + t2 * (v["k1"] + t2 * (v["k2"] + t2 * (v["k3"] + t2 * v["k4"])))
        with np.errstate(invalid="ignore", divide="ignore"):
            s = np.where(r > 1e-15, th * poly / np.where(r > 1e-15, r, 1.0), 1 / p[:, 2])
        return f * p[:, :2] * s[:, None] + c
    if model == "double_sphere":
        xi, al = v["xi"], v["alpha"]
        d1 = np.linalg.norm(p, axis=1)
        zs = xi * d1 + p[:, 2]
        d2 = np.sqrt(p[:, 0] ** 2 + p[:, 1] ** 2 + zs**2)
        return f * p[:, :2] / (al * d2 + (1 - al) * zs)[:, None] + c
    x = p[:, :2] / p[:, 2:3]
    if model == "rational":
        r2 = np.sum(x**2, axis=1, keepdims=True)
        num = 1 + r2 * (v["k1"] + r2 * (v["k2"] + r2 * v["k3"]))
        den = 1 + r2 * (v["k4"] + r2 * (v["k5"] + r2 * v["k6"]))
        p1, p2 = v["p1"], v["p2"]
        xy = x[:, 0:1] * x[:, 1:2]
        tang = np.column_stack([2 * p1 * xy[:, 0] + p2 * (r2[:, 0] + 2 * x[:, 0] ** 2),
                                p1 * (r2[:, 0] + 2 * x[:, 1] ** 2) + 2 * p2 * xy[:, 0]])
        return f * (x * num / den + tang) + c
    return project_pinhole(p, f, c, *[v.get(n, 0.0) for n in _BROWN_CONRADY])


def rays(k: np.ndarray, uv: np.ndarray, model: str = "opencv5", iters: int = 30) -> np.ndarray:
    """Viewing rays (N, 3) of pixels uv (N, 2), the inverse of :func:`project`:
    [x, y, 1] (undistorted normalised coordinates) for the pinhole family, unit
    vectors for the wide-angle models (whose rays may point sideways or back); NaN
    for a pixel outside a double sphere's field (no ray reaches it)."""
    uv = np.atleast_2d(np.asarray(uv, dtype=float))
    v = _values(k, model)
    m = (uv - [v["cx"], v["cy"]]) / [v["fx"], v["fy"]]
    if model == "kannala_brandt":
        # Newton on θ (1 + k1 θ² + … + k4 θ⁸) = θ_d from θ = θ_d (OpenCV's undistortPoints).
        td = np.hypot(m[:, 0], m[:, 1])
        ks = [v["k1"], v["k2"], v["k3"], v["k4"]]
        th = td.copy()
        for _ in range(iters):
            t2 = th * th
            g = th * (1 + t2 * (ks[0] + t2 * (ks[1] + t2 * (ks[2] + t2 * ks[3])))) - td
            dg = 1 + t2 * (3 * ks[0] + t2 * (5 * ks[1] + t2 * (7 * ks[2] + t2 * 9 * ks[3])))
            th = th - g / dg
        with np.errstate(invalid="ignore", divide="ignore"):
            s = np.where(td > 1e-15, np.sin(th) / np.where(td > 1e-15, td, 1.0), 1.0)
        return np.column_stack([m * s[:, None], np.cos(th)])
    if model == "double_sphere":
        xi, al = v["xi"], v["alpha"]
        r2 = np.sum(m**2, axis=1)
        with np.errstate(invalid="ignore"):  # beyond r² = 1/(2α − 1): NaN, by design
            mz = (1 - al * al * r2) / (al * np.sqrt(1 - (2 * al - 1) * r2) + 1 - al)
            fac = (mz * xi + np.sqrt(mz * mz + (1 - xi * xi) * r2)) / (mz * mz + r2)
            out = fac[:, None] * np.column_stack([m, mz]) - [0, 0, xi]
            return out / np.linalg.norm(out, axis=1, keepdims=True)
    if model == "rational":
        x = m.copy()
        p1, p2 = v["p1"], v["p2"]
        for _ in range(iters):
            r2 = np.sum(x**2, axis=1)
            rad = (1 + r2 * (v["k1"] + r2 * (v["k2"] + r2 * v["k3"]))) / \
                (1 + r2 * (v["k4"] + r2 * (v["k5"] + r2 * v["k6"])))
            dx = 2 * p1 * x[:, 0] * x[:, 1] + p2 * (r2 + 2 * x[:, 0] ** 2)
            dy = p1 * (r2 + 2 * x[:, 1] ** 2) + 2 * p2 * x[:, 0] * x[:, 1]
            x = (m - np.column_stack([dx, dy])) / rad[:, None]
        return np.column_stack([x, np.ones(len(x))])
    x = undistort(m, [v.get(n, 0.0) for n in _BROWN_CONRADY])
    return np.column_stack([x, np.ones(len(x))])
