"""Tutorial: a robot arm and a stereo pair calibrated together.

    python docs/tutorials/joint_rig.py [--out DIR]

A 5-joint arm holds a chessboard in front of a stereo pair (simulated, with
known truth: boxplus.synthetic.joint_rigs.make_rig). One JointRig holds the arm's
Denavit–Hartenberg table, both cameras' intrinsics, the pair's relative pose and
where the pair stands in the arm's frame; every board corner is predicted by the
arm at its encoder readings and reprojected into both images (Le & Ng's full
maximum likelihood). Prints the estimates with σ beside the truth and writes
the tutorial's picture (joint_rig.png) into DIR (default: this folder).
"""

from __future__ import annotations

import argparse
import warnings
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from boxplus import SE3, SO3, UndeterminedWarning
from boxplus.joint import DHArm, JointRig, Stereo, horn
from boxplus.joint.geometry import dh_pose, triangulate
from boxplus.synthetic.joint_rigs import make_rig

HERE = Path(__file__).resolve().parent


def build(data) -> JointRig:
    rig = JointRig(root="arm")  # every pose is expressed in the arm's base frame
    # Both cameras start at the data sheet's intrinsics, with its tolerance as a prior.
    for cam in ("cam1", "cam2"):
        rig.add_camera(cam, data.k_nominal, data.model, prior_sigma=[20.0, 10.0, 10.0, 0.1])
    # The arm: every entry of the maker's DH table unknown, within its tolerance
    # (5 mm, 2°); the encoder readings have noise of their own; the board's mount
    # on the flange is machined, hence known.
    rig.add_system(DHArm("arm", data.dh_nominal, data.convention, unknown="all",
                         prior_sigma=(0.005, np.radians(2.0)),
                         encoder_sigma=data.sigma_encoder, mount=data.end_from_board))
    # The pair: cam2_from_cam1 from the drawing (a few mm and a degree off).
    drawing = data.cam2_from_cam1 * SE3(SO3.exp(np.radians([0.5, -0.5, 0.3])), [0.003, -0.002, 0.002])
    rig.add_system(Stereo("stereo", "cam1", "cam2", drawing), pose=SE3())
    rig.problem.set_value(rig.ids["pose:stereo"], start_of_stereo_pose(rig, data))
    # Every board view: the arm's prediction of each corner, reprojected into both images.
    for v, b in enumerate(data.boards):
        for camera, z in ((0, b.z1), (1, b.z2)):
            rig.project_targets("arm", b.joints, data.board, "stereo", z, camera=camera,
                                reading=v, sigma=data.sigma_px)
    return rig


def start_of_stereo_pose(rig: JointRig, data) -> SE3:
    # arm_from_stereo in closed form: the corners triangulated by the pair
    # against the same corners predicted by the nominal arm (Horn's method).
    k1, k2 = rig.value("cam1").vec, rig.value("cam2").vec
    c21 = rig.value("stereo.cam2_from_cam1")
    seen, predicted = [], []
    for b in data.boards:
        seen.append(triangulate(data.model, k1, data.model, k2, c21, b.z1, b.z2, iterations=0))
        T = dh_pose(rig.table("arm"), b.joints, data.convention, None, data.end_from_board)
        predicted.append(data.board @ T.R.T + T.pos)
    return horn(np.vstack(seen), np.vstack(predicted))


def compare(rig: JointRig, data) -> dict:
    table = rig.table("arm")
    err_dh = table - data.dh_true  # rows: joints; columns: θ offset, d, a, α
    pose = rig.pose("stereo")
    d_pose = pose.inverse() * data.arm_from_cam1
    sigma_pose = rig.problem.std(rig.ids["pose:stereo"])
    return {"dh": err_dh, "pose_mm": 1e3 * np.linalg.norm(d_pose.pos),
            "pose_deg": np.degrees(np.linalg.norm(d_pose.rot.log())),
            "sigma_pose_mm": 1e3 * np.linalg.norm(sigma_pose[:3]),
            "k1": rig.value("cam1").vec - data.k1_true}


def prior_bound(rig: JointRig) -> list[str]:
    # An entry whose σ is close to its prior's was determined by the prior, not by
    # the data: with a board seen from one place, the base joint's θ and d trade
    # against where the pair stands, and the d of parallel joints against each other.
    sigma = rig.problem.std(rig.ids["arm.dh"])
    prior = np.array([0.005 if lab.startswith(("d", "a")) and not lab.startswith("alpha")
                      else np.radians(2.0) for lab in rig.dh_values("arm")])
    return [lab for lab, s, p in zip(rig.dh_values("arm"), sigma, prior) if s > 0.8 * p]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=HERE)
    args = ap.parse_args()
    data = make_rig(0)
    rig = build(data)
    nominal = rig.table("arm").copy()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", UndeterminedWarning)
        result = rig.solve()
    # RMS of each corner's 2-D error: 0.3 px noise per axis gives 0.3·√2 = 0.42 px
    print(f"solve: {result.termination}, reprojection RMS "
          f"{result.rms['projection[stereo]']:.3f} px, cost {result.cost:.1f}")
    for w in caught:
        print("warning:", w.message)
    c = compare(rig, data)
    print(f"DH table, largest error: nominal {1e3 * np.abs(nominal - data.dh_true)[:, 1:3].max():.2f} mm"
          f" -> estimated {1e3 * np.abs(c['dh'])[:, 1:3].max():.2f} mm (d, a); "
          f"{np.degrees(np.abs(nominal - data.dh_true)[:, [0, 3]]).max():.2f}° -> "
          f"{np.degrees(np.abs(c['dh'])[:, [0, 3]]).max():.2f}° (θ, α)")
    print(f"arm_from_stereo: {c['pose_mm']:.2f} mm and {c['pose_deg']:.3f}° from the truth "
          f"(σ of its position {c['sigma_pose_mm']:.2f} mm)")
    print(f"cam1 focal length: {c['k1'][0]:+.2f} px from the truth")
    print("left to the maker's tolerance (σ > 0.8 × the prior's):",
          ", ".join(prior_bound(rig)))

    # The picture: each DH entry's error before and after, against its σ.
    labels = list(rig.dh_values("arm"))
    sigma = rig.problem.std(rig.ids["arm.dh"])
    before = (nominal - data.dh_true).ravel()
    after = c["dh"].ravel()
    # lengths in mm, angles in degrees
    scale = np.array([1e3 if lab.startswith(("d", "a")) and not lab.startswith("alpha")
                      else np.degrees(1.0) for lab in labels])
    fig, ax = plt.subplots(figsize=(12, 4.2))
    x = np.arange(len(labels))
    ax.bar(x - 0.2, np.abs(before) * scale, 0.4, label="maker's table", color="0.7")
    ax.bar(x + 0.2, np.abs(after) * scale, 0.4, label="calibrated", color="tab:blue")
    ax.plot(x + 0.2, sigma * scale, "v", color="k", ms=5, label="σ of the calibrated value")
    prior = np.array([0.005 if lab.startswith(("d", "a")) and not lab.startswith("alpha")
                      else np.radians(2.0) for lab in labels])
    ax.plot(x + 0.2, prior * scale, "_", color="tab:red", ms=14, mew=2,
            label="σ of the maker's tolerance (the prior)")
    ax.set_xticks(x, labels, rotation=60, fontsize=8)
    ax.set(ylabel="|error|, σ [mm for d, a; ° for θ, α]",
           title="Denavit–Hartenberg table of the arm: error against the truth")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out / "joint_rig.png", dpi=90)
    plt.close(fig)


if __name__ == "__main__":
    main()
