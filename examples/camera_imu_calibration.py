"""Camera–IMU calibration on a levelled board (MTKM paper, Sec. V-A, first
step): intrinsics, one world_from_cam per view, the rotation camera → IMU and the
accelerometer's scale and bias, jointly, from a simulated rig with known truth.

    z_ij   = π(k, world_from_cam_i⁻¹ ∘ p_world_j)                    (board corners, px)
    g_imu_i = s · R_imu_from_cam · R_world_from_camᵀ · g_world + b          (accelerometer, m/s²)

The board is levelled, so gravity in the board frame is g_world = (0, 0, −9.81)
(board z points down, MTKM's sign). The IMU's translation does not enter the
measurements; it is measured by hand (a prior), as in the paper.

Run: .venv/bin/python examples/camera_imu_calibration.py [--noise PX] [--out DIR]
"""

from __future__ import annotations

import argparse
from typing import Any

import boxplus as bp
import numpy as np
from boxplus.calib import (
    add_board,
    add_camera,
    add_gravity,
    check_views,
    init_camera,
    report,
    rotation_between,
)
from boxplus.synthetic.cameras import TRUE_K, board_points, observe, random_views

G_WORLD = np.array([0.0, 0.0, -9.81])
# Any: the true values of different manifolds (poses, intrinsics vectors, ...).
TRUTH: dict[str, Any] = dict(k=TRUE_K, imu_from_cam=bp.SE3(bp.SO3.exp(np.array([0.3, -1.2, 0.5])), [0.02, -0.05, 0.01]),
             accel=np.array([1.02, 0.05, -0.03, 0.02]))


def simulate(rng, pixel_sigma=0.5, accel_sigma=0.02, n_views=12):
    p_in_world = board_points()
    views = random_views(n_views, rng, p_in_world.mean(axis=0))
    z, g = [], []
    R_ci = TRUTH["imu_from_cam"].rot.R
    s, b = TRUTH["accel"][0], TRUTH["accel"][1:]
    for world_from_cam in views:
        uv, vis = observe(TRUTH["k"], world_from_cam, p_in_world, pixel_sigma, rng)
        assert vis.all()
        z.append(uv)
        g.append(s * R_ci @ world_from_cam.rot.R.T @ G_WORLD + b + rng.normal(0, accel_sigma, 3))
    return dict(p_in_world=p_in_world, z=z, g=g, views=views, pixel_sigma=pixel_sigma,
                accel_sigma=accel_sigma, image_size=(640, 480))


def imu_position(imu_from_cam):
    """The hand-measured translation of the IMU (a prior on the translation only)."""
    return imu_from_cam.pos


def calibrate(data, gravity_views=None, estimate_accel=True):
    p_in_world, z, g = data["p_in_world"], data["z"], data["g"]
    z = check_views(z, p_in_world, data["image_size"], "camera")
    # closed-form initial values: Zhang, then camera→IMU rotation from gravity pairs
    K, cam_from_board = init_camera(p_in_world, z, data["image_size"])
    gravity_views = range(len(z)) if gravity_views is None else gravity_views
    g_in_cam = np.array([cam_from_board[i].rot.R @ G_WORLD for i in gravity_views])
    try:
        R0 = rotation_between(g_in_cam, np.array([g[i] for i in gravity_views]))
    except ValueError:
        R0 = np.eye(3)  # one gravity direction: the report will name what is undetermined

    o = bp.OptimizationProblem()
    camera = add_camera(o, "camera", K, "opencv5")
    identity = o.add_random_var(bp.SE3(), fixed=True, name="identity")
    imu_from_cam = o.add_random_var(bp.SE3(bp.SO3(R0), TRUTH["imu_from_cam"].pos), name="imu_from_cam")
    accel = None
    if estimate_accel:
        accel = o.add_random_var(bp.Rn([1.0, 0, 0, 0]), name="accel", labels=["scale", "bx", "by", "bz"])
    o.add_measurement(TRUTH["imu_from_cam"].pos, imu_position, [imu_from_cam], sigma=0.005, name="imu_from_cam_by_hand")
    for i, (z_i, pose) in enumerate(zip(z, cam_from_board)):
        world_from_cam = o.add_random_var(pose.inverse(), name=f"world_from_cam_{i}")
        add_board(o, z_i, camera, world_from_cam, identity, p_in_world, sigma=data["pixel_sigma"],
                    group="camera")
        if i in gravity_views:
            add_gravity(o, g[i], world_from_cam, imu_from_cam, accel, G_WORLD, sigma=data["accel_sigma"],
                          group="accelerometer")
    result = o.solve()
    return o, dict(camera=camera, imu_from_cam=imu_from_cam, accel=accel), result


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--noise", type=float, default=0.5, help="pixel noise σ (px)")
    ap.add_argument("--out", default=None, help="directory for the PNG figures")
    args = ap.parse_args()
    data = simulate(np.random.default_rng(0), args.noise)
    o, ids, result = calibrate(data)
    print(result)
    rep = report(o)
    print(rep)
    est = o[ids["imu_from_cam"]]
    print("imu_from_cam rotation error vs truth:", np.linalg.norm((TRUTH["imu_from_cam"].rot.inverse() * est.rot).log()), "rad")
    print("accel estimate", o[ids["accel"]].vec, "truth", TRUTH["accel"])
    if args.out:
        from boxplus.calib.plot import plot_reprojection_errors, plot_rig

        plot_reprojection_errors(o, f"{args.out}/camera_imu_reprojection.png")
        boards = [(bp.SE3(), data["p_in_world"])]
        frames = {f"cam{i}": o[o_id] for i, o_id in enumerate(
            [v for v in range(o.num_variables) if o.variable_name(v).startswith("world_from_cam")])}
        plot_rig(f"{args.out}/camera_imu_rig.png", frames, boards, length=0.05)


if __name__ == "__main__":
    main()
