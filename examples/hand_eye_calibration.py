"""Hand-eye calibration (eye in hand) as maximum likelihood: pixel noise and
robot-pose noise both modelled, compared with every closed form of OpenCV
(cv2.calibrateHandEye: Tsai, Park, Horaud, Andreff, Daniilidis;
cv2.calibrateRobotWorldHandEye: Shah, Li) on the same simulated data.

Unknowns (world = the board frame):
    cam_from_gripper  (X⁻¹, the camera on the gripper), board_from_base (the robot in the
    board frame), board_from_gripper_i (the true gripper pose of each station)
Measurements:
    z_ij   = π(k, cam_from_gripper ∘ board_from_gripper_i⁻¹ ∘ p_board_j)  (corners, px)
    G̃_i    = board_from_base⁻¹ ∘ board_from_gripper_i ⊞ n_i              (robot reading)
Intrinsics are known (calibrated before). Initial values: PnP per image and
Park–Martin's closed form (boxplus.calib.init); no guesses.

Run: .venv/bin/python examples/hand_eye_calibration.py [--trials N]
"""

from __future__ import annotations

import argparse
from typing import Any

import boxplus as bp
import numpy as np
from boxplus.calib import add_board, board_pose, hand_eye_park, mean_pose, report
from boxplus.synthetic.cameras import TRUE_K, board_points, observe, random_views

# Any: the true values of different manifolds (poses, intrinsics vectors, ...).
TRUTH: dict[str, Any] = dict(gripper_from_cam=bp.SE3(bp.SO3.exp(np.array([0.1, -0.2, 1.4])), [0.03, -0.05, 0.08]),
             base_from_board=bp.SE3(bp.SO3.exp(np.array([3.0, 0.1, 0.0])), [0.6, 0.1, 0.05]))


def perturb(pose, sigma_t, sigma_r, rng):
    return bp.SE3(pose.rot.R @ bp.SO3.exp(rng.normal(0, sigma_r, 3)).R, pose.pos + rng.normal(0, sigma_t, 3))


def simulate(rng, pixel_sigma=1.0, robot_t=0.0001, robot_r=0.0002, n=15):
    p = board_points()
    X, Z = TRUTH["gripper_from_cam"], TRUTH["base_from_board"]
    z, G_meas = [], []
    for board_from_cam in random_views(n, rng, p.mean(axis=0), roll=1.2, spread=0.5):
        G = Z * board_from_cam * X.inverse()  # base_from_gripper
        uv, vis = observe(TRUE_K, board_from_cam, p, pixel_sigma, rng)
        assert vis.all()
        z.append(uv)
        G_meas.append(perturb(G, robot_t, robot_r, rng))
    return dict(p=p, z=z, G=G_meas, pixel_sigma=pixel_sigma, robot_sigma=[robot_t] * 3 + [robot_r] * 3)


def calibrate(data):
    """ML estimate of gripper_from_cam; returns (problem, ids, gripper_from_cam)."""
    K = np.array([[TRUE_K[0], 0, TRUE_K[2]], [0, TRUE_K[1], TRUE_K[3]], [0, 0, 1]])
    cam_from_target = [board_pose(K, z, data["p"], TRUE_K[4:]) for z in data["z"]]
    X0 = hand_eye_park(data["G"], cam_from_target)
    Z0 = mean_pose([G * X0 * T for G, T in zip(data["G"], cam_from_target)])

    o = bp.OptimizationProblem()
    camera = o.add_random_var(bp.Rn(TRUE_K), fixed=True, name="camera")
    cam_from_gripper = o.add_random_var(X0.inverse(), name="cam_from_gripper")
    board_from_base = o.add_random_var(Z0.inverse(), name="board_from_base")
    for i, (z, G) in enumerate(zip(data["z"], data["G"])):
        board_from_gripper = o.add_random_var(Z0.inverse() * G, name=f"board_from_gripper_{i}")
        add_board(o, z, camera, board_from_gripper, cam_from_gripper, data["p"], sigma=data["pixel_sigma"],
                    group="camera")
        o.add_relative_pose(G, board_from_base, board_from_gripper, sigma=data["robot_sigma"], group="robot")
    o.solve()
    ids = dict(cam_from_gripper=cam_from_gripper, board_from_base=board_from_base, camera=camera)
    return o, ids, o[cam_from_gripper].inverse()


def robot_pose_candidates(o, ids, rng, n=30):
    """n robot poses (base_from_gripper) that show the whole board, from the current
    estimates of the hand–eye and board transforms."""
    p = board_points()
    X, Zb = o[ids["cam_from_gripper"]], o[ids["board_from_base"]]
    out: list[bp.SE3] = []
    while len(out) < n:
        board_from_cam = random_views(1, rng, p.mean(axis=0), roll=1.2, spread=0.5)[0]
        if observe(TRUE_K, board_from_cam, p, 0.0, rng)[1].all():
            out.append(Zb.inverse() * board_from_cam * X)  # base_from_gripper
    return out


def suggest_robot_poses(o, ids, data, candidates):
    """The candidate robot poses ranked by the largest σ of the hand–eye transform
    (cam_from_gripper) they would leave (:func:`boxplus.calib.suggest.rank_candidates`):
    [(index, σ)], best first. Each candidate adds a view at the pixels and the robot
    reading the current estimates predict."""
    from boxplus.calib.suggest import rank_candidates

    X, Zb, k = o[ids["cam_from_gripper"]], o[ids["board_from_base"]], o[ids["camera"]].vec

    def capture(G):
        def add(q):
            board_from_gripper = q.add_random_var(Zb * G)
            uv = observe(k, Zb * G * X.inverse(), data["p"], 0.0, np.random.default_rng(0),
                         image_size=None)[0]
            add_board(q, uv, ids["camera"], board_from_gripper, ids["cam_from_gripper"], data["p"],
                      sigma=data["pixel_sigma"], group="camera")
            q.add_relative_pose(G, ids["board_from_base"], board_from_gripper, sigma=data["robot_sigma"],
                                group="robot")
        return add

    return rank_candidates(o, [capture(G) for G in candidates], [ids["cam_from_gripper"]])


def opencv_estimates(data):
    """gripper_from_cam from every OpenCV closed form (solvePnP for the board poses)."""
    import cv2

    K = np.array([[TRUE_K[0], 0, TRUE_K[2]], [0, TRUE_K[1], TRUE_K[3]], [0, 0, 1]])
    Rt, tt = [], []
    for z in data["z"]:
        ok, rvec, tvec = cv2.solvePnP(data["p"], z, K, TRUE_K[4:], flags=cv2.SOLVEPNP_ITERATIVE)
        Rt.append(cv2.Rodrigues(rvec)[0])
        tt.append(tvec)
    Rg = [G.rot.R for G in data["G"]]
    tg = [G.pos.reshape(3, 1) for G in data["G"]]
    out = {}
    for name in ["TSAI", "PARK", "HORAUD", "ANDREFF", "DANIILIDIS"]:
        R, t = cv2.calibrateHandEye(Rg, tg, Rt, tt, method=getattr(cv2, f"CALIB_HAND_EYE_{name}"))
        out[f"calibrateHandEye {name}"] = bp.SE3(bp.SO3(R), t.ravel())
    Rbg = [G.rot.R.T for G in data["G"]]
    tbg = [-G.rot.R.T @ G.pos.reshape(3, 1) for G in data["G"]]
    for name in ["SHAH", "LI"]:
        _, _, R, t = cv2.calibrateRobotWorldHandEye(
            Rt, tt, Rbg, tbg, method=getattr(cv2, f"CALIB_ROBOT_WORLD_HAND_EYE_{name}"))
        out[f"calibrateRobotWorldHandEye {name}"] = bp.SE3(bp.SO3(R), t.ravel()).inverse()
    return out


def errors(X):
    """(translation error, rotation error rad) of a gripper_from_cam estimate."""
    T = TRUTH["gripper_from_cam"]
    return np.linalg.norm(X.pos - T.pos), np.linalg.norm((T.rot.inverse() * X.rot).log())


def compare(trials=20, seed=0, **noise):
    rng = np.random.default_rng(seed)
    res: dict[str, Any] = {}
    for _ in range(trials):
        data = simulate(rng, **noise)
        est = {"boxplus ML": calibrate(data)[2], **opencv_estimates(data)}
        for k, X in est.items():
            res.setdefault(k, []).append(errors(X))
    return {k: np.sqrt(np.mean(np.square(v), axis=0)) for k, v in res.items()}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--trials", type=int, default=20)
    args = ap.parse_args()
    rms = compare(args.trials)
    print(f"gripper_from_cam RMS error over {args.trials} trials (pixel σ 1 px, robot σ 0.1 mm / 0.2 mrad)")
    for k, (et, er) in sorted(rms.items(), key=lambda kv: kv[1][0]):
        print(f"  {k:40s} translation {et * 1e3:7.3f} mm   rotation {er * 1e3:7.3f} mrad")
    o, ids, X = calibrate(simulate(np.random.default_rng(99)))
    print(report(o).__str__().split("  parameters")[0])


if __name__ == "__main__":
    main()
