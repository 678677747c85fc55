"""A MEMS accelerometer on raw counts (Kinect-style: 819 counts per g, ±2 % per
axis, tens of counts of bias, a slightly non-orthogonal triad) calibrated
against a camera that sees a board: per-axis scale, bias and misalignment,
and the rotation from the camera to the IMU as an SO3 (its translation does
not enter gravity readings, so it is not a variable at all).

    a_i = T · R(imu_from_cam) · R(world_from_cam_i)ᵀ · g_world + b      (counts)
    T   = diag(s) · [[1, mxy, mxz], [0, 1, myz], [0, 0, 1]]

The camera poses come from the board (here simulated and solved jointly with
the intrinsics). The script compares the per-axis model with the single-scale
one on the same readings: the latter ends many σ off.

Run: .venv/bin/python examples/calib_accelerometer.py [--model 6|9]
"""

from __future__ import annotations

import argparse

import boxplus as bp
import numpy as np
from boxplus.calib import add_board, add_camera, add_gravity, init_camera, report, rotation_between
from boxplus.synthetic.cameras import TRUE_K, board_points, observe, random_views

G_WORLD = np.array([0.0, 0.0, -9.81])
COUNTS = 819 / 9.81  # counts per m/s²
TRUE_ACCEL = np.array([COUNTS * 1.02, COUNTS * 0.985, COUNTS * 1.01, 31.0, -18.0, 44.0,
                       0.012, -0.008, 0.015])
IMU_FROM_CAM = bp.SO3.exp(np.array([0.3, -1.2, 0.5]))


def read_counts(accel: np.ndarray, world_from_cam: bp.SE3) -> np.ndarray:
    """The accelerometer's reading (counts) for a camera pose, the model above."""
    a = IMU_FROM_CAM.R @ world_from_cam.rot.R.T @ G_WORLD
    U = np.array([[1, accel[6], accel[7]], [0, 1, accel[8]], [0, 0, 1.0]])
    return accel[:3] * (U @ a) + accel[3:6]


def calibrate(n_accel: int, rng: np.random.Generator, counts_sigma: float = 2.0,
              pixel_sigma: float = 0.3):
    p = board_points()
    # the board tilted many ways relative to gravity: every axis sees g at many angles
    views = random_views(30, rng, p.mean(axis=0), spread=0.6, roll=3.0)
    Z = [observe(TRUE_K, v, p, pixel_sigma, rng, image_size=None)[0] for v in views]
    A = [read_counts(TRUE_ACCEL, v) + rng.normal(0, counts_sigma, 3) for v in views]
    K, cam_from_board = init_camera(p, Z, (640, 480))
    o = bp.OptimizationProblem()
    cam = add_camera(o, "camera", K)
    ident = o.add_random_var(bp.SE3(), fixed=True, name="identity")
    # initial values: the rotation from the directions (Wahba), nominal scale, no bias
    dirs = np.array([pose.inverse().rot.R.T @ G_WORLD for pose in cam_from_board])
    imu = o.add_random_var(bp.SO3(rotation_between(dirs, np.array(A))), name="imu_from_cam")
    a0 = np.zeros(n_accel)
    a0[:3 if n_accel >= 6 else 1] = COUNTS
    labels = {4: ["s", "bx", "by", "bz"], 6: ["sx", "sy", "sz", "bx", "by", "bz"],
              9: ["sx", "sy", "sz", "bx", "by", "bz", "mxy", "mxz", "myz"]}[n_accel]
    accel = o.add_random_var(bp.Rn(a0), name="accel", labels=labels)
    for i, (z, a, pose) in enumerate(zip(Z, A, cam_from_board)):
        w = o.add_random_var(pose.inverse(), name=f"world_from_cam_{i}")
        add_board(o, z, cam, w, ident, p, sigma=pixel_sigma, group="camera")
        add_gravity(o, a, w, imu, accel, g_in_world=G_WORLD, sigma=counts_sigma)
    result = o.solve()
    return o, accel, imu, result


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--model", type=int, choices=[6, 9], default=9,
                    help="6: per-axis scale and bias, 9: also misalignment")
    args = ap.parse_args()
    for n in (4, args.model):
        o, accel, imu, result = calibrate(n, np.random.default_rng(0))
        rep = report(o)
        est = o[accel].vec
        truth = TRUE_ACCEL[:n] if n >= 6 else np.r_[COUNTS, TRUE_ACCEL[3:6]]
        print(f"accel model Rn({n}): {result.termination}, gravity RMS {rep.rms['gravity']:.2f} counts")
        for lab, e, t, s in zip(o.labels(accel), est, truth, rep.std("accel")):
            print(f"  {lab:6s} {e:10.4f}  truth {t:10.4f}  ({(e - t) / s:+6.1f} σ)")
        d = (IMU_FROM_CAM.inverse() * o[imu]).log()
        print(f"  imu_from_cam rotation error {np.degrees(np.linalg.norm(d)):.4f}°")


if __name__ == "__main__":
    main()
