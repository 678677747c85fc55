"""3D systems: a sensor or a group of sensors that turns a datum u into a point.

Le & Ng, "Joint calibration of multiple sensors", IROS 2009, Sec. IV-B and
VIII: a *3D system* has an intrinsic model p = I(α, u) ∈ R³ (eq. 3) that maps
a calibration datum u to a point in the system's own frame, given the
system's intrinsic parameters α. α may include transforms between the
members of a group (e.g. the two cameras of a stereo pair).

A system declares its intrinsic parameters as named manifold values (their
initial values) and implements :meth:`ThreeDSystem.points`, vectorised over
rows: ``points(alpha, U)`` gets ``alpha`` with one attribute per parameter,
each a batch (:mod:`boxplus.batch`) holding that parameter's value in every
row, and U (N, data_size), and returns (N, 3). A new kind of system is a
subclass writing ``parameters`` and ``points``; the solver differentiates it
numerically in the tangent space of each parameter.

Poses follow the library's convention: SE(3) = R³ × SO(3), tangent order
[translation, rotation]; ``b_from_a.fromlocal(p_in_a) = R p + t = p_in_b``.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import SimpleNamespace
from typing import Any

import numpy as np

from boxplus import batch
from boxplus.geometry import triangulate_midpoint
from boxplus.joint.camera import CameraIntrinsics, ray
from boxplus.manifolds import Rn, codec_of

__all__ = ["ActiveTriangulation", "RangeFinder", "RobotArm", "StereoPair", "ThreeDSystem", "camera"]


class ThreeDSystem:
    """Base class: a named 3D system with intrinsic model I(α, u).

    Parameters
    ----------
    name : str
        Unique name of the system (used in error messages and results).
    **parameters
        Initial values of the intrinsic parameters, by name (the names the
        subclass declares in ``parameter_names``).

    Attributes
    ----------
    parameter_names : tuple of str
        The names of α's members, in order.
    data_size : int
        Number of columns of a datum u.
    """

    parameter_names: tuple = ()
    data_size: int = 0

    def __init__(self, name: str, **parameters: Any) -> None:
        if not isinstance(name, str) or not name:
            raise ValueError(f"{type(self).__name__}: a system needs a non-empty name")
        self.name = name
        missing = [p for p in self.parameter_names if p not in parameters]
        unknown = [p for p in parameters if p not in self.parameter_names]
        if missing or unknown:
            raise TypeError(
                f"{type(self).__name__} '{name}': parameters are {list(self.parameter_names)}; "
                f"missing {missing}, unknown {unknown}"
            )
        for p in self.parameter_names:
            codec_of(parameters[p])  # raises TypeError for non-manifold values
        self.parameters: dict[str, Any] = {p: parameters[p] for p in self.parameter_names}

    def points(self, alpha: Any, U: np.ndarray) -> np.ndarray:
        """I(α, U): the points (N, 3) in the system's frame; ``alpha`` holds batches."""
        raise NotImplementedError

    def check_data(self, U: Any, what: str) -> np.ndarray:
        """U as an (N, data_size) float array; a ValueError naming ``what`` otherwise."""
        U = np.asarray(U, dtype=float)
        if U.ndim == 1 and self.data_size == 1:
            U = U[:, None]
        if U.ndim != 2 or U.shape[1] != self.data_size:
            raise ValueError(
                f"{what}: data of system '{self.name}' ({type(self).__name__}) must have shape "
                f"(N, {self.data_size}), got {U.shape}"
            )
        if not np.all(np.isfinite(U)):
            raise ValueError(f"{what}: data of system '{self.name}' have non-finite entries")
        return U

    def evaluate(self, U: Any, values: Mapping[str, Any] | None = None) -> np.ndarray:
        """I(α, U) at concrete parameter values (default: the initial ones)."""
        U = self.check_data(U, f"{self.name}.evaluate")
        values = {**self.parameters, **(values or {})}
        alpha = SimpleNamespace(**{
            p: batch.view(codec_of(v), np.tile(codec_of(v).to_ambient(v), (len(U), 1)))
            for p, v in values.items()
        })
        return self.points(alpha, U)

    def __repr__(self) -> str:
        return f"{type(self).__name__}('{self.name}')"


class RangeFinder(ThreeDSystem):
    """A sensor that measures points directly (Le & Ng eq. 12): I(u) = u.

    No intrinsic parameters (its makers calibrated it). A datum is the point
    (N, 3) in the sensor's frame.
    """

    parameter_names = ()
    data_size = 3

    def __init__(self, name: str) -> None:
        super().__init__(name)

    def points(self, alpha: Any, U: np.ndarray) -> np.ndarray:
        return U


class StereoPair(ThreeDSystem):
    """Two cameras triangulating a pixel pair (Le & Ng eq. 9).

    α = (cam1, cam2: :data:`CameraIntrinsics`, cam2_from_cam1: SE3), u =
    [u1, v1, u2, v2] (pixels in camera 1, then camera 2). The point, in the
    frame of camera 1, is the midpoint of the shortest segment between the two
    viewing rays.
    """

    parameter_names = ("cam1", "cam2", "cam2_from_cam1")
    data_size = 4

    def points(self, alpha: Any, U: np.ndarray) -> np.ndarray:
        d1 = ray(alpha.cam1, U[:, 0:2])
        X = alpha.cam2_from_cam1  # p_in_cam2 = R p_in_cam1 + t
        Rt = np.transpose(X.R, (0, 2, 1))
        o2 = -np.einsum("nij,nj->ni", Rt, X.pos)  # centre of camera 2 in camera 1
        d2 = np.einsum("nij,nj->ni", Rt, ray(alpha.cam2, U[:, 2:4]))
        return triangulate_midpoint(np.zeros(3), d1, o2, d2, f"StereoPair '{self.name}'")


class ActiveTriangulation(ThreeDSystem):
    """A camera and a laser projecting a sheet at a measured angle β (Le & Ng eq. 10).

    α = (camera: :data:`CameraIntrinsics`, cam_from_laser: SE3), u = [u, v, β]
    (pixel of the lit point, projector angle in radians). In the laser's frame
    the sheet contains the y axis and the direction (sin β, 0, cos β), i.e. its
    normal is n(β) = (cos β, 0, −sin β). The point, in the camera's frame, is
    where the viewing ray meets the sheet.

    Translation of the laser along its own y axis leaves every sheet unchanged,
    so that direction of cam_from_laser is not observable (the solver's
    damping keeps it where it starts).
    """

    parameter_names = ("camera", "cam_from_laser")
    data_size = 3

    def points(self, alpha: Any, U: np.ndarray) -> np.ndarray:
        d = ray(alpha.camera, U[:, 0:2])
        beta = U[:, 2]
        n_laser = np.column_stack([np.cos(beta), np.zeros_like(beta), -np.sin(beta)])
        L = alpha.cam_from_laser
        n = np.einsum("nij,nj->ni", L.R, n_laser)
        s = np.sum(n * L.pos, 1) / np.sum(n * d, 1)
        return s[:, None] * d


class RobotArm(ThreeDSystem):
    """Forward kinematics of a 5-DOF arm's tool point (Le & Ng eq. 11).

    Joint angles θ = e + o from encoder readings e (radians) and offsets o.
    The chain, in the base frame (z up)::

        p = Rz(θ1) ( [0, 0, d1] + Ry(θ2) ( [a2, 0, 0] + Ry(θ3) ( [a3, 0, 0]
              + Ry(θ4) ( [a4, 0, 0] + Rx(θ5) [0, 0, a5] ) ) ) )

    α = (lengths: Rn(4) = [a2, a3, a4, a5] in metres, offsets: Rn(4) = offsets
    of joints 2..5 in radians). The base height d1 and the offset of joint 1
    define the base frame and are constants (``base_height``): changing them
    would only move the frame every other system is expressed in.
    u = the five encoder readings.
    """

    parameter_names = ("lengths", "offsets")
    data_size = 5

    def __init__(self, name: str, lengths: Any, offsets: Any, base_height: float) -> None:
        super().__init__(name, lengths=_rn(lengths, 4, name, "lengths"), offsets=_rn(offsets, 4, name, "offsets"))
        self.base_height = float(base_height)

    def points(self, alpha: Any, U: np.ndarray) -> np.ndarray:
        a = alpha.lengths.vec
        th = U.copy()
        th[:, 1:] += alpha.offsets.vec
        c, s = np.cos(th), np.sin(th)
        # innermost: Rx(θ5) [0, 0, a5], then + [a4, 0, 0]
        x = a[:, 2]
        y = -s[:, 4] * a[:, 3]
        z = c[:, 4] * a[:, 3]
        for j, extra in ((3, 1), (2, 0), (1, None)):  # Ry(θ4), Ry(θ3), Ry(θ2)
            x, z = c[:, j] * x + s[:, j] * z, -s[:, j] * x + c[:, j] * z
            if extra is not None:
                x = x + a[:, extra]
        z = z + self.base_height
        x, y = c[:, 0] * x - s[:, 0] * y, s[:, 0] * x + c[:, 0] * y
        return np.column_stack([x, y, z])


def _rn(v: Any, n: int, name: str, what: str) -> Rn:
    if isinstance(v, Rn):
        arr = v.vec
    else:
        arr = np.atleast_1d(np.asarray(v, dtype=float))
    if arr.shape != (n,):
        raise ValueError(f"RobotArm '{name}': {what} must be {n} numbers, got shape {arr.shape}")
    return Rn(arr)


def camera(f: float, cx: float, cy: float, k1: float = 0.0) -> Any:
    """Camera intrinsics value (a :data:`CameraIntrinsics`)."""
    return CameraIntrinsics(f=[f], c=[cx, cy], k1=[k1])

