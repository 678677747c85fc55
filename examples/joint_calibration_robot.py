"""Joint calibration of a whole robot: Le & Ng's Table II on a synthetic robot.

A 5-DOF arm whose link lengths and joint offsets differ from the maker's
numbers, two cameras and a laser projector look at a table. The data, like
the paper's (Sec. XI-C): checkerboard views (each corner seen by both
cameras, lit by the laser at a measured angle and touched by the arm's tool
point, with encoder readings) and plane views (points of a flat surface lit
by the laser and seen by both cameras). Four methods are cross-validated
(5 folds; validation error = distance, in the arm's frame, between a
held-out corner as the arm reports it and as each camera system reports it):

1. incremental (Fig. 8): stereo pair, then laser + camera 1 with camera 1
   fixed, then the arm, then the transforms between them;
2. joint, no sharing (Fig. 9): the same systems in one objective, camera 1
   a separate variable in each system that uses it;
3. joint, sharing (Fig. 10): camera 1 and camera 2 shared, a second
   laser–camera system (camera 2); links form a tree (each system – arm);
4. joint, more redundancy (Fig. 11): also links between the camera systems.

Run:  python examples/joint_calibration_robot.py [--folds 5] [--restarts 2] [--seed 0]
"""

from __future__ import annotations

import argparse
import itertools
import time
from typing import Any

import boxplus as bp
import numpy as np
from boxplus.batch import view
from boxplus.geometry import look_at
from boxplus.joint import (
    EXTRINSICS,
    ActiveTriangulation,
    JointCalibration,
    RobotArm,
    StereoPair,
    calibrate_incrementally,
    camera,
    cross_validate,
    project,
)
from boxplus.manifolds import codec_of

# ---- the true robot -------------------------------------------------------------------

BASE_HEIGHT = 0.20
NOMINAL_LENGTHS = np.array([0.19, 0.14, 0.08, 0.05])  # the maker's a2, a3, a4, a5 (m)
SIGMA_PX, SIGMA_BETA, SIGMA_ENC = 0.3, 2e-4, 2e-4
SQUARE, BOARD = 0.04, (4, 3)  # checkerboard: square (m), corners
LIT_CORNERS = 3  # corners of a board view the laser is aimed at (it cannot light them all)
# noise of a point of each kind of system (m): weights of the terms
SIGMA_POINT = {"stereo": 1.5e-3, "laser": 1.0e-3, "arm": 0.3e-3}


UP = (0.0, 0.0, 1.0)  # the world's z appears up in every image (look_at's ``up``)


def make_robot(rng):
    """The true robot: parameters and sensor poses in the arm's base frame."""
    target = np.array([0.30, 0.0, 0.05])
    truth = {
        "cam1": camera(610.0, 322.0, 236.0, -0.12),
        "cam2": camera(595.0, 317.0, 243.0, -0.09),
        "world_from_cam1": look_at(np.array([-0.15, 0.06, 0.55]), target, UP),
        "world_from_cam2": look_at(np.array([-0.15, -0.06, 0.55]), target + [0, -0.02, 0], UP),
        "world_from_laser": look_at(np.array([-0.12, -0.22, 0.58]), target, UP),
        "lengths": NOMINAL_LENGTHS + rng.normal(0, 0.004, 4),
        "offsets": rng.normal(0, np.radians(1.5), 4),
    }
    truth["arm"] = RobotArm("arm", truth["lengths"], truth["offsets"], BASE_HEIGHT)
    return truth


def _pixels(truth, cam, p_in_world):
    T = truth[f"world_from_{cam}"]
    c = truth[cam]
    p = (p_in_world - T.pos) @ T.R  # tolocal
    b = view(codec_of(c), np.tile(c.ambient, (len(p), 1)))
    return project(b, p), p[:, 2]


def _beta(truth, p_in_world):
    T = truth["world_from_laser"]
    p = (p_in_world - T.pos) @ T.R
    return np.arctan2(p[:, 0], p[:, 2])


def _ik(truth, targets, rng, tries=10):
    """Encoder readings putting the arm's tool point on ``targets`` (damped least
    squares from random starts); None if some target is out of reach."""
    arm = truth["arm"]
    off = np.r_[0.0, truth["offsets"]]
    n = len(targets)
    out = np.full((n, 5), np.nan)
    todo = np.arange(n)
    for _ in range(tries):
        m, tg = len(todo), targets[todo]
        th = np.column_stack([np.arctan2(tg[:, 1], tg[:, 0]), rng.uniform(-0.2, 0.8, m),
                              rng.uniform(0.0, 1.5, m), rng.uniform(-0.5, 1.5, m), rng.uniform(-1.5, 1.5, m)])
        for _ in range(60):
            p = arm.evaluate(th - off)
            J = np.empty((m, 3, 5))
            for j in range(5):
                d = np.zeros(5)
                d[j] = 1e-7
                J[:, :, j] = (arm.evaluate(th - off + d) - p) / 1e-7
            A = J @ np.transpose(J, (0, 2, 1)) + 1e-6 * np.eye(3)
            th = th + np.einsum("nji,nj->ni", J, np.linalg.solve(A, (tg - p)[:, :, None])[:, :, 0])
        ok = np.linalg.norm(arm.evaluate(th - off) - tg, axis=1) < 1e-10
        out[todo[ok]] = th[ok] - off
        todo = todo[~ok]
        if not len(todo):
            return out
    return None


def _random_patch_pose(rng):
    centre = np.array([rng.uniform(0.22, 0.38), rng.uniform(-0.12, 0.12), rng.uniform(0.0, 0.15)])
    towards = np.array([-0.15, 0.0, 0.55]) - centre
    normal = towards / np.linalg.norm(towards)
    R = bp.SO3.exp(rng.normal(0, 0.3, 3)).R @ look_at(centre, centre - normal, UP).R
    return centre, R


def _observe(truth, p_in_world, rng):
    """The data of each system at world points: stereo, laser+cam1, laser+cam2, and depths."""
    u1, z1 = _pixels(truth, "cam1", p_in_world)
    u2, z2 = _pixels(truth, "cam2", p_in_world)
    u1 = u1 + rng.normal(0, SIGMA_PX, u1.shape)
    u2 = u2 + rng.normal(0, SIGMA_PX, u2.shape)
    beta = _beta(truth, p_in_world) + rng.normal(0, SIGMA_BETA, len(p_in_world))
    ok = np.all((u1 > 0) & (u1 < [640, 480]), 1) & np.all((u2 > 0) & (u2 < [640, 480]), 1) & (z1 > 0) & (z2 > 0)
    return {"stereo": np.column_stack([u1, u2]), "laser_cam1": np.column_stack([u1, beta]),
            "laser_cam2": np.column_stack([u2, beta])}, ok


def make_dataset(seed=0, n_boards=10, n_planes=5, points_per_plane=40):
    """Synthetic checkerboard and plane views of the robot (all in SI units)."""
    rng = np.random.default_rng(seed)
    truth = make_robot(rng)
    gx, gy = np.meshgrid(np.arange(BOARD[0]) * SQUARE, np.arange(BOARD[1]) * SQUARE)
    corners = np.column_stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)])
    corners -= corners.mean(0)
    boards: list[Any] = []
    planes: list[Any] = []
    while len(boards) < n_boards:
        c, R = _random_patch_pose(rng)
        p = corners @ R.T + c
        obs, ok = _observe(truth, p, rng)
        if not ok.all():
            continue
        enc = _ik(truth, p, rng)
        if enc is None:
            continue
        obs["arm"] = enc + rng.normal(0, SIGMA_ENC, (len(p), 5))
        obs["points"] = p
        obs["lit"] = np.sort(rng.choice(len(p), LIT_CORNERS, replace=False))
        boards.append(obs)
    while len(planes) < n_planes:
        c, R = _random_patch_pose(rng)
        uv = rng.uniform(-0.08, 0.08, (points_per_plane, 2))
        p = c + uv @ R[:, :2].T
        obs, ok = _observe(truth, p, rng)
        if ok.sum() < points_per_plane // 2:
            continue
        planes.append({k: v[ok] for k, v in obs.items()})
    return truth, boards, planes, corners


def initial_guess(truth, rng):
    """The 'simple guesses' of Sec. XI: nominal cameras, ruler-measured transforms, maker's arm."""
    cam2_from_cam1 = truth["world_from_cam2"].inverse() * truth["world_from_cam1"]
    cam1_from_laser = truth["world_from_cam1"].inverse() * truth["world_from_laser"]
    cam2_from_laser = truth["world_from_cam2"].inverse() * truth["world_from_laser"]

    def ruler(T):
        return T + np.r_[rng.normal(0, 0.005, 3), rng.normal(0, np.radians(2), 3)]

    return {
        "cam": camera(600.0, 320.0, 240.0, 0.0),
        "cam2_from_cam1": ruler(cam2_from_cam1),
        "cam1_from_laser": ruler(cam1_from_laser),
        "cam2_from_laser": ruler(cam2_from_laser),
    }


# ---- the four methods -----------------------------------------------------------------


def build(method, data, train, guess):
    """A JointCalibration of the grouping of ``method`` on the training views."""
    truth, boards, planes, corners = data
    shared = method in ("joint, sharing", "joint, more redundancy")
    incremental = method == "incremental"
    jc = JointCalibration(gamma=1.0, root="arm")
    jc.add_system(RobotArm("arm", NOMINAL_LENGTHS, np.zeros(4), BASE_HEIGHT))
    jc.add_system(StereoPair("stereo", cam1=guess["cam"], cam2=guess["cam"],
                             cam2_from_cam1=guess["cam2_from_cam1"]),
                  share={"cam1": "camera1", "cam2": "camera2"})
    jc.add_system(ActiveTriangulation("laser_cam1", camera=guess["cam"],
                                      cam_from_laser=guess["cam1_from_laser"]),
                  share={"camera": "camera1"} if shared or incremental else {})
    systems = ["stereo", "laser_cam1"]
    if shared:
        jc.add_system(ActiveTriangulation("laser_cam2", camera=guess["cam"],
                                          cam_from_laser=guess["cam2_from_laser"]),
                      share={"camera": "camera2"})
        systems.append("laser_cam2")
    sig = {s: SIGMA_POINT["stereo" if s == "stereo" else "laser"] for s in systems}
    sig["arm"] = SIGMA_POINT["arm"]
    for v in train["boards"]:
        b = boards[v]
        seen = {s: b["lit"] if s.startswith("laser") else np.arange(len(corners)) for s in systems}
        seen["arm"] = np.arange(len(corners))
        for s in ["arm"] + systems:
            i, j = np.array(list(itertools.combinations(seen[s], 2))).T
            dbar = np.linalg.norm(corners[i] - corners[j], axis=1)
            jc.add_distances(s, b[s][i], b[s][j], dbar, np.sqrt(2) * sig[s], name=f"{s}.board{v}")
        links = [(s, "arm") for s in systems]
        if method == "joint, more redundancy":
            links += list(itertools.combinations(systems, 2))
        for a, c in links:
            k = np.intersect1d(seen[a], seen[c])
            jc.add_correspondences(a, c, b[a][k], b[c][k], np.hypot(sig[a], sig[c]), name=f"{a}-{c}.board{v}")
    for v in train["planes"]:
        p = planes[v]
        for s in systems:
            jc.add_coplanar(s, p[s], sig[s], name=f"{s}.plane{v}")
    return jc


METHODS = ("incremental", "joint, no sharing", "joint, sharing", "joint, more redundancy")


def train(method, data, split, restarts, seed):
    guess = initial_guess(data[0], np.random.default_rng(seed + 1))
    jc = build(method, data, split, guess)
    kw = dict(restarts=restarts, seed=seed, max_iterations=200)
    if method == "incremental":
        calibrate_incrementally(jc, [["stereo"], ["laser_cam1"], ["arm"], EXTRINSICS], **kw)
    else:
        jc.solve(**kw)
    return jc


def validation_error(jc, data, split):
    """Distances (m), in the arm's frame, between held-out corners as the arm and as
    each camera system (stereo, laser + camera 1) report them."""
    _, boards, _, _ = data
    errs = []
    for v in split["boards"]:
        b = boards[v]
        errs.append(jc.link_errors("stereo", "arm", b["stereo"], b["arm"]))
        errs.append(jc.link_errors("laser_cam1", "arm", b["laser_cam1"][b["lit"]], b["arm"][b["lit"]]))
    return np.concatenate(errs)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--folds", type=int, default=5)
    ap.add_argument("--restarts", type=int, default=1)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--boards", type=int, default=10)
    ap.add_argument("--planes", type=int, default=5)
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    data = make_dataset(args.seed, args.boards, args.planes)
    methods = {m: (lambda split, m=m: train(m, data, split, args.restarts, args.seed)) for m in METHODS}
    cv = cross_validate(methods, lambda jc, split: validation_error(jc, data, split),
                        {"boards": args.boards, "planes": args.planes}, k=args.folds, seed=args.seed)
    print(f"{args.folds}-fold cross-validation, {args.boards} checkerboard views of {np.prod(BOARD)} corners, "
          f"{args.planes} plane views, {args.restarts} random restarts per solve")
    print(cv.table())
    print(f"({time.perf_counter() - t0:.1f} s)")
    return cv


if __name__ == "__main__":
    main()
