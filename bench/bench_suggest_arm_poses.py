"""Suggested arm poses against random ones for the joint rig: how many board views
until the DH table's σ is down to 30 %? (#29)

Le & Ng's arm holding a board in front of a stereo pair (the tutorial's rig,
docs/tutorials/joint_rig.py, on ``boxplus.synthetic.joint_rigs.make_rig`` data) is
calibrated from 4 board views; then views are added one at a time, re-solving
after each, until the score of :meth:`boxplus.joint.JointRig.suggest_arm_poses` —
the mean over the DH table's tangent directions of σ now / σ after the first 4
views — falls to ``--target`` (default 0.3), either

* **suggested**: of 20 candidate joint readings drawn about the arm's home pose
  (as make_rig draws its views, the board visible in both cameras and facing
  them), the one ``suggest_arm_poses`` ranks first, or
* **random**: the first of the same 20 candidates;

each view captured from the truth with fresh pixel and encoder noise. The
target of the issue: the suggested sequence needs ≤ 50 % of the views the
random one needs. Entries that only the DH prior bounds (the base joint's θ and
d against where the pair stands) cannot be halved by any view; they count in
the mean at their prior's σ.

Run: .venv/bin/python bench/bench_suggest_arm_poses.py [--seeds 6] [--target 0.3]
"""

from __future__ import annotations

import argparse
import importlib.util
import time
import warnings
from pathlib import Path

import numpy as np
from boxplus.calib.models import project
from boxplus.synthetic.joint_rigs import HOME, make_rig

TUTORIAL = Path(__file__).resolve().parents[1] / "docs" / "tutorials" / "joint_rig.py"
IMAGE = (640, 480)


def _tutorial():
    spec = importlib.util.spec_from_file_location("joint_rig_tutorial", TUTORIAL)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _pixels(data, q):
    """The board's true pixels in both cameras at joints q, or None when not in view."""
    T = data.board_pose(q)
    out = []
    for k, X in ((data.k1_true, data.arm_from_cam1), (data.k2_true, data.arm_from_cam2)):
        cam_from_board = X.inverse() * T
        p = data.board @ cam_from_board.R.T + cam_from_board.pos
        uv = project(k, p, data.model)
        facing = -(cam_from_board.R[:, 2] @ cam_from_board.pos) / np.linalg.norm(cam_from_board.pos)
        if not (np.all(p[:, 2] > 0.2) and np.all(uv > 10) and np.all(uv[:, 0] < IMAGE[0] - 10)
                and np.all(uv[:, 1] < IMAGE[1] - 10) and facing > 0.5):
            return None
        out.append(uv)
    return out


def _candidates(data, rng, n=20):
    out = []
    while len(out) < n:
        q = HOME + rng.normal(0.0, [0.25, 0.15, 0.15, 0.25, 0.5])
        if _pixels(data, q) is not None:
            out.append(q)
    return out


def views_needed(strategy: str, seed: int, target: float, cap: int = 60) -> tuple[int, float]:
    tut = _tutorial()
    data = make_rig(seed, n_boards=4)
    rig = tut.build(data)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rig.solve()
    ids = [rig.ids["arm.dh"]]
    start = np.sqrt(np.diag(rig.problem.joint_covariance(ids)))
    rng = np.random.default_rng(1000 + seed)
    for n in range(1, cap + 1):
        cands = _candidates(data, rng)
        if strategy == "suggested":
            pick = rig.suggest_arm_poses("arm", cands, data.board, "stereo", sigma=data.sigma_px,
                                         image_size=IMAGE)[0][0]
        else:
            pick = 0
        q = cands[pick]
        z1, z2 = _pixels(data, q)
        reading = q + rng.normal(0.0, data.sigma_encoder, 5)
        for camera, z in ((0, z1), (1, z2)):
            rig.project_targets("arm", reading, data.board, "stereo",
                                z + rng.normal(0.0, data.sigma_px, z.shape), camera=camera,
                                reading=("added", n), sigma=data.sigma_px)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rig.problem.solve()
        ratio = float(np.mean(np.sqrt(np.diag(rig.problem.joint_covariance(ids))) / start))
        if ratio <= target:
            return n, ratio
    return cap + 1, ratio


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=6)
    ap.add_argument("--target", type=float, default=0.3)
    args = ap.parse_args()
    print(f"{'seed':>4s} {'suggested':>10s} {'random':>8s} {'ratio':>6s} {'time s':>7s}")
    ratios = []
    for seed in range(args.seeds):
        t0 = time.perf_counter()
        s, _ = views_needed("suggested", seed, args.target)
        r, _ = views_needed("random", seed, args.target)
        ratios.append(s / r)
        print(f"{seed:4d} {s:10d} {r:8d} {s / r:6.2f} {time.perf_counter() - t0:7.1f}", flush=True)
    print(f"median views suggested / random: {np.median(ratios):.2f} (target ≤ 0.5; "
          f"'61' means the target was not reached in 60 views)")


if __name__ == "__main__":
    main()
