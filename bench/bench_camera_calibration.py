"""Single camera calibration (MTKM Listing 1 model) on OpenCV's sample corners:
boxplus with a vectorised Python measurement function vs. the same problem built
from the C++ pinhole factor, vs. scipy.optimize.least_squares on the same
residuals, vs. OpenCV's calibrateCamera — side by side, from the same initial
values (Zhang's closed form). Targets (issue 3): vectorised Python within 3× of
C++ factors, and faster than scipy.

Run: .venv/bin/python bench/bench_camera_calibration.py [--repeat N]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import boxplus as bp
import numpy as np
from boxplus.calib import add_projection, init_camera
from boxplus.calib.models import project_pinhole
from scipy.optimize import least_squares
from scipy.sparse import lil_matrix
from scipy.spatial.transform import Rotation

DATA = Path(__file__).resolve().parents[1] / "data" / "calib" / "opencv_stereo_corners.npz"
intrinsic_t = bp.make_compound("intrinsic_t", focal_length=bp.Rn(1), offset=bp.Rn(2), distortion=bp.Rn(1))


def pinhole(f, c, k1, p_in_cam):
    return project_pinhole(p_in_cam, f, c, k1=k1)


def project_points(intrinsic, world_from_cam, p_in_world):
    return pinhole(intrinsic.focal_length.vec, intrinsic.offset.vec, intrinsic.distortion.vec,
                   world_from_cam.tolocal(p_in_world))


def load():
    d = np.load(DATA)
    obj, imgs = d["object_points"], list(d["image_points_left"])
    K, poses = init_camera(obj, imgs, tuple(d["image_size"]))
    return obj, imgs, K, [p.inverse() for p in poses], tuple(int(s) for s in d["image_size"])


def run_boxplus(obj, imgs, K, world_from_cam, form):
    o = bp.OptimizationProblem()
    iid = o.add_random_var(intrinsic_t(focal_length=[K[0, 0]], offset=K[:2, 2], distortion=[0.0]))
    ident = o.add_random_var(bp.SE3(), fixed=True)
    for p_img, pose in zip(imgs, world_from_cam):
        cid = o.add_random_var(pose)
        if form == "vectorised":
            o.add_measurements(p_img, project_points, np.tile([iid, cid], (len(obj), 1)), constants=(obj,))
        elif form == "per point":
            for j in range(len(obj)):
                o.add_measurement(p_img[j], project_points, [iid, cid], constants=(obj[j],))
        else:
            for j in range(len(obj)):
                add_projection(o, p_img[j], iid, cid, ident, obj[j], model="simple_radial")
    t0 = time.perf_counter()
    r = o.solve()
    t = time.perf_counter() - t0
    return t, r.iterations, 2 * r.final_cost, np.sqrt(2 * r.final_cost / (len(imgs) * len(obj)))


def run_scipy(obj, imgs, K, world_from_cam):
    n = len(imgs)
    x0 = [K[0, 0], K[0, 2], K[1, 2], 0.0]
    for pose in world_from_cam:  # board→cam as rotation vector + translation
        inv = pose.inverse()
        x0 += list(inv.rot.log()) + list(inv.pos)
    x0 = np.array(x0)
    Z = np.stack(imgs)

    def residuals(x):
        f, c, k1 = x[0], x[1:3], x[3]
        P = x[4:].reshape(n, 6)
        R = Rotation.from_rotvec(P[:, :3]).as_matrix()
        p_in_cam = np.einsum("nij,mj->nmi", R, obj) + P[:, None, 3:]
        return (pinhole(f, c, k1, p_in_cam) - Z).ravel()

    m = n * len(obj) * 2
    S = lil_matrix((m, 4 + 6 * n), dtype=int)
    for i in range(n):
        rows = slice(i * len(obj) * 2, (i + 1) * len(obj) * 2)
        S[rows, :4] = 1
        S[rows, 4 + 6 * i : 10 + 6 * i] = 1
    t0 = time.perf_counter()
    r = least_squares(residuals, x0, jac_sparsity=S, method="trf", x_scale="jac",
                      ftol=1e-10, xtol=1e-10, gtol=1e-12)
    t = time.perf_counter() - t0
    ssq = float(np.sum(r.fun**2))
    return t, r.nfev, ssq, np.sqrt(ssq / (n * len(obj)))


def run_opencv(obj, imgs, size):
    import cv2

    flags = (cv2.CALIB_FIX_ASPECT_RATIO | cv2.CALIB_ZERO_TANGENT_DIST | cv2.CALIB_FIX_K2
             | cv2.CALIB_FIX_K3 | cv2.CALIB_USE_INTRINSIC_GUESS)
    K0 = np.array([[500.0, 0, size[0] / 2], [0, 500.0, size[1] / 2], [0, 0, 1]])
    t0 = time.perf_counter()
    rms, *_ = cv2.calibrateCamera([obj.astype(np.float32)] * len(imgs), [p.astype(np.float32) for p in imgs],
                                  size, K0, np.zeros(5), flags=flags)
    return time.perf_counter() - t0, None, rms**2 * len(imgs) * len(obj), rms


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5, help="best of N runs")
    args = ap.parse_args()
    obj, imgs, K, world_from_cam, size = load()
    runs = {
        "boxplus C++ factor": lambda: run_boxplus(obj, imgs, K, world_from_cam, "cpp"),
        "boxplus python (vectorised)": lambda: run_boxplus(obj, imgs, K, world_from_cam, "vectorised"),
        "boxplus python (per point)": lambda: run_boxplus(obj, imgs, K, world_from_cam, "per point"),
        "scipy least_squares (trf, sparse)": lambda: run_scipy(obj, imgs, K, world_from_cam),
    }
    try:
        import cv2  # noqa: F401

        runs["OpenCV calibrateCamera (same model)"] = lambda: run_opencv(obj, imgs, size)
    except ImportError:
        print("(opencv-python-headless not installed: OpenCV row skipped)")
    results = {}
    for name, fn in runs.items():
        reps = 1 if "per point" in name else args.repeat
        results[name] = min((fn() for _ in range(reps)), key=lambda r: r[0])
    print(f"single camera calibration, {len(imgs)} images × {len(obj)} corners, model f, cx, cy, k1;"
          f" solve time, best of {args.repeat}")
    print(f"{'method':38s} {'solve':>10s} {'iter/nfev':>10s} {'Σ‖e‖² px²':>12s} {'RMS px':>9s}")
    for name, (t, it, ssq, rms) in results.items():
        print(f"{name:38s} {t * 1e3:8.1f}ms {('-' if it is None else it):>10} {ssq:12.6f} {rms:9.5f}")
    cpp = results["boxplus C++ factor"][0]
    vec = results["boxplus python (vectorised)"][0]
    sp = results["scipy least_squares (trf, sparse)"][0]
    print(f"ratio python(vectorised) / C++ factor = {vec / cpp:.2f}  (target ≤ 3)")
    print(f"ratio python(vectorised) / scipy      = {vec / sp:.2f}  (target < 1)")


if __name__ == "__main__":
    main()
