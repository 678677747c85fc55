"""Joint calibration of a real rig with the C++ terms (factors/joint/terms.h).

Le & Ng, "Joint calibration of multiple sensors", IROS 2009: 3D systems
p = I_s(α_s, u) in their own frames, placed in the root frame by poses
root_from_s, tied by extrinsic terms (eq. 4) and constrained by distances,
planes and lines (eqs. 5, 6); here also by reprojection, so that the
maximum-likelihood objective of a camera rig can be written in the same API.

Systems (each a frame; the first added, or ``root=``, is the root):

* :class:`DHArm` — a Denavit–Hartenberg chain (standard or modified, any
  number of joints) carrying a target: any subset of the n × 4 table
  [θ offset, d, a, α] unknown with Gaussian priors, optional encoder noise
  (one Rⁿ error per reading, prior N(0, σ²)), a known or unknown mount
  end_from_target. Points: :meth:`JointRig.arm_point`; the target plane z = 0:
  :meth:`JointRig.arm_plane`.
* :class:`Stereo` — two cameras; a pixel pair becomes a point *variable* in
  camera 1's frame whose intrinsic term is the reprojection error in both
  images (:meth:`JointRig.stereo_point`).
* :class:`LightSheet` — a camera and a light sheet fixed in its frame (a Plane
  variable [n, d]); a stripe pixel is the ray ∩ sheet
  (:meth:`JointRig.sheet_point`). :class:`Beam` is the projector with an angle
  β per point (Le & Ng eq. 10), cam_from_laser an SE3 variable.
* :class:`RangeSensor` — measures points directly (eq. 12).
* :class:`Camera` — one camera; with :meth:`JointRig.project` any system's point
  (e.g. an arm's target corner) is a reprojection term in any camera of a
  Camera, Stereo or LightSheet system; :meth:`JointRig.project_targets` puts a
  whole board view of an arm into one term (forward kinematics once per view).

Cameras are named sensors (:meth:`JointRig.add_camera`): systems naming the
same camera *share* it (one intrinsics variable); a copy under another name is
the unshared variant. Terms: :meth:`link`, :meth:`distance`, :meth:`coplanar`,
:meth:`collinear`, :meth:`project`, each with its full Σ (``sigma``,
``covariance``, ``information`` or ``noise``). Planes and lines are variables
owned by a system (expressed in its frame) or free (root frame), or the target
plane of an arm reading.

SE(3) = R³ × SO(3), tangent [translation, rotation]; b_from_a maps
a-coordinates to b. Lengths in metres, angles in radians, pixels for images.
"""

from __future__ import annotations

import copy
import functools
from collections import deque
from collections.abc import Sequence
from concurrent.futures import Executor
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from boxplus import _core
from boxplus._journal import journalled
from boxplus._plain import fields_todict
from boxplus.calib.models import CAMERA_LABELS
from boxplus.joint.constraints import Line, Plane, fit_line, fit_plane
from boxplus.joint.geometry import dh_pose, plane_in, sheet_points, triangulate
from boxplus.losses import LossSpec
from boxplus.manifolds import S2, SE3, Rn
from boxplus.noise import NoiseModel, noise_model
from boxplus.problem import OptimizationProblem
from boxplus.restarts import RestartResult, solve_with_restarts

__all__ = ["Beam", "Camera", "DHArm", "JointRig", "LightSheet", "PointRef", "RangeSensor", "RigResult",
           "Stereo", "SurfaceRef", "dh_labels"]

_COLUMNS = ("theta", "d", "a", "alpha")


def dh_labels(n: int) -> list[str]:
    """Names of the n × 4 table's entries, row-major: theta1, d1, a1, alpha1, theta2, ..."""
    return [f"{c}{j + 1}" for j in range(n) for c in _COLUMNS]


# ---- systems ---------------------------------------------------------------------------

@dataclass
class DHArm:
    """A DH chain carrying a target (Le & Ng eq. 11 generalised).

    Parameters
    ----------
    name : str
    nominal : (n, 4) array
        The maker's table, rows [θ offset, d, a, α] (m, rad).
    convention : "standard" or "modified"
    unknown : "all", a list of labels (``dh_labels``: "a2", "theta3", ...) or an (n, 4) bool mask
        Entries estimated; the others stay at their nominal values. The rig's variable
        ``<name>.dh`` holds them in table order (row by row, θ, d, a, α in each row),
        whatever the order of this list: ``unknown_labels`` is that order, and
        :meth:`JointRig.dh_values` gives them by label.
    prior_sigma : (length, angle), an (n, 4) array, or None
        σ of the Gaussian prior of each unknown entry about its nominal value
        (None: no prior).
    encoder_sigma : float, (n,) array or None
        Encoder noise: each reading gets an Rⁿ error variable with prior N(0, σ²).
    mount : SE3
        end_from_target (initial value when ``mount_unknown``).
    mount_unknown : bool
    mount_prior_sigma : (6,) array or None
        σ of a prior on an unknown mount (tangent [δp, δθ]).
    base_from_chain : SE3, optional
        Constant pose of the chain's first frame in the arm's frame.
    """

    name: str
    nominal: Any
    convention: str = "standard"
    unknown: Any = "all"
    prior_sigma: Any = None
    encoder_sigma: Any = None
    mount: SE3 = field(default_factory=SE3)
    mount_unknown: bool = False
    mount_prior_sigma: Any = None
    base_from_chain: SE3 = field(default_factory=SE3)

    def __post_init__(self) -> None:
        self.nominal = np.asarray(self.nominal, dtype=float)
        if self.nominal.ndim != 2 or self.nominal.shape[1] != 4 or not 1 <= len(self.nominal) <= 16:
            raise ValueError(f"DHArm '{self.name}': the table must be n × 4 with 1 ≤ n ≤ 16, got "
                             f"shape {self.nominal.shape}")
        if not np.all(np.isfinite(self.nominal)):
            raise ValueError(f"DHArm '{self.name}': non-finite DH table")
        if self.convention not in ("standard", "modified"):
            raise ValueError(f"DHArm '{self.name}': convention must be 'standard' or 'modified', "
                             f"got '{self.convention}'")
        n = len(self.nominal)
        labels = dh_labels(n)
        if isinstance(self.unknown, str) and self.unknown == "all":
            mask = np.ones(4 * n, bool)
        elif isinstance(self.unknown, np.ndarray) and self.unknown.dtype == bool:
            if self.unknown.shape != (n, 4):
                raise ValueError(f"DHArm '{self.name}': unknown mask must be ({n}, 4)")
            mask = self.unknown.ravel().copy()
        else:
            bad = [u for u in self.unknown if u not in labels]
            if bad:
                raise ValueError(f"DHArm '{self.name}': unknown DH entries {bad}; names are {labels[:4]}...")
            mask = np.array([lab in set(self.unknown) for lab in labels])
        self.unknown_index = np.flatnonzero(mask)
        self.unknown_labels = [labels[i] for i in self.unknown_index]
        if self.prior_sigma is not None:
            ps = self.prior_sigma
            if isinstance(ps, tuple) and len(ps) == 2:
                ps = np.tile([ps[1], ps[0], ps[0], ps[1]], (n, 1))
            ps = np.asarray(ps, dtype=float)
            if ps.shape != (n, 4) or not np.all(ps > 0):
                raise ValueError(f"DHArm '{self.name}': prior_sigma must be (length, angle) or "
                                 f"positive ({n}, 4)")
            self.prior_sigma = ps
        if self.encoder_sigma is not None:
            es = np.broadcast_to(np.asarray(self.encoder_sigma, dtype=float), (n,)).copy()
            if not np.all(es > 0):
                raise ValueError(f"DHArm '{self.name}': encoder_sigma must be positive")
            self.encoder_sigma = es

    @property
    def joints(self) -> int:
        return len(self.nominal)

    def table(self, values: np.ndarray) -> np.ndarray:
        """The full table with the unknown entries set to ``values``."""
        t = self.nominal.ravel().copy()
        t[self.unknown_index] = values
        return t.reshape(-1, 4)


@dataclass
class Stereo:
    """Two named cameras; cam2_from_cam1 (SE3) is the system's parameter; frame = camera 1."""

    name: str
    cam1: str
    cam2: str
    cam2_from_cam1: SE3


@dataclass
class LightSheet:
    """A named camera and a light sheet [n, d] or a :data:`Plane` ({p : n·p = d}, camera frame);
    frame = the camera."""

    name: str
    camera: str
    sheet: Any


@dataclass
class Beam:
    """A named camera and a projector at angle β per point (eq. 10); cam_from_laser SE3."""

    name: str
    camera: str
    cam_from_laser: SE3


@dataclass
class RangeSensor:
    """Measures points in its frame (eq. 12); no parameters."""

    name: str


@dataclass
class Camera:
    """One named camera as a system (frame = the camera); its data are reprojections."""

    name: str
    camera: str


System = Any  # one of the dataclasses above


@dataclass
class PointRef:
    """A point of a system (the C++ point spec, with the system's pose)."""

    system: str
    spec: dict


@dataclass
class SurfaceRef:
    """A plane or line: a variable owned by a system or free (owner None), or an arm's target plane."""

    name: str
    kind: str                 # "plane", "line" or "chain_plane"
    owner: str | None
    spec: dict
    points: int = 0           # points constrained to it so far
    systems: list = field(default_factory=list)  # systems with points on it


@dataclass
class RigResult:
    """What :meth:`JointRig.solve` did: cost ½ Σ ‖r‖², termination, RMS per group, restarts."""

    cost: float
    termination: str
    rms: dict[str, float]
    restarts: RestartResult = field(repr=False)

    def todict(self) -> dict[str, Any]:
        """Plain Python values (``json.dumps`` takes them)."""
        return fields_todict(self)


# ---- the calibration -------------------------------------------------------------------

class JointRig:
    """Systems, sensors and terms of one joint calibration, as one OptimizationProblem.

    Parameters
    ----------
    root : str, optional
        The system whose frame is the root (default: the first added).
    gamma : float
        Weight γ of the extrinsic terms (links) against the intrinsic ones (eq. 8):
        a link's Σ is divided by γ.

    Examples
    --------
    >>> rig = JointRig()
    >>> rig.add_camera("cam1", [600, 320, 240, 0], "simple_radial")
    >>> rig.add_camera("cam2", [600, 320, 240, 0], "simple_radial")
    >>> rig.add_system(DHArm("arm", table, unknown="all", prior_sigma=(0.003, 0.02)))
    >>> rig.add_system(Stereo("stereo", "cam1", "cam2", SE3(...)), pose=SE3(...))
    >>> x = rig.stereo_point("stereo", z1, z2, sigma=0.3)
    >>> rig.link(x, rig.arm_point("arm", q, corner), sigma=0.001)
    >>> rig.solve()
    """

    def __init__(self, root: str | None = None, gamma: float = 1.0) -> None:
        if not np.isfinite(gamma) or gamma <= 0:
            raise ValueError(f"gamma must be a positive number, got {gamma}")
        self.gamma = float(gamma)
        self._root = root
        self.problem = OptimizationProblem()
        self.cameras: dict[str, tuple[int, str]] = {}
        self.systems: dict[str, System] = {}
        self.ids: dict[str, int] = {}          # variable name -> id
        self.surfaces: dict[str, SurfaceRef] = {}
        self._edges: list[tuple[str, str]] = []
        self._data: dict[str, int] = {}        # system -> number of terms using its data
        self._readings: dict[tuple[str, Any], int] = {}
        self._reading_q: dict[tuple[str, Any], np.ndarray] = {}
        self._isotropic: dict[tuple[int, float], NoiseModel] = {}

    # ---- sensors and systems ---------------------------------------------------------
    @property
    def root(self) -> str:
        if self._root is not None:
            return self._root
        if not self.systems:
            raise ValueError("the rig has no systems")
        return next(iter(self.systems))

    def _var(self, name: str, value: Any, labels: Sequence[str] | None = None, fixed: bool = False) -> int:
        if name in self.ids:
            raise ValueError(f"variable '{name}' exists already")
        self.ids[name] = self.problem.add_random_var(value, fixed=fixed, name=name, labels=labels)
        return self.ids[name]

    def _prior(self, vid: int, z: Any, sigma: Any, name: str) -> None:
        # its own RMS group: priors of different sizes cannot share one
        self.problem.add_prior(vid, z, sigma=sigma, name=name, group=name.split("[")[0])

    def add_camera(self, name: str, intrinsics: Any, model: str = "opencv5", fixed: bool = False,
                   prior_sigma: Any = None) -> int:
        """A camera's intrinsics variable (``camera_model_size(model)`` numbers, labelled
        as :func:`boxplus.calib.add_camera` labels them); returns its id.

        ``model``: any model of :mod:`boxplus.calib.models` (the Brown–Conrady family,
        ``rational``, ``kannala_brandt``, ``double_sphere``), in its order; the default is
        every ``add_camera``'s, OpenCV's ``opencv5``."""
        if name in self.cameras:
            raise ValueError(f"camera '{name}' exists already")
        k = np.asarray(intrinsics.vec if isinstance(intrinsics, Rn) else intrinsics, dtype=float).ravel()
        try:
            size = _core.camera_model_size(model)
        except (ValueError, RuntimeError) as e:
            raise ValueError(f"camera '{name}': {e}") from None
        if k.size != size:
            raise ValueError(f"camera '{name}': model '{model}' needs {size} intrinsics, got {k.size}")
        vid = self._var(name, Rn(k), fixed=fixed, labels=CAMERA_LABELS[model])
        if prior_sigma is not None:
            self._prior(vid, Rn(k), prior_sigma, f"prior:{name}")
        self.cameras[name] = (vid, model)
        return vid

    def _camera(self, name: str, what: str) -> tuple[int, str]:
        if name not in self.cameras:
            raise KeyError(f"{what}: unknown camera '{name}' (add it with add_camera)")
        return self.cameras[name]

    def add_system(self, system: System, pose: SE3 | None = None, fixed_pose: bool = False) -> System:
        """Adds a system; ``pose`` = root_from_system (initial value; ignored for the root)."""
        name = system.name
        if not isinstance(name, str) or not name:
            raise ValueError("a system needs a non-empty name")
        if name in self.systems:
            raise ValueError(f"system '{name}' exists already")
        what = f"system '{name}'"
        if isinstance(system, DHArm):
            if len(system.unknown_index):
                init = system.nominal.ravel()[system.unknown_index]
                vid = self._var(f"{name}.dh", Rn(init), labels=system.unknown_labels)
                if system.prior_sigma is not None:
                    self._prior(vid, Rn(init), system.prior_sigma.ravel()[system.unknown_index],
                                f"prior:{name}.dh")
            if system.mount_unknown:
                vid = self._var(f"{name}.mount", system.mount)
                if system.mount_prior_sigma is not None:
                    self._prior(vid, system.mount, system.mount_prior_sigma, f"prior:{name}.mount")
        elif isinstance(system, Stereo):
            self._camera(system.cam1, what)
            self._camera(system.cam2, what)
            self._var(f"{name}.cam2_from_cam1", system.cam2_from_cam1)
        elif isinstance(system, LightSheet):
            self._camera(system.camera, what)
            sh = system.sheet
            s = np.r_[sh.normal.vec, sh.distance.vec] if hasattr(sh, "normal") else np.asarray(sh, dtype=float)
            if s.shape != (4,) or not np.all(np.isfinite(s)) or np.linalg.norm(s[:3]) == 0:
                raise ValueError(f"{what}: sheet must be [n (3, non-zero), d]")
            nn = np.linalg.norm(s[:3])
            self._var(f"{name}.sheet", Plane(normal=S2(s[:3] / nn), distance=[s[3] / nn]))
        elif isinstance(system, Beam):
            self._camera(system.camera, what)
            self._var(f"{name}.cam_from_laser", system.cam_from_laser)
        elif isinstance(system, Camera):
            self._camera(system.camera, what)
        elif not isinstance(system, RangeSensor):
            raise TypeError(f"{what}: unknown kind of system {type(system).__name__}")
        self.systems[name] = system
        self._data[name] = 0
        if name != self.root:
            self._var(f"pose:{name}", pose if pose is not None else SE3(), fixed=fixed_pose)
        return system

    def _system(self, name: str, kind: type | tuple[type, ...], what: str) -> Any:
        if name not in self.systems:
            raise KeyError(f"{what}: unknown system '{name}'")
        s = self.systems[name]
        if not isinstance(s, kind):
            raise TypeError(f"{what}: system '{name}' is a {type(s).__name__}")
        return s

    def _pose_id(self, system: str) -> int | None:
        return None if system == self.root else self.ids[f"pose:{system}"]

    # ---- points of systems -----------------------------------------------------------
    def _chain(self, arm: DHArm, joints: Any, reading: Any, what: str) -> dict:
        q = np.asarray(joints, dtype=float).ravel()
        if q.size != arm.joints or not np.all(np.isfinite(q)):
            raise ValueError(f"{what}: arm '{arm.name}' needs {arm.joints} finite joint readings, got {q.size}")
        chain = {"convention": arm.convention, "nominal": arm.nominal, "joints": q,
                 "unknown": arm.unknown_index.tolist(), "dh": self.ids.get(f"{arm.name}.dh"),
                 "mount": self.ids.get(f"{arm.name}.mount"),
                 "base_from_chain": arm.base_from_chain.ambient, "mount_value": arm.mount.ambient}
        if arm.encoder_sigma is not None:
            if reading is None:
                raise ValueError(f"{what}: arm '{arm.name}' has encoder noise: name the reading "
                                 f"(reading=...) so that its points share one encoder error")
            key = (arm.name, reading)
            if key not in self._readings:
                vid = self._var(f"{arm.name}.encoder[{reading}]", Rn(np.zeros(arm.joints)))
                self._prior(vid, Rn(np.zeros(arm.joints)), arm.encoder_sigma, f"encoder:{arm.name}[{reading}]")
                self._readings[key] = vid
            elif not np.array_equal(self._reading_q[key], q):
                raise ValueError(f"{what}: reading '{reading}' of arm '{arm.name}' was given other joints")
            chain["encoder"] = self._readings[key]
            self._reading_q[key] = q
        return chain

    def arm_point(self, arm: str, joints: Any, p_in_target: Any, reading: Any = None) -> PointRef:
        """The point ``p_in_target`` of the arm's target at the joint readings (FK, eq. 11)."""
        what = f"arm_point of '{arm}'"
        a = self._system(arm, DHArm, what)
        c = np.asarray(p_in_target, dtype=float).ravel()
        if c.size != 3 or not np.all(np.isfinite(c)):
            raise ValueError(f"{what}: p_in_target must be 3 finite numbers")
        return PointRef(arm, {"kind": "chain", "c": c, "chain": self._chain(a, joints, reading, what),
                              "pose": self._pose_id(arm)})

    def arm_plane(self, arm: str, joints: Any, reading: Any = None, name: str | None = None) -> SurfaceRef:
        """The target's plane z = 0 at the joint readings (the board plane as the arm sees it)."""
        what = f"arm_plane of '{arm}'"
        a = self._system(arm, DHArm, what)
        spec = {"kind": "chain_plane", "chain": self._chain(a, joints, reading, what), "pose": self._pose_id(arm)}
        return SurfaceRef(name or f"{arm}.target_plane[{reading}]", "chain_plane", arm, spec)

    def stereo_point(self, stereo: str, z1: Any, z2: Any, sigma: Any = None, covariance: Any = None,
                     information: Any = None, noise: NoiseModel | None = None, loss: LossSpec = None,
                     name: str | None = None) -> PointRef:
        """A pixel pair of a stereo system: a point variable (camera-1 frame), with its
        reprojection terms in both images; it starts at the midpoint of the two rays at the
        current values (a start value only: the model is the reprojection error)."""
        what = f"stereo_point of '{stereo}'"
        z1, z2 = _pixels(z1, what), _pixels(z2, what)
        return self.stereo_points(stereo, z1[None], z2[None], sigma, covariance, information, noise, loss,
                                  None if name is None else [name])[0]

    def stereo_points(self, stereo: str, Z1: Any, Z2: Any, sigma: Any = None, covariance: Any = None,
                      information: Any = None, noise: NoiseModel | None = None, loss: LossSpec = None,
                      names: Sequence[str] | None = None) -> list[PointRef]:
        """:meth:`stereo_point` for rows of pixel pairs Z1, Z2 (N, 2), triangulated together."""
        what = f"stereo_points of '{stereo}'"
        s = self._system(stereo, Stereo, what)
        Z1, Z2 = np.asarray(Z1, dtype=float), np.asarray(Z2, dtype=float)
        if Z1.ndim != 2 or Z1.shape[1] != 2 or Z2.shape != Z1.shape or not np.all(np.isfinite(Z1)) \
                or not np.all(np.isfinite(Z2)):
            raise ValueError(f"{what}: Z1 and Z2 must be finite (N, 2) arrays of one shape, got {Z1.shape}, "
                             f"{Z2.shape}")
        (k1, m1), (k2, m2) = self.cameras[s.cam1], self.cameras[s.cam2]
        c21_id = self.ids[f"{stereo}.cam2_from_cam1"]
        # a start value only (the model is the reprojection error the solver minimises):
        # the midpoint of the two rays at the current values
        X = triangulate(m1, self.problem.value(k1).vec, m2, self.problem.value(k2).vec,
                        self.problem.value(c21_id), Z1, Z2, iterations=0)
        bad = np.flatnonzero(~np.all(np.isfinite(X), axis=1) | (X[:, 2] <= 0))
        if bad.size:
            i = int(bad[0])
            raise ValueError(f"{what}: the pixels {Z1[i]}, {Z2[i]} (row {i}) do not triangulate in front "
                             f"of the cameras")
        pose = self._pose_id(stereo)
        out = []
        for i in range(len(Z1)):
            label = names[i] if names is not None else f"{stereo}.X{self.problem.num_variables}"
            point = {"kind": "variable", "var": self._var(label, Rn(X[i]))}
            for cam, z, c2 in ((s.cam1, Z1[i], None), (s.cam2, Z2[i], c21_id)):
                kid, model = self.cameras[cam]
                self._add({"kind": "projection", "a": point, "z": z,
                           "camera": {"model": model, "intrinsics": kid, "cam_from_system": c2}},
                          2, f"reprojection[{stereo}]", sigma, covariance, information, noise, loss, what)
            self._data[stereo] += 1
            out.append(PointRef(stereo, {**point, "pose": pose}))
        return out

    def sheet_point(self, sheet: str, uv: Any) -> PointRef:
        """A stripe pixel of a light-sheet system: the ray ∩ the sheet (camera frame)."""
        what = f"sheet_point of '{sheet}'"
        s = self._system(sheet, LightSheet, what)
        kid, model = self.cameras[s.camera]
        return PointRef(sheet, {"kind": "sheet", "model": model, "camera": kid, "uv": _pixels(uv, what),
                                "sheet": self.ids[f"{sheet}.sheet"], "pose": self._pose_id(sheet)})

    def beam_point(self, beam: str, uv: Any, beta: float) -> PointRef:
        """A lit pixel with projector angle β (rad): the ray ∩ the sheet at β (eq. 10)."""
        what = f"beam_point of '{beam}'"
        s = self._system(beam, Beam, what)
        kid, model = self.cameras[s.camera]
        if not np.isfinite(beta):
            raise ValueError(f"{what}: beta must be finite")
        return PointRef(beam, {"kind": "beam", "model": model, "camera": kid, "uv": _pixels(uv, what),
                               "beta": float(beta), "sheet": self.ids[f"{beam}.cam_from_laser"],
                               "pose": self._pose_id(beam)})

    def sensor_point(self, sensor: str, p: Any) -> PointRef:
        """A point measured by a range sensor (its frame)."""
        what = f"sensor_point of '{sensor}'"
        self._system(sensor, RangeSensor, what)
        c = np.asarray(p, dtype=float).ravel()
        if c.size != 3 or not np.all(np.isfinite(c)):
            raise ValueError(f"{what}: a point must be 3 finite numbers")
        return PointRef(sensor, {"kind": "constant", "c": c, "pose": self._pose_id(sensor)})

    # ---- planes and lines ------------------------------------------------------------
    def plane(self, name: str, owner: str | None = None, init: Any = None) -> SurfaceRef:
        """A plane variable in the frame of ``owner`` (None: the root frame); ``init`` [n, d] or
        None (fitted to the points of the first :meth:`coplanar` call)."""
        return self._surface(name, "plane", owner, init)

    def line(self, name: str, owner: str | None = None, init: Any = None) -> SurfaceRef:
        """A line variable [v, c] in the frame of ``owner`` (None: the root frame)."""
        return self._surface(name, "line", owner, init)

    def _surface(self, name: str, kind: str, owner: str | None, init: Any) -> SurfaceRef:
        if name in self.surfaces:
            raise ValueError(f"{kind} '{name}' exists already")
        if owner is not None:
            self._system(owner, object, f"{kind} '{name}'")
        ref = SurfaceRef(name, kind, owner, {"kind": kind, "var": None,
                                             "pose": None if owner is None else self._pose_id(owner)})
        if init is not None:
            self._init_surface(ref, init)
        self.surfaces[name] = ref
        return ref

    def _init_surface(self, ref: SurfaceRef, value: Any) -> None:
        v = np.asarray(value, dtype=float).ravel()
        if ref.kind == "plane":
            val = Plane(normal=S2(v[:3]), distance=[v[3] / np.linalg.norm(v[:3])])
        else:
            val = Line(direction=S2(v[:3]), point=v[3:6] - (v[3:6] @ v[:3]) / (v[:3] @ v[:3]) * v[:3])
        ref.spec["var"] = self._var(f"{ref.kind}:{ref.name}", val)

    def coplanar(self, points: Sequence[PointRef], plane: SurfaceRef, sigma: Any = None,
                 covariance: Any = None, information: Any = None, noise: NoiseModel | None = None,
                 loss: LossSpec = None) -> list[int]:
        """n·P − d ~ N(0, Σ) for each point (coplanarity, eq. 6); the plane may belong to any system.
        Returns the measurement ids."""
        what = f"plane group '{plane.name}'"
        if plane.kind == "line":
            raise TypeError(f"{what}: coplanar needs a plane, got a line")
        return self._constrain(points, plane, "plane", 1, sigma, covariance, information, noise, loss, what)

    def collinear(self, points: Sequence[PointRef], line: SurfaceRef, sigma: Any = None,
                  covariance: Any = None, information: Any = None, noise: NoiseModel | None = None,
                  loss: LossSpec = None) -> list[int]:
        """(I − v vᵀ)(P − c) ~ N(0, Σ) for each point (collinearity, eq. 6); the measurement ids."""
        what = f"line group '{line.name}'"
        if line.kind != "line":
            raise TypeError(f"{what}: collinear needs a line")
        return self._constrain(points, line, "line", 3, sigma, covariance, information, noise, loss, what)

    def _constrain(self, points, surface, kind, dim, sigma, covariance, information, noise, loss,
                   what) -> list[int]:
        points = list(points)
        if not points:
            raise ValueError(f"{what}: no points")
        if surface.spec.get("var") is None and surface.kind != "chain_plane":
            if len(points) < (3 if kind == "plane" else 2):
                raise ValueError(f"{what}: {len(points)} points cannot define a {kind}: give at least "
                                 f"{3 if kind == 'plane' else 2} (or an initial value)")
            P = np.array([self.evaluate(p) for p in points])
            if surface.owner is not None and surface.owner != self.root:
                P = (P - self.value(f"pose:{surface.owner}").pos) @ self.value(f"pose:{surface.owner}").R
            fit = fit_plane(P) if kind == "plane" else fit_line(P)
            v = np.r_[fit.normal.vec, fit.distance.vec] if kind == "plane" else np.r_[fit.direction.vec, fit.point.vec]
            self._init_surface(surface, v)
            if kind == "line":
                # v·c = 0 fixes the slide of c along v: a gauge, exactly satisfiable, so its weight
                # does not move the optimum (unit σ, in metres)
                self._add({"kind": "line_anchor", "surface": surface.spec}, 1, "line_anchor",
                          None, None, None, None, None, what)
        group = f"{kind}[{surface.name}]"
        mids = []
        for p in points:
            mids.append(self._add({"kind": kind, "a": p.spec, "surface": surface.spec}, dim, group, sigma,
                                  covariance, information, noise, loss, what))
            self._data[p.system] += 1
            if surface.owner is not None:
                self._edges.append((p.system, surface.owner))
        surface.points += len(points)
        if surface.owner is None:  # a free plane ties every system with points on it
            systems = list(dict.fromkeys(p.system for p in points))
            surface.systems = list(dict.fromkeys(surface.systems + systems))
            self._edges += [(surface.systems[0], s) for s in surface.systems[1:]]
        return mids

    # ---- other terms -----------------------------------------------------------------
    def link(self, a: PointRef, b: PointRef, sigma: Any = None, covariance: Any = None,
             information: Any = None, noise: NoiseModel | None = None, loss: LossSpec = None,
             name: str | None = None) -> int:
        """T_a p_a − T_b p_b ~ N(0, Σ/γ): the same physical point seen by two systems (eq. 4)."""
        what = f"link '{name}'" if name else f"link {a.system}–{b.system}"
        if a.system == b.system:
            raise ValueError(f"{what}: a link ties two different systems")
        if isinstance(sigma, (float, int)) and covariance is None and information is None and noise is None:
            sigma, nm = sigma / np.sqrt(self.gamma), None  # the cached isotropic models of _add
        else:
            nm = noise_model(3, sigma, covariance, information, noise, what)
            nm = NoiseModel.sqrt_information(np.sqrt(self.gamma) * np.asarray(nm.sqrt_information_matrix))
            sigma = None
        self._data[a.system] += 1
        self._data[b.system] += 1
        self._edges.append((a.system, b.system))
        return self._add({"kind": "link", "a": a.spec, "b": b.spec}, 3, f"link[{a.system}-{b.system}]",
                         sigma, None, None, nm, loss, what, name)

    def distance(self, a: PointRef, b: PointRef, d: float, sigma: Any = None, covariance: Any = None,
                 information: Any = None, noise: NoiseModel | None = None, loss: LossSpec = None) -> int:
        """‖p_a − p_b‖ − d ~ N(0, σ²) for two points of one system (eq. 5)."""
        what = f"distance of '{a.system}'"
        if a.system != b.system:
            raise ValueError(f"{what}: both points must belong to one system, got '{a.system}' and '{b.system}'")
        if not np.isfinite(d) or d < 0:
            raise ValueError(f"{what}: d must be a non-negative number, got {d}")
        self._data[a.system] += 1
        return self._add({"kind": "distance", "a": a.spec, "b": b.spec, "z": [float(d)]}, 1,
                         f"distance[{a.system}]", sigma, covariance, information, noise, loss, what)

    def project(self, point: PointRef, system: str, z: Any, camera: int = 0, sigma: Any = None,
                covariance: Any = None, information: Any = None, noise: NoiseModel | None = None,
                loss: LossSpec = None) -> int:
        """π(k, cam_from_system · root_from_system⁻¹ · P) − z ~ N(0, Σ): ``point`` (of any system)
        seen in camera ``camera`` (0 or 1 for a stereo pair) of ``system``."""
        what = f"projection into '{system}'"
        cam = self._camera_of(system, camera, what)
        self._data[system] += 1
        self._data[point.system] += 1
        if point.system != system:
            self._edges.append((point.system, system))
        return self._add({"kind": "projection", "a": point.spec, "z": _pixels(z, what), "camera": cam},
                         2, f"projection[{system}]", sigma, covariance, information, noise, loss, what)

    def project_targets(self, arm: str, joints: Any, p_in_target: Any, system: str, Z: Any, camera: int = 0,
                        reading: Any = None, sigma: Any = None, covariance: Any = None,
                        information: Any = None, noise: NoiseModel | None = None,
                        loss: LossSpec = None) -> int:
        """:meth:`project` of M points of the arm's target at one reading (a board view) in one
        camera, as one term: FK once for all M (the fast form of M ``project(arm_point(...))``).
        Z (M, 2) pixels; the noise is that of one point (2-dim)."""
        what = f"target projection of '{arm}' into '{system}'"
        a = self._system(arm, DHArm, what)
        P = np.asarray(p_in_target, dtype=float)
        Z = np.asarray(Z, dtype=float)
        if P.ndim != 2 or P.shape[1] != 3 or Z.shape != (len(P), 2) or len(P) == 0:
            raise ValueError(f"{what}: p_in_target must be (M, 3) and Z (M, 2) with M >= 1, got {P.shape} "
                             f"and {Z.shape}")
        if not (np.all(np.isfinite(P)) and np.all(np.isfinite(Z))):
            raise ValueError(f"{what}: non-finite targets or pixels")
        point = {"kind": "chain", "chain": self._chain(a, joints, reading, what), "pose": self._pose_id(arm)}
        cam = self._camera_of(system, camera, what)
        self._data[system] += 1
        self._data[arm] += 1
        if arm != system:
            self._edges.append((arm, system))
        return self._add({"kind": "target_projection", "a": point, "z": Z.ravel(), "targets": P, "camera": cam},
                         2, f"projection[{system}]", sigma, covariance, information, noise, loss, what)

    def _camera_of(self, system: str, camera: int, what: str) -> dict:
        s = self._system(system, (Stereo, Camera, LightSheet, Beam), what)
        if isinstance(s, Stereo):
            if camera not in (0, 1):
                raise ValueError(f"{what}: camera must be 0 or 1 for a stereo pair")
            cam = s.cam1 if camera == 0 else s.cam2
            c2 = self.ids[f"{system}.cam2_from_cam1"] if camera == 1 else None
        else:
            if camera != 0:
                raise ValueError(f"{what}: the system has one camera (camera=0)")
            cam, c2 = s.camera, None
        kid, model = self.cameras[cam]
        return {"model": model, "intrinsics": kid, "cam_from_system": c2, "pose": self._pose_id(system)}

    def _add(self, spec, dim, group, sigma, covariance, information, noise, loss, what, name=None) -> int:
        if isinstance(noise, NoiseModel) and sigma is None:
            nm = noise
        elif isinstance(sigma, (float, int)) and covariance is None and information is None and noise is None:
            # thousands of terms share a few scalar σ: build each NoiseModel once
            key = (dim, float(sigma))
            if key not in self._isotropic:
                self._isotropic[key] = noise_model(dim, sigma, None, None, None, what)
            nm = self._isotropic[key]
        else:
            nm = noise_model(dim, sigma, covariance, information, noise, what)
        return add_joint_term(self.problem, spec, nm, loss, name, group, what)

    # ---- values ----------------------------------------------------------------------
    def value(self, name: str) -> Any:
        """The current value of a variable by name (e.g. "cam1", "arm.dh", "pose:stereo")."""
        if name not in self.ids:
            raise KeyError(f"unknown variable '{name}'")
        return self.problem.value(self.ids[name])

    def pose(self, system: str) -> SE3:
        """root_from_system (identity for the root)."""
        self._system(system, object, "pose")
        return SE3() if system == self.root else self.value(f"pose:{system}")

    def table(self, arm: str) -> np.ndarray:
        """The arm's current full DH table (n × 4)."""
        a = self._system(arm, DHArm, "table")
        return a.table(self.value(f"{arm}.dh").vec) if f"{arm}.dh" in self.ids else a.nominal.copy()

    def mount(self, arm: str) -> SE3:
        a = self._system(arm, DHArm, "mount")
        return self.value(f"{arm}.mount") if a.mount_unknown else a.mount

    def target_pose(self, arm: str, joints: Any, reading: Any = None) -> SE3:
        """root_from_target at the readings (with the reading's encoder error, if estimated)."""
        a = self._system(arm, DHArm, "target_pose")
        q = np.asarray(joints, dtype=float)
        if (arm, reading) in self._readings:
            q = q + self.problem.value(self._readings[(arm, reading)]).vec
        return self.pose(arm) * dh_pose(self.table(arm), q, a.convention, a.base_from_chain, self.mount(arm))

    def evaluate(self, point: PointRef) -> np.ndarray:
        """The point in the root frame at the current values."""
        s, sp = self.systems[point.system], point.spec
        if sp["kind"] == "constant":
            p = sp["c"]
        elif sp["kind"] == "variable":
            p = self.problem.value(sp["var"]).vec
        elif sp["kind"] == "chain":
            ch = sp["chain"]
            q = ch["joints"] + (self.problem.value(ch["encoder"]).vec if ch.get("encoder") is not None else 0)
            T = dh_pose(self.table(s.name), q, s.convention, s.base_from_chain, self.mount(s.name))
            p = T.fromlocal(sp["c"])
        else:
            k = self.problem.value(sp["camera"]).vec
            if sp["kind"] == "sheet":
                pl = self.problem.value(sp["sheet"])
                sheet = np.r_[pl.normal.vec, pl.distance.vec]
            else:
                L = self.problem.value(sp["sheet"])
                n = L.R @ [np.cos(sp["beta"]), 0.0, -np.sin(sp["beta"])]
                sheet = np.r_[n, n @ L.pos]
            p = sheet_points(sp["model"], k, sheet, sp["uv"][None])[0]
        return self.pose(point.system).fromlocal(np.asarray(p, float))

    def plane_in_root(self, plane: SurfaceRef) -> np.ndarray:
        v = self.problem.value(plane.spec["var"])
        pl = np.r_[v.normal.vec, v.distance.vec]
        return pl if plane.owner is None else plane_in(self.pose(plane.owner), pl)

    # ---- checks, solving ---------------------------------------------------------------
    def check(self) -> None:
        """Raises ValueError naming a system with no data, a plane/line group with too few
        points, or the systems not connected to the root by any term."""
        if not self.systems:
            raise ValueError("the rig has no systems")
        idle = [s for s, n in self._data.items() if n == 0]
        if idle:
            raise ValueError(f"system(s) {idle} have no data: add points of them to terms "
                             f"(links, planes, projections, distances)")
        for ref in self.surfaces.values():
            need = 3 if ref.kind == "plane" else 2
            if ref.points < need:
                raise ValueError(f"{ref.kind} group '{ref.name}' has {ref.points} points: a {ref.kind} "
                                 f"needs at least {need}")
        reached = {self.root}
        queue = deque([self.root])
        while queue:
            s = queue.popleft()
            for a, b in self._edges:
                for u, v in ((a, b), (b, a)):
                    if u == s and v not in reached:
                        reached.add(v)
                        queue.append(v)
        missing = [s for s in self.systems if s not in reached]
        if missing:
            raise ValueError(f"the graph of systems is not connected: {missing} share no term with "
                             f"'{self.root}' (directly or through other systems); add links, shared "
                             f"planes or projections")

    def dh_values(self, arm: str) -> dict[str, float]:
        """The current values of arm ``arm``'s unknown DH entries by label ("a2": 0.43,
        ...), in the table order the variable ``<arm>.dh`` stores them in."""
        system = self._system(arm, DHArm, f"dh_values of '{arm}'")
        if f"{arm}.dh" not in self.ids:
            return {}
        values = self.problem[self.ids[f"{arm}.dh"]].vec
        return dict(zip(system.unknown_labels, (float(v) for v in values)))

    def degeneracy(self) -> list[tuple[float, list[str]]]:
        """Directions the data cannot determine: (singular value ratio, parameter names)
        from the whitened Jacobian at the current values (:func:`boxplus.calib.report`)."""
        from boxplus.calib.report import report

        return report(self.problem).undetermined

    def check_determined(self) -> None:
        """Raises ValueError naming the parameters the data cannot determine."""
        bad = self.degeneracy()
        if bad:
            names = sorted({n for _, ns in bad for n in ns})
            raise ValueError(f"the data cannot determine {names}: add data, priors (prior_sigma) or "
                             f"take these entries out of 'unknown'")

    def suggest_arm_poses(self, arm: str, candidates: Sequence[Any], p_in_target: Any, system: str,
                          sigma: Any, cameras: Sequence[int] | None = None,
                          variables: Sequence[str] | None = None,
                          score: Callable[[np.ndarray], float] | None = None,
                          image_size: tuple[int, int] | None = None) -> list[tuple[int, float]]:
        """What to capture next: candidate joint readings of ``arm`` ranked by the σ their
        board view would leave (as :func:`boxplus.calib.suggest.rank_candidates` ranks the
        captures of any problem).

        Each candidate adds, to a copy of the rig, the view of the target points
        ``p_in_target`` (M, 3) in ``cameras`` of ``system`` (default: both cameras of a
        stereo pair, the one camera otherwise) at corner noise ``sigma``, with a reading of
        its own (encoder noise) — the terms :meth:`project_targets` adds, at the current
        estimates (only the Jacobians enter the covariance). Scored by ``score`` of the
        joint covariance of ``variables`` (names of :attr:`ids`; default the arm's DH
        table); the default score is the mean over their tangent directions of σ after /
        σ now (1: the view adds nothing), which mixes lengths and angles without units
        and is not stuck at the entries only a prior bounds, as the largest σ would be. With ``image_size`` (width, height) a candidate
        whose target leaves any of the images, or lies behind a camera, is left out.
        Returns [(candidate index, score)], best first; call after :meth:`solve`."""
        what = f"suggest_arm_poses of '{arm}'"
        self._system(arm, DHArm, what)
        s = self._system(system, (Stereo, Camera, LightSheet, Beam), what)
        cams = list(cameras) if cameras is not None else ([0, 1] if isinstance(s, Stereo) else [0])
        names = list(variables) if variables is not None else [f"{arm}.dh"]
        missing = [n for n in names if n not in self.ids]
        if missing:
            raise ValueError(f"{what}: no variable {missing} (variables: {', '.join(self.ids)})")
        ids = [self.ids[n] for n in names]
        before = np.sqrt(np.diag(np.asarray(self.problem.joint_covariance(ids))))

        def relative(c: np.ndarray) -> float:
            return float(np.mean(np.sqrt(np.diag(c)) / before))

        measure = score or relative
        P = np.asarray(p_in_target, dtype=float)
        zeros = np.zeros((len(P), 2))  # z = 0: a term's error is then its predicted pixels
        out = []
        for i, q in enumerate(candidates):
            rig = self._bound_to(self.problem.copy())
            mids = [rig.project_targets(arm, q, P, system, zeros, camera=c, reading=("suggest", i),
                                        sigma=sigma) for c in cams]
            if image_size is not None and not all(_in_image(rig, m, image_size) for m in mids):
                continue
            out.append((i, measure(np.asarray(rig.problem.joint_covariance(ids)))))
        return sorted(out, key=lambda r: r[1])

    def _bound_to(self, problem: OptimizationProblem) -> JointRig:
        """This rig writing into ``problem`` (a copy of its own), its bookkeeping copied so
        that terms added there leave this rig unchanged."""
        rig = copy.copy(self)
        rig.problem = problem
        rig.ids, rig.surfaces = dict(self.ids), dict(self.surfaces)
        rig._edges, rig._data = list(self._edges), dict(self._data)
        rig._readings, rig._reading_q = dict(self._readings), dict(self._reading_q)
        return rig

    def factory(self) -> Callable[[], OptimizationProblem]:
        """A picklable callable building a fresh copy of the problem (same ids, current values,
        the same fixed variables): what parallel restarts solve. The copy is rebuilt from the
        problem's journal (:meth:`OptimizationProblem.copy`)."""
        return functools.partial(OptimizationProblem.copy, self.problem.copy())

    def solve(self, restarts: int = 0, seed: int | None = 0,
              perturbation: Callable[[Any], np.ndarray] | None = None,
              executor: Executor | None = None, **solve_kw: Any) -> RigResult:
        """Checks the rig, then solves with ``restarts`` random restarts about the first
        solution (:func:`boxplus.joint.solve_with_restarts`; ``executor`` runs them in parallel,
        each on a :meth:`factory` copy, with the same answer as without).

        The method is ``'auto'`` (Gauss–Newton with the line search, LM when a step
        fails; :class:`boxplus.SolverOptions`) unless ``options`` or ``method`` say
        otherwise: on the generated rigs of :func:`boxplus.synthetic.joint_rigs.make_rig`
        (6 seeds × 2 folds × 4 methods) it reaches LM's cost (within 1.2e-12 relative)
        in 0.41 of LM's CPU time: at the optimum χ²/dof ≈ 1, small residuals against the
        model's curvature, where Gauss–Newton takes full steps and converges quickly."""
        self.check()
        if "options" not in solve_kw:
            solve_kw.setdefault("method", "auto")
        factory = self.factory() if restarts > 0 else None
        rr = solve_with_restarts(self.problem, restarts, seed=seed, perturbation=perturbation,
                                 executor=executor, factory=factory, **solve_kw)
        return RigResult(rr.best_cost, rr.best.termination, dict(self.problem.rms().items()), rr)


@journalled
def add_joint_term(problem: OptimizationProblem, spec: dict, noise: NoiseModel, loss: LossSpec,
                   name: str | None, group: str, what: str) -> int:
    """One C++ joint term (factors/joint/terms.h) described by ``spec``, whose variables
    are named by id; journalled, so a rig's problem copies and pickles like any other."""
    try:
        factor = _core.joint_factor(problem._core, spec, noise, what)
    except (RuntimeError, ValueError, KeyError, TypeError) as e:
        raise ValueError(f"{what}: {e}") from None
    return problem.add_factor(factor, loss, name, group)


def _in_image(rig: JointRig, mid: int, image_size: tuple[int, int]) -> bool:
    """Whether the pixels a term with z = 0 predicts (its error) lie in the image and in
    front of the camera (a point behind it projects to non-finite or mirrored pixels)."""
    with np.errstate(invalid="ignore"):
        uv = np.asarray(rig.problem.measurement_errors(mid), dtype=float).reshape(-1, 2)
    w, h = image_size
    return bool(np.all(np.isfinite(uv)) and np.all(uv >= 0) and np.all(uv[:, 0] < w) and np.all(uv[:, 1] < h))


def _pixels(z: Any, what: str) -> np.ndarray:
    a = np.asarray(z, dtype=float).ravel()
    if a.size != 2 or not np.all(np.isfinite(a)):
        raise ValueError(f"{what}: a pixel must be 2 finite numbers, got {z!r}")
    return a


