"""Humanoid head calibration (MTKM paper, Sec. V-A and Listing 2, DLR's Rollin'
Justin): a stereo head, an IMU and markers on both hands seen in many arm and
head poses, all estimated jointly in one problem, from a simulated robot with
known truth.

Unknowns (the left camera is the reference frame x):
    left, right            intrinsics (opencv5)
    right_from_left             stereo extrinsics
    imu_from_left               camera → IMU (rotation from gravity; the translation
                           is measured by hand: a prior, as in the paper)
    head_from_left              the cameras' mount on the last head link
    p_hand_l, p_hand_r     the marker on each hand (hand frame, unknown)
    world_from_left_i           one pose per board image (world = the board)
  with kinematics="dh", additionally
    dh_l, dh_r             each arm's Denavit–Hartenberg parameters, per joint
                           [θ offset, d, a, α], with the CAD values as a prior
                           (nominal ± tolerance)
Measurements:
    corners   z = π(k_c, cam_from_left ∘ world_from_left_i⁻¹ ∘ p_board)                 (px)
    gravity   g = R_imu_from_left · R_world_from_left_iᵀ · g_world                     (m/s², levelled board)
    markers   z = π(k_c, cam_from_left ∘ head_from_left⁻¹ ∘ head_from_hand_j ∘ p_hand)         (px)
              head_from_hand_j = torso_from_head(pan_j, tilt_j)⁻¹ ∘ torso_from_shoulder ∘ A₁(q₁)…A₆(q₆)
    kinematics="known": head_from_hand_j from forward kinematics (constants, Listing 2);
    kinematics="dh":    Aᵢ = Rot_z(qᵢ + θᵢ) Trans_z(dᵢ) Trans_x(aᵢ) Rot_x(αᵢ) with
                        unknown DH parameters and the joint readings q_j.
cam_from_left is the identity for the left camera and right_from_left for the right one.

Initial values, all closed form (boxplus.calib.init), no guesses: Zhang per
camera, right_from_left the chordal mean of the per-view transforms, the IMU rotation
by Kabsch from gravity pairs; after solving the board step, the markers are
triangulated (stereo) and head_from_left with both p_hand follows from
marker_hand_eye (linear in R, t, p; R projected onto SO(3)); DH from CAD. Then
everything is solved jointly.

Run: .venv/bin/python examples/humanoid_head_calibration.py [--noise PX] [--kinematics known|dh]
"""

from __future__ import annotations

import argparse
from typing import Any

import boxplus as bp
import numpy as np
from boxplus.calib import (
    add_board,
    add_camera,
    add_dh_marker,
    add_gravity,
    add_marker,
    init_camera,
    marker_hand_eye,
    relative_pose_init,
    report,
    rotation_between,
    triangulate,
)
from boxplus.synthetic import cameras as synthetic
from boxplus.synthetic.cameras import TRUE_K, board_points, observe, random_views

MODEL = "opencv5"
SIZE = (640, 480)
G_WORLD = np.array([0.0, 0.0, -9.81])
# head_from_left: camera z (optical axis) → head x (forward), camera x → −y, camera y → −z
_CAM_IN_HEAD = np.array([[0.0, 0, 1], [-1, 0, 0], [0, -1, 0]])

# Nominal (CAD) DH of a 6R arm, per joint [θ offset, d, a, α]; the true arm differs
# by the manufacturing tolerance DH_SIGMA.
DH_NOMINAL = np.array([
    [0.0, 0.00, 0.00, np.pi / 2],
    [0.0, 0.05, 0.30, 0.0],
    [0.0, 0.00, 0.02, np.pi / 2],
    [0.0, 0.28, 0.00, -np.pi / 2],
    [0.0, 0.00, 0.00, np.pi / 2],
    [0.0, 0.08, 0.00, 0.0],
]).reshape(-1)
DH_SIGMA = np.tile([0.003, 0.002, 0.002, 0.003], 6)  # rad, m, m, rad
DH_LABELS = [f"{n}{j + 1}" for j in range(6) for n in ("θ", "d", "a", "α")]

_rng_truth = np.random.default_rng(2024)
# Any: the true values of different manifolds (poses, intrinsics vectors, ...).
TRUTH: dict[str, Any] = dict(
    left=TRUE_K,
    right=np.array([524.0, 521.0, 317.0, 241.0, -0.27, 0.07, -0.0008, 0.0006, 0.0]),
    right_from_left=bp.SE3(bp.SO3.exp(np.array([0.004, -0.012, 0.003])), [-0.09, 0.0012, -0.0008]),
    imu_from_left=bp.SE3(bp.SO3.exp(np.array([1.2, -0.3, 0.4])), [0.03, -0.06, 0.01]),
    head_from_left=bp.SE3(bp.SO3(_CAM_IN_HEAD @ bp.SO3.exp(np.array([0.02, -0.03, 0.01])).R),
                     [0.09, 0.045, 0.11]),
    p_hand_l=np.array([0.03, 0.06, 0.10]),
    p_hand_r=np.array([0.03, -0.06, 0.10]),
    dh_l=DH_NOMINAL + _rng_truth.normal(0, DH_SIGMA),
    dh_r=DH_NOMINAL + _rng_truth.normal(0, DH_SIGMA),
)
SHOULDER2TORSO = dict(l=bp.SE3(bp.SO3.exp(np.array([-np.pi / 2, 0, 0])), [0.0, 0.22, 0.35]),
                      r=bp.SE3(bp.SO3.exp(np.array([np.pi / 2, 0, 0])), [0.0, -0.22, 0.35]))


def torso_from_head(pan: float, tilt: float) -> bp.SE3:
    """The head's known kinematics (pan about z, then tilt about y)."""
    R = bp.SO3.exp(np.array([0, 0, pan])).R @ bp.SO3.exp(np.array([0, tilt, 0])).R
    return bp.SE3(bp.SO3(R), [0.05, 0.0, 0.55])


def dh_chain(dh: np.ndarray, q: np.ndarray) -> np.ndarray:
    """4×4 product A₁(q₁)…Aₙ(qₙ), Aᵢ = Rot_z(qᵢ+θᵢ) Trans_z(dᵢ) Trans_x(aᵢ) Rot_x(αᵢ)."""
    T = np.eye(4)
    for (th, d, a, al), qi in zip(np.reshape(dh, (-1, 4)), q):
        ct, st, ca, sa = np.cos(qi + th), np.sin(qi + th), np.cos(al), np.sin(al)
        T = T @ np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st],
                          [0, sa, ca, d], [0, 0, 0, 1]])
    return T


def to_se3(T: np.ndarray) -> bp.SE3:
    return bp.SE3(bp.SO3(T[:3, :3]), T[:3, 3])


def head_from_hand(dh, q, side, pan, tilt) -> bp.SE3:
    return base_from_chain(side, pan, tilt) * to_se3(dh_chain(dh, q))


def base_from_chain(side, pan, tilt) -> bp.SE3:
    """The arm's first DH frame in the head frame (known head kinematics)."""
    return torso_from_head(pan, tilt).inverse() * SHOULDER2TORSO[side]


def _batch_chain(dh: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """dh_chain for a batch of joint readings Q (N, n) → (N, 4, 4)."""
    T = np.broadcast_to(np.eye(4), (len(Q), 4, 4))
    for j, (th, d, a, al) in enumerate(np.reshape(dh, (-1, 4))):
        ct, st, ca, sa = np.cos(Q[:, j] + th), np.sin(Q[:, j] + th), np.cos(al), np.sin(al)
        A = np.zeros((len(Q), 4, 4))
        A[:, 0] = np.column_stack([ct, -st * ca, st * sa, a * ct])
        A[:, 1] = np.column_stack([st, ct * ca, -ct * sa, a * st])
        A[:, 2, 1:] = [sa, ca, d]
        A[:, 3, 3] = 1
        T = T @ A
    return T


def _arm_poses(side, n, rng, batch=4000):
    """n random (q, pan, tilt) whose hand marker both cameras see (rejection sampling)."""
    from boxplus.calib.models import project

    out: list[tuple[np.ndarray, float, float]] = []  # (joint angles, pan, tilt)
    S, L2H, L2R = SHOULDER2TORSO[side], TRUTH["head_from_left"], TRUTH["right_from_left"]
    while len(out) < n:
        Q = rng.uniform(-np.pi, np.pi, (batch, 6))
        pan, tilt = rng.uniform(-0.3, 0.3, batch), rng.uniform(0.2, 0.6, batch)
        T = _batch_chain(TRUTH[f"dh_{side}"], Q)
        m_torso = S.fromlocal(T[:, :3, :3] @ TRUTH[f"p_hand_{side}"] + T[:, :3, 3])
        cp, sp, ct, st = np.cos(pan), np.sin(pan), np.cos(tilt), np.sin(tilt)
        Rh = np.stack([np.column_stack([cp * ct, -sp, cp * st]), np.column_stack([sp * ct, cp, sp * st]),
                       np.column_stack([-st, 0 * st, ct])], axis=1)  # Rz(pan) Ry(tilt)
        m_head = np.einsum("nji,nj->ni", Rh, m_torso - [0.05, 0.0, 0.55])
        p_left = L2H.tolocal(m_head)
        p_right = L2R.fromlocal(p_left)
        ok = (p_left[:, 2] > 0.25) & (p_right[:, 2] > 0.25)
        for cam, pc in (("left", p_left), ("right", p_right)):
            uv = project(TRUTH[cam], np.where(ok[:, None], pc, [0, 0, 1.0]))
            ok &= np.all((uv >= 0) & (uv < np.array(SIZE)), axis=1)
        out += [(Q[i], pan[i], tilt[i]) for i in np.flatnonzero(ok)]
    return out[:n]


def simulate(rng, pixel_sigma=0.5, marker_sigma=None, accel_sigma=0.02, imu_by_hand_sigma=0.003,
             n_views=12, n_arm=25):
    """Board images (stereo + gravity) and marker images of both hands (stereo)."""
    from boxplus.calib.models import project

    marker_sigma = 2 * pixel_sigma if marker_sigma is None else marker_sigma
    p = board_points()
    left_from_right = TRUTH["right_from_left"].inverse()
    boards = []
    for world_from_left in random_views(n_views, rng, p.mean(axis=0)):
        zl, vl = observe(TRUTH["left"], world_from_left, p, pixel_sigma, rng)
        zr, vr = observe(TRUTH["right"], world_from_left * left_from_right, p, pixel_sigma, rng)
        g = TRUTH["imu_from_left"].rot.R @ world_from_left.rot.R.T @ G_WORLD + rng.normal(0, accel_sigma, 3)
        boards.append(dict(z_left=zl, vis_left=vl, z_right=zr, vis_right=vr, g=g))
    arms = {}
    for side in "lr":
        obs = []
        for q, pan, tilt in _arm_poses(side, n_arm, rng):
            H = head_from_hand(TRUTH[f"dh_{side}"], q, side, pan, tilt)
            p_left = TRUTH["head_from_left"].tolocal(H.fromlocal(TRUTH[f"p_hand_{side}"]))
            p_right = TRUTH["right_from_left"].fromlocal(p_left)
            obs.append(dict(
                q=q, pan=pan, tilt=tilt, head_from_hand=H,  # forward kinematics of the true arm
                z_left=project(TRUTH["left"], p_left[None])[0] + rng.normal(0, marker_sigma, 2),
                z_right=project(TRUTH["right"], p_right[None])[0] + rng.normal(0, marker_sigma, 2)))
        arms[side] = obs
    imu_pos = TRUTH["imu_from_left"].pos + rng.normal(0, imu_by_hand_sigma, 3)
    return dict(p_board=p, boards=boards, arms=arms, imu_pos_by_hand=imu_pos,
                imu_by_hand_sigma=imu_by_hand_sigma, pixel_sigma=pixel_sigma,
                marker_sigma=marker_sigma, accel_sigma=accel_sigma)


def imu_position(imu_from_left):
    return imu_from_left.pos


def calibrate(data, kinematics="known", dh_prior=True):
    """Returns (problem, ids, solve result). kinematics: "known" (head_from_hand from
    forward kinematics) or "dh" (unknown DH parameters from joint readings)."""
    p = data["p_board"]
    B = data["boards"]
    # ---- closed-form initial values of the board step
    Kl, left_from_board = init_camera([p[b["vis_left"]] for b in B], [b["z_left"] for b in B], SIZE)
    Kr, right_from_board = init_camera([p[b["vis_right"]] for b in B], [b["z_right"] for b in B], SIZE)
    R_imu = rotation_between(np.array([T.rot.R @ G_WORLD for T in left_from_board]), np.array([b["g"] for b in B]))

    o = bp.OptimizationProblem()
    left = add_camera(o, "left", Kl, MODEL)
    right = add_camera(o, "right", Kr, MODEL)
    identity = o.add_random_var(bp.SE3(), fixed=True, name="identity")
    right_from_left = o.add_random_var(relative_pose_init(left_from_board, right_from_board), name="right_from_left")
    imu_from_left = o.add_random_var(bp.SE3(bp.SO3(R_imu), data["imu_pos_by_hand"]), name="imu_from_left")
    o.add_measurement(data["imu_pos_by_hand"], imu_position, [imu_from_left],
                      sigma=data["imu_by_hand_sigma"], name="imu_from_left_by_hand")
    for i, (b, T) in enumerate(zip(B, left_from_board)):
        world_from_left = o.add_random_var(T.inverse(), name=f"world_from_left_{i}")
        add_board(o, b["z_left"], left, world_from_left, identity, p[b["vis_left"]], sigma=data["pixel_sigma"],
                    model=MODEL, group="board left")
        add_board(o, b["z_right"], right, world_from_left, right_from_left, p[b["vis_right"]],
                    sigma=data["pixel_sigma"], model=MODEL, group="board right")
        add_gravity(o, b["g"], world_from_left, imu_from_left, None, G_WORLD, sigma=data["accel_sigma"], group="imu")
    o.solve()  # the board step: cameras, stereo, IMU rotation

    # ---- markers: triangulate with the board step, then marker_hand_eye (closed form)
    def fk(side, a):
        if kinematics == "known":
            return a["head_from_hand"]
        return head_from_hand(DH_NOMINAL, a["q"], side, a["pan"], a["tilt"])

    arms = data["arms"]
    P, H = [], []
    for side in "lr":
        zl = np.array([a["z_left"] for a in arms[side]])
        zr = np.array([a["z_right"] for a in arms[side]])
        P.append(triangulate(zl, zr, o[left].vec, o[right].vec, o[right_from_left], MODEL))
        H.append([fk(side, a) for a in arms[side]])
    left2head0, (pl0, pr0) = marker_hand_eye(P, H)
    head_from_left = o.add_random_var(left2head0, name="head_from_left")
    ids = dict(left=left, right=right, right_from_left=right_from_left, imu_from_left=imu_from_left, head_from_left=head_from_left)
    for side, p0 in zip("lr", (pl0, pr0)):
        ph = o.add_random_var(bp.Rn(p0), name=f"p_hand_{side}", labels=["x", "y", "z"])
        ids[f"p_hand_{side}"] = ph
        if kinematics == "dh":
            dh = o.add_random_var(bp.Rn(DH_NOMINAL), name=f"dh_{side}", labels=DH_LABELS)
            ids[f"dh_{side}"] = dh
            if dh_prior:
                o.add_prior(dh, bp.Rn(DH_NOMINAL), sigma=DH_SIGMA, name=f"CAD dh_{side}")
        for _j, a in enumerate(arms[side]):
            for cam, cam_from_left, z in ((left, identity, a["z_left"]), (right, right_from_left, a["z_right"])):
                if kinematics == "known":
                    add_marker(o, z, cam, head_from_left, ph, cam_from_left, a["head_from_hand"], sigma=data["marker_sigma"],
                                 model=MODEL, group=f"marker {side}")
                else:
                    add_dh_marker(o, z, cam, head_from_left, ph, cam_from_left, dh, a["q"],
                                    base_from_chain=base_from_chain(side, a["pan"], a["tilt"]),
                                    sigma=data["marker_sigma"], model=MODEL, group=f"marker {side}")
    result = o.solve()  # everything jointly
    return o, ids, result


def errors_in_sigma(o, rep, ids):
    """{variable: |estimate − truth| / σ per tangent direction}."""
    return synthetic.errors_in_sigma(o, rep, ids, TRUTH)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--noise", type=float, default=0.5, help="board corner noise σ (px); markers 2σ")
    ap.add_argument("--kinematics", choices=["known", "dh"], default="known")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=None, help="directory for the PNG figures")
    args = ap.parse_args()
    data = simulate(np.random.default_rng(args.seed), args.noise)
    o, ids, result = calibrate(data, args.kinematics)
    print(result)
    rep = report(o)
    print(rep)
    err = errors_in_sigma(o, rep, ids)
    for k, v in err.items():
        print(f"  {k:12s} max |error|/σ = {v.max():.2f}")
    print(f"max |error|/σ over all parameters: {max(v.max() for v in err.values()):.2f}")
    if args.out:
        from boxplus.calib.plot import plot_reprojection_errors, plot_rig

        plot_reprojection_errors(o, f"{args.out}/humanoid_head_reprojection.png")
        left_from_head = o[ids["head_from_left"]].inverse()
        frames = {"left": bp.SE3(), "right": o[ids["right_from_left"]].inverse(),
                  "imu": o[ids["imu_from_left"]].inverse(), "head": left_from_head}
        markers = {f"hand {s}": np.array([o[ids["head_from_left"]].tolocal(a["head_from_hand"].fromlocal(
            o[ids[f"p_hand_{s}"]].vec)) for a in data["arms"][s]]) for s in "lr"}
        plot_rig(f"{args.out}/humanoid_head_rig.png", frames, points=markers, length=0.05)


if __name__ == "__main__":
    main()
