"""Standard rigs in a few calls: cameras as variables with named intrinsics,
mono and stereo calibration built from the C++ board factor, with closed-form
initial values (:mod:`boxplus.calib.init`).

Frames: ``world`` is the board frame; ``world_from_cam_i`` is the reference
camera's pose in the board frame for view i; ``right_from_left`` takes points
of the left camera into the right camera. Camera models: see
``cpp/include/boxplus/factors/camera/models.h`` ("opencv5" is OpenCV's default
k1 k2 p1 p2 k3; "radial2" k1 k2; "radial1" k1).
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from boxplus import blas_threads
from boxplus import problem as _problem
from boxplus._core import SolveSummary
from boxplus._optional import require
from boxplus.calib.factors import add_board
from boxplus.calib.fold import check_fold_over
from boxplus.calib.init import (
    CAMERA_LABELS,
    camera_matrix,
    check_solved_views,
    check_views,
    init_camera,
    intrinsics_vector,
    mean_pose,
    relative_pose_init,
)
from boxplus.calib.io import CalibratedCamera, to_opencv
from boxplus.calib.models import model_labels
from boxplus.calib.regularize import (
    DEFAULT_PRIOR_SIGMA,
    REGULARIZED_BY_DEFAULT,
    add_distortion_prior,
)
from boxplus.manifolds import SE3, Rn

__all__ = ["add_camera", "Calibration", "DroppedCorner", "IntrinsicsShift", "RigConsistencyWarning",
           "SkippedView", "calibrate_mono", "calibrate_rig", "calibrate_stereo", "detect_corners"]


def _one_blas_thread(fn: Any) -> Any:
    """Runs a calibration's linear algebra (Zhang's SVDs, the solve, the report) on one
    BLAS thread: its matrices are small, and threads of a busy machine's BLAS made
    calibrate_stereo 4–6× slower under load."""

    @functools.wraps(fn)
    def call(*args: Any, **kwargs: Any) -> Any:
        with blas_threads.limit(1):
            return fn(*args, **kwargs)

    return call

# Default k of robust=True: a corner is dropped when its error exceeds k σ̂
# (σ̂ per image coordinate, from the median absolute error). For Gaussian
# noise ‖e‖/σ is Rayleigh, P(‖e‖ > 5σ) = exp(−12.5) ≈ 4e-6: good corners stay.
ROBUST_K = 5.0


def add_camera(o: _problem.OptimizationProblem, name: str, K: np.ndarray, model: str = "opencv5",
               dist: Sequence[float] = (), fixed: bool = False) -> int:
    """Adds the intrinsics of a camera (an Rn of the model's size, labelled fx, fy, ...);
    ``dist`` in OpenCV's order for the model (missing ones 0: Zhang's start)."""
    k = intrinsics_vector(np.asarray(K, float), model, dist)
    return o.add_random_var(Rn(k), fixed=fixed, name=name, labels=CAMERA_LABELS[model])


@dataclass
class DroppedCorner:
    """A corner the robust option removed: its camera, view (index and name),
    index in the target, and its error (px) when it was dropped."""

    camera: str
    view: int
    view_name: str
    corner: int
    error_px: float


@dataclass
class SkippedView:
    """A view a camera could not use, and why (named by its index and view name)."""

    camera: str
    view: int
    view_name: str
    reason: str


def _unusable(det: tuple[np.ndarray, np.ndarray]) -> str | None:
    """Why a detection cannot place the board (None when it can): its corners are
    collinear in the target or in the image, so no homography exists."""
    z, obj = det
    for pts, where in ((obj[:, :2], "on the target"), (z, "in the image")):
        c = pts - pts.mean(axis=0)
        s = np.linalg.svd(c, compute_uv=False)
        if s[0] == 0 or s[1] < 1e-6 * s[0]:
            return f"its {len(z)} corners are collinear {where} (no homography places the board)"
    return None


@dataclass
class _Obs:
    """The detections of one camera in one view: pixels z (N, 2), the target points
    p_in_board (N, 3) and their indices in the target (for reports)."""

    camera: str
    view: int
    z: np.ndarray
    obj: np.ndarray
    corners: np.ndarray


@dataclass
class Calibration:
    """A solved calibration: the problem, ids of its variables, the solve result.

    ``ids`` names the variables: each camera's intrinsics by the camera's name,
    ``<cam>_from_<reference>`` for the other cameras' poses; ``view_ids``
    {camera: board measurement ids}, ``view_index`` {camera: the view (image)
    index of each}, ``view_names`` a name per view (e.g. file names),
    ``world_from_ref`` the pose variable of each view (None when no camera
    saw it), ``dropped`` the corners the robust option removed.
    """

    problem: _problem.OptimizationProblem
    model: str
    ids: dict[str, int]
    view_ids: dict[str, list[int]] = field(default_factory=dict)
    result: SolveSummary | None = None
    image_size: dict[str, tuple[int, int]] = field(default_factory=dict)
    models: dict[str, str] = field(default_factory=dict)
    reference: str = ""
    view_index: dict[str, list[int]] = field(default_factory=dict)
    view_names: list[str] = field(default_factory=list)
    world_from_ref: list[int | None] = field(default_factory=list)
    dropped: list[DroppedCorner] = field(default_factory=list)
    skipped: list[SkippedView] = field(default_factory=list)
    intrinsics_shift: list[Any] = field(default_factory=list)
    # the distortion priors of regularize= (boxplus.calib.regularize), one per camera
    priors: list[Any] = field(default_factory=list)
    observations: list[_Obs] = field(default_factory=list, repr=False)
    # reports by (rescale, problem generation): computed once per state (report())
    _reports: dict[tuple[bool, int], Any] = field(default_factory=dict, repr=False, compare=False)

    def camera(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """(K, distortion in OpenCV's order for the camera's model) of a camera."""
        return camera_matrix(self.problem[self.ids[name]].vec, self.models.get(name, self.model))

    def todict(self) -> dict[str, Any]:
        """Plain Python types only (``json.dumps`` takes it): the model(s), the
        reference camera, each camera's K, distortion (OpenCV's order) and image size,
        every variable of ``ids`` as its ambient vector (poses [p, q], q = [x, y, z, w]),
        the view names, the RMS, the distortion priors and the solve summary."""
        cameras = {}
        for name in self.view_ids:
            K, dist = self.camera(name)
            cameras[name] = {"model": self.models.get(name, self.model),
                             "K": np.asarray(K, dtype=float).tolist(),
                             "distortion": np.asarray(dist, dtype=float).ravel().tolist(),
                             "image_size": list(self.image_size.get(name, ()))}
        return {
            "model": self.model,
            "reference": self.reference,
            "cameras": cameras,
            "variables": {k: np.asarray(self.problem[i].ambient, dtype=float).tolist()
                          for k, i in self.ids.items()},
            "view_names": list(self.view_names),
            "rms_px": self.rms(),
            "dropped_corners": len(self.dropped),
            "distortion_priors": [p.todict() for p in self.priors],
            "summary": self.result.todict() if self.result is not None else None,
        }

    def rms(self) -> float:
        """OpenCV's RMS: sqrt(Σ‖2-D error‖² / number of points), over all boards."""
        E = np.concatenate([self.problem.measurement_errors(m) for ms in self.view_ids.values() for m in ms])
        return float(np.sqrt(np.mean(np.sum(E**2, axis=1))))

    @_one_blas_thread
    def profile(self, name: str, parameter: str, level: float = 1.0) -> Any:
        """The profile-likelihood interval of one intrinsic (``name`` a camera,
        ``parameter`` a label such as "alpha"): for the parameters whose linearised σ
        is too narrow (a double sphere's f, ξ and α), see :mod:`boxplus.profile`."""
        if name not in self.ids:
            raise ValueError(f"profile: no variable '{name}' (have: {', '.join(self.ids)})")
        return self.problem.profile(self.ids[name], parameter, level)

    @_one_blas_thread
    def report(self, rescale: bool = False):
        """The :func:`boxplus.calib.report` of the solved problem; σ from the given
        corner noise unless ``rescale`` (the printed report shows both). Computed once
        per state of the problem (one normal matrix and rank test for every camera's
        projection uncertainty and the printed report), again after any change."""
        from boxplus.calib.report import report

        generation = self.problem._core.generation
        for old in [k for k in self._reports if k[1] != generation]:
            del self._reports[old]
        key = (bool(rescale), generation)
        if key not in self._reports:
            self._reports[key] = report(self.problem, rescale=rescale)
        return self._reports[key]

    def cameras(self) -> list[CalibratedCamera]:
        """The rig as :class:`boxplus.calib.io.CalibratedCamera` values (reference first), for the
        file writers of :mod:`boxplus.calib.io`."""
        out = []
        for name in self.view_ids:
            pose = SE3() if name == self.reference else self.problem[self.ids[f"{name}_from_{self.reference}"]]
            out.append(CalibratedCamera(name, self.models.get(name, self.model), self.problem[self.ids[name]].vec,
                              self.image_size[name], pose))
        return out

    def to_opencv(self) -> dict[str, Any]:
        """K, distortion, R, T in OpenCV's layout (:func:`boxplus.calib.io.to_opencv`); for a
        stereo pair ready for ``cv2.stereoRectify(K1, D1, K2, D2, image_size, R, T)``."""
        return to_opencv(self.cameras())


def _warm(name: str, value: Any, prev: dict[str, Any] | None) -> Any:
    return prev.get(name, value) if prev else value


def _assemble(obs: Sequence[_Obs], cams: Sequence[str], models: dict[str, str],
              k0: dict[str, np.ndarray], cam_from_ref0: dict[str, SE3],
              world_from_ref0: Sequence[SE3 | None], sizes: dict[str, tuple[int, int]],
              sigma: Any, covariance: Any, fixed: Sequence[str] = (),
              view_prefix: str | None = None, prev: dict[str, Any] | None = None,
              regularize: float | bool | None = None) -> Calibration:
    """The board problem of a rig: intrinsics per camera, the reference camera's
    pose per view (world = the board), cam_from_ref per other camera; values
    from ``prev`` {variable name: value} where given (a re-solve); the distortion
    prior of :mod:`boxplus.calib.regularize` on the estimated cameras that
    ``regularize`` selects (:func:`_prior_width`)."""
    ref = cams[0]
    o = _problem.OptimizationProblem()
    ids: dict[str, int] = {}
    for c in cams:
        ids[c] = o.add_random_var(_warm(c, Rn(k0[c]), prev), fixed=c in fixed, name=c,
                                  labels=CAMERA_LABELS[models[c]])
    ident = o.add_random_var(SE3(), fixed=True, name="identity")
    rig = {ref: ident}
    for c in cams[1:]:
        n = f"{c}_from_{ref}"
        ids[n] = rig[c] = o.add_random_var(_warm(n, cam_from_ref0[c], prev), name=n)
    prefix = view_prefix or f"world_from_{ref}"
    views: list[int | None] = []
    observed = {ob.view for ob in obs}
    for i, pose in enumerate(world_from_ref0):
        n = f"{prefix}_{i}"
        seen = pose is not None and i in observed
        views.append(o.add_random_var(_warm(n, pose, prev), name=n) if seen else None)
    cal = Calibration(o, models[ref], ids, {c: [] for c in cams}, image_size=dict(sizes),
                      models=dict(models), reference=ref, view_index={c: [] for c in cams},
                      world_from_ref=views, observations=list(obs))
    for ob in obs:
        view = views[ob.view]
        assert view is not None  # every observed view has a pose
        cal.view_ids[ob.camera].append(add_board(o,
            ob.z, ids[ob.camera], view, rig[ob.camera], ob.obj, sigma=sigma, covariance=covariance,
            model=models[ob.camera], group=ob.camera))
        cal.view_index[ob.camera].append(ob.view)
    for c in cams:
        width = _prior_width(regularize, models[c])
        prior = add_distortion_prior(cal, c, width) if width is not None else None
        if prior is not None:
            cal.priors.append(prior)
    return cal


def _prior_width(regularize: float | bool | None, model: str = "") -> float | None:
    """The distortion prior's width s for a camera of ``model`` (None: no prior): by
    default (None) only the over-parameterised models of
    :data:`boxplus.calib.regularize.REGULARIZED_BY_DEFAULT`; True every model at the
    default width, a number every model at that width, False none."""
    if regularize is None:
        return DEFAULT_PRIOR_SIGMA if model in REGULARIZED_BY_DEFAULT else None
    if regularize is False:
        return None
    if regularize is True:
        return DEFAULT_PRIOR_SIGMA
    s = float(regularize)
    if not (np.isfinite(s) and s > 0):
        raise ValueError(f"regularize: True, False, or the prior's width s > 0, got {regularize}")
    return s


def _values(cal: Calibration) -> dict[str, Any]:
    o = cal.problem
    return {o.variable_name(v): o[v] for v in range(o.num_variables)}


def _outliers(cal: Calibration, k: float) -> list[tuple[int, np.ndarray, np.ndarray]]:
    """[(observation index, keep mask, error norms)] of the observations with a corner
    whose error exceeds k σ̂ (σ̂ = 1.4826 · median |error coordinate|, over all corners)."""
    errs = [cal.problem.measurement_errors(m) for c in cal.view_ids for m in cal.view_ids[c]]
    order = [(c, j) for c in cal.view_ids for j in range(len(cal.view_ids[c]))]
    allE = np.concatenate(errs)
    s = 1.4826 * float(np.median(np.abs(allE)))
    if s <= 0:
        return []
    by_obs: dict[tuple[str, int], int] = {}
    counters: dict[str, int] = {}
    for i, ob in enumerate(cal.observations):
        j = counters.get(ob.camera, 0)
        counters[ob.camera] = j + 1
        by_obs[ob.camera, j] = i
    out = []
    for (c, j), e in zip(order, errs):
        norm = np.linalg.norm(e, axis=1)
        bad = norm > k * s
        if bad.any():
            out.append((by_obs[c, j], ~bad, norm))
    return out


# Further starts (ξ, α) of the wide-angle models whose pinhole start (ξ = α = 0)
# can lie in another basin: double sphere, rendered at ξ = −0.18 and solved from
# the pinhole start even on noise-free corners, stopped at fx 1.8× the truth
# and ξ = +0.5 (RMS 0.01 px); from (−0.2, 0.6) it reaches the truth.
_WIDE_STARTS: dict[str, list[tuple[float, float]]] = {"double_sphere": [(-0.2, 0.6), (0.5, 0.7)]}


def _first_solve(cal: Calibration) -> SolveSummary:
    """The first solve, from Zhang's start and, for wide-angle models, from the
    further starts of :data:`_WIDE_STARTS` (the focal length scaled by 1 + ξ, which
    keeps the projection near the axis): the lowest cost wins, its warnings are the
    ones shown."""
    o = cal.problem
    alts = [(c, s) for c, m in cal.models.items() if m in _WIDE_STARTS and not o.is_fixed(cal.ids[c])
            for s in _WIDE_STARTS[m]]
    if not alts:
        return o.solve()
    start = [o[v] for v in range(o.num_variables)]
    runs = []
    starts: list[tuple[str | None, tuple[float, float]]] = [(None, (0.0, 0.0)), *alts]
    for camera, (xi, alpha) in starts:
        for v, value in enumerate(start):
            o.set_value(v, value)
        if camera is not None:
            k = o[cal.ids[camera]].vec.copy()
            labels = model_labels(cal.models[camera])
            k[labels.index("fx")] *= 1 + xi
            k[labels.index("fy")] *= 1 + xi
            k[labels.index("xi")], k[labels.index("alpha")] = xi, alpha
            o.set_value(cal.ids[camera], Rn(k))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            result = o.solve()
        ok = result.usable and np.isfinite(result.final_cost)
        runs.append((result.final_cost if ok else np.inf, [o[v] for v in range(o.num_variables)],
                     result, caught))
    _, values, result, caught = min(runs, key=lambda r: r[0])
    for v, value in enumerate(values):
        o.set_value(v, value)
    for w in caught:
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return result


def _solve(cal: Calibration, robust: float | bool | None, rebuild, max_rounds: int = 10) -> Calibration:
    """Solves; with ``robust`` (k, or True for :data:`ROBUST_K`) drops the corners beyond
    k σ̂ and re-solves from the current values until none is beyond (at most
    ``max_rounds`` times); views left with fewer than 4 corners are dropped whole."""
    cal.result = _first_solve(cal)
    if not robust:
        check_fold_over(cal)
        return cal
    k = ROBUST_K if robust is True else float(robust)
    if not k > 0:
        raise ValueError(f"robust: k must be > 0, got {robust}")
    dropped: list[DroppedCorner] = []
    for _ in range(max_rounds):
        bad = _outliers(cal, k)
        if not bad:
            break
        obs = list(cal.observations)
        for i, keep, norm in bad:
            ob = obs[i]
            if keep.sum() < 4:
                keep = np.zeros_like(keep)
            vname = cal.view_names[ob.view] if ob.view < len(cal.view_names) else str(ob.view)
            dropped += [DroppedCorner(ob.camera, ob.view, vname, int(ob.corners[j]), float(norm[j]))
                        for j in np.flatnonzero(~keep)]
            obs[i] = _Obs(ob.camera, ob.view, ob.z[keep], ob.obj[keep], ob.corners[keep])
        obs = [ob for ob in obs if len(ob.z)]
        names = cal.view_names
        cal = rebuild(obs, _values(cal))
        cal.view_names = names
        cal.result = cal.problem.solve()
    cal.dropped = dropped
    check_fold_over(cal)
    return cal


def _camera_init(image_points, object_points, image_size, camera):
    pts = check_views(image_points, object_points, image_size, camera)
    K, cam_from_board = init_camera(object_points, pts, image_size, camera)
    return pts, K, cam_from_board


def _names(view_names: Sequence[str] | None, n: int) -> list[str]:
    if view_names is None:
        return [str(i) for i in range(n)]
    if len(view_names) != n:
        raise ValueError(f"view_names: {len(view_names)} names for {n} views")
    return [str(v) for v in view_names]


@_one_blas_thread
def calibrate_mono(image_points: Sequence[np.ndarray], object_points: np.ndarray,
                   image_size: tuple[int, int], model: str = "opencv5", sigma: Any = None,
                   name: str = "camera", solve: bool = True, covariance: Any = None,
                   robust: float | bool | None = None,
                   view_names: Sequence[str] | None = None,
                   regularize: float | bool | None = None) -> Calibration:
    """One camera from views of a planar board (Zhang's initial values, then ML).

    The corner noise is ``sigma`` (σ or [σu, σv], pixels) or a 2×2 ``covariance``
    (none: σ = 1). ``model`` is any of :data:`boxplus.calib.models.CAMERA_LABELS`
    (the wide-angle ones start from the pinhole K of Zhang's closed form).
    ``robust`` (k, or True for k = :data:`ROBUST_K`) drops the corners whose
    error exceeds k σ̂ and re-solves; ``cal.dropped`` lists them. Raises
    ValueError naming the camera and view for bad detections, and when the
    board planes are parallel in every view (the intrinsics are then
    undetermined); warns when the solved focal length is barely determined
    (:func:`boxplus.calib.init.check_solved_views`). ``regularize`` pulls the
    distortion terms lightly towards 0 (:mod:`boxplus.calib.regularize`), against
    fold-overs of over-parameterised models: by default (None) for ``rational``
    only, True for every model, a number for every model with that prior width s,
    False never (OpenCV's problem exactly); ``cal.priors`` says what each camera
    got."""
    _prior_width(regularize)  # a bad width fails before the solve
    pts, K, cam_from_board = _camera_init(image_points, object_points, image_size, name)
    obj = np.asarray(object_points, float)
    obs = [_Obs(name, i, p, obj, np.arange(len(obj))) for i, p in enumerate(pts)]

    def build(obs, prev=None):
        return _assemble(obs, [name], {name: model}, {name: intrinsics_vector(K, model)}, {},
                         [p.inverse() for p in cam_from_board], {name: (int(image_size[0]), int(image_size[1]))},
                         sigma, covariance, view_prefix=f"world_from_{name}", prev=prev,
                         regularize=regularize)

    cal = build(obs)
    cal.view_names = _names(view_names, len(pts))
    if solve:
        cal = _solve(cal, robust, build)
        check_solved_views(cal.problem, [cal.ids[name]], [v for v in cal.world_from_ref if v is not None],
                           name)
    return cal


@_one_blas_thread
def calibrate_stereo(left_points: Sequence[np.ndarray], right_points: Sequence[np.ndarray],
                     object_points: np.ndarray, image_size: tuple[int, int],
                     model: str = "opencv5", sigma: Any = None,
                     fixed_intrinsics: tuple[np.ndarray, np.ndarray] | None = None,
                     solve: bool = True, covariance: Any = None,
                     robust: float | bool | None = None,
                     view_names: Sequence[str] | None = None,
                     regularize: float | bool | None = None) -> Calibration:
    """A stereo pair seeing the same boards: intrinsics of both cameras, right_from_left
    and one world_from_left per view, jointly (or with ``fixed_intrinsics`` =
    (k_left, k_right) model vectors held constant, like OpenCV's
    CALIB_FIX_INTRINSIC). Refuses parallel boards and warns of a barely determined
    focal length like :func:`calibrate_mono`; ``robust`` and ``regularize`` as there."""
    _prior_width(regularize)
    if len(left_points) != len(right_points):
        raise ValueError(f"stereo: {len(left_points)} left and {len(right_points)} right views")
    pl, Kl, left_from_board = _camera_init(left_points, object_points, image_size, "left")
    pr, Kr, right_from_board = _camera_init(right_points, object_points, image_size, "right")
    obj = np.asarray(object_points, float)
    size = (int(image_size[0]), int(image_size[1]))
    if fixed_intrinsics is None:
        k0 = {"left": intrinsics_vector(Kl, model), "right": intrinsics_vector(Kr, model)}
    else:
        k0 = {"left": np.asarray(fixed_intrinsics[0], float), "right": np.asarray(fixed_intrinsics[1], float)}
    idx = np.arange(len(obj))
    obs = [ob for i, (zl, zr) in enumerate(zip(pl, pr))
           for ob in (_Obs("left", i, zl, obj, idx), _Obs("right", i, zr, obj, idx))]

    def build(obs, prev=None):
        return _assemble(obs, ["left", "right"], {"left": model, "right": model}, k0,
                         {"right": relative_pose_init(left_from_board, right_from_board)},
                         [p.inverse() for p in left_from_board],
                         {"left": size, "right": size}, sigma, covariance,
                         fixed=("left", "right") if fixed_intrinsics is not None else (), prev=prev,
                         regularize=regularize)

    cal = build(obs)
    cal.view_names = _names(view_names, len(pl))
    if solve:
        cal = _solve(cal, robust, build)
        # the right camera sees the same boards turned by one rotation: the
        # same spread of planes
        check_solved_views(cal.problem, [cal.ids["left"], cal.ids["right"]],
                           [v for v in cal.world_from_ref if v is not None], "stereo")
    return cal


def _check_detection(camera: str, i: int, det: Any, size: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    if det is None:
        return None
    try:
        z, obj = (np.asarray(a, float) for a in det)
    except (TypeError, ValueError):
        raise ValueError(f"{camera}, view {i}: a detection must be (pixels (N, 2), board points (N, 3))") from None
    if z.ndim != 2 or z.shape[1] != 2 or obj.shape != (len(z), 3):
        raise ValueError(f"{camera}, view {i}: pixels must be (N, 2) and board points (N, 3), got "
                         f"{z.shape} and {obj.shape}")
    if len(z) < 4:
        return None  # too few corners to place the board: not a view of this camera
    if not (np.all(np.isfinite(z)) and np.all(np.isfinite(obj))):
        raise ValueError(f"{camera}, view {i}: non-finite points")
    if np.any(z < -0.5) or np.any(z > size - 0.5):
        raise ValueError(f"{camera}, view {i}: points outside the {size[0]}×{size[1]} image")
    return z, obj


@_one_blas_thread
def calibrate_rig(detections: Mapping[str, Sequence[Any]],
                  image_size: tuple[int, int] | Mapping[str, tuple[int, int]],
                  model: str | Mapping[str, str] = "opencv5", sigma: Any = None,
                  covariance: Any = None, robust: float | bool | None = None,
                  view_names: Sequence[str] | None = None, solve: bool = True,
                  known_intrinsics: Mapping[str, Any] | None = None,
                  regularize: float | bool | None = None) -> Calibration:
    """Any number of cameras with partial overlap, in one joint solve.

    Parameters
    ----------
    detections : {camera name: [per view (pixels (N, 2), board points (N, 3)) or None]}
        One entry per synchronised capture (view) for every camera, None where
        the camera did not see the board; the points may be any subset of the
        target (ChArUco, AprilTag grids). The first camera is the reference.
    image_size : (width, height), or one per camera
    model : a camera model name, or one per camera
    sigma, covariance : the corner noise (pixels), as :func:`calibrate_mono`
    robust : drop corners beyond k σ̂ and re-solve (:func:`calibrate_mono`)
    view_names : a name per view (e.g. file names) for reports and plots
    known_intrinsics : {camera name: intrinsics vector in its model's order}, optional
        Cameras calibrated before (e.g. a fisheye read from its own file): their
        intrinsics are held fixed, so the rig solve estimates only the poses for them
        (OpenCV's ``calibrateMultiview`` with ``CALIB_FIX_INTRINSIC``).
    regularize : None (rational cameras only), True, False, or the prior's width s
        Pulls the estimated cameras' distortion terms lightly towards 0
        (:func:`calibrate_mono`).

    Notes
    -----
    Initialisation: Zhang per camera (≥ 3 views each); a camera graph whose
    edges are the pairs of cameras that saw the board in the same views,
    weighted by the number of such views; cam_from_ref along the tree of the
    most shared views from the reference (each edge the chordal mean of the
    pairwise poses); the reference camera's pose per view from every camera
    that saw it. Then one solve over all intrinsics, cam_from_ref and views.
    Raises ValueError when a camera is not connected to the reference through
    shared views, naming it. A view a camera cannot use (fewer than 4 corners, or
    corners that are collinear, in the target or in the image, so that no homography
    places the board) is left out for that camera and listed in ``skipped`` with the
    reason, instead of ending the run.

    Variables: intrinsics named by the camera, ``<cam>_from_<ref>``, and
    ``world_from_<ref>_<i>`` per view (world = the board).
    """
    cams = list(detections)
    if not cams:
        raise ValueError("calibrate_rig: no cameras")
    _prior_width(regularize)
    n_views = {len(v) for v in detections.values()}
    if len(n_views) != 1:
        raise ValueError(f"calibrate_rig: every camera needs one entry per view, got "
                         f"{ {c: len(v) for c, v in detections.items()} }")
    nv = n_views.pop()
    sizes: dict[str, tuple[int, int]] = {}
    for c in cams:
        s = image_size[c] if isinstance(image_size, Mapping) else image_size
        if len(s) != 2:
            raise ValueError(f"{c}: image_size must be (width, height), got {s}")
        sizes[c] = (int(s[0]), int(s[1]))
    models = {c: model[c] if isinstance(model, Mapping) else model for c in cams}
    for c in cams:
        model_labels(models[c])  # raises for an unknown model
        if min(sizes[c]) <= 0:
            raise ValueError(f"{c}: image_size must be (width, height) > 0, got {sizes[c]}")
    known = dict(known_intrinsics or {})
    for c, k in known.items():
        if c not in models:
            raise ValueError(f"known_intrinsics: no camera '{c}' (cameras: {', '.join(cams)})")
        k = np.asarray(k, dtype=float).reshape(-1)
        if k.size != len(model_labels(models[c])) or not np.all(np.isfinite(k)):
            raise ValueError(f"known_intrinsics of '{c}': model '{models[c]}' needs "
                             f"{len(model_labels(models[c]))} finite numbers, got {k.size}")
        known[c] = k
    names = _names(view_names, nv)
    skipped: list[SkippedView] = []
    det: dict[str, list[Any]] = {}
    for c in cams:
        det[c] = []
        for i, d in enumerate(detections[c]):
            checked = _check_detection(c, i, d, np.asarray(sizes[c], float))
            reason = None if checked is None else _unusable(checked)
            if reason is not None:
                skipped.append(SkippedView(c, i, names[i], reason))
                checked = None
            det[c].append(checked)
    k0: dict[str, np.ndarray] = {}
    cam_from_board: dict[str, dict[int, SE3]] = {}
    for c in cams:
        seen = [i for i in range(nv) if det[c][i] is not None]
        if len(seen) < 3:
            raise ValueError(f"{c}: {len(seen)} views with the board, at least 3 are needed to "
                             "calibrate a camera from a planar board")
        K, poses = init_camera([det[c][i][1] for i in seen], [det[c][i][0] for i in seen],
                               sizes[c], c)
        k0[c] = known[c] if c in known else intrinsics_vector(K, models[c])
        cam_from_board[c] = dict(zip(seen, poses))
    # the camera graph: a maximum spanning tree (Prim) by shared views
    ref = cams[0]
    cam_from_ref: dict[str, SE3] = {ref: SE3()}
    while len(cam_from_ref) < len(cams):
        best = None
        for a in cam_from_ref:
            for b in cams:
                if b in cam_from_ref:
                    continue
                shared = sorted(set(cam_from_board[a]) & set(cam_from_board[b]))
                if shared and (best is None or len(shared) > len(best[2])):
                    best = (a, b, shared)
        if best is None:
            missing = [c for c in cams if c not in cam_from_ref]
            raise ValueError(f"calibrate_rig: camera(s) {', '.join(missing)} share no view with "
                             f"{', '.join(cam_from_ref)}: their poses in the rig are undetermined")
        a, b, shared = best
        b_from_a = relative_pose_init([cam_from_board[a][i] for i in shared],
                                      [cam_from_board[b][i] for i in shared])
        cam_from_ref[b] = b_from_a * cam_from_ref[a]
    world_from_ref: list[SE3 | None] = []
    for i in range(nv):
        # ref_from_board = c_from_ref⁻¹ · c_from_board, from every camera c that saw view i
        est = [cam_from_ref[c].inverse() * cam_from_board[c][i] for c in cams if i in cam_from_board[c]]
        world_from_ref.append(mean_pose(est).inverse() if est else None)
    obs = [_Obs(c, i, det[c][i][0], det[c][i][1], np.arange(len(det[c][i][0])))
           for i in range(nv) for c in cams if det[c][i] is not None]

    def build(obs, prev=None):
        return _assemble(obs, cams, models, k0, cam_from_ref, world_from_ref, sizes, sigma,
                         covariance, fixed=list(known), prev=prev, regularize=regularize)

    cal = build(obs)
    cal.view_names = names
    if solve:
        cal = _solve(cal, robust, build)
        for c in cams:
            vids = [cal.world_from_ref[i] for i in sorted(set(cal.view_index[c]))]
            check_solved_views(cal.problem, [cal.ids[c]], [v for v in vids if v is not None], c)
        if len(cams) > 1:
            cal.intrinsics_shift = _mono_consistency(cal, [c for c in cams if c not in known],
                                                     regularize)
            for shift in cal.intrinsics_shift:
                if shift.worst_sigmas > MONO_SHIFT_SIGMAS:
                    warnings.warn(str(shift), RigConsistencyWarning, stacklevel=3)
    cal.skipped = skipped
    return cal


# A rig's intrinsics more than this many of the mono fit's σ from that fit are
# reported (RigConsistencyWarning): the rig solve trades them for the poses.
MONO_SHIFT_SIGMAS = 5.0


class RigConsistencyWarning(UserWarning):
    """The joint rig solve moved a camera's intrinsics far from its own mono fit."""


@dataclass
class IntrinsicsShift:
    """How far the rig solve moved a camera's intrinsics from its mono fit: per
    intrinsic (rig − mono) / σ_mono, and the largest absolute value with its label."""

    camera: str
    labels: list[str]
    shift_sigmas: np.ndarray
    mono: np.ndarray
    rig: np.ndarray

    @property
    def worst(self) -> str:
        return self.labels[int(np.argmax(np.abs(self.shift_sigmas)))]

    @property
    def worst_sigmas(self) -> float:
        return float(np.max(np.abs(self.shift_sigmas)))

    def __str__(self) -> str:
        i = int(np.argmax(np.abs(self.shift_sigmas)))
        return (f"camera '{self.camera}': the rig solve moved {self.labels[i]} from "
                f"{self.mono[i]:.6g} (its own mono fit) to {self.rig[i]:.6g}, "
                f"{self.shift_sigmas[i]:+.1f} σ of the mono fit; the poses between the cameras "
                f"and this camera's intrinsics disagree (a wrong model, unsynchronised views, or "
                f"give its intrinsics as known_intrinsics)")


def _mono_consistency(cal: Calibration, cameras: Sequence[str],
                      regularize: float | bool | None = None) -> list[IntrinsicsShift]:
    """Each camera's mono fit (its own views only, started at the rig's values, with the
    rig's regularisation) against the rig's estimate of its intrinsics."""
    o = cal.problem
    out = []
    for c in cameras:
        obs = [ob for ob in cal.observations if ob.camera == c]
        views = sorted({ob.view for ob in obs})
        if len(views) < 3:
            continue
        c_from_ref = SE3() if c == cal.reference else o[cal.ids[f"{c}_from_{cal.reference}"]]
        world_from_c: list[SE3 | None] = [None] * len(cal.world_from_ref)
        for i in views:
            v = cal.world_from_ref[i]
            if v is not None:
                world_from_c[i] = o[v] * c_from_ref.inverse()
        k_rig = o[cal.ids[c]].vec
        # the rig's corner noise, so that σ is on the same footing
        corner_cov = o._core.noise(cal.view_ids[c][0]).covariance_matrix
        mono = _assemble(obs, [c], {c: cal.models[c]}, {c: k_rig}, {c: SE3()}, world_from_c,
                         {c: cal.image_size[c]}, None, corner_cov, view_prefix=f"world_from_{c}",
                         regularize=regularize)
        mono.problem.solve()
        try:
            std = mono.problem.std(mono.ids[c])
        except ValueError:
            continue
        k_mono = mono.problem[mono.ids[c]].vec
        with np.errstate(divide="ignore", invalid="ignore"):
            shift = np.where(std > 0, (k_rig - k_mono) / std, 0.0)
        out.append(IntrinsicsShift(c, list(CAMERA_LABELS[cal.models[c]]), shift, k_mono, k_rig))
    return out


def detect_corners(images: Sequence[np.ndarray], pattern_size: tuple[int, int]) -> list[np.ndarray | None]:
    """Chessboard corners per image with OpenCV (the optional extra
    opencv-python-headless): (N, 2) float arrays, None where no board was found."""
    cv2 = require("cv2", "corner detection")
    out: list[np.ndarray | None] = []
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 30, 0.01)
    for img in images:
        # Any: cv2's stubs take only integer/floating dtypes, an image arrives as any array.
        gray: Any = img if img.ndim == 2 else cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
        # flags by keyword: the third positional argument is the output array `corners`.
        ok, c = cv2.findChessboardCorners(gray, tuple(pattern_size),
                                          flags=cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE)
        if not ok:
            out.append(None)
            continue
        c = cv2.cornerSubPix(gray, c, (7, 7), (-1, -1), crit)
        out.append(c.reshape(-1, 2).astype(float))
    return out
