"""Joint calibration of a whole robot: Le & Ng's Table II on a rig like their Sec. VIII.

The rig (``boxplus.synthetic.joint_rigs.make_rig``): a 5-DOF arm in standard DH
holding a checkerboard on a machined mount, a stereo pair (cam1, cam2) and a
laser-line triangulator (cam2 plus a light sheet fixed in cam2's frame; stripe
pixels without correspondences along the line). 10 board views (encoder
readings, corners in both cameras, the stripe on the board) and 5 plane views
(a textured plane seen by both cameras, the stripe on it); 5 given folds, each
holding out 2 board views and 1 plane view. The true DH table is the nominal
one perturbed by ~3 mm / 1°.

Five methods, each through :class:`boxplus.joint.JointRig`:

1. incremental (Fig. 8): the stereo pair alone (reprojection + board distances),
   then the light sheet with the cameras fixed, then the arm against the
   stereo's points, then the poses with every intrinsic parameter fixed;
2. joint, no sharing (Fig. 9): one objective; the laser's camera is a separate
   copy of cam2; links form a tree (stereo–arm corners, laser–arm board plane);
3. joint, sharing (Fig. 10): the laser uses cam2 itself;
4. joint, more redundancy (Fig. 11): also the plane views, which tie the stereo
   pair and the laser through shared planes (a graph);
5. full ML: the arm-predicted corners reprojected into both images, encoder
   errors estimated, the stripes on the arm's board plane and the plane views.

Held-out metrics: the 3D error (mm) between the stereo's triangulated corners
(in the arm frame) and the arm's prediction at the encoder readings; the pixel
error (RMS) of the arm-predicted corners reprojected into both cameras; the
distance (mm) of held-out stripe points to the arm's board plane.

Run:  python examples/joint_calibration_robot.py [--seed 0] [--workers N]

The folds run on ``--workers`` threads (default: one per core, at most 5): a
solve releases the GIL, so one fold's Python set-up overlaps another's solve.
"""

from __future__ import annotations

import argparse
import functools
import os
import time
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
from boxplus.joint import (
    DHArm,
    JointRig,
    LightSheet,
    Stereo,
    cross_validate,
    horn,
)
from boxplus.joint.geometry import dh_pose, project, sheet_points, triangulate
from boxplus.manifolds import SE3, SO3
from boxplus.synthetic.joint_rigs import SyntheticRig, make_rig

METHODS = ("incremental", "joint, no sharing", "joint, sharing", "joint, more redundancy", "full ML")
DH_PRIOR = (0.005, np.radians(2.0))  # the maker's tolerance on the table (m, rad)
SIGMA_LINK = 0.5e-3   # arm point vs stereo point (m): the arm's repeatability
SIGMA_BOARD = 0.1e-3  # distance between two corners of the (machined) board (m)
SIGMA_SHEET = 1.0e-3  # stripe point to its plane (m)
SIGMA_FLAT = 0.1e-3   # textured point to its plane (m)
K_PRIOR = np.array([20.0, 10.0, 10.0, 0.1])  # the data sheet's tolerance on [f, cx, cy, k1]


def drawing(data: SyntheticRig, seed: int = 1) -> dict[str, Any]:
    """What the rig's drawing and data sheets say: the truth off by a few mm / degrees."""
    rng = np.random.default_rng(seed)

    def off(T: SE3, mm: float, deg: float) -> SE3:
        return SE3(T.rot * SO3.exp(rng.normal(0, np.radians(deg), 3)), T.pos + rng.normal(0, mm / 1000, 3))

    n = data.sheet_true[:3] @ SO3.exp(rng.normal(0, np.radians(1.0), 3)).R.T
    return {"cam2_from_cam1": off(data.cam2_from_cam1, 3.0, 0.5),
            "sheet": np.r_[n, data.sheet_true[3] + rng.normal(0, 0.003)]}


def _arm(data: SyntheticRig, encoder: bool) -> DHArm:
    return DHArm("arm", data.dh_nominal, data.convention, unknown="all", prior_sigma=DH_PRIOR,
                 encoder_sigma=data.sigma_encoder if encoder else None, mount=data.end_from_board)


def _stereo_pose(rig: JointRig, data: SyntheticRig, boards: np.ndarray) -> SE3:
    """root_from_stereo by Horn's method: triangulated corners vs the nominal arm's."""
    k1, k2 = rig.value("cam1").vec, rig.value("cam2").vec
    c21 = rig.value("stereo.cam2_from_cam1")
    P_s, P_a = [], []
    for v in boards:
        b = data.boards[v]
        P_s.append(triangulate(data.model, k1, data.model, k2, c21, b.z1, b.z2, iterations=0))
        T = dh_pose(rig.table("arm"), b.joints, data.convention, None, data.end_from_board)
        P_a.append(data.board @ T.R.T + T.pos)
    return horn(np.vstack(P_s), np.vstack(P_a))


def build(data: SyntheticRig, split: dict, method: str, values: dict[str, Any] | None = None,
          fixed: tuple[str, ...] = (), parts: tuple[str, ...] = ("arm", "stereo", "laser"),
          encoder: bool | None = None) -> JointRig:
    """The rig of one method on the training views of ``split``.

    ``values`` start values by variable name (cameras, stereo.cam2_from_cam1,
    laser.sheet, arm.dh, poses); ``fixed`` names variables held constant;
    ``parts`` the systems included (incremental steps use subsets);
    ``encoder`` whether encoder errors are estimated (default: for the full ML).
    """
    values = dict(values or {})
    guess = drawing(data)
    ml = method == "full ML"
    shared = method != "joint, no sharing"
    planes = method in ("joint, more redundancy", "full ML")
    rig = JointRig(root=parts[0])
    laser_cam = "cam2" if shared else "cam2_laser"
    for cam in ("cam1", "cam2") + ((laser_cam,) if not shared and "laser" in parts else ()):
        # a camera starts at (and, when not given, is tied to) the data sheet's values
        rig.add_camera(cam, values.get(cam, data.k_nominal), data.model,
                       prior_sigma=None if cam in values else K_PRIOR)
    boards, plane_views = split["boards"], split["planes"]
    if "arm" in parts:
        rig.add_system(_arm(data, encoder=ml if encoder is None else encoder))
        if "arm.dh" in values:
            rig.problem.set_value(rig.ids["arm.dh"], values["arm.dh"])
    if "stereo" in parts:
        rig.add_system(Stereo("stereo", "cam1", "cam2", values.get("stereo.cam2_from_cam1", guess["cam2_from_cam1"])),
                       pose=SE3())
        if rig.root != "stereo":
            pose = values["pose:stereo"] if "pose:stereo" in values else _stereo_pose(rig, data, boards)
            rig.problem.set_value(rig.ids["pose:stereo"], pose)
    if "laser" in parts:
        sheet = values.get("laser.sheet", guess["sheet"])
        stereo_from_cam2 = rig.value("stereo.cam2_from_cam1").inverse() if "stereo" in parts else SE3()
        pose = values["pose:laser"] if "pose:laser" in values else rig.pose("stereo") * stereo_from_cam2
        rig.add_system(LightSheet("laser", laser_cam, sheet), pose=pose)
    for v in boards:
        b = data.boards[v]
        has_arm = "arm" in parts
        if "stereo" in parts:
            if ml and has_arm:  # the arm-predicted corners in both images
                for index, z in ((0, b.z1), (1, b.z2)):
                    rig.project_targets("arm", b.joints, data.board, "stereo", z, camera=index, reading=v,
                                        sigma=data.sigma_px)
            else:
                X = rig.stereo_points("stereo", b.z1, b.z2, sigma=data.sigma_px,
                                      names=[f"stereo.board{v}.X{j}" for j in range(len(data.board))])
                for i, j in _board_neighbours(data):
                    rig.distance(X[i], X[j], float(np.linalg.norm(data.board[i] - data.board[j])), sigma=SIGMA_BOARD)
                if has_arm:
                    for x, c in zip(X, data.board):
                        rig.link(x, rig.arm_point("arm", b.joints, c, reading=v), sigma=SIGMA_LINK)
                elif "laser" in parts:  # incremental step 2: the board plane as the stereo sees it
                    board_plane = rig.plane(f"board{v}", owner="stereo")
                    rig.coplanar(X, board_plane, sigma=SIGMA_FLAT)
                    rig.coplanar([rig.sheet_point("laser", uv) for uv in b.stripe], board_plane, sigma=SIGMA_SHEET)
        if "laser" in parts and has_arm:
            rig.coplanar([rig.sheet_point("laser", uv) for uv in b.stripe],
                         rig.arm_plane("arm", b.joints, reading=v), sigma=SIGMA_SHEET)
    if planes and "stereo" in parts and "laser" in parts:
        for v in plane_views:
            pv = data.planes[v]
            plane = rig.plane(f"plane{v}")
            X = rig.stereo_points("stereo", pv.z1, pv.z2, sigma=data.sigma_px,
                                  names=[f"stereo.plane{v}.X{j}" for j in range(len(pv.z1))])
            rig.coplanar(X, plane, sigma=SIGMA_FLAT)
            rig.coplanar([rig.sheet_point("laser", uv) for uv in pv.stripe], plane, sigma=SIGMA_SHEET)
    for name in fixed:
        if name in rig.ids:
            rig.problem.fix(rig.ids[name])
    return rig


@functools.lru_cache(maxsize=1)
def _neighbours(cols: int, rows: int) -> tuple[tuple[int, int], ...]:
    out = []
    for r in range(rows):
        for c in range(cols):
            i = r * cols + c
            if c + 1 < cols:
                out.append((i, i + 1))
            if r + 1 < rows:
                out.append((i, i + cols))
    return tuple(out)


def _board_neighbours(data: SyntheticRig) -> tuple[tuple[int, int], ...]:
    xs = np.unique(np.round(data.board[:, 0], 9))
    return _neighbours(len(xs), len(data.board) // len(xs))


def _values(rig: JointRig, names: tuple[str, ...]) -> dict[str, Any]:
    return {n: rig.value(n) for n in names if n in rig.ids}


def train(data: SyntheticRig, method: str, split: dict) -> dict[str, Any]:
    """Calibrates with one method; returns the estimates by variable name."""
    keep = ("cam1", "cam2", "cam2_laser", "stereo.cam2_from_cam1", "laser.sheet", "arm.dh", "pose:stereo",
            "pose:laser")
    if method != "incremental":
        rig = build(data, split, method)
        rig.solve()
        return _values(rig, keep)
    # 1. the stereo pair alone
    r1 = build(data, split, method, parts=("stereo",))
    r1.solve()
    v = _values(r1, keep)
    # 2. the light sheet, cameras fixed (the laser's camera is cam2: its pose in the stereo frame is known)
    v["pose:laser"] = v["stereo.cam2_from_cam1"].inverse()
    r2 = build(data, split, method, v, fixed=("cam1", "cam2", "stereo.cam2_from_cam1", "pose:laser"),
               parts=("stereo", "laser"))
    r2.solve()
    v.update(_values(r2, ("laser.sheet",)))
    # 3. the arm and the stereo's pose against the stereo's points
    r3 = build(data, split, method, v, fixed=("cam1", "cam2", "stereo.cam2_from_cam1"), parts=("arm", "stereo"))
    r3.solve()
    v.update(_values(r3, ("arm.dh", "pose:stereo")))
    v["pose:laser"] = v["pose:stereo"] * v["stereo.cam2_from_cam1"].inverse()
    # 4. the poses, every intrinsic parameter fixed
    r4 = build(data, split, "joint, sharing", v, fixed=("cam1", "cam2", "stereo.cam2_from_cam1", "laser.sheet",
                                                        "arm.dh"))
    r4.solve()
    v.update(_values(r4, ("pose:stereo", "pose:laser")))
    return v


def truth_values(data: SyntheticRig) -> dict[str, Any]:
    from boxplus.manifolds import Rn

    return {"cam1": Rn(data.k1_true), "cam2": Rn(data.k2_true), "stereo.cam2_from_cam1": data.cam2_from_cam1,
            "laser.sheet": data.sheet_true, "arm.dh": Rn(data.dh_true.ravel()), "pose:stereo": data.arm_from_cam1,
            "pose:laser": data.arm_from_cam2}


def metrics(data: SyntheticRig, v: dict[str, Any], split: dict) -> np.ndarray:
    """Held-out (3D mm, reprojection px, laser mm, vs truth mm) over the validation boards of ``split``.

    3D: stereo-triangulated corners vs the arm's prediction at the encoder readings (the paper's
    measure: includes the stereo's own depth noise); reprojection: RMS of the arm-predicted corners
    in both images; laser: held-out stripe points to the arm's board plane; vs truth: the
    arm-predicted corners in camera 1 against the true corners there (simulation only: the
    calibration's own error, free of measurement noise).
    """
    k1, k2, c21 = np.asarray(v["cam1"].vec), np.asarray(v["cam2"].vec), v["stereo.cam2_from_cam1"]
    k_laser = np.asarray(v.get("cam2_laser", v["cam2"]).vec)
    sheet = v["laser.sheet"]
    sheet = np.r_[sheet.normal.vec, sheet.distance.vec] if hasattr(sheet, "normal") else np.asarray(sheet)
    table = np.asarray(v["arm.dh"].vec).reshape(-1, 4)
    S, L = v["pose:stereo"], v["pose:laser"]
    e3, epx, elaser, etrue = [], [], [], []
    for b in (data.boards[i] for i in split["boards"]):
        T = dh_pose(table, b.joints, data.convention, None, data.end_from_board)
        P_arm = data.board @ T.R.T + T.pos
        X = triangulate(data.model, k1, data.model, k2, c21, b.z1, b.z2)
        e3.append(np.linalg.norm(X @ S.R.T + S.pos - P_arm, axis=1))
        p1 = (P_arm - S.pos) @ S.R
        epx.append(np.concatenate([project(data.model, k1, p1) - b.z1,
                                   project(data.model, k2, p1 @ c21.R.T + c21.pos) - b.z2]))
        P_l = sheet_points(data.model, k_laser, sheet, b.stripe) @ L.R.T + L.pos
        n = T.R[:, 2]
        elaser.append(np.abs(P_l @ n - n @ T.pos))
        T_true = data.board_pose(b.joints_true)
        p1_true = (data.board @ T_true.R.T + T_true.pos - data.arm_from_cam1.pos) @ data.arm_from_cam1.R
        etrue.append(np.linalg.norm(p1 - p1_true, axis=1))
    px = np.vstack(epx)
    return np.array([1000 * np.mean(np.concatenate(e3)), np.sqrt(np.mean(np.sum(px * px, 1))),
                     1000 * np.mean(np.concatenate(elaser)), 1000 * np.mean(np.concatenate(etrue))])


def main(argv: list[str] | None = None) -> dict[str, Any]:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--workers", type=int, default=min(5, os.cpu_count() or 1),
                    help="threads running the folds (default: one per core, at most 5; 1: serial)")
    ap.add_argument("--methods", nargs="*", default=list(METHODS))
    ap.add_argument("--folds", type=int, default=5, help="use the first N of the 5 given folds")
    args = ap.parse_args(argv)
    t0, c0 = time.perf_counter(), time.process_time()
    data = make_rig(args.seed)
    data.folds = data.folds[:args.folds]
    fit_time: dict[str, list[float]] = {m: [] for m in args.methods}
    fit_cpu: dict[str, list[float]] = {m: [] for m in args.methods}

    def method(name: str, split: dict) -> dict[str, Any]:
        t, c = time.perf_counter(), time.thread_time()
        v = train(data, name, split)
        fit_time[name].append(time.perf_counter() - t)
        fit_cpu[name].append(time.thread_time() - c)  # this thread's CPU: other processes' load does not count
        return v

    executor = ThreadPoolExecutor(args.workers) if args.workers > 1 else None
    # one fit per (method, fold); the three metrics are read off the same fit
    cv = cross_validate({m: functools.partial(method, m) for m in args.methods},
                        lambda v, split: metrics(data, v, split)[None], folds=data.folds, executor=executor,
                        scale=1.0, unit="mm")
    print(f"rig: {len(data.boards)} board views x {len(data.board)} corners, {len(data.planes)} plane views, "
          f"{len(data.folds)} given folds; pixel noise {data.sigma_px} px, encoder noise {data.sigma_encoder} rad")
    truth = np.array([metrics(data, truth_values(data), va) for _, va in data.folds])
    rows = {"(true parameters)": truth}
    rows.update({m: np.array(cv.fold_metrics[m]) for m in args.methods})
    print(f"{'method':24s} {'3D error (mm)':>15s} {'reprojection (px)':>17s} {'laser (mm)':>15s} "
          f"{'vs truth (mm)':>15s}  fit/fold wall (CPU) s")
    for m, e in rows.items():
        mean, std = e.mean(0), e.std(0)
        ft = f"{np.mean(fit_time[m]):.2f} ({np.mean(fit_cpu[m]):.2f})" if m in fit_time else ""
        print(f"{m:24s} " + " ".join(f"{mean[i]:7.3f} ± {std[i]:5.3f}" for i in range(4)) + f"  {ft}")
    verdict = _ordering(rows, args.methods)
    print(verdict)
    total = time.perf_counter() - t0
    print(f"total {total:.1f} s wall, {time.process_time() - c0:.1f} s CPU")
    return {"rows": rows, "fit_time": fit_time, "fit_cpu": fit_cpu, "total": total, "verdict": verdict}


def _ordering(rows: dict[str, np.ndarray], methods: list[str]) -> str:
    """Whether Table II's ordering holds, per metric, with gaps larger than the fold spread."""
    order = [m for m in METHODS if m in methods]
    lines = ["Table II ordering (the error must fall down the list; a gap is 'clear' when larger than "
             "the larger of the two methods' standard deviations over the folds):"]
    for i, metric in ((0, "3D error (mm)"), (1, "reprojection (px)"), (3, "vs truth (mm)")):
        lines.append(f"  {metric}:")
        for a, b in zip(order, order[1:]):
            da, db = rows[a][:, i], rows[b][:, i]
            gap = da.mean() - db.mean()
            spread = max(da.std(), db.std())
            state = "holds, clear" if gap > spread else "holds, within the fold spread" if gap > 0 else \
                "does NOT hold"
            lines.append(f"    {a} -> {b}: {da.mean():.3f} -> {db.mean():.3f} (gap {gap:+.3f}, spread "
                         f"{spread:.3f}): {state}")
    return "\n".join(lines)


if __name__ == "__main__":
    main()
