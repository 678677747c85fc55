"""boxplus vs OpenCV on OpenCV's stereo sample, side by side in one run:
mono calibration of each camera (three models) and stereo calibration (fixed
intrinsics, joint). Time includes initialisation for both (OpenCV's
calibrateCamera does its own); RMS as OpenCV defines it; Δ parameters in
units of boxplus' σ (a-posteriori, like OpenCV's).

Run: .venv/bin/python bench/bench_calib_opencv.py
"""

from __future__ import annotations

import time
from pathlib import Path

import boxplus as bp
import cv2
import numpy as np
from boxplus.calib import calibrate_mono, calibrate_stereo, intrinsics_vector

DATA = Path(__file__).resolve().parents[1] / "data" / "calib" / "opencv_stereo_corners.npz"
CV_FLAGS = {
    "opencv5": 0,
    "radial2": cv2.CALIB_ZERO_TANGENT_DIST | cv2.CALIB_FIX_K3,
    "radial1": cv2.CALIB_ZERO_TANGENT_DIST | cv2.CALIB_FIX_K3 | cv2.CALIB_FIX_K2,
}


def timed(f):
    t0 = time.perf_counter()
    out = f()
    return out, time.perf_counter() - t0


def row(case, t_bp, rms_bp, t_cv, rms_cv, dsig):
    print(f"{case:34s} {t_bp * 1e3:8.1f} ms {rms_bp:9.5f} | {t_cv * 1e3:8.1f} ms {rms_cv:9.5f} | "
          f"{rms_bp - rms_cv:+.1e} | {dsig:5.2f}")


def main() -> None:
    cv2.setNumThreads(1)
    d = np.load(DATA)
    obj = d["object_points"]
    size = tuple(int(s) for s in d["image_size"])
    pts = {"left": list(d["image_points_left"]), "right": list(d["image_points_right"])}
    o32 = [obj.astype(np.float32)] * len(pts["left"])
    p32 = {k: [p.astype(np.float32) for p in v] for k, v in pts.items()}
    print(f"{'case':34s} {'boxplus time':>11s} {'RMS px':>9s} | {'OpenCV time':>11s} {'RMS px':>9s} | "
          f"{'ΔRMS':>8s} | max |Δparam|/σ")
    mono = {}
    for cam in ("left", "right"):
        for model in ("opencv5", "radial2", "radial1"):
            cal, t_bp = timed(lambda cam=cam, model=model: calibrate_mono(pts[cam], obj, size, model, name=cam))
            (rms_cv, K, dist, _, _), t_cv = timed(lambda cam=cam, model=model: cv2.calibrateCamera(
                o32, p32[cam], size, None, None, flags=CV_FLAGS[model]))
            rep = cal.report()
            k_cv = intrinsics_vector(K, model, dist.ravel())
            dsig = np.max(np.abs(cal.problem[cal.ids[cam]].vec - k_cv) / rep.std(cam))
            row(f"mono {cam} {model}", t_bp, cal.rms(), t_cv, rms_cv, dsig)
            if model == "opencv5":
                mono[cam] = (K, dist)
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 200, 1e-10)
    for fixed in (True, False):
        (Kl, dl), (Kr, dr) = mono["left"], mono["right"]
        flags = cv2.CALIB_FIX_INTRINSIC if fixed else cv2.CALIB_USE_INTRINSIC_GUESS
        out, t_cv = timed(lambda Kl=Kl, dl=dl, Kr=Kr, dr=dr, flags=flags: cv2.stereoCalibrate(
            o32, p32["left"], p32["right"], Kl, dl, Kr, dr, size, flags=flags, criteria=crit))
        rms_cv, _, _, _, _, Rcv, tcv = out[:7]
        fk = (intrinsics_vector(Kl, "opencv5", dl.ravel()), intrinsics_vector(Kr, "opencv5", dr.ravel()))
        cal, t_bp = timed(lambda fk=fk, fixed=fixed: calibrate_stereo(pts["left"], pts["right"], obj, size, "opencv5",
                                                                 fixed_intrinsics=fk if fixed else None))
        rep = cal.report()
        right_from_left = cal.problem[cal.ids["right_from_left"]]
        delta = np.concatenate([right_from_left.pos - tcv.ravel(), (right_from_left.rot.inverse() * bp.SO3(Rcv)).log()])
        dsig = np.max(np.abs(delta) / rep.std("right_from_left"))
        row(f"stereo {'fixed intrinsics' if fixed else 'joint'} (right_from_left)", t_bp, cal.rms(), t_cv,
            rms_cv, dsig)
    print("(boxplus stereo time includes two Zhang initialisations; OpenCV's is given mono "
          "intrinsics)")


if __name__ == "__main__":
    main()
