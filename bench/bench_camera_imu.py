"""Camera–IMU calibration in motion against the truth, on motions that are no spline
(#28): which knot spacing the trajectory needs.

Each recording is simulated by boxplus.synthetic.camera_imu.simulate_camera_imu with
``motion="sines"``: the IMU's true motion is a sum of sinusoids up to a bandwidth (1–3
Hz: a rig waved by hand, slowly to vigorously), so the spline of any knot spacing
has a modelling error. For every (bandwidth, IMU rate, knot spacing) the script fits
``--seeds`` recordings and prints what a user cares about, against the truth:
imu_from_cam's translation (mm) and rotation (deg) errors and the time offset's
(ms), each as a median, the largest normalised error |e|/σ over those seven
quantities (σ right: mostly < 3), the IMU residuals' RMS over the noise put in
(1: the spline follows the motion), the solve time, and the recordings the fit
refused as implausible. Kalibr, the peer for this job, needs ROS 1 and is not run
here (no pip-installable peer exists).

Run: .venv/bin/python bench/bench_camera_imu.py [--seeds 4] [--spacings 0.01 0.02 0.05]
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
from boxplus import SE3, SO3
from boxplus.calib.camera_imu import calibrate_camera_imu
from boxplus.synthetic.camera_imu import simulate_camera_imu

IMU_FROM_CAM = SE3(SO3.exp(np.array([0.1, -0.05, 1.2])), np.array([0.05, 0.02, -0.03]))


def one(bandwidth: float, imu_rate: float, spacing: float | None, seed: int) -> dict | None:
    rng = np.random.default_rng(seed)
    offset = float(rng.uniform(-0.05, 0.05))
    data, truth, K = simulate_camera_imu(rng, time_offset=offset, imu_from_cam=IMU_FROM_CAM, motion="sines",
                                         bandwidth=bandwidth, imu_rate=imu_rate)
    kwargs = {} if spacing is None else {"knot_spacing": spacing}
    t = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cal = calibrate_camera_imu(data, K, pixel_sigma=0.3, **kwargs)
    except ValueError:
        return None
    seconds = time.perf_counter() - t
    est = cal.imu_from_cam
    e = np.r_[est.pos - IMU_FROM_CAM.pos, (IMU_FROM_CAM.rot.inverse() * est.rot).log(), cal.time_offset - offset]
    s = np.r_[cal.std("imu_from_cam"), cal.std("time_offset")]
    rms = cal.problem.rms()
    return {"pos": np.linalg.norm(e[:3]) * 1e3, "rot": np.degrees(np.linalg.norm(e[3:6])),
            "d": abs(e[6]) * 1e3, "z": float(np.max(np.abs(e / s))),
            "imu": max(rms["gyroscope"] / (0.005 * np.sqrt(3)), rms["accelerometer"] / (0.05 * np.sqrt(3))),
            "time": seconds, "spacing": cal.knot_spacing}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--bandwidths", type=float, nargs="+", default=[1.0, 2.0, 3.0])
    ap.add_argument("--imu-rates", type=float, nargs="+", default=[200.0])
    ap.add_argument("--spacings", type=float, nargs="+", default=[0.01, 0.02, 0.033, 0.05],
                    help="knot spacings (s); 0 = calibrate_camera_imu's default")
    args = ap.parse_args()
    print(f"{'bandwidth':>9s} {'IMU Hz':>6s} {'knots':>7s} {'fits':>5s} {'pos mm':>7s} {'rot deg':>8s} "
          f"{'d ms':>6s} {'max|z|':>7s} {'IMU RMS/σ':>10s} {'time s':>7s}")
    for bw in args.bandwidths:
        for rate in args.imu_rates:
            for spacing in args.spacings:
                rows = [one(bw, rate, spacing or None, seed) for seed in range(args.seeds)]
                ok = [r for r in rows if r is not None]
                if not ok:
                    print(f"{bw:9.1f} {rate:6.0f} {spacing:7.3f} {0:>2d}/{len(rows):<2d} (every fit refused)")
                    continue
                med = {k: float(np.median([r[k] for r in ok])) for k in ok[0]}
                worst_imu = max(r["imu"] for r in ok)
                label = f"{med['spacing']:.3f}" if spacing else f"d {med['spacing']:.3f}"
                print(f"{bw:9.1f} {rate:6.0f} {label:>7s} {len(ok):>2d}/{len(rows):<2d} {med['pos']:7.2f} "
                      f"{med['rot']:8.3f} {med['d']:6.3f} {max(r['z'] for r in ok):7.1f} "
                      f"{worst_imu:10.2f} {med['time']:7.2f}", flush=True)


if __name__ == "__main__":
    main()
