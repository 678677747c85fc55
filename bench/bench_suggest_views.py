"""Suggested views against random ones: how many captures reach a target σ? (#29)

A camera (opencv5, 640×480, 0.3 px corner noise) is calibrated from 3 random
board views; then views are added one at a time until the worst projection σ
over the image (intrinsics only, points at the boards' distance; the score of
:func:`boxplus.calib.suggest.suggest_views`) falls below the target, either

* **suggested**: the best-ranked board pose of ``suggest_views`` (the next one
  when the truth would not show all its corners), or
* **random**: a board at a random place of the image (its centre uniform over
  the middle 70 % of each axis), a random distance (0.45–0.85 m) and random
  tilts (±40° about its x and y axes) — the same range the suggestions choose
  from, drawn blindly; views that do not show every corner are drawn again,

each capture with fresh corner noise, re-calibrated after every view. The score
is computed the same way for both (from the calibration's own covariance and
the true intrinsics' grid Jacobians). The target of the issue: the suggested
sequence needs ≤ 50 % of the views the random one needs.

Run: .venv/bin/python bench/bench_suggest_views.py [--seeds 10] [--target 2.0]
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
from boxplus import SE3, SO3
from boxplus.calib import calibrate_mono
from boxplus.calib.models import rays
from boxplus.calib.suggest import (
    image_grid_jacobians,
    rotation_onto,
    suggest_views,
    worst_projection_sigma,
)
from boxplus.synthetic.cameras import board_points, observe

K_TRUE = np.array([500.0, 505.0, 320.0, 240.0, -0.25, 0.08, 0.001, -0.0015, -0.01])
SIZE = (640, 480)
SIGMA = 0.3
MAX_VIEWS = 40


def _visible_view(rng: np.random.Generator, p: np.ndarray) -> SE3:
    """world_from_cam (the board's frame is the world) of a random view showing every corner."""
    while True:
        px = rng.uniform(0.15, 0.85, 2) * (np.array(SIZE) - 1)
        r = rays(K_TRUE, px[None], "opencv5")[0]
        r = r / np.linalg.norm(r)
        tx, ty = rng.uniform(-40, 40, 2)
        R = (rotation_onto(np.array([0.0, 0.0, 1.0]), r)
             @ SO3.exp(np.radians([tx, 0.0, 0.0])).R @ SO3.exp(np.radians([0.0, ty, 0.0])).R)
        cam_from_board = SE3(SO3(R), rng.uniform(0.45, 0.85) * r - R @ p.mean(axis=0))
        v = cam_from_board.inverse()
        if _inside(v, p, rng):
            return v


def _inside(world_from_cam: SE3, p: np.ndarray, rng: np.random.Generator) -> bool:
    """Every corner at least 5 px inside the image (noise must not push one out)."""
    uv, vis = observe(K_TRUE, world_from_cam, p, 0.0, rng)
    return bool(vis.all() and np.all((uv >= 5) & (uv < np.array(SIZE) - 5)))


def views_needed(strategy: str, seed: int, target: float) -> tuple[int, float]:
    rng = np.random.default_rng(seed)
    p = board_points()
    views = [_visible_view(rng, p) for _ in range(3)]
    z = [observe(K_TRUE, v, p, SIGMA, rng)[0] for v in views]
    G = image_grid_jacobians(K_TRUE, "opencv5", SIZE, 0.6, (16, 12))
    while True:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cal = calibrate_mono(z, p, SIZE, sigma=SIGMA)
        score = worst_projection_sigma(G, np.asarray(cal.problem.covariance(cal.ids["camera"])))
        if score <= target or len(z) >= MAX_VIEWS:
            return len(z), score
        if strategy == "random":
            v = _visible_view(rng, p)
        else:
            v = None
            for s in suggest_views(cal, n=5, distance=0.6):
                world_from_cam = s.cam_from_board.inverse()
                if _inside(world_from_cam, p, rng):
                    v = world_from_cam
                    break
            if v is None:
                v = _visible_view(rng, p)
        z.append(observe(K_TRUE, v, p, SIGMA, rng)[0])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--target", type=float, default=2.0, help="worst projection σ to reach (px)")
    args = ap.parse_args()
    print(f"target: worst projection σ ≤ {args.target} px (opencv5, {SIGMA} px corners), "
          f"start: 3 random views, cap {MAX_VIEWS}")
    print(f"{'seed':>4s} {'suggested':>10s} {'random':>8s} {'ratio':>6s}")
    ratios, t0 = [], time.perf_counter()
    for seed in range(args.seeds):
        ns, _ = views_needed("suggested", seed, args.target)
        nr, _ = views_needed("random", seed, args.target)
        ratios.append(ns / nr)
        print(f"{seed:4d} {ns:10d} {nr:8d} {ns / nr:6.2f}", flush=True)
    print(f"median ratio suggested/random: {np.median(ratios):.2f} (worst {max(ratios):.2f}); "
          f"{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
