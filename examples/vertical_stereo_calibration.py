"""Stereo calibration on a vertical baseline (MTKM paper, Sec. V-B, the Nao
soccer robot): two cameras 5 cm apart vertically whose optical axes differ by
43° (one faces forward, the other down), so that in a stereo pair each camera
sees only part of the board; extra mono images of the whole board keep each
camera's intrinsics well determined. Simulated with known truth.

Unknowns (the top camera is the reference frame x):
    top, bottom          intrinsics (radial2: fx fy cx cy k1 k2)
    bottom_from_top           stereo extrinsics
    world_from_top_i          one pose per stereo pair (world = the board)
    world_from_top_mono_j,    one pose per extra mono image of each camera
    world_from_bottom_mono_j
Measurements (the board factor with the visible corners only):
    stereo pair   z_top = π(k_top, world_from_top_i⁻¹ ∘ p)            (partial board)
                  z_bot = π(k_bot, bottom_from_top ∘ world_from_top_i⁻¹ ∘ p) (the other part)
    mono image    z = π(k_c, world_from_c_mono_j⁻¹ ∘ p)                 (whole board)
Compared with a plain stereo calibration only the mono poses and their board
measurements are added (the paper's point).

Initial values, closed form: Zhang per camera over all its views (homographies
of partial views use their visible corners), bottom_from_top the chordal mean of the
per-pair transforms.

Run: .venv/bin/python examples/vertical_stereo_calibration.py [--noise PX] [--no-mono]
"""

from __future__ import annotations

import argparse
from typing import Any

import boxplus as bp
import numpy as np
from boxplus.calib import add_board, add_camera, init_camera, relative_pose_init, report
from boxplus.synthetic import cameras as synthetic
from boxplus.synthetic.cameras import board_points, observe, random_views

MODEL = "radial2"
SIZE = (640, 480)
TILT = np.deg2rad(43.0)
_top_from_bottom = bp.SE3(bp.SO3.exp(np.array([-TILT, 0.003, -0.002])), [0.001, 0.05, 0.002])
# Any: the true values of different manifolds (poses, intrinsics vectors, ...).
TRUTH: dict[str, Any] = dict(
    top=np.array([556.0, 554.0, 322.0, 236.0, -0.07, 0.12]),
    bottom=np.array([549.0, 548.0, 315.0, 244.0, -0.05, 0.09]),
    bottom_from_top=_top_from_bottom.inverse(),
)
# a virtual camera on the bisector of the two optical axes, for placing the board
_mid_from_top = bp.SE3(bp.SO3.exp(np.array([TILT / 2, 0, 0])), [0.0, -0.025, 0.0])


def _board():
    return board_points(cols=13, rows=10, square=0.045)


def simulate(rng, pixel_sigma=0.5, n_stereo=10, n_mono=6, min_points=12):
    p = _board()
    center = p.mean(axis=0)
    stereo: list[dict[str, np.ndarray]] = []
    while len(stereo) < n_stereo:
        world_from_mid = random_views(1, rng, center, distance=rng.uniform(0.45, 0.6), spread=0.25)[0]
        world_from_top = world_from_mid * _mid_from_top
        world_from_bottom = world_from_top * TRUTH["bottom_from_top"].inverse()
        zt, vt = observe(TRUTH["top"], world_from_top, p, pixel_sigma, rng, MODEL)
        zb, vb = observe(TRUTH["bottom"], world_from_bottom, p, pixel_sigma, rng, MODEL)
        if vt.sum() >= min_points and vb.sum() >= min_points:
            stereo.append(dict(z_top=zt, vis_top=vt, z_bottom=zb, vis_bottom=vb))
    mono: dict[str, list[np.ndarray]] = {}
    for cam in ("top", "bottom"):
        mono[cam] = []
        while len(mono[cam]) < n_mono:
            world_from_cam = random_views(1, rng, center, distance=rng.uniform(0.75, 0.9), spread=0.35)[0]
            z, vis = observe(TRUTH[cam], world_from_cam, p, pixel_sigma, rng, MODEL)
            if vis.all():
                mono[cam].append(z)
    return dict(p_board=p, stereo=stereo, mono=mono, pixel_sigma=pixel_sigma)


def calibrate(data, use_mono=True):
    p, S = data["p_board"], data["stereo"]
    mono = data["mono"] if use_mono else {"top": [], "bottom": []}
    # ---- closed form: Zhang per camera over its stereo (partial) and mono (whole) views
    K, cam_from_board = {}, {}
    for cam in ("top", "bottom"):
        objs = [p[s[f"vis_{cam}"]] for s in S] + [p] * len(mono[cam])
        K[cam], cam_from_board[cam] = init_camera(objs, [s[f"z_{cam}"] for s in S] + mono[cam], SIZE)
    o = bp.OptimizationProblem()
    top = add_camera(o, "top", K["top"], MODEL)
    bottom = add_camera(o, "bottom", K["bottom"], MODEL)
    identity = o.add_random_var(bp.SE3(), fixed=True, name="identity")
    n = len(S)
    bottom_from_top = o.add_random_var(relative_pose_init(cam_from_board["top"][:n], cam_from_board["bottom"][:n]),
                                  name="bottom_from_top")
    sigma = data["pixel_sigma"]
    for i, (s, T) in enumerate(zip(S, cam_from_board["top"])):
        world_from_top = o.add_random_var(T.inverse(), name=f"world_from_top_{i}")
        add_board(o, s["z_top"], top, world_from_top, identity, p[s["vis_top"]], sigma=sigma, model=MODEL,
                    group="stereo top")
        add_board(o, s["z_bottom"], bottom, world_from_top, bottom_from_top, p[s["vis_bottom"]], sigma=sigma,
                    model=MODEL, group="stereo bottom")
    for cam, cid in (("top", top), ("bottom", bottom)):
        for j, (z, T) in enumerate(zip(mono[cam], cam_from_board[cam][n:])):
            world_from_cam = o.add_random_var(T.inverse(), name=f"world_from_{cam}_mono_{j}")
            add_board(o, z, cid, world_from_cam, identity, p, sigma=sigma, model=MODEL, group=f"mono {cam}")
    result = o.solve()
    return o, dict(top=top, bottom=bottom, bottom_from_top=bottom_from_top), result


def errors_in_sigma(o, rep, ids):
    return synthetic.errors_in_sigma(o, rep, ids, TRUTH)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--noise", type=float, default=0.5, help="corner noise σ (px)")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    data = simulate(np.random.default_rng(args.seed), args.noise)
    visible = [(s["vis_top"].mean(), s["vis_bottom"].mean()) for s in data["stereo"]]
    print("fraction of the board seen in the stereo pairs (top, bottom):",
          " ".join(f"({a:.2f}, {b:.2f})" for a, b in visible))
    reps = {}
    for use_mono in (True, False):
        o, ids, result = calibrate(data, use_mono)
        rep = reps[use_mono] = report(o)
        print(f"\n=== {'with' if use_mono else 'without'} the mono images: {result}")
        for w in rep.warnings:
            print("  WARNING:", w)
        err = errors_in_sigma(o, rep, ids)
        print(f"  condition number {rep.condition:.3g}; max |error|/σ "
              f"{max(v.max() for v in err.values()):.2f}")
    print("\nσ without / σ with the mono images:")
    for name in ("top", "bottom", "bottom_from_top"):
        ratio = reps[False].std(name) / reps[True].std(name)
        labels = [p.label for p in reps[True].parameters if p.variable == name]
        print(f"  {name:10s} " + "  ".join(f"{lab} {r:.2f}" for lab, r in zip(labels, ratio)))


if __name__ == "__main__":
    main()
