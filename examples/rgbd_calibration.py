"""RGB-D sensor calibration (MTKM paper, Sec. V-B, a Microsoft Kinect): RGB
and infrared (IR) cameras with their stereo extrinsics, the IR camera's
depth-to-disparity mapping, and the accelerometer's rotation and scale, all
jointly, from a levelled checkerboard; simulated with known truth.

Unknowns (the RGB camera is the reference frame x):
    rgb, ir          intrinsics (opencv5)
    ir_from_rgb           stereo extrinsics (RGB → IR camera)
    disparity        [a, b] of the depth-to-disparity model below
    accel_from_rgb        camera → accelerometer (rotation from gravity; the
                     translation does not enter any measurement and is
                     measured by hand: a prior)
    accel            [s], the accelerometer's scale factor
    world_from_rgb_i      one pose per board image (world = the board)
Measurements:
    corners     z = π(k_c, cam_from_rgb ∘ world_from_rgb_i⁻¹ ∘ p_board)      (px, c = rgb, ir)
    disparity   d = a / Z + b,  Z = [ir_from_rgb ∘ world_from_rgb_i⁻¹ ∘ p_board]_z   (raw units)
    gravity     g = s · R_accel_from_rgb · R_world_from_rgb_iᵀ · g_world    (m/s², levelled board)

Depth-to-disparity model (factors/depth/disparity.h): a structured-light sensor
reports a raw disparity d that is affine in inverse depth, d = a / Z + b, the
usual Z = 1 / (c₁ d + c₀) with a = 1/c₁, b = −c₀/c₁; Z (m) is the depth of the
point along the IR camera's optical axis. Its depth is not measured directly:
it follows from the board's pose and the stereo extrinsics, so the disparity
of "well perceived" board points (inner corners away from the board's edge)
calibrates [a, b]. The Kinect's values are about a = −325.6 units·m,
b = 1084.6 units (Burrus' c₁ = −0.0030711, c₀ = 3.3309495).

Initial values, closed form: Zhang per camera, ir_from_rgb the chordal mean of the
per-view transforms, [a, b] by a line fit of d against 1/Z from those poses,
the accelerometer rotation by Kabsch from gravity pairs and its scale from the
mean norm of the readings.

Run: .venv/bin/python examples/rgbd_calibration.py [--noise PX] [--out DIR]
"""

from __future__ import annotations

import argparse
from typing import Any

import boxplus as bp
import numpy as np
from boxplus.calib import (
    add_board,
    add_camera,
    add_disparity,
    add_gravity,
    init_camera,
    relative_pose_init,
    report,
    rotation_between,
)
from boxplus.synthetic import cameras as synthetic
from boxplus.synthetic.cameras import board_points, observe, random_views

MODEL = "opencv5"
SIZE = (640, 480)
G_WORLD = np.array([0.0, 0.0, -9.81])
# Any: the true values of different manifolds (poses, intrinsics vectors, ...).
TRUTH: dict[str, Any] = dict(
    rgb=np.array([525.0, 523.0, 319.5, 239.5, 0.18, -0.35, 0.001, -0.0007, 0.0]),
    ir=np.array([584.0, 582.0, 316.0, 247.0, -0.12, 0.28, -0.0012, 0.0008, 0.0]),
    ir_from_rgb=bp.SE3(bp.SO3.exp(np.array([0.003, 0.006, -0.002])), [0.025, 0.0006, -0.0012]),
    disparity=np.array([-325.6, 1084.6]),
    accel_from_rgb=bp.SE3(bp.SO3.exp(np.array([0.02, -1.55, 0.01])), [0.0, 0.05, 0.02]),
    accel=np.array([1.03]),
)


def well_perceived(p_board: np.ndarray) -> np.ndarray:
    """Mask of the corners whose disparity is used: not on the board's outer ring."""
    x, y = p_board[:, 0], p_board[:, 1]
    return (x > x.min()) & (x < x.max()) & (y > y.min()) & (y < y.max())


def simulate(rng, pixel_sigma=0.5, disparity_sigma=None, accel_sigma=0.02, accel_by_hand_sigma=0.005,
             n_views=15):
    disparity_sigma = pixel_sigma if disparity_sigma is None else disparity_sigma
    p = board_points()
    use = well_perceived(p)
    rgb_from_ir = TRUTH["ir_from_rgb"].inverse()
    a, b = TRUTH["disparity"]
    views = []
    for world_from_rgb in random_views(n_views, rng, p.mean(axis=0), distance=0.5, spread=0.5):
        z_rgb, v_rgb = observe(TRUTH["rgb"], world_from_rgb, p, pixel_sigma, rng)
        z_ir, v_ir = observe(TRUTH["ir"], world_from_rgb * rgb_from_ir, p, pixel_sigma, rng)
        d_mask = use & v_ir
        Z = TRUTH["ir_from_rgb"].fromlocal(world_from_rgb.tolocal(p[d_mask]))[:, 2]
        d = a / Z + b + rng.normal(0, disparity_sigma, len(Z))
        g = TRUTH["accel"][0] * TRUTH["accel_from_rgb"].rot.R @ world_from_rgb.rot.R.T @ G_WORLD
        views.append(dict(z_rgb=z_rgb, vis_rgb=v_rgb, z_ir=z_ir, vis_ir=v_ir, d=d, d_mask=d_mask,
                          g=g + rng.normal(0, accel_sigma, 3)))
    return dict(p_board=p, views=views, pixel_sigma=pixel_sigma, disparity_sigma=disparity_sigma,
                accel_sigma=accel_sigma, accel_pos_by_hand=TRUTH["accel_from_rgb"].pos
                + rng.normal(0, accel_by_hand_sigma, 3), accel_by_hand_sigma=accel_by_hand_sigma)


def accel_position(accel_from_rgb):
    return accel_from_rgb.pos


def calibrate(data):
    p, V = data["p_board"], data["views"]
    # ---- closed-form initial values
    K_rgb, rgb_from_board = init_camera([p[v["vis_rgb"]] for v in V], [v["z_rgb"] for v in V], SIZE)
    K_ir, ir_from_board = init_camera([p[v["vis_ir"]] for v in V], [v["z_ir"] for v in V], SIZE)
    inv_Z = np.concatenate([1 / T.fromlocal(p[v["d_mask"]])[:, 2] for v, T in zip(V, ir_from_board)])
    d_all = np.concatenate([v["d"] for v in V])
    ab0 = np.linalg.lstsq(np.column_stack([inv_Z, np.ones_like(inv_Z)]), d_all, rcond=None)[0]
    G = np.array([v["g"] for v in V])
    R_acc = rotation_between(np.array([T.rot.R @ G_WORLD for T in rgb_from_board]), G)
    s0 = np.mean(np.linalg.norm(G, axis=1)) / np.linalg.norm(G_WORLD)

    o = bp.OptimizationProblem()
    rgb = add_camera(o, "rgb", K_rgb, MODEL)
    ir = add_camera(o, "ir", K_ir, MODEL)
    identity = o.add_random_var(bp.SE3(), fixed=True, name="identity")
    ir_from_rgb = o.add_random_var(relative_pose_init(rgb_from_board, ir_from_board), name="ir_from_rgb")
    disparity = o.add_random_var(bp.Rn(ab0), name="disparity", labels=["a", "b"])
    accel_from_rgb = o.add_random_var(bp.SE3(bp.SO3(R_acc), data["accel_pos_by_hand"]), name="accel_from_rgb")
    accel = o.add_random_var(bp.Rn([s0]), name="accel", labels=["scale"])
    o.add_measurement(data["accel_pos_by_hand"], accel_position, [accel_from_rgb],
                      sigma=data["accel_by_hand_sigma"], name="accel_from_rgb_by_hand")
    for i, (v, T) in enumerate(zip(V, rgb_from_board)):
        world_from_rgb = o.add_random_var(T.inverse(), name=f"world_from_rgb_{i}")
        add_board(o, v["z_rgb"], rgb, world_from_rgb, identity, p[v["vis_rgb"]], sigma=data["pixel_sigma"],
                    model=MODEL, group="rgb")
        add_board(o, v["z_ir"], ir, world_from_rgb, ir_from_rgb, p[v["vis_ir"]], sigma=data["pixel_sigma"],
                    model=MODEL, group="ir")
        for d, p_in_world in zip(v["d"], p[v["d_mask"]]):
            add_disparity(o, d, world_from_rgb, ir_from_rgb, disparity, p_in_world, sigma=data["disparity_sigma"])
        add_gravity(o, v["g"], world_from_rgb, accel_from_rgb, accel, G_WORLD, sigma=data["accel_sigma"],
                      group="accelerometer")
    result = o.solve()
    ids = dict(rgb=rgb, ir=ir, ir_from_rgb=ir_from_rgb, disparity=disparity, accel_from_rgb=accel_from_rgb, accel=accel)
    return o, ids, result


def errors_in_sigma(o, rep, ids):
    return synthetic.errors_in_sigma(o, rep, ids, TRUTH)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--noise", type=float, default=0.5, help="corner noise σ (px); disparity σ the same")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=None, help="directory for the PNG figures")
    args = ap.parse_args()
    data = simulate(np.random.default_rng(args.seed), args.noise)
    o, ids, result = calibrate(data)
    print(result)
    rep = report(o)
    print(rep)
    err = errors_in_sigma(o, rep, ids)
    for k, v in err.items():
        print(f"  {k:10s} max |error|/σ = {v.max():.2f}")
    print(f"max |error|/σ over all parameters: {max(v.max() for v in err.values()):.2f}")
    if args.out:
        from boxplus.calib.plot import plot_reprojection_errors, plot_rig

        plot_reprojection_errors(o, f"{args.out}/rgbd_reprojection.png")
        frames = {"rgb": bp.SE3(), "ir": o[ids["ir_from_rgb"]].inverse(), "accel": o[ids["accel_from_rgb"]].inverse()}
        plot_rig(f"{args.out}/rgbd_rig.png", frames, length=0.02)


if __name__ == "__main__":
    main()
