"""A seeded rig like Le & Ng's Sec. VIII–XI robot, with its ground truth.

:func:`make_rig` simulates

* a 5-DOF arm in standard DH (Katana-like link lengths) whose true table is
  the maker's nominal one perturbed by ~3 mm / 1° per entry, holding a
  checkerboard on a machined (known) mount at the flange;
* a stereo pair (cam1, cam2; ``simple_radial`` [f, cx, cy, k1]) looking at the
  workspace;
* a laser-line triangulator: camera 2 plus a light sheet fixed in camera 2's
  frame — stripe pixels on a surface, with no correspondence along the line;
* board views: encoder readings (noisy), both cameras' corner pixels and the
  stripe on the board; plane views: a textured plane (points seen by both
  cameras, no correspondence to anything) with the stripe on it;
* 5 given folds (each holds out 2 board views and 1 plane view).

Everything is in the arm's base frame ("arm", z up); poses are SE3 b_from_a.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from boxplus.geometry import look_at
from boxplus.joint.geometry import dh_pose, plane_in, project
from boxplus.manifolds import SE3, SO3

__all__ = ["BoardView", "PlaneView", "SyntheticRig", "make_rig", "NOMINAL_DH"]

MODEL = "simple_radial"
IMAGE = (640, 480)
# The maker's table, one row [θ offset, d, a, α] per joint (m, rad).
NOMINAL_DH = np.array([
    [0.0, 0.20, 0.0, np.pi / 2],
    [0.0, 0.0, 0.19, 0.0],
    [0.0, 0.0, 0.14, 0.0],
    [0.0, 0.0, 0.0, np.pi / 2],
    [0.0, 0.10, 0.0, 0.0],
])
HOME = np.array([0.0, 0.9, -1.0, 0.6, 0.0])  # the board faces the cameras


@dataclass
class BoardView:
    joints: np.ndarray        # encoder readings (rad), with noise
    joints_true: np.ndarray
    z1: np.ndarray            # (N, 2) corners in camera 1 (pixels)
    z2: np.ndarray            # (N, 2) in camera 2
    stripe: np.ndarray        # (M, 2) stripe pixels in camera 2 (on the board)


@dataclass
class PlaneView:
    z1: np.ndarray            # (P, 2) textured points in camera 1
    z2: np.ndarray            # (P, 2) the same points in camera 2
    stripe: np.ndarray        # (M, 2) stripe pixels in camera 2 (on the plane)
    plane_true: np.ndarray    # [n, d] in the arm's frame


@dataclass
class SyntheticRig:
    """The simulated rig: truth, the maker's / nominal values, data and folds."""

    model: str
    convention: str
    dh_nominal: np.ndarray
    dh_true: np.ndarray
    end_from_board: SE3               # the board mount (known, machined)
    board: np.ndarray                 # (N, 3) corners in the board frame
    k1_true: np.ndarray
    k2_true: np.ndarray
    k_nominal: np.ndarray             # the data sheet's intrinsics (initial guess)
    arm_from_cam1: SE3                # root_from_stereo (stereo frame = camera 1)
    cam2_from_cam1: SE3
    sheet_true: np.ndarray            # [n, d] light sheet in camera 2
    sigma_px: float
    sigma_encoder: float
    boards: list[BoardView] = field(default_factory=list)
    planes: list[PlaneView] = field(default_factory=list)
    folds: list[tuple[dict[str, np.ndarray], dict[str, np.ndarray]]] = field(default_factory=list)

    @property
    def arm_from_cam2(self) -> SE3:
        return self.arm_from_cam1 * self.cam2_from_cam1.inverse()

    def board_pose(self, joints: np.ndarray, dh: np.ndarray | None = None) -> SE3:
        """arm_from_board at the readings (true table unless ``dh`` is given)."""
        return dh_pose(self.dh_true if dh is None else dh, joints, self.convention,
                       None, self.end_from_board)


def _stripe_on_plane(sheet_in_cam: np.ndarray, cam_from_surface: SE3, inside, n: int) -> np.ndarray:
    """n points (surface frame, z = 0) of the sheet ∩ the surface's plane z = 0 that ``inside`` keeps."""
    s = plane_in(cam_from_surface.inverse(), sheet_in_cam)  # the sheet in the surface's frame
    # points with s_x x + s_y y = s_d on z = 0
    if abs(s[0]) > abs(s[1]):
        y = np.linspace(-1.0, 1.0, 4001)
        x = (s[3] - s[1] * y) / s[0]
    else:
        x = np.linspace(-1.0, 1.0, 4001)
        y = (s[3] - s[0] * x) / s[1]
    P = np.column_stack([x, y, np.zeros_like(x)])
    P = P[inside(P)]
    if len(P) < n:
        return np.zeros((0, 3))
    return P[np.linspace(0, len(P) - 1, n).round().astype(int)]


def _visible(uv: np.ndarray, p_in_cam: np.ndarray, margin: float = 10.0) -> bool:
    return bool(np.all(p_in_cam[:, 2] > 0.2) and np.all(uv > margin)
                and np.all(uv[:, 0] < IMAGE[0] - margin) and np.all(uv[:, 1] < IMAGE[1] - margin))


def make_rig(seed: int = 0, n_boards: int = 10, n_planes: int = 5, n_folds: int = 5,
             cols: int = 8, rows: int = 6, square: float = 0.025, stripe_points: int = 15,
             plane_points: int = 20, sigma_px: float = 0.3, sigma_encoder: float = 2e-4,
             dh_sigma: tuple[float, float] = (0.003, np.radians(1.0))) -> SyntheticRig:
    """The rig of the module docstring, seeded.

    Parameters
    ----------
    seed : int
        Seed of everything random (perturbation of the table, views, noise).
    n_boards, n_planes, n_folds : int
        Views of each kind and the number of given folds (each kind is dealt in
        order: fold i holds out views i, i + n_folds, ...).
    cols, rows, square : board corners and their spacing (m)
    stripe_points, plane_points : stripe pixels per view, textured points per plane view
    sigma_px, sigma_encoder : pixel noise (px) and encoder noise (rad)
    dh_sigma : (length, angle)
        Standard deviations of the true table about the nominal one (m, rad).
    """
    rng = np.random.default_rng(seed)
    dh_true = NOMINAL_DH.copy()
    dh_true[:, [1, 2]] += rng.normal(0.0, dh_sigma[0], (5, 2))
    dh_true[:, [0, 3]] += rng.normal(0.0, dh_sigma[1], (5, 2))
    gx, gy = np.meshgrid(np.arange(cols) * square, np.arange(rows) * square)
    board = np.column_stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)])
    board -= board.mean(axis=0) * [1, 1, 0]
    end_from_board = SE3(SO3.exp([0.0, 0.0, np.pi / 2]), [0.0, 0.0, 0.03])
    home = dh_pose(dh_true, HOME, "standard", None, end_from_board)
    # the cameras look at the board at home from 0.7 m in front of it, 0.12 m apart
    normal = home.R[:, 2]
    eye = home.pos + 0.7 * normal + np.array([0.0, 0.0, 0.1])
    arm_from_cam1 = look_at(eye, home.pos, (0.0, 0.0, 1.0))
    eye2 = eye + 0.12 * arm_from_cam1.R[:, 0]
    arm_from_cam2 = look_at(eye2, home.pos, (0.0, 0.0, 1.0))
    cam2_from_cam1 = arm_from_cam2.inverse() * arm_from_cam1
    o = np.array([-0.15, 0.0, 0.0])  # the laser, left of camera 2; its sheet contains y
    n = np.cross([0.0, 1.0, 0.0], [0.2, 0.0, 1.0])
    n /= np.linalg.norm(n)
    sheet = np.r_[n, n @ o]
    k1 = np.array([600.0, 322.0, 238.0, -0.10])
    k2 = np.array([590.0, 318.0, 243.0, -0.08])
    rig = SyntheticRig(MODEL, "standard", NOMINAL_DH.copy(), dh_true, end_from_board, board, k1, k2,
                       np.array([600.0, 320.0, 240.0, 0.0]), arm_from_cam1, cam2_from_cam1, sheet,
                       sigma_px, sigma_encoder)
    half = np.abs(board).max(axis=0)[:2] + square / 2

    def on_board(P):
        return np.all(np.abs(P[:, :2]) <= half, axis=1)

    def pix(k, cam_from_x, P):
        p = P @ cam_from_x.R.T + cam_from_x.pos
        return project(MODEL, k, p), p

    while len(rig.boards) < n_boards:
        q = HOME + rng.normal(0.0, [0.25, 0.15, 0.15, 0.25, 0.5])
        arm_from_board = rig.board_pose(q)
        cam1_from_board = arm_from_cam1.inverse() * arm_from_board
        cam2_from_board = arm_from_cam2.inverse() * arm_from_board
        uv1, p1 = pix(k1, cam1_from_board, board)
        uv2, p2 = pix(k2, cam2_from_board, board)
        facing = -(cam1_from_board.R[:, 2] @ cam1_from_board.pos) / np.linalg.norm(cam1_from_board.pos)
        stripe = _stripe_on_plane(sheet, cam2_from_board, on_board, stripe_points)
        if not (_visible(uv1, p1) and _visible(uv2, p2) and facing > 0.5 and len(stripe)):
            continue
        s_uv, _ = pix(k2, cam2_from_board, stripe)
        rig.boards.append(BoardView(q + rng.normal(0.0, sigma_encoder, 5), q,
                                    uv1 + rng.normal(0.0, sigma_px, uv1.shape),
                                    uv2 + rng.normal(0.0, sigma_px, uv2.shape),
                                    s_uv + rng.normal(0.0, sigma_px, s_uv.shape)))
    while len(rig.planes) < n_planes:
        tilt = SO3.exp(rng.normal(0.0, 0.3, 3))
        cam1_from_plane = SE3(tilt * SO3.exp([np.pi, 0.0, 0.0]),
                              [rng.normal(0, 0.03), rng.normal(0, 0.03), rng.uniform(0.6, 0.8)])
        cam2_from_plane = cam2_from_cam1 * cam1_from_plane
        P = np.column_stack([rng.uniform(-0.15, 0.15, (plane_points, 2)), np.zeros(plane_points)])
        uv1, p1 = pix(k1, cam1_from_plane, P)
        uv2, p2 = pix(k2, cam2_from_plane, P)
        stripe = _stripe_on_plane(sheet, cam2_from_plane, lambda S: np.all(np.abs(S[:, :2]) <= 0.15, axis=1),
                                  stripe_points)
        if not (_visible(uv1, p1) and _visible(uv2, p2) and len(stripe)):
            continue
        s_uv, _ = pix(k2, cam2_from_plane, stripe)
        rig.planes.append(PlaneView(uv1 + rng.normal(0.0, sigma_px, uv1.shape),
                                    uv2 + rng.normal(0.0, sigma_px, uv2.shape),
                                    s_uv + rng.normal(0.0, sigma_px, s_uv.shape),
                                    plane_in(arm_from_cam1 * cam1_from_plane, np.array([0, 0, 1.0, 0]))))
    for i in range(n_folds):
        val = {"boards": np.arange(i, n_boards, n_folds), "planes": np.arange(i, n_planes, n_folds)}
        train = {kind: np.setdiff1d(np.arange(n), val[kind])
                 for kind, n in (("boards", n_boards), ("planes", n_planes))}
        rig.folds.append((train, val))
    return rig
